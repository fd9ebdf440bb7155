//! The SQLite schema: its versions (`PRAGMA user_version`, and one row
//! each in `schema_version` from version 3 on), applied at open by
//! [`migrate`] in one `BEGIN IMMEDIATE` transaction.

use rusqlite::{Connection, TransactionBehavior};

use crate::jobs::backend::StoreError;

const SCHEMA_V1: &str = "
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

const SCHEMA_V2: &str = "
ALTER TABLE jobs ADD COLUMN owner TEXT;
ALTER TABLE jobs ADD COLUMN idempotency_key TEXT;
ALTER TABLE jobs ADD COLUMN request_hash TEXT;
ALTER TABLE jobs ADD COLUMN lease_owner TEXT;
ALTER TABLE jobs ADD COLUMN lease_expires_ms INTEGER;
ALTER TABLE jobs ADD COLUMN lease_epoch INTEGER NOT NULL DEFAULT 0;
CREATE UNIQUE INDEX jobs_by_idempotency_key ON jobs (ifnull(owner, ''), idempotency_key)
    WHERE idempotency_key IS NOT NULL;
CREATE INDEX jobs_by_owner ON jobs (owner, status);
";

const SCHEMA_V3: &str = "
ALTER TABLE jobs ADD COLUMN priority INTEGER NOT NULL DEFAULT 0;
CREATE INDEX jobs_by_claim ON jobs (status, priority, id);
CREATE TABLE job_chunks (
    job_id           INTEGER NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,
    idx              INTEGER NOT NULL,
    status           TEXT NOT NULL CHECK (status IN ('pending', 'running', 'done', 'failed')),
    attempts         INTEGER NOT NULL DEFAULT 0,
    lease_owner      TEXT,
    lease_expires_ms INTEGER,
    lease_epoch      INTEGER NOT NULL DEFAULT 0,
    result           TEXT,
    error            TEXT,
    finished_by      TEXT,
    PRIMARY KEY (job_id, idx)
);
CREATE INDEX job_chunks_by_status ON job_chunks (status, job_id, idx);
CREATE TABLE workers (
    id           TEXT PRIMARY KEY,
    role         TEXT NOT NULL,
    started_ms   INTEGER NOT NULL,
    heartbeat_ms INTEGER NOT NULL
);
CREATE TABLE IF NOT EXISTS schema_version (
    version    INTEGER PRIMARY KEY,
    applied_at TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now'))
);
INSERT OR IGNORE INTO schema_version (version) VALUES (1), (2), (3);
";

const SCHEMA_V4: &str = "
CREATE TABLE systems (
    owner      TEXT NOT NULL,
    name       TEXT NOT NULL,
    body       TEXT NOT NULL,
    created_at TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),
    updated_at TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),
    PRIMARY KEY (owner, name)
);
INSERT OR IGNORE INTO schema_version (version) VALUES (4);
";

const SCHEMA_V5: &str = "
ALTER TABLE jobs ADD COLUMN stored_bytes INTEGER NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN chunk_takeovers INTEGER NOT NULL DEFAULT 0;
CREATE TABLE job_answers (
    job_id INTEGER NOT NULL,
    page   INTEGER NOT NULL,
    data   BLOB NOT NULL,
    PRIMARY KEY (job_id, page)
);
INSERT INTO job_answers (job_id, page, data)
    SELECT id, 0, CAST(result AS BLOB) FROM jobs WHERE status = 'done' AND result IS NOT NULL;
UPDATE jobs SET stored_bytes = octet_length(request) + ifnull(octet_length(result), 0)
    + ifnull(octet_length(error), 0), result = NULL;
INSERT OR IGNORE INTO schema_version (version) VALUES (5);
";

/// The current schema version.
pub const SCHEMA_VERSION: i64 = 5;

/// `PRAGMA auto_vacuum` of a file kept in incremental vacuum.
pub(super) const AUTO_VACUUM_INCREMENTAL: i64 = 2;

pub(super) fn migrate(conn: &mut Connection) -> Result<(), StoreError> {
    let version: i64 = conn.query_row("PRAGMA user_version", [], |r| r.get(0))?;
    if version >= SCHEMA_VERSION {
        return Ok(());
    }
    let tx = conn.transaction_with_behavior(TransactionBehavior::Immediate)?;
    // Re-read under the write lock: another process may have migrated meanwhile.
    let version: i64 = tx.query_row("PRAGMA user_version", [], |r| r.get(0))?;
    if version < 1 {
        tx.execute_batch(SCHEMA_V1)?;
    }
    if version < 2 {
        tx.execute_batch(SCHEMA_V2)?;
    }
    if version < 3 {
        tx.execute_batch(SCHEMA_V3)?;
    }
    if version < 4 {
        tx.execute_batch(SCHEMA_V4)?;
    }
    if version < 5 {
        tx.execute_batch(SCHEMA_V5)?;
    }
    tx.pragma_update(None, "user_version", SCHEMA_VERSION)?;
    tx.commit()?;
    Ok(())
}
