//! The uncertainty job kinds of the plan and the envelope (SPEC §8):
//! `plan_bands` and `envelope_bands`. Progress counts samples; both stop
//! when cancelled.

use serde_json::Value;

use crate::contract::bands::envelope::{self, EnvelopeBandsRequest};
use crate::contract::bands::plan::{self, PlanBandsRequest};
use crate::contract::{Progress, RequestError};
use crate::jobs::estimate::{self as est, Estimate, Estimate as E};
use crate::jobs::kinds::JobKind;
use crate::numerics::chart::Parallelism;

/// The answer as JSON; never one holding a non-finite number.
fn to_json(value: &impl serde::Serialize) -> Result<String, RequestError> {
    crate::contract::finite::to_string(value)
}

/// One percentile band: 14 numbers and their keys.
pub const PER_PERCENTILE_BAND: u64 = 14 * est::PER_NUMBER + 250;
/// One probability: 5 numbers and their keys.
pub const PER_PROBABILITY: u64 = 5 * est::PER_NUMBER + 150;
/// A plan answer's fixed part (phases, bound, checks, inputs echoed).
pub const PLAN_BASE: u64 = 256 << 10;
/// One schedule sample of a plan: 9 numbers and their keys.
pub const PER_PLAN_SAMPLE: u64 = 9 * est::PER_NUMBER + 300;

impl JobKind for PlanBandsRequest {
    const NAME: &'static str = "plan_bands";
    fn parse_body(body: &[u8]) -> Result<Self, RequestError> {
        plan::parse_plan_bands(body)
    }
    fn validate(&self) -> Result<(), RequestError> {
        plan::prepare_plan_bands(self).map(drop)
    }
    fn run(&self, progress: &dyn Progress) -> Result<String, RequestError> {
        to_json(&plan::plan_bands(self, Parallelism::Rayon, progress)?)
    }
    fn estimate(&self) -> Estimate {
        // the schedule: `samples` evenly spaced instants plus the phase
        // boundaries (at most one per length segment of the pass)
        let instants = (self.plan.samples as u64).saturating_add(4000);
        E::new(
            "samples",
            PLAN_BASE
                + instants.saturating_mul(
                    PER_PLAN_SAMPLE + 3 * PER_PERCENTILE_BAND + 2 * est::PER_NUMBER + 100,
                )
                + 4 * PER_PROBABILITY
                + 2 * PER_PERCENTILE_BAND,
        )
    }
}

impl JobKind for EnvelopeBandsRequest {
    const NAME: &'static str = "envelope_bands";
    fn parse_body(body: &[u8]) -> Result<Self, RequestError> {
        envelope::parse_envelope_bands(body)
    }
    fn validate(&self) -> Result<(), RequestError> {
        envelope::prepare_envelope_bands(self).map(drop)
    }
    fn run(&self, progress: &dyn Progress) -> Result<String, RequestError> {
        to_json(&envelope::envelope_bands(
            self,
            Parallelism::Rayon,
            progress,
        )?)
    }
    fn estimate(&self) -> Estimate {
        let cells = self.envelope.points() as u64;
        let rows = (self
            .envelope
            .wind_speeds_m_s
            .as_ref()
            .map_or(1, |g| g.count())
            + self.envelope.tether_lengths_m.count()) as u64;
        E::new(
            "wind_speeds_m_s.count",
            est::SIMULATE_BASE
                + cells.saturating_mul(
                    est::PER_ENVELOPE_POINT
                        + 3 * PER_PROBABILITY
                        + PER_PERCENTILE_BAND
                        + 2 * est::PER_NUMBER
                        + 200,
                )
                + rows * 8 * est::PER_NUMBER,
        )
    }
}

/// A valid request of these kinds (their schema examples), for tests.
pub fn example_request(kind: &str) -> Option<Value> {
    use utoipa::PartialSchema;
    let schema = match kind {
        "plan_bands" => PlanBandsRequest::schema(),
        "envelope_bands" => EnvelopeBandsRequest::schema(),
        _ => return None,
    };
    let value = serde_json::to_value(&schema).ok()?;
    value.get("example").cloned()
}
