//! Running jobs: the worker thread of a [`JobQueue`] and its step
//! ([`try_execute_next`]: claim the oldest queued job under a lease, run it
//! while a heartbeat renews the lease, record the outcome with fenced
//! writes; [`work_once`]: else a pending chunk), its presence in the
//! store's live workers, and the job's progress and cancellation.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use super::backend::{ClaimPolicy, JobStatus, StoreError};
use super::chunks;
use super::kinds::JobSubmission;
use super::lease::Lease;
use super::queue::{JobQueue, RunningJob, error_json};
use crate::contract::error::ErrorBody;
use crate::contract::{Progress, RequestError};

impl JobQueue {
    /// Starts the worker thread; it runs until [`JobQueue::shutdown`].
    /// An idle worker looks for work at least every second (jobs submitted
    /// by other processes, expired leases).
    pub fn spawn_worker(self: &Arc<Self>) -> std::thread::JoinHandle<()> {
        self.spawn_worker_as("serve")
    }

    /// [`JobQueue::spawn_worker`], registered in the store's live workers
    /// under `role` (`serve`, `worker`) with a heartbeat every
    /// [`PRESENCE_INTERVAL`]; it leaves the list when it stops. Each step
    /// takes a queued job first (short jobs before chunked ones), else a
    /// pending chunk of a running job.
    pub fn spawn_worker_as(self: &Arc<Self>, role: &'static str) -> std::thread::JoinHandle<()> {
        let queue = Arc::clone(self);
        std::thread::Builder::new()
            .name("job-worker".into())
            .spawn(move || {
                std::thread::scope(|scope| {
                    scope.spawn(|| presence(&queue, role));
                    while !queue.is_shut_down() {
                        match work_once(&queue) {
                            Ok(true) => {}
                            Ok(false) => queue.wait_for_work(IDLE_POLL),
                            Err(e) => {
                                tracing::error!(error = %e, "job worker");
                                std::thread::sleep(Duration::from_secs(1));
                            }
                        }
                    }
                    queue.notify();
                });
            })
            .expect("the job worker starts")
    }
}

/// How long an idle worker waits before looking for work again (jobs and
/// chunks submitted by other processes, expired leases).
const IDLE_POLL: Duration = Duration::from_millis(250);

/// How often a worker records that it is alive.
pub const PRESENCE_INTERVAL: Duration = Duration::from_secs(1);

/// How often a worker purges expired jobs, assembled chunks and stale
/// worker rows ([`store::JobBackend::housekeeping`]).
pub const HOUSEKEEPING_INTERVAL: Duration = Duration::from_secs(60);

/// A worker row silent this long is deleted (its process is gone).
pub const STALE_WORKER_AGE: Duration = Duration::from_secs(60);

/// A worker is counted live while its last heartbeat is this recent.
pub const PRESENCE_TIMEOUT: Duration = Duration::from_secs(5);

/// Heartbeats this worker into the store's live workers until shutdown,
/// then leaves the list.
fn presence(queue: &JobQueue, role: &str) {
    let mut last_housekeeping: Option<std::time::Instant> = None;
    while !queue.is_shut_down() {
        if let Err(e) = queue.store.worker_heartbeat(role) {
            tracing::warn!(error = %e, "worker heartbeat not recorded");
        }
        if last_housekeeping.is_none_or(|t| t.elapsed() >= HOUSEKEEPING_INTERVAL) {
            last_housekeeping = Some(std::time::Instant::now());
            match queue
                .store
                .housekeeping(queue.limits.job_retention, STALE_WORKER_AGE)
            {
                Ok(0) => {}
                Ok(n) => tracing::info!(purged = n, "finished jobs past their retention deleted"),
                Err(e) => tracing::warn!(error = %e, "housekeeping failed"),
            }
        }
        let (lock, cvar) = &queue.stopping;
        let guard = lock.lock().unwrap_or_else(|e| e.into_inner());
        if !queue.is_shut_down() {
            let _ = cvar.wait_timeout(guard, PRESENCE_INTERVAL);
        }
    }
    if let Err(e) = queue.store.worker_leave() {
        tracing::warn!(error = %e, "worker not removed from the live workers");
    }
}

/// One step of a worker: a queued job, else a pending chunk; false when
/// there was nothing to do.
pub fn work_once(queue: &JobQueue) -> Result<bool, StoreError> {
    if try_execute_next(queue)?.is_some() {
        return Ok(true);
    }
    Ok(chunks::execute_chunk(queue, None)?.is_some())
}

/// Progress and cancellation of one running job.
struct JobControl<'a> {
    lease: &'a Lease,
    queue: &'a JobQueue,
    job: Arc<RunningJob>,
    started: Instant,
    last_write: Mutex<Instant>,
}

impl JobControl<'_> {
    fn timed_out(&self) -> bool {
        self.started.elapsed() > self.queue.limits.max_job_run_time
    }

    fn lose(&self) {
        self.job.lost.store(true, Ordering::Relaxed);
    }
}

impl Progress for JobControl<'_> {
    fn report(&self, done: usize, total: usize) {
        let Ok(mut last) = self.last_write.try_lock() else {
            return;
        };
        if last.elapsed() < self.queue.progress_interval {
            return;
        }
        *last = Instant::now();
        match self
            .queue
            .store
            .set_progress(self.lease, done as f64 / total.max(1) as f64)
        {
            Ok(true) => {}
            // Cancelled or taken over meanwhile (possibly by another process).
            Ok(false) => self.lose(),
            Err(e) => tracing::warn!(job = self.lease.job_id, error = %e, "progress not recorded"),
        }
    }

    fn cancelled(&self) -> bool {
        self.job.cancelled.load(Ordering::Relaxed)
            || self.job.lost.load(Ordering::Relaxed)
            || self.queue.is_shut_down()
            || self.timed_out()
    }
}

/// Renews `ctl`'s lease every third of the lease length until `stop`
/// fires; a lost lease stops the job.
fn heartbeat(ctl: &JobControl<'_>, stop: std::sync::mpsc::Receiver<()>) {
    let every = ctl.queue.limits.job_lease / 3;
    while let Err(std::sync::mpsc::RecvTimeoutError::Timeout) = stop.recv_timeout(every) {
        match ctl.queue.store.renew(ctl.lease, ctl.queue.limits.job_lease) {
            Ok(true) => {}
            Ok(false) => {
                tracing::warn!(job = ctl.lease.job_id, "lease lost: the job stops here");
                ctl.lose();
                return;
            }
            Err(e) => tracing::warn!(job = ctl.lease.job_id, error = %e, "lease not renewed"),
        }
    }
}

/// A job the worker took: its id and where it ended up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Executed {
    pub id: i64,
    pub status: JobStatus,
}

/// Runs the oldest queued job (or one whose lease expired) to its end, if
/// there is one: the worker's step, also called directly by tests.
pub fn try_execute_next(queue: &JobQueue) -> Result<Option<Executed>, StoreError> {
    let limits = &queue.limits;
    let exhausted = error_json(ErrorBody::new(
        "attempts_exhausted",
        None,
        format!(
            "the job was started {} times and each time the process running it stopped before it \
             finished (crash, out of memory or kill); it is not started again",
            limits.max_job_attempts
        ),
    ));
    let policy = ClaimPolicy {
        lease: limits.job_lease,
        max_attempts: limits.max_job_attempts,
        exhausted_error: &exhausted,
    };
    let Some(job) = queue.store.claim(&policy)? else {
        return Ok(None);
    };
    let span = tracing::info_span!("job", id = job.id, kind = %job.kind, attempt = job.attempts);
    let _enter = span.enter();
    let started = Instant::now();
    let running = Arc::new(RunningJob {
        cancelled: AtomicBool::new(false),
        lost: AtomicBool::new(false),
    });
    queue
        .running
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .insert(job.id, running.clone());
    let ctl = JobControl {
        lease: &job.lease,
        queue,
        job: running,
        started,
        last_write: Mutex::new(Instant::now()),
    };
    let chunk_failure = Mutex::new(None);
    let outcome = std::thread::scope(|scope| {
        let (stop, stopped) = std::sync::mpsc::channel::<()>();
        let ctl = &ctl;
        scope.spawn(move || heartbeat(ctl, stopped));
        let outcome = catch_unwind(AssertUnwindSafe(|| {
            queue.pool.install(|| {
                let submission = JobSubmission::parse(job.request.as_bytes(), &queue.limits)?;
                match submission.chunk_plan() {
                    Some(plan) if plan.count() > 1 => chunks::coordinate(
                        queue,
                        &job.lease,
                        &submission,
                        plan,
                        ctl,
                        &chunk_failure,
                    ),
                    _ => submission.run(ctl),
                }
            })
        }));
        drop(stop);
        outcome
    });
    queue
        .running
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .remove(&job.id);
    let lease = &job.lease;
    let lost = ctl.job.lost.load(Ordering::Relaxed);
    let now = |queue: &JobQueue| -> Result<JobStatus, StoreError> {
        Ok(queue.store.status(job.id)?.unwrap_or(JobStatus::Cancelled))
    };
    let fail = |body: ErrorBody| -> Result<JobStatus, StoreError> {
        if queue.store.finish_failed(lease, &error_json(body))? {
            Ok(JobStatus::Failed)
        } else {
            now(queue)
        }
    };
    let chunk_failure = chunk_failure
        .into_inner()
        .unwrap_or_else(|e| e.into_inner());
    let status = match outcome {
        _ if chunk_failure.is_some() && !lost => {
            let body = chunk_failure.unwrap_or_default();
            if queue.store.finish_failed(lease, &body)? {
                JobStatus::Failed
            } else {
                now(queue)?
            }
        }
        Ok(Ok(result)) if result.len() as u64 > limits.max_job_result_bytes => {
            fail(ErrorBody::new(
                "result_too_large",
                None,
                format!(
                    "the answer has {} bytes, more than this server keeps for one job ({} bytes): \
                 ask for fewer points",
                    result.len(),
                    limits.max_job_result_bytes
                ),
            ))?
        }
        Ok(Ok(result)) => {
            if queue.store.finish_done(lease, &result)? {
                JobStatus::Done
            } else {
                now(queue)?
            }
        }
        Ok(Err(RequestError::Cancelled)) if lost => now(queue)?,
        Ok(Err(RequestError::Cancelled)) if ctl.job.cancelled.load(Ordering::Relaxed) => {
            now(queue)?
        }
        Ok(Err(RequestError::Cancelled)) if queue.is_shut_down() => {
            queue.store.release(lease)?;
            now(queue)?
        }
        Ok(Err(RequestError::Cancelled)) if ctl.timed_out() => fail(ErrorBody::new(
            "run_time_exceeded",
            None,
            format!(
                "the job ran longer than this server allows one job ({} s) and was stopped",
                limits.max_job_run_time.as_secs_f64()
            ),
        ))?,
        Ok(Err(RequestError::Cancelled)) => now(queue)?,
        Ok(Err(e)) => fail(e.body())?,
        Err(_) => {
            tracing::error!("job panicked");
            fail(ErrorBody::new("internal", None, "the job panicked"))?
        }
    };
    tracing::info!(
        status = status.as_str(),
        lost,
        elapsed_ms = started.elapsed().as_millis() as u64,
        "job ended"
    );
    Ok(Some(Executed { id: job.id, status }))
}
