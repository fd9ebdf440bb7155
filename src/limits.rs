//! The limits that keep the service responsive: the HTTP service's
//! (body size, requests in flight, synchronous work) and the job queue's
//! (pending jobs, leases, attempts, run time, answer size, retention).
//! A plain struct below both: `config` fills it from the flags, the job
//! queue carries it, and the HTTP state reads it from the queue. The
//! connection limits ([`ConnectionLimits`]: timeouts and caps of the HTTP
//! server's connections) likewise, for `config` and `api::server`.

use std::time::Duration;

/// Limits of the HTTP service and its job queue.
#[derive(Clone, Debug, PartialEq)]
pub struct Limits {
    pub max_body_bytes: usize,
    pub max_in_flight: usize,
    pub solve_timeout: Duration,
    pub max_pending_jobs: usize,
    /// Largest chart answered synchronously (points = rates × buoyancies).
    pub max_sync_chart_points: usize,
    /// Largest synchronous chart work, points × elements.
    pub max_sync_chart_work: usize,
    /// Largest model answered synchronously when the answer needs a dense
    /// QEP solve (stability; critical time with QEP confirmation or an
    /// accelerating profile). 400 elements ≈ 0.4 s per solve.
    pub max_sync_qep_elements: usize,
    /// Largest number of requests in one batch job.
    pub max_batch_items: usize,
    /// Jobs queued or running at once for one API token.
    pub max_pending_jobs_per_token: usize,
    /// How long a job claim lasts unless renewed (heartbeat every third of it).
    pub job_lease: Duration,
    /// Claims of one job whose process died before it is failed.
    pub max_job_attempts: u32,
    /// Longest run of one job.
    pub max_job_run_time: Duration,
    /// Largest estimated answer of one job, bytes of JSON.
    pub max_job_result_bytes: u64,
    /// How long a finished job is kept before it is deleted.
    pub job_retention: Duration,
    /// Bytes one token's jobs and named systems may keep in the store.
    pub max_stored_bytes_per_token: u64,
}

impl Default for Limits {
    fn default() -> Self {
        Self {
            max_body_bytes: 1 << 20,
            max_in_flight: 64,
            solve_timeout: Duration::from_secs(30),
            max_pending_jobs: 1000,
            max_sync_chart_points: 20_000,
            max_sync_chart_work: 2_000_000,
            max_sync_qep_elements: 400,
            max_batch_items: 1000,
            max_pending_jobs_per_token: 100,
            job_lease: Duration::from_secs(30),
            max_job_attempts: 3,
            max_job_run_time: Duration::from_secs(3600),
            max_job_result_bytes: 64 << 20,
            job_retention: Duration::from_secs(7 * 24 * 3600),
            max_stored_bytes_per_token: 1 << 30,
        }
    }
}

/// Timeouts and the connection cap.
#[derive(Clone, Debug, PartialEq)]
pub struct ConnectionLimits {
    /// Time allowed for a request head to arrive (also the idle keep-alive
    /// timeout).
    pub header_timeout: Duration,
    /// Time allowed between two frames of a request body.
    pub body_timeout: Duration,
    /// Connections open at once (before the file-limit clamp).
    pub max_connections: usize,
    /// How long a connection asked to close may take to finish its answer.
    pub close_grace: Duration,
    /// Time allowed for a whole request body, from its head on (a body
    /// trickling a byte at a time is dropped at this deadline).
    pub body_deadline: Duration,
    /// Time allowed for writing a whole answer (a client that does not
    /// read it is dropped at this deadline, and the answer freed).
    pub write_deadline: Duration,
    /// Largest request body; a larger `Content-Length` is 413 at once,
    /// before any `100 Continue` and without reading a byte.
    pub max_body_bytes: usize,
    /// Request-body bytes held at once over all connections (read and not
    /// yet answered); a body that would exceed it is refused (503).
    pub body_budget_bytes: usize,
}

impl Default for ConnectionLimits {
    fn default() -> Self {
        Self {
            header_timeout: Duration::from_secs(5),
            body_timeout: Duration::from_secs(10),
            max_connections: 10_000,
            close_grace: Duration::from_secs(60),
            body_deadline: Duration::from_secs(30),
            write_deadline: Duration::from_secs(120),
            max_body_bytes: 1 << 20,
            body_budget_bytes: 64 << 20,
        }
    }
}
