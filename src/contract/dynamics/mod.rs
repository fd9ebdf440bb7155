//! `POST /api/v1/dynamics` and `tetherplan dynamics` (SPEC §11, issue 23):
//! the tether in time, from rest in the static equilibrium of `wind.flow`,
//! through a gust, a sinusoid or seeded turbulence (`wind.time_history`),
//! at a fixed length or along a profile; and `POST /api/v1/dynamics/peaks`
//! ([`peaks`]): the distribution of the largest tension over an exposure
//! by Monte Carlo over turbulence seeds.
//!
//! * [`dto`]: the request and the answer (samples, shapes, slack events,
//!   peaks beside the quasi-static tensions at the same wind);
//! * [`validate`]: the checks (the schema's bounds) and the numerical
//!   problem ([`crate::numerics::dynamics`]);
//! * [`converged`]: the figures an operator acts on with their error
//!   estimates, the step chosen to meet a tolerance (issue 31 item 2);
//! * [`run`]: the run with progress and cancellation, the quasi-static
//!   comparison (the §6 equilibrium with the flow changed by the run's
//!   largest and smallest wind change);
//! * [`peaks`]: the Monte Carlo, chunked by sample for the job queue.

pub mod converged;
pub mod dto;
pub mod kind;
pub mod peaks;
pub mod price;
pub mod run;
pub mod validate;

pub use converged::dynamics;
pub use dto::{DynamicsRequest, DynamicsResponse};
pub use peaks::{DynamicsPeaksRequest, DynamicsPeaksResponse};

use crate::contract::RequestError;

/// Segment-steps a synchronous run may take (about a second on one core;
/// larger runs go to the job queue as `dynamics`).
pub const MAX_SYNC_WORK: f64 = 3e6;
/// Samples a synchronous answer may keep.
pub const MAX_SYNC_SAMPLES: usize = 20_000;
/// Segment-steps (all samples) a synchronous peaks request may take.
pub const MAX_SYNC_PEAK_WORK: f64 = 6e6;

/// Parses a dynamics body (one pass, field paths kept).
pub fn parse_dynamics(body: &[u8]) -> Result<DynamicsRequest, RequestError> {
    crate::contract::parse_plain(body)
}

/// Parses a peaks body.
pub fn parse_peaks(body: &[u8]) -> Result<DynamicsPeaksRequest, RequestError> {
    crate::contract::parse_plain(body)
}
