//! The PostgreSQL job store ([`PgStore`]): the same [`JobBackend`] as
//! SQLite, for an API and any number of worker processes on any hosts
//! sharing one database (`TETHERPLAN_DATABASE_URL=postgres://…`).
//!
//! Claims are one statement each: `UPDATE … WHERE id = (SELECT … FOR
//! UPDATE SKIP LOCKED)`, so concurrent workers never wait on each other's
//! candidate rows, and the claim is a lease (owner, expiry in ms since the
//! Unix epoch, epoch) exactly as in SQLite, not a row lock held by an open
//! transaction: a worker that dies, or loses its network, loses its jobs
//! and chunks when the lease expires, and its fenced writes change nothing
//! afterwards. (Lease expiry compares the workers' clocks: keep them in
//! sync, as NTP does.)
//!
//! Crate: the synchronous `postgres` client (rust-postgres, which is
//! `tokio-postgres` driven by a private runtime). The store is used from
//! plain threads (workers) and from `spawn_blocking` (handlers), like the
//! SQLite one; the client panics if it is called on a thread that runs a
//! tokio runtime, so such a call is moved to a scoped thread
//! ([`PgStore::with`]). sqlx is not used: its `libsqlite3-sys` cannot be
//! linked with the one `rusqlite` needs. Queue crates (apalis-postgres,
//! graphile_worker) own their job model; ours needs fenced chunk writes
//! and the existing job contract, a few statements over two tables.
//!
//! Schema versions, one row each in `schema_version`, applied at start
//! under an advisory lock (idempotent; several processes may start at once):
//! 1. `jobs` (as SQLite's versions 1–2, with `priority`);
//! 2. `job_chunks` and `workers`;
//! 3. `systems`: the named systems (SPEC §9), keyed by (owner, name);
//! 4. `jobs.stored_bytes` (the store quota), `jobs.chunk_takeovers` and
//!    `job_answers`: a done
//!    job's answer in pages (`BYTEA`, streamed by `GET /api/v1/jobs/{id}`);
//!    the answers of version 3 move there, one page each.

use std::sync::{Mutex, MutexGuard};
use std::time::Duration;

use postgres::{Client, NoTls, Row};

use super::chunks::{ChunkLease, ChunkState, ClaimedChunk};
use super::lease::{Lease, WorkerId, expiry_ms, now_ms};
use super::store::{
    ClaimPolicy, ClaimedJob, InsertError, Inserted, JobBackend, JobHead, JobRecord, JobStatus,
    KeyedJob, NewJob, PutSystem, StoreError, StoredSystem,
};

const MIGRATIONS: &[(i32, &str)] = &[
    (
        1,
        "CREATE TABLE jobs (
            id               BIGSERIAL PRIMARY KEY,
            kind             TEXT NOT NULL,
            request          TEXT NOT NULL,
            status           TEXT NOT NULL
                CHECK (status IN ('queued', 'running', 'done', 'failed', 'cancelled')),
            progress         DOUBLE PRECISION NOT NULL DEFAULT 0,
            attempts         INTEGER NOT NULL DEFAULT 0,
            result           TEXT,
            error            TEXT,
            created_at       TEXT NOT NULL DEFAULT to_char(clock_timestamp() AT TIME ZONE 'UTC',
                                 'YYYY-MM-DD\"T\"HH24:MI:SS.MS\"Z\"'),
            started_at       TEXT,
            finished_at      TEXT,
            owner            TEXT,
            idempotency_key  TEXT,
            request_hash     TEXT,
            lease_owner      TEXT,
            lease_expires_ms BIGINT,
            lease_epoch      BIGINT NOT NULL DEFAULT 0,
            priority         INTEGER NOT NULL DEFAULT 0
        );
        CREATE INDEX jobs_by_claim ON jobs (status, priority, id);
        CREATE INDEX jobs_by_owner ON jobs (owner, status);
        CREATE UNIQUE INDEX jobs_by_idempotency_key ON jobs (coalesce(owner, ''), idempotency_key)
            WHERE idempotency_key IS NOT NULL;",
    ),
    (
        2,
        "CREATE TABLE job_chunks (
            job_id           BIGINT NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,
            idx              INTEGER NOT NULL,
            status           TEXT NOT NULL CHECK (status IN ('pending', 'running', 'done', 'failed')),
            attempts         INTEGER NOT NULL DEFAULT 0,
            lease_owner      TEXT,
            lease_expires_ms BIGINT,
            lease_epoch      BIGINT NOT NULL DEFAULT 0,
            result           TEXT,
            error            TEXT,
            finished_by      TEXT,
            PRIMARY KEY (job_id, idx)
        );
        CREATE INDEX job_chunks_by_status ON job_chunks (status, job_id, idx);
        CREATE TABLE workers (
            id           TEXT PRIMARY KEY,
            role         TEXT NOT NULL,
            started_ms   BIGINT NOT NULL,
            heartbeat_ms BIGINT NOT NULL
        );",
    ),
    (
        3,
        "CREATE TABLE systems (
            owner      TEXT NOT NULL,
            name       TEXT NOT NULL,
            body       TEXT NOT NULL,
            created_at TEXT NOT NULL DEFAULT to_char(clock_timestamp() AT TIME ZONE 'UTC',
                           'YYYY-MM-DD\"T\"HH24:MI:SS.MS\"Z\"'),
            updated_at TEXT NOT NULL DEFAULT to_char(clock_timestamp() AT TIME ZONE 'UTC',
                           'YYYY-MM-DD\"T\"HH24:MI:SS.MS\"Z\"'),
            PRIMARY KEY (owner, name)
        );",
    ),
    (
        4,
        "ALTER TABLE jobs ADD COLUMN stored_bytes BIGINT NOT NULL DEFAULT 0;
        ALTER TABLE jobs ADD COLUMN chunk_takeovers INTEGER NOT NULL DEFAULT 0;
        CREATE TABLE job_answers (
            job_id BIGINT NOT NULL,
            page   INTEGER NOT NULL,
            data   BYTEA NOT NULL,
            PRIMARY KEY (job_id, page)
        );
        INSERT INTO job_answers (job_id, page, data)
            SELECT id, 0, convert_to(result, 'UTF8') FROM jobs
            WHERE status = 'done' AND result IS NOT NULL;
        UPDATE jobs SET stored_bytes = octet_length(request) + coalesce(octet_length(result), 0)
            + coalesce(octet_length(error), 0), result = NULL;",
    ),
];

/// The current schema version.
pub const SCHEMA_VERSION: i32 = 4;

/// See the SQLite store: a claim of a job with chunks to run is counted
/// in `chunk_takeovers`, not against its limit of attempts.
const UNFINISHED_CHUNKS: &str =
    "EXISTS (SELECT 1 FROM job_chunks c WHERE c.job_id = jobs.id AND c.status <> 'done')";

/// The chunks of a finished job left running go back to pending.
const RELEASE_ENDED_CHUNKS: &str =
    "UPDATE job_chunks SET status = 'pending', lease_expires_ms = NULL
    WHERE status = 'running'
      AND job_id IN (SELECT id FROM jobs WHERE status IN ('done', 'failed', 'cancelled'))";

/// Seconds since owner `$1`'s oldest finished job finished (NULL: none).
const OLDEST_FINISHED: &str =
    "SELECT extract(epoch FROM clock_timestamp() - min(finished_at)::TIMESTAMPTZ)::FLOAT8
     FROM jobs WHERE owner IS NOT DISTINCT FROM $1::TEXT
       AND status IN ('done', 'failed', 'cancelled')";

/// Bytes kept by owner `$1` (NULL: no tokens): its jobs and named systems.
const STORED_BYTES: &str = "SELECT
    (SELECT coalesce(sum(stored_bytes), 0) FROM jobs WHERE owner IS NOT DISTINCT FROM $1::TEXT)::BIGINT
    + (SELECT coalesce(sum(octet_length(body)), 0) FROM systems
       WHERE owner = coalesce($1::TEXT, ''))::BIGINT";

/// Advisory lock key of migrations (and of inserts: quotas are counted
/// and the row written under it).
const MIGRATION_LOCK: i64 = 0x7465_7468_6572_0001;
const INSERT_LOCK: i64 = 0x7465_7468_6572_0002;

const NOW: &str =
    "to_char(clock_timestamp() AT TIME ZONE 'UTC', 'YYYY-MM-DD\"T\"HH24:MI:SS.MS\"Z\"')";

const FENCE: &str = "id = $1 AND status = 'running' AND lease_owner = $2 AND lease_epoch = $3";

const CHUNK_FENCE: &str = "job_id = $1 AND idx = $2 AND status = 'running' AND lease_owner = $3
    AND lease_epoch = $4 AND (SELECT status FROM jobs WHERE id = $1) = 'running'";

const COLUMNS: &str =
    "id, kind, status, progress, attempts, created_at, started_at, finished_at, lease_owner";

/// The job tables of one PostgreSQL database, claiming as one worker.
pub struct PgStore {
    url: String,
    client: Mutex<Option<Client>>,
    worker: WorkerId,
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
    /// Connects, migrates the schema and takes over the jobs of dead
    /// processes on this host.
    pub fn open(url: &str) -> Result<Self, StoreError> {
        let store = Self {
            url: url.to_string(),
            client: Mutex::new(None),
            worker: WorkerId::this_process(),
        };
        store.with(|c| migrate(c))?;
        let recovered = store.recover_local()?;
        if recovered > 0 {
            tracing::info!(
                recovered,
                "jobs of a dead process on this host taken over at start-up"
            );
        }
        Ok(store)
    }

    /// Runs `f` on the connection (reconnecting when it was lost), off any
    /// tokio runtime thread.
    fn with<R: Send>(
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

    fn fenced(
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

    fn chunk_fenced(
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

fn connect(url: &str) -> Result<Client, StoreError> {
    Client::connect(url, NoTls).map_err(|e| {
        StoreError(format!(
            "cannot connect to {}: {}",
            redact(url),
            plain_error(&e)
        ))
    })
}

/// The tables a migration creates (`CREATE TABLE [IF NOT EXISTS] name`).
fn created_tables(sql: &str) -> Vec<&str> {
    sql.split("CREATE TABLE ")
        .skip(1)
        .filter_map(|rest| {
            let rest = rest.trim_start();
            let rest = rest.strip_prefix("IF NOT EXISTS ").unwrap_or(rest);
            rest.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .next()
                .filter(|n| !n.is_empty())
        })
        .collect()
}

/// Brings the schema to [`SCHEMA_VERSION`] in one transaction: either
/// every missing version is applied, or (a table it did not make, a
/// failed statement) nothing is and the database is left as it was.
fn migrate(c: &mut Client) -> Result<(), StoreError> {
    let mut tx = c.transaction()?;
    tx.execute("SELECT pg_advisory_xact_lock($1)", &[&MIGRATION_LOCK])?;
    tx.batch_execute(
        "CREATE TABLE IF NOT EXISTS schema_version (
            version    INTEGER PRIMARY KEY,
            applied_at TIMESTAMPTZ NOT NULL DEFAULT now()
        )",
    )?;
    let current: i32 = tx
        .query_one("SELECT coalesce(max(version), 0) FROM schema_version", &[])
        .map_err(|e| {
            StoreError(format!(
                "the table `schema_version` is not the one tetherplan keeps ({}): use an empty \
                 database or schema; nothing was changed",
                plain_error(&e)
            ))
        })?
        .get(0);
    if current > SCHEMA_VERSION {
        return Err(StoreError(format!(
            "the job database is at schema version {current}, newer than this server's \
             {SCHEMA_VERSION}: run a newer tetherplan; nothing was changed"
        )));
    }
    let mut applied = Vec::new();
    for (version, sql) in MIGRATIONS {
        if *version > current {
            for table in created_tables(sql) {
                let exists: bool = tx
                    .query_one("SELECT to_regclass($1::TEXT) IS NOT NULL", &[&table])?
                    .get(0);
                if exists {
                    return Err(StoreError(format!(
                        "the database already has a table `{table}` that tetherplan did not make \
                         (its schema is at version {current}; version {version} creates \
                         `{table}`): point TETHERPLAN_DATABASE_URL at an empty database or \
                         schema, or drop that table; nothing was changed"
                    )));
                }
            }
            tx.batch_execute(sql).map_err(|e| {
                StoreError(format!(
                    "the migration of the job database to schema version {version} failed: {}; \
                     nothing was changed",
                    plain_error(&e)
                ))
            })?;
            tx.execute(
                "INSERT INTO schema_version (version) VALUES ($1)",
                &[version],
            )?;
            applied.push(*version);
        }
    }
    tx.commit().map_err(|e| {
        StoreError(format!(
            "the migration of the job database could not be committed: {}; nothing was changed",
            plain_error(&e)
        ))
    })?;
    // Logged once committed: a rolled-back migration is not reported as done.
    for version in applied {
        tracing::info!(version, "job database migrated");
    }
    Ok(())
}

fn record(r: &Row) -> JobRecord {
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

fn find_by_key(
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

fn millis(d: Duration) -> i64 {
    d.as_millis().min(i64::MAX as u128) as i64
}

impl JobBackend for PgStore {
    fn worker(&self) -> &WorkerId {
        &self.worker
    }

    fn find_by_key(&self, owner: Option<&str>, key: &str) -> Result<Option<KeyedJob>, StoreError> {
        self.with(|c| find_by_key(c, owner, key))
    }

    fn insert(&self, job: &NewJob<'_>) -> Result<Inserted, InsertError> {
        let outcome = self.with(|c| {
            let mut tx = c.transaction()?;
            tx.execute("SELECT pg_advisory_xact_lock($1)", &[&INSERT_LOCK])?;
            if let Some(key) = job.idempotency_key
                && let Some(first) = find_by_key(&mut tx, job.owner, key)?
            {
                if first.request_hash != job.request_hash {
                    return Ok(Err(InsertError::KeyReused {
                        key: key.to_string(),
                        id: first.id,
                    }));
                }
                return Ok(Ok(Inserted::Existing {
                    id: first.id,
                    kind: first.kind,
                    status: first.status,
                }));
            }
            let pending: i64 = tx
                .query_one(
                    "SELECT count(*) FROM jobs WHERE status IN ('queued', 'running')",
                    &[],
                )?
                .get(0);
            if pending as usize >= job.max_pending {
                return Ok(Err(InsertError::QueueFull {
                    pending: pending as usize,
                    limit: job.max_pending,
                }));
            }
            if let Some(owner) = job.owner {
                let mine: i64 = tx
                    .query_one(
                        "SELECT count(*) FROM jobs WHERE owner = $1 AND status IN ('queued', 'running')",
                        &[&owner],
                    )?
                    .get(0);
                if mine as usize >= job.max_pending_per_owner {
                    return Ok(Err(InsertError::QuotaFull {
                        pending: mine as usize,
                        limit: job.max_pending_per_owner,
                    }));
                }
            }
            let adding = (job.request.len() as u64).saturating_add(job.reserve_bytes);
            let stored: i64 = tx.query_one(STORED_BYTES, &[&job.owner])?.get(0);
            let stored = stored.max(0) as u64;
            if stored.saturating_add(adding) > job.max_stored_bytes {
                let oldest_finished_s: Option<f64> =
                    tx.query_one(OLDEST_FINISHED, &[&job.owner])?.get(0);
                return Ok(Err(InsertError::StoreFull {
                    stored,
                    adding,
                    limit: job.max_stored_bytes,
                    oldest_finished_s,
                }));
            }
            let priority = job.priority as i32;
            let stored_bytes = adding.min(i64::MAX as u64) as i64;
            let id: i64 = tx
                .query_one(
                    "INSERT INTO jobs (kind, request, status, owner, idempotency_key, request_hash, priority,
                         stored_bytes)
                     VALUES ($1, $2, 'queued', $3, $4, $5, $6, $7) RETURNING id",
                    &[
                        &job.kind,
                        &job.request,
                        &job.owner,
                        &job.idempotency_key,
                        &job.request_hash,
                        &priority,
                        &stored_bytes,
                    ],
                )?
                .get(0);
            tx.commit()?;
            Ok(Ok(Inserted::New(id)))
        })?;
        outcome
    }

    fn claim(&self, policy: &ClaimPolicy<'_>) -> Result<Option<ClaimedJob>, StoreError> {
        let owner = self.worker.as_str().to_string();
        self.with(|c| {
            let now = now_ms();
            let max_attempts = policy.max_attempts.min(i32::MAX as u32) as i32;
            let exhausted = c.execute(
                &format!(
                    "UPDATE jobs SET status = 'failed', result = NULL, error = $1, finished_at = {NOW},
                        lease_expires_ms = NULL,
                        stored_bytes = octet_length(request) + octet_length($1::TEXT)
                     WHERE status = 'running' AND coalesce(lease_expires_ms, 0) < $2 AND attempts - chunk_takeovers >= $3
                       AND NOT {UNFINISHED_CHUNKS}"
                ),
                &[&policy.exhausted_error, &now, &max_attempts],
            )?;
            if exhausted > 0 {
                c.execute(RELEASE_ENDED_CHUNKS, &[])?;
                tracing::warn!(
                    jobs = exhausted,
                    attempts = policy.max_attempts,
                    "jobs whose process died at every attempt were failed"
                );
            }
            let expires = now.saturating_add(millis(policy.lease));
            let row = c.query_opt(
                &format!(
                    "UPDATE jobs SET status = 'running', progress = 0,
                        attempts = attempts + 1,
                        chunk_takeovers = chunk_takeovers
                            + (CASE WHEN {UNFINISHED_CHUNKS} THEN 1 ELSE 0 END),
                        started_at = {NOW}, lease_owner = $1, lease_expires_ms = $2,
                        lease_epoch = lease_epoch + 1
                     WHERE id = (SELECT id FROM jobs
                                 WHERE status = 'queued'
                                    OR (status = 'running' AND coalesce(lease_expires_ms, 0) < $3)
                                 ORDER BY priority, id LIMIT 1
                                 FOR UPDATE SKIP LOCKED)
                     RETURNING id, kind, request, attempts, lease_epoch"
                ),
                &[&owner, &expires, &now],
            )?;
            Ok(row.map(|r| {
                let attempts: i32 = r.get(3);
                ClaimedJob {
                    id: r.get(0),
                    kind: r.get(1),
                    request: r.get(2),
                    attempts: attempts.max(0) as u32,
                    lease: Lease {
                        job_id: r.get(0),
                        owner: owner.clone(),
                        epoch: r.get(4),
                    },
                }
            }))
        })
    }

    fn renew(&self, lease: &Lease, duration: Duration) -> Result<bool, StoreError> {
        let at = expiry_ms(duration);
        self.fenced("lease_expires_ms = $4", lease, Some(&at))
    }

    fn set_progress(&self, lease: &Lease, progress: f64) -> Result<bool, StoreError> {
        let p = progress.clamp(0.0, 1.0);
        self.fenced("progress = $4", lease, Some(&p))
    }

    /// The answer goes into `job_answers` in pages, in the transaction
    /// that marks the job done.
    fn finish_done(&self, lease: &Lease, result: &str) -> Result<bool, StoreError> {
        let bytes = result.len() as i64;
        self.with(|c| {
            let mut tx = c.transaction()?;
            let n = tx.execute(
                &format!(
                    "UPDATE jobs SET status = 'done', progress = 1, result = NULL, error = NULL,
                        finished_at = {NOW}, lease_expires_ms = NULL,
                        stored_bytes = octet_length(request) + $4::BIGINT
                     WHERE {FENCE}"
                ),
                &[&lease.job_id, &lease.owner, &lease.epoch, &bytes],
            )?;
            if n != 1 {
                return Ok(false);
            }
            let insert = tx.prepare(
                "INSERT INTO job_answers (job_id, page, data) VALUES ($1, $2, $3)
                 ON CONFLICT (job_id, page) DO UPDATE SET data = excluded.data",
            )?;
            for (i, page) in super::store::answer_pages(result).enumerate() {
                let i = i as i32;
                tx.execute(&insert, &[&lease.job_id, &i, &page])?;
            }
            // the chunks' results are in the answer now: not kept twice
            tx.execute(
                "UPDATE job_chunks SET result = NULL WHERE job_id = $1",
                &[&lease.job_id],
            )?;
            tx.commit()?;
            Ok(true)
        })
    }

    fn finish_failed(&self, lease: &Lease, error: &str) -> Result<bool, StoreError> {
        let failed = self.fenced(
            &format!(
                "status = 'failed', result = NULL, error = $4, finished_at = {NOW},
                 lease_expires_ms = NULL, stored_bytes = octet_length(request) + octet_length($4::TEXT)"
            ),
            lease,
            Some(&error),
        )?;
        if failed {
            self.with(|c| {
                c.execute(RELEASE_ENDED_CHUNKS, &[])?;
                Ok(())
            })?;
        }
        Ok(failed)
    }

    fn release(&self, lease: &Lease) -> Result<bool, StoreError> {
        self.fenced("status = 'queued', lease_expires_ms = NULL", lease, None)
    }

    fn release_all(&self) -> Result<usize, StoreError> {
        let me = self.worker.as_str();
        self.with(|c| {
            c.execute(
                "UPDATE job_chunks SET status = 'pending', lease_expires_ms = NULL
                 WHERE status = 'running' AND lease_owner = $1",
                &[&me],
            )?;
            Ok(c.execute(
                "UPDATE jobs SET status = 'queued', lease_expires_ms = NULL
                 WHERE status = 'running' AND lease_owner = $1",
                &[&me],
            )? as usize)
        })
    }

    fn recover_local(&self) -> Result<usize, StoreError> {
        self.with(|c| {
            let mut n = 0;
            for table in ["jobs", "job_chunks"] {
                let owners: Vec<String> = c
                    .query(
                        &format!(
                            "SELECT DISTINCT lease_owner FROM {table}
                             WHERE status = 'running' AND lease_owner IS NOT NULL"
                        ),
                        &[],
                    )?
                    .iter()
                    .map(|r| r.get(0))
                    .collect();
                for owner in owners.iter().filter(|o| self.worker.is_dead_local(o)) {
                    let k = c.execute(
                        &format!(
                            "UPDATE {table} SET lease_expires_ms = 0
                             WHERE status = 'running' AND lease_owner = $1"
                        ),
                        &[owner],
                    )?;
                    if table == "jobs" {
                        n += k as usize;
                    }
                }
            }
            Ok(n)
        })
    }

    fn cancel(
        &self,
        id: i64,
        owner: Option<&str>,
        error: &str,
    ) -> Result<Option<JobRecord>, StoreError> {
        self.with(|c| {
            c.execute(
                &format!(
                    "UPDATE jobs SET status = 'cancelled', error = $2, finished_at = {NOW},
                        lease_expires_ms = NULL,
                        stored_bytes = octet_length(request) + octet_length($2::TEXT)
                     WHERE id = $1 AND status IN ('queued', 'running')
                       AND ($3::TEXT IS NULL OR owner = $3)"
                ),
                &[&id, &error, &owner],
            )?;
            c.execute(RELEASE_ENDED_CHUNKS, &[])?;
            Ok(())
        })?;
        self.get_owned(id, owner)
    }

    fn get_owned(&self, id: i64, owner: Option<&str>) -> Result<Option<JobRecord>, StoreError> {
        let Some(head) = self.get_head(id, owner)? else {
            return Ok(None);
        };
        let mut rec = head.record;
        if head.answer_pages.is_some() {
            let pages: Vec<Vec<u8>> = self.with(|c| {
                Ok(c.query(
                    "SELECT data FROM job_answers WHERE job_id = $1 ORDER BY page",
                    &[&id],
                )?
                .iter()
                .map(|r| r.get(0))
                .collect())
            })?;
            rec.result = Some(super::store::join_pages(id, pages)?);
        }
        Ok(Some(rec))
    }

    fn get_head(&self, id: i64, owner: Option<&str>) -> Result<Option<JobHead>, StoreError> {
        self.with(|c| {
            Ok(c.query_opt(
                &format!(
                    "SELECT {COLUMNS}, error,
                        (SELECT count(*) FROM job_answers WHERE job_id = jobs.id)
                     FROM jobs WHERE id = $1 AND ($2::TEXT IS NULL OR owner = $2)"
                ),
                &[&id, &owner],
            )?
            .map(|r| {
                let mut record = record(&r);
                record.error = r.get(9);
                let pages: i64 = r.get(10);
                let answer_pages =
                    (record.status == JobStatus::Done).then_some(pages.max(0) as usize);
                JobHead {
                    record,
                    answer_pages,
                }
            }))
        })
    }

    fn answer_page(&self, id: i64, page: usize) -> Result<Option<Vec<u8>>, StoreError> {
        let page = page.min(i32::MAX as usize) as i32;
        self.with(|c| {
            Ok(c.query_opt(
                "SELECT data FROM job_answers WHERE job_id = $1 AND page = $2",
                &[&id, &page],
            )?
            .map(|r| r.get(0)))
        })
    }

    fn stored_bytes(&self, owner: Option<&str>) -> Result<u64, StoreError> {
        self.with(|c| {
            let n: i64 = c.query_one(STORED_BYTES, &[&owner])?.get(0);
            Ok(n.max(0) as u64)
        })
    }

    fn list_owned(
        &self,
        owner: Option<&str>,
        status: Option<JobStatus>,
        limit: usize,
    ) -> Result<Vec<JobRecord>, StoreError> {
        let status = status.map(JobStatus::as_str);
        let limit = limit.min(i64::MAX as usize) as i64;
        self.with(|c| {
            Ok(c.query(
                &format!(
                    "SELECT {COLUMNS}, error FROM jobs
                     WHERE ($1::TEXT IS NULL OR status = $1) AND ($3::TEXT IS NULL OR owner = $3)
                     ORDER BY id DESC LIMIT $2"
                ),
                &[&status, &limit, &owner],
            )?
            .iter()
            .map(|r| {
                let mut rec = record(r);
                rec.error = r.get(9);
                rec
            })
            .collect())
        })
    }

    fn status_owned(&self, id: i64, owner: Option<&str>) -> Result<Option<JobStatus>, StoreError> {
        self.with(|c| {
            Ok(c.query_opt(
                "SELECT status FROM jobs WHERE id = $1 AND ($2::TEXT IS NULL OR owner = $2)",
                &[&id, &owner],
            )?
            .map(|r| JobStatus::parse(&r.get::<_, String>(0))))
        })
    }

    fn pending(&self) -> Result<usize, StoreError> {
        self.with(|c| {
            let n: i64 = c
                .query_one(
                    "SELECT count(*) FROM jobs WHERE status IN ('queued', 'running')",
                    &[],
                )?
                .get(0);
            Ok(n as usize)
        })
    }

    fn store_kind(&self) -> &'static str {
        "postgres"
    }

    fn create_chunks(&self, lease: &Lease, count: usize) -> Result<bool, StoreError> {
        let count = count.min(i32::MAX as usize) as i32;
        self.with(|c| {
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

    fn claim_chunk(
        &self,
        job: Option<i64>,
        policy: &ClaimPolicy<'_>,
    ) -> Result<Option<ClaimedChunk>, StoreError> {
        let owner = self.worker.as_str().to_string();
        self.with(|c| {
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

    fn renew_chunk(&self, lease: &ChunkLease, duration: Duration) -> Result<bool, StoreError> {
        let at = expiry_ms(duration);
        self.chunk_fenced("lease_expires_ms = $5", lease, Some(&at))
    }

    fn finish_chunk(&self, lease: &ChunkLease, result: &str) -> Result<bool, StoreError> {
        self.chunk_fenced(
            "status = 'done', result = $5, lease_expires_ms = NULL, finished_by = lease_owner",
            lease,
            Some(&result),
        )
    }

    fn fail_chunk(&self, lease: &ChunkLease, error: &str) -> Result<bool, StoreError> {
        self.chunk_fenced(
            "status = 'failed', error = $5, lease_expires_ms = NULL",
            lease,
            Some(&error),
        )
    }

    fn release_chunk(&self, lease: &ChunkLease) -> Result<bool, StoreError> {
        self.chunk_fenced("status = 'pending', lease_expires_ms = NULL", lease, None)
    }

    fn chunk_state(&self, job_id: i64) -> Result<ChunkState, StoreError> {
        self.with(|c| {
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

    fn chunk_results(&self, job_id: i64) -> Result<Vec<(usize, String)>, StoreError> {
        self.with(|c| {
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

    fn worker_heartbeat(&self, role: &str) -> Result<(), StoreError> {
        let me = self.worker.as_str();
        self.with(|c| {
            let now = now_ms();
            c.execute(
                "INSERT INTO workers (id, role, started_ms, heartbeat_ms) VALUES ($1, $2, $3, $3)
                 ON CONFLICT (id) DO UPDATE SET heartbeat_ms = excluded.heartbeat_ms",
                &[&me, &role, &now],
            )?;
            Ok(())
        })
    }

    fn worker_leave(&self) -> Result<(), StoreError> {
        let me = self.worker.as_str();
        self.with(|c| {
            c.execute("DELETE FROM workers WHERE id = $1", &[&me])?;
            Ok(())
        })
    }

    fn housekeeping(
        &self,
        retention: Duration,
        stale_workers: Duration,
    ) -> Result<usize, StoreError> {
        let seconds = retention.as_secs_f64().min(1e12);
        let since = now_ms() - millis(stale_workers);
        self.with(|c| {
            let mut tx = c.transaction()?;
            tx.execute(
                "UPDATE job_chunks SET result = NULL WHERE result IS NOT NULL AND job_id IN
                     (SELECT id FROM jobs WHERE status IN ('done', 'failed', 'cancelled'))",
                &[],
            )?;
            let expired = "status IN ('done', 'failed', 'cancelled')
                     AND finished_at IS NOT NULL
                     AND finished_at <= to_char((clock_timestamp() - make_interval(secs => $1))
                         AT TIME ZONE 'UTC', 'YYYY-MM-DD\"T\"HH24:MI:SS.MS\"Z\"')";
            tx.execute(RELEASE_ENDED_CHUNKS, &[])?;
            for table in ["job_chunks", "job_answers"] {
                tx.execute(
                    &format!(
                        "DELETE FROM {table} WHERE job_id IN (SELECT id FROM jobs WHERE {expired})"
                    ),
                    &[&seconds],
                )?;
            }
            let purged = tx.execute(&format!("DELETE FROM jobs WHERE {expired}"), &[&seconds])?;
            tx.execute("DELETE FROM workers WHERE heartbeat_ms < $1", &[&since])?;
            tx.commit()?;
            Ok(purged as usize)
        })
    }

    fn live_workers(&self, within: Duration) -> Result<usize, StoreError> {
        let since = now_ms() - millis(within);
        self.with(|c| {
            let n: i64 = c
                .query_one(
                    "SELECT count(*) FROM workers WHERE heartbeat_ms >= $1",
                    &[&since],
                )?
                .get(0);
            Ok(n as usize)
        })
    }

    fn put_system(
        &self,
        owner: &str,
        name: &str,
        body: &str,
        max_per_owner: usize,
        max_stored_bytes: u64,
    ) -> Result<PutSystem, StoreError> {
        self.with(|c| {
            let mut tx = c.transaction()?;
            // Counted and written under the insert lock (the quota holds across processes).
            tx.execute("SELECT pg_advisory_xact_lock($1)", &[&INSERT_LOCK])?;
            let jobs_owner = (!owner.is_empty()).then_some(owner);
            let stored: i64 = tx.query_one(STORED_BYTES, &[&jobs_owner])?.get(0);
            let replaced: i64 = tx
                .query_one(
                    "SELECT coalesce(sum(octet_length(body)), 0)::BIGINT FROM systems
                     WHERE owner = $1 AND name = $2",
                    &[&owner, &name],
                )?
                .get(0);
            let stored = (stored - replaced).max(0) as u64;
            if stored.saturating_add(body.len() as u64) > max_stored_bytes {
                let oldest_finished_s: Option<f64> =
                    tx.query_one(OLDEST_FINISHED, &[&jobs_owner])?.get(0);
                return Ok(PutSystem::StoreFull {
                    stored,
                    limit: max_stored_bytes,
                    oldest_finished_s,
                });
            }
            let updated = tx.execute(
                &format!(
                    "UPDATE systems SET body = $3, updated_at = {NOW} WHERE owner = $1 AND name = $2"
                ),
                &[&owner, &name, &body],
            )?;
            let out = if updated == 1 {
                PutSystem::Updated
            } else {
                let n: i64 = tx
                    .query_one("SELECT count(*) FROM systems WHERE owner = $1", &[&owner])?
                    .get(0);
                if n as usize >= max_per_owner {
                    return Ok(PutSystem::Full { max: max_per_owner });
                }
                tx.execute(
                    "INSERT INTO systems (owner, name, body) VALUES ($1, $2, $3)",
                    &[&owner, &name, &body],
                )?;
                PutSystem::Created
            };
            tx.commit()?;
            Ok(out)
        })
    }

    fn get_system(&self, owner: &str, name: &str) -> Result<Option<StoredSystem>, StoreError> {
        self.with(|c| {
            Ok(c.query_opt(
                "SELECT name, body, created_at, updated_at FROM systems WHERE owner = $1 AND name = $2",
                &[&owner, &name],
            )?
            .map(|r| StoredSystem {
                name: r.get(0),
                body: r.get(1),
                created_at: r.get(2),
                updated_at: r.get(3),
            }))
        })
    }

    fn delete_system(&self, owner: &str, name: &str) -> Result<bool, StoreError> {
        self.with(|c| {
            let n = c.execute(
                "DELETE FROM systems WHERE owner = $1 AND name = $2",
                &[&owner, &name],
            )?;
            Ok(n == 1)
        })
    }

    fn list_systems(&self, owner: &str) -> Result<Vec<StoredSystem>, StoreError> {
        self.with(|c| {
            Ok(c.query(
                "SELECT name, created_at, updated_at FROM systems WHERE owner = $1 ORDER BY name",
                &[&owner],
            )?
            .iter()
            .map(|r| StoredSystem {
                name: r.get(0),
                body: String::new(),
                created_at: r.get(1),
                updated_at: r.get(2),
            })
            .collect())
        })
    }
}
