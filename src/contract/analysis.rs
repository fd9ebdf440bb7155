//! One analysis kind as one unit ([`Analysis`]): its name, its request
//! (the implementing type) and answer types, its input checks, its
//! synchronous limit, its run with progress and cancellation, the size of
//! its answer and, optionally, how it splits into chunks.
//!
//! The synchronous route, the job kind, the batch item, the CLI subcommand
//! and the OpenAPI operation of a kind are all made from its impl and its
//! one line in [`crate::contract::catalogue`]; nothing else names a kind.

use std::ops::Range;

use serde::Serialize;

use crate::contract::error::{Progress, RequestError};
use crate::contract::estimate::Estimate;
use crate::contract::price::Price;
use crate::limits::Limits;
use crate::numerics::params::InvalidInput;

/// The independent items of a request that may run as chunks of a job
/// (chart points or rates, Monte-Carlo samples, envelope rows).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Items {
    /// How many.
    pub count: usize,
    /// Seconds one item may take (sizing chunks of a few seconds).
    pub seconds_each: f64,
    /// Items one chunk may hold at most when the job is split (bounds a
    /// chunk's result), beyond the engine's own bound.
    pub most_per_chunk: Option<usize>,
}

/// An analysis kind: the request type of one synchronous route and one
/// job kind.
pub trait Analysis: Serialize + Sized + Send + Sync + 'static {
    /// The kind's name: `kind` of a job or a batch item; its CLI
    /// subcommand is this with `-` for `_`.
    const NAME: &'static str;
    /// The route's summary (the OpenAPI `summary`).
    const SUMMARY: &'static str;
    /// The route's description (the OpenAPI `description`; may be empty).
    const DESCRIPTION: &'static str;
    /// The CLI subcommand's help.
    const ABOUT: &'static str;
    /// The answer (the route's 200 body, a done job's `result`).
    type Response: Serialize + utoipa::ToSchema;

    /// Parses a body (errors name the field; unknown fields are errors).
    fn parse(body: &[u8]) -> Result<Self, RequestError>;

    /// Every check that needs no solve, so that bad input is refused at
    /// submission (422) instead of failing later.
    fn prepare(&self) -> Result<(), RequestError>;

    /// The synchronous route's checks before it runs, in its order: refuses
    /// a request too large to answer in about a second
    /// ([`RequestError::TooLarge`], pointing at the job queue).
    fn check_sync(&self, _limits: &Limits) -> Result<(), RequestError> {
        Ok(())
    }

    /// What the synchronous answer costs in CPU seconds
    /// ([`crate::contract::price`]), checked after [`Analysis::check_sync`]
    /// against the budget and the priced work in flight (None: cheap
    /// enough never to be priced).
    fn price(&self) -> Option<Price> {
        None
    }

    /// Computes the answer; long kinds report progress and stop (with
    /// [`RequestError::Cancelled`]) once `progress.cancelled()`.
    fn run(&self, progress: &dyn Progress) -> Result<Self::Response, RequestError>;

    /// An upper estimate of the answer's size, from the validated request.
    fn estimate(&self) -> Estimate;

    /// The independent items a job of this request splits into (None: it
    /// runs as one piece).
    fn items(&self) -> Option<Items> {
        None
    }

    /// The result (JSON text) of the items `range` (only kinds with
    /// [`Analysis::items`]).
    fn run_items(
        &self,
        _range: Range<usize>,
        progress: &dyn Progress,
    ) -> Result<String, RequestError> {
        to_json(&self.run(progress)?)
    }

    /// The answer (JSON text) from the results of its chunks, in order.
    fn assemble(&self, parts: &[String]) -> Result<String, RequestError> {
        parts
            .first()
            .cloned()
            .ok_or_else(|| RequestError::Malformed("no chunk result".into()))
    }
}

/// An answer as JSON text; never one holding a non-finite number (the
/// request fails `invalid_input`).
pub fn to_json(value: &impl Serialize) -> Result<String, RequestError> {
    crate::contract::finite::to_string(value)
}

/// The synchronous limit's refusal: `field` makes the request too large.
pub fn too_large(field: &str, message: impl std::fmt::Display) -> RequestError {
    RequestError::TooLarge(InvalidInput::new(field, message.to_string()))
}

/// Progress that is cancelled from the start: running a request with it
/// performs every input check and stops before the first step.
pub struct CancelledFromTheStart;

impl Progress for CancelledFromTheStart {
    fn report(&self, _: usize, _: usize) {}
    fn cancelled(&self) -> bool {
        true
    }
}

/// Validates by running with [`CancelledFromTheStart`]: invalid input is
/// the error; a cancellation (or an answer) means the input is good.
pub fn validate_by_cancelled_run<T>(
    run: impl FnOnce(&dyn Progress) -> Result<T, RequestError>,
) -> Result<(), RequestError> {
    match run(&CancelledFromTheStart) {
        Ok(_) | Err(RequestError::Cancelled) => Ok(()),
        Err(e) => Err(e),
    }
}
