//! The tether job kinds: `equilibrium` and `envelope` (SPEC §6). The
//! envelope reports progress per wind row and stops when cancelled.

use serde_json::Value;

use crate::contract::envelope::dto::EnvelopeRequest;
use crate::contract::equilibrium::dto::EquilibriumRequest;
use crate::contract::{self, Progress, RequestError, envelope, equilibrium};
use crate::jobs::estimate::{self as est, Estimate, Estimate as E};
use crate::jobs::kinds::JobKind;
use crate::numerics::chart::Parallelism;

/// The answer as JSON; never one holding a non-finite number.
fn to_json(value: &impl serde::Serialize) -> Result<String, RequestError> {
    contract::finite::to_string(value)
}

impl JobKind for EquilibriumRequest {
    const NAME: &'static str = "equilibrium";
    fn parse_body(body: &[u8]) -> Result<Self, RequestError> {
        contract::parse_plain(body)
    }
    fn validate(&self) -> Result<(), RequestError> {
        EquilibriumRequest::validate(self)
    }
    fn run(&self, _: &dyn Progress) -> Result<String, RequestError> {
        to_json(&equilibrium::equilibrium(self)?)
    }
    fn estimate(&self) -> Estimate {
        E::new(
            "shape_samples",
            est::SIMULATE_BASE + self.shape_samples as u64 * est::PER_SHAPE_SAMPLE,
        )
    }
}

impl JobKind for EnvelopeRequest {
    const NAME: &'static str = "envelope";
    fn parse_body(body: &[u8]) -> Result<Self, RequestError> {
        contract::parse_plain(body)
    }
    fn validate(&self) -> Result<(), RequestError> {
        EnvelopeRequest::validate(self)
    }
    fn run(&self, progress: &dyn Progress) -> Result<String, RequestError> {
        to_json(&envelope::envelope(self, Parallelism::Rayon, progress)?)
    }
    fn estimate(&self) -> Estimate {
        let rows = (self.wind_speeds_m_s.as_ref().map_or(1, |g| g.count())
            + self.tether_lengths_m.count()) as u64;
        E::new(
            "wind_speeds_m_s.count",
            est::SIMULATE_BASE
                + (self.points() as u64).saturating_mul(est::PER_ENVELOPE_POINT)
                + rows * 8 * est::PER_NUMBER,
        )
    }
}

/// A valid request of the tether kinds (their schema examples), for tests.
pub fn example_request(kind: &str) -> Option<Value> {
    use utoipa::PartialSchema;
    let schema = match kind {
        "equilibrium" => EquilibriumRequest::schema(),
        "envelope" => EnvelopeRequest::schema(),
        _ => return None,
    };
    let value = serde_json::to_value(&schema).ok()?;
    value.get("example").cloned()
}
