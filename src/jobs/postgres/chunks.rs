//! The chunk rows of the PostgreSQL store (`job_chunks`, claimed with
//! `FOR UPDATE SKIP LOCKED`): a large job's leased pieces, created by its
//! coordinator, claimed, renewed, finished or failed by any worker under
//! fenced writes, and read back in order. [`super::PgStore`]'s
//! `JobBackend` methods of the same names call these.

use std::time::Duration;

use super::rows::{FENCE, PgStore};
use crate::jobs::admission::millis;
use crate::jobs::backend::{ChunkLease, ChunkState, ClaimPolicy, ClaimedChunk, StoreError};
use crate::jobs::lease::{Lease, expiry_ms, now_ms};

pub(super) fn create_chunks(
    store: &PgStore,
    lease: &Lease,
    count: usize,
) -> Result<bool, StoreError> {
    let count = count.min(i32::MAX as usize) as i32;
    store.with(|c| {
        let mut tx = c.transaction()?;
        let held = tx.query_opt(
            &format!("SELECT id FROM jobs WHERE {FENCE} FOR UPDATE"),
            &[&lease.job_id, &lease.owner, &lease.epoch],
        )?;
        if held.is_none() {
            return Ok(false);
        }
        tx.execute(
            "INSERT INTO job_chunks (job_id, idx, status)
                 SELECT $1, i, 'pending' FROM generate_series(0, $2 - 1) AS i
                 ON CONFLICT (job_id, idx) DO NOTHING",
            &[&lease.job_id, &count],
        )?;
        tx.commit()?;
        Ok(true)
    })
}

pub(super) fn claim_chunk(
    store: &PgStore,
    job: Option<i64>,
    policy: &ClaimPolicy<'_>,
) -> Result<Option<ClaimedChunk>, StoreError> {
    let owner = store.worker.as_str().to_string();
    store.with(|c| {
            let now = now_ms();
            let max_attempts = policy.max_attempts.min(i32::MAX as u32) as i32;
            c.execute(
                "UPDATE job_chunks SET status = 'failed', error = $1, lease_expires_ms = NULL
                 WHERE status = 'running' AND coalesce(lease_expires_ms, 0) < $2 AND attempts >= $3",
                &[&policy.exhausted_error, &now, &max_attempts],
            )?;
            let expires = now.saturating_add(millis(policy.lease));
            let row = c.query_opt(
                "WITH next AS (
                     SELECT c.job_id, c.idx FROM job_chunks c JOIN jobs j ON j.id = c.job_id
                     WHERE j.status = 'running' AND ($4::BIGINT IS NULL OR c.job_id = $4)
                       AND (c.status = 'pending'
                            OR (c.status = 'running' AND coalesce(c.lease_expires_ms, 0) < $3))
                     ORDER BY j.priority, c.job_id, c.idx LIMIT 1
                     FOR UPDATE OF c SKIP LOCKED)
                 UPDATE job_chunks u SET status = 'running', attempts = u.attempts + 1,
                     lease_owner = $1, lease_expires_ms = $2, lease_epoch = u.lease_epoch + 1
                 FROM next WHERE u.job_id = next.job_id AND u.idx = next.idx
                 RETURNING u.job_id, u.idx, u.attempts, u.lease_epoch,
                     (SELECT request FROM jobs WHERE id = u.job_id)",
                &[&owner, &expires, &now, &job],
            )?;
            Ok(row.map(|r| {
                let idx: i32 = r.get(1);
                let attempts: i32 = r.get(2);
                ClaimedChunk {
                    lease: ChunkLease {
                        job_id: r.get(0),
                        index: idx.max(0) as usize,
                        owner: owner.clone(),
                        epoch: r.get(3),
                    },
                    request: r.get(4),
                    attempts: attempts.max(0) as u32,
                }
            }))
        })
}

pub(super) fn renew_chunk(
    store: &PgStore,
    lease: &ChunkLease,
    duration: Duration,
) -> Result<bool, StoreError> {
    let at = expiry_ms(duration);
    store.chunk_fenced("lease_expires_ms = $5", lease, Some(&at))
}

pub(super) fn finish_chunk(
    store: &PgStore,
    lease: &ChunkLease,
    result: &str,
) -> Result<bool, StoreError> {
    store.chunk_fenced(
        "status = 'done', result = $5, lease_expires_ms = NULL, finished_by = lease_owner",
        lease,
        Some(&result),
    )
}

pub(super) fn fail_chunk(
    store: &PgStore,
    lease: &ChunkLease,
    error: &str,
) -> Result<bool, StoreError> {
    store.chunk_fenced(
        "status = 'failed', error = $5, lease_expires_ms = NULL",
        lease,
        Some(&error),
    )
}

pub(super) fn release_chunk(store: &PgStore, lease: &ChunkLease) -> Result<bool, StoreError> {
    store.chunk_fenced("status = 'pending', lease_expires_ms = NULL", lease, None)
}

pub(super) fn chunk_state(store: &PgStore, job_id: i64) -> Result<ChunkState, StoreError> {
    store.with(|c| {
        let r = c.query_one(
            "SELECT count(*), count(*) FILTER (WHERE status = 'done'),
                    (SELECT error FROM job_chunks WHERE job_id = $1 AND status = 'failed'
                     ORDER BY idx LIMIT 1)
                 FROM job_chunks WHERE job_id = $1",
            &[&job_id],
        )?;
        let (total, done): (i64, i64) = (r.get(0), r.get(1));
        Ok(ChunkState {
            total: total as usize,
            done: done as usize,
            failed: r.get(2),
        })
    })
}

pub(super) fn chunk_results(
    store: &PgStore,
    job_id: i64,
) -> Result<Vec<(usize, String)>, StoreError> {
    store.with(|c| {
            Ok(c.query(
                "SELECT idx, result FROM job_chunks WHERE job_id = $1 AND status = 'done' AND result IS NOT NULL
                 ORDER BY idx",
                &[&job_id],
            )?
            .iter()
            .map(|r| (r.get::<_, i32>(0).max(0) as usize, r.get(1)))
            .collect())
        })
}
