//! Re-plan from now (SPEC §13): the committed plan's request from the
//! current tether length in the measured wind (the plan's flow scaled to
//! the 10-minute mean at the anemometer, the largest 3 s gust of the last
//! 10 minutes as its gust), to the same target; when that is NO-GO (not
//! feasible, or the haul-down deadline says down before the limit), the
//! haul-down from the current length back to the flight's start length in
//! the same wind, with the deadline from the plan's forecast.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::contract::RequestError;
use crate::contract::error::NoProgress;
use crate::contract::flight::wind::measured_wind;
use crate::contract::json::parse_value;
use crate::contract::plan::run::MIN_TARGET_M;
use crate::contract::plan::{PlanRequest, PlanResponse, plan};
use crate::numerics::params::InvalidInput;

/// The re-plan.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
pub struct ReplanOutput {
    /// `continue` (the plan to the target from now) or `haul_down` (that was NO-GO).
    pub mode: String,
    /// Why this mode.
    pub reason: String,
    /// The length the plan starts from (m): the latest measured.
    pub current_length_m: f64,
    /// The 10-minute mean at the anemometer (m/s); null: no wind measured (the plan's own wind is used).
    pub measured_mean_wind_m_s: Option<f64>,
    /// The largest 3 s mean of the last 10 minutes (m/s).
    pub measured_gust_m_s: Option<f64>,
    pub plan: PlanResponse,
}

/// Runs the re-plan. `measured`: `(mean, gust)` at the anemometer.
pub fn replan(
    request: &serde_json::Value,
    current_length_m: f64,
    measured: Option<(f64, f64)>,
    anemometer_height_m: f64,
) -> Result<ReplanOutput, RequestError> {
    let base: PlanRequest = parse_value(request)?;
    let mut req = base.clone();
    req.initial_length_m = current_length_m.max(0.0);
    if let Some((mean, gust)) = measured {
        req.wind = Some(measured_wind(
            base.wind.as_ref(),
            anemometer_height_m,
            mean,
            Some(gust),
        ));
    }
    let at_target = (req.initial_length_m - req.target_elevation_m).abs()
        < 1e-6 * req.target_elevation_m.max(1.0);
    let forward = if at_target {
        None
    } else {
        Some(plan(&req, &NoProgress)?)
    };
    let (mode, reason, out) = match forward {
        Some(p) if p.feasible && p.go => (
            "continue",
            format!("GO from {:.1} m: {}", req.initial_length_m, p.reason),
            p,
        ),
        other => {
            let why = match &other {
                Some(p) => format!(
                    "NO-GO to the target from {:.1} m ({}): haul down",
                    req.initial_length_m, p.reason
                ),
                None => "at the target: the haul-down from here".to_string(),
            };
            let mut down = req.clone();
            down.target_elevation_m = base.initial_length_m.max(MIN_TARGET_M);
            if down.target_elevation_m >= down.initial_length_m {
                return Err(RequestError::Invalid(InvalidInput::new(
                    "tether_length_m",
                    format!(
                        "the current length {:.1} m is at or below the flight's start ({:.1} m): nothing to haul down",
                        down.initial_length_m, down.target_elevation_m
                    ),
                )));
            }
            let p = plan(&down, &NoProgress)?;
            ("haul_down", why, p)
        }
    };
    Ok(ReplanOutput {
        mode: mode.into(),
        reason,
        current_length_m: req.initial_length_m,
        measured_mean_wind_m_s: measured.map(|m| m.0),
        measured_gust_m_s: measured.map(|m| m.1),
        plan: out,
    })
}
