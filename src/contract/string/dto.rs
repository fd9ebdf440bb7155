//! Request and response bodies (JSON, SI units; every field name ends in
//! its unit, non-dimensional values sit beside them with `_nondim`).
//! The same types serve the CLI, the HTTP API and the job queue.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

pub use crate::contract::error::{ErrorBody, ErrorDetail};
pub use crate::contract::system::{AerostatInput, CableInput, WinchInput, WindInput};

/// Which cable model, and its discretisation.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct ModelInput {
    /// Model kind.
    #[serde(default)]
    pub kind: ModelKind,
    /// Number of uniform finite elements (2..=2000). Omitted: every
    /// stability answer (t*, h*, safe rate, chart points) is converged to
    /// `numerics.relative_tolerance` on meshes graded toward the roller and
    /// given on the safe side of its error bound; the spectrum of
    /// `/stability` and transient runs use 50 elements. Given: that mesh's
    /// values, with their estimated error.
    #[serde(default)]
    #[schema(example = 50, minimum = 2, maximum = 2000)]
    pub elements: Option<usize>,
}

impl Default for ModelInput {
    fn default() -> Self {
        Self {
            kind: ModelKind::LinearString,
            elements: None,
        }
    }
}

/// Elements of the uniform mesh used for spectra and transient runs when
/// `model.elements` is omitted.
pub const DEFAULT_ELEMENTS: usize = 50;

impl ModelInput {
    /// The uniform mesh size: the one asked for, or [`DEFAULT_ELEMENTS`].
    pub fn mesh_elements(&self) -> usize {
        self.elements.unwrap_or(DEFAULT_ELEMENTS)
    }
}

/// Accuracy of converged answers.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
pub struct NumericsInput {
    /// Relative tolerance of converged answers (t*, h*, safe rate) when
    /// `model.elements` is omitted.
    #[serde(default = "default_relative_tolerance")]
    #[schema(example = 1e-4, minimum = 1e-8, maximum = 1e-2)]
    pub relative_tolerance: f64,
}

impl Default for NumericsInput {
    fn default() -> Self {
        Self {
            relative_tolerance: default_relative_tolerance(),
        }
    }
}

fn default_relative_tolerance() -> f64 {
    crate::numerics::string::converged::DEFAULT_RELATIVE_TOLERANCE
}

#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, ToSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum ModelKind {
    /// Linear string with end mass (thesis ch. 2–4).
    #[default]
    LinearString,
}

/// The keys of [`SystemInput`]: a flattened request gives these to the
/// system part and the rest to its parameters.
pub const SYSTEM_KEYS: &[&str] = &[
    "cable",
    "aerostat",
    "initial_length_m",
    "gravity_m_s2",
    "numerics",
    "model",
    "wind",
    "winch",
    "required_safety_factor_nondim",
    "lift_reserve_nondim",
];

/// The physical system and its model: common to every request.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct SystemInput {
    pub cable: CableInput,
    pub aerostat: AerostatInput,
    /// Initial cable length L0 (m), the length scale.
    #[serde(default = "default_initial_length")]
    #[schema(example = 1.0, minimum = 0.001, maximum = 10000.0)]
    pub initial_length_m: f64,
    /// Gravitational acceleration (m/s²).
    #[serde(default = "default_gravity")]
    #[schema(example = 9.81, minimum = 0.01, maximum = 100.0)]
    pub gravity_m_s2: f64,
    #[serde(default)]
    pub model: ModelInput,
    /// Accuracy of converged answers.
    #[serde(default)]
    pub numerics: NumericsInput,
    /// The air: accepted with the whole system, but this analysis is in calm
    /// air, so a non-zero wind is refused (naming `wind.flow`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wind: Option<WindInput>,
    /// The winch limits (used by the plan; checked here).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub winch: Option<WinchInput>,
    /// Safety factor required on the breaking strength (default 5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 5.0, minimum = 1.0, maximum = 100.0)]
    pub required_safety_factor_nondim: Option<f64>,
    /// Lift reserve (used by the plan; checked here).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 0.05, minimum = 0.0, maximum = 0.9)]
    pub lift_reserve_nondim: Option<f64>,
}

fn default_initial_length() -> f64 {
    1.0
}

fn default_gravity() -> f64 {
    9.81
}

/// A deployment profile L(t). Positive rates lengthen, negative shorten.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(tag = "kind", rename_all = "snake_case")]
#[serde(deny_unknown_fields)]
pub enum ProfileInput {
    /// L = L0 + v t.
    ConstantRate {
        /// Winch rate v (m/s); negative retrieves.
        #[schema(example = 10.0, minimum = -1000.0, maximum = 1000.0)]
        rate_m_s: f64,
        /// Length at which the winch stops (m); none: never stops.
        #[serde(default)]
        #[schema(minimum = 0.001, maximum = 1e5)]
        target_length_m: Option<f64>,
    },
    /// From rest: L = L0 + a t²/2.
    ConstantAcceleration {
        /// Winch acceleration a (m/s²); negative retrieves.
        #[schema(example = 0.5, minimum = -1000.0, maximum = 1000.0)]
        acceleration_m_s2: f64,
        /// Length at which the winch stops (m); none: never stops.
        #[serde(default)]
        #[schema(minimum = 0.001, maximum = 1e5)]
        target_length_m: Option<f64>,
    },
    /// Rate ramps linearly from 0 to the cruise rate, holds, and ramps back
    /// to 0, arriving at rest at the target length (thesis Figs 4.8–4.9).
    Trapezoidal {
        /// Cruise rate (m/s); negative retrieves.
        #[schema(example = 10.0, minimum = -1000.0, maximum = 1000.0)]
        cruise_rate_m_s: f64,
        /// Ramp-up time (s), > 0: short is sharp, long is gradual.
        #[schema(example = 5.0, minimum = 1e-6, maximum = 1e7)]
        ramp_up_s: f64,
        /// Ramp-down time (s), > 0.
        #[schema(example = 5.0, minimum = 1e-6, maximum = 1e7)]
        ramp_down_s: f64,
        /// Length at which the winch comes to rest (m).
        #[schema(example = 1100.0, minimum = 0.001, maximum = 1e5)]
        target_length_m: f64,
    },
    /// Rate interpolated linearly in a table of (time, rate), first time 0;
    /// the last rate is held after the table.
    PiecewiseLinearRate {
        /// The table, times strictly increasing (at most 10000 points).
        points: Vec<RatePointInput>,
        /// Length at which the winch stops (m); none: the table decides.
        #[serde(default)]
        #[schema(minimum = 0.001, maximum = 1e5)]
        target_length_m: Option<f64>,
    },
}

/// One point of a rate table.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct RatePointInput {
    /// Time (s).
    #[schema(example = 0.0, minimum = 0.0, maximum = 1e7)]
    pub time_s: f64,
    /// Winch rate at that time (m/s).
    #[schema(example = 10.0, minimum = -1000.0, maximum = 1000.0)]
    pub rate_m_s: f64,
}

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

/// Scales and non-dimensional groups of the system.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct Groups {
    /// Wave speed sqrt(F/ρA) (m/s).
    pub wave_speed_m_s: f64,
    /// Time scale L0/c (s).
    pub time_scale_s: f64,
    /// F̃ = F/(ρA g L0).
    pub buoyancy_ratio_nondim: f64,
    /// m̃ = m/(ρA L0).
    pub mass_ratio_nondim: f64,
    /// F/(ρA g) (m): no rate is safe above it.
    pub static_lift_limit_m: f64,
}

/// One eigenvalue λ of λ²M + λC + K = 0.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct EigenvalueOutput {
    /// Re λ (1/s): growth rate if positive.
    pub re_1_s: f64,
    /// Im λ (rad/s): circular frequency.
    pub im_1_s: f64,
    /// Re λ in units of 1/t̄.
    pub re_nondim: f64,
    /// Im λ in units of 1/t̄.
    pub im_nondim: f64,
    /// Im λ / 2π (Hz).
    pub frequency_hz: f64,
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

/// A request made of the common system part and its own parameters;
/// the two are parsed separately so that every error names its field
/// (serde loses the path inside `#[serde(flatten)]`).
pub trait SystemRequest: Sized {
    type Params: serde::de::DeserializeOwned;
    fn from_parts(system: SystemInput, params: Self::Params) -> Self;
    /// The plausible-magnitude checks of both parts (field and range named).
    fn check_ranges(&self) -> Result<(), crate::numerics::params::InvalidInput> {
        Ok(())
    }
}
