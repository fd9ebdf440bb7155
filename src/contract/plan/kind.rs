//! The `plan` analysis kind ([`Analysis`], SPEC §7): progress of its
//! transient check.

use crate::contract::analysis::Analysis;
use crate::contract::error::{Progress, RequestError};
use crate::contract::estimate::{self as est, Estimate};
use crate::contract::plan::{PlanRequest, PlanResponse};

/// One schedule sample: 10 numbers and their keys.
pub const PER_PLAN_SAMPLE: u64 = 10 * est::PER_NUMBER + 220;
/// One phase of the operator's table: 7 numbers, the limit, the instruction and keys.
pub const PER_PLAN_PHASE: u64 = 7 * est::PER_NUMBER + 300;
/// A plan answer without its samples and phases (method, inputs, limits, checks).
pub const PLAN_BASE: u64 = 32 << 10;

impl Analysis for PlanRequest {
    const NAME: &'static str = "plan";
    const SUMMARY: &'static str = "The fastest safe deployment (or retrieval) schedule (SPEC §7).";
    const DESCRIPTION: &'static str = "Every instant stable with the lift reserve, within the winch limits\n\
        and the tension rating; the time saved against the best\n\
        constant-rate plan; the schedule run on the FE string; with a wind\n\
        forecast, the haul-down deadline. `feasible: false` names the\n\
        binding limit.";
    const ABOUT: &'static str =
        "The fastest safe deployment (or retrieval) schedule, with the haul-down deadline.";
    type Response = PlanResponse;
    fn parse(body: &[u8]) -> Result<Self, RequestError> {
        super::parse_plan(body)
    }
    fn prepare(&self) -> Result<(), RequestError> {
        super::validate_plan(self)
    }
    fn run(&self, progress: &dyn Progress) -> Result<PlanResponse, RequestError> {
        super::plan(self, progress)
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
