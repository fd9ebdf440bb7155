//! Request and response bodies of `POST /api/v1/dynamics` (SPEC §11): the
//! one system of §9 (cable, aerostat, wind with its `time_history`,
//! winch …), the unstretched length (fixed or a profile), the duration and
//! the numerics. SI units; every bound in the schema is the bound the
//! validation applies ([`super::validate`]).

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::contract::equilibrium::dto::{AerostatInput, CableInput, WindFlowInput};
use crate::contract::system::WinchInput;
use crate::contract::system::input::ProfileInput;

pub(crate) fn default_gravity() -> f64 {
    9.81
}
fn default_air_density() -> f64 {
    1.225
}
fn default_spectral_radius() -> f64 {
    0.8
}
fn default_sample_count() -> usize {
    601
}
/// Shapes kept when neither `shape_count` nor `shape_times_s` is given.
pub const DEFAULT_SHAPE_COUNT: usize = 31;

/// The turbulence spectrum.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, ToSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum TurbulenceModelInput {
    /// `S(f) = 4σ²(L_u/U)/(1 + 70.8 n²)^(5/6)`, `n = f L_u/U`.
    VonKarman,
    /// `S(f) = 4σ²(L_u/U)/(1 + 6 n)^(5/3)`.
    Kaimal,
}

/// A change of the wind in time, added to the steady `wind.flow`. The
/// discrete kinds are spatially uniform: the same change at every height.
/// A "speed" is the new wind at the flow's reference height (`uniform`:
/// everywhere; `power_law`, `log_law`: their `reference_height_m`;
/// `tabulated`: the aerostat's starting altitude).
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum TimeHistoryInput {
    /// The wind jumps to `speed_m_s` at `time_s`.
    Step {
        /// When the step happens (s).
        #[schema(example = 10.0, minimum = 0.0, maximum = 1000000.0)]
        time_s: f64,
        /// The new speed (m/s).
        #[schema(example = 15.0, minimum = -150.0, maximum = 150.0)]
        speed_m_s: f64,
    },
    /// The wind rises (or falls) linearly to `speed_m_s` over `duration_s` from `start_time_s`.
    Ramp {
        #[schema(example = 10.0, minimum = 0.0, maximum = 1000000.0)]
        start_time_s: f64,
        #[schema(example = 5.0, exclusive_minimum = 0.0, maximum = 1000000.0)]
        duration_s: f64,
        /// The speed reached (m/s).
        #[schema(example = 15.0, minimum = -150.0, maximum = 150.0)]
        speed_m_s: f64,
    },
    /// A `1 − cos` gust: `ΔU = (A/2)(1 − cos 2π(t − t₀)/T)` on `[t₀, t₀ + T]`,
    /// peak `A` at `t₀ + T/2`, zero before and after.
    OneMinusCosine {
        #[schema(example = 10.0, minimum = 0.0, maximum = 1000000.0)]
        start_time_s: f64,
        #[schema(example = 8.0, exclusive_minimum = 0.0, maximum = 1000000.0)]
        duration_s: f64,
        /// Peak change A (m/s).
        #[schema(example = 6.0, minimum = -100.0, maximum = 100.0)]
        amplitude_m_s: f64,
    },
    /// `ΔU = A sin(2π t/T)`.
    Sinusoid {
        #[schema(example = 2.0, minimum = -100.0, maximum = 100.0)]
        amplitude_m_s: f64,
        /// Period T (s), at least four time steps.
        #[schema(example = 30.0, exclusive_minimum = 0.0, maximum = 1000000.0)]
        period_s: f64,
    },
    /// Seeded turbulence of the longitudinal component: a field, not a
    /// uniform change. Spectrum of intensity `I = σ_u/U` and length scale
    /// `L_u` at every height, Davenport's vertical coherence, frozen and
    /// carried downwind at the mean speed at the aerostat. The same seed
    /// gives the same field on any machine and worker count.
    Turbulence {
        model: TurbulenceModelInput,
        /// `I = σ_u/U`.
        #[schema(example = 0.15, minimum = 0.0, maximum = 1.0)]
        turbulence_intensity_nondim: f64,
        /// `L_u` (m), e.g. 340 m (von Kármán, IEC 61400-1 at heights above 60 m).
        #[schema(example = 340.0, exclusive_minimum = 0.0, maximum = 100000.0)]
        length_scale_m: f64,
        #[serde(default)]
        #[schema(example = 7, minimum = 0, maximum = 9007199254740991_u64)]
        seed: u64,
    },
}

/// The air of a dynamic run: the steady flow (where the run starts at
/// rest, in its static equilibrium) and how the wind changes in time.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct DynamicsWindInput {
    pub flow: WindFlowInput,
    /// Air density (kg/m³), default 1.225 (ISA sea level).
    #[serde(default = "default_air_density")]
    #[schema(example = 1.225, exclusive_minimum = 0.0, maximum = 5.0)]
    pub air_density_kg_m3: f64,
    /// The change in time; absent: the steady flow only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_history: Option<TimeHistoryInput>,
}

/// Discretisation and integrator. Leave `segments` and `time_step_s`
/// out (the default) for converged figures: the run is repeated at halved
/// steps until its figures (`converged` in the answer) change by at most
/// `tolerance_nondim`, or refused naming `numerics` when the finest
/// default step does not get there. Give them to run that discretisation
/// as it is: the answer still carries the error estimate from the run at
/// twice the step and half the segments, and says the tolerance was not
/// enforced.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct DynamicsNumericsInput {
    /// Equal segments of the tether (lumped masses at their ends); default 50.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 50, minimum = 2, maximum = 1000)]
    pub segments: Option<usize>,
    /// Time step (s); the generalized-α step is unconditionally stable, so
    /// it is set by the accuracy wanted. Default: chosen (0.2, 0.1 or
    /// 0.05 s, at most a quarter of the shortest gust or sinusoid period)
    /// so that the figures meet `tolerance_nondim`; for a damped tether
    /// (`internal_damping_n_s` > 0) whose winch changes its rate or
    /// acceleration, halved further (at most 6 times) down to a 32nd of
    /// the first axial period `4L/c` at the shortest length.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 0.05, minimum = 0.0001, maximum = 10.0)]
    pub time_step_s: Option<f64>,
    /// Spectral radius ρ∞ at infinite frequency: 1 keeps every mode
    /// (trapezoidal rule), smaller damps the unresolved axial waves.
    #[serde(default = "default_spectral_radius")]
    #[schema(example = 0.8, minimum = 0.0, maximum = 1.0)]
    pub spectral_radius_nondim: f64,
    /// Relative tolerance of the converged figures (of their scale: the
    /// largest tension figure for tensions, the altitude itself), default
    /// 0.01; enforced only when `segments` and `time_step_s` are left out.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 0.01, minimum = 0.0001, maximum = 0.1)]
    pub tolerance_nondim: Option<f64>,
}

impl Default for DynamicsNumericsInput {
    fn default() -> Self {
        Self {
            segments: None,
            time_step_s: None,
            spectral_radius_nondim: default_spectral_radius(),
            tolerance_nondim: None,
        }
    }
}

/// `POST /api/v1/dynamics`: the tether in time through a gust or
/// turbulence, from rest in the static equilibrium of `wind.flow`.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({
    "cable": {"preset": "dyneema", "diameter_m": 0.006},
    "aerostat": {"net_buoyancy_n": 2000.0, "mass_kg": 100.0, "drag_coefficient_nondim": 0.3,
                 "reference_area_m2": 20.0, "added_mass_coefficient_nondim": 0.5},
    "wind": {"flow": {"kind": "uniform", "speed_m_s": 8.0}, "air_density_kg_m3": 1.225,
             "time_history": {"kind": "one_minus_cosine", "start_time_s": 10.0, "duration_s": 8.0,
                              "amplitude_m_s": 6.0}},
    "tether_length_m": 1000.0,
    "duration_s": 60.0,
    "sample_count": 601,
    "shape_count": 31,
    "numerics": {"segments": 50, "time_step_s": 0.05, "spectral_radius_nondim": 0.8}
}))]
pub struct DynamicsRequest {
    pub cable: CableInput,
    pub aerostat: AerostatInput,
    pub wind: DynamicsWindInput,
    /// A fixed unstretched length L (m); give this or `profile`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 1000.0, minimum = 1.0, maximum = 20000.0)]
    pub tether_length_m: Option<f64>,
    /// The length following a deployment profile from `initial_length_m`
    /// (a plan's schedule: its `(time_s, rate_m_s)` as a
    /// `piecewise_linear_rate`); give this or `tether_length_m`. The
    /// length must stay at least 1 m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub profile: Option<ProfileInput>,
    /// Length at t = 0 with a `profile` (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 100.0, minimum = 1.0, maximum = 10000.0)]
    pub initial_length_m: Option<f64>,
    /// Simulated time (s).
    #[schema(example = 60.0, exclusive_minimum = 0.0, maximum = 100000.0)]
    pub duration_s: f64,
    /// Samples kept, evenly spaced from 0 to `duration_s` (at most one per
    /// time step); peaks, minima and slack are checked at every step.
    #[serde(default = "default_sample_count")]
    #[schema(example = 601, minimum = 2, maximum = 200000)]
    pub sample_count: usize,
    /// Tether shapes kept, evenly spaced from 0 to `duration_s` (0: none;
    /// default 31); `shape_times_s` instead names the times (give one of
    /// the two, not both). Shapes × (segments + 1) nodes at most 200 000.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 31, default = 31, minimum = 0, maximum = 1000)]
    pub shape_count: Option<usize>,
    /// The times of the kept shapes (s), instead of `shape_count` (at most 1000).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape_times_s: Option<Vec<f64>>,
    /// Kelvin–Voigt internal damping of the tether `c` in `T = EA ε + c ε̇`
    /// (N s), default 0 (the integrator's ρ∞ damps the unresolved axial waves).
    #[serde(default)]
    #[schema(example = 0.0, minimum = 0.0, maximum = 1e12)]
    pub internal_damping_n_s: f64,
    /// Height of a fixed wind probe (m): every sample keeps the wind there
    /// (`probe_wind_m_s`), above the aerostat's starting station; default
    /// the aerostat's starting altitude.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 500.0, minimum = 0.0, maximum = 30000.0)]
    pub wind_probe_height_m: Option<f64>,
    /// Tangential (skin-friction) drag coefficient on π d, default 0.
    #[serde(default)]
    #[schema(example = 0.0, minimum = 0.0, maximum = 1.0)]
    pub tangential_drag_coefficient_nondim: f64,
    #[serde(default)]
    pub numerics: DynamicsNumericsInput,
    /// Gravitational acceleration (m/s²).
    #[serde(default = "default_gravity")]
    #[schema(example = 9.81, exclusive_minimum = 0.0, maximum = 100.0)]
    pub gravity_m_s2: f64,
    /// Safety factor required of the peak tension (breaking strength / peak), default 5.
    #[serde(default = "crate::contract::system::default_safety_factor")]
    #[schema(example = 5.0, minimum = 1.0, maximum = 100.0)]
    pub required_safety_factor_nondim: f64,
    /// The rest of the system (accepted and checked; the run has no use for them).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub winch: Option<WinchInput>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 0.05, minimum = 0.0, maximum = 0.9)]
    pub lift_reserve_nondim: Option<f64>,
}

/// One kept sample.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct DynamicsSampleOutput {
    pub time_s: f64,
    /// Tension at the winch `|τ(0)|` (N).
    pub winch_tension_n: f64,
    /// Tension at the aerostat `|τ(L)|` (N).
    pub top_tension_n: f64,
    /// Height of the aerostat above the winch (m).
    pub aerostat_altitude_m: f64,
    /// Downwind distance of the aerostat from the winch (m).
    pub aerostat_downwind_m: f64,
    /// Unstretched length (m).
    pub tether_length_m: f64,
    /// Wind speed at the aerostat (m/s).
    pub aerostat_wind_m_s: f64,
    /// Wind speed at the fixed probe point (`wind_probe_height_m`,
    /// `wind_probe_downwind_m` of the answer) (m/s): the field a fixed
    /// anemometer would record.
    pub probe_wind_m_s: f64,
}

/// One node of a kept shape.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct DynamicsShapeNodeOutput {
    /// Unstretched arc length from the winch (m).
    pub s_m: f64,
    /// Downwind distance from the winch (m).
    pub x_m: f64,
    /// Height above the winch (m).
    pub z_m: f64,
    /// Tension of the segment below the node (the winch tension at s = 0) (N).
    pub tension_n: f64,
}

/// The tether at one time.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct DynamicsShapeOutput {
    pub time_s: f64,
    /// From the winch (s = 0) to the aerostat.
    pub nodes: Vec<DynamicsShapeNodeOutput>,
}

/// An interval during which some segment carries no tension.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct SlackEventOutput {
    pub start_time_s: f64,
    /// Null: still slack at the end of the run.
    pub end_time_s: Option<f64>,
    /// Lowest slack point seen (unstretched arc length from the winch, m).
    pub lowest_s_m: f64,
}

/// The static equilibrium (SPEC §6) the dynamic answer is judged against,
/// at the same wind.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct QuasiStaticOutput {
    /// Winch tension at rest in the steady flow at t = 0 (N): the lumped
    /// tether's static equilibrium, where the run starts.
    pub start_winch_tension_n: f64,
    /// Aerostat altitude at t = 0 (m).
    pub start_aerostat_altitude_m: f64,
    /// The same from the continuum equilibrium of SPEC §6 (N): the lumped
    /// tether's differs from it by O(segments⁻²).
    pub continuum_start_winch_tension_n: f64,
    /// Largest and smallest change of the wind over the run (m/s): the
    /// time history's (turbulence: the fluctuation at the aerostat, over the samples).
    pub max_wind_change_m_s: f64,
    pub min_wind_change_m_s: f64,
    /// Static winch tension with the flow raised by `max_wind_change_m_s`,
    /// at the length of the dynamic peak's instant (N); null: no static
    /// equilibrium there.
    pub winch_tension_at_max_wind_n: Option<f64>,
    /// Largest static tension along the tether at the same wind (N).
    pub max_tension_at_max_wind_n: Option<f64>,
    /// Static aerostat altitude at the same wind (m): the blown-down height.
    pub aerostat_altitude_at_max_wind_m: Option<f64>,
    /// Static winch tension with the flow changed by `min_wind_change_m_s`,
    /// at the length of the dynamic minimum's instant (N).
    pub winch_tension_at_min_wind_n: Option<f64>,
    /// Whether the static equilibrium at the smallest wind is slack.
    pub slack_at_min_wind: Option<bool>,
}

/// How the run ended.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, ToSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum DynamicsOutcomeOutput {
    /// Ran to `duration_s`.
    Completed,
    /// The Newton iteration failed even on the smallest sub-step (`stopped_at_s`).
    NewtonFailed,
    /// The state became non-finite (`stopped_at_s`).
    Diverged,
    /// The aerostat went below the winch (`stopped_at_s`): the state left
    /// the physical (the model has no ground).
    AerostatBelowWinch,
    /// The tether and aerostat held more mechanical energy than they
    /// started with plus all the winch and the air could have put in, past
    /// the stated allowance (`stopped_at_s`; the numbers in
    /// `explanation`): the step made energy, so the state left the
    /// physical (try a smaller `numerics.time_step_s`).
    EnergyGained,
}

/// How the answer was computed.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct DynamicsNumericsOutput {
    pub segments: usize,
    /// The time step used (s): `duration_s` divided into equal steps of at most the one asked.
    pub time_step_s: f64,
    pub spectral_radius_nondim: f64,
    /// Accepted steps (halved steps count each half).
    pub steps: usize,
    pub newton_iterations: usize,
    /// Steps retried as two halves after a failed Newton iteration.
    pub halvings: usize,
    /// Axial stiffness EA used (N).
    pub axial_stiffness_n: f64,
    /// Aerostat inertia `m + C_a ρ V` (kg).
    pub aerostat_inertia_kg: f64,
    /// Largest nodal force left by the static start (N).
    pub start_residual_n: f64,
    /// `generalized_alpha` (Chung & Hulbert 1993), second order.
    pub method: String,
}

/// The answer of `POST /api/v1/dynamics`.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct DynamicsResponse {
    pub outcome: DynamicsOutcomeOutput,
    /// Time the run stopped at (s): `duration_s` when completed.
    pub stopped_at_s: f64,
    /// True when the run did not complete: every figure below (peaks,
    /// minima, lowest altitude) covers only `[0, stopped_at_s]`, is not a
    /// final figure, and no dynamic or safety factor is given.
    pub figures_partial: bool,
    pub samples: Vec<DynamicsSampleOutput>,
    pub shapes: Vec<DynamicsShapeOutput>,
    pub slack_events: Vec<SlackEventOutput>,
    /// Largest winch tension at any step and when (N, s).
    pub peak_winch_tension_n: f64,
    pub peak_winch_tension_time_s: f64,
    /// Smallest winch tension at any step and when (N, s).
    pub min_winch_tension_n: f64,
    pub min_winch_tension_time_s: f64,
    /// Largest tension anywhere along the tether and when (N, s).
    pub peak_tension_n: f64,
    pub peak_tension_time_s: f64,
    /// Lowest aerostat altitude at any step and when (m, s).
    pub min_aerostat_altitude_m: f64,
    /// The fixed point where `probe_wind_m_s` is read: height above the
    /// winch and distance downwind of it (m).
    pub wind_probe_height_m: f64,
    pub wind_probe_downwind_m: f64,
    pub quasi_static: QuasiStaticOutput,
    /// The four figures above with their error estimates and safe sides,
    /// and how the step and segments were chosen (SPEC §5).
    pub converged: DynamicsConvergedOutput,
    /// Peak winch tension (its safe value, `converged`) / static winch
    /// tension at the largest wind; null without it, or when the run did
    /// not complete (`figures_partial`).
    pub dynamic_factor_nondim: Option<f64>,
    /// Breaking strength / peak tension anywhere (its safe value,
    /// `converged.peak_tension_n.safe_value`); null without a breaking
    /// strength, or when the run did not complete.
    pub safety_factor_nondim: Option<f64>,
    pub required_safety_factor_nondim: f64,
    /// Whether the safety factor meets the required one; null without a breaking strength.
    pub meets_required_safety_factor: Option<bool>,
    /// Plain-language account of the run.
    pub explanation: String,
    pub numerics: DynamicsNumericsOutput,
}

/// One figure an operator acts on, with its discretisation error (SPEC §5);
/// its unit is the one its field's name ends in.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct EstimatedFigureOutput {
    /// The figure of the answer's run (the one whose samples are returned).
    pub value: f64,
    /// Estimated discretisation error (≥ 0): its change from the run at
    /// twice the step plus its change from the run at half the segments
    /// (a bound when the method converges at order ≥ 1 in the step and
    /// ≥ 1 in the segments).
    pub error_estimate: f64,
    /// `value + error_estimate` for a peak, `value − error_estimate` for a
    /// minimum: the side to act on.
    pub safe_value: f64,
    /// When it happened in the answer's run (s).
    pub time_s: f64,
}

/// The observed order of convergence in the time step of each figure,
/// `log₂(|q(4h) − q(2h)| / |q(2h) − q(h)|)` over the last three default
/// steps; null when fewer than three steps were run, when a change is at
/// roundoff, or when the changes did not decrease.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct ObservedOrdersOutput {
    pub peak_winch_tension_nondim: Option<f64>,
    pub min_winch_tension_nondim: Option<f64>,
    pub peak_tension_nondim: Option<f64>,
    pub min_aerostat_altitude_nondim: Option<f64>,
}

/// One run of the refinement, with its figures.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct RefinementOutput {
    /// Its time step (s).
    pub time_step_s: f64,
    pub segments: usize,
    /// Whether it ran to the end.
    pub completed: bool,
    /// Its figures (N, N, N, m).
    pub peak_winch_tension_n: f64,
    pub min_winch_tension_n: f64,
    pub peak_tension_n: f64,
    pub min_aerostat_altitude_m: f64,
}

/// The converged figures (issue 31 item 2): what an operator acts on,
/// each with its error estimate and safe side.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct DynamicsConvergedOutput {
    pub peak_winch_tension_n: EstimatedFigureOutput,
    pub min_winch_tension_n: EstimatedFigureOutput,
    /// Largest segment tension anywhere along the tether.
    pub peak_tension_n: EstimatedFigureOutput,
    pub min_aerostat_altitude_m: EstimatedFigureOutput,
    /// The relative tolerance (of the largest tension figure for the
    /// tensions, of the altitude for the altitude).
    pub tolerance_nondim: f64,
    /// True when the step was chosen to meet the tolerance (numerics
    /// `segments` and `time_step_s` left out); false when the request
    /// fixed them: the estimate is then given, the tolerance not enforced.
    pub tolerance_enforced: bool,
    /// Whether every figure's change from the coarser runs is within the tolerance.
    pub tolerance_met: bool,
    /// The answer's time step (s) and segments.
    pub time_step_s: f64,
    pub segments: usize,
    pub observed_orders: ObservedOrdersOutput,
    /// Every run made, the answer's included, in the order run.
    pub refinements: Vec<RefinementOutput>,
}
