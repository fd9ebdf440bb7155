//! The PostgreSQL store's connection and the pieces every part of it uses:
//! [`PgStore`] (one client, reconnected when lost, used off any tokio
//! runtime thread), errors in plain words, the SQL fragments (fences, the
//! store quota's sums), the job row reader, fenced writes of a job and of a
//! chunk, and the idempotency key's lookup.

use std::sync::{Mutex, MutexGuard};

use postgres::{Client, NoTls, Row};

use crate::jobs::backend::{ChunkLease, JobRecord, JobStatus, KeyedJob, StoreError};
use crate::jobs::lease::{Lease, WorkerId};

/// See the SQLite store: a claim of a job with chunks to run is counted
/// in `chunk_takeovers`, not against its limit of attempts.
pub(super) const UNFINISHED_CHUNKS: &str =
    "EXISTS (SELECT 1 FROM job_chunks c WHERE c.job_id = jobs.id AND c.status <> 'done')";

/// The chunks of a finished job left running go back to pending.
pub(super) const RELEASE_ENDED_CHUNKS: &str =
    "UPDATE job_chunks SET status = 'pending', lease_expires_ms = NULL
    WHERE status = 'running'
      AND job_id IN (SELECT id FROM jobs WHERE status IN ('done', 'failed', 'cancelled'))";

/// Seconds since owner `$1`'s oldest finished job finished (NULL: none).
pub(super) const OLDEST_FINISHED: &str =
    "SELECT extract(epoch FROM clock_timestamp() - min(finished_at)::TIMESTAMPTZ)::FLOAT8
     FROM jobs WHERE owner IS NOT DISTINCT FROM $1::TEXT
       AND status IN ('done', 'failed', 'cancelled')";

/// Bytes kept by owner `$1` (NULL: no tokens): its jobs and named systems.
pub(super) const STORED_BYTES: &str = "SELECT
    (SELECT coalesce(sum(stored_bytes), 0) FROM jobs WHERE owner IS NOT DISTINCT FROM $1::TEXT)::BIGINT
    + (SELECT coalesce(sum(octet_length(body)), 0) FROM systems
       WHERE owner = coalesce($1::TEXT, ''))::BIGINT";

/// Advisory lock key of inserts (next to the migrations' in `schema.rs`):
/// quotas are counted and the row written under it.
pub(super) const INSERT_LOCK: i64 = 0x7465_7468_6572_0002;

pub(super) const NOW: &str =
    "to_char(clock_timestamp() AT TIME ZONE 'UTC', 'YYYY-MM-DD\"T\"HH24:MI:SS.MS\"Z\"')";

pub(super) const FENCE: &str =
    "id = $1 AND status = 'running' AND lease_owner = $2 AND lease_epoch = $3";

pub(super) const CHUNK_FENCE: &str =
    "job_id = $1 AND idx = $2 AND status = 'running' AND lease_owner = $3
    AND lease_epoch = $4 AND (SELECT status FROM jobs WHERE id = $1) = 'running'";

pub(super) const COLUMNS: &str =
    "id, kind, status, progress, attempts, created_at, started_at, finished_at, lease_owner";

/// The job tables of one PostgreSQL database, claiming as one worker.
pub struct PgStore {
    pub(super) url: String,
    pub(super) client: Mutex<Option<Client>>,
    pub(super) worker: WorkerId,
}

impl From<postgres::Error> for StoreError {
    fn from(e: postgres::Error) -> Self {
        Self(format!("postgres: {}", plain_error(&e)))
    }
}

/// A PostgreSQL error in plain words. The client's own `Display` says only
/// "db error" for everything the server refuses: this gives the server's
/// message, detail and code, named by what it means (authentication, a
/// missing database, a table that exists already), or for a connection
/// that never opened, why (refused, timed out, name not found).
pub fn plain_error(e: &postgres::Error) -> String {
    use postgres::error::SqlState;
    if let Some(db) = e.as_db_error() {
        let code = db.code();
        let what = if *code == SqlState::INVALID_PASSWORD
            || *code == SqlState::INVALID_AUTHORIZATION_SPECIFICATION
        {
            "authentication failed (check the user and password of the database URL)"
        } else if *code == SqlState::INVALID_CATALOG_NAME {
            "no such database"
        } else if *code == SqlState::DUPLICATE_TABLE || *code == SqlState::DUPLICATE_OBJECT {
            "a table or index of that name exists already"
        } else if *code == SqlState::INSUFFICIENT_PRIVILEGE {
            "permission denied"
        } else if *code == SqlState::TOO_MANY_CONNECTIONS {
            "the server has no free connection"
        } else {
            "the server refused the statement"
        };
        let mut s = format!("{what}: {} (SQLSTATE {})", db.message(), code.code());
        if let Some(d) = db.detail() {
            s.push_str("; ");
            s.push_str(d);
        }
        if let Some(h) = db.hint() {
            s.push_str("; hint: ");
            s.push_str(h);
        }
        return s;
    }
    let mut source = std::error::Error::source(e);
    while let Some(cause) = source {
        if let Some(io) = cause.downcast_ref::<std::io::Error>() {
            use std::io::ErrorKind::*;
            let what = match io.kind() {
                ConnectionRefused => {
                    "connection refused: nothing accepts connections at that host and port \
                     (is PostgreSQL running, and on that port?)"
                }
                TimedOut => "the connection timed out (host unreachable or a firewall?)",
                NotFound => "the host name was not found",
                ConnectionReset | UnexpectedEof => "the server closed the connection",
                _ => "the server could not be reached",
            };
            return format!("{what} ({io})");
        }
        source = cause.source();
    }
    e.to_string()
}

/// `url` without its password, for logs and messages.
pub fn redact(url: &str) -> String {
    match (url.find("://"), url.rfind('@')) {
        (Some(s), Some(at)) if at > s => {
            let creds = &url[s + 3..at];
            match creds.find(':') {
                Some(c) => format!("{}{}:***{}", &url[..s + 3], &creds[..c], &url[at..]),
                None => url.to_string(),
            }
        }
        _ => url.to_string(),
    }
}

impl PgStore {
    /// Runs `f` on the connection (reconnecting when it was lost), off any
    /// tokio runtime thread.
    pub(super) fn with<R: Send>(
        &self,
        f: impl FnOnce(&mut Client) -> Result<R, StoreError> + Send,
    ) -> Result<R, StoreError> {
        let run = || -> Result<R, StoreError> {
            let mut guard: MutexGuard<'_, Option<Client>> =
                self.client.lock().unwrap_or_else(|e| e.into_inner());
            if guard.as_ref().is_none_or(Client::is_closed) {
                *guard = Some(connect(&self.url)?);
            }
            let client = guard.as_mut().expect("connected above");
            let out = f(client);
            if out.is_err() && client.is_closed() {
                *guard = None;
            }
            out
        };
        if tokio::runtime::Handle::try_current().is_ok() {
            std::thread::scope(|s| {
                s.spawn(run)
                    .join()
                    .unwrap_or_else(|_| Err(StoreError("the database call panicked".into())))
            })
        } else {
            run()
        }
    }

    pub(super) fn fenced(
        &self,
        set: &str,
        lease: &Lease,
        extra: Option<&(dyn postgres::types::ToSql + Sync)>,
    ) -> Result<bool, StoreError> {
        let n = self.with(|c| {
            let n = match extra {
                Some(x) => c.execute(
                    &format!("UPDATE jobs SET {set} WHERE {FENCE}"),
                    &[&lease.job_id, &lease.owner, &lease.epoch, x],
                )?,
                None => c.execute(
                    &format!("UPDATE jobs SET {set} WHERE {FENCE}"),
                    &[&lease.job_id, &lease.owner, &lease.epoch],
                )?,
            };
            Ok(n)
        })?;
        Ok(n == 1)
    }

    pub(super) fn chunk_fenced(
        &self,
        set: &str,
        lease: &ChunkLease,
        extra: Option<&(dyn postgres::types::ToSql + Sync)>,
    ) -> Result<bool, StoreError> {
        let idx = lease.index as i32;
        let n = self.with(|c| {
            let sql = format!("UPDATE job_chunks SET {set} WHERE {CHUNK_FENCE}");
            let n = match extra {
                Some(x) => {
                    c.execute(&sql, &[&lease.job_id, &idx, &lease.owner, &lease.epoch, x])?
                }
                None => c.execute(&sql, &[&lease.job_id, &idx, &lease.owner, &lease.epoch])?,
            };
            Ok(n)
        })?;
        Ok(n == 1)
    }
}

/// The client is dropped off any tokio runtime thread: rust-postgres'
/// `Client` blocks on its private runtime when dropped, which panics
/// ("Cannot start a runtime from within a runtime") on a runtime thread,
/// as when the store fails to open inside `serve`.
impl Drop for PgStore {
    fn drop(&mut self) {
        let client = self
            .client
            .get_mut()
            .unwrap_or_else(|e| e.into_inner())
            .take();
        if let Some(client) = client {
            if tokio::runtime::Handle::try_current().is_ok() {
                std::thread::scope(|s| {
                    s.spawn(move || drop(client));
                });
            } else {
                drop(client);
            }
        }
    }
}

pub(super) fn connect(url: &str) -> Result<Client, StoreError> {
    Client::connect(url, NoTls).map_err(|e| {
        StoreError(format!(
            "cannot connect to {}: {}",
            redact(url),
            plain_error(&e)
        ))
    })
}

pub(super) fn record(r: &Row) -> JobRecord {
    let status: String = r.get(2);
    let attempts: i32 = r.get(4);
    JobRecord {
        id: r.get(0),
        kind: r.get(1),
        status: JobStatus::parse(&status),
        progress: r.get(3),
        attempts: attempts.max(0) as u32,
        created_at: r.get(5),
        started_at: r.get(6),
        finished_at: r.get(7),
        worker: r.get(8),
        result: None,
        error: None,
    }
}

pub(super) fn find_by_key(
    c: &mut impl postgres::GenericClient,
    owner: Option<&str>,
    key: &str,
) -> Result<Option<KeyedJob>, StoreError> {
    Ok(c.query_opt(
        "SELECT id, kind, status, request_hash FROM jobs
         WHERE coalesce(owner, '') = coalesce($1, '') AND idempotency_key = $2",
        &[&owner, &key],
    )?
    .map(|r| {
        let status: String = r.get(2);
        KeyedJob {
            id: r.get(0),
            kind: r.get(1),
            status: JobStatus::parse(&status),
            request_hash: r.get::<_, Option<String>>(3).unwrap_or_default(),
        }
    }))
}
