//! The windows job kind (SPEC §12, issue 32): `windows`, launch windows
//! from a forecast whose distinct winds are too many for a synchronous
//! answer (progress in plans).

use serde_json::Value;

use crate::contract::windows::{self, WindowsRequest};
use crate::contract::{Progress, RequestError};
use crate::jobs::estimate::{self as est, Estimate};
use crate::jobs::kinds::JobKind;

/// One period of the answer: its wind, reason and a dozen numbers.
pub const PER_PERIOD: u64 = 24 * est::PER_NUMBER + 1200;

impl JobKind for WindowsRequest {
    const NAME: &'static str = "windows";
    fn parse_body(body: &[u8]) -> Result<Self, RequestError> {
        windows::parse_windows(body)
    }
    fn validate(&self) -> Result<(), RequestError> {
        windows::prepare(self).map(drop)
    }
    fn run(&self, progress: &dyn Progress) -> Result<String, RequestError> {
        crate::contract::finite::to_string(&windows::windows(self, progress)?)
    }
    fn estimate(&self) -> Estimate {
        // The answer lists the first member's periods (parsing is cheap;
        // an unparsable forecast is refused by `validate`).
        let periods = windows::source::parse_forecast(&self.forecast)
            .map_or(0, |f| f.members.first().map_or(0, |m| m.periods.len())) as u64;
        Estimate::new("forecast.data", est::SMALL_ANSWER + periods.saturating_mul(PER_PERIOD))
    }
}

/// A valid request of this kind (its schema example), for tests.
pub fn example_request(kind: &str) -> Option<Value> {
    use utoipa::PartialSchema;
    if kind != "windows" {
        return None;
    }
    serde_json::to_value(WindowsRequest::schema())
        .ok()?
        .get("example")
        .cloned()
}
