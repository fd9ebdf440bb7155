//! The dynamics job kinds (SPEC §11): `dynamics` (one run; progress in
//! time steps) and `dynamics_peaks` (Monte Carlo over turbulence seeds;
//! chunked by sample in [`crate::jobs::kinds`], progress in samples).

use serde_json::Value;

use crate::contract::dynamics::{self, DynamicsPeaksRequest, DynamicsRequest, peaks};
use crate::contract::{Progress, RequestError};
use crate::jobs::estimate::{self as est, Estimate, Estimate as E};
use crate::jobs::kinds::JobKind;
use crate::numerics::chart::Parallelism;

/// The answer as JSON; never one holding a non-finite number.
fn to_json(value: &impl serde::Serialize) -> Result<String, RequestError> {
    crate::contract::finite::to_string(value)
}

/// One kept sample: 7 numbers and their keys.
pub const PER_DYNAMICS_SAMPLE: u64 = 7 * est::PER_NUMBER + 140;
/// One shape node: 4 numbers and their keys.
pub const PER_SHAPE_NODE: u64 = 4 * est::PER_NUMBER + 40;
/// One Monte-Carlo sample's extremes: 9 values and their keys.
pub const PER_PEAK_SAMPLE: u64 = 9 * est::PER_NUMBER + 220;
/// Seconds per segment-step of a run (measured on the 50-segment gust
/// case: 300 s at 0.05 s in 0.225 s on a loaded core, 3.8e-8 s; costed at
/// twice that for turbulence sampling).
pub const SEGMENT_STEP_S: f64 = 8e-8;

impl JobKind for DynamicsRequest {
    const NAME: &'static str = "dynamics";
    fn parse_body(body: &[u8]) -> Result<Self, RequestError> {
        dynamics::parse_dynamics(body)
    }
    fn validate(&self) -> Result<(), RequestError> {
        self.prepare().map(drop).map_err(Into::into)
    }
    fn run(&self, progress: &dyn Progress) -> Result<String, RequestError> {
        to_json(&dynamics::dynamics(self, progress)?)
    }
    fn estimate(&self) -> Estimate {
        let shapes = self
            .shape_times_s
            .as_ref()
            .map_or(
                self.shape_count
                    .unwrap_or(crate::contract::dynamics::dto::DEFAULT_SHAPE_COUNT),
                Vec::len,
            ) as u64;
        let nodes = shapes.saturating_mul(self.numerics.segments as u64 + 1);
        E::new(
            "sample_count",
            est::SIMULATE_BASE
                + (self.sample_count as u64).saturating_mul(PER_DYNAMICS_SAMPLE)
                + nodes.saturating_mul(PER_SHAPE_NODE)
                + shapes * 64,
        )
    }
}

impl JobKind for DynamicsPeaksRequest {
    const NAME: &'static str = "dynamics_peaks";
    fn parse_body(body: &[u8]) -> Result<Self, RequestError> {
        dynamics::parse_peaks(body)
    }
    fn validate(&self) -> Result<(), RequestError> {
        self.prepare().map(drop).map_err(Into::into)
    }
    fn run(&self, progress: &dyn Progress) -> Result<String, RequestError> {
        to_json(&peaks::peaks(self, Parallelism::Rayon, progress)?)
    }
    fn estimate(&self) -> Estimate {
        E::new(
            "samples",
            est::SIMULATE_BASE
                + (self.samples as u64).saturating_mul(PER_PEAK_SAMPLE)
                + 2 * (self.percentiles_nondim.len() as u64) * 4 * est::PER_NUMBER,
        )
    }
}

/// A valid request of these kinds (their schema examples), for tests.
pub fn example_request(kind: &str) -> Option<Value> {
    use utoipa::PartialSchema;
    let schema = match kind {
        "dynamics" => DynamicsRequest::schema(),
        "dynamics_peaks" => DynamicsPeaksRequest::schema(),
        _ => return None,
    };
    let value = serde_json::to_value(&schema).ok()?;
    value.get("example").cloned()
}
