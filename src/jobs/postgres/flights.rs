//! [`FlightStore`] on PostgreSQL (schema version 5): the same rows and
//! rules as SQLite's (`crate::jobs::flights_sqlite`), for servers whose
//! jobs are in PostgreSQL, so that a flight survives the loss of the API
//! host as its jobs do.
//!
//! A batch is stored in one transaction that first locks its flight's row
//! (`FOR UPDATE`): two processes feeding one flight take arrival numbers
//! one batch after the other, so the numbers stay contiguous from 1 (the
//! events' ids, and what a restarted server replays). The batch costs
//! three statements whatever its size: the lock, one query for the times
//! already stored, one `INSERT … SELECT FROM unnest(…)` of the new ones.

use std::collections::HashSet;

use super::rows::{NOW, PgStore};
use crate::jobs::backend::StoreError;
use crate::jobs::flights::{
    FlightEntry, FlightRow, FlightStore, MAX_FLIGHTS_PER_OWNER, NewFlight, StoredBatch,
};
use crate::numerics::monitor::Sample;

const SAMPLE_COLUMNS: &str = "time_s, tether_length_m, winch_rate_m_s, winch_tension_n, \
     wind_speed_m_s, wind_height_m, aerostat_altitude_m";

fn sample_from(r: &postgres::Row, at: usize) -> Sample {
    Sample {
        time_s: r.get(at),
        tether_length_m: r.get(at + 1),
        winch_rate_m_s: r.get(at + 2),
        winch_tension_n: r.get(at + 3),
        wind_speed_m_s: r.get(at + 4),
        wind_height_m: r.get(at + 5),
        aerostat_altitude_m: r.get(at + 6),
    }
}

/// The key a `time_s` is compared by (`-0.0` and `0.0` are one time, as
/// in SQL).
fn time_key(t: f64) -> u64 {
    (t + 0.0).to_bits()
}

impl FlightStore for PgStore {
    fn create_flight(&self, owner: &str, f: &NewFlight<'_>) -> Result<Option<i64>, StoreError> {
        self.with(|c| {
            let mut tx = c.transaction()?;
            // One owner's count and insert are not interleaved with another's.
            tx.execute("SELECT pg_advisory_xact_lock(hashtext($1))", &[&owner])?;
            let n: i64 = tx
                .query_one("SELECT count(*) FROM flights WHERE owner = $1", &[&owner])?
                .get(0);
            if n as usize >= MAX_FLIGHTS_PER_OWNER {
                return Ok(None);
            }
            let id: i64 = tx
                .query_one(
                    "INSERT INTO flights (owner, name, request, plan, limits, ceiling)
                     VALUES ($1, $2, $3, $4, $5, $6) RETURNING id",
                    &[&owner, &f.name, &f.request, &f.plan, &f.limits, &f.ceiling],
                )?
                .get(0);
            tx.commit()?;
            Ok(Some(id))
        })
    }

    fn get_flight(&self, id: i64, owner: &str) -> Result<Option<FlightRow>, StoreError> {
        self.with(|c| {
            Ok(c.query_opt(
                "SELECT id, owner, name, request, plan, limits, ceiling, created_at, ended_at,
                        last_arrival_ms, samples
                 FROM flights WHERE id = $1 AND owner = $2",
                &[&id, &owner],
            )?
            .map(|r| FlightRow {
                id: r.get(0),
                owner: r.get(1),
                name: r.get(2),
                request: r.get(3),
                plan: r.get(4),
                limits: r.get(5),
                ceiling: r.get(6),
                created_at: r.get(7),
                ended_at: r.get(8),
                last_arrival_ms: r.get(9),
                samples: r.get::<_, i64>(10) as u64,
            }))
        })
    }

    fn owner_of(&self, id: i64) -> Result<Option<String>, StoreError> {
        self.with(|c| {
            Ok(
                c.query_opt("SELECT owner FROM flights WHERE id = $1", &[&id])?
                    .map(|r| r.get(0)),
            )
        })
    }

    fn list_flights(&self, owner: &str) -> Result<Vec<FlightEntry>, StoreError> {
        self.with(|c| {
            Ok(c.query(
                "SELECT id, name, created_at, ended_at FROM flights WHERE owner = $1 ORDER BY id DESC",
                &[&owner],
            )?
            .iter()
            .map(|r| FlightEntry {
                id: r.get(0),
                name: r.get(1),
                created_at: r.get(2),
                ended_at: r.get(3),
            })
            .collect())
        })
    }

    fn end_flight(&self, id: i64, owner: &str) -> Result<bool, StoreError> {
        self.with(|c| {
            let n = c.execute(
                &format!(
                    "UPDATE flights SET ended_at = coalesce(ended_at, {NOW})
                     WHERE id = $1 AND owner = $2"
                ),
                &[&id, &owner],
            )?;
            Ok(n == 1)
        })
    }

    fn insert_samples(
        &self,
        id: i64,
        samples: &[Sample],
        arrival_ms: i64,
    ) -> Result<StoredBatch, StoreError> {
        self.with(|c| {
            let mut tx = c.transaction()?;
            let next: i64 = tx
                .query_opt(
                    "SELECT next_seq FROM flights WHERE id = $1 FOR UPDATE",
                    &[&id],
                )?
                .ok_or_else(|| StoreError(format!("flight {id} is not stored")))?
                .get(0);
            let times: Vec<f64> = samples.iter().map(|s| s.time_s).collect();
            let mut seen: HashSet<u64> = tx
                .query(
                    "SELECT time_s FROM flight_samples WHERE flight_id = $1 AND time_s = ANY($2)",
                    &[&id, &times],
                )?
                .iter()
                .map(|r| time_key(r.get(0)))
                .collect();
            let mut out = StoredBatch::default();
            let mut new: Vec<&Sample> = Vec::new();
            for s in samples {
                let fresh = seen.insert(time_key(s.time_s));
                out.stored.push(fresh);
                if fresh {
                    new.push(s);
                } else {
                    out.duplicates += 1;
                }
            }
            out.accepted = new.len();
            if !new.is_empty() {
                let col = |f: fn(&Sample) -> Option<f64>| -> Vec<Option<f64>> {
                    new.iter().map(|s| f(s)).collect()
                };
                let seqs: Vec<i64> = (0..new.len() as i64).map(|k| next + k).collect();
                let time_s: Vec<f64> = new.iter().map(|s| s.time_s).collect();
                let length: Vec<Option<f64>> = col(|s| s.tether_length_m);
                let rate: Vec<Option<f64>> = col(|s| s.winch_rate_m_s);
                let tension: Vec<Option<f64>> = col(|s| s.winch_tension_n);
                let wind: Vec<Option<f64>> = col(|s| s.wind_speed_m_s);
                let height: Vec<Option<f64>> = col(|s| s.wind_height_m);
                let altitude: Vec<Option<f64>> = col(|s| s.aerostat_altitude_m);
                tx.execute(
                    &format!(
                        "INSERT INTO flight_samples (flight_id, seq, {SAMPLE_COLUMNS})
                         SELECT $1::BIGINT, * FROM unnest($2::BIGINT[], $3::DOUBLE PRECISION[],
                             $4::DOUBLE PRECISION[], $5::DOUBLE PRECISION[],
                             $6::DOUBLE PRECISION[], $7::DOUBLE PRECISION[],
                             $8::DOUBLE PRECISION[], $9::DOUBLE PRECISION[])"
                    ),
                    &[
                        &id, &seqs, &time_s, &length, &rate, &tension, &wind, &height, &altitude,
                    ],
                )?;
            }
            let after = next + out.accepted as i64;
            tx.execute(
                "UPDATE flights SET next_seq = $2, samples = samples + $3, last_arrival_ms = $4
                 WHERE id = $1",
                &[&id, &after, &(out.accepted as i64), &arrival_ms],
            )?;
            tx.commit()?;
            out.last_seq = after - 1;
            Ok(out)
        })
    }

    fn samples_by_time(&self, id: i64) -> Result<Vec<Sample>, StoreError> {
        self.with(|c| {
            Ok(c.query(
                &format!(
                    "SELECT {SAMPLE_COLUMNS} FROM flight_samples WHERE flight_id = $1 ORDER BY time_s"
                ),
                &[&id],
            )?
            .iter()
            .map(|r| sample_from(r, 0))
            .collect())
        })
    }

    fn samples_after(
        &self,
        id: i64,
        after_seq: i64,
        limit: usize,
    ) -> Result<Vec<(i64, Sample)>, StoreError> {
        self.with(|c| {
            Ok(c.query(
                &format!(
                    "SELECT seq, {SAMPLE_COLUMNS} FROM flight_samples
                     WHERE flight_id = $1 AND seq > $2 ORDER BY seq LIMIT $3"
                ),
                &[&id, &after_seq, &(limit as i64)],
            )?
            .iter()
            .map(|r| (r.get(0), sample_from(r, 1)))
            .collect())
        })
    }

    fn add_acknowledgement(&self, id: i64, time_s: f64) -> Result<(), StoreError> {
        self.with(|c| {
            c.execute(
                "INSERT INTO flight_acknowledgements (flight_id, time_s) VALUES ($1, $2)",
                &[&id, &time_s],
            )?;
            Ok(())
        })
    }

    fn acknowledgements(&self, id: i64) -> Result<Vec<f64>, StoreError> {
        self.with(|c| {
            Ok(c.query(
                "SELECT time_s FROM flight_acknowledgements WHERE flight_id = $1 ORDER BY id",
                &[&id],
            )?
            .iter()
            .map(|r| r.get(0))
            .collect())
        })
    }
}
