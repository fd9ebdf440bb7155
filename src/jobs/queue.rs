//! The job queue ([`JobQueue`]): submissions parsed and validated by the
//! catalogue of kinds ([`super::kinds`]) and stored, with their quota and
//! idempotency keys; cancellation, shutdown and the wake-up of idle
//! workers. Running jobs is [`super::execute`]'s.

use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::time::Duration;

use super::backend::{InsertError, Inserted, JobBackend, JobRecord, JobStatus, NewJob, StoreError};
use super::kinds::JobSubmission;
use crate::contract::RequestError;
use crate::contract::error::ErrorBody;
use crate::limits::Limits;

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
pub(super) struct RunningJob {
    pub(super) cancelled: AtomicBool,
    pub(super) lost: AtomicBool,
}

/// The queue: store, job pool, limits, and the worker's signals.
pub struct JobQueue {
    pub store: Box<dyn JobBackend>,
    pub(super) pool: rayon::ThreadPool,
    pub(super) limits: Limits,
    pub(super) shutdown: AtomicBool,
    pub(super) wake: (Mutex<bool>, Condvar),
    pub(super) running: Mutex<HashMap<i64, Arc<RunningJob>>>,
    /// Least time between two progress writes of one job.
    pub progress_interval: Duration,
    /// Wakes the presence heartbeat at shutdown.
    pub(super) stopping: (Mutex<()>, Condvar),
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

    pub(super) fn notify(&self) {
        let (lock, cvar) = &self.wake;
        *lock.lock().unwrap_or_else(|e| e.into_inner()) = true;
        cvar.notify_all();
    }

    pub(super) fn wait_for_work(&self, timeout: Duration) {
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
}

/// An error body as the store keeps it (JSON text).
pub(crate) fn error_json(body: ErrorBody) -> String {
    serde_json::to_string(&body).expect("error bodies serialise")
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
