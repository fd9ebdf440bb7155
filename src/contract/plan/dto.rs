//! Request and response bodies of `POST /api/v1/plan` (SPEC §7): SI
//! units, every field name ends in its unit.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::contract::system::input::ModelInput;
use crate::contract::system::output::Groups;
use crate::contract::system::{AerostatInput, CableInput};
use crate::contract::system::{WindInput, default_lift_reserve, default_safety_factor};

pub use crate::contract::system::WinchInput;

/// One point of a wind forecast (wind at the aerostat).
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct WindForecastPointInput {
    /// Time from now (s).
    #[schema(example = 600.0, minimum = 0.0, maximum = 1e9)]
    pub time_s: f64,
    /// Forecast wind speed (m/s).
    #[schema(example = 8.0, minimum = 0.0, maximum = 200.0)]
    pub wind_speed_m_s: f64,
    /// Forecast gust (m/s), at least the wind speed; absent: the wind speed
    /// times `wind.gust`'s factor when the plan has one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 12.0, minimum = 0.0, maximum = 200.0)]
    pub gust_m_s: Option<f64>,
}

/// Haul-down deadline: when must the retrieval start so the aerostat is
/// down before the wind exceeds the operating limit?
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct HaulDownInput {
    /// Wind speed against time, times strictly increasing (1..=10000 points);
    /// or leave it out and give `source`.
    #[serde(default)]
    pub forecast: Vec<WindForecastPointInput>,
    /// The forecast as it comes (issue 32: `open_meteo`, `metar`, `taf`,
    /// `csv`, as `POST /api/v1/windows` takes it), instead of `forecast`: each
    /// period's flow read at `target_elevation_m`, its gust by its gust ratio,
    /// times from its first period (an ensemble: its first member).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source: Option<crate::contract::windows::forecast::ForecastInput>,
    /// Largest wind in which the aerostat may stay aloft (m/s).
    #[schema(example = 12.0, exclusive_minimum = 0.0, maximum = 200.0)]
    pub max_operating_wind_m_s: f64,
    /// Largest gust in which the aerostat may stay aloft (m/s); the
    /// deadline is then the first forecast time at which the wind passes
    /// `max_operating_wind_m_s` or the gust passes this. Needs the forecast's
    /// gusts (`gust_m_s` on its points, or `wind.gust`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 18.0, exclusive_minimum = 0.0, maximum = 200.0)]
    pub max_gust_m_s: Option<f64>,
}

/// How the plan judges stability.
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, ToSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum PlanStabilityMethod {
    /// The string criterion: in calm air the closed form (1−r)F − ρA g L − ρA L̇² − (m + ρA L)L̈
    /// at the roller; in wind the smallest tension of the blown-down tether (as the envelope).
    #[default]
    String,
    /// The quasi-static geometrically exact tether: the largest stable payout rate of the local GE QEP
    /// about the (blown-down) equilibrium, tabulated over length; the schedule is checked by the GE QEP
    /// at its samples.
    QuasiStaticGe,
}

/// The stability criterion of the plan (default: the string criterion).
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct PlanStabilityInput {
    #[serde(default)]
    pub method: PlanStabilityMethod,
    /// `quasi_static_ge`: bending stiffness EI of the tether (N m²); default the tether's
    /// (`cable.bending_stiffness_n_m2`, else the full-slip bound of its preset or of a 12-strand braid of
    /// its diameter; in calm air without a diameter, of the diameter of a 1000 kg/m³ fibre of its ρA).
    #[serde(default)]
    #[schema(example = 1000.0, minimum = 1e-6, maximum = 1e12)]
    pub bending_stiffness_n_m2: Option<f64>,
    /// `quasi_static_ge`: finite elements of one GE mesh for the critical-rate table and the divergence
    /// check. Omitted (the default): the table's maximum safe length and critical rates are converged
    /// (nested meshes from 20 elements, Richardson, to `relative_tolerance_nondim`) and taken on the safe
    /// side, with their error estimates.
    #[serde(default)]
    #[schema(example = 40, minimum = 4, maximum = 2000)]
    pub elements: Option<usize>,
    /// `quasi_static_ge`: relative tolerance of the converged table (default 1e-3); only without `elements`.
    #[serde(default)]
    #[schema(example = 0.001, minimum = 1e-6, maximum = 0.05)]
    pub relative_tolerance_nondim: Option<f64>,
    /// `quasi_static_ge`: finite elements of the QEP (flutter) check of the schedule's samples.
    #[serde(default = "default_ge_check_elements")]
    #[schema(example = 16, minimum = 4, maximum = 100)]
    pub check_elements: usize,
    /// `quasi_static_ge`: lengths of the critical-rate table (the last one is the GE maximum safe length).
    #[serde(default = "default_table_samples")]
    #[schema(example = 12, minimum = 3, maximum = 400)]
    pub table_samples: usize,
    /// `quasi_static_ge`: schedule samples checked by the local GE QEP (evenly spaced plus every phase boundary).
    #[serde(default = "default_check_samples")]
    #[schema(example = 41, minimum = 2, maximum = 2000)]
    pub check_samples: usize,
}

fn default_ge_check_elements() -> usize {
    16
}
fn default_table_samples() -> usize {
    12
}
fn default_check_samples() -> usize {
    41
}

/// `POST /api/v1/plan`: the fastest safe deployment (or retrieval) schedule.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({
    "cable": {"mass_per_length_kg_m": 0.078, "diameter_m": 0.006, "breaking_strength_n": 20000.0},
    "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0, "drag_coefficient_nondim": 0.3,
                 "reference_area_m2": 20.0},
    "initial_length_m": 1.0,
    "gravity_m_s2": 9.81,
    "target_elevation_m": 1200.0,
    "winch": {"max_rate_m_s": 40.0, "max_acceleration_m_s2": 2.0},
    "lift_reserve_nondim": 0.05,
    "required_safety_factor_nondim": 5.0,
    "haul_down": {
        "forecast": [{"time_s": 0.0, "wind_speed_m_s": 5.0}, {"time_s": 3600.0, "wind_speed_m_s": 15.0}],
        "max_operating_wind_m_s": 12.0
    }
}))]
pub struct PlanRequest {
    pub cable: CableInput,
    pub aerostat: AerostatInput,
    /// Cable length now (m): where the plan starts.
    #[serde(default = "default_initial_length")]
    #[schema(example = 1.0, minimum = 0.001, maximum = 10000.0)]
    pub initial_length_m: f64,
    /// Gravitational acceleration (m/s²).
    #[serde(default = "default_gravity")]
    #[schema(example = 9.81, minimum = 0.01, maximum = 100.0)]
    pub gravity_m_s2: f64,
    /// Discretisation of the transient check (the plan itself uses the
    /// converged continuum criterion).
    #[serde(default)]
    pub model: ModelInput,
    /// Altitude of the aerostat to end at (m): in calm air the cable length, in
    /// wind the altitude in that wind (the answer's `wind.target_length_m` is the
    /// tether it needs); below `initial_length_m` plans a retrieval.
    #[schema(example = 1200.0, minimum = 0.001, maximum = 1e6)]
    pub target_elevation_m: f64,
    pub winch: WinchInput,
    /// Stay stable with the net buoyancy reduced by this fraction
    /// (helium loss, temperature, downdraft).
    #[serde(default = "default_lift_reserve")]
    #[schema(example = 0.05, minimum = 0.0, maximum = 0.9)]
    pub lift_reserve_nondim: f64,
    /// With `cable.breaking_strength_n` (or a cable preset): the plan keeps the
    /// largest tension within breaking strength / this factor (default 5,
    /// fibrous tethers, FAA 14 CFR 31.25 practice). Without a breaking
    /// strength the tension is NOT checked (`tension_checked: false`).
    #[serde(default = "default_safety_factor")]
    #[schema(example = 5.0, minimum = 1.0, maximum = 100.0)]
    pub required_safety_factor_nondim: f64,
    /// Retrieval only: the largest growth of an oscillation's tip amplitude
    /// over the retrieval (the winch is slowed to meet it when it can).
    #[serde(default)]
    #[schema(exclusive_minimum = 0.0, maximum = 1e6)]
    pub max_amplification_nondim: Option<f64>,
    /// Haul-down deadline under a wind forecast.
    #[serde(default)]
    pub haul_down: Option<HaulDownInput>,
    /// Steady wind during the plan; absent: calm air. In wind the plan needs
    /// `cable.diameter_m` and the aerostat's drag data.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wind: Option<WindInput>,
    /// Lowest altitude (m) the aerostat may be blown down to where the plan
    /// leaves it (its end): terrain or an airspace floor; with `wind.gust`
    /// the altitude in the gust must clear it. Leave it out for a haul-down
    /// to the ground. Absent: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 150.0, minimum = 0.0, maximum = 1e6)]
    pub min_altitude_m: Option<f64>,
    /// Stability criterion; absent: the string criterion.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stability: Option<PlanStabilityInput>,
    /// Tip deflection of the first-mode disturbance of the transient check (m).
    #[serde(default = "default_disturbance")]
    #[schema(example = 0.1, exclusive_minimum = 0.0, maximum = 1e3)]
    pub disturbance_tip_deflection_m: f64,
    /// Evenly spaced schedule samples (phase boundaries are added).
    #[serde(default = "default_samples")]
    #[schema(example = 201, minimum = 2, maximum = 10000)]
    pub samples: usize,
}

fn default_initial_length() -> f64 {
    1.0
}
fn default_gravity() -> f64 {
    9.81
}
fn default_disturbance() -> f64 {
    0.1
}
fn default_samples() -> usize {
    201
}

/// One instant of the schedule.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct PlanSampleOutput {
    pub time_s: f64,
    /// Cable length L (m).
    pub length_m: f64,
    /// Altitude of the aerostat above the winch (m): L in calm air, lower in wind.
    pub altitude_m: f64,
    /// Winch rate L̇ (m/s); negative hauls in.
    pub rate_m_s: f64,
    /// Winch acceleration L̈ (m/s²) from this instant on.
    pub acceleration_m_s2: f64,
    /// Axial tension at the winch, F − mL̈ − ρA(g + L̈)L (N).
    pub winch_tension_n: f64,
    /// Largest axial tension along the cable (N): at the aerostat, F − mL̈.
    pub max_tension_n: f64,
    /// Largest stable rate here at this acceleration with the lift reserve (m/s).
    pub rate_ceiling_m_s: f64,
    /// rate_ceiling_m_s − |rate_m_s| (m/s): ≥ 0 is stable.
    pub stability_margin_m_s: f64,
    /// Effective tension at the roller with the reserve (N):
    /// (1−r)F − mL̈ − ρA(g + L̈)L − ρA L̇² ≥ 0 is stable.
    pub effective_tension_margin_n: f64,
    /// With `wind.gust`: the altitude in the gust (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gust_altitude_m: Option<f64>,
    /// With `wind.gust`: the winch tension in the gust, with the acceleration (N).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gust_winch_tension_n: Option<f64>,
    /// With `wind.gust`: the largest tension in the gust, with the acceleration (N).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gust_max_tension_n: Option<f64>,
}

/// A stretch of the schedule under one limit: a line of the operator's table.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct PlanPhaseOutput {
    pub start_time_s: f64,
    pub end_time_s: f64,
    pub start_length_m: f64,
    pub end_length_m: f64,
    pub start_rate_m_s: f64,
    pub end_rate_m_s: f64,
    /// Mean acceleration over the phase (m/s²).
    pub mean_acceleration_m_s2: f64,
    /// `winch_acceleration`, `winch_rate`, `stability`, `tension` or `winch_braking`.
    pub limit: String,
    /// What the winch operator does.
    pub instruction: String,
}

/// The best constant-rate plan with the same limits.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct ConstantRateOutput {
    /// Cruise rate, ramps at the acceleration limit (m/s).
    pub rate_m_s: f64,
    pub duration_s: f64,
    /// duration_s − the plan's duration (s).
    pub time_saved_s: f64,
    /// time_saved_s / duration_s.
    pub time_saved_fraction_nondim: f64,
}

/// The SPEC §7 orientation bound.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct PlanBoundOutput {
    /// Minimum time with the static ceiling v ≤ √((1−r)F/ρA − gL) and the winch limits (s).
    pub duration_s: f64,
    /// plan duration / bound − 1.
    pub plan_excess_fraction_nondim: f64,
    /// Why the plan differs from the bound.
    pub explanation: String,
}

/// The FE transient run of the schedule.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct TransientCheckOutput {
    pub elements: usize,
    pub time_step_s: f64,
    pub steps: usize,
    /// The schedule (s).
    pub run_duration_s: f64,
    /// First-mode disturbance at the start (m).
    pub initial_tip_deflection_m: f64,
    pub peak_tip_deflection_m: f64,
    /// First-mode tip amplitude at the end, at rest (m): projection of the final state on the rest mode.
    pub final_tip_amplitude_m: f64,
    /// final / initial.
    pub amplification_nondim: f64,
    /// `completed`, `diverged`, `length_collapsed` or `cancelled`.
    pub outcome: String,
}

/// Oscillation growth (both directions) and, retrieving, the tension rise.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct OscillationOutput {
    /// WKB tip-amplitude ratio end/start, [ψ(2m̃+l)]^(-1/2); null beyond the one-mode model's limit.
    pub wkb_amplification_nondim: Option<f64>,
    /// The same WKB invariant with the FE string's own first rest mode in place of sin(πζ/2): A ∝ (ω φᵀMφ)^(-1/2).
    pub wkb_fe_mode_amplification_nondim: Option<f64>,
    /// WKB mode-energy ratio end/start (ψ₁/ψ₀).
    pub wkb_energy_amplification_nondim: Option<f64>,
    /// From the transient run.
    pub transient_amplification_nondim: Option<f64>,
    /// The limit asked for, if any.
    pub max_amplification_nondim: Option<f64>,
    /// Whether the winch was slowed below its rate limit to meet it.
    pub slowed_for_amplification: bool,
    /// Rate limit the plan used (m/s).
    pub rate_limit_used_m_s: f64,
}

/// Retrieval only.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct RetrievalOutput {
    /// Largest winch-tension rise from hauling in, −(m + ρA L) L̈ (N).
    pub tension_rise_n: f64,
    /// Largest winch tension during the retrieval (N).
    pub peak_winch_tension_n: f64,
    /// Winch tension at rest at the start (N).
    pub initial_winch_tension_n: f64,
    /// Why a retrieval has no stability verdict.
    pub note: String,
}

/// Haul-down deadline.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct HaulDownOutput {
    /// First time the forecast wind exceeds the limit (s); null: never within the forecast.
    pub wind_exceeds_limit_at_s: Option<f64>,
    /// Fastest safe haul-down from the operating altitude (s).
    pub retrieval_duration_s: f64,
    /// Operating altitude the haul-down starts from (m).
    pub from_length_m: f64,
    /// Length it ends at (m).
    pub to_length_m: f64,
    /// Latest start of the haul-down (s from now); null without an exceedance.
    pub latest_start_s: Option<f64>,
    pub go: bool,
    pub reason: String,
    /// Which series passed its limit first: `mean` (the wind) or `gust`; null: neither.
    pub exceeded_by: Option<String>,
    /// With `max_gust_m_s`: the first time the forecast gust exceeds it (s); null: never.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gust_exceeds_limit_at_s: Option<f64>,
}

/// Limits and margins of the plan.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct PlanLimitsOutput {
    /// (1 − r)F (N).
    pub reserve_buoyancy_n: f64,
    /// Static lift limit with the reserve and the margin (m).
    pub lift_limit_m: f64,
    /// Breaking strength / required safety factor (N); null without a breaking strength.
    pub allowable_tension_n: Option<f64>,
    /// Effective-tension margin kept at every instant, ε(1 − r)F (N).
    pub stability_margin_n: f64,
    /// Smallest stability margin over the samples (m/s).
    pub min_stability_margin_m_s: Option<f64>,
    /// Smallest effective tension over the samples (N).
    pub min_effective_tension_margin_n: Option<f64>,
    /// Largest tension over the schedule (N); when infeasible, at the target (or the reachable limit) at rest.
    pub peak_tension_n: Option<f64>,
    /// Breaking strength / peak tension; null without a breaking strength.
    pub min_safety_factor_nondim: Option<f64>,
    /// With `wind.gust`: the largest tension in the gust over the schedule (N).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gust_peak_tension_n: Option<f64>,
    /// With `wind.gust` and a breaking strength: breaking strength / gust peak tension.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gust_min_safety_factor_nondim: Option<f64>,
    /// The floor asked for (m), if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_altitude_m: Option<f64>,
}

/// The plan in wind.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct PlanWindOutput {
    /// Tether length that flies the aerostat at `target_elevation_m` in this wind (m); null when unreachable.
    pub target_length_m: Option<f64>,
    /// Angle of the winch–aerostat line from the vertical at the target (deg), full buoyancy; null when unreachable.
    pub blowdown_angle_deg: Option<f64>,
    /// Downwind distance of the aerostat from the winch at the target (m); null when unreachable.
    pub target_downwind_m: Option<f64>,
    /// Static lift limit in this wind with the reserve (m of tether).
    pub lift_limit_m: f64,
    /// Altitude at the lift limit with full buoyancy (m): the highest reachable.
    pub reachable_altitude_m: f64,
    /// The stability criterion applied to the equilibrium.
    pub stability_criterion: String,
    /// Winch tension at the target at rest, full buoyancy (N); null when unreachable.
    pub target_winch_tension_n: Option<f64>,
    /// Largest tension at the target at rest (N); null when unreachable.
    pub target_max_tension_n: Option<f64>,
    /// With `wind.gust`: the same figures in the gust, beside these.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gust: Option<PlanGustOutput>,
}

/// The plan's figures in the gust (SPEC §10): the static equilibrium at the
/// gust speed at the same tether lengths.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct PlanGustOutput {
    /// Gust over mean at every height.
    pub gust_factor_nondim: f64,
    /// Height the gust speed refers to (m).
    pub reference_height_m: f64,
    /// Gust speed there (m/s).
    pub reference_speed_m_s: f64,
    /// Altitude of the aerostat at the target length in the gust (m): the lowest it is blown down to.
    pub target_altitude_m: Option<f64>,
    /// Its downwind distance (m).
    pub target_downwind_m: Option<f64>,
    /// Angle of the winch–aerostat line from the vertical in the gust (deg).
    pub blowdown_angle_deg: Option<f64>,
    /// Winch tension at the target at rest in the gust (N), times
    /// `dynamic_tension_factor_nondim`.
    pub target_winch_tension_n: Option<f64>,
    /// Largest tension at the target at rest in the gust (N), times
    /// `dynamic_tension_factor_nondim`: the tension the rating is judged on.
    pub target_max_tension_n: Option<f64>,
    /// The static equilibrium's largest tension at the target in the gust
    /// (N), before the factor.
    pub static_target_max_tension_n: Option<f64>,
    /// Breaking strength / `target_max_tension_n`; null without a breaking strength.
    pub target_safety_factor_nondim: Option<f64>,
    /// Factor on every static gust tension of the plan (here, the schedule's
    /// `gust_*_tension_n` and the limits): with a turbulence intensity the
    /// 99th percentile of the hourly largest winch tension in the
    /// time-domain dynamics over the static check, 1.363
    /// (`docs/gust_check.md`); 1 for a gust given as a speed or `I = 0`.
    pub dynamic_tension_factor_nondim: f64,
    /// Where the factor comes from and whether this wind lies within its measurement.
    pub dynamic_tension_note: String,
    /// Altitude in the gust at the lift limit (m).
    pub reachable_altitude_m: f64,
}

/// The jerk limit.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct JerkOutput {
    /// The limit asked for (m/s³).
    pub max_jerk_m_s3: f64,
    /// Largest |d L̈/dt| of the schedule (m/s³).
    pub peak_jerk_m_s3: f64,
    /// Width of the velocity average that made the S-curve (s): the time it adds.
    pub averaging_window_s: f64,
}

/// One length of the GE critical-rate table.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct PlanGeTableRowOutput {
    pub length_m: f64,
    /// Largest stable constant payout rate of the local GE QEP (m/s; stable end of the search bracket).
    pub critical_rate_m_s: f64,
    /// Every rate up to the search cap was stable (the rate is the cap).
    pub capped: bool,
    /// Not even the slowest rate was stable.
    pub unstable: bool,
    /// Converged table only: the estimated discretisation error of the critical rate (m/s); the rate
    /// is the safe side (best estimate minus this).
    pub critical_rate_error_m_s: Option<f64>,
    /// The pass's rate ceiling at rest at this length, paying out: the largest L̇ with
    /// ρA L̇² + δ(L̇) ≤ S − ε(1−r)F, δ the bound on the aerostat's ascent drag (m/s).
    pub plan_rate_ceiling_m_s: f64,
    /// The string criterion's critical rate at this length (m/s), the closed form beside the GE
    /// one: √(T_min/ρA) of the static tether with the reserve buoyancy in the mean wind (calm air:
    /// √(((1 − r)F − ρA g L)/ρA)). A reference, not a bound: in wind the GE spectrum may flutter
    /// first. `null` where the static tether is slack.
    pub string_critical_rate_m_s: Option<f64>,
}

/// The check of the schedule by the local GE QEP at its samples.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct PlanGeCheckOutput {
    pub checked_samples: usize,
    /// Samples found unstable (hauling in: divergent).
    pub unstable_samples: usize,
    /// Largest max Re λ over the checked (payout) samples (1/s): ≤ its roundoff tolerance is stable.
    pub worst_max_real_1_s: Option<f64>,
    /// Its roundoff tolerance (1/s).
    pub worst_tolerance_1_s: Option<f64>,
    pub worst_time_s: Option<f64>,
    pub worst_length_m: Option<f64>,
    pub worst_rate_m_s: Option<f64>,
    pub worst_acceleration_m_s2: Option<f64>,
}

/// The quasi-static GE stability of the plan.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct PlanGeStabilityOutput {
    /// EI used (N m²): as given, else the tether's default.
    pub bending_stiffness_n_m2: f64,
    /// Elements of the mesh (converged: the base mesh of the nested ones).
    pub elements: usize,
    /// Whether the table is converged (`elements` omitted).
    pub converged: bool,
    /// Converged only: the relative tolerance asked.
    pub relative_tolerance_nondim: Option<f64>,
    /// QS GE maximum safe length with the reserve, at a vanishing payout rate (m); converged: the safe
    /// side (best estimate minus its error estimate).
    pub max_safe_length_m: f64,
    /// Converged only: the estimated discretisation error of the maximum safe length (m).
    pub max_safe_length_error_m: Option<f64>,
    /// Cap of the critical-rate searches (m/s).
    pub rate_cap_m_s: f64,
    /// Bound on the table's interpolation error where it can change the plan (N): the largest change of
    /// S − S₀ between table rows (the most the lower-neighbour interpolation takes off, plus its curvature margin)
    /// over the intervals where the interpolated S can limit a schedule, i.e. S < (m + ρA L)·a_max + ρA·v_max² +
    /// ε(1 − r)F at the interval's longer end; 0 where the stability ceiling binds nowhere. Converged in wind: 0
    /// (no interpolation).
    pub interpolation_error_n: f64,
    /// The same as a critical length, interpolation_error_n / (ρA g) (m).
    pub interpolation_error_length_m: f64,
    /// The same bound over every interval of the table (N), including short lengths where the bending offset
    /// changes fast but the ceiling is far above the winch's rate and cannot bind.
    pub interpolation_error_all_lengths_n: f64,
    pub table: Vec<PlanGeTableRowOutput>,
    pub check: Option<PlanGeCheckOutput>,
    /// Re-plans with a lowered GE criterion after a failed check.
    pub tightening_steps: usize,
    /// Taken off S by the tightenings (N).
    pub offset_n: f64,
    pub qep_solves: usize,
    pub equilibrium_solves: usize,
}

#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct PlanResponse {
    /// Whether a schedule exists within every limit.
    pub feasible: bool,
    /// Overall go/no-go: feasible and, with a forecast, down before the wind limit.
    pub go: bool,
    /// `deployment` or `retrieval`.
    pub direction: String,
    /// Plan duration (s); null when infeasible.
    pub duration_s: Option<f64>,
    /// When infeasible: `static_lift_limit`, `tension_limit`, `gust_tension_limit` (the tension in the
    /// gust), `min_altitude` (below the floor where the plan ends), `amplification_limit`, `jerk_limit`,
    /// `wind_blowdown` (the wind blows the aerostat below the target altitude), `quasi_static_ge_limit`
    /// or `quasi_static_ge_check`.
    pub binding_limit: Option<String>,
    /// Plain-language verdict.
    pub reason: String,
    /// Whether the tension was checked against a rating: false without
    /// `cable.breaking_strength_n` (the tension is then NOT checked).
    pub tension_checked: bool,
    /// The schedule, sampled (evenly spaced plus every phase boundary).
    pub schedule: Vec<PlanSampleOutput>,
    /// The operator's table: one line per phase.
    pub phases: Vec<PlanPhaseOutput>,
    pub constant_rate: Option<ConstantRateOutput>,
    pub bound: Option<PlanBoundOutput>,
    pub transient_check: Option<TransientCheckOutput>,
    pub oscillation: Option<OscillationOutput>,
    pub retrieval: Option<RetrievalOutput>,
    pub haul_down: Option<HaulDownOutput>,
    pub limits: PlanLimitsOutput,
    /// In wind only.
    #[serde(default)]
    pub wind: Option<PlanWindOutput>,
    /// With a jerk limit only.
    #[serde(default)]
    pub jerk: Option<JerkOutput>,
    /// With `stability.method = quasi_static_ge` only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ge_stability: Option<PlanGeStabilityOutput>,
    /// How the schedule was found and checked.
    pub method: String,
    /// Computation time of the plan (s).
    pub compute_time_s: f64,
    /// The request as understood (every input, defaults filled in).
    #[schema(value_type = Object)]
    pub inputs: serde_json::Value,
    pub groups: Groups,
}
