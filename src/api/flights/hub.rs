//! The live flights of a server: each flight's monitor in memory, rebuilt
//! from the store on first use (every stored sample and acknowledgement
//! replayed in time order, so a restarted server answers the same state),
//! one lock per flight so that its batches are judged one after the
//! other, and a broadcast per flight that wakes its event streams.
//!
//! The flight clock: telemetry without a time (NMEA lines) is taken at
//! the latest sample's time plus the server's seconds since that sample
//! arrived, or, before any, the seconds since the flight was created.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};
use std::time::{SystemTime, UNIX_EPOCH};

use tokio::sync::broadcast;

use crate::contract::flight::dto::{FlightLimitsOutput, FlightOutput};
use crate::contract::flight::model::{StoredTable, flight_model, status_output};
use crate::contract::plan::PlanResponse;
use crate::jobs::flights::{FlightRow, FlightStore, StoredBatch};
use crate::jobs::flights_sqlite::SqliteFlights;
use crate::jobs::postgres::PgStore;
use crate::jobs::store::{StoreConfig, StoreError};
use crate::numerics::monitor::{Event, FlightModel, Monitor, Pushed, Sample};

/// Milliseconds since the Unix epoch.
pub fn now_ms() -> i64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_millis() as i64)
}

/// What woke a flight's event streams: samples up to `last_seq` are
/// stored, or its state changed (acknowledged, ended).
#[derive(Clone, Copy, Debug)]
pub struct Changed {
    pub last_seq: i64,
}

/// A flight's monitor and what it answers beside it.
pub struct LiveState {
    pub monitor: Monitor,
    pub model: FlightModel,
    pub last_arrival_ms: Option<i64>,
    pub samples_received: u64,
    pub last_seq: i64,
    pub name: String,
    pub created_at: String,
    pub created_ms: i64,
    pub ended_at: Option<String>,
    pub limits: FlightLimitsOutput,
    pub request: serde_json::Value,
}

impl LiveState {
    /// Seconds since the last sample arrived at `now_ms`.
    pub fn since_last_s(&self, now_ms: i64) -> Option<f64> {
        self.last_arrival_ms
            .map(|a| (now_ms - a).max(0) as f64 / 1000.0)
    }

    /// The flight clock at `now_ms` (s), see the module's note.
    pub fn flight_time_s(&self, now_ms: i64) -> f64 {
        match (self.monitor.last_sample_time_s(), self.since_last_s(now_ms)) {
            (Some(t), Some(since)) => t + since,
            _ => (now_ms - self.created_ms).max(0) as f64 / 1000.0,
        }
    }

    /// The flight as answered.
    pub fn output(&self, id: i64, now_ms: i64) -> FlightOutput {
        let (state, checks, alarms) = status_output(&self.monitor, self.since_last_s(now_ms));
        FlightOutput {
            id,
            name: self.name.clone(),
            created_at: self.created_at.clone(),
            ended_at: self.ended_at.clone(),
            state,
            checks,
            alarms,
            last_sample_time_s: self.monitor.last_sample_time_s(),
            samples_received: self.samples_received,
            seconds_since_last_sample_s: self.since_last_s(now_ms),
            limits: self.limits.clone(),
        }
    }
}

/// One live flight.
pub struct LiveFlight {
    pub id: i64,
    pub owner: String,
    pub state: Mutex<LiveState>,
    pub changed: broadcast::Sender<Changed>,
}

impl LiveFlight {
    pub fn lock(&self) -> std::sync::MutexGuard<'_, LiveState> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// The flights of a server.
pub struct FlightHub {
    pub store: Arc<dyn FlightStore>,
    live: Mutex<HashMap<i64, Arc<LiveFlight>>>,
}

/// A stored `YYYY-MM-DDTHH:MM:SS.sssZ` (SQLite's strftime) as ms since
/// the Unix epoch (the time now when it is not one).
pub fn parse_ms(created_at: &str) -> i64 {
    let num = |a: usize, b: usize| created_at.get(a..b).and_then(|s| s.parse::<i64>().ok());
    let (Some(y), Some(mo), Some(d), Some(h), Some(mi)) =
        (num(0, 4), num(5, 7), num(8, 10), num(11, 13), num(14, 16))
    else {
        return now_ms();
    };
    let sec: f64 = created_at
        .get(17..created_at.len().saturating_sub(1))
        .and_then(|s| s.parse().ok())
        .unwrap_or(0.0);
    // days from civil (Howard Hinnant)
    let y = if mo <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let mp = (mo + 9) % 12;
    let doy = (153 * mp + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    let days = era * 146_097 + doe - 719_468;
    (days * 86_400 + h * 3600 + mi * 60) * 1000 + (sec * 1000.0) as i64
}

impl FlightHub {
    pub fn new(store: Arc<dyn FlightStore>) -> Self {
        Self {
            store,
            live: Mutex::new(HashMap::new()),
        }
    }

    /// Flights in memory only (tests, servers built without a store).
    pub fn in_memory() -> Self {
        Self::new(Arc::new(
            SqliteFlights::open_in_memory().expect("an in-memory SQLite opens"),
        ))
    }

    /// The flights of the job database: the SQLite file itself, or the
    /// PostgreSQL database the jobs are in (so another API process on the
    /// same database serves the same flights after this one is lost).
    pub fn open(config: &StoreConfig) -> Result<Self, StoreError> {
        let store: Arc<dyn FlightStore> = match config {
            StoreConfig::Sqlite(p) => Arc::new(SqliteFlights::open(p)?),
            StoreConfig::Postgres(url) => Arc::new(PgStore::open_for_flights(url)?),
        };
        Ok(Self::new(store))
    }

    /// The live flight `id` of `owner`, loaded (and replayed) on first
    /// use; `None`: no such flight for this owner.
    pub fn get(&self, id: i64, owner: &str) -> Result<Option<Arc<LiveFlight>>, StoreError> {
        if let Some(f) = self.live.lock().unwrap_or_else(|e| e.into_inner()).get(&id) {
            return Ok((f.owner == owner).then(|| f.clone()));
        }
        let Some(row) = self.store.get_flight(id, owner)? else {
            return Ok(None);
        };
        let state = self.load(&row)?;
        let (tx, _) = broadcast::channel(64);
        let flight = Arc::new(LiveFlight {
            id,
            owner: owner.to_string(),
            state: Mutex::new(state),
            changed: tx,
        });
        let mut live = self.live.lock().unwrap_or_else(|e| e.into_inner());
        Ok(Some(live.entry(id).or_insert(flight).clone()))
    }

    /// The live flight `id` whoever owns it (feeds that name the flight
    /// only: the MQTT topics); `None`: no such flight.
    pub fn get_any(&self, id: i64) -> Result<Option<Arc<LiveFlight>>, StoreError> {
        match self.store.owner_of(id)? {
            Some(owner) => self.get(id, &owner),
            None => Ok(None),
        }
    }

    fn load(&self, row: &FlightRow) -> Result<LiveState, StoreError> {
        let bad = |what: &str, e: serde_json::Error| {
            StoreError(format!("flight {}: stored {what}: {e}", row.id))
        };
        let limits: FlightLimitsOutput =
            serde_json::from_str(&row.limits).map_err(|e| bad("limits", e))?;
        let plan: PlanResponse = serde_json::from_str(&row.plan).map_err(|e| bad("plan", e))?;
        let table: StoredTable =
            serde_json::from_str(&row.ceiling).map_err(|e| bad("ceiling", e))?;
        let request: serde_json::Value =
            serde_json::from_str(&row.request).map_err(|e| bad("request", e))?;
        let model = flight_model(&limits, &plan, &table);
        let monitor = self.replay(row.id, &model)?;
        // every stored sample took the next number from 1
        let last_seq = row.samples as i64;
        Ok(LiveState {
            monitor,
            model,
            last_arrival_ms: row.last_arrival_ms,
            samples_received: row.samples,
            last_seq,
            name: row.name.clone(),
            created_ms: parse_ms(&row.created_at),
            created_at: row.created_at.clone(),
            ended_at: row.ended_at.clone(),
            limits,
            request,
        })
    }

    /// The monitor of every stored sample and acknowledgement.
    fn replay(&self, id: i64, model: &FlightModel) -> Result<Monitor, StoreError> {
        let mut events: Vec<Event> = self
            .store
            .samples_by_time(id)?
            .into_iter()
            .map(Event::Sample)
            .collect();
        events.extend(
            self.store
                .acknowledgements(id)?
                .into_iter()
                .map(|time_s| Event::Acknowledge { time_s }),
        );
        Ok(Monitor::replay(model.clone(), &events))
    }

    /// Stores a batch and judges its new samples (in time order; a sample
    /// earlier than the monitor's latest replays the flight).
    pub fn ingest(
        &self,
        flight: &LiveFlight,
        samples: &[Sample],
        arrival_ms: i64,
    ) -> Result<StoredBatch, StoreError> {
        let mut st = flight.lock();
        let stored = self.store.insert_samples(flight.id, samples, arrival_ms)?;
        let mut fresh: Vec<Sample> = samples
            .iter()
            .zip(&stored.stored)
            .filter(|(_, s)| **s)
            .map(|(x, _)| *x)
            .collect();
        fresh.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
        let mut late = false;
        for s in &fresh {
            if st.monitor.push(s) == Pushed::OutOfOrder {
                late = true;
                break;
            }
        }
        if late {
            st.monitor = self.replay(flight.id, &st.model)?;
        }
        st.samples_received += stored.accepted as u64;
        st.last_arrival_ms = Some(arrival_ms);
        st.last_seq = st.last_seq.max(stored.last_seq);
        let last_seq = st.last_seq;
        drop(st);
        let _ = flight.changed.send(Changed { last_seq });
        Ok(stored)
    }

    /// Acknowledges every alarm at the latest sample time.
    pub fn acknowledge(&self, flight: &LiveFlight) -> Result<usize, StoreError> {
        let mut st = flight.lock();
        let t = st.monitor.last_sample_time_s().unwrap_or(0.0);
        self.store.add_acknowledgement(flight.id, t)?;
        let n = st.monitor.acknowledge_at(t);
        let last_seq = st.last_seq;
        drop(st);
        let _ = flight.changed.send(Changed { last_seq });
        Ok(n)
    }

    /// Ends the flight.
    pub fn end(&self, flight: &LiveFlight) -> Result<(), StoreError> {
        let mut st = flight.lock();
        self.store.end_flight(flight.id, &flight.owner)?;
        if let Some(row) = self.store.get_flight(flight.id, &flight.owner)? {
            st.ended_at = row.ended_at;
        }
        let last_seq = st.last_seq;
        drop(st);
        let _ = flight.changed.send(Changed { last_seq });
        Ok(())
    }
}
