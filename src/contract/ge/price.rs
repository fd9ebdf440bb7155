//! What a GE transient run or chart costs in CPU seconds (issue 34, item
//! 2), from its steps, elements and eigenvalue checks.
//!
//! Measured through the routes (server CPU time from /proc, 2-core
//! machine, release build):
//!   simulate, 10 elements, 100 000 steps: 1.10 CPU-s (1.1e-5 per step);
//!     1 000 elements, 100 steps: 0.14 CPU-s; 2 000 elements, 100 steps:
//!     0.57 CPU-s (2.9e-6 per element-step);
//!   simulate's eigenvalues (`eigenvalues_every_steps`), one solve: 5e-3 s
//!     at 20 elements, 0.031 s at 50, 0.22 s at 100 (as elements^2.8);
//!   base-excitation frequency response, 16 runs of 40 000 steps on 10
//!     elements: 8.45 CPU-s (1.3e-5 per step); 16 × 400 steps on 100
//!     elements: 0.75 CPU-s (1.2e-6 per element-step);
//!   chart, 8 points of the default numerics: 0.34 CPU-s at 20 elements,
//!     1.82 at 40, 2.68 at 50 (per point as elements^2.4).

use crate::contract::ge::base_response::GeBaseFrequencyResponseRequest;
use crate::contract::ge::charts::{self, GeChartRequest};
use crate::contract::ge::numerics::{default_check, default_dt, default_horizon};
use crate::contract::ge::simulate::GeSimulateRequest;
use crate::contract::price::Price;

/// Simulate: one time step's fixed cost, s.
pub const SIMULATE_STEP_S: f64 = 1.5e-5;
/// Simulate: one element of one time step, s.
pub const SIMULATE_STEP_ELEMENT_S: f64 = 3e-6;
/// Simulate: one eigenvalue solve at 100 elements, s (as `elements^2.35`
/// below 100 elements, `elements^3` above).
pub const EIGEN_SOLVE_100_S: f64 = 0.33;
/// Chart: one point at 20 elements on the default numerics, s.
pub const CHART_POINT_20_S: f64 = 0.051;
/// Chart: a point's cost grows as `elements^CHART_ELEMENT_POWER`.
pub const CHART_ELEMENT_POWER: f64 = 2.4;

/// `POST /api/v1/simulate` of the GE model (None: invalid).
pub fn simulate(req: &GeSimulateRequest) -> Option<Price> {
    let steps = (req.duration_s / req.time_step_s).round();
    let elements = req.model.elements() as f64;
    // Past the run's limits the run refuses it, naming the field.
    if !(steps.is_finite() && steps >= 1.0)
        || steps > crate::contract::ge::simulate::MAX_STEPS as f64
        || steps * elements > crate::contract::ge::simulate::MAX_WORK
    {
        return None;
    }
    let solves = if req.eigenvalues_every_steps > 0 {
        (steps / req.eigenvalues_every_steps as f64).floor() + 1.0
    } else {
        0.0
    };
    let ratio = elements / 100.0;
    let eigen = solves * EIGEN_SOLVE_100_S * ratio.powf(if ratio < 1.0 { 2.35 } else { 3.0 });
    let stepping = steps * (SIMULATE_STEP_S + elements * SIMULATE_STEP_ELEMENT_S);
    Some(Price {
        cpu_s: stepping + eigen,
        field: if eigen > stepping {
            "eigenvalues_every_steps".into()
        } else {
            "duration_s".into()
        },
        counts: format!(
            "{steps:.0} time steps on {elements:.0} elements with {solves:.0} eigenvalue solves"
        ),
    })
}

/// `POST /api/v1/charts` of the GE model: every point runs to the horizon
/// (an upper bound: an unstable point stops early).
pub fn chart(req: &GeChartRequest) -> Option<Price> {
    let points = charts::chart_points(req) as f64;
    let elements = req.model.elements as f64;
    let (steps, check) = match &req.numerics {
        Some(n) => (
            n.horizon_s / n.time_step_s,
            n.check_every_steps.max(1) as f64,
        ),
        None => (default_horizon() / default_dt(), default_check() as f64),
    };
    let default_steps = default_horizon() / default_dt();
    let length = (steps / default_steps).max(1.0) * (default_check() as f64 / check).max(1.0);
    if !length.is_finite() {
        return None;
    }
    Some(Price {
        cpu_s: points
            * CHART_POINT_20_S
            * (elements / 20.0).max(1.0).powf(CHART_ELEMENT_POWER)
            * length,
        field: "model.elements".into(),
        counts: format!("{points:.0} chart points on {elements:.0} elements"),
    })
}

/// `POST /api/v1/frequency-response` with `excitation = "base"`: one GE
/// run per frequency (None: invalid).
pub fn base_frequency_response(req: &GeBaseFrequencyResponseRequest) -> Option<Price> {
    let steps = (req.duration_s / req.time_step_s).round();
    // Past the run's step limit the run refuses it, naming its field.
    if !(steps.is_finite() && steps >= 1.0)
        || steps > crate::contract::ge::simulate::MAX_STEPS as f64
    {
        return None;
    }
    let runs = req.frequencies_rad_s.count() as f64;
    let elements = req.model.elements() as f64;
    Some(Price {
        cpu_s: runs * steps * (SIMULATE_STEP_S + elements * SIMULATE_STEP_ELEMENT_S),
        field: "duration_s".into(),
        counts: format!("{runs:.0} runs of {steps:.0} time steps on {elements:.0} elements"),
    })
}
