//! How a synchronous route solves: one request, one answer, computed on the
//! global rayon pool while the handler awaits a oneshot (with a timeout).
//! At most `max_in_flight` solves run or wait at once; beyond: 503 +
//! Retry-After. The routes themselves, one per kind, are in
//! [`crate::api::kinds`].

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use axum::http::{StatusCode, header};
use axum::response::{IntoResponse, Response};

use crate::api::AppState;
use crate::api::error::ApiError;
use crate::config::Limits;
use crate::contract;

/// What a synchronous solve sees: the limits, and when its answer is no
/// longer wanted (the solve timeout has passed, or the caller went away).
pub(crate) struct SolveCtx {
    limits: Limits,
    end: std::time::Instant,
    abandoned: Arc<AtomicBool>,
    /// The priced work of all synchronous requests running now.
    priced: Arc<crate::contract::price::InFlight>,
}

impl std::ops::Deref for SolveCtx {
    type Target = Limits;
    fn deref(&self) -> &Limits {
        &self.limits
    }
}

impl SolveCtx {
    /// Charges a request's price ([`crate::contract::price`]): 422 `too_large`
    /// (naming the field, pointing to a `job_kind` job) past the
    /// synchronous budget; 503 with Retry-After while other priced work
    /// fills the pool; else the admission, held while the work runs.
    pub(crate) fn charge(
        &self,
        price: &crate::contract::price::Price,
        job_kind: &str,
    ) -> Result<crate::contract::price::Admitted<'_>, ApiError> {
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
                    crate::contract::price::IN_FLIGHT_CPU_S
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
