//! Batch jobs: a bounded queue persisted in SQLite ([`store`]), what a job
//! computes ([`kinds`]), and the worker that runs them on a dedicated rayon
//! pool, apart from the pool that answers synchronous requests.
//!
//! The worker is a plain thread looping on [`try_execute_next`], which
//! claims the oldest queued job, runs it, and records the outcome; tests
//! call it directly to drain the queue deterministically. Progress is
//! written to the store at most every [`JobQueue::progress_interval`];
//! cancellation (`DELETE`) and shutdown are seen between chunks of work.
//! A job interrupted by shutdown goes back to `queued`; one interrupted by a
//! crash is requeued when the store is next opened.

pub mod kinds;
pub mod store;
pub mod tether;

use std::collections::HashMap;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant};

use crate::config::Limits;
use crate::contract::dto::ErrorBody;
use crate::contract::{Progress, RequestError};
use kinds::JobSubmission;
use store::{InsertError, JobRecord, JobStatus, JobStore, StoreError};

/// Why a submission was refused.
#[derive(Debug, thiserror::Error)]
pub enum SubmitError {
    #[error(transparent)]
    Request(#[from] RequestError),
    #[error(transparent)]
    Queue(#[from] InsertError),
}

/// The queue: store, job pool, limits, and the worker's signals.
pub struct JobQueue {
    pub store: JobStore,
    pool: rayon::ThreadPool,
    limits: Limits,
    shutdown: AtomicBool,
    wake: (Mutex<bool>, Condvar),
    running: Mutex<HashMap<i64, Arc<AtomicBool>>>,
    /// Least time between two progress writes of one job.
    pub progress_interval: Duration,
}

impl JobQueue {
    /// A queue over `store` with a pool of `threads` for the jobs.
    pub fn new(store: JobStore, threads: usize, limits: Limits) -> Self {
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
        }
    }

    pub fn limits(&self) -> &Limits {
        &self.limits
    }

    /// Validates and stores a submission; returns its id. Nothing is stored
    /// when the request is invalid or the queue is full.
    pub fn submit(&self, body: &[u8]) -> Result<(i64, &'static str), SubmitError> {
        let submission = JobSubmission::parse(body, &self.limits)?;
        let kind = submission.kind();
        let request =
            std::str::from_utf8(body).map_err(|e| RequestError::Malformed(e.to_string()))?;
        let id = self
            .store
            .insert(kind, request, self.limits.max_pending_jobs)?;
        self.notify();
        Ok((id, kind))
    }

    /// Cancels a queued or running job; None for an unknown id.
    pub fn cancel(&self, id: i64) -> Result<Option<JobRecord>, StoreError> {
        let body = ErrorBody::new(
            "cancelled",
            None,
            "the job was cancelled by DELETE /api/v1/jobs/{id}",
        );
        let record = self.store.cancel(
            id,
            &serde_json::to_string(&body).expect("error bodies serialise"),
        )?;
        if let Some(flag) = self
            .running
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .get(&id)
        {
            flag.store(true, Ordering::Relaxed);
        }
        Ok(record)
    }

    /// Asks the worker to stop: the running job returns to the queue.
    pub fn shutdown(&self) {
        self.shutdown.store(true, Ordering::Relaxed);
        self.notify();
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
    pub fn spawn_worker(self: &Arc<Self>) -> std::thread::JoinHandle<()> {
        let queue = Arc::clone(self);
        std::thread::Builder::new()
            .name("job-worker".into())
            .spawn(move || {
                while !queue.is_shut_down() {
                    match try_execute_next(&queue) {
                        Ok(Some(_)) => {}
                        Ok(None) => queue.wait_for_work(Duration::from_secs(1)),
                        Err(e) => {
                            tracing::error!(error = %e, "job worker");
                            std::thread::sleep(Duration::from_secs(1));
                        }
                    }
                }
            })
            .expect("the job worker starts")
    }
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
    id: i64,
    queue: &'a JobQueue,
    cancelled: Arc<AtomicBool>,
    last_write: Mutex<Instant>,
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
            .set_progress(self.id, done as f64 / total.max(1) as f64)
        {
            Ok(true) => {}
            // No longer running: cancelled meanwhile (possibly by another process).
            Ok(false) => self.cancelled.store(true, Ordering::Relaxed),
            Err(e) => tracing::warn!(job = self.id, error = %e, "progress not recorded"),
        }
    }

    fn cancelled(&self) -> bool {
        self.cancelled.load(Ordering::Relaxed) || self.queue.is_shut_down()
    }
}

/// A job the worker took: its id and where it ended up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Executed {
    pub id: i64,
    pub status: JobStatus,
}

/// Runs the oldest queued job to its end, if there is one: the worker's
/// step, also called directly by tests.
pub fn try_execute_next(queue: &JobQueue) -> Result<Option<Executed>, StoreError> {
    let Some(job) = queue.store.claim_next()? else {
        return Ok(None);
    };
    let span = tracing::info_span!("job", id = job.id, kind = %job.kind);
    let _enter = span.enter();
    let started = Instant::now();
    let flag = Arc::new(AtomicBool::new(false));
    queue
        .running
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .insert(job.id, flag.clone());
    let ctl = JobControl {
        id: job.id,
        queue,
        cancelled: flag,
        last_write: Mutex::new(Instant::now()),
    };
    let outcome = catch_unwind(AssertUnwindSafe(|| {
        queue.pool.install(|| {
            let submission = JobSubmission::parse(job.request.as_bytes(), &queue.limits)?;
            submission.run(&ctl)
        })
    }));
    queue
        .running
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .remove(&job.id);
    let error_json =
        |body: ErrorBody| serde_json::to_string(&body).expect("error bodies serialise");
    let status = match outcome {
        Ok(Ok(result)) => {
            if queue.store.finish_done(job.id, &result)? {
                JobStatus::Done
            } else {
                queue.store.status(job.id)?.unwrap_or(JobStatus::Cancelled)
            }
        }
        Ok(Err(RequestError::Cancelled))
            if queue.is_shut_down() && !ctl.cancelled.load(Ordering::Relaxed) =>
        {
            queue.store.requeue(job.id)?;
            queue.store.status(job.id)?.unwrap_or(JobStatus::Queued)
        }
        Ok(Err(RequestError::Cancelled)) => {
            queue.store.status(job.id)?.unwrap_or(JobStatus::Cancelled)
        }
        Ok(Err(e)) => {
            queue.store.finish_failed(job.id, &error_json(e.body()))?;
            JobStatus::Failed
        }
        Err(_) => {
            tracing::error!("job panicked");
            queue.store.finish_failed(
                job.id,
                &error_json(ErrorBody::new("internal", None, "the job panicked")),
            )?;
            JobStatus::Failed
        }
    };
    tracing::info!(
        status = status.as_str(),
        elapsed_ms = started.elapsed().as_millis() as u64,
        "job ended"
    );
    Ok(Some(Executed { id: job.id, status }))
}
