//! What the SQLite and PostgreSQL stores decide alike, whatever their SQL:
//! a retried submission under an idempotency key, the queue's and the
//! owner's limits on pending jobs, the store quota's arithmetic (for a job
//! and for a named system), and the conversions of byte counts and
//! durations to the stores' `BIGINT` columns. Each store reads the counts
//! in its own transaction and asks here what they mean.

use std::time::Duration;

use super::backend::{InsertError, Inserted, KeyedJob, NewJob, PutSystem, StoreError};

/// The job first stored under `key`: the same job again when the body is
/// the same, a refusal when it differs.
pub fn replay(first: KeyedJob, job: &NewJob<'_>, key: &str) -> Result<Inserted, InsertError> {
    if first.request_hash != job.request_hash {
        return Err(InsertError::KeyReused {
            key: key.to_string(),
            id: first.id,
        });
    }
    Ok(Inserted::Existing {
        id: first.id,
        kind: first.kind,
        status: first.status,
    })
}

/// Refuses a job when `pending` jobs (all owners) fill the queue.
pub fn check_pending(job: &NewJob<'_>, pending: usize) -> Result<(), InsertError> {
    if pending >= job.max_pending {
        return Err(InsertError::QueueFull {
            pending,
            limit: job.max_pending,
        });
    }
    Ok(())
}

/// Refuses a job when its owner already has `mine` jobs pending.
pub fn check_owner_pending(job: &NewJob<'_>, mine: usize) -> Result<(), InsertError> {
    if mine >= job.max_pending_per_owner {
        return Err(InsertError::QuotaFull {
            pending: mine,
            limit: job.max_pending_per_owner,
        });
    }
    Ok(())
}

/// The bytes a new job keeps until its answer is stored: its request and
/// its answer's estimate.
pub fn job_bytes(job: &NewJob<'_>) -> u64 {
    (job.request.len() as u64).saturating_add(job.reserve_bytes)
}

/// Refuses a job adding `adding` bytes to the owner's `stored` (the sum
/// the store read) past the quota; `oldest_finished_s` is read only then.
pub fn check_job_store(
    job: &NewJob<'_>,
    stored: i64,
    adding: u64,
    oldest_finished_s: impl FnOnce() -> Result<Option<f64>, StoreError>,
) -> Result<Result<(), InsertError>, StoreError> {
    let stored = stored.max(0) as u64;
    if stored.saturating_add(adding) > job.max_stored_bytes {
        return Ok(Err(InsertError::StoreFull {
            stored,
            adding,
            limit: job.max_stored_bytes,
            oldest_finished_s: oldest_finished_s()?,
        }));
    }
    Ok(Ok(()))
}

/// Refuses a named system of `body_bytes` when the owner's `stored` bytes,
/// less the `replaced` body of the same name, would pass `limit`;
/// `oldest_finished_s` is read only then.
pub fn check_system_store(
    stored: i64,
    replaced: i64,
    body_bytes: usize,
    limit: u64,
    oldest_finished_s: impl FnOnce() -> Result<Option<f64>, StoreError>,
) -> Result<Option<PutSystem>, StoreError> {
    let stored = (stored - replaced).max(0) as u64;
    if stored.saturating_add(body_bytes as u64) > limit {
        return Ok(Some(PutSystem::StoreFull {
            stored,
            limit,
            oldest_finished_s: oldest_finished_s()?,
        }));
    }
    Ok(None)
}

/// A byte count as a `BIGINT` column holds it (saturating).
pub fn bytes_column(bytes: u64) -> i64 {
    bytes.min(i64::MAX as u64) as i64
}

/// A duration in milliseconds as a `BIGINT` column holds it (saturating).
pub fn millis(d: Duration) -> i64 {
    d.as_millis().min(i64::MAX as u128) as i64
}
