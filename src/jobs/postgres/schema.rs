//! The PostgreSQL schema: its versions (one row each in `schema_version`),
//! applied at start by [`migrate`] in one transaction under an advisory
//! lock (several processes may start at once).

use postgres::Client;

use super::rows::plain_error;
use crate::jobs::backend::StoreError;

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
    (
        5,
        "CREATE TABLE flights (
            id              BIGSERIAL PRIMARY KEY,
            owner           TEXT NOT NULL,
            name            TEXT NOT NULL,
            request         TEXT NOT NULL,
            plan            TEXT NOT NULL,
            limits          TEXT NOT NULL,
            ceiling         TEXT NOT NULL,
            created_at      TEXT NOT NULL DEFAULT to_char(clock_timestamp() AT TIME ZONE 'UTC',
                                'YYYY-MM-DD\"T\"HH24:MI:SS.MS\"Z\"'),
            ended_at        TEXT,
            last_arrival_ms BIGINT,
            next_seq        BIGINT NOT NULL DEFAULT 1,
            samples         BIGINT NOT NULL DEFAULT 0
        );
        CREATE INDEX flights_by_owner ON flights (owner, id);
        CREATE TABLE flight_samples (
            flight_id           BIGINT NOT NULL REFERENCES flights (id) ON DELETE CASCADE,
            time_s              DOUBLE PRECISION NOT NULL,
            seq                 BIGINT NOT NULL,
            tether_length_m     DOUBLE PRECISION,
            winch_rate_m_s      DOUBLE PRECISION,
            winch_tension_n     DOUBLE PRECISION,
            wind_speed_m_s      DOUBLE PRECISION,
            wind_height_m       DOUBLE PRECISION,
            aerostat_altitude_m DOUBLE PRECISION,
            PRIMARY KEY (flight_id, time_s)
        );
        CREATE UNIQUE INDEX flight_samples_by_seq ON flight_samples (flight_id, seq);
        CREATE TABLE flight_acknowledgements (
            id        BIGSERIAL PRIMARY KEY,
            flight_id BIGINT NOT NULL REFERENCES flights (id) ON DELETE CASCADE,
            time_s    DOUBLE PRECISION NOT NULL
        );
        CREATE INDEX flight_acknowledgements_by_flight ON flight_acknowledgements (flight_id, id);",
    ),
];

/// The current schema version.
pub const SCHEMA_VERSION: i32 = 5;

/// Advisory lock key of migrations (inserts take the next key,
/// `rows::INSERT_LOCK`).
pub(super) const MIGRATION_LOCK: i64 = 0x7465_7468_6572_0001;

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
pub(super) fn migrate(c: &mut Client) -> Result<(), StoreError> {
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
