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
//!    the answers of version 3 move there, one page each;
//! 5. `flights`, `flight_samples`, `flight_acknowledgements`: the live
//!    flights (issue 33), as SQLite keeps them (`flights.rs`).
//!
//! The store by part: `schema.rs` the migrations, `rows.rs` the
//! connection, errors in plain words, SQL fragments, row reader and fenced
//! writes, `chunks.rs` the chunk rows, `systems.rs` the named systems, `flights.rs` the live flights
//! ([`crate::jobs::flights::FlightStore`]); this
//! file opens the store and implements [`JobBackend`]: the job rows,
//! workers and housekeeping here, the chunks and systems by calling their
//! files. What it decides as SQLite does (quota, idempotency) is in
//! [`crate::jobs::admission`].

mod chunks;
mod flights;
mod rows;
mod schema;
mod systems;

use std::sync::Mutex;
use std::time::Duration;

use rows::{
    COLUMNS, FENCE, INSERT_LOCK, NOW, OLDEST_FINISHED, RELEASE_ENDED_CHUNKS, STORED_BYTES,
    UNFINISHED_CHUNKS, find_by_key, record,
};
pub use rows::{PgStore, plain_error, redact};
pub use schema::SCHEMA_VERSION;
use schema::migrate;

use super::admission::{self, millis};
use super::backend::{
    ChunkLease, ChunkState, ClaimPolicy, ClaimedChunk, ClaimedJob, InsertError, Inserted,
    JobBackend, JobHead, JobRecord, JobStatus, KeyedJob, NewJob, PutSystem, StoreError,
    StoredSystem,
};
use super::lease::{Lease, WorkerId, expiry_ms, now_ms};

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

    /// Connects and migrates the schema, without taking over any job: a
    /// second handle on the same database for the live flights.
    pub fn open_for_flights(url: &str) -> Result<Self, StoreError> {
        let store = Self {
            url: url.to_string(),
            client: Mutex::new(None),
            worker: WorkerId::this_process(),
        };
        store.with(|c| migrate(c))?;
        Ok(store)
    }
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
                return Ok(admission::replay(first, job, key));
            }
            let pending: i64 = tx
                .query_one(
                    "SELECT count(*) FROM jobs WHERE status IN ('queued', 'running')",
                    &[],
                )?
                .get(0);
            if let Err(e) = admission::check_pending(job, pending as usize) {
                return Ok(Err(e));
            }
            if let Some(owner) = job.owner {
                let mine: i64 = tx
                    .query_one(
                        "SELECT count(*) FROM jobs WHERE owner = $1 AND status IN ('queued', 'running')",
                        &[&owner],
                    )?
                    .get(0);
                if let Err(e) = admission::check_owner_pending(job, mine as usize) {
                    return Ok(Err(e));
                }
            }
            let adding = admission::job_bytes(job);
            let stored: i64 = tx.query_one(STORED_BYTES, &[&job.owner])?.get(0);
            if let Err(e) = admission::check_job_store(job, stored, adding, || {
                Ok(tx.query_one(OLDEST_FINISHED, &[&job.owner])?.get(0))
            })? {
                return Ok(Err(e));
            }
            let priority = job.priority as i32;
            let stored_bytes = admission::bytes_column(adding);
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
            for (i, page) in super::backend::answer_pages(result).enumerate() {
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
            rec.result = Some(super::backend::join_pages(id, pages)?);
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
}
