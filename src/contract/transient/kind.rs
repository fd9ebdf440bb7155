//! The `simulate` analysis kind ([`Analysis`]): a transient run of either
//! cable model (`model.kind`).

use crate::contract::analysis::{Analysis, validate_by_cancelled_run};
use crate::contract::error::{Progress, RequestError};
use crate::contract::estimate::{self as est, Estimate as E, Estimate};
use crate::contract::price::Price;
use crate::contract::transient::any::{self, AnySimulateRequest, AnySimulateResponse};
use crate::contract::{ge, transient};

impl Analysis for AnySimulateRequest {
    const NAME: &'static str = "simulate";
    const SUMMARY: &'static str = "Transient run of either cable model: tip deflection, energy and\n\
        eigenvalues along a deployment, with wind on the aerostat.";
    const DESCRIPTION: &'static str = "`model.kind` picks the model: `linear_string` (default) or\n\
        `geometrically_exact`. Runs longer than the solve timeout are\n\
        stopped (504): submit them as jobs with `\"kind\": \"simulate\"`.";
    const ABOUT: &'static str =
        "Transient run (linear string, or `\"model\": {\"kind\": \"geometrically_exact\"}`).";
    type Response = AnySimulateResponse;
    fn parse(body: &[u8]) -> Result<Self, RequestError> {
        any::parse_simulate(body)
    }
    fn prepare(&self) -> Result<(), RequestError> {
        validate_by_cancelled_run(|p| any::simulate_any(self, p))
    }
    fn price(&self) -> Option<Price> {
        match self {
            Self::LinearString(r) => transient::price::simulate(r),
            Self::GeometricallyExact(r) => ge::price::simulate(r),
        }
    }
    fn run(&self, progress: &dyn Progress) -> Result<AnySimulateResponse, RequestError> {
        any::simulate_any(self, progress)
    }
    fn estimate(&self) -> Estimate {
        match self {
            Self::LinearString(r) => {
                let samples = r.params.samples as f64;
                let tracks = r.params.eigenvalues.as_ref().map_or(0.0, |e| {
                    let solves = (r.params.duration_s / e.interval_s).ceil() + 1.0;
                    solves
                        * (est::PER_EIGEN_TRACK as f64
                            + e.count as f64 * est::PER_EIGENVALUE as f64)
                });
                E::bytes(
                    "samples",
                    est::SIMULATE_BASE as f64 + samples * est::PER_SIMULATE_SAMPLE as f64 + tracks,
                )
            }
            Self::GeometricallyExact(r) => {
                let steps = (r.duration_s / r.time_step_s).ceil();
                let samples = (steps / r.output_every_steps.max(1) as f64).ceil() + 1.0;
                let spectra = if r.eigenvalues_every_steps > 0 {
                    (steps / r.eigenvalues_every_steps as f64).ceil() + 1.0
                } else {
                    0.0
                };
                E::bytes(
                    "output_every_steps",
                    est::SIMULATE_BASE as f64
                        + samples * est::PER_GE_SAMPLE as f64
                        + spectra
                            * (est::PER_EIGEN_TRACK as f64
                                + r.modes as f64 * est::PER_EIGENVALUE as f64),
                )
            }
        }
    }
}
