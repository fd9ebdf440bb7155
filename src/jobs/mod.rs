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

pub mod admission;
pub mod backend;
pub mod chunks;
pub mod estimate;
pub mod execute;
pub mod flights;
pub mod flights_sqlite;
pub mod kinds;
pub mod lease;
pub mod postgres;
pub mod queue;
pub mod split;
pub mod sqlite;
pub mod store;
pub mod worker;

pub use execute::{
    Executed, HOUSEKEEPING_INTERVAL, PRESENCE_INTERVAL, PRESENCE_TIMEOUT, STALE_WORKER_AGE,
    try_execute_next, work_once,
};
pub use queue::{JOB_NICENESS, JobQueue, SubmitError, Submitted, Submitter, sha256_hex};
