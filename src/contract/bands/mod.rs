//! `POST /api/v1/bands` (SPEC §8, issue 14): the deployment chart of one
//! system under uncertain inputs — 5/50/95 % bands of `h*` and `t*` at
//! each rate, each percentile with its sampling error, and the probability
//! that a target elevation is unsafe.
//!
//! * [`dto`]: request and response bodies.
//! * [`run`]: parsing (system part and parameters separately, unknown
//!   fields refused everywhere), the uncertain-field paths
//!   (`aerostat.net_buoyancy_n`, …) resolved to a direct numeric setter
//!   (no JSON round trip per sample), the ensemble on rayon
//!   ([`crate::numerics::uncertainty`]) and the summaries.
//! * [`plan`]: `POST /api/v1/plan/bands`, the nominal schedule under
//!   uncertain inputs (probabilities of instability and of exceeding the
//!   tether rating, bands of the plan's traces).
//! * [`envelope`]: `POST /api/v1/envelope/bands`, per-cell probabilities
//!   of exceeding the tension limit, of instability and of leaving the
//!   envelope.
//! * [`common`]: what the three share.
//!
//! The sampling layer is request-agnostic: a plan or envelope band needs
//! only its own field table and per-sample evaluation.

pub mod common;
pub mod dto;
pub mod envelope;
pub mod kind;
pub mod plan;
pub mod run;

pub use dto::{BandsRequest, BandsResponse};
pub use envelope::{
    EnvelopeBandsRequest, EnvelopeBandsResponse, envelope_bands, parse_envelope_bands,
};
pub use plan::{PlanBandsRequest, PlanBandsResponse, parse_plan_bands, plan_bands};
pub use run::{bands, bands_chunk, bands_from_chunks, evaluations, parse_bands, prepare};
