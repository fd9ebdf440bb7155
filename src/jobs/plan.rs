//! The `plan` job kind (SPEC §7): the body of `POST /api/v1/plan` run as a
//! job, with the progress of its transient check; the result is the
//! synchronous route's answer.

use crate::contract::plan::{self, PlanRequest};
use crate::contract::{Progress, RequestError};
use crate::jobs::estimate::{self as est, Estimate};
use crate::jobs::kinds::JobKind;

/// One schedule sample: 10 numbers and their keys.
pub const PER_PLAN_SAMPLE: u64 = 10 * est::PER_NUMBER + 220;
/// One phase of the operator's table: 7 numbers, the limit, the instruction and keys.
pub const PER_PLAN_PHASE: u64 = 7 * est::PER_NUMBER + 300;
/// A plan answer without its samples and phases (method, inputs, limits, checks).
pub const PLAN_BASE: u64 = 32 << 10;

impl JobKind for PlanRequest {
    const NAME: &'static str = "plan";
    fn parse_body(body: &[u8]) -> Result<Self, RequestError> {
        plan::parse_plan(body)
    }
    fn validate(&self) -> Result<(), RequestError> {
        plan::validate_plan(self)
    }
    fn run(&self, progress: &dyn Progress) -> Result<String, RequestError> {
        crate::contract::finite::to_string(&plan::plan(self, progress)?)
    }
    /// The samples asked for, plus every phase start; a schedule has at
    /// most one phase per segment of the pass's grid (and twice that with
    /// a jerk limit), each also a sample. The request itself is echoed.
    fn estimate(&self) -> Estimate {
        let phases = 2 * (crate::numerics::plan::DEFAULT_GRID_SEGMENTS as u64 + 2);
        let echo = serde_json::to_string(self).map_or(0, |s| s.len() as u64);
        Estimate::new(
            "samples",
            PLAN_BASE
                + echo
                + (self.samples as u64 + phases).saturating_mul(PER_PLAN_SAMPLE)
                + phases * PER_PLAN_PHASE,
        )
    }
}
