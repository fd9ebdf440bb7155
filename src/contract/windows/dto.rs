//! Request and response bodies of `POST /api/v1/windows` (SPEC §12): SI
//! units, every field name ends in its unit; the forecast as its source
//! gives it.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::contract::plan::dto::PlanStabilityInput;
use crate::contract::system::{AerostatInput, CableInput};
use crate::contract::system::{WinchInput, WindInput};
pub use crate::contract::windows::forecast::{ForecastFormat, ForecastInput};

/// Default roughness length of the log law through one height (m): open
/// terrain (WMO class "open", Davenport's 0.03 m).
pub const DEFAULT_ROUGHNESS_LENGTH_M: f64 = 0.03;

/// Wind limits of the operation: an hour whose wind (or gust) at the target
/// altitude passes them is no-go.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct WindowsHaulDownInput {
    /// Largest wind at the aerostat in which it may stay aloft (m/s).
    #[schema(example = 12.0, exclusive_minimum = 0.0, maximum = 200.0)]
    pub max_operating_wind_m_s: f64,
    /// Largest gust at the aerostat in which it may stay aloft (m/s).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 18.0, exclusive_minimum = 0.0, maximum = 200.0)]
    pub max_gust_m_s: Option<f64>,
}

/// The lead-time factor α = max(min_nondim, 1 − per_hour_nondim × lead hours)
/// that shrinks the wind limits of a window as the forecast ages.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LeadTimeFactorInput {
    /// Fraction of the limit taken off per hour of lead time (default 0.01).
    #[serde(default = "default_per_hour")]
    #[schema(example = 0.01, minimum = 0.0, maximum = 1.0)]
    pub per_hour_nondim: f64,
    /// Smallest factor (default 0.5).
    #[serde(default = "default_floor")]
    #[schema(example = 0.5, minimum = 0.0, maximum = 1.0)]
    pub min_nondim: f64,
}

fn default_per_hour() -> f64 {
    0.01
}
fn default_floor() -> f64 {
    0.5
}

/// The air of the windows request: its density (the flow comes from the forecast).
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct WindowsAirInput {
    /// Air density (kg/m³), default 1.225.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 1.225, exclusive_minimum = 0.0, maximum = 5.0)]
    pub air_density_kg_m3: Option<f64>,
}

/// `POST /api/v1/windows`: the day's launch windows from a forecast.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({
    "cable": {"mass_per_length_kg_m": 0.078, "diameter_m": 0.006, "breaking_strength_n": 20000.0},
    "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0, "drag_coefficient_nondim": 0.3,
                 "reference_area_m2": 20.0},
    "winch": {"max_rate_m_s": 10.0, "max_acceleration_m_s2": 1.0},
    "target_elevation_m": 300.0,
    "operation_s": 3600.0,
    "haul_down": {"max_operating_wind_m_s": 12.0},
    "forecast": {"format": "csv", "data": "time,height_m,speed_m_s,gust_m_s\n2026-12-03T08:00,10,3,5\n2026-12-03T09:00,10,4,6\n2026-12-03T10:00,10,5,7\n2026-12-03T11:00,10,11,16\n"}
}))]
pub struct WindowsRequest {
    pub cable: CableInput,
    pub aerostat: AerostatInput,
    /// Cable length before the deployment (m), default 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 1.0, minimum = 0.001, maximum = 10000.0)]
    pub initial_length_m: Option<f64>,
    /// Gravitational acceleration (m/s²), default 9.81.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 9.81, minimum = 0.01, maximum = 100.0)]
    pub gravity_m_s2: Option<f64>,
    pub winch: WinchInput,
    /// Lift reserve of the plan (default 0.05).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 0.05, minimum = 0.0, maximum = 0.9)]
    pub lift_reserve_nondim: Option<f64>,
    /// Required safety factor on the breaking strength (default 5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 5.0, minimum = 1.0, maximum = 100.0)]
    pub required_safety_factor_nondim: Option<f64>,
    /// Altitude of the aerostat to fly at (m), as the plan's.
    #[schema(example = 300.0, minimum = 0.001, maximum = 1e6)]
    pub target_elevation_m: f64,
    /// Lowest altitude the aerostat may be blown down to (m), as the plan's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 150.0, minimum = 0.0, maximum = 1e6)]
    pub min_altitude_m: Option<f64>,
    /// The plan's stability criterion (default the string criterion).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stability: Option<PlanStabilityInput>,
    /// The air's density; the flow and gusts come from the forecast.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wind: Option<WindowsAirInput>,
    /// Time the aerostat must stay up at its altitude (s).
    #[schema(example = 3600.0, minimum = 0.0, maximum = 1e7)]
    pub operation_s: f64,
    /// Wind limits at the aerostat; absent: the plan's own limits only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub haul_down: Option<WindowsHaulDownInput>,
    /// The lead-time factor of the limits (default 0.01 per hour, at least 0.5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lead_time_factor: Option<LeadTimeFactorInput>,
    pub forecast: ForecastInput,
}

/// One forecast period (an hour, or a TAF group) judged as `/plan` judges its wind.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
pub struct WindowsHourOutput {
    /// The period's start as the forecast wrote it.
    pub time: String,
    /// Its end (the next time; a TAF group's end).
    pub end: String,
    /// Lead time of its start (s) from the forecast's first time (a TAF: its issue).
    pub lead_time_s: f64,
    /// TAF: `base`, `fm`, `becmg`, `tempo`, `prob`; METAR: `metar`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub group: Option<String>,
    /// The §9 wind of this period: the fitted flow and its gust (the plan's `wind`).
    pub wind: WindInput,
    /// `go` or `no-go`: `/plan`'s verdict for this wind (and, with `haul_down`, its limits).
    pub verdict: String,
    /// `/plan`'s reason.
    pub reason: String,
    /// The highest altitude reachable in this wind (m): `/plan`'s `wind.reachable_altitude_m`
    /// (calm air: its lift limit).
    pub max_altitude_m: f64,
    /// `/plan`'s `limits.peak_tension_n` (N).
    pub peak_tension_n: Option<f64>,
    /// `/plan`'s `limits.min_safety_factor_nondim`.
    pub safety_factor_nondim: Option<f64>,
    /// Deployment duration in this wind (s); null when no-go for want of a schedule.
    pub deployment_s: Option<f64>,
    /// Haul-down duration from the target in this wind (s).
    pub haul_down_s: Option<f64>,
    /// Mean wind at the target altitude (m/s).
    pub wind_at_target_m_s: f64,
    /// Gust at the target altitude (m/s); null without a gust.
    pub gust_at_target_m_s: Option<f64>,
    /// The lead-time factor α on the limits at this period's start.
    pub limit_factor_nondim: f64,
    /// Whether the period counts toward a window: `go`, and with `haul_down` its wind and gust
    /// within α × the limits.
    pub in_window_limits: bool,
    /// Ensemble: the share of members that are GO.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub probability_go: Option<f64>,
    /// Ensemble: the 95 % Wilson interval of `probability_go`, low end.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub probability_go_low: Option<f64>,
    /// Ensemble: its high end.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub probability_go_high: Option<f64>,
    /// Ensemble: 10 % of the members' `max_altitude_m` (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_altitude_p10_m: Option<f64>,
    /// Ensemble: 50 %.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_altitude_p50_m: Option<f64>,
    /// Ensemble: 90 %.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_altitude_p90_m: Option<f64>,
}

/// A launch window: deployment, `operation_s` aloft and the haul-down fit.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct WindowOutput {
    pub start: String,
    pub end: String,
    /// Latest launch that still fits (start + … ≤ this).
    pub latest_launch: String,
    /// end − start (s).
    pub duration_s: f64,
    /// Deployment + operation + haul-down, the longest over the window's periods (s).
    pub required_s: f64,
    /// Ensemble: the share of members in which the operation can start at `start`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub probability: Option<f64>,
}

/// The lead-time factor used.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct LeadTimeFactorOutput {
    pub per_hour_nondim: f64,
    pub min_nondim: f64,
    pub explanation: String,
}

#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
pub struct WindowsResponse {
    /// One per forecast period (of the control member with an ensemble), in time order.
    pub hours: Vec<WindowsHourOutput>,
    /// The launch windows (of the control member), in time order.
    pub windows: Vec<WindowOutput>,
    /// Members of the forecast (1 without an ensemble).
    pub members: usize,
    pub format: ForecastFormat,
    /// Roughness length of the log laws through one height (m).
    pub roughness_length_m: f64,
    pub lead_time_factor: LeadTimeFactorOutput,
    /// How each period's flow was made.
    pub method: String,
    /// What the parser assumed or left out.
    pub notes: Vec<String>,
    /// Distinct winds planned (identical winds are planned once).
    pub plans_computed: usize,
    pub compute_time_s: f64,
}
