//! The SQLite store's connection and the pieces every part of it uses:
//! [`JobStore`] (one connection, one worker), the SQL fragments (fences,
//! the store quota's sums), the job row reader, fenced writes of a job and
//! of a chunk, and the idempotency key's lookup.

use std::sync::Mutex;

use rusqlite::{Connection, OptionalExtension, params};

use crate::jobs::backend::{ChunkLease, JobRecord, JobStatus, KeyedJob, StoreError};
use crate::jobs::lease::{Lease, WorkerId};

impl From<rusqlite::Error> for StoreError {
    fn from(e: rusqlite::Error) -> Self {
        Self(e.to_string())
    }
}

/// A job that still has chunks to run: a new claim of it (its coordinator
/// died) is counted in `chunk_takeovers` and not against its attempts
/// (`attempts - chunk_takeovers` is compared with the limit), and such a
/// job is not failed for its attempts: the chunks count their own.
pub(super) const UNFINISHED_CHUNKS: &str =
    "EXISTS (SELECT 1 FROM job_chunks c WHERE c.job_id = jobs.id AND c.status <> 'done')";

/// The chunks of a finished (failed, cancelled) job that were left
/// running go back to pending: never claimed again (their job is not
/// running), and none is left `running`.
pub(super) const RELEASE_ENDED_CHUNKS: &str =
    "UPDATE job_chunks SET status = 'pending', lease_expires_ms = NULL
    WHERE status = 'running'
      AND job_id IN (SELECT id FROM jobs WHERE status IN ('done', 'failed', 'cancelled'))";

/// Seconds since owner `?1`'s oldest finished job finished (NULL: none).
pub(super) const OLDEST_FINISHED: &str =
    "SELECT (julianday('now') - julianday(min(finished_at))) * 86400
    FROM jobs WHERE owner IS ?1 AND status IN ('done', 'failed', 'cancelled')";

/// Bytes kept by owner `?1` (NULL: no tokens): its jobs and named systems.
pub(super) const STORED_BYTES: &str = "SELECT
    (SELECT ifnull(sum(stored_bytes), 0) FROM jobs WHERE owner IS ?1)
    + (SELECT ifnull(sum(octet_length(body)), 0) FROM systems WHERE owner = ifnull(?1, ''))";

pub(super) const NOW: &str = "strftime('%Y-%m-%dT%H:%M:%fZ', 'now')";

/// The fence of a write: the row is still running under this lease.
pub(super) const FENCE: &str =
    "id = ?1 AND status = 'running' AND lease_owner = ?2 AND lease_epoch = ?3";

/// The job table behind one connection, claiming as one worker.
pub struct JobStore {
    pub(super) conn: Mutex<Connection>,
    pub(super) worker: WorkerId,
}

impl JobStore {
    pub(super) fn conn(&self) -> std::sync::MutexGuard<'_, Connection> {
        // A panic while holding the lock leaves the connection usable.
        self.conn.lock().unwrap_or_else(|e| e.into_inner())
    }

    pub(super) const COLUMNS: &str =
        "id, kind, status, progress, attempts, created_at, started_at, finished_at, lease_owner";

    pub(super) fn record(r: &rusqlite::Row<'_>) -> rusqlite::Result<JobRecord> {
        let status: String = r.get(2)?;
        Ok(JobRecord {
            id: r.get(0)?,
            kind: r.get(1)?,
            status: JobStatus::parse(&status),
            progress: r.get(3)?,
            attempts: r.get(4)?,
            created_at: r.get(5)?,
            started_at: r.get(6)?,
            finished_at: r.get(7)?,
            worker: r.get(8)?,
            result: None,
            error: None,
        })
    }

    pub(super) fn fenced(
        &self,
        sql_set: &str,
        lease: &Lease,
        extra: Option<&dyn rusqlite::ToSql>,
    ) -> Result<bool, StoreError> {
        let sql = format!("UPDATE jobs SET {sql_set} WHERE {FENCE}");
        let n = match extra {
            Some(x) => self
                .conn()
                .execute(&sql, params![lease.job_id, lease.owner, lease.epoch, x])?,
            None => self
                .conn()
                .execute(&sql, params![lease.job_id, lease.owner, lease.epoch])?,
        };
        Ok(n == 1)
    }
}

/// The fence of a chunk write: the chunk is still running under this
/// lease and its job is still running.
pub(super) const CHUNK_FENCE: &str =
    "job_id = ?1 AND idx = ?2 AND status = 'running' AND lease_owner = ?3
    AND lease_epoch = ?5 AND (SELECT status FROM jobs WHERE id = job_id) = 'running'";

impl JobStore {
    pub(super) fn chunk_fenced(
        &self,
        sql_set: &str,
        lease: &ChunkLease,
        extra: Option<&dyn rusqlite::ToSql>,
    ) -> Result<bool, StoreError> {
        let sql = format!("UPDATE job_chunks SET {sql_set} WHERE {CHUNK_FENCE}");
        let none: Option<i64> = None;
        let x: &dyn rusqlite::ToSql = extra.unwrap_or(&none);
        let n = self.conn().execute(
            &sql,
            params![
                lease.job_id,
                lease.index as i64,
                lease.owner,
                x,
                lease.epoch
            ],
        )?;
        Ok(n == 1)
    }
}

pub(super) fn find_by_key(
    conn: &Connection,
    owner: Option<&str>,
    key: &str,
) -> Result<Option<KeyedJob>, StoreError> {
    Ok(conn
        .query_row(
            "SELECT id, kind, status, request_hash FROM jobs
             WHERE ifnull(owner, '') = ifnull(?1, '') AND idempotency_key = ?2",
            params![owner, key],
            |r| {
                let status: String = r.get(2)?;
                Ok(KeyedJob {
                    id: r.get(0)?,
                    kind: r.get(1)?,
                    status: JobStatus::parse(&status),
                    request_hash: r.get::<_, Option<String>>(3)?.unwrap_or_default(),
                })
            },
        )
        .optional()?)
}
