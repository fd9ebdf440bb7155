//! The job store: what a job row (and a chunk row) holds and the
//! operations a backend offers ([`JobBackend`]); SQLite (`sqlite/`) is
//! the embedded default, and another database (PostgreSQL: `FOR UPDATE
//! SKIP LOCKED`, `postgres/`) implements the same trait. Neither is
//! named here: both depend on this file, not it on them.
//!
//! Status moves `queued → running → done | failed`, or `→ cancelled` from
//! `queued`/`running`. A worker claims a job under a lease ([`Lease`]:
//! owner, expiry, epoch) and renews it while the job runs; every write of
//! progress, result or failure is fenced by that lease. A `running` job
//! whose lease expired (its process died) is claimed again by any worker;
//! one that was claimed `max_attempts` times without finishing is failed
//! instead (it probably kills the process that runs it).
//!
//! Jobs carry an owner (the hash of the API token that submitted them, or
//! none without tokens) and optionally an idempotency key, unique per owner.
//!
//! A done job's answer is stored in pages of [`ANSWER_PAGE_BYTES`], so that
//! `GET /api/v1/jobs/{id}` streams it page by page ([`JobBackend::get_head`],
//! [`JobBackend::answer_page`]) instead of building it in memory.
//!
//! Store quota (issue 22): every job row counts the bytes it keeps
//! (`stored_bytes`: its request, plus its estimated answer while queued or
//! running, then its answer or error), and an owner's jobs and named
//! systems together may keep at most [`NewJob::max_stored_bytes`]; a
//! submission or a named system past it is refused
//! ([`InsertError::StoreFull`], [`PutSystem::StoreFull`]).

use std::time::Duration;

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::lease::{Lease, WorkerId};

/// A claim on one chunk: fenced chunk writes carry it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ChunkLease {
    pub job_id: i64,
    pub index: usize,
    pub owner: String,
    pub epoch: i64,
}

/// A chunk taken by a worker, with its job's request.
#[derive(Clone, Debug)]
pub struct ClaimedChunk {
    pub lease: ChunkLease,
    /// The job's submitted body, JSON text.
    pub request: String,
    /// Claims of this chunk so far, this one included.
    pub attempts: u32,
}

/// How far the chunks of one job are.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ChunkState {
    pub total: usize,
    pub done: usize,
    /// The error body (JSON text) of the first failed chunk, if any.
    pub failed: Option<String>,
}

/// Where a job is in its life.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum JobStatus {
    /// Accepted, waiting for the worker.
    Queued,
    /// Being computed now.
    Running,
    /// Finished; `result` holds the answer.
    Done,
    /// Finished with an error; `error` says why.
    Failed,
    /// Cancelled by `DELETE` before it finished.
    Cancelled,
}

impl JobStatus {
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Queued => "queued",
            Self::Running => "running",
            Self::Done => "done",
            Self::Failed => "failed",
            Self::Cancelled => "cancelled",
        }
    }

    pub fn parse(s: &str) -> Self {
        match s {
            "queued" => Self::Queued,
            "running" => Self::Running,
            "done" => Self::Done,
            "failed" => Self::Failed,
            _ => Self::Cancelled,
        }
    }

    pub fn is_finished(self) -> bool {
        matches!(self, Self::Done | Self::Failed | Self::Cancelled)
    }
}

/// A failure of the database itself (disk full, corrupt file, lost connection).
#[derive(Debug, thiserror::Error)]
#[error("job store: {0}")]
pub struct StoreError(pub String);

/// Why a job was not accepted.
#[derive(Debug, thiserror::Error)]
pub enum InsertError {
    #[error("the job queue is full ({pending} jobs queued or running, at most {limit})")]
    QueueFull { pending: usize, limit: usize },
    #[error(
        "this token has {pending} jobs queued or running, at most {limit}: wait for some to finish"
    )]
    QuotaFull { pending: usize, limit: usize },
    #[error(
        "this token keeps {stored} bytes of jobs and named systems and this job would add about \
         {adding} more (its request and its estimated answer), past the {limit} bytes kept per \
         token: delete named systems it no longer needs, or wait until its finished jobs expire"
    )]
    StoreFull {
        stored: u64,
        adding: u64,
        limit: u64,
        /// Seconds since the owner's oldest finished job finished (None: none
        /// finished): with the retention, when room is freed next.
        oldest_finished_s: Option<f64>,
    },
    #[error(
        "Idempotency-Key `{key}` was first used for job {id} with a different body; \
         use a new key for a different request"
    )]
    KeyReused { key: String, id: i64 },
    #[error(transparent)]
    Store(#[from] StoreError),
}

/// A submission to store.
#[derive(Clone, Debug)]
pub struct NewJob<'a> {
    pub kind: &'a str,
    /// The submitted body, JSON text.
    pub request: &'a str,
    /// Hash of the submitting token (None without tokens).
    pub owner: Option<&'a str>,
    /// The client's `Idempotency-Key`, unique per owner.
    pub idempotency_key: Option<&'a str>,
    /// Hash of the body, to tell a retry from a different request under one key.
    pub request_hash: &'a str,
    /// Jobs queued or running at once, all owners.
    pub max_pending: usize,
    /// Jobs queued or running at once, this owner (with an owner).
    pub max_pending_per_owner: usize,
    /// Claim order: lower first (0: one piece of work, 1: a chunked job),
    /// then oldest first; short jobs pass long ones.
    pub priority: i64,
    /// Bytes reserved for the answer until it is stored (its estimate).
    pub reserve_bytes: u64,
    /// Bytes the owner's jobs and named systems may keep at once.
    pub max_stored_bytes: u64,
}

/// Bytes of one page of a stored answer.
pub const ANSWER_PAGE_BYTES: usize = 256 << 10;

/// A job row without its answer, and how many pages its answer has.
#[derive(Clone, Debug, PartialEq)]
pub struct JobHead {
    /// The row (`result` is None).
    pub record: JobRecord,
    /// Pages of the answer ([`JobBackend::answer_page`]); None unless done.
    pub answer_pages: Option<usize>,
}

/// `text` cut into the pages it is stored in.
pub fn answer_pages(text: &str) -> impl Iterator<Item = &[u8]> {
    text.as_bytes().chunks(ANSWER_PAGE_BYTES)
}

/// Pages read back into the answer text.
pub fn join_pages(id: i64, pages: Vec<Vec<u8>>) -> Result<String, StoreError> {
    let mut buf = Vec::with_capacity(pages.iter().map(Vec::len).sum());
    for p in pages {
        buf.extend_from_slice(&p);
    }
    String::from_utf8(buf)
        .map_err(|e| StoreError(format!("the answer of job {id} is not UTF-8: {e}")))
}

/// What an insert did.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Inserted {
    /// A new queued job.
    New(i64),
    /// The job first stored under the same idempotency key and body.
    Existing {
        id: i64,
        kind: String,
        status: JobStatus,
    },
}

/// The job first stored under an idempotency key.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct KeyedJob {
    pub id: i64,
    pub kind: String,
    pub status: JobStatus,
    /// Hash of the body it was stored with.
    pub request_hash: String,
}

/// One job row.
#[derive(Clone, Debug, PartialEq)]
pub struct JobRecord {
    pub id: i64,
    pub kind: String,
    pub status: JobStatus,
    pub progress: f64,
    pub attempts: u32,
    pub created_at: String,
    pub started_at: Option<String>,
    pub finished_at: Option<String>,
    /// The answer (JSON text) when done.
    pub result: Option<String>,
    /// The error body (JSON text) when failed or cancelled.
    pub error: Option<String>,
    /// The worker holding (or that last held) the job's lease.
    pub worker: Option<String>,
}

/// A job taken from the queue by a worker.
#[derive(Clone, Debug)]
pub struct ClaimedJob {
    pub id: i64,
    pub kind: String,
    /// The submitted body, JSON text.
    pub request: String,
    /// Claims so far, this one included.
    pub attempts: u32,
    /// The claim; fenced writes carry it.
    pub lease: Lease,
}

/// How a worker claims.
#[derive(Clone, Debug)]
pub struct ClaimPolicy<'a> {
    /// Lease length (renewed by the heartbeat).
    pub lease: Duration,
    /// A job whose lease expired after this many claims is failed, not claimed.
    pub max_attempts: u32,
    /// The error body (JSON text) such a job gets.
    pub exhausted_error: &'a str,
}

/// A job store. Every method is one short transaction; `owner` scopes a
/// request to one token's jobs (None: all jobs, as without tokens).
pub trait JobBackend: Send + Sync {
    /// The identity this store claims jobs under.
    fn worker(&self) -> &WorkerId;
    /// Stores a queued job, or returns the one stored under the same key.
    fn insert(&self, job: &NewJob<'_>) -> Result<Inserted, InsertError>;
    /// The job stored under `key` by `owner`, if any.
    fn find_by_key(&self, owner: Option<&str>, key: &str) -> Result<Option<KeyedJob>, StoreError>;
    /// Fails the expired jobs out of attempts, then claims the oldest
    /// queued (or expired `running`) job under a new lease.
    fn claim(&self, policy: &ClaimPolicy<'_>) -> Result<Option<ClaimedJob>, StoreError>;
    /// Extends a lease; false when it was lost (taken over, cancelled).
    fn renew(&self, lease: &Lease, duration: Duration) -> Result<bool, StoreError>;
    /// Records progress (0 to 1); false when the lease was lost.
    fn set_progress(&self, lease: &Lease, progress: f64) -> Result<bool, StoreError>;
    /// The job is done with `result` (JSON text); false when the lease was lost.
    fn finish_done(&self, lease: &Lease, result: &str) -> Result<bool, StoreError>;
    /// The job failed with `error` (JSON error body); false when the lease was lost.
    fn finish_failed(&self, lease: &Lease, error: &str) -> Result<bool, StoreError>;
    /// Hands a running job back to the queue (shutdown); false when the lease was lost.
    fn release(&self, lease: &Lease) -> Result<bool, StoreError>;
    /// Hands back every job this store's worker holds; returns how many.
    fn release_all(&self) -> Result<usize, StoreError>;
    /// Expires at once the leases of dead processes on this host (start-up).
    fn recover_local(&self) -> Result<usize, StoreError>;
    /// Cancels a queued or running job; the row afterwards (None: unknown
    /// or another owner's). A finished job is left as it is.
    fn cancel(
        &self,
        id: i64,
        owner: Option<&str>,
        error: &str,
    ) -> Result<Option<JobRecord>, StoreError>;
    /// One job with its answer or error (None: unknown or another owner's).
    fn get_owned(&self, id: i64, owner: Option<&str>) -> Result<Option<JobRecord>, StoreError>;
    /// One job with its error but without its answer, and the number of
    /// pages of its answer (None: unknown or another owner's).
    fn get_head(&self, id: i64, owner: Option<&str>) -> Result<Option<JobHead>, StoreError>;
    /// Page `page` of a done job's answer (None: no such page, or the job
    /// is gone).
    fn answer_page(&self, id: i64, page: usize) -> Result<Option<Vec<u8>>, StoreError>;
    /// Bytes kept for `owner` (None: no tokens): its jobs' `stored_bytes`
    /// and its named systems.
    fn stored_bytes(&self, owner: Option<&str>) -> Result<u64, StoreError>;
    /// Jobs, newest first, without answers.
    fn list_owned(
        &self,
        owner: Option<&str>,
        status: Option<JobStatus>,
        limit: usize,
    ) -> Result<Vec<JobRecord>, StoreError>;
    /// Status of a job (None: unknown or another owner's).
    fn status_owned(&self, id: i64, owner: Option<&str>) -> Result<Option<JobStatus>, StoreError>;
    /// Jobs queued or running (all owners).
    fn pending(&self) -> Result<usize, StoreError>;

    /// `sqlite` or `postgres`.
    fn store_kind(&self) -> &'static str;
    /// Creates the chunks `0..count` of the job held under `lease` (those
    /// that exist are kept, with their results); false when the lease was lost.
    fn create_chunks(&self, lease: &Lease, count: usize) -> Result<bool, StoreError>;
    /// Fails the expired chunks out of attempts, then claims a pending (or
    /// expired running) chunk of a running job (of `job` only, when given),
    /// lowest job priority, oldest job, lowest index first.
    fn claim_chunk(
        &self,
        job: Option<i64>,
        policy: &ClaimPolicy<'_>,
    ) -> Result<Option<ClaimedChunk>, StoreError>;
    /// Extends a chunk lease; false when it was lost (taken over, or the job
    /// is no longer running: cancelled, failed).
    fn renew_chunk(&self, lease: &ChunkLease, duration: Duration) -> Result<bool, StoreError>;
    /// The chunk is done with `result` (JSON text); false when the lease was lost.
    fn finish_chunk(&self, lease: &ChunkLease, result: &str) -> Result<bool, StoreError>;
    /// The chunk failed with `error` (JSON error body); false when the lease was lost.
    fn fail_chunk(&self, lease: &ChunkLease, error: &str) -> Result<bool, StoreError>;
    /// Hands a running chunk back (shutdown); false when the lease was lost.
    fn release_chunk(&self, lease: &ChunkLease) -> Result<bool, StoreError>;
    /// How far the chunks of a job are.
    fn chunk_state(&self, job_id: i64) -> Result<ChunkState, StoreError>;
    /// The results of the done chunks of a job, by index.
    fn chunk_results(&self, job_id: i64) -> Result<Vec<(usize, String)>, StoreError>;
    /// Records (or refreshes) this store's worker as alive, with its role.
    fn worker_heartbeat(&self, role: &str) -> Result<(), StoreError>;
    /// Removes this store's worker from the live workers (clean exit).
    fn worker_leave(&self) -> Result<(), StoreError>;
    /// Workers whose last heartbeat is at most `within` old.
    fn live_workers(&self, within: Duration) -> Result<usize, StoreError>;
    /// Retention (issue 22): deletes the finished jobs (done, failed,
    /// cancelled) that finished more than `retention` ago with their chunk
    /// rows, empties the chunk results of every finished job (its answer
    /// is assembled, or it failed), and
    /// the worker rows whose last heartbeat is older than `stale_workers`.
    /// Returns the jobs deleted.
    fn housekeeping(
        &self,
        retention: Duration,
        stale_workers: Duration,
    ) -> Result<usize, StoreError>;

    /// One job, any owner.
    fn get(&self, id: i64) -> Result<Option<JobRecord>, StoreError> {
        self.get_owned(id, None)
    }
    /// Jobs of every owner.
    fn list(&self, status: Option<JobStatus>, limit: usize) -> Result<Vec<JobRecord>, StoreError> {
        self.list_owned(None, status, limit)
    }
    /// Status of a job, any owner.
    fn status(&self, id: i64) -> Result<Option<JobStatus>, StoreError> {
        self.status_owned(id, None)
    }

    // Named systems (SPEC §9), keyed by (owner, name); `owner` is the
    // token's hash, "" without tokens.

    /// Stores (or replaces) a named system; at most `max_per_owner` per
    /// owner, and within the owner's `max_stored_bytes`.
    fn put_system(
        &self,
        owner: &str,
        name: &str,
        body: &str,
        max_per_owner: usize,
        max_stored_bytes: u64,
    ) -> Result<PutSystem, StoreError>;
    /// One named system of `owner`.
    fn get_system(&self, owner: &str, name: &str) -> Result<Option<StoredSystem>, StoreError>;
    /// Deletes a named system; false when there was none.
    fn delete_system(&self, owner: &str, name: &str) -> Result<bool, StoreError>;
    /// The named systems of `owner` by name (bodies left empty).
    fn list_systems(&self, owner: &str) -> Result<Vec<StoredSystem>, StoreError>;
}

/// Most named systems per token.
pub const MAX_SYSTEMS_PER_OWNER: usize = 100;

/// A stored named system.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StoredSystem {
    pub name: String,
    /// The system objects (JSON text).
    pub body: String,
    pub created_at: String,
    pub updated_at: String,
}

/// What storing a named system did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PutSystem {
    Created,
    Updated,
    /// The owner already has `max` systems (nothing stored).
    Full {
        max: usize,
    },
    /// The owner's jobs and systems would keep more than `limit` bytes
    /// (they keep `stored`; nothing stored).
    StoreFull {
        stored: u64,
        limit: u64,
        /// As [`InsertError::StoreFull`]'s.
        oldest_finished_s: Option<f64>,
    },
}
