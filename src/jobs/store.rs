//! The SQLite job store (one file, WAL mode). A job row holds the submitted
//! request, its status, progress, and the answer or error body as JSON text.
//!
//! Status moves `queued → running → done | failed`, or `→ cancelled` from
//! `queued`/`running`. A `running` row whose process died (SIGKILL, power
//! loss) goes back to `queued` when the store is next opened, so no accepted
//! job is lost and every one runs to completion.

use std::path::Path;
use std::sync::Mutex;
use std::time::Duration;

use rusqlite::{Connection, OptionalExtension, params};
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

const SCHEMA: &str = "
CREATE TABLE IF NOT EXISTS jobs (
    id          INTEGER PRIMARY KEY AUTOINCREMENT,
    kind        TEXT NOT NULL,
    request     TEXT NOT NULL,
    status      TEXT NOT NULL CHECK (status IN ('queued', 'running', 'done', 'failed', 'cancelled')),
    progress    REAL NOT NULL DEFAULT 0,
    attempts    INTEGER NOT NULL DEFAULT 0,
    result      TEXT,
    error       TEXT,
    created_at  TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),
    started_at  TEXT,
    finished_at TEXT
);
CREATE INDEX IF NOT EXISTS jobs_by_status ON jobs (status, id);
";

const NOW: &str = "strftime('%Y-%m-%dT%H:%M:%fZ', 'now')";

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

    fn parse(s: &str) -> Self {
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

/// A failure of the database itself (disk full, corrupt file).
#[derive(Debug, thiserror::Error)]
#[error("job store: {0}")]
pub struct StoreError(#[from] rusqlite::Error);

/// Why a job was not accepted.
#[derive(Debug, thiserror::Error)]
pub enum InsertError {
    #[error("the job queue is full ({pending} jobs queued or running, at most {limit})")]
    QueueFull { pending: usize, limit: usize },
    #[error(transparent)]
    Store(#[from] StoreError),
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
}

/// A job taken from the queue by a worker.
#[derive(Clone, Debug)]
pub struct ClaimedJob {
    pub id: i64,
    pub kind: String,
    /// The submitted body, JSON text.
    pub request: String,
}

/// The job table behind one connection (SQLite serialises writers anyway).
pub struct JobStore {
    conn: Mutex<Connection>,
}

impl JobStore {
    /// Opens (or creates) the database at `path`, in WAL mode, and puts
    /// jobs left `running` by a dead process back in the queue.
    pub fn open(path: &Path) -> Result<Self, StoreError> {
        let conn = Connection::open(path)?;
        conn.busy_timeout(Duration::from_secs(5))?;
        conn.pragma_update(None, "journal_mode", "WAL")?;
        conn.pragma_update(None, "synchronous", "NORMAL")?;
        Self::init(conn)
    }

    /// A private in-memory store (tests).
    pub fn open_in_memory() -> Result<Self, StoreError> {
        Self::init(Connection::open_in_memory()?)
    }

    fn init(conn: Connection) -> Result<Self, StoreError> {
        conn.execute_batch(SCHEMA)?;
        let store = Self {
            conn: Mutex::new(conn),
        };
        let requeued = store.requeue_running()?;
        if requeued > 0 {
            tracing::info!(requeued, "interrupted jobs put back in the queue");
        }
        Ok(store)
    }

    fn conn(&self) -> std::sync::MutexGuard<'_, Connection> {
        // A panic while holding the lock leaves the connection usable.
        self.conn.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The SQLite journal mode (`wal` for a file database).
    pub fn journal_mode(&self) -> Result<String, StoreError> {
        Ok(self
            .conn()
            .query_row("PRAGMA journal_mode", [], |r| r.get(0))?)
    }

    /// Every `running` job back to `queued` (at start-up and shutdown).
    pub fn requeue_running(&self) -> Result<usize, StoreError> {
        Ok(self.conn().execute(
            "UPDATE jobs SET status = 'queued' WHERE status = 'running'",
            [],
        )?)
    }

    /// Stores a new queued job unless `limit` jobs are already pending.
    pub fn insert(&self, kind: &str, request: &str, limit: usize) -> Result<i64, InsertError> {
        let mut conn = self.conn();
        let tx = conn.transaction().map_err(StoreError)?;
        let pending: i64 = tx
            .query_row(
                "SELECT count(*) FROM jobs WHERE status IN ('queued', 'running')",
                [],
                |r| r.get(0),
            )
            .map_err(StoreError)?;
        let pending = pending as usize;
        if pending >= limit {
            return Err(InsertError::QueueFull { pending, limit });
        }
        tx.execute(
            "INSERT INTO jobs (kind, request, status) VALUES (?1, ?2, 'queued')",
            params![kind, request],
        )
        .map_err(StoreError)?;
        let id = tx.last_insert_rowid();
        tx.commit().map_err(StoreError)?;
        Ok(id)
    }

    /// Marks the oldest queued job `running` and returns it.
    pub fn claim_next(&self) -> Result<Option<ClaimedJob>, StoreError> {
        let conn = self.conn();
        let sql = format!(
            "UPDATE jobs SET status = 'running', progress = 0, attempts = attempts + 1, started_at = {NOW}
             WHERE id = (SELECT id FROM jobs WHERE status = 'queued' ORDER BY id LIMIT 1)
             RETURNING id, kind, request"
        );
        Ok(conn
            .query_row(&sql, [], |r| {
                Ok(ClaimedJob {
                    id: r.get(0)?,
                    kind: r.get(1)?,
                    request: r.get(2)?,
                })
            })
            .optional()?)
    }

    /// Records progress of a running job; `false` when it is no longer
    /// running (cancelled meanwhile).
    pub fn set_progress(&self, id: i64, progress: f64) -> Result<bool, StoreError> {
        let n = self.conn().execute(
            "UPDATE jobs SET progress = ?2 WHERE id = ?1 AND status = 'running'",
            params![id, progress.clamp(0.0, 1.0)],
        )?;
        Ok(n == 1)
    }

    /// Whether the job is still `running` (not cancelled meanwhile).
    pub fn is_running(&self, id: i64) -> Result<bool, StoreError> {
        Ok(self.status(id)? == Some(JobStatus::Running))
    }

    pub fn status(&self, id: i64) -> Result<Option<JobStatus>, StoreError> {
        let s: Option<String> = self
            .conn()
            .query_row("SELECT status FROM jobs WHERE id = ?1", [id], |r| r.get(0))
            .optional()?;
        Ok(s.map(|s| JobStatus::parse(&s)))
    }

    /// A running job finished with `result` (JSON text). No effect if it
    /// was cancelled meanwhile.
    pub fn finish_done(&self, id: i64, result: &str) -> Result<bool, StoreError> {
        let sql = format!(
            "UPDATE jobs SET status = 'done', progress = 1, result = ?2, error = NULL, finished_at = {NOW}
             WHERE id = ?1 AND status = 'running'"
        );
        Ok(self.conn().execute(&sql, params![id, result])? == 1)
    }

    /// A running job failed with `error` (JSON error body).
    pub fn finish_failed(&self, id: i64, error: &str) -> Result<bool, StoreError> {
        let sql = format!(
            "UPDATE jobs SET status = 'failed', result = NULL, error = ?2, finished_at = {NOW}
             WHERE id = ?1 AND status = 'running'"
        );
        Ok(self.conn().execute(&sql, params![id, error])? == 1)
    }

    /// A running job interrupted by shutdown goes back to the queue.
    pub fn requeue(&self, id: i64) -> Result<bool, StoreError> {
        Ok(self.conn().execute(
            "UPDATE jobs SET status = 'queued' WHERE id = ?1 AND status = 'running'",
            [id],
        )? == 1)
    }

    /// Cancels a queued or running job; returns the row afterwards (None:
    /// unknown id). A finished job is left as it is.
    pub fn cancel(&self, id: i64, error: &str) -> Result<Option<JobRecord>, StoreError> {
        let sql = format!(
            "UPDATE jobs SET status = 'cancelled', error = ?2, finished_at = {NOW}
             WHERE id = ?1 AND status IN ('queued', 'running')"
        );
        self.conn().execute(&sql, params![id, error])?;
        self.get(id)
    }

    const COLUMNS: &str =
        "id, kind, status, progress, attempts, created_at, started_at, finished_at";

    fn record(r: &rusqlite::Row<'_>, with_payload: bool) -> rusqlite::Result<JobRecord> {
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
            result: if with_payload { r.get(8)? } else { None },
            error: if with_payload { r.get(9)? } else { None },
        })
    }

    /// One job with its answer or error.
    pub fn get(&self, id: i64) -> Result<Option<JobRecord>, StoreError> {
        let sql = format!(
            "SELECT {}, result, error FROM jobs WHERE id = ?1",
            Self::COLUMNS
        );
        Ok(self
            .conn()
            .query_row(&sql, [id], |r| Self::record(r, true))
            .optional()?)
    }

    /// Jobs, newest first, without answers; optionally only one status.
    pub fn list(
        &self,
        status: Option<JobStatus>,
        limit: usize,
    ) -> Result<Vec<JobRecord>, StoreError> {
        let conn = self.conn();
        let sql = format!(
            "SELECT {}, error FROM jobs WHERE (?1 IS NULL OR status = ?1) ORDER BY id DESC LIMIT ?2",
            Self::COLUMNS
        );
        let mut stmt = conn.prepare(&sql)?;
        let rows = stmt.query_map(params![status.map(JobStatus::as_str), limit as i64], |r| {
            let mut rec = Self::record(r, false)?;
            rec.error = r.get(8)?;
            Ok(rec)
        })?;
        Ok(rows.collect::<Result<_, _>>()?)
    }

    /// The submitted request of a job (JSON text).
    pub fn request(&self, id: i64) -> Result<Option<String>, StoreError> {
        Ok(self
            .conn()
            .query_row("SELECT request FROM jobs WHERE id = ?1", [id], |r| r.get(0))
            .optional()?)
    }

    /// Number of jobs queued or running.
    pub fn pending(&self) -> Result<usize, StoreError> {
        let n: i64 = self.conn().query_row(
            "SELECT count(*) FROM jobs WHERE status IN ('queued', 'running')",
            [],
            |r| r.get(0),
        )?;
        Ok(n as usize)
    }
}
