//! The `envelope` analysis kind ([`Analysis`], SPEC §6): progress per wind
//! row, chunked by wind row.

use crate::contract::envelope::price;
use crate::contract::envelope::stability::EnvelopeStabilityInput;
use crate::contract::price::Price;
use std::ops::Range;

use crate::contract::analysis::{Analysis, Items, to_json, too_large};
use crate::contract::envelope::dto::{EnvelopeRequest, EnvelopeResponse};
use crate::contract::envelope::{
    MAX_SYNC_ENVELOPE_POINTS, MAX_SYNC_GE_ENVELOPE_POINTS, chunks, envelope,
};
use crate::contract::error::{Progress, RequestError};
use crate::contract::estimate::{self as est, Estimate};
use crate::limits::Limits;
use crate::numerics::parallel::Parallelism;

/// Seconds per sample × cell × integration step of a string envelope cell
/// (measured with envelope bands: 200 samples × 42 cells × 100 steps in
/// 0.94 s on one core, 1.1e-6 s).
pub const ENVELOPE_CELL_STEP_S: f64 = 1.2e-6;
/// Seconds per envelope cell per element of the quasi-static GE verdict,
/// the row's critical length and rate searches included (measured: 40 ×
/// 50 cells at 20 elements in 12.1 s on 2 loaded cores, 5.8 s quiet;
/// costed at the loaded figure, 12 ms a cell on one core).
const GE_ENVELOPE_CELL_ELEMENT_S: f64 = 6e-4;

impl Analysis for EnvelopeRequest {
    const NAME: &'static str = "envelope";
    const SUMMARY: &'static str = "Operating envelope over wind speed × tether length: altitude,\n\
        blow-down, tensions, safety factor, slack and stability at each point,\n\
        the largest operating wind per length and the highest altitude per wind.";
    const DESCRIPTION: &'static str = "Each point is judged against slack, the required safety factor, an\n\
        optional ceiling and (with `payout_rate_m_s`) stability; the first\n\
        violated is its binding limit. Synchronously at most 5 000 points\n\
        and 2 CPU-seconds (points × `integration_steps`, about 0.7 µs per\n\
        point and step: 5 000 points at 500 steps);\n\
        larger envelopes (up to 250 000 points) go to `POST /api/v1/jobs` with\n\
        `\"kind\": \"envelope\"`.";
    const ABOUT: &'static str = "Operating envelope over wind speed × tether length.";
    type Response = EnvelopeResponse;
    fn parse(body: &[u8]) -> Result<Self, RequestError> {
        crate::contract::parse_plain(body)
    }
    fn prepare(&self) -> Result<(), RequestError> {
        EnvelopeRequest::validate(self)
    }
    fn check_sync(&self, _: &Limits) -> Result<(), RequestError> {
        self.validate()?;
        let points = self.points();
        if points > MAX_SYNC_ENVELOPE_POINTS {
            return Err(too_large(
                &self.tether_lengths_m.count_field("tether_lengths_m"),
                format!(
                    "the envelope has {points} points; synchronous envelopes have at most {MAX_SYNC_ENVELOPE_POINTS} (submit a job with \"kind\": \"envelope\")"
                ),
            ));
        }
        if self.uses_ge() && points > MAX_SYNC_GE_ENVELOPE_POINTS {
            return Err(too_large(
                &self.tether_lengths_m.count_field("tether_lengths_m"),
                format!(
                    "the envelope has {points} points; synchronous envelopes with the quasi-static GE stability have at most {MAX_SYNC_GE_ENVELOPE_POINTS} (submit a job with \"kind\": \"envelope\")"
                ),
            ));
        }
        Ok(())
    }
    /// The equilibria, and the quasi-static GE searches when asked for
    /// (the field of the larger share named).
    fn price(&self) -> Option<Price> {
        let points = self.points();
        let mut total = price::envelope(
            points,
            self.integration_steps,
            &self.tether_lengths_m.count_field("tether_lengths_m"),
        );
        if let Some(EnvelopeStabilityInput::QuasiStaticGe { elements, .. }) = &self.stability {
            let rows = self.wind_speeds_m_s.as_ref().map_or(1, |g| g.count());
            let ge = price::ge_envelope(rows, points, *elements);
            total.cpu_s += ge.cpu_s;
            if ge.cpu_s > 0.5 * total.cpu_s {
                total.field = ge.field;
                total.counts = ge.counts;
            }
        }
        Some(total)
    }
    fn run(&self, progress: &dyn Progress) -> Result<EnvelopeResponse, RequestError> {
        envelope(self, Parallelism::Rayon, progress)
    }
    fn estimate(&self) -> Estimate {
        let rows = (self.wind_speeds_m_s.as_ref().map_or(1, |g| g.count())
            + self.tether_lengths_m.count()) as u64;
        Estimate::new(
            "wind_speeds_m_s.count",
            est::SIMULATE_BASE
                + (self.points() as u64).saturating_mul(est::PER_ENVELOPE_POINT)
                + rows * 8 * est::PER_NUMBER,
        )
    }
    /// By wind row.
    fn items(&self) -> Option<Items> {
        let (_, config, spec) = self.ge_problem().ok()?;
        let cell = match spec {
            Some(spec) => spec.elements as f64 * GE_ENVELOPE_CELL_ELEMENT_S,
            // A string cell costs what an envelope bands cell does.
            None => config.steps as f64 * ENVELOPE_CELL_STEP_S,
        };
        let lengths = self.tether_lengths_m.count() as f64;
        Some(Items {
            count: chunks::envelope_row_count(self),
            seconds_each: lengths * cell,
            most_per_chunk: None,
        })
    }
    fn run_items(
        &self,
        range: Range<usize>,
        progress: &dyn Progress,
    ) -> Result<String, RequestError> {
        to_json(&chunks::envelope_chunk(
            self,
            range,
            Parallelism::Rayon,
            progress,
        )?)
    }
    fn assemble(&self, parts: &[String]) -> Result<String, RequestError> {
        to_json(&chunks::envelope_from_chunks(self, parts)?)
    }
}
