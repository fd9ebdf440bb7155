//! Live flights in the job store (issue 33): what a flight row holds and
//! the operations a backend offers ([`FlightStore`]), beside the jobs in
//! the same database (SQLite by default: `flights_sqlite.rs`).
//!
//! A flight belongs to the token that created it (its owner hash; `""`
//! without tokens): every read and write names the owner, and another
//! token's flight is not found. Samples are keyed by `(flight, time_s)`:
//! a sample whose `time_s` is stored already is a duplicate and stores
//! nothing; each stored sample gets the next arrival number of its flight
//! (`seq`, the Server-Sent Events' id). Acknowledgements are stored with
//! the sample time they were made at. Nothing of the monitor is stored
//! that the samples and acknowledgements do not determine: a restarted
//! server replays them ([`crate::numerics::monitor::Monitor::replay`]).

use crate::numerics::monitor::Sample;

pub use super::backend::StoreError;

/// A flight to store: its JSON parts as committed.
#[derive(Clone, Debug)]
pub struct NewFlight<'a> {
    pub name: &'a str,
    /// The plan request part of the creation.
    pub request: &'a str,
    /// The committed plan (`PlanResponse`).
    pub plan: &'a str,
    /// The resolved limits.
    pub limits: &'a str,
    /// The stability ceiling table.
    pub ceiling: &'a str,
}

/// A stored flight.
#[derive(Clone, Debug, PartialEq)]
pub struct FlightRow {
    pub id: i64,
    pub owner: String,
    pub name: String,
    pub request: String,
    pub plan: String,
    pub limits: String,
    pub ceiling: String,
    pub created_at: String,
    pub ended_at: Option<String>,
    /// When the last sample arrived (ms since the Unix epoch).
    pub last_arrival_ms: Option<i64>,
    pub samples: u64,
}

/// One line of a listing.
#[derive(Clone, Debug, PartialEq)]
pub struct FlightEntry {
    pub id: i64,
    pub name: String,
    pub created_at: String,
    pub ended_at: Option<String>,
}

/// What a batch did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct StoredBatch {
    pub accepted: usize,
    pub duplicates: usize,
    /// Per sample of the batch: whether it was stored (false: a duplicate).
    pub stored: Vec<bool>,
    /// Arrival number of the last stored sample (0: none stored ever).
    pub last_seq: i64,
}

/// Most flights one token may keep.
pub const MAX_FLIGHTS_PER_OWNER: usize = 1000;

/// The flight operations of a store.
pub trait FlightStore: Send + Sync {
    /// Stores a new flight of `owner`; `None` when the owner has
    /// [`MAX_FLIGHTS_PER_OWNER`] already.
    fn create_flight(&self, owner: &str, f: &NewFlight<'_>) -> Result<Option<i64>, StoreError>;
    fn get_flight(&self, id: i64, owner: &str) -> Result<Option<FlightRow>, StoreError>;
    /// The owner of flight `id` (for a feed that names the flight only,
    /// as the MQTT topics do); `None`: no such flight.
    fn owner_of(&self, id: i64) -> Result<Option<String>, StoreError>;
    /// Every flight (for a restart's recovery), without its JSON parts.
    fn list_flights(&self, owner: &str) -> Result<Vec<FlightEntry>, StoreError>;
    /// Ends a flight; false when not found (or another token's).
    fn end_flight(&self, id: i64, owner: &str) -> Result<bool, StoreError>;
    /// Stores the samples not stored yet (by `time_s`), in one transaction,
    /// and the arrival time.
    fn insert_samples(
        &self,
        id: i64,
        samples: &[Sample],
        arrival_ms: i64,
    ) -> Result<StoredBatch, StoreError>;
    /// The flight's samples in time order.
    fn samples_by_time(&self, id: i64) -> Result<Vec<Sample>, StoreError>;
    /// The samples stored after arrival number `after_seq`, in arrival
    /// order, with their numbers.
    fn samples_after(
        &self,
        id: i64,
        after_seq: i64,
        limit: usize,
    ) -> Result<Vec<(i64, Sample)>, StoreError>;
    /// Stores an acknowledgement made at sample time `time_s`.
    fn add_acknowledgement(&self, id: i64, time_s: f64) -> Result<(), StoreError>;
    /// The acknowledgements' sample times, in the order made.
    fn acknowledgements(&self, id: i64) -> Result<Vec<f64>, StoreError>;
}
