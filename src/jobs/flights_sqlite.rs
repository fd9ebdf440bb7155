//! [`FlightStore`] on SQLite: its own connection to the job database (WAL:
//! the job threads and the flights do not wait on one lock), its tables
//! migrated at open under their own version row (`flight_schema`), apart
//! from the jobs' `user_version`:
//! 1. `flights` (owner, name, the committed JSON, ended, last arrival,
//!    the next arrival number), `flight_samples` keyed by
//!    `(flight_id, time_s)` with their arrival number `seq`,
//!    `flight_acknowledgements`.

use std::path::Path;
use std::sync::Mutex;
use std::time::Duration;

use rusqlite::{Connection, OptionalExtension, TransactionBehavior, params};

use super::backend::StoreError;
use super::flights::{
    FlightEntry, FlightRow, FlightStore, MAX_FLIGHTS_PER_OWNER, NewFlight, StoredBatch,
};
use crate::numerics::monitor::Sample;

const SCHEMA_V1: &str = "
CREATE TABLE IF NOT EXISTS flight_schema (version INTEGER NOT NULL);
CREATE TABLE flights (
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    owner TEXT NOT NULL,
    name TEXT NOT NULL,
    request TEXT NOT NULL,
    plan TEXT NOT NULL,
    limits TEXT NOT NULL,
    ceiling TEXT NOT NULL,
    created_at TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),
    ended_at TEXT,
    last_arrival_ms INTEGER,
    next_seq INTEGER NOT NULL DEFAULT 1,
    samples INTEGER NOT NULL DEFAULT 0
);
CREATE INDEX flights_owner ON flights(owner, id);
CREATE TABLE flight_samples (
    flight_id INTEGER NOT NULL,
    time_s REAL NOT NULL,
    seq INTEGER NOT NULL,
    tether_length_m REAL,
    winch_rate_m_s REAL,
    winch_tension_n REAL,
    wind_speed_m_s REAL,
    wind_height_m REAL,
    aerostat_altitude_m REAL,
    PRIMARY KEY (flight_id, time_s)
) WITHOUT ROWID;
CREATE INDEX flight_samples_seq ON flight_samples(flight_id, seq);
CREATE TABLE flight_acknowledgements (
    flight_id INTEGER NOT NULL,
    time_s REAL NOT NULL,
    made_at TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now'))
);
CREATE INDEX flight_acknowledgements_flight ON flight_acknowledgements(flight_id);
";

/// The flight tables' schema version.
pub const FLIGHT_SCHEMA_VERSION: i64 = 1;

/// The flights behind one SQLite connection.
pub struct SqliteFlights {
    conn: Mutex<Connection>,
}

fn migrate(conn: &mut Connection) -> Result<(), StoreError> {
    let tx = conn.transaction_with_behavior(TransactionBehavior::Immediate)?;
    let exists: bool = tx.query_row(
        "SELECT count(*) > 0 FROM sqlite_master WHERE type = 'table' AND name = 'flight_schema'",
        [],
        |r| r.get(0),
    )?;
    let version: i64 = if exists {
        tx.query_row(
            "SELECT ifnull(max(version), 0) FROM flight_schema",
            [],
            |r| r.get(0),
        )?
    } else {
        0
    };
    if version < 1 {
        tx.execute_batch(SCHEMA_V1)?;
        tx.execute(
            "INSERT INTO flight_schema (version) VALUES (?1)",
            [FLIGHT_SCHEMA_VERSION],
        )?;
    }
    tx.commit()?;
    Ok(())
}

impl SqliteFlights {
    /// Opens the flight tables of the database at `path` (created and
    /// migrated when needed).
    pub fn open(path: &Path) -> Result<Self, StoreError> {
        let conn = Connection::open(path)?;
        conn.busy_timeout(Duration::from_secs(10))?;
        conn.pragma_update(None, "journal_mode", "WAL")?;
        conn.pragma_update(None, "synchronous", "NORMAL")?;
        Self::init(conn)
    }

    /// A private in-memory store (tests, and servers built without a path).
    pub fn open_in_memory() -> Result<Self, StoreError> {
        Self::init(Connection::open_in_memory()?)
    }

    fn init(mut conn: Connection) -> Result<Self, StoreError> {
        migrate(&mut conn)?;
        Ok(Self {
            conn: Mutex::new(conn),
        })
    }

    fn conn(&self) -> std::sync::MutexGuard<'_, Connection> {
        self.conn.lock().unwrap_or_else(|e| e.into_inner())
    }
}

fn sample_from(r: &rusqlite::Row<'_>, at: usize) -> rusqlite::Result<Sample> {
    Ok(Sample {
        time_s: r.get(at)?,
        tether_length_m: r.get(at + 1)?,
        winch_rate_m_s: r.get(at + 2)?,
        winch_tension_n: r.get(at + 3)?,
        wind_speed_m_s: r.get(at + 4)?,
        wind_height_m: r.get(at + 5)?,
        aerostat_altitude_m: r.get(at + 6)?,
    })
}

const SAMPLE_COLUMNS: &str = "time_s, tether_length_m, winch_rate_m_s, winch_tension_n, wind_speed_m_s, wind_height_m, aerostat_altitude_m";

impl FlightStore for SqliteFlights {
    fn create_flight(&self, owner: &str, f: &NewFlight<'_>) -> Result<Option<i64>, StoreError> {
        let mut conn = self.conn();
        let tx = conn.transaction_with_behavior(TransactionBehavior::Immediate)?;
        let n: i64 = tx.query_row(
            "SELECT count(*) FROM flights WHERE owner = ?1",
            [owner],
            |r| r.get(0),
        )?;
        if n as usize >= MAX_FLIGHTS_PER_OWNER {
            return Ok(None);
        }
        tx.execute(
            "INSERT INTO flights (owner, name, request, plan, limits, ceiling) VALUES (?1, ?2, ?3, ?4, ?5, ?6)",
            params![owner, f.name, f.request, f.plan, f.limits, f.ceiling],
        )?;
        let id = tx.last_insert_rowid();
        tx.commit()?;
        Ok(Some(id))
    }

    fn get_flight(&self, id: i64, owner: &str) -> Result<Option<FlightRow>, StoreError> {
        Ok(self
            .conn()
            .query_row(
                "SELECT id, owner, name, request, plan, limits, ceiling, created_at, ended_at,
                        last_arrival_ms, samples
                 FROM flights WHERE id = ?1 AND owner = ?2",
                params![id, owner],
                |r| {
                    Ok(FlightRow {
                        id: r.get(0)?,
                        owner: r.get(1)?,
                        name: r.get(2)?,
                        request: r.get(3)?,
                        plan: r.get(4)?,
                        limits: r.get(5)?,
                        ceiling: r.get(6)?,
                        created_at: r.get(7)?,
                        ended_at: r.get(8)?,
                        last_arrival_ms: r.get(9)?,
                        samples: r.get::<_, i64>(10)? as u64,
                    })
                },
            )
            .optional()?)
    }

    fn owner_of(&self, id: i64) -> Result<Option<String>, StoreError> {
        Ok(self
            .conn()
            .query_row("SELECT owner FROM flights WHERE id = ?1", [id], |r| {
                r.get(0)
            })
            .optional()?)
    }

    fn list_flights(&self, owner: &str) -> Result<Vec<FlightEntry>, StoreError> {
        let conn = self.conn();
        let mut st = conn.prepare(
            "SELECT id, name, created_at, ended_at FROM flights WHERE owner = ?1 ORDER BY id DESC",
        )?;
        let rows = st.query_map([owner], |r| {
            Ok(FlightEntry {
                id: r.get(0)?,
                name: r.get(1)?,
                created_at: r.get(2)?,
                ended_at: r.get(3)?,
            })
        })?;
        Ok(rows.collect::<Result<_, _>>()?)
    }

    fn end_flight(&self, id: i64, owner: &str) -> Result<bool, StoreError> {
        let conn = self.conn();
        let n = conn.execute(
            "UPDATE flights SET ended_at = ifnull(ended_at, strftime('%Y-%m-%dT%H:%M:%fZ', 'now'))
             WHERE id = ?1 AND owner = ?2",
            params![id, owner],
        )?;
        Ok(n == 1)
    }

    fn insert_samples(
        &self,
        id: i64,
        samples: &[Sample],
        arrival_ms: i64,
    ) -> Result<StoredBatch, StoreError> {
        let mut conn = self.conn();
        let tx = conn.transaction_with_behavior(TransactionBehavior::Immediate)?;
        let next: i64 = tx.query_row("SELECT next_seq FROM flights WHERE id = ?1", [id], |r| {
            r.get(0)
        })?;
        let mut seq = next;
        let mut out = StoredBatch::default();
        {
            let mut st = tx.prepare_cached(&format!(
                "INSERT OR IGNORE INTO flight_samples (flight_id, seq, {SAMPLE_COLUMNS})
                 VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9)"
            ))?;
            for s in samples {
                let n = st.execute(params![
                    id,
                    seq,
                    s.time_s,
                    s.tether_length_m,
                    s.winch_rate_m_s,
                    s.winch_tension_n,
                    s.wind_speed_m_s,
                    s.wind_height_m,
                    s.aerostat_altitude_m
                ])?;
                out.stored.push(n == 1);
                if n == 1 {
                    out.accepted += 1;
                    seq += 1;
                } else {
                    out.duplicates += 1;
                }
            }
        }
        tx.execute(
            "UPDATE flights SET next_seq = ?2, samples = samples + ?3, last_arrival_ms = ?4 WHERE id = ?1",
            params![id, seq, out.accepted as i64, arrival_ms],
        )?;
        tx.commit()?;
        out.last_seq = seq - 1;
        Ok(out)
    }

    fn samples_by_time(&self, id: i64) -> Result<Vec<Sample>, StoreError> {
        let conn = self.conn();
        let mut st = conn.prepare_cached(&format!(
            "SELECT {SAMPLE_COLUMNS} FROM flight_samples WHERE flight_id = ?1 ORDER BY time_s"
        ))?;
        let rows = st.query_map([id], |r| sample_from(r, 0))?;
        Ok(rows.collect::<Result<_, _>>()?)
    }

    fn samples_after(
        &self,
        id: i64,
        after_seq: i64,
        limit: usize,
    ) -> Result<Vec<(i64, Sample)>, StoreError> {
        let conn = self.conn();
        let mut st = conn.prepare_cached(&format!(
            "SELECT seq, {SAMPLE_COLUMNS} FROM flight_samples
             WHERE flight_id = ?1 AND seq > ?2 ORDER BY seq LIMIT ?3"
        ))?;
        let rows = st.query_map(params![id, after_seq, limit as i64], |r| {
            Ok((r.get(0)?, sample_from(r, 1)?))
        })?;
        Ok(rows.collect::<Result<_, _>>()?)
    }

    fn add_acknowledgement(&self, id: i64, time_s: f64) -> Result<(), StoreError> {
        self.conn().execute(
            "INSERT INTO flight_acknowledgements (flight_id, time_s) VALUES (?1, ?2)",
            params![id, time_s],
        )?;
        Ok(())
    }

    fn acknowledgements(&self, id: i64) -> Result<Vec<f64>, StoreError> {
        let conn = self.conn();
        let mut st = conn.prepare_cached(
            "SELECT time_s FROM flight_acknowledgements WHERE flight_id = ?1 ORDER BY rowid",
        )?;
        let rows = st.query_map([id], |r| r.get(0))?;
        Ok(rows.collect::<Result<_, _>>()?)
    }
}
