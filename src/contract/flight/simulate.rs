//! A flight flown in the dynamics model (issue 33): `tetherplan
//! simulate-flight` and `POST /api/v1/flights/simulate`.
//!
//! The request is a flight as `POST /api/v1/flights` takes it (a plan
//! request with `name` and `limits`), a wind event (a `wind.time_history`
//! of the dynamics request: a `1 − cos` gust, seeded turbulence, …), a
//! sample rate and a hold time. The flight's plan is committed exactly as
//! the flight route commits it ([`prepare_with`]); the dynamics model of
//! SPEC §11 then flies its schedule (the schedule's `(time_s, rate_m_s)` as
//! a `piecewise_linear_rate` profile from `initial_length_m`, its last
//! rate, zero, held) and holds at the target for `hold_s`, in
//! the plan's steady flow plus the event. The answer is the telemetry a
//! flight would record: the unstretched length, the winch rate of the
//! profile, the winch tension, the wind at the anemometer (the model's
//! fixed probe at `limits.anemometer_height_m`) and the aerostat's
//! altitude, at `sample_rate_hz` from t = 0 (the committed plan's t = 0),
//! in the flight's CSV format ([`to_csv`]) or as JSON.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::contract::RequestError;
use crate::contract::dynamics::dto::{
    DynamicsNumericsInput, DynamicsOutcomeOutput, DynamicsRequest, DynamicsWindInput,
    TimeHistoryInput,
};
use crate::contract::dynamics::run::run_prepared;
use crate::contract::dynamics::validate::Prepared as DynamicsPrepared;
use crate::contract::dynamics::validate::{DEFAULT_SEGMENTS, PEAKS_TIME_STEP_S};
use crate::contract::error::Progress;
use crate::contract::flight::dto::{CreateFlightRequest, FlightLimitsOutput};
use crate::contract::flight::model::{PreparedFlight, prepare_with};
use crate::contract::flight::telemetry::{FIELDS, TelemetrySampleInput};
use crate::contract::plan::PlanRequest;
use crate::contract::price::Price;
use crate::contract::system::WindFlowInput;
use crate::contract::system::input::{ProfileInput, RatePointInput};
use crate::numerics::dynamics::Outcome;
use crate::numerics::params::InvalidInput;

fn default_rate() -> f64 {
    10.0
}
fn default_hold() -> f64 {
    60.0
}

/// Most samples of a simulated log.
pub const MAX_SIMULATED_SAMPLES: usize = 200_000;
/// Longest hold at the target (s).
pub const MAX_HOLD_S: f64 = 86_400.0;

/// `POST /api/v1/flights/simulate`, `tetherplan simulate-flight`: a flight
/// flown in the dynamics model through a wind event.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({
    "flight": {
        "name": "simulated gust",
        "cable": {"preset": "dyneema", "diameter_m": 0.006},
        "aerostat": {"net_buoyancy_n": 2000.0, "mass_kg": 100.0, "drag_coefficient_nondim": 0.3,
                     "reference_area_m2": 20.0},
        "initial_length_m": 50.0,
        "target_elevation_m": 150.0,
        "winch": {"max_rate_m_s": 2.0, "max_acceleration_m_s2": 0.5},
        "wind": {"flow": {"kind": "uniform", "speed_m_s": 6.0}},
        "limits": {"max_operating_wind_m_s": 15.0, "max_gust_m_s": 20.0}
    },
    "wind_event": {"kind": "one_minus_cosine", "start_time_s": 100.0, "duration_s": 10.0,
                   "amplitude_m_s": 6.0},
    "sample_rate_hz": 5.0,
    "hold_s": 60.0,
    "numerics": {"segments": 20, "time_step_s": 0.05, "spectral_radius_nondim": 0.8}
}))]
pub struct SimulateFlightRequest {
    /// The flight as `POST /api/v1/flights` takes it. The dynamics model
    /// also needs the cable's `axial_stiffness_n` (or a preset) and, in
    /// wind, its `diameter_m` and the aerostat's drag data.
    #[schema(value_type = CreateFlightRequest)]
    pub flight: serde_json::Value,
    /// The change of the wind in time, added to the plan's steady flow
    /// (the dynamics request's `wind.time_history`: a `one_minus_cosine`
    /// gust, seeded `turbulence`, a step, ramp or sinusoid); absent: the
    /// steady flow only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wind_event: Option<TimeHistoryInput>,
    /// Samples per second of the log (Hz), default 10; at most one per
    /// time step.
    #[serde(default = "default_rate")]
    #[schema(example = 10.0, exclusive_minimum = 0.0, maximum = 10000.0)]
    pub sample_rate_hz: f64,
    /// Time held at the target after the schedule ends (s), default 60.
    #[serde(default = "default_hold")]
    #[schema(example = 60.0, minimum = 0.0, maximum = 86400.0)]
    pub hold_s: f64,
    /// The dynamics model's discretisation (as in `POST /api/v1/dynamics`).
    #[serde(default)]
    pub numerics: DynamicsNumericsInput,
}

/// The simulated log.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct SimulatedFlightOutput {
    /// `completed`, or how the run stopped (the log then ends at `stopped_at_s`).
    pub outcome: DynamicsOutcomeOutput,
    /// Time the run stopped at (s).
    pub stopped_at_s: f64,
    /// The committed plan's duration (s): the schedule flown before the hold.
    pub plan_duration_s: f64,
    /// Simulated time (s): the plan, the hold, rounded up to a whole sample.
    pub duration_s: f64,
    pub sample_rate_hz: f64,
    /// Where the log's `wind_speed_m_s` is read (m above the winch).
    pub anemometer_height_m: f64,
    /// The flight's limits as `POST /api/v1/flights` resolves them.
    pub limits: FlightLimitsOutput,
    /// The telemetry, every field given.
    pub samples: Vec<TelemetrySampleInput>,
}

fn invalid(field: &str, reason: impl std::fmt::Display) -> RequestError {
    RequestError::Invalid(InvalidInput::new(field, reason))
}

/// An error of the flight part, its field under `flight.`.
fn in_flight(e: RequestError) -> RequestError {
    match e {
        RequestError::Invalid(i) => invalid(&format!("flight.{}", i.field), i.reason),
        e => e,
    }
}

/// An error of the dynamics request built here, named by this request's fields.
fn in_dynamics(e: InvalidInput) -> RequestError {
    let field = match e.field.as_str() {
        f if f.starts_with("wind.time_history") => f.replacen("wind.time_history", "wind_event", 1),
        f if f.starts_with("numerics") => f.to_string(),
        "sample_count" => "sample_rate_hz".to_string(),
        "duration_s" => "hold_s".to_string(),
        "profile" => "flight.target_elevation_m".to_string(),
        f => format!("flight.{f}"),
    };
    invalid(&field, e.reason)
}

/// A request checked, its plan committed and its dynamics run prepared.
pub struct Setup {
    pub flight: PreparedFlight,
    pub dynamics: DynamicsRequest,
    pub prepared: DynamicsPrepared,
    pub plan_duration_s: f64,
    pub sample_rate_hz: f64,
}

impl SimulateFlightRequest {
    /// Parses a body (field paths kept).
    pub fn parse(body: &[u8]) -> Result<Self, RequestError> {
        crate::contract::json_keys::reject_duplicate_keys(body)?;
        crate::contract::parse_plain(body)
    }

    /// Commits the plan and prepares the run (the plan is solved here:
    /// `progress` may stop it).
    pub fn setup(&self, progress: &dyn Progress) -> Result<Setup, RequestError> {
        let rate = self.sample_rate_hz;
        if !(rate.is_finite() && rate > 0.0 && rate <= 1e4) {
            return Err(invalid(
                "sample_rate_hz",
                format!("must be above 0 and at most 10000 Hz, got {rate}"),
            ));
        }
        // one run at the fixed step (a telemetry log, not a converged figure)
        let mut numerics = self.numerics.clone();
        let step = *numerics.time_step_s.get_or_insert(PEAKS_TIME_STEP_S);
        numerics.segments.get_or_insert(DEFAULT_SEGMENTS);
        if step.is_finite() && step > 0.0 && rate * step > 1.0 + 1e-9 {
            return Err(invalid(
                "sample_rate_hz",
                format!(
                    "at most one sample per time step: at most {} Hz with numerics.time_step_s = {step} s, got {rate}",
                    1.0 / step
                ),
            ));
        }
        if !(self.hold_s.is_finite() && (0.0..=MAX_HOLD_S).contains(&self.hold_s)) {
            return Err(invalid(
                "hold_s",
                format!("must be between 0 and {MAX_HOLD_S} s, got {}", self.hold_s),
            ));
        }
        let body = serde_json::to_vec(&self.flight).expect("a JSON value serialises");
        let flight = prepare_with(&body, progress).map_err(in_flight)?;
        let req: PlanRequest =
            crate::contract::json::parse_value(&flight.request).map_err(in_flight)?;
        let schedule = &flight.plan.schedule;
        let plan_duration_s = flight
            .plan
            .duration_s
            .or(schedule.last().map(|s| s.time_s))
            .unwrap_or(0.0);
        // the schedule's rates, times strictly increasing from 0
        let mut points: Vec<RatePointInput> = Vec::with_capacity(schedule.len() + 1);
        for s in schedule {
            if points.last().is_some_and(|p| s.time_s <= p.time_s) {
                continue;
            }
            if points.is_empty() && s.time_s > 0.0 {
                points.push(RatePointInput {
                    time_s: 0.0,
                    rate_m_s: 0.0,
                });
            }
            points.push(RatePointInput {
                time_s: s.time_s,
                rate_m_s: s.rate_m_s,
            });
        }
        if points.len() > 10_000 {
            return Err(invalid(
                "flight.schedule_samples",
                format!(
                    "gives {} schedule points; the dynamics profile takes at most 10000",
                    points.len()
                ),
            ));
        }
        // a whole number of samples: sample k at k / rate
        let intervals = ((plan_duration_s + self.hold_s) * rate).ceil().max(1.0);
        if intervals + 1.0 > MAX_SIMULATED_SAMPLES as f64 {
            return Err(invalid(
                "sample_rate_hz",
                format!(
                    "gives {intervals:.0} samples over the plan and the hold; at most {MAX_SIMULATED_SAMPLES}"
                ),
            ));
        }
        let duration_s = intervals / rate;
        let wind = req.wind.as_ref();
        let dynamics = DynamicsRequest {
            cable: req.cable.clone(),
            aerostat: req.aerostat.clone(),
            wind: DynamicsWindInput {
                flow: wind.map_or(WindFlowInput::Uniform { speed_m_s: 0.0 }, |w| {
                    w.flow.clone()
                }),
                air_density_kg_m3: wind.map_or(1.225, |w| w.air_density_kg_m3),
                time_history: self.wind_event.clone(),
            },
            tether_length_m: None,
            profile: Some(ProfileInput::PiecewiseLinearRate {
                points,
                // the table decides: its integral is the schedule's within the
                // interpolation (a target it fell short of would be refused)
                target_length_m: None,
            }),
            initial_length_m: Some(req.initial_length_m),
            duration_s,
            sample_count: intervals as usize + 1,
            shape_count: Some(0),
            shape_times_s: None,
            internal_damping_n_s: 0.0,
            wind_probe_height_m: Some(flight.limits.anemometer_height_m),
            tangential_drag_coefficient_nondim: 0.0,
            numerics,
            gravity_m_s2: req.gravity_m_s2,
            required_safety_factor_nondim: req.required_safety_factor_nondim,
            winch: Some(req.winch.clone()),
            lift_reserve_nondim: Some(req.lift_reserve_nondim),
        };
        let prepared = dynamics.prepare().map_err(in_dynamics)?;
        Ok(Setup {
            flight,
            dynamics,
            prepared,
            plan_duration_s,
            sample_rate_hz: rate,
        })
    }
}

impl Setup {
    /// The run's price (the dynamics run's: the plan is already solved).
    pub fn price(&self) -> Price {
        let mut p = crate::contract::dynamics::price::dynamics(&self.prepared);
        p.field = match p.field.as_str() {
            "duration_s" => "hold_s".into(),
            f if f.starts_with("wind.time_history") => {
                f.replacen("wind.time_history", "wind_event", 1)
            }
            f => f.to_string(),
        };
        p
    }

    /// Flies it.
    pub fn run(&self, progress: &dyn Progress) -> Result<SimulatedFlightOutput, RequestError> {
        let ran = run_prepared(&self.prepared, progress)?;
        let run = &ran.run;
        let (outcome, stopped_at_s) = match run.outcome {
            Outcome::Completed | Outcome::Stopped { .. } => {
                (DynamicsOutcomeOutput::Completed, run.final_state.time_s)
            }
            Outcome::NewtonFailed { time_s } => (DynamicsOutcomeOutput::NewtonFailed, time_s),
            Outcome::Diverged { time_s } => (DynamicsOutcomeOutput::Diverged, time_s),
            Outcome::AerostatBelowWinch { time_s, .. } => {
                (DynamicsOutcomeOutput::AerostatBelowWinch, time_s)
            }
            Outcome::EnergyGained { time_s, .. } => (DynamicsOutcomeOutput::EnergyGained, time_s),
        };
        let height = self.flight.limits.anemometer_height_m;
        let rate = self.sample_rate_hz;
        let samples = run
            .samples
            .iter()
            .map(|s| {
                // the nominal sample time k / rate when the model's is it but
                // for rounding; else the model's step time (to 1 ns)
                let k = (s.time_s * rate).round();
                let t = if (k / rate - s.time_s).abs() < 1e-9 {
                    k / rate
                } else {
                    (s.time_s * 1e9).round() / 1e9
                };
                TelemetrySampleInput {
                    time_s: t,
                    tether_length_m: Some(s.length_m),
                    winch_rate_m_s: Some(self.prepared.problem.length.at(s.time_s).rate_m_s),
                    winch_tension_n: Some(s.winch_tension_n),
                    wind_speed_m_s: Some(s.probe_wind_m_s.max(0.0)),
                    wind_height_m: Some(height),
                    aerostat_altitude_m: Some(s.aerostat_altitude_m),
                }
            })
            .collect();
        Ok(SimulatedFlightOutput {
            outcome,
            stopped_at_s,
            plan_duration_s: self.plan_duration_s,
            duration_s: self.dynamics.duration_s,
            sample_rate_hz: rate,
            anemometer_height_m: height,
            limits: self.flight.limits.clone(),
            samples,
        })
    }
}

/// Commits, prepares and flies a request.
pub fn simulate_flight(
    req: &SimulateFlightRequest,
    progress: &dyn Progress,
) -> Result<SimulatedFlightOutput, RequestError> {
    req.setup(progress)?.run(progress)
}

/// The log in the flight's CSV format: the header
/// `time_s,tether_length_m,winch_rate_m_s,winch_tension_n,wind_speed_m_s,wind_height_m,aerostat_altitude_m`,
/// then one sample a line (shortest round-trip decimals; an absent value
/// is an empty cell).
pub fn to_csv(samples: &[TelemetrySampleInput]) -> String {
    let mut out = FIELDS.join(",");
    out.push('\n');
    for s in samples {
        let values = [
            Some(s.time_s),
            s.tether_length_m,
            s.winch_rate_m_s,
            s.winch_tension_n,
            s.wind_speed_m_s,
            s.wind_height_m,
            s.aerostat_altitude_m,
        ];
        let cells: Vec<String> = values
            .iter()
            .map(|v| v.map(|v| format!("{v}")).unwrap_or_default())
            .collect();
        out.push_str(&cells.join(","));
        out.push('\n');
    }
    out
}
