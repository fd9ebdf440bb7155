//! The synchronous routes: one request, one answer, computed on the global
//! rayon pool while the handler awaits a oneshot (with a timeout). At most
//! `max_in_flight` solves run or wait at once; beyond: 503 + Retry-After.
//! Requests too large to answer in about a second are refused (422,
//! `too_large`) with a pointer to the job queue.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use axum::extract::State;
use axum::http::{StatusCode, header};
use axum::response::{IntoResponse, Response};
use serde::Serialize;

use crate::api::AppState;
use crate::api::error::{ApiError, JsonBody};
use crate::config::Limits;
use crate::contract;
use crate::contract::dto::*;
use crate::contract::ge_charts::{
    self, AnyChartRequest, AnyChartResponse, AnyFrequencyResponseRequest,
    AnyFrequencyResponseResponse,
};
use crate::contract::ge_critical::{
    self, AnyCriticalRequest, AnyCriticalResponse, AnyStabilityRequest, AnyStabilityResponse,
};
use crate::contract::run;
use crate::contract::simulate::{self, AnySimulateRequest, AnySimulateResponse};
use crate::numerics::chart::Parallelism;

/// What a synchronous solve sees: the limits, and when its answer is no
/// longer wanted (the solve timeout has passed, or the caller went away).
pub(crate) struct SolveCtx {
    limits: Limits,
    end: std::time::Instant,
    abandoned: Arc<AtomicBool>,
    /// The priced work of all synchronous requests running now.
    priced: Arc<crate::price::InFlight>,
}

impl std::ops::Deref for SolveCtx {
    type Target = Limits;
    fn deref(&self) -> &Limits {
        &self.limits
    }
}

impl SolveCtx {
    /// Charges a request's price ([`crate::price`]): 422 `too_large`
    /// (naming the field, pointing to a `job_kind` job) past the
    /// synchronous budget; 503 with Retry-After while other priced work
    /// fills the pool; else the admission, held while the work runs.
    pub(crate) fn charge(
        &self,
        price: &crate::price::Price,
        job_kind: &str,
    ) -> Result<crate::price::Admitted<'_>, ApiError> {
        if !price.fits() {
            return Err(ApiError::too_large(&price.field, price.refusal(job_kind)));
        }
        self.priced.admit(price).map_err(|running| {
            ApiError::new(
                StatusCode::SERVICE_UNAVAILABLE,
                "overloaded",
                None,
                format!(
                    "this request costs about {:.1} CPU-seconds and {running:.1} CPU-seconds of other \
                     synchronous work are running (at most {} at once); retry shortly or submit a job",
                    price.cpu_s,
                    crate::price::IN_FLIGHT_CPU_S
                ),
            )
            .retry_after(1)
        })
    }

    /// Has the caller had its 504 or gone away?
    pub(crate) fn abandoned(&self) -> bool {
        self.abandoned.load(Ordering::Relaxed) || std::time::Instant::now() >= self.end
    }
}

/// Marks the solve abandoned when the handler's future ends: after its
/// answer (harmless), its 504, or when hyper drops it because the client
/// closed the connection.
struct AbandonOnDrop(Arc<AtomicBool>);

impl Drop for AbandonOnDrop {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Relaxed);
    }
}

impl AppState {
    /// Runs `work` on the rayon pool; the in-flight permit is held until the
    /// work ends (even if the caller has timed out), so the bound is real.
    /// Work whose caller has gone (504 or closed connection) is not started,
    /// and long work polls [`SolveCtx::abandoned`] through its [`Deadline`]
    /// progress, so the permit comes back within a bounded time.
    pub(crate) async fn solve(
        &self,
        work: impl FnOnce(&SolveCtx) -> Result<Vec<u8>, ApiError> + Send + 'static,
    ) -> Result<Response, ApiError> {
        let permit = self.solves.clone().try_acquire_owned().map_err(|_| {
            ApiError::new(
                StatusCode::SERVICE_UNAVAILABLE,
                "overloaded",
                None,
                format!(
                    "{} solves are already in flight; retry shortly",
                    self.limits.max_in_flight
                ),
            )
            .retry_after(1)
        })?;
        let (tx, rx) = tokio::sync::oneshot::channel();
        let abandoned = Arc::new(AtomicBool::new(false));
        let _abandon_on_drop = AbandonOnDrop(abandoned.clone());
        let ctx = SolveCtx {
            limits: self.limits.clone(),
            end: std::time::Instant::now() + self.limits.solve_timeout,
            abandoned,
            priced: self.priced.clone(),
        };
        let span = tracing::Span::current();
        rayon::spawn(move || {
            let _permit = permit;
            let _enter = span.enter();
            if ctx.abandoned() {
                tracing::debug!("solve abandoned before it started");
                return;
            }
            let started = std::time::Instant::now();
            let out = catch_unwind(AssertUnwindSafe(|| work(&ctx)))
                .unwrap_or_else(|_| Err(ApiError::internal("the solver panicked")));
            if ctx.abandoned() {
                tracing::info!(
                    ran_s = started.elapsed().as_secs_f64(),
                    "abandoned solve stopped (timeout or caller gone)"
                );
            }
            let _ = tx.send(out);
        });
        let timeout = self.limits.solve_timeout;
        let timed_out = || {
            ApiError::new(
                StatusCode::GATEWAY_TIMEOUT,
                "timeout",
                None,
                format!(
                    "no answer within {:.1} s; submit it as a batch job instead: POST /api/v1/jobs",
                    timeout.as_secs_f64()
                ),
            )
        };
        let body = match tokio::time::timeout(timeout, rx).await {
            // A solve stopped by its own deadline answers as the timeout it is.
            Ok(Ok(Err(e))) if e.body.error.code == "cancelled" => return Err(timed_out()),
            Ok(Ok(out)) => out?,
            Ok(Err(_)) => return Err(timed_out()),
            Err(_) => return Err(timed_out()),
        };
        Ok((
            StatusCode::OK,
            [(header::CONTENT_TYPE, "application/json")],
            body,
        )
            .into_response())
    }
}

/// The answer as JSON; never one holding a non-finite number (422).
fn to_json(value: &impl Serialize) -> Result<Vec<u8>, ApiError> {
    Ok(contract::finite::to_vec(value)?)
}

fn limit_qep_elements(system: &SystemInput, limits: &Limits, why: &str) -> Result<(), ApiError> {
    let n = system.model.mesh_elements();
    if n > limits.max_sync_qep_elements {
        return Err(ApiError::too_large(
            "model.elements",
            format!(
                "{why} with {n} elements takes too long to answer synchronously (at most {})",
                limits.max_sync_qep_elements
            ),
        ));
    }
    Ok(())
}

/// Checks a chart against the synchronous limits.
pub fn check_sync_chart(req: &ChartRequest, limits: &Limits) -> Result<(), ApiError> {
    let points = run::chart_points(req);
    let work = points.saturating_mul(req.system.model.mesh_elements());
    if points > limits.max_sync_chart_points {
        return Err(ApiError::too_large(
            &req.params.rates_m_s.count_field("rates_m_s"),
            format!(
                "the chart has {points} points; synchronous charts have at most {}",
                limits.max_sync_chart_points
            ),
        ));
    }
    if work > limits.max_sync_chart_work {
        return Err(ApiError::too_large(
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

/// Progress that gives up once the solve timeout has passed or the caller
/// has gone away, so an abandoned request stops using the CPU.
pub(crate) struct Deadline {
    end: std::time::Instant,
    abandoned: Arc<AtomicBool>,
}

impl Deadline {
    pub(crate) fn after(ctx: &SolveCtx) -> Self {
        Self {
            end: ctx.end,
            abandoned: ctx.abandoned.clone(),
        }
    }
}

impl contract::Progress for Deadline {
    fn report(&self, _: usize, _: usize) {}
    fn cancelled(&self) -> bool {
        self.abandoned.load(Ordering::Relaxed) || std::time::Instant::now() >= self.end
    }
}

/// A synchronous route: parse, check the synchronous limits, solve; with
/// its OpenAPI operation (every status listed).
macro_rules! solve_path {
    ($(#[$doc:meta])* $name:ident, $path:literal, $req:ty, $resp:ty, |$r:ident, $limits:ident| $body:expr) => {
        solve_path!($(#[$doc])* $name, $path, $req, $resp, parse = |body| {
            let req: $req = contract::parse(body)?;
            // The system's own errors (elements out of range…) come
            // before the synchronous limits.
            req.system.model().map_err(contract::RequestError::from)?;
            Ok::<$req, contract::RequestError>(req)
        }, |$r, $limits| $body);
    };
    ($(#[$doc:meta])* $name:ident, $path:literal, $req:ty, $resp:ty, parse = |$b:ident| $parse:expr, |$r:ident, $limits:ident| $body:expr) => {
        $(#[$doc])*
        #[utoipa::path(
            post, path = $path, tag = "solve",
            request_body(content = $req, description = "The system and the question (SI units)"),
            responses(
                (status = 200, description = "The answer", body = $resp),
                (status = 400, description = "Malformed JSON", body = ErrorBody),
                (status = 413, description = "Body larger than the limit", body = ErrorBody),
                (status = 415, description = "Content type is not JSON", body = ErrorBody),
                (status = 422, description = "Invalid input (`invalid_input`) or too large for a synchronous answer (`too_large`: use /api/v1/jobs); `field` names the culprit", body = ErrorBody),
                (status = 500, description = "Numerical failure on valid input (a bug)", body = ErrorBody),
                (status = 503, description = "Too many solves in flight", body = ErrorBody,
                    headers(("Retry-After" = u32, description = "Seconds to wait before retrying"))),
                (status = 504, description = "No answer within the solve timeout", body = ErrorBody),
            )
        )]
        pub async fn $name(
            State(app): State<AppState>,
            axum::Extension(caller): axum::Extension<crate::api::auth::Caller>,
            JsonBody(body): JsonBody,
        ) -> Result<Response, ApiError> {
            let resolver = app.clone();
            app.solve(move |$limits: &SolveCtx| {
                // A named system is merged in before the body is parsed.
                let resolved = resolver.resolve_body(&caller, &body)?;
                let $b: &[u8] = resolved.as_deref().unwrap_or(&body);
                let $r: $req = $parse?;
                $body
            })
            .await
        }
    };
}
pub(crate) use solve_path;

solve_path!(
    /// Eigenvalues and stability verdict at one deployment state.
    ///
    /// Solves the quadratic eigenvalue problem λ²M + λC + K = 0 of the
    /// discretised cable. `model.kind` picks the model: `linear_string`
    /// (default; at most 400 elements synchronously) or
    /// `geometrically_exact` (the straight quasi-static equilibrium at the
    /// state's length, rate and acceleration, then the local QEP about it;
    /// at most 100 elements synchronously).
    compute_stability, "/api/v1/stability", AnyStabilityRequest, AnyStabilityResponse,
    parse = |body| ge_critical::parse_stability(body),
    |req, limits| match &req {
        AnyStabilityRequest::LinearString(req) => {
            req.system.model().map_err(contract::RequestError::from)?;
            limit_qep_elements(&req.system, limits, "a stability analysis")?;
            to_json(&run::stability(req)?)
        }
        AnyStabilityRequest::GeometricallyExact(r) => {
            limit_ge_elements(r.model.elements(), MAX_SYNC_GE_STABILITY_ELEMENTS, "a GE stability analysis")?;
            to_json(&ge_critical::ge_stability(r)?)
        }
    }
);

solve_path!(
    /// Critical time t* and maximum safe elevation h* of a deployment profile.
    ///
    /// With the closed-form continuum bound beside it. `model.kind` picks
    /// the model: `linear_string` (default; QEP-based searches —
    /// accelerating profiles, `confirm_with_qep` — take at most 400
    /// elements synchronously) or `geometrically_exact` (a Newmark march
    /// with local-stability checks, generalized-α by default, steps cut
    /// on Newton failure; about a second at 20 elements, at most 40
    /// elements synchronously; longer runs stop at the timeout: submit a
    /// job with `"kind": "critical"`).
    compute_critical, "/api/v1/critical", AnyCriticalRequest, AnyCriticalResponse,
    parse = |body| ge_critical::parse_critical(body),
    |req, limits| match &req {
        AnyCriticalRequest::LinearString(req) => {
            req.system.model().map_err(contract::RequestError::from)?;
            if req.params.confirm_with_qep || matches!(req.params.profile, ProfileInput::ConstantAcceleration { .. }) {
                limit_qep_elements(&req.system, limits, "a QEP-based critical-time search")?;
            }
            to_json(&run::critical_with(req, &Deadline::after(limits))?)
        }
        AnyCriticalRequest::GeometricallyExact(r) => {
            limit_ge_elements(r.model.elements(), MAX_SYNC_GE_CRITICAL_ELEMENTS, "a GE critical-time search")?;
            to_json(&ge_critical::ge_critical(r, &Deadline::after(limits))?)
        }
    }
);

/// Elements a synchronous GE stability answer may have.
pub const MAX_SYNC_GE_STABILITY_ELEMENTS: usize = 100;
/// Elements a synchronous GE critical-time search may have.
pub const MAX_SYNC_GE_CRITICAL_ELEMENTS: usize = 40;

fn limit_ge_elements(n: usize, max: usize, why: &str) -> Result<(), ApiError> {
    if n > max {
        return Err(ApiError::too_large(
            "model.elements",
            format!(
                "{why} with {n} elements takes too long to answer synchronously (at most {max}; submit a job)"
            ),
        ));
    }
    Ok(())
}

solve_path!(
    /// Largest safe constant winch rate to reach a target elevation.
    compute_safe_rate, "/api/v1/safe-rate", SafeRateRequest, SafeRateResponse,
    |req, _limits| to_json(&run::safe_rate(&req)?)
);

solve_path!(
    /// Deployment chart: t* and h* against rate, one series per buoyancy
    /// (and, for the GE cable, per stiffness ratio, perturbation and wind
    /// amplitude).
    ///
    /// `model.kind` picks the model: `linear_string` (default) or
    /// `geometrically_exact` (with `stiffness_ratios`). Linear string:
    /// synchronously at most 20 000 points and 2 000 000 points × elements;
    /// larger charts (up to 1 000 000 points) go to `POST /api/v1/jobs`
    /// with `"kind": "chart"`. GE: each point is a Newmark march with
    /// local-stability checks (about a second at 20 elements), so at most
    /// 8 points synchronously; up to 2 000 as a job.
    create_chart, "/api/v1/charts", AnyChartRequest, AnyChartResponse,
    parse = |body| ge_charts::parse_chart(body),
    |req, limits| match &req {
        AnyChartRequest::LinearString(r) => {
            r.system.model().map_err(contract::RequestError::from)?;
            check_sync_chart(r, limits)?;
            to_json(&run::chart(r, Parallelism::Rayon, &Deadline::after(limits))?)
        }
        AnyChartRequest::GeometricallyExact(r) => {
            let points = ge_charts::chart_points(r);
            if points > MAX_SYNC_GE_CHART_POINTS {
                return Err(ApiError::too_large(
                    "rates_m_s.count",
                    format!(
                        "the GE chart has {points} points; synchronous GE charts have at most {MAX_SYNC_GE_CHART_POINTS} (submit a job with \"kind\": \"chart\")"
                    ),
                ));
            }
            to_json(&ge_charts::ge_chart(r, Parallelism::Rayon, &Deadline::after(limits))?)
        }
    }
);

/// Points a synchronous GE chart may have.
pub const MAX_SYNC_GE_CHART_POINTS: usize = 8;

solve_path!(
    /// Transient run of either cable model: tip deflection, energy and
    /// eigenvalues along a deployment, with wind on the aerostat.
    ///
    /// `model.kind` picks the model: `linear_string` (default) or
    /// `geometrically_exact`. Runs longer than the solve timeout are
    /// stopped (504): submit them as jobs with `"kind": "simulate"`.
    run_simulation, "/api/v1/simulate", AnySimulateRequest, AnySimulateResponse,
    parse = |body| simulate::parse_simulate(body),
    |req, limits| to_json(&simulate::simulate_any(&req, &Deadline::after(limits))?)
);

solve_path!(
    /// Response against forcing frequency: wind on the linear string, or
    /// (`"excitation": "base"`) a shaken platform under the GE cable.
    ///
    /// Wind: one transient run per frequency of u = U0 sin(ω t), envelope
    /// of the tip amplitude against ω and time. Base: one run per ω0 of
    /// r = R0 sin(ω0 t), amplitude gain (thesis (8.3)) with the two-DOF
    /// model's resonance bands (8.9). Synchronously at most 16
    /// frequencies; more go to `POST /api/v1/jobs` with
    /// `"kind": "frequency_response"`.
    compute_frequency_response, "/api/v1/frequency-response", AnyFrequencyResponseRequest, AnyFrequencyResponseResponse,
    parse = |body| ge_charts::parse_frequency_response(body),
    |req, limits| {
        let count = match &req {
            AnyFrequencyResponseRequest::Wind(r) => r.frequencies_rad_s.count(),
            AnyFrequencyResponseRequest::Base(r) => r.frequencies_rad_s.count(),
        };
        if count > MAX_SYNC_FREQUENCIES {
            return Err(ApiError::too_large(
                "frequencies_rad_s.count",
                format!(
                    "{count} frequencies take too long to answer synchronously (at most {MAX_SYNC_FREQUENCIES})"
                ),
            ));
        }
        to_json(&ge_charts::frequency_response_any(&req, Parallelism::Rayon, &Deadline::after(limits))?)
    }
);

/// Frequencies a synchronous frequency response may have.
pub const MAX_SYNC_FREQUENCIES: usize = 16;

solve_path!(
    /// The fastest safe deployment (or retrieval) schedule (SPEC §7).
    ///
    /// Every instant stable with the lift reserve, within the winch limits
    /// and the tension rating; the time saved against the best
    /// constant-rate plan; the schedule run on the FE string; with a wind
    /// forecast, the haul-down deadline. `feasible: false` names the
    /// binding limit.
    compute_plan, "/api/v1/plan", crate::contract::plan::PlanRequest, crate::contract::plan::PlanResponse,
    parse = |body| contract::plan::parse_plan(body),
    |req, limits| to_json(&contract::plan::plan(&req, &Deadline::after(limits))?)
);

/// Chart points (samples × rates) a synchronous bands request may have.
pub const MAX_SYNC_BAND_EVALUATIONS: usize = 200_000;
/// Synchronous bands work on a fixed mesh: points × elements.
pub const MAX_SYNC_BAND_WORK: usize = 20_000_000;

solve_path!(
    /// Uncertainty bands of a deployment chart (SPEC §8): 5/50/95 % points
    /// of h* and t* at each rate under uncertain inputs, each with its
    /// sampling error, and the probability that a target elevation is
    /// unsafe.
    ///
    /// Seeded Monte Carlo: sample i draws from its own stream of
    /// (seed, i), so the answer is identical at any thread count.
    /// Synchronously at most 200 000 chart points (samples × rates); up
    /// to 2 000 000 as a job with `"kind": "bands"`.
    compute_bands, "/api/v1/bands", crate::contract::bands::BandsRequest, crate::contract::bands::BandsResponse,
    parse = |body| contract::bands::parse_bands(body),
    |req, limits| {
        let points = contract::bands::evaluations(&req);
        let work = points.saturating_mul(req.system.model.mesh_elements());
        if points > MAX_SYNC_BAND_EVALUATIONS || work > MAX_SYNC_BAND_WORK {
            return Err(ApiError::too_large(
                "uncertainty.samples",
                format!(
                    "{points} chart points (samples × rates) on {} elements take too long to answer synchronously (at most {MAX_SYNC_BAND_EVALUATIONS} points and {MAX_SYNC_BAND_WORK} points × elements): submit a job with \"kind\": \"bands\"",
                    req.system.model.mesh_elements()
                ),
            ));
        }
        to_json(&contract::bands::bands(&req, Parallelism::Rayon, &Deadline::after(limits))?)
    }
);
