//! How large a job's answer will be, estimated at submission from the
//! validated request, so that a job whose answer would not fit the limit
//! (`TETHERPLAN_JOB_MAX_RESULT_BYTES`, 64 MiB by default) is refused with
//! 422 naming the field that sets its size, before anything is stored.
//!
//! The figures are upper bounds of the JSON text: a number is at most
//! [`PER_NUMBER`] bytes (`-1.2345678901234567e-300,`), plus the keys of its
//! object. `jobs/kinds.rs` tests that a real answer never exceeds its estimate.
//! The worker also checks the real size before storing an answer.

use crate::contract::RequestError;
use crate::numerics::params::InvalidInput;

/// One JSON number with its separator, at most.
pub const PER_NUMBER: u64 = 25;
/// Answers of a fixed shape (critical time, safe rate), at most.
pub const SMALL_ANSWER: u64 = 8 << 10;
/// A stability answer without its eigenvalues.
pub const STABILITY_BASE: u64 = 2 << 10;
/// One eigenvalue object (`re_1_s`, `im_1_s`, ... 6 numbers and keys).
pub const PER_EIGENVALUE: u64 = 6 * PER_NUMBER + 120;
/// A chart answer without its series.
pub const CHART_BASE: u64 = 512;
/// One chart series without its points.
pub const PER_CHART_SERIES: u64 = 256;
/// One chart point: 8 numbers and their keys.
pub const PER_CHART_POINT: u64 = 8 * PER_NUMBER + 240;
/// One GE chart point: 12 numbers or nulls, the onset, the closed-form
/// note and their keys.
pub const PER_GE_CHART_POINT: u64 = 12 * PER_NUMBER + 900;
/// One rate of an uncertainty band: percentiles, their errors, the
/// exceedance probability and their keys.
pub const PER_BAND_POINT: u64 = 40 * PER_NUMBER + 1000;
/// One envelope grid point: about 16 values, the binding limit and keys.
pub const PER_ENVELOPE_POINT: u64 = 16 * PER_NUMBER + 600;
/// One sample of a tether shape: 4 numbers and their keys.
pub const PER_SHAPE_SAMPLE: u64 = 4 * PER_NUMBER + 60;
/// A transient answer without its samples.
pub const SIMULATE_BASE: u64 = 4 << 10;
/// One sample of a linear-string run: 13 columns (9 of the run, 4 of the reduced model).
pub const PER_SIMULATE_SAMPLE: u64 = 13 * PER_NUMBER;
/// One sample of a GE run: 19 columns.
pub const PER_GE_SAMPLE: u64 = 19 * PER_NUMBER;
/// One eigenvalue record of a run without its eigenvalues.
pub const PER_EIGEN_TRACK: u64 = 4 * PER_NUMBER + 100;
/// One point of a base-excitation sweep: 5 values and their keys.
pub const PER_BASE_POINT: u64 = 5 * PER_NUMBER + 100;

/// The estimated size of an answer and the field that sets it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Estimate {
    /// The request field that makes the answer large (a JSON path).
    pub field: String,
    /// Upper estimate of the answer, bytes of JSON.
    pub result_bytes: u64,
}

impl Estimate {
    pub fn new(field: &str, result_bytes: u64) -> Self {
        Self {
            field: field.into(),
            result_bytes,
        }
    }

    /// An estimate computed in floating point (saturates at `u64::MAX`;
    /// NaN, from input that validation refuses next, counts as 0).
    pub fn bytes(field: &str, result_bytes: f64) -> Self {
        Self::new(field, result_bytes.clamp(0.0, u64::MAX as f64) as u64)
    }

    /// The same with the field under `prefix` (`request`, `request[3].request`).
    pub fn prefixed(mut self, prefix: &str) -> Self {
        self.field = format!("{prefix}.{}", self.field);
        self
    }
}

/// `1.5 GB`, `64.0 MB`, `812 bytes`.
pub fn human_bytes(n: u64) -> String {
    let n = n as f64;
    if n >= 1e9 {
        format!("{:.1} GB", n / 1e9)
    } else if n >= 1e6 {
        format!("{:.1} MB", n / 1e6)
    } else if n >= 1e3 {
        format!("{:.1} kB", n / 1e3)
    } else {
        format!("{n} bytes")
    }
}

/// Refuses one request whose answer would exceed `limit` bytes.
pub fn check(e: &Estimate, limit: u64) -> Result<(), RequestError> {
    if e.result_bytes <= limit {
        return Ok(());
    }
    Err(InvalidInput::new(
        e.field.clone(),
        format!(
            "the answer would take about {} ({} bytes), more than this server keeps for one job ({}): \
             ask for fewer points or split the job",
            human_bytes(e.result_bytes),
            e.result_bytes,
            human_bytes(limit)
        ),
    )
    .into())
}

/// Refuses a batch whose answers together would exceed `limit` bytes
/// (each item was checked on its own as it was parsed).
pub fn check_batch(items: impl Iterator<Item = Estimate>, limit: u64) -> Result<(), RequestError> {
    let estimates: Vec<Estimate> = items.collect();
    let total: u64 = estimates
        .iter()
        .map(|e| e.result_bytes.saturating_add(64))
        .fold(0u64, u64::saturating_add);
    if total <= limit {
        return Ok(());
    }
    let mut sum = 0u64;
    let first = estimates
        .iter()
        .position(|e| {
            sum = sum.saturating_add(e.result_bytes + 64);
            sum > limit
        })
        .unwrap_or(0);
    Err(InvalidInput::new(
        "request",
        format!(
            "the batch's {} answers would take about {} ({total} bytes) together, more than this server \
             keeps for one job ({}); the limit is passed at request[{first}]: split the batch",
            estimates.len(),
            human_bytes(total),
            human_bytes(limit)
        ),
    )
    .into())
}
