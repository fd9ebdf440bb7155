//! The linear string's analysis kind `safe_rate` ([`Analysis`]), and the
//! linear string's checks, sizes and chunking behind the kinds that pick
//! the model (`stability`, `critical`, `chart`: [`crate::contract::ge::kind`]).

use crate::contract::analysis::{Analysis, Items, too_large};
use crate::contract::error::{Progress, RequestError};
use crate::contract::estimate::{self as est, Estimate as E, Estimate};
use crate::contract::string::chunks::chart_rate_count;
use crate::contract::string::dto::{
    ChartRequest, SafeRateRequest, SafeRateResponse, StabilityRequest,
};
use crate::contract::string::run::{self, MAX_MODES};
use crate::limits::Limits;
use crate::numerics::parallel::Parallelism;
use crate::numerics::params::{InvalidInput, require_finite, require_positive};
use crate::numerics::string::chart::{self, Discretisation, MAX_CHART_POINTS};

/// Seconds per element of one point of a string chart on a uniform mesh
/// (measured: 300 rates × 3 buoyancies at 400 elements in 0.21-0.23 s on
/// one core, 5.9-6.5e-7 s, timing `run_chunk` on one rayon thread).
const STRING_CHART_ELEMENT_POINT_S: f64 = 7e-7;
/// Seconds per converged point of a string chart (measured: 74 points in
/// 0.5 ms, 6.5-7.3e-6 s, on one core; slower near the wave speed).
const STRING_CHART_CONVERGED_POINT_S: f64 = 1e-5;

impl Analysis for SafeRateRequest {
    const NAME: &'static str = "safe_rate";
    const SUMMARY: &'static str = "Largest safe constant winch rate to reach a target elevation.";
    const DESCRIPTION: &'static str = "";
    const ABOUT: &'static str = "Largest safe constant rate for a target elevation.";
    type Response = SafeRateResponse;
    fn parse(body: &[u8]) -> Result<Self, RequestError> {
        crate::contract::parse(body)
    }
    fn prepare(&self) -> Result<(), RequestError> {
        let model = self.system.model()?;
        let target = require_positive("target_elevation_m", self.params.target_elevation_m)?;
        let l0 = model.system.initial_length_m;
        if target <= l0 {
            return Err(InvalidInput::new(
                "target_elevation_m",
                format!("must be a finite length above initial_length_m = {l0} m, got {target}"),
            )
            .into());
        }
        Ok(())
    }
    fn check_sync(&self, _: &Limits) -> Result<(), RequestError> {
        self.system.model()?;
        Ok(())
    }
    fn run(&self, _: &dyn Progress) -> Result<SafeRateResponse, RequestError> {
        run::safe_rate(self)
    }
    fn estimate(&self) -> Estimate {
        E::new("target_elevation_m", est::SMALL_ANSWER)
    }
}

/// Every check of a string stability request that needs no solve.
pub fn prepare_stability(r: &StabilityRequest) -> Result<(), RequestError> {
    r.system.model()?;
    require_positive("state.length_m", r.params.state.length_m)?;
    require_finite("state.rate_m_s", r.params.state.rate_m_s)?;
    require_finite("state.acceleration_m_s2", r.params.state.acceleration_m_s2)?;
    if r.params.modes == 0 || r.params.modes > MAX_MODES {
        return Err(InvalidInput::new(
            "modes",
            format!("must be between 1 and {MAX_MODES}, got {}", r.params.modes),
        )
        .into());
    }
    Ok(())
}

/// The buoyancies of a string chart (the system's own when none is given).
fn buoyancies(r: &ChartRequest, sys: &crate::numerics::params::AerostatSystem) -> Vec<f64> {
    if r.params.net_buoyancies_n.is_empty() {
        vec![sys.net_buoyancy_n]
    } else {
        r.params.net_buoyancies_n.clone()
    }
}

/// Every check of a string chart that needs no solve.
pub fn prepare_chart(r: &ChartRequest) -> Result<(), RequestError> {
    let model = r.system.model()?;
    let points = run::chart_points(r);
    if points > MAX_CHART_POINTS {
        return Err(InvalidInput::new(
            "rates_m_s.count",
            format!("the chart would have {points} points; at most {MAX_CHART_POINTS} are allowed"),
        )
        .into());
    }
    r.params.rates_m_s.rates("rates_m_s").map(drop)?;
    chart::deployment_chart_with(
        &model.system,
        r.system.discretisation()?,
        &[],
        &buoyancies(r, &model.system),
        Parallelism::Serial,
        &|_, _| {},
    )?;
    Ok(())
}

/// Checks a string chart against the synchronous limits.
pub fn check_sync_chart(req: &ChartRequest, limits: &Limits) -> Result<(), RequestError> {
    let points = run::chart_points(req);
    let work = points.saturating_mul(req.system.model.mesh_elements());
    if points > limits.max_sync_chart_points {
        return Err(too_large(
            &req.params.rates_m_s.count_field("rates_m_s"),
            format!(
                "the chart has {points} points; synchronous charts have at most {}",
                limits.max_sync_chart_points
            ),
        ));
    }
    if work > limits.max_sync_chart_work {
        return Err(too_large(
            &req.params.rates_m_s.count_field("rates_m_s"),
            format!(
                "the chart has {points} points × {} elements = {work}; synchronous charts have at most {}",
                req.system.model.mesh_elements(),
                limits.max_sync_chart_work
            ),
        ));
    }
    Ok(())
}

/// The size of a string chart's answer.
pub fn chart_estimate(r: &ChartRequest) -> Estimate {
    let series = r.params.net_buoyancies_n.len().max(1) as f64;
    let points = series * r.params.rates_m_s.count() as f64;
    E::bytes(
        "rates_m_s.count",
        (est::CHART_BASE as f64)
            + series * est::PER_CHART_SERIES as f64
            + points * est::PER_CHART_POINT as f64,
    )
}

/// A string chart's items: its rates, each costing every buoyancy.
pub fn chart_items(r: &ChartRequest) -> Option<Items> {
    let series = r.params.net_buoyancies_n.len().max(1) as f64;
    let point = match r.system.discretisation().ok()? {
        Discretisation::Elements(n) => n as f64 * STRING_CHART_ELEMENT_POINT_S,
        _ => STRING_CHART_CONVERGED_POINT_S,
    };
    Some(Items {
        count: chart_rate_count(r),
        seconds_each: series * point,
        most_per_chunk: None,
    })
}
