//! The chunk rows of the SQLite store (`job_chunks`): a large job's
//! leased pieces, created by its coordinator, claimed, renewed, finished
//! or failed by any worker under fenced writes, and read back in order.
//! [`super::JobStore`]'s `JobBackend` methods of the same names call these.

use std::time::Duration;

use rusqlite::{OptionalExtension, TransactionBehavior, params};

use super::rows::{FENCE, JobStore};
use crate::jobs::admission;
use crate::jobs::backend::{ChunkLease, ChunkState, ClaimPolicy, ClaimedChunk, StoreError};
use crate::jobs::lease::{Lease, expiry_ms, now_ms};

pub(super) fn create_chunks(
    store: &JobStore,
    lease: &Lease,
    count: usize,
) -> Result<bool, StoreError> {
    let mut conn = store.conn();
    let tx = conn.transaction_with_behavior(TransactionBehavior::Immediate)?;
    let held: Option<i64> = tx
        .query_row(
            &format!("SELECT id FROM jobs WHERE {FENCE}"),
            params![lease.job_id, lease.owner, lease.epoch],
            |r| r.get(0),
        )
        .optional()?;
    if held.is_none() {
        return Ok(false);
    }
    {
        let mut stmt = tx.prepare(
            "INSERT OR IGNORE INTO job_chunks (job_id, idx, status) VALUES (?1, ?2, 'pending')",
        )?;
        for i in 0..count {
            stmt.execute(params![lease.job_id, i as i64])?;
        }
    }
    tx.commit()?;
    Ok(true)
}

pub(super) fn claim_chunk(
    store: &JobStore,
    job: Option<i64>,
    policy: &ClaimPolicy<'_>,
) -> Result<Option<ClaimedChunk>, StoreError> {
    let mut conn = store.conn();
    let tx = conn.transaction_with_behavior(TransactionBehavior::Immediate)?;
    let now = now_ms();
    tx.execute(
        "UPDATE job_chunks SET status = 'failed', error = ?1, lease_expires_ms = NULL
             WHERE status = 'running' AND ifnull(lease_expires_ms, 0) < ?2 AND attempts >= ?3",
        params![policy.exhausted_error, now, policy.max_attempts],
    )?;
    let expires = now.saturating_add(admission::millis(policy.lease));
    let claimed = tx
        .query_row(
            "UPDATE job_chunks SET status = 'running', attempts = attempts + 1,
                    lease_owner = ?1, lease_expires_ms = ?2, lease_epoch = lease_epoch + 1
                 WHERE (job_id, idx) = (
                     SELECT c.job_id, c.idx FROM job_chunks c JOIN jobs j ON j.id = c.job_id
                     WHERE j.status = 'running' AND (?4 IS NULL OR c.job_id = ?4)
                       AND (c.status = 'pending'
                            OR (c.status = 'running' AND ifnull(c.lease_expires_ms, 0) < ?3))
                     ORDER BY j.priority, c.job_id, c.idx LIMIT 1)
                 RETURNING job_id, idx, attempts, lease_epoch",
            params![store.worker.as_str(), expires, now, job],
            |r| {
                Ok((
                    r.get::<_, i64>(0)?,
                    r.get::<_, i64>(1)?,
                    r.get::<_, u32>(2)?,
                    r.get::<_, i64>(3)?,
                ))
            },
        )
        .optional()?;
    let Some((job_id, idx, attempts, epoch)) = claimed else {
        tx.commit()?;
        return Ok(None);
    };
    let request: String =
        tx.query_row("SELECT request FROM jobs WHERE id = ?1", [job_id], |r| {
            r.get(0)
        })?;
    tx.commit()?;
    Ok(Some(ClaimedChunk {
        lease: ChunkLease {
            job_id,
            index: idx as usize,
            owner: store.worker.as_str().to_string(),
            epoch,
        },
        request,
        attempts,
    }))
}

pub(super) fn renew_chunk(
    store: &JobStore,
    lease: &ChunkLease,
    duration: Duration,
) -> Result<bool, StoreError> {
    store.chunk_fenced("lease_expires_ms = ?4", lease, Some(&expiry_ms(duration)))
}

pub(super) fn finish_chunk(
    store: &JobStore,
    lease: &ChunkLease,
    result: &str,
) -> Result<bool, StoreError> {
    store.chunk_fenced(
        "status = 'done', result = ?4, lease_expires_ms = NULL, finished_by = lease_owner",
        lease,
        Some(&result),
    )
}

pub(super) fn fail_chunk(
    store: &JobStore,
    lease: &ChunkLease,
    error: &str,
) -> Result<bool, StoreError> {
    store.chunk_fenced(
        "status = 'failed', error = ?4, lease_expires_ms = NULL",
        lease,
        Some(&error),
    )
}

pub(super) fn release_chunk(store: &JobStore, lease: &ChunkLease) -> Result<bool, StoreError> {
    store.chunk_fenced("status = 'pending', lease_expires_ms = NULL", lease, None)
}

pub(super) fn chunk_state(store: &JobStore, job_id: i64) -> Result<ChunkState, StoreError> {
    let conn = store.conn();
    let (total, done): (i64, i64) = conn.query_row(
        "SELECT count(*), ifnull(sum(status = 'done'), 0) FROM job_chunks WHERE job_id = ?1",
        [job_id],
        |r| Ok((r.get(0)?, r.get(1)?)),
    )?;
    let failed: Option<String> = conn
        .query_row(
            "SELECT error FROM job_chunks WHERE job_id = ?1 AND status = 'failed'
                 ORDER BY idx LIMIT 1",
            [job_id],
            |r| r.get(0),
        )
        .optional()?;
    Ok(ChunkState {
        total: total as usize,
        done: done as usize,
        failed,
    })
}

pub(super) fn chunk_results(
    store: &JobStore,
    job_id: i64,
) -> Result<Vec<(usize, String)>, StoreError> {
    let conn = store.conn();
    let mut stmt = conn.prepare(
            "SELECT idx, result FROM job_chunks WHERE job_id = ?1 AND status = 'done' AND result IS NOT NULL ORDER BY idx",
        )?;
    let rows = stmt.query_map([job_id], |r| {
        Ok((r.get::<_, i64>(0)? as usize, r.get::<_, String>(1)?))
    })?;
    Ok(rows.collect::<Result<_, _>>()?)
}
