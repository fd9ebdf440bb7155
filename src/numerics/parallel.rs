//! Where a sweep runs: `Parallelism` is passed into every routine that can
//! fan out (charts, envelopes, ensembles, frequency responses), so each
//! says where it runs and a test can check parallel == serial.

/// Where the sweep runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Parallelism {
    Serial,
    Rayon,
}
