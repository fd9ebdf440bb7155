//! The deployment plan (SPEC §7): the JSON contract of `POST /api/v1/plan`
//! and `tetherplan plan` ([`dto`]) and its run ([`run`]) over
//! [`crate::numerics::plan`].

pub mod dto;
pub mod ge;
pub mod run;

pub use dto::{PlanRequest, PlanResponse};
pub use run::{plan, validate_plan};

use crate::contract::RequestError;

/// Parses a plan request (one pass, unknown fields refused, field paths kept).
pub fn parse_plan(body: &[u8]) -> Result<PlanRequest, RequestError> {
    crate::contract::parse_plain(body)
}
