//! Request and response bodies (JSON, SI units; every field name ends in
//! its unit, non-dimensional values sit beside them with `_nondim`).
//! The same types serve the CLI, the HTTP API and the job queue. The
//! parts every domain shares (the system, its model, the profile, the
//! groups) live in [`crate::contract::system`] and are re-exported here
//! for the old `contract::dto::…` paths.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

pub use crate::contract::error::{ErrorBody, ErrorDetail};
pub use crate::contract::system::input::{
    DEFAULT_ELEMENTS, ModelInput, ModelKind, NumericsInput, ProfileInput, RatePointInput,
    SYSTEM_KEYS, SystemInput, SystemRequest,
};
pub use crate::contract::system::output::{EigenvalueOutput, Groups};
pub use crate::contract::system::{AerostatInput, CableInput, WinchInput, WindInput};

/// Instantaneous deployment state for a stability query.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct StateInput {
    /// Cable length L (m).
    #[schema(example = 500.0, minimum = 0.001, maximum = 1e5)]
    pub length_m: f64,
    /// Winch rate L̇ (m/s).
    #[serde(default)]
    #[schema(example = 10.0, minimum = -1000.0, maximum = 1000.0)]
    pub rate_m_s: f64,
    /// Winch acceleration L̈ (m/s²).
    #[serde(default)]
    #[schema(minimum = -1000.0, maximum = 1000.0)]
    pub acceleration_m_s2: f64,
}

/// `POST /api/v1/stability`: the QEP spectrum at one state.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
pub struct StabilityRequest {
    #[serde(flatten)]
    pub system: SystemInput,
    #[serde(flatten)]
    pub params: StabilityParams,
}

/// The fields of a stability request besides the system.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct StabilityParams {
    pub state: StateInput,
    /// How many modes (eigenvalues with Im ≥ 0, by frequency) to return.
    #[serde(default = "default_modes")]
    #[schema(example = 3, minimum = 1, maximum = 4000)]
    pub modes: usize,
}

fn default_modes() -> usize {
    3
}

/// `POST /api/v1/critical`: critical time of one profile.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
pub struct CriticalRequest {
    #[serde(flatten)]
    pub system: SystemInput,
    #[serde(flatten)]
    pub params: CriticalParams,
}

/// The fields of a critical-time request besides the system.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct CriticalParams {
    pub profile: ProfileInput,
    /// Also solve the full QEP at the start, half-way, and 0.1 % either side
    /// of t* to confirm the answer (about 10 ms at 50 elements). Profiles
    /// whose criterion is the QEP itself (accelerating) always do.
    #[serde(default)]
    pub confirm_with_qep: bool,
}

/// `POST /api/v1/safe-rate`: largest constant rate that reaches a target.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
pub struct SafeRateRequest {
    #[serde(flatten)]
    pub system: SystemInput,
    #[serde(flatten)]
    pub params: SafeRateParams,
}

/// The fields of a safe-rate request besides the system.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct SafeRateParams {
    /// Elevation (cable length) to reach (m).
    #[schema(example = 1200.0, minimum = 0.001, maximum = 1e5)]
    pub target_elevation_m: f64,
}

/// The rates of a chart (m/s, each above 0 and at most 1000): a list, or
/// `{min, max, count}` evenly spaced (the one [`GridInput`] of every grid).
pub type RateGrid = crate::contract::system::grid::RateGridInput;

/// `POST /api/v1/charts`: t* and h* against rate, one series per buoyancy.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
pub struct ChartRequest {
    #[serde(flatten)]
    pub system: SystemInput,
    #[serde(flatten)]
    pub params: ChartParams,
}

/// The fields of a chart request besides the system.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct ChartParams {
    /// Rates of the chart (m/s).
    pub rates_m_s: RateGrid,
    /// Net buoyancies, one series each (N); default: the aerostat's.
    #[serde(default)]
    #[schema(minimum = 0.001, maximum = 1e7)]
    pub net_buoyancies_n: Vec<f64>,
}

/// The deployment state, SI and non-dimensional.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct StateOutput {
    pub length_m: f64,
    pub rate_m_s: f64,
    pub acceleration_m_s2: f64,
    pub length_nondim: f64,
    pub rate_nondim: f64,
    pub acceleration_nondim: f64,
}

#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct StabilityResponse {
    /// Every Re λ ≤ tolerance on the spectrum's mesh and, when converged
    /// (model.elements omitted), the length is below the safe side of the
    /// converged `critical_length_m`.
    pub stable: bool,
    /// Shortest length (m) at which a state with this rate and acceleration
    /// diverges (the roller-end effective tension is lost); converged: on
    /// the safe (low) side of its error. Null when shortening (unstable at
    /// any length), or when no such length exists up to 4× the static limit.
    pub critical_length_m: Option<f64>,
    /// Estimated discretisation error of `critical_length_m` (m).
    pub critical_length_error_m: Option<f64>,
    /// Whether the verdict and `critical_length_m` are converged.
    pub converged: bool,
    /// Largest Re λ (1/s).
    pub max_real_1_s: f64,
    /// Largest Re λ (1/t̄).
    pub max_real_nondim: f64,
    /// Tolerance on Re λ used for the verdict (1/s).
    pub tolerance_1_s: f64,
    /// The first `modes` eigenvalues with Im λ ≥ 0, by frequency.
    pub eigenvalues: Vec<EigenvalueOutput>,
    pub state: StateOutput,
    pub groups: Groups,
    pub elements: usize,
}

/// A QEP solve made to confirm a critical time.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct QepProbeOutput {
    pub time_s: f64,
    pub length_m: f64,
    /// Largest Re λ there (1/s).
    pub max_real_1_s: f64,
    pub stable: bool,
    pub expected_stable: bool,
}

#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct CriticalResponse {
    /// t* (s): first unstable instant; 0 if unstable at once, null if never.
    pub critical_time_s: Option<f64>,
    /// t* in units of L0/c.
    pub critical_time_nondim: Option<f64>,
    /// h* = L(t*) (m): the highest safe elevation; null if never unstable.
    pub max_elevation_m: Option<f64>,
    /// Continuum estimate of h* (m): (F/ρA − v²)/g for constant rate; the
    /// root-tension estimate for constant acceleration; null when shortening.
    pub closed_form_elevation_m: Option<f64>,
    /// Estimated discretisation error of `critical_time_s` (s); null when t*
    /// is null. Converged answers give t* on the safe (early) side of it.
    pub critical_time_error_s: Option<f64>,
    /// Estimated discretisation error of `max_elevation_m` (m); null when h*
    /// is null. Converged answers give h* on the safe (low) side of it.
    pub max_elevation_error_m: Option<f64>,
    /// Whether t* and h* are converged (model.elements omitted) rather than
    /// one fixed mesh's values.
    pub converged: bool,
    /// Observed order of convergence in the first element's size (null
    /// unless converged and measurable; linear elements give 1).
    pub convergence_order_nondim: Option<f64>,
    /// `immediate`, `during` or `never`.
    pub onset: String,
    /// Plain-language account of the answer.
    pub explanation: String,
    /// How t* was located.
    pub method: String,
    /// Whether every QEP probe agreed with the answer (true if none were made).
    pub confirmed_by_qep: bool,
    pub qep_probes: Vec<QepProbeOutput>,
    /// Tensions at t* (rate and acceleration terms included); null if never unstable.
    pub tension_at_onset: Option<crate::contract::tension::TensionOutput>,
    pub groups: Groups,
    pub elements: usize,
}

#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct SafeRateResponse {
    /// Largest safe constant rate (m/s); null when none is safe.
    pub max_rate_m_s: Option<f64>,
    /// The same as ṽ = v/c.
    pub max_rate_nondim: Option<f64>,
    /// Continuum estimate sqrt(F/ρA − g H) (m/s); null above the static limit.
    pub closed_form_rate_m_s: Option<f64>,
    /// Estimated discretisation error of `max_rate_m_s` (m/s). Converged
    /// answers give the rate on the safe (low) side of it: never above the
    /// continuum limit.
    pub max_rate_error_m_s: Option<f64>,
    /// Whether the rate is converged (model.elements omitted).
    pub converged: bool,
    /// Time to reach the target at the safe rate (s).
    pub time_to_target_s: Option<f64>,
    /// Why no rate is safe, when none is.
    pub reason: Option<String>,
    pub target_elevation_m: f64,
    pub groups: Groups,
    pub elements: usize,
}

/// One chart point.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct ChartPointOutput {
    /// Deployment rate (m/s).
    pub rate_m_s: f64,
    /// t* (s); 0 if unstable at once.
    pub critical_time_s: f64,
    /// h* (m).
    pub max_elevation_m: f64,
    /// (F/ρA − v²)/g (m), clipped at 0.
    pub closed_form_elevation_m: f64,
    /// Estimated discretisation error of `critical_time_s` (s).
    pub critical_time_error_s: f64,
    /// Estimated discretisation error of `max_elevation_m` (m).
    pub max_elevation_error_m: f64,
    /// Winch tension F − ρA g h* at the onset (N).
    pub winch_tension_at_onset_n: f64,
    /// Kinematic term ρA v² (N): the winch tension it must exceed.
    pub kinematic_tension_n: f64,
}

#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct ChartSeriesOutput {
    /// Net buoyancy of this series (N).
    pub net_buoyancy_n: f64,
    /// Wave speed sqrt(F/ρA) of this series (m/s): rates above it fail at once.
    pub wave_speed_m_s: f64,
    pub points: Vec<ChartPointOutput>,
}

#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct ChartResponse {
    pub series: Vec<ChartSeriesOutput>,
    /// Uniform elements, or (converged) those of the coarsest graded mesh
    /// (each point refines from it as far as its tolerance needs).
    pub elements: usize,
    /// Whether the points are converged (model.elements omitted); their
    /// t* and h* are then on the safe side of the error bound.
    pub converged: bool,
}
