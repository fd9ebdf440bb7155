//! Batch jobs: a bounded queue persisted in a job store ([`store`]: the
//! [`store::JobBackend`] trait, SQLite by default), what a job computes
//! ([`kinds`]), and the worker that runs them on a dedicated rayon pool,
//! apart from the pool that answers synchronous requests.
//!
//! The worker is a plain thread looping on [`try_execute_next`], which
//! claims the oldest queued job under a lease ([`lease`]), runs it while a
//! heartbeat renews the lease, and records the outcome with fenced writes;
//! tests call it directly to drain the queue deterministically. Progress is
//! written to the store at most every [`JobQueue::progress_interval`];
//! cancellation (`DELETE`), lease loss, the run-time limit and shutdown are
//! seen between chunks of work. A job interrupted by shutdown goes back to
//! `queued`; one whose process died is taken over when its lease expires
//! (at once by a restarted process on the same host), and failed after
//! `max_job_attempts` such claims.

pub mod bands;
pub mod chunks;
pub mod dynamics;
pub mod windows;
pub mod estimate;
pub mod flights;
pub mod flights_sqlite;
pub mod kinds;
pub mod lease;
pub mod plan;
pub mod postgres;
pub mod sqlite;
pub mod store;
pub mod tether;
pub mod worker;

use std::collections::HashMap;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant};

use crate::contract::dto::ErrorBody;
use crate::contract::{Progress, RequestError};
use crate::limits::Limits;
use kinds::JobSubmission;
use store::{
    ClaimPolicy, InsertError, Inserted, JobBackend, JobRecord, JobStatus, Lease, NewJob, StoreError,
};

/// Why a submission was refused.
#[derive(Debug, thiserror::Error)]
pub enum SubmitError {
    #[error(transparent)]
    Request(#[from] RequestError),
    #[error(transparent)]
    Queue(#[from] InsertError),
}

/// Who submits: the owner (hash of the API token) and the idempotency key.
#[derive(Clone, Debug, Default)]
pub struct Submitter {
    pub owner: Option<String>,
    pub idempotency_key: Option<String>,
}

/// A stored submission.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Submitted {
    pub id: i64,
    pub kind: String,
    pub status: JobStatus,
    /// False when an earlier submission with the same idempotency key is returned.
    pub created: bool,
}

/// A job running in this process: its lease and stop signals.
struct RunningJob {
    cancelled: AtomicBool,
    lost: AtomicBool,
}

/// The queue: store, job pool, limits, and the worker's signals.
pub struct JobQueue {
    pub store: Box<dyn JobBackend>,
    pool: rayon::ThreadPool,
    limits: Limits,
    shutdown: AtomicBool,
    wake: (Mutex<bool>, Condvar),
    running: Mutex<HashMap<i64, Arc<RunningJob>>>,
    /// Least time between two progress writes of one job.
    pub progress_interval: Duration,
    /// Wakes the presence heartbeat at shutdown.
    stopping: (Mutex<()>, Condvar),
}

/// Lowercase hex SHA-256 of `bytes`.
pub fn sha256_hex(bytes: &[u8]) -> String {
    use sha2::Digest;
    let digest = sha2::Sha256::digest(bytes);
    let mut s = String::with_capacity(64);
    for b in digest.iter() {
        s.push_str(&format!("{b:02x}"));
    }
    s
}

impl JobQueue {
    /// A queue over `store` with a pool of `threads` for the jobs.
    pub fn new(store: impl JobBackend + 'static, threads: usize, limits: Limits) -> Self {
        Self::with_store(Box::new(store), threads, limits)
    }

    /// [`JobQueue::new`] over a store chosen at run time (SQLite or PostgreSQL).
    pub fn with_store(store: Box<dyn JobBackend>, threads: usize, limits: Limits) -> Self {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads.max(1))
            .thread_name(|i| format!("job-{i}"))
            .start_handler(|_| lower_thread_priority())
            .build()
            .expect("the job pool starts");
        Self {
            store,
            pool,
            limits,
            shutdown: AtomicBool::new(false),
            wake: (Mutex::new(false), Condvar::new()),
            running: Mutex::new(HashMap::new()),
            progress_interval: Duration::from_millis(200),
            stopping: (Mutex::new(()), Condvar::new()),
        }
    }

    pub fn limits(&self) -> &Limits {
        &self.limits
    }

    /// The named system `name` of `owner` (None: no tokens), as JSON.
    pub fn stored_system(
        &self,
        owner: Option<&str>,
        name: &str,
    ) -> Result<Option<serde_json::Value>, StoreError> {
        match self.store.get_system(owner.unwrap_or(""), name)? {
            None => Ok(None),
            Some(s) => serde_json::from_str(&s.body)
                .map(Some)
                .map_err(|e| StoreError(format!("stored system `{name}` is not JSON: {e}"))),
        }
    }

    /// Validates and stores a submission without owner or key; returns its id.
    pub fn submit(&self, body: &[u8]) -> Result<(i64, &'static str), SubmitError> {
        let kind = JobSubmission::parse(body, &self.limits)?.kind();
        let s = self.submit_as(body, &Submitter::default())?;
        Ok((s.id, kind))
    }

    /// Validates and stores a submission (nothing is stored when the
    /// request is invalid, too large, or the queue or the owner's quota is
    /// full); a repeated idempotency key with the same body returns the
    /// first job.
    pub fn submit_as(&self, body: &[u8], who: &Submitter) -> Result<Submitted, SubmitError> {
        let request_hash = sha256_hex(body);
        // A named system is resolved at submission: the job stores (and
        // runs) the request with the system merged in.
        let resolved =
            crate::contract::system::resolve::resolve_job_body::<SubmitError>(body, &mut |name| {
                self.stored_system(who.owner.as_deref(), name)
                    .map_err(|e| SubmitError::Queue(InsertError::Store(e)))
            })?;
        let body: &[u8] = resolved.as_deref().unwrap_or(body);
        let request =
            std::str::from_utf8(body).map_err(|e| RequestError::Malformed(e.to_string()))?;
        // A retry is answered before the (possibly long) validation.
        if let (Some(key), Some(first)) = (
            who.idempotency_key.as_deref(),
            self.store
                .find_by_key(
                    who.owner.as_deref(),
                    who.idempotency_key.as_deref().unwrap_or(""),
                )
                .map_err(InsertError::Store)?,
        ) {
            if first.request_hash != request_hash {
                return Err(InsertError::KeyReused {
                    key: key.to_string(),
                    id: first.id,
                }
                .into());
            }
            return Ok(Submitted {
                id: first.id,
                kind: first.kind,
                status: first.status,
                created: false,
            });
        }
        let submission = JobSubmission::parse(body, &self.limits)?;
        let kind = submission.kind();
        let new = NewJob {
            kind,
            request,
            owner: who.owner.as_deref(),
            idempotency_key: who.idempotency_key.as_deref(),
            request_hash: &request_hash,
            max_pending: self.limits.max_pending_jobs,
            max_pending_per_owner: self.limits.max_pending_jobs_per_token,
            priority: submission
                .chunk_plan()
                .map_or(0, |p| i64::from(p.count() > 1)),
            reserve_bytes: submission
                .answer_bytes_estimate()
                .min(self.limits.max_job_result_bytes),
            max_stored_bytes: self.limits.max_stored_bytes_per_token,
        };
        let submitted = match self.store.insert(&new)? {
            Inserted::New(id) => {
                self.notify();
                Submitted {
                    id,
                    kind: kind.into(),
                    status: JobStatus::Queued,
                    created: true,
                }
            }
            Inserted::Existing { id, kind, status } => Submitted {
                id,
                kind,
                status,
                created: false,
            },
        };
        Ok(submitted)
    }

    /// Cancels a queued or running job of `owner` (None: any); None for an
    /// unknown id or another owner's job.
    pub fn cancel(&self, id: i64, owner: Option<&str>) -> Result<Option<JobRecord>, StoreError> {
        let body = ErrorBody::new(
            "cancelled",
            None,
            "the job was cancelled by DELETE /api/v1/jobs/{id}",
        );
        let record = self.store.cancel(
            id,
            owner,
            &serde_json::to_string(&body).expect("error bodies serialise"),
        )?;
        if record
            .as_ref()
            .is_some_and(|r| r.status == JobStatus::Cancelled)
            && let Some(job) = self
                .running
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .get(&id)
        {
            job.cancelled.store(true, Ordering::Relaxed);
        }
        Ok(record)
    }

    /// Asks the worker to stop: the running job returns to the queue.
    pub fn shutdown(&self) {
        self.shutdown.store(true, Ordering::Relaxed);
        self.notify();
        let (lock, cvar) = &self.stopping;
        let _guard = lock.lock().unwrap_or_else(|e| e.into_inner());
        cvar.notify_all();
    }

    pub fn is_shut_down(&self) -> bool {
        self.shutdown.load(Ordering::Relaxed)
    }

    fn notify(&self) {
        let (lock, cvar) = &self.wake;
        *lock.lock().unwrap_or_else(|e| e.into_inner()) = true;
        cvar.notify_all();
    }

    fn wait_for_work(&self, timeout: Duration) {
        let (lock, cvar) = &self.wake;
        let mut woken = lock.lock().unwrap_or_else(|e| e.into_inner());
        if !*woken {
            woken = cvar
                .wait_timeout(woken, timeout)
                .unwrap_or_else(|e| e.into_inner())
                .0;
        }
        *woken = false;
    }

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

/// Niceness of the job threads: batch work yields the CPU to the threads
/// that answer requests (about 10:1 under contention with CFS), so
/// `/healthz` and synchronous answers stay fast while a job runs.
pub const JOB_NICENESS: i32 = 10;

/// Lowers the calling thread's scheduling priority to [`JOB_NICENESS`].
fn lower_thread_priority() {
    #[cfg(target_os = "linux")]
    {
        // SAFETY: setpriority on the calling thread's id only reads its arguments.
        let rc = unsafe {
            libc::setpriority(
                libc::PRIO_PROCESS,
                libc::gettid() as libc::id_t,
                JOB_NICENESS,
            )
        };
        if rc != 0 {
            tracing::warn!("could not lower the priority of a job thread");
        }
    }
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

fn error_json(body: ErrorBody) -> String {
    serde_json::to_string(&body).expect("error bodies serialise")
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
