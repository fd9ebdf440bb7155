//! A flight from its request, and the monitor's answer in JSON.
//!
//! [`prepare`] parses `POST /api/v1/flights` (the `name`, the `limits` and
//! the rest as a plan request, each part refusing unknown fields), commits
//! the plan (an infeasible one is refused: there is no schedule to fly),
//! resolves the limits and tabulates the stability ceiling over lengths ×
//! measured winds ([`ceiling_table`]). What it returns is what the store
//! keeps; [`flight_model`] rebuilds the monitor's references from it, so a
//! restarted server judges the same samples the same way.

use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::contract::RequestError;
use crate::contract::error::{NoProgress, Progress};
use crate::contract::flight::dto::*;
use crate::contract::flight::wind::measured_wind;
use crate::contract::json::parse_value;
use crate::contract::plan::ceiling::rate_ceilings_m_s;
use crate::contract::plan::{PlanRequest, PlanResponse, plan};
use crate::numerics::monitor::{
    CeilingTable, CheckName, Dwell, FlightModel, Limits, Monitor, PlanTrace, Sense,
};
use crate::numerics::params::InvalidInput;

/// Longest flight name.
pub const MAX_NAME_CHARS: usize = 100;

/// The ceiling table as stored.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
pub struct StoredTable {
    pub lengths_m: Vec<f64>,
    pub winds_m_s: Vec<f64>,
    pub ceilings_m_s: Vec<f64>,
}

/// A flight ready to store.
#[derive(Clone, Debug)]
pub struct PreparedFlight {
    pub name: String,
    /// The plan request part (for the re-plan).
    pub request: serde_json::Value,
    pub plan: PlanResponse,
    pub limits: FlightLimitsOutput,
    pub table: StoredTable,
}

fn invalid(field: &str, reason: impl std::fmt::Display) -> RequestError {
    RequestError::Invalid(InvalidInput::new(field, reason))
}

fn bounded(
    field: &str,
    v: Option<f64>,
    default: f64,
    lo: f64,
    hi: f64,
    open_lo: bool,
) -> Result<f64, RequestError> {
    let Some(v) = v else { return Ok(default) };
    let ok = v.is_finite() && v <= hi && if open_lo { v > lo } else { v >= lo };
    if !ok {
        let lower = if open_lo { "above" } else { "at least" };
        return Err(invalid(
            field,
            format!("must be {lower} {lo} and at most {hi}, got {v}"),
        ));
    }
    Ok(v)
}

/// Resolves the limits against the plan.
pub fn resolve_limits(
    input: &FlightLimitsInput,
    req: &PlanRequest,
    plan: &PlanResponse,
) -> Result<FlightLimitsOutput, RequestError> {
    let l = input;
    let hd = req.haul_down.as_ref();
    let wind = l
        .max_operating_wind_m_s
        .or(hd.map(|h| h.max_operating_wind_m_s));
    let gust = l.max_gust_m_s.or(hd.and_then(|h| h.max_gust_m_s));
    let net = plan
        .inputs
        .pointer("/aerostat/net_buoyancy_n")
        .and_then(|v| v.as_f64());
    let net_buoyancy_n = match (net, req.aerostat.net_buoyancy_n) {
        (Some(v), _) | (None, Some(v)) => v,
        (None, None) => {
            return Err(invalid(
                "aerostat.net_buoyancy_n",
                "is needed for the slack check",
            ));
        }
    };
    Ok(FlightLimitsOutput {
        allowable_tension_n: plan.limits.allowable_tension_n,
        net_buoyancy_n,
        max_operating_wind_m_s: Some(bounded(
            "limits.max_operating_wind_m_s",
            wind,
            0.0,
            0.0,
            150.0,
            true,
        )?)
        .filter(|_| wind.is_some()),
        max_gust_m_s: Some(bounded("limits.max_gust_m_s", gust, 0.0, 0.0, 150.0, true)?)
            .filter(|_| gust.is_some()),
        anemometer_height_m: bounded(
            "limits.anemometer_height_m",
            l.anemometer_height_m,
            10.0,
            0.0,
            1e4,
            true,
        )?,
        tension_caution_fraction_nondim: bounded(
            "limits.tension_caution_fraction_nondim",
            l.tension_caution_fraction_nondim,
            0.8,
            0.0,
            1.0,
            true,
        )?,
        slack_fraction_nondim: bounded(
            "limits.slack_fraction_nondim",
            l.slack_fraction_nondim,
            0.05,
            0.0,
            1.0,
            false,
        )?,
        wind_caution_fraction_nondim: bounded(
            "limits.wind_caution_fraction_nondim",
            l.wind_caution_fraction_nondim,
            0.8,
            0.0,
            1.0,
            true,
        )?,
        payout_caution_fraction_nondim: bounded(
            "limits.payout_caution_fraction_nondim",
            l.payout_caution_fraction_nondim,
            0.9,
            0.0,
            1.0,
            true,
        )?,
        plan_ahead_fraction_nondim: bounded(
            "limits.plan_ahead_fraction_nondim",
            l.plan_ahead_fraction_nondim,
            0.05,
            0.0,
            10.0,
            true,
        )?,
        stale_after_s: bounded(
            "limits.stale_after_s",
            l.stale_after_s,
            5.0,
            0.0,
            3600.0,
            true,
        )?,
        raise_after_s: bounded(
            "limits.raise_after_s",
            l.raise_after_s,
            1.0,
            0.0,
            600.0,
            false,
        )?,
        clear_after_s: bounded(
            "limits.clear_after_s",
            l.clear_after_s,
            5.0,
            0.0,
            3600.0,
            false,
        )?,
        payout_ceiling: String::new(),
    })
}

/// Parses and commits a flight.
pub fn prepare(body: &[u8]) -> Result<PreparedFlight, RequestError> {
    prepare_with(body, &NoProgress)
}

/// Parses and commits a flight; `progress` may stop the plan's solve and
/// the ceiling table between its winds ([`RequestError::Cancelled`]).
pub fn prepare_with(body: &[u8], progress: &dyn Progress) -> Result<PreparedFlight, RequestError> {
    crate::contract::json_keys::reject_duplicate_keys(body)?;
    let mut value: serde_json::Value =
        serde_json::from_slice(body).map_err(|e| RequestError::Malformed(e.to_string()))?;
    let Some(obj) = value.as_object_mut() else {
        return Err(invalid(
            "body",
            "must be a JSON object: a plan request with `name`",
        ));
    };
    let name = match obj.remove("name") {
        Some(serde_json::Value::String(s)) => s,
        Some(_) => return Err(invalid("name", "must be text")),
        None => return Err(invalid("name", "is required: the flight's name")),
    };
    let chars = name.chars().count();
    if chars == 0 || chars > MAX_NAME_CHARS || name.chars().any(char::is_control) {
        return Err(invalid(
            "name",
            format!("must be 1 to {MAX_NAME_CHARS} characters without control characters"),
        ));
    }
    let limits: FlightLimitsInput = match obj.remove("limits") {
        None | Some(serde_json::Value::Null) => FlightLimitsInput::default(),
        Some(v) => parse_value(&v).map_err(|e| match e {
            RequestError::Invalid(i) => invalid(&format!("limits.{}", i.field), i.reason),
            e => e,
        })?,
    };
    let req: PlanRequest = parse_value(&value)?;
    let plan = plan(&req, progress)?;
    if !plan.feasible {
        return Err(invalid(
            plan.binding_limit
                .as_deref()
                .unwrap_or("target_elevation_m"),
            format!(
                "the plan is not feasible, so there is no schedule to fly: {}",
                plan.reason
            ),
        ));
    }
    let mut limits = resolve_limits(&limits, &req, &plan)?;
    if progress.cancelled() {
        return Err(RequestError::Cancelled);
    }
    let (table, note) = ceiling_table(&req, &plan, &limits, progress)?;
    limits.payout_ceiling = note;
    Ok(PreparedFlight {
        name,
        request: value,
        plan,
        limits,
        table,
    })
}

/// Lengths of the ceiling table.
const TABLE_LENGTHS: usize = 41;
/// Winds of the ceiling table.
const TABLE_WINDS: usize = 9;

/// The stability ceiling over lengths (0 to 1.25 × the longest of the
/// schedule) × winds at the anemometer (0 to 1.5 × the largest limit, at
/// least 30 m/s), each wind the plan's flow scaled to it ([`measured_wind`])
/// without gusts (the monitor takes the smaller ceiling of the mean and the
/// gust). A plan without the drag data a wind needs is tabulated in calm
/// air, and says so.
pub fn ceiling_table(
    req: &PlanRequest,
    plan: &PlanResponse,
    limits: &FlightLimitsOutput,
    progress: &dyn Progress,
) -> Result<(StoredTable, String), RequestError> {
    let longest = plan
        .schedule
        .iter()
        .map(|s| s.length_m)
        .fold(req.initial_length_m, f64::max);
    let top = 1.25 * longest.max(1.0);
    let lengths: Vec<f64> = (0..TABLE_LENGTHS)
        .map(|i| top * i as f64 / (TABLE_LENGTHS - 1) as f64)
        .collect();
    let fastest = limits
        .max_gust_m_s
        .into_iter()
        .chain(limits.max_operating_wind_m_s)
        .fold(20.0, f64::max);
    let wind_top = 1.5 * fastest;
    let winds: Vec<f64> = (0..TABLE_WINDS)
        .map(|j| wind_top * j as f64 / (TABLE_WINDS - 1) as f64)
        .collect();
    let mut columns = Vec::with_capacity(winds.len());
    let mut calm_only = false;
    for &w in &winds {
        if progress.cancelled() {
            return Err(RequestError::Cancelled);
        }
        let mut r = req.clone();
        r.haul_down = None;
        r.wind = Some(measured_wind(
            req.wind.as_ref(),
            limits.anemometer_height_m,
            w,
            None,
        ));
        match rate_ceilings_m_s(&r, &lengths) {
            Ok(c) => columns.push(c),
            Err(_) if w > 0.0 && columns.len() == 1 => {
                calm_only = true;
                break;
            }
            Err(e) => return Err(e),
        }
    }
    let (winds, note) = if calm_only {
        (
            vec![0.0],
            "calm air only: the plan request lacks the drag data a wind needs, so the ceiling does not \
             fall with the measured wind"
                .to_string(),
        )
    } else {
        (
            winds,
            format!(
                "the plan's criterion at rest, tabulated over {TABLE_LENGTHS} lengths to {top:.0} m × \
                 {TABLE_WINDS} winds to {wind_top:.0} m/s at the anemometer (bilinear), the smaller of the \
                 ceilings in the mean and in the gust"
            ),
        )
    };
    let mut ceilings = Vec::with_capacity(lengths.len() * winds.len());
    for i in 0..lengths.len() {
        for col in columns.iter().take(winds.len()) {
            ceilings.push(col[i]);
        }
    }
    Ok((
        StoredTable {
            lengths_m: lengths,
            winds_m_s: winds,
            ceilings_m_s: ceilings,
        },
        note,
    ))
}

/// The monitor's references from what the store keeps.
pub fn flight_model(
    limits: &FlightLimitsOutput,
    plan: &PlanResponse,
    table: &StoredTable,
) -> FlightModel {
    let mut l = Limits::new(limits.net_buoyancy_n);
    l.allowable_tension_n = limits.allowable_tension_n;
    l.tension_caution_fraction = limits.tension_caution_fraction_nondim;
    l.slack_fraction = limits.slack_fraction_nondim;
    l.max_operating_wind_m_s = limits.max_operating_wind_m_s;
    l.max_gust_m_s = limits.max_gust_m_s;
    l.wind_caution_fraction = limits.wind_caution_fraction_nondim;
    l.payout_caution_fraction = limits.payout_caution_fraction_nondim;
    l.plan_ahead_fraction = limits.plan_ahead_fraction_nondim;
    l.stale_after_s = limits.stale_after_s;
    l.dwell = Dwell {
        raise_after_s: limits.raise_after_s,
        clear_after_s: limits.clear_after_s,
        ..Dwell::default()
    };
    let (times, lengths): (Vec<f64>, Vec<f64>) =
        plan.schedule.iter().map(|s| (s.time_s, s.length_m)).unzip();
    let ceiling = CeilingTable::new(
        table.lengths_m.clone(),
        table.winds_m_s.clone(),
        table.ceilings_m_s.clone(),
    )
    .ok()
    .map(|t| Arc::new(t) as Arc<dyn crate::numerics::monitor::RateCeiling + Send + Sync>);
    FlightModel {
        limits: l,
        plan: PlanTrace::new(times, lengths),
        ceiling,
    }
}

fn unit(c: CheckName) -> &'static str {
    match c {
        CheckName::Tension | CheckName::Slack => "N",
        CheckName::Wind | CheckName::Gust | CheckName::PayoutRate => "m/s",
        CheckName::Plan => "nondim",
        CheckName::Data => "s",
    }
}

fn sense(c: CheckName) -> Sense {
    if c == CheckName::Slack {
        Sense::Below
    } else {
        Sense::Above
    }
}

/// The monitor's state, checks and alarms as JSON, `since_s` after the
/// last sample arrived.
pub fn status_output(
    m: &Monitor,
    since_s: Option<f64>,
) -> (String, Vec<CheckOutput>, Vec<AlarmOutput>) {
    let st = m.status(since_s);
    let checks = st
        .checks
        .iter()
        .map(|c| CheckOutput {
            name: c.name.name().into(),
            state: c.state.name().into(),
            value: c.value,
            caution_at: c.caution_at,
            stop_at: c.stop_at,
            unit: unit(c.name).into(),
            sense: match sense(c.name) {
                Sense::Above => "above",
                Sense::Below => "below",
            }
            .into(),
        })
        .collect();
    let alarms = m
        .alarms()
        .iter()
        .map(|a| AlarmOutput {
            check: a.check.name().into(),
            level: a.level.name().into(),
            raised_at_s: a.raised_at_s,
            cleared_at_s: a.cleared_at_s,
            acknowledged_at_s: a.acknowledged_at_s,
        })
        .collect();
    (st.state.name().into(), checks, alarms)
}
