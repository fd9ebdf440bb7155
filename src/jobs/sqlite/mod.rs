//! The SQLite job store (one file, WAL mode): [`JobStore`], the embedded
//! default [`JobBackend`]. Several processes may share one file; SQLite
//! serialises writers, claims run in `BEGIN IMMEDIATE` transactions, and
//! leases (owner, expiry in ms since the Unix epoch, epoch) fence writes.
//!
//! Schema versions (`PRAGMA user_version`, and one row each in
//! `schema_version` from version 3 on), applied at open:
//! 1. the `jobs` table;
//! 2. owner, idempotency key and body hash, lease owner/expiry/epoch;
//! 3. job priority, `job_chunks` (leased chunks of large jobs), `workers`
//!    (live workers), `schema_version`;
//! 4. `systems`: the named systems (SPEC §9), keyed by (owner, name);
//! 5. `jobs.stored_bytes` (the store quota), `jobs.chunk_takeovers`
//!    (claims of a chunked job while chunks remain) and `job_answers`: a done
//!    job's answer in pages (streamed by `GET /api/v1/jobs/{id}`); the
//!    answers of version 4 move there, one page each.
//!
//! The file shrinks after a purge: the database is kept in
//! `auto_vacuum = INCREMENTAL` (set on a new file; an older file made
//! without it is converted by one `VACUUM` at open), and housekeeping that
//! deleted anything runs `PRAGMA incremental_vacuum` and a truncating WAL
//! checkpoint, so the pages of purged jobs go back to the file system.
//!
//! The store by part: `schema.rs` the schema versions and their migration,
//! `rows.rs` the connection, SQL fragments, row reader and fenced writes,
//! `chunks.rs` the chunk rows, `systems.rs` the named systems; this file
//! opens the store and implements [`JobBackend`]: the job rows, workers and
//! housekeeping here, the chunks and systems by calling their files. What
//! it decides as PostgreSQL does (quota, idempotency) is in
//! [`crate::jobs::admission`].

mod chunks;
mod rows;
mod schema;
mod systems;

use std::path::Path;
use std::sync::Mutex;
use std::time::Duration;

use rusqlite::{Connection, OptionalExtension, TransactionBehavior, params};

pub use rows::JobStore;
use rows::{
    FENCE, NOW, OLDEST_FINISHED, RELEASE_ENDED_CHUNKS, STORED_BYTES, UNFINISHED_CHUNKS, find_by_key,
};
pub use schema::SCHEMA_VERSION;
use schema::{AUTO_VACUUM_INCREMENTAL, migrate};

use super::admission;
use super::backend::{
    ChunkLease, ChunkState, ClaimPolicy, ClaimedChunk, ClaimedJob, InsertError, Inserted,
    JobBackend, JobHead, JobRecord, JobStatus, KeyedJob, NewJob, PutSystem, StoreError,
    StoredSystem,
};
use super::lease::{Lease, WorkerId, expiry_ms, now_ms};

impl JobStore {
    /// Opens (or creates) the database at `path`, in WAL mode, migrates it,
    /// and takes over the jobs of dead processes on this host.
    pub fn open(path: &Path) -> Result<Self, StoreError> {
        let conn = Connection::open(path)?;
        conn.busy_timeout(Duration::from_secs(10))?;
        // Before any table exists this takes effect at once; an older file
        // needs one VACUUM to change it (below).
        conn.pragma_update(None, "auto_vacuum", "INCREMENTAL")?;
        conn.pragma_update(None, "journal_mode", "WAL")?;
        conn.pragma_update(None, "synchronous", "NORMAL")?;
        let mode: i64 = conn.query_row("PRAGMA auto_vacuum", [], |r| r.get(0))?;
        if mode != AUTO_VACUUM_INCREMENTAL {
            tracing::info!(
                path = %path.display(),
                "converting the job database to incremental vacuum (once; the file shrinks after purges from now on)"
            );
            conn.execute_batch("VACUUM")?;
        }
        Self::init(conn)
    }

    /// Gives the free pages of the file back to the file system (after a
    /// purge): `incremental_vacuum` moves them to the end of the file and
    /// cuts it, the checkpoint writes that through the WAL and empties it.
    pub fn compact(&self) -> Result<(), StoreError> {
        let conn = self.conn();
        // Stepped to its end: each step frees one page.
        let mut stmt = conn.prepare("PRAGMA incremental_vacuum")?;
        let mut rows = stmt.query([])?;
        while rows.next()?.is_some() {}
        drop(rows);
        drop(stmt);
        // Busy readers may keep part of the WAL: that part is cut next time.
        conn.query_row("PRAGMA wal_checkpoint(TRUNCATE)", [], |_| Ok(()))?;
        Ok(())
    }

    /// A private in-memory store (tests).
    pub fn open_in_memory() -> Result<Self, StoreError> {
        Self::init(Connection::open_in_memory()?)
    }

    fn init(mut conn: Connection) -> Result<Self, StoreError> {
        migrate(&mut conn)?;
        let store = Self {
            conn: Mutex::new(conn),
            worker: WorkerId::this_process(),
        };
        let recovered = store.recover_local()?;
        if recovered > 0 {
            tracing::info!(
                recovered,
                "jobs of a dead process on this host taken over at start-up"
            );
        }
        Ok(store)
    }
    /// The SQLite journal mode (`wal` for a file database).
    pub fn journal_mode(&self) -> Result<String, StoreError> {
        Ok(self
            .conn()
            .query_row("PRAGMA journal_mode", [], |r| r.get(0))?)
    }

    /// Stores a queued job without owner or key (tests, tools).
    pub fn insert_simple(
        &self,
        kind: &str,
        request: &str,
        limit: usize,
    ) -> Result<i64, InsertError> {
        let job = NewJob {
            kind,
            request,
            owner: None,
            idempotency_key: None,
            request_hash: "",
            max_pending: limit,
            max_pending_per_owner: limit,
            priority: 0,
            reserve_bytes: 0,
            max_stored_bytes: u64::MAX,
        };
        match self.insert(&job)? {
            Inserted::New(id) | Inserted::Existing { id, .. } => Ok(id),
        }
    }

    /// Claims the next job with a 30 s lease and no attempt cap (tests, tools).
    pub fn claim_next(&self) -> Result<Option<ClaimedJob>, StoreError> {
        self.claim(&ClaimPolicy {
            lease: Duration::from_secs(30),
            max_attempts: u32::MAX,
            exhausted_error: "{}",
        })
    }
}

impl JobBackend for JobStore {
    fn worker(&self) -> &WorkerId {
        &self.worker
    }

    fn find_by_key(&self, owner: Option<&str>, key: &str) -> Result<Option<KeyedJob>, StoreError> {
        find_by_key(&self.conn(), owner, key)
    }

    fn insert(&self, job: &NewJob<'_>) -> Result<Inserted, InsertError> {
        let mut conn = self.conn();
        let tx = conn
            .transaction_with_behavior(TransactionBehavior::Immediate)
            .map_err(StoreError::from)?;
        if let Some(key) = job.idempotency_key
            && let Some(first) = find_by_key(&tx, job.owner, key)?
        {
            return admission::replay(first, job, key);
        }
        let count = |sql: &str, p: &[&dyn rusqlite::ToSql]| -> Result<usize, StoreError> {
            let n: i64 = tx.query_row(sql, p, |r| r.get(0))?;
            Ok(n as usize)
        };
        let pending = count(
            "SELECT count(*) FROM jobs WHERE status IN ('queued', 'running')",
            &[],
        )?;
        admission::check_pending(job, pending)?;
        if let Some(owner) = job.owner {
            let mine = count(
                "SELECT count(*) FROM jobs WHERE owner = ?1 AND status IN ('queued', 'running')",
                &[&owner],
            )?;
            admission::check_owner_pending(job, mine)?;
        }
        let adding = admission::job_bytes(job);
        let stored: i64 = tx
            .query_row(STORED_BYTES, [job.owner], |r| r.get(0))
            .map_err(StoreError::from)?;
        admission::check_job_store(job, stored, adding, || {
            Ok(tx.query_row(OLDEST_FINISHED, [job.owner], |r| r.get(0))?)
        })??;
        tx.execute(
            "INSERT INTO jobs (kind, request, status, owner, idempotency_key, request_hash, priority,
                 stored_bytes)
             VALUES (?1, ?2, 'queued', ?3, ?4, ?5, ?6, ?7)",
            params![
                job.kind,
                job.request,
                job.owner,
                job.idempotency_key,
                job.request_hash,
                job.priority,
                admission::bytes_column(adding)
            ],
        )
        .map_err(StoreError::from)?;
        let id = tx.last_insert_rowid();
        tx.commit().map_err(StoreError::from)?;
        Ok(Inserted::New(id))
    }

    fn claim(&self, policy: &ClaimPolicy<'_>) -> Result<Option<ClaimedJob>, StoreError> {
        let mut conn = self.conn();
        let tx = conn.transaction_with_behavior(TransactionBehavior::Immediate)?;
        let now = now_ms();
        let exhausted = tx.execute(
            &format!(
                "UPDATE jobs SET status = 'failed', result = NULL, error = ?1, finished_at = {NOW},
                    lease_expires_ms = NULL, stored_bytes = octet_length(request) + octet_length(?1)
                 WHERE status = 'running' AND ifnull(lease_expires_ms, 0) < ?2 AND attempts - chunk_takeovers >= ?3
                   AND NOT {UNFINISHED_CHUNKS}"
            ),
            params![policy.exhausted_error, now, policy.max_attempts],
        )?;
        if exhausted > 0 {
            tx.execute(RELEASE_ENDED_CHUNKS, [])?;
            tracing::warn!(
                jobs = exhausted,
                attempts = policy.max_attempts,
                "jobs whose process died at every attempt were failed"
            );
        }
        let expires = now.saturating_add(admission::millis(policy.lease));
        let claimed = tx
            .query_row(
                &format!(
                    "UPDATE jobs SET status = 'running', progress = 0,
                        attempts = attempts + 1,
                        chunk_takeovers = chunk_takeovers
                            + (CASE WHEN {UNFINISHED_CHUNKS} THEN 1 ELSE 0 END),
                        started_at = {NOW}, lease_owner = ?1, lease_expires_ms = ?2,
                        lease_epoch = lease_epoch + 1
                     WHERE id = (SELECT id FROM jobs
                                 WHERE status = 'queued'
                                    OR (status = 'running' AND ifnull(lease_expires_ms, 0) < ?3)
                                 ORDER BY priority, id LIMIT 1)
                     RETURNING id, kind, request, attempts, lease_epoch"
                ),
                params![self.worker.as_str(), expires, now],
                |r| {
                    Ok(ClaimedJob {
                        id: r.get(0)?,
                        kind: r.get(1)?,
                        request: r.get(2)?,
                        attempts: r.get(3)?,
                        lease: Lease {
                            job_id: r.get(0)?,
                            owner: self.worker.as_str().to_string(),
                            epoch: r.get(4)?,
                        },
                    })
                },
            )
            .optional()?;
        tx.commit()?;
        Ok(claimed)
    }

    fn renew(&self, lease: &Lease, duration: Duration) -> Result<bool, StoreError> {
        self.fenced("lease_expires_ms = ?4", lease, Some(&expiry_ms(duration)))
    }

    fn set_progress(&self, lease: &Lease, progress: f64) -> Result<bool, StoreError> {
        self.fenced("progress = ?4", lease, Some(&progress.clamp(0.0, 1.0)))
    }

    /// The answer goes into `job_answers` in pages, in the transaction
    /// that marks the job done.
    fn finish_done(&self, lease: &Lease, result: &str) -> Result<bool, StoreError> {
        let mut conn = self.conn();
        let tx = conn.transaction_with_behavior(TransactionBehavior::Immediate)?;
        let n = tx.execute(
            &format!(
                "UPDATE jobs SET status = 'done', progress = 1, result = NULL, error = NULL,
                    finished_at = {NOW}, lease_expires_ms = NULL,
                    stored_bytes = octet_length(request) + ?4
                 WHERE {FENCE}"
            ),
            params![lease.job_id, lease.owner, lease.epoch, result.len() as i64],
        )?;
        if n != 1 {
            return Ok(false);
        }
        {
            let mut stmt = tx.prepare(
                "INSERT OR REPLACE INTO job_answers (job_id, page, data) VALUES (?1, ?2, ?3)",
            )?;
            for (i, page) in super::backend::answer_pages(result).enumerate() {
                stmt.execute(params![lease.job_id, i as i64, page])?;
            }
        }
        // the chunks' results are in the answer now: not kept twice
        tx.execute(
            "UPDATE job_chunks SET result = NULL WHERE job_id = ?1",
            [lease.job_id],
        )?;
        tx.commit()?;
        Ok(true)
    }

    fn finish_failed(&self, lease: &Lease, error: &str) -> Result<bool, StoreError> {
        let failed = self.fenced(
            &format!(
                "status = 'failed', result = NULL, error = ?4, finished_at = {NOW},
                 lease_expires_ms = NULL, stored_bytes = octet_length(request) + octet_length(?4)"
            ),
            lease,
            Some(&error),
        )?;
        if failed {
            self.conn().execute(RELEASE_ENDED_CHUNKS, [])?;
        }
        Ok(failed)
    }

    fn release(&self, lease: &Lease) -> Result<bool, StoreError> {
        self.fenced("status = 'queued', lease_expires_ms = NULL", lease, None)
    }

    fn release_all(&self) -> Result<usize, StoreError> {
        let conn = self.conn();
        conn.execute(
            "UPDATE job_chunks SET status = 'pending', lease_expires_ms = NULL
             WHERE status = 'running' AND lease_owner = ?1",
            [self.worker.as_str()],
        )?;
        Ok(conn.execute(
            "UPDATE jobs SET status = 'queued', lease_expires_ms = NULL
             WHERE status = 'running' AND lease_owner = ?1",
            [self.worker.as_str()],
        )?)
    }

    fn recover_local(&self) -> Result<usize, StoreError> {
        let conn = self.conn();
        let owners: Vec<String> = {
            let mut stmt = conn.prepare(
                "SELECT DISTINCT lease_owner FROM jobs
                 WHERE status = 'running' AND lease_owner IS NOT NULL",
            )?;
            stmt.query_map([], |r| r.get(0))?
                .collect::<Result<_, _>>()?
        };
        let mut n = 0;
        for owner in owners.iter().filter(|o| self.worker.is_dead_local(o)) {
            n += conn.execute(
                "UPDATE jobs SET lease_expires_ms = 0 WHERE status = 'running' AND lease_owner = ?1",
                [owner],
            )?;
        }
        let chunk_owners: Vec<String> = {
            let mut stmt = conn.prepare(
                "SELECT DISTINCT lease_owner FROM job_chunks
                 WHERE status = 'running' AND lease_owner IS NOT NULL",
            )?;
            stmt.query_map([], |r| r.get(0))?
                .collect::<Result<_, _>>()?
        };
        for owner in chunk_owners.iter().filter(|o| self.worker.is_dead_local(o)) {
            conn.execute(
                "UPDATE job_chunks SET lease_expires_ms = 0 WHERE status = 'running' AND lease_owner = ?1",
                [owner],
            )?;
        }
        Ok(n)
    }

    fn cancel(
        &self,
        id: i64,
        owner: Option<&str>,
        error: &str,
    ) -> Result<Option<JobRecord>, StoreError> {
        let sql = format!(
            "UPDATE jobs SET status = 'cancelled', error = ?2, finished_at = {NOW}, lease_expires_ms = NULL,
                 stored_bytes = octet_length(request) + octet_length(?2)
             WHERE id = ?1 AND status IN ('queued', 'running') AND (?3 IS NULL OR owner = ?3)"
        );
        if self.conn().execute(&sql, params![id, error, owner])? == 1 {
            self.conn().execute(RELEASE_ENDED_CHUNKS, [])?;
        }
        self.get_owned(id, owner)
    }

    fn get_owned(&self, id: i64, owner: Option<&str>) -> Result<Option<JobRecord>, StoreError> {
        let Some(head) = self.get_head(id, owner)? else {
            return Ok(None);
        };
        let mut rec = head.record;
        if head.answer_pages.is_some() {
            let conn = self.conn();
            let mut stmt =
                conn.prepare("SELECT data FROM job_answers WHERE job_id = ?1 ORDER BY page")?;
            let pages = stmt
                .query_map([id], |r| r.get::<_, Vec<u8>>(0))?
                .collect::<Result<Vec<_>, _>>()?;
            rec.result = Some(super::backend::join_pages(id, pages)?);
        }
        Ok(Some(rec))
    }

    fn get_head(&self, id: i64, owner: Option<&str>) -> Result<Option<JobHead>, StoreError> {
        let sql = format!(
            "SELECT {}, error, (SELECT count(*) FROM job_answers WHERE job_id = jobs.id)
             FROM jobs WHERE id = ?1 AND (?2 IS NULL OR owner = ?2)",
            Self::COLUMNS
        );
        Ok(self
            .conn()
            .query_row(&sql, params![id, owner], |r| {
                let mut record = Self::record(r)?;
                record.error = r.get(9)?;
                let pages: i64 = r.get(10)?;
                let answer_pages = (record.status == JobStatus::Done).then_some(pages as usize);
                Ok(JobHead {
                    record,
                    answer_pages,
                })
            })
            .optional()?)
    }

    fn answer_page(&self, id: i64, page: usize) -> Result<Option<Vec<u8>>, StoreError> {
        Ok(self
            .conn()
            .query_row(
                "SELECT data FROM job_answers WHERE job_id = ?1 AND page = ?2",
                params![id, page as i64],
                |r| r.get(0),
            )
            .optional()?)
    }

    fn stored_bytes(&self, owner: Option<&str>) -> Result<u64, StoreError> {
        let n: i64 = self.conn().query_row(STORED_BYTES, [owner], |r| r.get(0))?;
        Ok(n.max(0) as u64)
    }

    fn list_owned(
        &self,
        owner: Option<&str>,
        status: Option<JobStatus>,
        limit: usize,
    ) -> Result<Vec<JobRecord>, StoreError> {
        let conn = self.conn();
        let sql = format!(
            "SELECT {}, error FROM jobs
             WHERE (?1 IS NULL OR status = ?1) AND (?3 IS NULL OR owner = ?3)
             ORDER BY id DESC LIMIT ?2",
            Self::COLUMNS
        );
        let mut stmt = conn.prepare(&sql)?;
        let rows = stmt.query_map(
            params![status.map(JobStatus::as_str), limit as i64, owner],
            |r| {
                let mut rec = Self::record(r)?;
                rec.error = r.get(9)?;
                Ok(rec)
            },
        )?;
        Ok(rows.collect::<Result<_, _>>()?)
    }

    fn status_owned(&self, id: i64, owner: Option<&str>) -> Result<Option<JobStatus>, StoreError> {
        let s: Option<String> = self
            .conn()
            .query_row(
                "SELECT status FROM jobs WHERE id = ?1 AND (?2 IS NULL OR owner = ?2)",
                params![id, owner],
                |r| r.get(0),
            )
            .optional()?;
        Ok(s.map(|s| JobStatus::parse(&s)))
    }

    fn store_kind(&self) -> &'static str {
        "sqlite"
    }

    fn create_chunks(&self, lease: &Lease, count: usize) -> Result<bool, StoreError> {
        chunks::create_chunks(self, lease, count)
    }

    fn claim_chunk(
        &self,
        job: Option<i64>,
        policy: &ClaimPolicy<'_>,
    ) -> Result<Option<ClaimedChunk>, StoreError> {
        chunks::claim_chunk(self, job, policy)
    }

    fn renew_chunk(&self, lease: &ChunkLease, duration: Duration) -> Result<bool, StoreError> {
        chunks::renew_chunk(self, lease, duration)
    }

    fn finish_chunk(&self, lease: &ChunkLease, result: &str) -> Result<bool, StoreError> {
        chunks::finish_chunk(self, lease, result)
    }

    fn fail_chunk(&self, lease: &ChunkLease, error: &str) -> Result<bool, StoreError> {
        chunks::fail_chunk(self, lease, error)
    }

    fn release_chunk(&self, lease: &ChunkLease) -> Result<bool, StoreError> {
        chunks::release_chunk(self, lease)
    }

    fn chunk_state(&self, job_id: i64) -> Result<ChunkState, StoreError> {
        chunks::chunk_state(self, job_id)
    }

    fn chunk_results(&self, job_id: i64) -> Result<Vec<(usize, String)>, StoreError> {
        chunks::chunk_results(self, job_id)
    }

    fn worker_heartbeat(&self, role: &str) -> Result<(), StoreError> {
        let now = now_ms();
        self.conn().execute(
            "INSERT INTO workers (id, role, started_ms, heartbeat_ms) VALUES (?1, ?2, ?3, ?3)
             ON CONFLICT (id) DO UPDATE SET heartbeat_ms = excluded.heartbeat_ms",
            params![self.worker.as_str(), role, now],
        )?;
        Ok(())
    }

    fn worker_leave(&self) -> Result<(), StoreError> {
        self.conn()
            .execute("DELETE FROM workers WHERE id = ?1", [self.worker.as_str()])?;
        Ok(())
    }

    fn housekeeping(
        &self,
        retention: Duration,
        stale_workers: Duration,
    ) -> Result<usize, StoreError> {
        let mut conn = self.conn();
        let tx = conn.transaction()?;
        let seconds = retention.as_secs_f64().min(1e12);
        let cutoff: String = tx.query_row(
            "SELECT strftime('%Y-%m-%dT%H:%M:%fZ', 'now', ?1)",
            [format!("-{seconds:.3} seconds")],
            |r| r.get(0),
        )?;
        tx.execute(
            "UPDATE job_chunks SET result = NULL WHERE result IS NOT NULL AND job_id IN
                 (SELECT id FROM jobs WHERE status IN ('done', 'failed', 'cancelled'))",
            [],
        )?;
        tx.execute(RELEASE_ENDED_CHUNKS, [])?;
        for table in ["job_chunks", "job_answers"] {
            tx.execute(
                &format!(
                    "DELETE FROM {table} WHERE job_id IN
                         (SELECT id FROM jobs WHERE status IN ('done', 'failed', 'cancelled')
                             AND finished_at IS NOT NULL AND finished_at <= ?1)"
                ),
                [&cutoff],
            )?;
        }
        let purged = tx.execute(
            "DELETE FROM jobs WHERE status IN ('done', 'failed', 'cancelled')
                 AND finished_at IS NOT NULL AND finished_at <= ?1",
            [&cutoff],
        )?;
        let since = now_ms() - admission::millis(stale_workers);
        tx.execute("DELETE FROM workers WHERE heartbeat_ms < ?1", [since])?;
        tx.commit()?;
        let free_pages: i64 = conn.query_row("PRAGMA freelist_count", [], |r| r.get(0))?;
        drop(conn);
        if free_pages > 0 {
            self.compact()?;
        }
        Ok(purged)
    }

    fn live_workers(&self, within: Duration) -> Result<usize, StoreError> {
        let since = now_ms() - admission::millis(within);
        let n: i64 = self.conn().query_row(
            "SELECT count(*) FROM workers WHERE heartbeat_ms >= ?1",
            [since],
            |r| r.get(0),
        )?;
        Ok(n as usize)
    }

    fn put_system(
        &self,
        owner: &str,
        name: &str,
        body: &str,
        max_per_owner: usize,
        max_stored_bytes: u64,
    ) -> Result<PutSystem, StoreError> {
        systems::put_system(self, owner, name, body, max_per_owner, max_stored_bytes)
    }

    fn get_system(&self, owner: &str, name: &str) -> Result<Option<StoredSystem>, StoreError> {
        systems::get_system(self, owner, name)
    }

    fn delete_system(&self, owner: &str, name: &str) -> Result<bool, StoreError> {
        systems::delete_system(self, owner, name)
    }

    fn list_systems(&self, owner: &str) -> Result<Vec<StoredSystem>, StoreError> {
        systems::list_systems(self, owner)
    }

    fn pending(&self) -> Result<usize, StoreError> {
        let n: i64 = self.conn().query_row(
            "SELECT count(*) FROM jobs WHERE status IN ('queued', 'running')",
            [],
            |r| r.get(0),
        )?;
        Ok(n as usize)
    }
}
