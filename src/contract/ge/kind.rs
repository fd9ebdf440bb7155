//! The analysis kinds whose body picks the cable model (`model.kind`:
//! the linear string or the geometrically exact cable): `stability`,
//! `critical`, `chart` and `frequency_response` ([`Analysis`] impls; the
//! linear string's checks are in [`crate::contract::string::kind`]).

use std::ops::Range;

use crate::contract::analysis::{Analysis, Items, to_json, too_large, validate_by_cancelled_run};
use crate::contract::error::{Progress, RequestError};
use crate::contract::estimate::{self as est, Estimate as E, Estimate};
use crate::contract::ge::charts::{
    self, AnyChartRequest, AnyChartResponse, AnyFrequencyResponseRequest,
    AnyFrequencyResponseResponse, GeChartPointOutput,
};
use crate::contract::ge::critical::{self, AnyCriticalRequest, AnyCriticalResponse};
use crate::contract::ge::stability::{self, AnyStabilityRequest, AnyStabilityResponse};
use crate::contract::price::Price;
use crate::contract::string::{chunks, kind as string, run};
use crate::contract::system::input::{ProfileInput, SystemInput};
use crate::limits::Limits;
use crate::numerics::parallel::Parallelism;

/// Elements a synchronous GE stability answer may have.
pub const MAX_SYNC_GE_STABILITY_ELEMENTS: usize = 100;
/// Elements a synchronous GE critical-time search may have.
pub const MAX_SYNC_GE_CRITICAL_ELEMENTS: usize = 40;
/// Points a synchronous GE chart may have.
pub const MAX_SYNC_GE_CHART_POINTS: usize = 8;
/// Frequencies a synchronous frequency response may have.
pub const MAX_SYNC_FREQUENCIES: usize = 16;

/// Seconds per element-step of a GE search, QEP checks included (measured:
/// 24 points of 10 elements, 6 100 steps in 0.48 s on one core), for sizing
/// chunks; a point is costed at its whole horizon, an upper bound (most
/// end at the onset).
const GE_ELEMENT_STEP_S: f64 = 8e-6;

fn limit_qep_elements(
    system: &SystemInput,
    limits: &Limits,
    why: &str,
) -> Result<(), RequestError> {
    let n = system.model.mesh_elements();
    if n > limits.max_sync_qep_elements {
        return Err(too_large(
            "model.elements",
            format!(
                "{why} with {n} elements takes too long to answer synchronously (at most {})",
                limits.max_sync_qep_elements
            ),
        ));
    }
    Ok(())
}

fn limit_ge_elements(n: usize, max: usize, why: &str) -> Result<(), RequestError> {
    if n > max {
        return Err(too_large(
            "model.elements",
            format!(
                "{why} with {n} elements takes too long to answer synchronously (at most {max}; submit a job)"
            ),
        ));
    }
    Ok(())
}

impl Analysis for AnyStabilityRequest {
    const NAME: &'static str = "stability";
    const SUMMARY: &'static str = "Eigenvalues and stability verdict at one deployment state.";
    const DESCRIPTION: &'static str = "Solves the quadratic eigenvalue problem λ²M + λC + K = 0 of the\n\
        discretised cable. `model.kind` picks the model: `linear_string`\n\
        (default; at most 400 elements synchronously) or\n\
        `geometrically_exact` (the straight quasi-static equilibrium at the\n\
        state's length, rate and acceleration, then the local QEP about it;\n\
        at most 100 elements synchronously).";
    const ABOUT: &'static str = "Eigenvalues and stability verdict at one state.";
    type Response = AnyStabilityResponse;
    fn parse(body: &[u8]) -> Result<Self, RequestError> {
        stability::parse_stability(body)
    }
    fn prepare(&self) -> Result<(), RequestError> {
        match self {
            Self::LinearString(r) => string::prepare_stability(r),
            Self::GeometricallyExact(r) => stability::validate_stability(r).map_err(Into::into),
        }
    }
    fn check_sync(&self, limits: &Limits) -> Result<(), RequestError> {
        match self {
            Self::LinearString(r) => {
                r.system.model()?;
                limit_qep_elements(&r.system, limits, "a stability analysis")
            }
            Self::GeometricallyExact(r) => limit_ge_elements(
                r.model.elements(),
                MAX_SYNC_GE_STABILITY_ELEMENTS,
                "a GE stability analysis",
            ),
        }
    }
    fn run(&self, _: &dyn Progress) -> Result<AnyStabilityResponse, RequestError> {
        stability::stability_any(self)
    }
    fn estimate(&self) -> Estimate {
        match self {
            Self::LinearString(r) => E::bytes(
                "modes",
                est::STABILITY_BASE as f64 + r.params.modes as f64 * est::PER_EIGENVALUE as f64,
            ),
            Self::GeometricallyExact(r) => E::new(
                "modes",
                est::STABILITY_BASE + r.modes as u64 * est::PER_EIGENVALUE,
            ),
        }
    }
}

impl Analysis for AnyCriticalRequest {
    const NAME: &'static str = "critical";
    const SUMMARY: &'static str =
        "Critical time t* and maximum safe elevation h* of a deployment profile.";
    const DESCRIPTION: &'static str = "With the closed-form continuum bound beside it. `model.kind` picks\n\
        the model: `linear_string` (default; QEP-based searches —\n\
        accelerating profiles, `confirm_with_qep` — take at most 400\n\
        elements synchronously) or `geometrically_exact` (a Newmark march\n\
        with local-stability checks, generalized-α by default, steps cut\n\
        on Newton failure; about a second at 20 elements, at most 40\n\
        elements synchronously; longer runs stop at the timeout: submit a\n\
        job with `\"kind\": \"critical\"`).";
    const ABOUT: &'static str = "Critical time and maximum safe elevation of a deployment profile.";
    type Response = AnyCriticalResponse;
    fn parse(body: &[u8]) -> Result<Self, RequestError> {
        critical::parse_critical(body)
    }
    fn prepare(&self) -> Result<(), RequestError> {
        match self {
            Self::LinearString(r) => run::check_critical(r),
            Self::GeometricallyExact(r) => {
                critical::prepare_critical(r).map(drop).map_err(Into::into)
            }
        }
    }
    fn check_sync(&self, limits: &Limits) -> Result<(), RequestError> {
        match self {
            Self::LinearString(r) => {
                r.system.model()?;
                if r.params.confirm_with_qep
                    || matches!(r.params.profile, ProfileInput::ConstantAcceleration { .. })
                {
                    limit_qep_elements(&r.system, limits, "a QEP-based critical-time search")?;
                }
                Ok(())
            }
            Self::GeometricallyExact(r) => limit_ge_elements(
                r.model.elements(),
                MAX_SYNC_GE_CRITICAL_ELEMENTS,
                "a GE critical-time search",
            ),
        }
    }
    fn run(&self, progress: &dyn Progress) -> Result<AnyCriticalResponse, RequestError> {
        match self {
            Self::LinearString(r) => {
                run::critical_with(r, progress).map(AnyCriticalResponse::LinearString)
            }
            Self::GeometricallyExact(r) => critical::ge_critical(r, progress)
                .map(|r| AnyCriticalResponse::GeometricallyExact(Box::new(r))),
        }
    }
    fn estimate(&self) -> Estimate {
        E::new("profile", est::SMALL_ANSWER)
    }
}

impl Analysis for AnyChartRequest {
    const NAME: &'static str = "chart";
    const SUMMARY: &'static str = "Deployment chart: t* and h* against rate, one series per buoyancy\n\
        (and, for the GE cable, per stiffness ratio, perturbation and wind\n\
        amplitude).";
    const DESCRIPTION: &'static str = "`model.kind` picks the model: `linear_string` (default) or\n\
        `geometrically_exact` (with `stiffness_ratios`). Linear string:\n\
        synchronously at most 20 000 points and 2 000 000 points × elements;\n\
        larger charts (up to 1 000 000 points) go to `POST /api/v1/jobs`\n\
        with `\"kind\": \"chart\"`. GE: each point is a Newmark march with\n\
        local-stability checks (about a second at 20 elements), so at most\n\
        8 points synchronously; up to 2 000 as a job.";
    const ABOUT: &'static str = "Deployment chart: t* and h* against rate, one series per buoyancy (`model.kind = \"geometrically_exact\"`: and per stiffness ratio).";
    type Response = AnyChartResponse;
    fn parse(body: &[u8]) -> Result<Self, RequestError> {
        charts::parse_chart(body)
    }
    fn prepare(&self) -> Result<(), RequestError> {
        match self {
            Self::LinearString(r) => string::prepare_chart(r),
            Self::GeometricallyExact(r) => charts::prepare_chart(r).map(drop).map_err(Into::into),
        }
    }
    fn check_sync(&self, limits: &Limits) -> Result<(), RequestError> {
        match self {
            Self::LinearString(r) => {
                r.system.model()?;
                string::check_sync_chart(r, limits)
            }
            Self::GeometricallyExact(r) => {
                let points = charts::chart_points(r);
                if points > MAX_SYNC_GE_CHART_POINTS {
                    return Err(too_large(
                        "rates_m_s.count",
                        format!(
                            "the GE chart has {points} points; synchronous GE charts have at most {MAX_SYNC_GE_CHART_POINTS} (submit a job with \"kind\": \"chart\")"
                        ),
                    ));
                }
                Ok(())
            }
        }
    }
    fn price(&self) -> Option<Price> {
        match self {
            Self::LinearString(r) => crate::contract::string::price::chart(r),
            Self::GeometricallyExact(r) => crate::contract::ge::price::chart(r),
        }
    }
    fn run(&self, progress: &dyn Progress) -> Result<AnyChartResponse, RequestError> {
        match self {
            Self::LinearString(r) => {
                run::chart(r, Parallelism::Rayon, progress).map(AnyChartResponse::LinearString)
            }
            Self::GeometricallyExact(r) => charts::ge_chart(r, Parallelism::Rayon, progress)
                .map(AnyChartResponse::GeometricallyExact),
        }
    }
    fn estimate(&self) -> Estimate {
        match self {
            Self::LinearString(r) => string::chart_estimate(r),
            Self::GeometricallyExact(r) => {
                let points = charts::prepare_chart(r).map_or(0, |c| c.point_count()) as f64;
                E::bytes(
                    "rates_m_s",
                    est::CHART_BASE as f64
                        + points * (est::PER_GE_CHART_POINT + est::PER_CHART_SERIES) as f64,
                )
            }
        }
    }
    /// A GE chart by point, a string chart by rate.
    fn items(&self) -> Option<Items> {
        match self {
            Self::LinearString(r) => string::chart_items(r),
            Self::GeometricallyExact(r) => {
                let core = charts::prepare_chart(r).ok()?;
                let steps = core.config.horizon_s / core.config.time_step_s;
                Some(Items {
                    count: core.point_count(),
                    seconds_each: steps * core.system.elements as f64 * GE_ELEMENT_STEP_S,
                    most_per_chunk: None,
                })
            }
        }
    }
    fn run_items(
        &self,
        range: Range<usize>,
        progress: &dyn Progress,
    ) -> Result<String, RequestError> {
        match self {
            Self::LinearString(r) => chunks::chart_chunk(r, range, Parallelism::Rayon, progress),
            Self::GeometricallyExact(r) => to_json(&charts::ge_chart_points(
                r,
                range,
                Parallelism::Rayon,
                progress,
            )?),
        }
    }
    fn assemble(&self, parts: &[String]) -> Result<String, RequestError> {
        match self {
            Self::LinearString(r) => to_json(&chunks::chart_from_chunks(r, parts)?),
            Self::GeometricallyExact(r) => {
                let mut points = Vec::new();
                for part in parts {
                    let chunk: Vec<GeChartPointOutput> = serde_json::from_str(part)
                        .map_err(|e| RequestError::Malformed(format!("a chunk result: {e}")))?;
                    points.extend(chunk);
                }
                to_json(&charts::ge_chart_assemble(r, points)?)
            }
        }
    }
}

impl Analysis for AnyFrequencyResponseRequest {
    const NAME: &'static str = "frequency_response";
    const SUMMARY: &'static str = "Response against forcing frequency: wind on the linear string, or\n\
        (`\"excitation\": \"base\"`) a shaken platform under the GE cable.";
    const DESCRIPTION: &'static str = "Wind: one transient run per frequency of u = U0 sin(ω t), envelope\n\
        of the tip amplitude against ω and time. Base: one run per ω0 of\n\
        r = R0 sin(ω0 t), amplitude gain (thesis (8.3)) with the two-DOF\n\
        model's resonance bands (8.9). Synchronously at most 16\n\
        frequencies; more go to `POST /api/v1/jobs` with\n\
        `\"kind\": \"frequency_response\"`.";
    const ABOUT: &'static str = "Response against forcing frequency: wind on the linear string, or `\"excitation\": \"base\"` (shaken platform, GE cable).";
    type Response = AnyFrequencyResponseResponse;
    fn parse(body: &[u8]) -> Result<Self, RequestError> {
        charts::parse_frequency_response(body)
    }
    fn prepare(&self) -> Result<(), RequestError> {
        validate_by_cancelled_run(|p| charts::frequency_response_any(self, Parallelism::Serial, p))
    }
    fn check_sync(&self, _: &Limits) -> Result<(), RequestError> {
        let count = match self {
            Self::Wind(r) => r.frequencies_rad_s.count(),
            Self::Base(r) => r.frequencies_rad_s.count(),
        };
        if count > MAX_SYNC_FREQUENCIES {
            return Err(too_large(
                "frequencies_rad_s.count",
                format!(
                    "{count} frequencies take too long to answer synchronously (at most {MAX_SYNC_FREQUENCIES})"
                ),
            ));
        }
        Ok(())
    }
    fn price(&self) -> Option<Price> {
        match self {
            Self::Wind(r) => crate::contract::transient::price::frequency_response(r),
            Self::Base(r) => crate::contract::ge::price::base_frequency_response(r),
        }
    }
    fn run(&self, progress: &dyn Progress) -> Result<AnyFrequencyResponseResponse, RequestError> {
        charts::frequency_response_any(self, Parallelism::Rayon, progress)
    }
    fn estimate(&self) -> Estimate {
        match self {
            Self::Wind(r) => {
                let f = r.params.frequencies_rad_s.count() as f64;
                let n = r.params.samples as f64;
                E::bytes(
                    "frequencies_rad_s.count",
                    est::SIMULATE_BASE as f64 + (f * (n + 4.0) + n) * est::PER_NUMBER as f64,
                )
            }
            Self::Base(r) => E::bytes(
                "frequencies_rad_s.count",
                est::SIMULATE_BASE as f64
                    + r.frequencies_rad_s.count() as f64 * est::PER_BASE_POINT as f64,
            ),
        }
    }
}
