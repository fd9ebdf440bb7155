//! The JSON of a live flight (issue 33): the limits a flight is judged by
//! ([`FlightLimitsInput`], resolved as [`FlightLimitsOutput`]), the
//! monitor's answer (state, checks, alarms) and the answers of the
//! flight routes.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::contract::flight::telemetry::RejectedSampleOutput;
use crate::contract::plan::{PlanRequest, PlanResponse};

/// A flight's limits; every field optional (the defaults of SPEC §13).
#[derive(Clone, Debug, Default, Deserialize, Serialize, ToSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct FlightLimitsInput {
    /// `wind` check: the 10-minute mean's limit at the anemometer (m/s); default the plan's
    /// `haul_down.max_operating_wind_m_s` (without either the check is not made).
    #[schema(example = 12.0, exclusive_minimum = 0.0, maximum = 150.0)]
    pub max_operating_wind_m_s: Option<f64>,
    /// `gust` check: the largest 3 s mean of the last 10 minutes' limit (m/s); default the plan's
    /// `haul_down.max_gust_m_s`.
    #[schema(example = 18.0, exclusive_minimum = 0.0, maximum = 150.0)]
    pub max_gust_m_s: Option<f64>,
    /// Height of the anemometer (m), default 10: the measured wind scales the plan's flow there.
    #[schema(example = 10.0, exclusive_minimum = 0.0, maximum = 10000.0)]
    pub anemometer_height_m: Option<f64>,
    /// `tension` caution at this fraction of the allowed tension (default 0.8).
    #[schema(example = 0.8, exclusive_minimum = 0.0, maximum = 1.0)]
    pub tension_caution_fraction_nondim: Option<f64>,
    /// `slack` stop below this fraction of the net buoyancy (default 0.05).
    #[schema(example = 0.05, minimum = 0.0, maximum = 1.0)]
    pub slack_fraction_nondim: Option<f64>,
    /// `wind` and `gust` caution at this fraction of their limits (default 0.8).
    #[schema(example = 0.8, exclusive_minimum = 0.0, maximum = 1.0)]
    pub wind_caution_fraction_nondim: Option<f64>,
    /// `payout_rate` caution at this fraction of the stability ceiling (default 0.9).
    #[schema(example = 0.9, exclusive_minimum = 0.0, maximum = 1.0)]
    pub payout_caution_fraction_nondim: Option<f64>,
    /// `plan` caution when the length is ahead of the schedule by more than this fraction (default 0.05).
    #[schema(example = 0.05, exclusive_minimum = 0.0, maximum = 10.0)]
    pub plan_ahead_fraction_nondim: Option<f64>,
    /// No sample for this long (server clock) makes the flight `unavailable` (s, default 5).
    #[schema(example = 5.0, exclusive_minimum = 0.0, maximum = 3600.0)]
    pub stale_after_s: Option<f64>,
    /// A threshold passed for this long of sample time raises its level (s, default 1).
    #[schema(example = 1.0, minimum = 0.0, maximum = 600.0)]
    pub raise_after_s: Option<f64>,
    /// Back below 0.9 of the threshold for this long clears it (s, default 5).
    #[schema(example = 5.0, minimum = 0.0, maximum = 3600.0)]
    pub clear_after_s: Option<f64>,
}

/// The limits as resolved.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct FlightLimitsOutput {
    /// Breaking strength ÷ required safety factor (N); null without a breaking strength (no `tension` check).
    pub allowable_tension_n: Option<f64>,
    pub net_buoyancy_n: f64,
    pub max_operating_wind_m_s: Option<f64>,
    pub max_gust_m_s: Option<f64>,
    pub anemometer_height_m: f64,
    pub tension_caution_fraction_nondim: f64,
    pub slack_fraction_nondim: f64,
    pub wind_caution_fraction_nondim: f64,
    pub payout_caution_fraction_nondim: f64,
    pub plan_ahead_fraction_nondim: f64,
    pub stale_after_s: f64,
    pub raise_after_s: f64,
    pub clear_after_s: f64,
    /// How the `payout_rate` check's ceiling is known.
    pub payout_ceiling: String,
}

/// `POST /api/v1/flights`: a plan request (SPEC §7, §9) with the flight's `name` and optional `limits`.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({
    "name": "morning launch",
    "cable": {"mass_per_length_kg_m": 0.078, "diameter_m": 0.006, "breaking_strength_n": 20000.0},
    "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0, "drag_coefficient_nondim": 0.3,
                 "reference_area_m2": 20.0},
    "initial_length_m": 1.0,
    "target_elevation_m": 300.0,
    "winch": {"max_rate_m_s": 3.0, "max_acceleration_m_s2": 0.5},
    "lift_reserve_nondim": 0.05,
    "required_safety_factor_nondim": 5.0,
    "wind": {"flow": {"kind": "log_law", "speed_m_s": 4.0, "roughness_length_m": 0.03}},
    "limits": {"max_operating_wind_m_s": 12.0, "max_gust_m_s": 18.0, "anemometer_height_m": 10.0}
}))]
pub struct CreateFlightRequest {
    /// 1 to 100 characters.
    #[schema(example = "morning launch")]
    pub name: String,
    #[serde(default)]
    pub limits: Option<FlightLimitsInput>,
    #[serde(flatten)]
    pub plan: PlanRequest,
}

/// One check of the monitor.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct CheckOutput {
    /// `tension`, `slack`, `wind`, `gust`, `payout_rate`, `plan` or `data`.
    pub name: String,
    /// `normal`, `caution`, `stop` or `unavailable`.
    pub state: String,
    /// The checked value (in `unit`); null before the first.
    pub value: Option<f64>,
    /// Its caution threshold; null when the check has none.
    pub caution_at: Option<f64>,
    /// Its stop threshold; null when the check has none.
    pub stop_at: Option<f64>,
    /// Unit of `value`, `caution_at`, `stop_at`: `N`, `m/s`, `nondim` (plan: the fraction ahead of
    /// the schedule) or `s` (data: seconds since the last sample arrived).
    pub unit: String,
    /// `above` (alarms past the threshold) or `below` (slack).
    pub sense: String,
}

/// One raised level.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct AlarmOutput {
    pub check: String,
    /// `caution` or `stop`.
    pub level: String,
    /// Sample time it was raised at (s).
    pub raised_at_s: f64,
    /// Sample time it cleared at (s); null while raised.
    pub cleared_at_s: Option<f64>,
    /// Sample time of the last sample when it was acknowledged (s); null: not acknowledged (a stop
    /// stays latched until then).
    pub acknowledged_at_s: Option<f64>,
}

/// A flight and its monitor.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct FlightOutput {
    pub id: i64,
    pub name: String,
    pub created_at: String,
    /// When it was ended; null while flying.
    pub ended_at: Option<String>,
    /// The worst check: `normal`, `caution`, `stop` or `unavailable`.
    pub state: String,
    pub checks: Vec<CheckOutput>,
    pub alarms: Vec<AlarmOutput>,
    /// Latest sample time (s from the flight's start); null before the first.
    pub last_sample_time_s: Option<f64>,
    /// Samples stored (duplicates not counted).
    pub samples_received: u64,
    /// Seconds since the last sample arrived by the server's clock; null before the first.
    pub seconds_since_last_sample_s: Option<f64>,
    pub limits: FlightLimitsOutput,
}

/// The answer to `POST /api/v1/flights`.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
pub struct FlightCreatedOutput {
    pub id: i64,
    /// The committed plan.
    pub plan: PlanResponse,
    /// `unavailable` until samples arrive.
    pub state: String,
    pub limits: FlightLimitsOutput,
}

/// One line of the listing.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct FlightEntryOutput {
    pub id: i64,
    pub name: String,
    pub created_at: String,
    pub ended_at: Option<String>,
}

/// The token's flights, newest first.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct FlightListOutput {
    pub flights: Vec<FlightEntryOutput>,
}

/// The answer to a batch of telemetry.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct TelemetryOutput {
    /// New samples stored.
    pub accepted: usize,
    /// Samples whose `time_s` was already stored (nothing stored twice).
    pub duplicates: usize,
    /// Samples refused.
    pub rejected: usize,
    /// Why each refused sample was refused (the first 100).
    pub errors: Vec<RejectedSampleOutput>,
    /// The flight's state after the batch.
    pub state: String,
    pub last_sample_time_s: Option<f64>,
    pub samples_received: u64,
}

/// The answer to an acknowledgement.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct AcknowledgeOutput {
    /// Alarms acknowledged now.
    pub acknowledged: usize,
    /// The flight's state after it (a stop whose value is still past its threshold stays).
    pub state: String,
}
