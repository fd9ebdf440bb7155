//! The dynamics analysis kinds (SPEC §11, [`Analysis`]): `dynamics` (one
//! run; progress in time steps) and `dynamics_peaks` (Monte Carlo over
//! turbulence seeds; chunked by sample, progress in samples).

use crate::contract::dynamics::price;
use crate::contract::price::Price;
use std::ops::Range;

use crate::contract::analysis::{Analysis, Items, to_json, too_large};
use crate::contract::dynamics::{
    self, DynamicsPeaksRequest, DynamicsPeaksResponse, DynamicsRequest, DynamicsResponse,
    MAX_SYNC_PEAK_WORK, MAX_SYNC_SAMPLES, MAX_SYNC_WORK, peaks,
};
use crate::contract::error::{Progress, RequestError};
use crate::contract::estimate::{self as est, Estimate};
use crate::limits::Limits;
use crate::numerics::parallel::Parallelism;

/// One kept sample: 7 numbers and their keys.
pub const PER_DYNAMICS_SAMPLE: u64 = 7 * est::PER_NUMBER + 140;
/// One run of the converged figures' refinement: 6 numbers and their keys.
pub const PER_REFINEMENT: u64 = 6 * est::PER_NUMBER + 200;
/// One shape node: 4 numbers and their keys.
pub const PER_SHAPE_NODE: u64 = 4 * est::PER_NUMBER + 40;
/// One Monte-Carlo sample's extremes: 9 values and their keys.
pub const PER_PEAK_SAMPLE: u64 = 9 * est::PER_NUMBER + 220;
/// Seconds per segment-step of a run (measured on the 50-segment gust
/// case: 300 s at 0.05 s in 0.225 s on a loaded core, 3.8e-8 s; costed at
/// twice that for turbulence sampling).
pub const SEGMENT_STEP_S: f64 = 8e-8;

impl Analysis for DynamicsRequest {
    const NAME: &'static str = "dynamics";
    const SUMMARY: &'static str = "The tether in time (SPEC §11): from rest in the static equilibrium\n\
        of `wind.flow`, through the change of `wind.time_history` (a step,\n\
        ramp or `1 − cos` gust, a sinusoid, or seeded von Kármán / Kaimal\n\
        turbulence), at a fixed `tether_length_m` or along a `profile`.";
    const DESCRIPTION: &'static str = "A lumped-mass tether in the vertical plane downwind (EA, internal\n\
        damping, weight, drag on the relative velocity), the aerostat with\n\
        its added mass, generalized-α steps. The answer: `samples` of the\n\
        winch and top tensions and the aerostat's position, tether `shapes`\n\
        at evenly spaced times, `slack_events`, and the peak and minimum\n\
        tensions beside the quasi-static ones at the same wind.\n\
        Its `converged` figures carry error estimates from runs at twice\n\
        the step and half the segments; by default the step is chosen to\n\
        meet `numerics.tolerance_nondim` (issue 31 item 2).\n\
        Synchronously at most 3 000 000 segment-steps over every run\n\
        (`duration_s / time step × segments`), 20 000 samples and\n\
        2 CPU-seconds as priced from the steps, segments and turbulence\n\
        field (`contract::price`); larger runs: a job with `\"kind\": \"dynamics\"`.";
    const ABOUT: &'static str = "The tether in time through a gust or turbulence, from rest in the static equilibrium of `wind.flow` (progress bar in time steps).";
    type Response = DynamicsResponse;
    fn parse(body: &[u8]) -> Result<Self, RequestError> {
        dynamics::parse_dynamics(body)
    }
    fn prepare(&self) -> Result<(), RequestError> {
        DynamicsRequest::prepare(self).map(drop).map_err(Into::into)
    }
    fn check_sync(&self, _: &Limits) -> Result<(), RequestError> {
        let prepared = DynamicsRequest::prepare(self)?;
        if prepared.total_work() > MAX_SYNC_WORK {
            return Err(too_large(
                "duration_s",
                format!(
                    "{:.0} segment-steps (every run of the converged figures) take too long to answer synchronously (at most {MAX_SYNC_WORK:e}): submit a job with \"kind\": \"dynamics\"",
                    prepared.total_work()
                ),
            ));
        }
        if self.sample_count > MAX_SYNC_SAMPLES {
            return Err(too_large(
                "sample_count",
                format!(
                    "{} samples are more than a synchronous answer keeps (at most {MAX_SYNC_SAMPLES}): submit a job with \"kind\": \"dynamics\"",
                    self.sample_count
                ),
            ));
        }
        Ok(())
    }
    fn price(&self) -> Option<Price> {
        Some(price::dynamics(&DynamicsRequest::prepare(self).ok()?))
    }
    fn run(&self, progress: &dyn Progress) -> Result<DynamicsResponse, RequestError> {
        dynamics::dynamics(self, progress)
    }
    fn estimate(&self) -> Estimate {
        let shapes = self.shape_times_s.as_ref().map_or(
            self.shape_count
                .unwrap_or(crate::contract::dynamics::dto::DEFAULT_SHAPE_COUNT),
            Vec::len,
        ) as u64;
        let segments = self
            .numerics
            .segments
            .unwrap_or(crate::contract::dynamics::validate::DEFAULT_SEGMENTS);
        let nodes = shapes.saturating_mul(segments as u64 + 1);
        Estimate::new(
            "sample_count",
            est::SIMULATE_BASE
                + PER_REFINEMENT * 8
                + (self.sample_count as u64).saturating_mul(PER_DYNAMICS_SAMPLE)
                + nodes.saturating_mul(PER_SHAPE_NODE)
                + shapes * 64,
        )
    }
}

impl Analysis for DynamicsPeaksRequest {
    const NAME: &'static str = "dynamics_peaks";
    const SUMMARY: &'static str = "The largest tension over an exposure by Monte Carlo over turbulence\n\
        seeds (issue 23): e.g. the 99th percentile of the hourly maximum\n\
        winch tension with its order-statistic interval, beside the\n\
        quasi-static tensions of the mean wind and of the §10 gust check.";
    const DESCRIPTION: &'static str = "Sample `i` is the `POST /api/v1/dynamics` run of the same system\n\
        with turbulence seed `seed + i` and `duration_s = exposure_s`.\n\
        Synchronously at most 6 000 000 segment-steps in all and 2\n\
        CPU-seconds as priced per sample (its static start, its turbulence\n\
        field, its steps and segments: `contract::price`); larger: a job\n\
        with `\"kind\": \"dynamics_peaks\"`, split by sample over any number of\n\
        workers with the same answer.";
    const ABOUT: &'static str = "The largest tension over an exposure, Monte Carlo over turbulence seeds (progress bar in samples).";
    type Response = DynamicsPeaksResponse;
    fn parse(body: &[u8]) -> Result<Self, RequestError> {
        dynamics::parse_peaks(body)
    }
    fn prepare(&self) -> Result<(), RequestError> {
        DynamicsPeaksRequest::prepare(self)
            .map(drop)
            .map_err(Into::into)
    }
    fn check_sync(&self, _: &Limits) -> Result<(), RequestError> {
        let prepared = DynamicsPeaksRequest::prepare(self)?;
        let work = prepared.work() * self.samples as f64;
        if work > MAX_SYNC_PEAK_WORK {
            return Err(too_large(
                "samples",
                format!(
                    "{work:.0} segment-steps (samples × steps × segments) take too long to answer synchronously (at most {MAX_SYNC_PEAK_WORK:e}): submit a job with \"kind\": \"dynamics_peaks\""
                ),
            ));
        }
        Ok(())
    }
    fn price(&self) -> Option<Price> {
        Some(price::dynamics_peaks(
            &DynamicsPeaksRequest::prepare(self).ok()?,
            self.samples,
        ))
    }
    fn run(&self, progress: &dyn Progress) -> Result<DynamicsPeaksResponse, RequestError> {
        peaks::peaks(self, Parallelism::Rayon, progress)
    }
    fn estimate(&self) -> Estimate {
        Estimate::new(
            "samples",
            est::SIMULATE_BASE
                // the samples and the step check's block (about one sample's)
                + (self.samples as u64 + 1).saturating_mul(PER_PEAK_SAMPLE)
                + 2 * (self.percentiles_nondim.len() as u64) * 5 * est::PER_NUMBER,
        )
    }
    /// By sample.
    fn items(&self) -> Option<Items> {
        let per = DynamicsPeaksRequest::prepare(self).ok()?.work() * SEGMENT_STEP_S;
        Some(Items {
            count: self.samples,
            seconds_each: per,
            most_per_chunk: None,
        })
    }
    fn run_items(
        &self,
        range: Range<usize>,
        progress: &dyn Progress,
    ) -> Result<String, RequestError> {
        peaks::peaks_chunk(self, range, Parallelism::Rayon, progress)
    }
    fn assemble(&self, parts: &[String]) -> Result<String, RequestError> {
        to_json(&peaks::peaks_from_chunks(self, parts)?)
    }
}
