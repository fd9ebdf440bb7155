//! The uncertainty analysis kinds (SPEC §8, [`Analysis`]): `bands` (the
//! deployment chart's), `plan_bands` and `envelope_bands`. Progress counts
//! samples; each is chunked by sample and stops when cancelled.

use std::ops::Range;

use crate::contract::price::Price;

use crate::contract::analysis::{Analysis, Items, to_json, too_large};
use crate::contract::bands::dto::{BandsRequest, BandsResponse};
use crate::contract::bands::envelope::{self, EnvelopeBandsRequest, EnvelopeBandsResponse};
use crate::contract::bands::plan::{self, PlanBandsRequest, PlanBandsResponse};
use crate::contract::bands::run;
use crate::contract::envelope::kind::ENVELOPE_CELL_STEP_S;
use crate::contract::error::{Progress, RequestError};
use crate::contract::estimate::{self as est, Estimate};
use crate::limits::Limits;
use crate::numerics::parallel::Parallelism;
use crate::numerics::string::chart::Discretisation;

/// Chart points (samples × rates) a synchronous bands request may have.
pub const MAX_SYNC_BAND_EVALUATIONS: usize = 200_000;
/// Synchronous bands work on a fixed mesh: points × elements.
pub const MAX_SYNC_BAND_WORK: usize = 20_000_000;
/// Sample × instant values a synchronous plan bands request may have.
pub const MAX_SYNC_PLAN_BAND_VALUES: usize = 2_000_000;
/// Equilibria (samples × cells) a synchronous envelope bands request may have.
pub const MAX_SYNC_ENVELOPE_BAND_EVALUATIONS: usize = 10_000;

/// One percentile band: 14 numbers and their keys.
pub const PER_PERCENTILE_BAND: u64 = 14 * est::PER_NUMBER + 250;
/// One probability: 5 numbers and their keys.
pub const PER_PROBABILITY: u64 = 5 * est::PER_NUMBER + 150;
/// A plan answer's fixed part (phases, bound, checks, inputs echoed).
pub const PLAN_BASE: u64 = 256 << 10;
/// One schedule sample of a plan: 9 numbers and their keys.
pub const PER_PLAN_SAMPLE: u64 = 9 * est::PER_NUMBER + 300;

/// Seconds per element of one chart point of a bands sample on a uniform
/// mesh (measured: 6 400 points of 500 elements in 1.2 s on one core;
/// through the route 4 000 points of 2 000 elements in 2.14 CPU-s).
const BAND_ELEMENT_POINT_S: f64 = 4e-7;
/// Seconds per converged chart point of a bands sample (measured: 9 600
/// points in 0.06 s; through the route 200 000 points in 1.04 CPU-s).
const BAND_CONVERGED_POINT_S: f64 = 1e-5;
/// Seconds per sample × schedule instant of a plan bands chunk, its wire
/// result included (measured: 3 000 samples × 2 003 instants in 1.36 s on
/// one core, 2.2e-7 s, most of it writing the result; the nominal plan,
/// computed again by every chunk, 0.02 s).
const PLAN_BAND_VALUE_S: f64 = 2.5e-7;
/// Sample × instant values of one plan bands chunk at most: its result
/// holds every value of three traces, about 60 bytes a value (15 MB).
const MAX_PLAN_BAND_CHUNK_VALUES: usize = 250_000;

impl Analysis for BandsRequest {
    const NAME: &'static str = "bands";
    const SUMMARY: &'static str = "Uncertainty bands of a deployment chart (SPEC §8): 5/50/95 % points\n\
        of h* and t* at each rate under uncertain inputs, each with its\n\
        sampling error, and the probability that a target elevation is\n\
        unsafe.";
    const DESCRIPTION: &'static str = "Seeded Monte Carlo: sample i draws from its own stream of\n\
        (seed, i), so the answer is identical at any thread count.\n\
        Synchronously at most 200 000 chart points (samples × rates); up\n\
        to 2 000 000 as a job with `\"kind\": \"bands\"`.";
    const ABOUT: &'static str = "Uncertainty bands of a deployment chart: 5/50/95 % of h* and t* per rate under uncertain inputs (seeded Monte Carlo).";
    type Response = BandsResponse;
    fn parse(body: &[u8]) -> Result<Self, RequestError> {
        run::parse_bands(body)
    }
    fn prepare(&self) -> Result<(), RequestError> {
        run::prepare(self).map(drop)
    }
    fn check_sync(&self, _: &Limits) -> Result<(), RequestError> {
        let points = run::evaluations(self);
        let work = points.saturating_mul(self.system.model.mesh_elements());
        if points > MAX_SYNC_BAND_EVALUATIONS || work > MAX_SYNC_BAND_WORK {
            return Err(too_large(
                "uncertainty.samples",
                format!(
                    "{points} chart points (samples × rates) on {} elements take too long to answer synchronously (at most {MAX_SYNC_BAND_EVALUATIONS} points and {MAX_SYNC_BAND_WORK} points × elements): submit a job with \"kind\": \"bands\"",
                    self.system.model.mesh_elements()
                ),
            ));
        }
        Ok(())
    }
    /// Chart points (samples × rates) × the mesh's cost of a point.
    fn price(&self) -> Option<Price> {
        let points = run::evaluations(self);
        let per_point = match self.system.discretisation().ok()? {
            Discretisation::Elements(n) => n as f64 * BAND_ELEMENT_POINT_S,
            _ => BAND_CONVERGED_POINT_S,
        };
        Some(Price {
            cpu_s: points as f64 * per_point,
            field: "uncertainty.samples".into(),
            counts: format!(
                "{points} chart points (samples × rates) on {} elements",
                self.system.model.mesh_elements()
            ),
        })
    }
    fn run(&self, progress: &dyn Progress) -> Result<BandsResponse, RequestError> {
        run::bands(self, Parallelism::Rayon, progress)
    }
    fn estimate(&self) -> Estimate {
        let samples = self.params.uncertainty.samples.max(1);
        let rates = (run::evaluations(self) / samples) as u64;
        Estimate::new(
            "rates_m_s",
            est::CHART_BASE + rates.saturating_mul(est::PER_BAND_POINT),
        )
    }
    /// By sample.
    fn items(&self) -> Option<Items> {
        let samples = self.params.uncertainty.samples;
        let rates = run::evaluations(self) / samples.max(1);
        let point = match self.system.discretisation().ok()? {
            Discretisation::Elements(n) => n as f64 * BAND_ELEMENT_POINT_S,
            _ => BAND_CONVERGED_POINT_S,
        };
        Some(Items {
            count: samples,
            seconds_each: rates as f64 * point,
            most_per_chunk: None,
        })
    }
    fn run_items(
        &self,
        range: Range<usize>,
        progress: &dyn Progress,
    ) -> Result<String, RequestError> {
        run::bands_chunk(self, range, Parallelism::Rayon, progress)
    }
    fn assemble(&self, parts: &[String]) -> Result<String, RequestError> {
        to_json(&run::bands_from_chunks(self, parts)?)
    }
}

impl Analysis for PlanBandsRequest {
    const NAME: &'static str = "plan_bands";
    const SUMMARY: &'static str = "A deployment plan under uncertain inputs: the nominal schedule, and per\n\
        sample what it does to that sample's system.";
    const DESCRIPTION: &'static str = "The body is a `POST /api/v1/plan` request plus `uncertainty` (seeded\n\
        Monte Carlo over `aerostat.net_buoyancy_n`, `aerostat.mass_kg`, the\n\
        cable's mass, `gravity_m_s2`, `tether.breaking_strength_n`). The answer\n\
        holds the nominal plan, 5/50/95 % bands of the winch tension, largest\n\
        tension and stability margin at every instant of its schedule, and the\n\
        probabilities (Wilson 95 % interval) that some instant is unstable,\n\
        breaks the lift reserve, or exceeds the tether rating. Synchronously at\n\
        most 2 000 000 sample × instant values; larger as a job with\n\
        `\"kind\": \"plan_bands\"`.";
    const ABOUT: &'static str = "Uncertainty bands of the deployment plan: probabilities and 5/50/95 % bands per instant of its schedule (seeded Monte Carlo).";
    type Response = PlanBandsResponse;
    fn parse(body: &[u8]) -> Result<Self, RequestError> {
        plan::parse_plan_bands(body)
    }
    fn prepare(&self) -> Result<(), RequestError> {
        plan::prepare_plan_bands(self).map(drop)
    }
    fn check_sync(&self, _: &Limits) -> Result<(), RequestError> {
        plan::prepare_plan_bands(self)?;
        let values = plan::plan_band_values(self);
        if values > MAX_SYNC_PLAN_BAND_VALUES {
            return Err(too_large(
                "uncertainty.samples",
                format!(
                    "{values} sample × instant values take too long to answer synchronously (at most {MAX_SYNC_PLAN_BAND_VALUES}): submit a job with \"kind\": \"plan_bands\""
                ),
            ));
        }
        Ok(())
    }
    fn run(&self, progress: &dyn Progress) -> Result<PlanBandsResponse, RequestError> {
        plan::plan_bands(self, Parallelism::Rayon, progress)
    }
    fn estimate(&self) -> Estimate {
        // the schedule: `samples` evenly spaced instants plus the phase
        // boundaries (at most one per length segment of the pass)
        let instants = (self.plan.samples as u64).saturating_add(4000);
        Estimate::new(
            "samples",
            PLAN_BASE
                + instants.saturating_mul(
                    PER_PLAN_SAMPLE + 3 * PER_PERCENTILE_BAND + 2 * est::PER_NUMBER + 100,
                )
                + 4 * PER_PROBABILITY
                + 2 * PER_PERCENTILE_BAND,
        )
    }
    /// By sample; a split job's chunks hold results of bounded size.
    fn items(&self) -> Option<Items> {
        let samples = self.params.uncertainty.samples;
        let instants = plan::plan_band_values(self) / samples.max(1);
        Some(Items {
            count: samples,
            seconds_each: instants as f64 * PLAN_BAND_VALUE_S,
            most_per_chunk: Some((MAX_PLAN_BAND_CHUNK_VALUES / instants.max(1)).max(1)),
        })
    }
    fn run_items(
        &self,
        range: Range<usize>,
        progress: &dyn Progress,
    ) -> Result<String, RequestError> {
        plan::plan_bands_chunk(self, range, Parallelism::Rayon, progress)
    }
    fn assemble(&self, parts: &[String]) -> Result<String, RequestError> {
        to_json(&plan::plan_bands_from_chunks(self, parts)?)
    }
}

impl Analysis for EnvelopeBandsRequest {
    const NAME: &'static str = "envelope_bands";
    const SUMMARY: &'static str = "The operating envelope under uncertain inputs: per cell, the\n\
        probability of exceeding the tension limit, of instability and of\n\
        leaving the envelope, and the band of the largest tension.";
    const DESCRIPTION: &'static str = "The body is a `POST /api/v1/envelope` request plus `uncertainty` (over\n\
        the aerostat's buoyancy, drag and lift coefficients and area, the\n\
        tether's mass, diameter, drag coefficient, stiffness and breaking\n\
        strength, the air density and gravity). Each sample solves the whole\n\
        envelope. Synchronously at most 10 000 sample × cell equilibria; up to\n\
        2 000 000 as a job with `\"kind\": \"envelope_bands\"`.";
    const ABOUT: &'static str = "Uncertainty bands of the operating envelope: per cell the probabilities of exceeding the tension limit, of instability and of leaving the envelope (seeded Monte Carlo).";
    type Response = EnvelopeBandsResponse;
    fn parse(body: &[u8]) -> Result<Self, RequestError> {
        envelope::parse_envelope_bands(body)
    }
    fn prepare(&self) -> Result<(), RequestError> {
        envelope::prepare_envelope_bands(self).map(drop)
    }
    fn check_sync(&self, _: &Limits) -> Result<(), RequestError> {
        envelope::prepare_envelope_bands(self)?;
        let total = envelope::envelope_band_evaluations(self);
        if total > MAX_SYNC_ENVELOPE_BAND_EVALUATIONS {
            return Err(too_large(
                "uncertainty.samples",
                format!(
                    "{total} equilibria (samples × cells) take too long to answer synchronously (at most {MAX_SYNC_ENVELOPE_BAND_EVALUATIONS}): submit a job with \"kind\": \"envelope_bands\""
                ),
            ));
        }
        Ok(())
    }
    fn price(&self) -> Option<Price> {
        Some(crate::contract::envelope::price::envelope(
            envelope::envelope_band_evaluations(self),
            self.envelope.integration_steps,
            "uncertainty.samples",
        ))
    }
    fn run(&self, progress: &dyn Progress) -> Result<EnvelopeBandsResponse, RequestError> {
        envelope::envelope_bands(self, Parallelism::Rayon, progress)
    }
    fn estimate(&self) -> Estimate {
        let cells = self.envelope.points() as u64;
        let rows = (self
            .envelope
            .wind_speeds_m_s
            .as_ref()
            .map_or(1, |g| g.count())
            + self.envelope.tether_lengths_m.count()) as u64;
        Estimate::new(
            "wind_speeds_m_s.count",
            est::SIMULATE_BASE
                + cells.saturating_mul(
                    est::PER_ENVELOPE_POINT
                        + 3 * PER_PROBABILITY
                        + PER_PERCENTILE_BAND
                        + 2 * est::PER_NUMBER
                        + 200,
                )
                + rows * 8 * est::PER_NUMBER,
        )
    }
    /// By sample.
    fn items(&self) -> Option<Items> {
        let samples = self.params.uncertainty.samples;
        let (_, config) = self.envelope.problem().ok()?;
        let cells = self.envelope.points() as f64;
        Some(Items {
            count: samples,
            seconds_each: cells * config.steps as f64 * ENVELOPE_CELL_STEP_S,
            most_per_chunk: None,
        })
    }
    fn run_items(
        &self,
        range: Range<usize>,
        progress: &dyn Progress,
    ) -> Result<String, RequestError> {
        envelope::envelope_bands_chunk(self, range, Parallelism::Rayon, progress)
    }
    fn assemble(&self, parts: &[String]) -> Result<String, RequestError> {
        to_json(&envelope::envelope_bands_from_chunks(self, parts)?)
    }
}
