//! The deployment plan (SPEC §7): the JSON contract of `POST /api/v1/plan`
//! and `tetherplan plan` ([`dto`]), its validation (`validate`), its run
//! in named steps ([`run`]) and the answer's pieces (`output`) over
//! [`crate::numerics::plan`].

pub mod ceiling;
pub mod dto;
pub mod ge;
pub mod kind;
mod output;
pub mod run;
mod validate;

pub use dto::{PlanRequest, PlanResponse};
pub use run::{PlanVerdict, plan, plan_verdict, validate_plan};

use crate::contract::RequestError;

/// Parses a plan request (one pass, unknown fields refused, field paths kept).
pub fn parse_plan(body: &[u8]) -> Result<PlanRequest, RequestError> {
    crate::contract::parse_plain(body)
}
