//! What a transient run or a wind frequency response of the linear string
//! costs in CPU seconds (issue 34, item 2): time steps × elements, as the
//! run fixes its step ([`crate::numerics::string::transient::plan`]).
//!
//! Measured through the routes (server CPU time from /proc, 2-core
//! machine, release build), each constant about 1.5 times the measurement:
//!   simulate, 50 elements, 50 000 s at the automatic 0.113 s step (442 000
//!     steps): 0.78 CPU-s (3.5e-8 per step and element);
//!   frequency response, 16 runs of 400 s at 0.00999 s on 50 elements:
//!     1.17 CPU-s (3.7e-8); 16 runs of 10 s on 2 000 elements: 1.19 CPU-s.

use crate::contract::price::Price;
use crate::contract::transient::{self, FrequencyResponseRequest, SimulateRequest};

/// One time step's fixed cost (outputs, the profile), s.
pub const STEP_S: f64 = 3e-7;
/// One element of one time step (the banded step of the string), s.
pub const STEP_ELEMENT_S: f64 = 5.5e-8;

/// CPU seconds of one run of `steps` steps on `elements` elements.
pub fn run_s(steps: usize, elements: usize) -> f64 {
    steps as f64 * (STEP_S + elements as f64 * STEP_ELEMENT_S)
}

/// `POST /api/v1/simulate` of the linear string (None: invalid, its run
/// refuses it).
pub fn simulate(req: &SimulateRequest) -> Option<Price> {
    let (steps, elements) = transient::simulate::run_size(req)?;
    Some(Price {
        cpu_s: run_s(steps, elements),
        field: "duration_s".into(),
        counts: format!("{steps} time steps on {elements} elements"),
    })
}

/// `POST /api/v1/frequency-response` with wind forcing (every run priced
/// at the step of the highest frequency, the smallest).
pub fn frequency_response(req: &FrequencyResponseRequest) -> Option<Price> {
    let (runs, steps, elements) = transient::frequency::run_size(req)?;
    Some(Price {
        cpu_s: runs as f64 * run_s(steps, elements),
        field: "duration_s".into(),
        counts: format!("{runs} runs of {steps} time steps on {elements} elements"),
    })
}
