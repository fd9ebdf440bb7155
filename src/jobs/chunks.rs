//! Chunked jobs: one engine for every store.
//!
//! A large job (a GE or string chart, a bands, plan bands or envelope
//! bands request, a batch) is a list of independent items (chart points
//! or rates, Monte Carlo samples, requests). The worker that claims such a
//! job (its *coordinator*) splits it into chunks of consecutive items
//! ([`ChunkPlan`], a few seconds of work each), stored as rows keyed by
//! (job, index). Any worker of any process claims a pending chunk under a
//! lease of its own ([`ChunkLease`]: owner, expiry, epoch), renews it while
//! the chunk runs and writes the chunk's result fenced by it: a result is
//! written once per (job, index), by the holder of the current lease, and
//! a chunk whose worker died is claimed again once its lease expired. The
//! coordinator runs chunks of its job too; when every chunk is done it
//! assembles their results, in index order, into the job's answer, the
//! same JSON as the single-process run. Progress counts chunks;
//! cancelling the job stops its pending chunks (only chunks of running
//! jobs are claimed) and its running ones: between lease renewals a
//! running chunk reads its job's status every [`CANCEL_POLL`] and stops
//! once the job is no longer running (cancelled, failed, gone).
//!
//! If the coordinator dies, its job lease expires and another worker (of
//! any process) becomes the coordinator and assembles the answer; the
//! chunks already done are kept. Such a takeover, while chunks remain, is
//! not counted against the job's limit of attempts (`chunk_takeovers`
//! counts it apart): the chunks count their own
//! (the coordinator's death while it ran a chunk is that chunk's attempt),
//! so a job dies of a chunk that kills its process every time, not of its
//! coordinators' deaths. A job that ends (failed, cancelled) hands its
//! running chunks back to `pending`, where nothing claims them.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

pub use super::backend::{ChunkLease, ChunkState, ClaimedChunk};
use super::backend::{ClaimPolicy, JobStatus, StoreError};
use super::kinds::JobSubmission;
use super::queue::{JobQueue, error_json};
pub use super::split::{
    CHUNK_TARGET_S, ChunkPlan, MAX_ITEMS_PER_CHUNK, MIN_CHUNKS, MIN_SPLIT_JOB_S,
};
use crate::contract::error::ErrorBody;
use crate::contract::{Progress, RequestError};

/// How often a running chunk looks at its job's status between lease
/// renewals (one `SELECT status` by primary key): a cancelled job's
/// running chunks stop within about this long, on any store and in any
/// process, instead of at the next renewal (a third of the lease).
pub const CANCEL_POLL: Duration = Duration::from_millis(200);
/// How often an idle coordinator looks at its chunks.
const COORDINATOR_POLL: Duration = Duration::from_millis(50);

/// Runs a chunked job as its coordinator: creates its chunks, runs those
/// it can claim, and assembles the answer when every chunk is done. When a
/// chunk failed (or the store did), its error body goes to `failure` and
/// the answer is `Err(Cancelled)`.
pub(super) fn coordinate(
    queue: &JobQueue,
    lease: &super::lease::Lease,
    submission: &JobSubmission,
    plan: ChunkPlan,
    progress: &dyn Progress,
    failure: &std::sync::Mutex<Option<String>>,
) -> Result<String, RequestError> {
    let fail = |body: String| {
        *failure.lock().unwrap_or_else(|e| e.into_inner()) = Some(body);
        RequestError::Cancelled
    };
    let store_err = |e: StoreError| {
        fail(error_json(ErrorBody::new(
            "internal",
            None,
            format!("the job store failed while the chunks of this job ran: {e}"),
        )))
    };
    let store = &queue.store;
    let total = plan.count();
    if !store.create_chunks(lease, total).map_err(store_err)? {
        return Err(RequestError::Cancelled);
    }
    let mut iterations: u64 = 0;
    loop {
        iterations += 1;
        if iterations > MAX_COORDINATOR_LOOPS {
            return Err(fail(error_json(ErrorBody::new(
                "internal",
                None,
                "the chunks of this job did not finish within the coordinator's loop limit",
            ))));
        }
        if progress.cancelled() {
            return Err(RequestError::Cancelled);
        }
        let state = store.chunk_state(lease.job_id).map_err(store_err)?;
        if let Some(error) = state.failed {
            return Err(fail(error));
        }
        progress.report(state.done, total);
        if state.done >= total {
            let parts = store.chunk_results(lease.job_id).map_err(store_err)?;
            let indices: Vec<usize> = parts.iter().map(|(i, _)| *i).collect();
            if indices != (0..total).collect::<Vec<_>>() {
                return Err(fail(error_json(ErrorBody::new(
                    "internal",
                    None,
                    format!("chunk results {indices:?} are not exactly 0..{total}"),
                ))));
            }
            let parts: Vec<String> = parts.into_iter().map(|(_, r)| r).collect();
            return submission.assemble(plan, &parts);
        }
        match execute_chunk(queue, Some(lease.job_id)).map_err(store_err)? {
            Some(_) => {}
            None => std::thread::sleep(COORDINATOR_POLL),
        }
    }
}

/// Polls of one coordinator at most (at 50 ms, more than 50 days).
const MAX_COORDINATOR_LOOPS: u64 = 100_000_000;

/// Where a chunk ended, for the caller.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ChunkOutcome {
    Done,
    Failed,
    /// Lease lost (taken over, job cancelled) or handed back at shutdown.
    Stopped,
}

/// Stop signals of one running chunk.
struct ChunkControl<'a> {
    queue: &'a JobQueue,
    lost: AtomicBool,
    started: Instant,
}

impl Progress for ChunkControl<'_> {
    fn report(&self, _: usize, _: usize) {}
    fn cancelled(&self) -> bool {
        self.lost.load(Ordering::Relaxed)
            || self.queue.is_shut_down()
            || self.started.elapsed() > self.queue.limits.max_job_run_time
    }
}

/// Claims one pending chunk (of `job` only, when given) and runs it to its
/// end; None when there was none to claim.
pub fn execute_chunk(
    queue: &JobQueue,
    job: Option<i64>,
) -> Result<Option<(ChunkLease, ChunkOutcome)>, StoreError> {
    let limits = &queue.limits;
    let exhausted = error_json(ErrorBody::new(
        "attempts_exhausted",
        None,
        format!(
            "a chunk of the job was started {} times and each time the process running it \
             stopped before it finished (crash, out of memory or kill); the job is failed",
            limits.max_job_attempts
        ),
    ));
    let policy = ClaimPolicy {
        lease: limits.job_lease,
        max_attempts: limits.max_job_attempts,
        exhausted_error: &exhausted,
    };
    let Some(chunk) = queue.store.claim_chunk(job, &policy)? else {
        return Ok(None);
    };
    let lease = chunk.lease.clone();
    let span = tracing::info_span!(
        "chunk",
        job = lease.job_id,
        index = lease.index,
        attempt = chunk.attempts
    );
    let _enter = span.enter();
    let ctl = ChunkControl {
        queue,
        lost: AtomicBool::new(false),
        started: Instant::now(),
    };
    let outcome = std::thread::scope(|scope| {
        let (stop, stopped) = std::sync::mpsc::channel::<()>();
        let (ctl, lease) = (&ctl, &lease);
        scope.spawn(move || {
            let every = limits.job_lease / 3;
            let poll = CANCEL_POLL.min(every);
            let mut renewed = Instant::now();
            while let Err(std::sync::mpsc::RecvTimeoutError::Timeout) = stopped.recv_timeout(poll) {
                if renewed.elapsed() < every {
                    // Between renewals: a cheap look at the job's status, so
                    // that a cancellation stops the chunk within `poll`.
                    match queue.store.status(lease.job_id) {
                        Ok(Some(JobStatus::Running)) => {}
                        Ok(status) => {
                            tracing::info!(?status, "job no longer running: the chunk stops here");
                            ctl.lost.store(true, Ordering::Relaxed);
                            return;
                        }
                        Err(e) => tracing::warn!(error = %e, "job status not read"),
                    }
                    continue;
                }
                renewed = Instant::now();
                match queue.store.renew_chunk(lease, limits.job_lease) {
                    Ok(true) => {}
                    Ok(false) => {
                        tracing::warn!("chunk lease lost: the chunk stops here");
                        ctl.lost.store(true, Ordering::Relaxed);
                        return;
                    }
                    Err(e) => tracing::warn!(error = %e, "chunk lease not renewed"),
                }
            }
        });
        let outcome = catch_unwind(AssertUnwindSafe(|| {
            queue.pool.install(|| {
                let submission = JobSubmission::parse(chunk.request.as_bytes(), limits)?;
                match submission.chunk_plan() {
                    Some(plan) => submission.run_chunk(plan.range(lease.index), ctl),
                    None => Err(crate::numerics::params::InvalidInput::new(
                        "kind",
                        "a chunk of a job whose kind is not chunked",
                    )
                    .into()),
                }
            })
        }));
        drop(stop);
        outcome
    });
    let ended = match outcome {
        Ok(Ok(result)) => {
            if queue.store.finish_chunk(&lease, &result)? {
                ChunkOutcome::Done
            } else {
                ChunkOutcome::Stopped
            }
        }
        Ok(Err(RequestError::Cancelled)) => {
            if queue.is_shut_down() {
                queue.store.release_chunk(&lease)?;
            }
            ChunkOutcome::Stopped
        }
        Ok(Err(e)) => {
            if queue.store.fail_chunk(&lease, &error_json(e.body()))? {
                ChunkOutcome::Failed
            } else {
                ChunkOutcome::Stopped
            }
        }
        Err(_) => {
            tracing::error!("chunk panicked");
            let body = ErrorBody::new("internal", None, "a chunk of the job panicked");
            queue.store.fail_chunk(&lease, &error_json(body))?;
            ChunkOutcome::Failed
        }
    };
    tracing::info!(
        outcome = ?ended,
        elapsed_ms = ctl.started.elapsed().as_millis() as u64,
        "chunk ended"
    );
    Ok(Some((lease, ended)))
}
