//! `POST /api/v1/dynamics/peaks` (job kind `dynamics_peaks`): the
//! distribution of the largest tension over an exposure, by Monte Carlo
//! over turbulence seeds (issue 23, item 4).
//!
//! Sample `i` is the dynamics run of the same request with the turbulence
//! seed `seed + i` and `duration_s = exposure_s` (so any one sample can be
//! replayed, with its time series, by `POST /api/v1/dynamics`). Samples
//! are independent and deterministic, so the job splits into chunks of
//! samples ([`peaks_chunk`]) run by any number of workers, and the answer
//! put together from them ([`peaks_from_chunks`]) is the single-process
//! answer byte for byte.
//!
//! The summary gives type-7 percentiles of the per-sample maxima with
//! distribution-free order-statistic intervals
//! ([`crate::numerics::uncertainty::percentiles`]), beside the
//! quasi-static tensions of SPEC §10: the mean wind's and the gust
//! check's (the mean flow scaled by `1 + k I`), and the probability
//! (Wilson interval) that the dynamic maximum exceeds the gust check.
//!
//! Every sample runs at one discretisation (default 50 segments, 0.05 s):
//! the answer is a distribution over seeds, and converging each of
//! hundreds of runs would multiply the cost. Its step error is measured
//! instead ([`step_check`]): the sample nearest the highest requested
//! percentile is run again at half the step (the same turbulence field,
//! which is synthesised on its own time grid), and the larger relative
//! change of its two maxima is `step_check.relative_error_estimate_nondim`.

use std::sync::atomic::{AtomicUsize, Ordering};

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::dto::*;
use super::run::{equilibrium_at, run_prepared};
use super::validate::{MAX_SEED, Prepared};
use crate::contract::bands::common::{ProbabilityOutput, probability_output};
use crate::contract::equilibrium::dto::{AerostatInput, CableInput};
use crate::contract::system::WinchInput;
use crate::contract::system::validate::{require_count, require_range};
use crate::contract::{Progress, RequestError};
use crate::numerics::dynamics::Outcome;
use crate::numerics::parallel::Parallelism;
use crate::numerics::params::InvalidInput;
use crate::numerics::tether::gust::scaled_profile;
use crate::numerics::uncertainty::percentiles::{mean_std, order_statistic_interval, quantiles};

/// Most samples of one request.
pub const MAX_PEAK_SAMPLES: usize = 10_000;
/// Most segment-steps of one request (all samples).
pub const MAX_PEAK_WORK: f64 = 2e10;
/// Samples kept per second of exposure at most (for the lowest altitude).
const SAMPLES_PER_SECOND: f64 = 1.0;

fn default_levels() -> Vec<f64> {
    vec![0.5, 0.9, 0.99]
}
fn default_confidence() -> f64 {
    0.95
}
fn default_peak_factor() -> f64 {
    3.0
}

/// `POST /api/v1/dynamics/peaks`: the largest winch tension over an
/// exposure, sampled over turbulence seeds.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({
    "cable": {"preset": "dyneema", "diameter_m": 0.006},
    "aerostat": {"net_buoyancy_n": 2000.0, "mass_kg": 100.0, "drag_coefficient_nondim": 0.3,
                 "reference_area_m2": 20.0},
    "wind": {"flow": {"kind": "uniform", "speed_m_s": 8.0}, "air_density_kg_m3": 1.225,
             "time_history": {"kind": "turbulence", "model": "von_karman",
                              "turbulence_intensity_nondim": 0.15, "length_scale_m": 340.0, "seed": 1}},
    "tether_length_m": 500.0,
    "exposure_s": 60.0,
    "samples": 8,
    "percentiles_nondim": [0.5, 0.9],
    "numerics": {"segments": 20, "time_step_s": 0.1}
}))]
pub struct DynamicsPeaksRequest {
    pub cable: CableInput,
    pub aerostat: AerostatInput,
    /// The mean flow and `time_history` of kind `turbulence` (its seed is sample 0's).
    pub wind: DynamicsWindInput,
    /// Unstretched length L (m).
    #[schema(example = 1000.0, minimum = 1.0, maximum = 20000.0)]
    pub tether_length_m: f64,
    /// Length of each sample's run (s): the exposure whose maximum is counted (3600: the hourly maximum).
    #[schema(example = 600.0, exclusive_minimum = 0.0, maximum = 100000.0)]
    pub exposure_s: f64,
    /// Seeds sampled (sample i has seed `seed + i`).
    #[schema(example = 100, minimum = 1, maximum = 10000)]
    pub samples: usize,
    /// Percentile levels of the maxima, each in (0, 1) (default 0.5, 0.9, 0.99; at most 9).
    #[serde(default = "default_levels")]
    pub percentiles_nondim: Vec<f64>,
    /// Confidence of the percentiles' order-statistic intervals (default 0.95).
    #[serde(default = "default_confidence")]
    #[schema(example = 0.95, minimum = 0.5, maximum = 0.999)]
    pub confidence_nondim: f64,
    /// Peak factor k of the quasi-static gust check (SPEC §10: gust = mean × (1 + k I)), default 3.
    #[serde(default = "default_peak_factor")]
    #[schema(example = 3.0, minimum = 0.0, maximum = 10.0)]
    pub peak_factor_nondim: f64,
    /// Kelvin–Voigt internal damping (N s), default 0.
    #[serde(default)]
    #[schema(example = 0.0, minimum = 0.0, maximum = 1e12)]
    pub internal_damping_n_s: f64,
    /// Tangential drag coefficient on π d, default 0.
    #[serde(default)]
    #[schema(example = 0.0, minimum = 0.0, maximum = 1.0)]
    pub tangential_drag_coefficient_nondim: f64,
    #[serde(default)]
    pub numerics: DynamicsNumericsInput,
    #[serde(default = "super::dto::default_gravity")]
    #[schema(example = 9.81, exclusive_minimum = 0.0, maximum = 100.0)]
    pub gravity_m_s2: f64,
    /// Safety factor required of the percentiles (breaking strength / tension), default 5.
    #[serde(default = "crate::contract::system::default_safety_factor")]
    #[schema(example = 5.0, minimum = 1.0, maximum = 100.0)]
    pub required_safety_factor_nondim: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub winch: Option<WinchInput>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 1.0, minimum = 0.001, maximum = 10000.0)]
    pub initial_length_m: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 0.05, minimum = 0.0, maximum = 0.9)]
    pub lift_reserve_nondim: Option<f64>,
}

/// One sample's extremes.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct PeakSampleOutput {
    pub sample: usize,
    /// Its turbulence seed (`seed + sample`).
    pub seed: u64,
    /// Largest winch tension over the exposure and when (N, s).
    pub max_winch_tension_n: f64,
    pub max_winch_tension_time_s: f64,
    /// Smallest winch tension (N).
    pub min_winch_tension_n: f64,
    /// Largest tension anywhere along the tether (N).
    pub max_tension_n: f64,
    /// Lowest aerostat altitude among the 1 s samples (m).
    pub min_aerostat_altitude_m: f64,
    /// Whether some segment went slack.
    pub slack: bool,
    /// Whether the run reached the end of the exposure (a failed run is left out of the summary).
    pub completed: bool,
}

/// One percentile with its interval.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct PeakPercentileOutput {
    pub level_nondim: f64,
    /// Type-7 estimate (N).
    pub value_n: f64,
    /// Order-statistic interval at `confidence_nondim` (N); null when there are too few samples for that end.
    pub low_n: Option<f64>,
    pub high_n: Option<f64>,
    /// `value_n` raised by the step error estimate (`value_n × (1 +
    /// step_check.relative_error_estimate_nondim)`, N): the safe side of
    /// the discretisation; null without a step check.
    pub safe_side_n: Option<f64>,
}

/// The distribution of one maximum over the completed samples.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct PeakDistributionOutput {
    pub mean_n: f64,
    pub std_dev_n: f64,
    pub largest_n: f64,
    pub percentiles: Vec<PeakPercentileOutput>,
}

/// The quasi-static tensions at the same length (SPEC §6, §10).
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct PeaksQuasiStaticOutput {
    /// Static winch tension in the mean flow (N); null: no equilibrium.
    pub mean_wind_winch_tension_n: Option<f64>,
    /// `1 + k I`.
    pub gust_factor_nondim: f64,
    /// Static winch tension with the mean flow scaled by the gust factor (N): the §10 gust check; null: no equilibrium.
    pub gust_check_winch_tension_n: Option<f64>,
    /// Largest static tension along the tether at the gust (N).
    pub gust_check_max_tension_n: Option<f64>,
}

/// The step error of the samples, measured on one of them.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct PeaksStepCheckOutput {
    /// The sample re-run: the completed one whose largest winch tension is
    /// nearest the highest requested percentile.
    pub sample: usize,
    /// The samples' time step and the check's, half of it (s).
    pub time_step_s: f64,
    pub check_time_step_s: f64,
    /// That sample's largest winch tension at the samples' step and at half of it (N).
    pub max_winch_tension_n: f64,
    pub check_max_winch_tension_n: f64,
    /// Its largest tension anywhere at both steps (N).
    pub max_tension_n: f64,
    pub check_max_tension_n: f64,
    /// The larger of the two maxima's changes over their half-step value:
    /// the estimated relative step error of every sample's maxima (and so
    /// of the percentiles).
    pub relative_error_estimate_nondim: f64,
}

/// The answer of `POST /api/v1/dynamics/peaks`.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct DynamicsPeaksResponse {
    /// Every sample, in sample order.
    pub samples: Vec<PeakSampleOutput>,
    /// The largest winch tension over the exposure.
    pub max_winch_tension: PeakDistributionOutput,
    /// The largest tension anywhere along the tether over the exposure.
    pub max_tension: PeakDistributionOutput,
    pub quasi_static: PeaksQuasiStaticOutput,
    /// Probability that the exposure's largest winch tension exceeds the gust check's (Wilson 95 %).
    pub probability_above_gust_check: Option<ProbabilityOutput>,
    /// Completed samples (the summary's).
    pub completed_samples: usize,
    /// Samples that went slack at some step.
    pub slack_samples: usize,
    pub exposure_s: f64,
    pub seed: u64,
    pub confidence_nondim: f64,
    /// Allowable tension: breaking strength / required factor (N); null without a breaking strength.
    pub allowable_tension_n: Option<f64>,
    /// The step error of the samples, measured on one re-run at half the
    /// step; null when that run did not reach the end (the explanation says so).
    pub step_check: Option<PeaksStepCheckOutput>,
    /// `monte_carlo`: independent seeds, one run each.
    pub method: String,
    pub explanation: String,
}

impl DynamicsPeaksRequest {
    fn turbulence_seed(&self) -> Result<u64, InvalidInput> {
        match &self.wind.time_history {
            Some(TimeHistoryInput::Turbulence { seed, .. }) => Ok(*seed),
            _ => Err(InvalidInput::new(
                "wind.time_history",
                "the peaks need turbulence: give {\"kind\": \"turbulence\", \"model\", \"turbulence_intensity_nondim\", \"length_scale_m\", \"seed\"}",
            )),
        }
    }

    /// The dynamics request of sample `i`.
    pub fn sample_request(&self, i: usize) -> DynamicsRequest {
        let mut wind = self.wind.clone();
        if let Some(TimeHistoryInput::Turbulence { seed, .. }) = &mut wind.time_history {
            *seed = seed.wrapping_add(i as u64);
        }
        let count = ((self.exposure_s * SAMPLES_PER_SECOND).ceil() as usize + 1).clamp(2, 100_001);
        // One run per sample at a fixed discretisation (the answer is a
        // distribution over seeds, not one converged history).
        let mut numerics = self.numerics.clone();
        numerics
            .segments
            .get_or_insert(super::validate::DEFAULT_SEGMENTS);
        numerics
            .time_step_s
            .get_or_insert(super::validate::PEAKS_TIME_STEP_S);
        DynamicsRequest {
            cable: self.cable.clone(),
            aerostat: self.aerostat.clone(),
            wind,
            tether_length_m: Some(self.tether_length_m),
            profile: None,
            initial_length_m: None,
            duration_s: self.exposure_s,
            sample_count: count,
            shape_count: Some(0),
            shape_times_s: None,
            wind_probe_height_m: None,
            internal_damping_n_s: self.internal_damping_n_s,
            tangential_drag_coefficient_nondim: self.tangential_drag_coefficient_nondim,
            numerics,
            gravity_m_s2: self.gravity_m_s2,
            required_safety_factor_nondim: self.required_safety_factor_nondim,
            winch: self.winch.clone(),
            lift_reserve_nondim: self.lift_reserve_nondim,
        }
    }

    /// Every check that needs no run; sample 0's prepared problem.
    pub fn prepare(&self) -> Result<Prepared, InvalidInput> {
        let seed = self.turbulence_seed()?;
        require_count("samples", self.samples, 1, MAX_PEAK_SAMPLES)?;
        if seed > MAX_SEED || MAX_SEED - seed < self.samples as u64 {
            return Err(InvalidInput::new(
                "wind.time_history.seed",
                format!(
                    "plus the samples must stay at most {MAX_SEED} (2^53 − 1), got {seed} + {}",
                    self.samples
                ),
            ));
        }
        require_range("exposure_s", self.exposure_s, 0.0, true, 1e5)?;
        if self.percentiles_nondim.is_empty() || self.percentiles_nondim.len() > 9 {
            return Err(InvalidInput::new(
                "percentiles_nondim",
                format!("give 1 to 9 levels, got {}", self.percentiles_nondim.len()),
            ));
        }
        for (i, p) in self.percentiles_nondim.iter().enumerate() {
            require_range(&format!("percentiles_nondim[{i}]"), *p, 0.0, true, 0.999999)?;
        }
        require_range(
            "confidence_nondim",
            self.confidence_nondim,
            0.5,
            false,
            0.999,
        )?;
        require_range(
            "peak_factor_nondim",
            self.peak_factor_nondim,
            0.0,
            false,
            10.0,
        )?;
        if let Some(l) = self.initial_length_m {
            crate::numerics::params::ranges::INITIAL_LENGTH_M.check("initial_length_m", l)?;
        }
        let prepared = self
            .sample_request(0)
            .prepare()
            .map_err(|e| match e.field.as_str() {
                "duration_s" => InvalidInput::new("exposure_s", e.reason),
                _ => e,
            })?;
        let total = prepared.work() * self.samples as f64;
        if total > MAX_PEAK_WORK {
            return Err(InvalidInput::new(
                "samples",
                format!(
                    "{} samples of {:.0} segment-steps each exceed {MAX_PEAK_WORK:e} segment-steps in all",
                    self.samples,
                    prepared.work()
                ),
            ));
        }
        Ok(prepared)
    }

    /// Segment-steps of the whole request.
    pub fn work(&self) -> f64 {
        self.prepare()
            .map_or(0.0, |p| p.work() * self.samples as f64)
    }
}

/// The samples `range` (in sample order), on rayon or serially.
pub fn peak_samples(
    req: &DynamicsPeaksRequest,
    range: std::ops::Range<usize>,
    parallelism: Parallelism,
    progress: &dyn Progress,
) -> Result<Vec<PeakSampleOutput>, RequestError> {
    req.prepare()?;
    if range.end > req.samples {
        return Err(RequestError::Malformed(format!(
            "samples {range:?} outside the {} samples",
            req.samples
        )));
    }
    let base = req.turbulence_seed()?;
    let done = AtomicUsize::new(0);
    let total = range.len();
    let one = |i: usize| -> Result<PeakSampleOutput, RequestError> {
        if progress.cancelled() {
            return Err(RequestError::Cancelled);
        }
        let prepared = req.sample_request(i).prepare()?;
        struct Stop<'a>(&'a dyn Progress);
        impl Progress for Stop<'_> {
            fn report(&self, _: usize, _: usize) {}
            fn cancelled(&self) -> bool {
                self.0.cancelled()
            }
        }
        let ran = run_prepared(&prepared, &Stop(progress))?;
        let run = &ran.run;
        let out = PeakSampleOutput {
            sample: i,
            seed: base + i as u64,
            max_winch_tension_n: run.peak_winch_tension.value,
            max_winch_tension_time_s: run.peak_winch_tension.time_s,
            min_winch_tension_n: run.min_winch_tension.value,
            max_tension_n: run.peak_tension.value,
            min_aerostat_altitude_m: run
                .samples
                .iter()
                .map(|s| s.aerostat_altitude_m)
                .fold(f64::INFINITY, f64::min),
            slack: !run.slack_events.is_empty(),
            completed: matches!(run.outcome, Outcome::Completed),
        };
        let d = done.fetch_add(1, Ordering::Relaxed) + 1;
        progress.report(d, total);
        Ok(out)
    };
    let out: Result<Vec<_>, _> = match parallelism {
        Parallelism::Serial => range.map(one).collect(),
        Parallelism::Rayon => range.into_par_iter().map(one).collect(),
    };
    out
}

fn distribution(mut values: Vec<f64>, levels: &[f64], confidence: f64) -> PeakDistributionOutput {
    let n = values.len();
    let (mean, std) = mean_std(&values);
    let intervals: Vec<_> = levels
        .iter()
        .map(|&p| order_statistic_interval(n, p, confidence))
        .collect();
    let qs = quantiles(&mut values, levels, &intervals);
    PeakDistributionOutput {
        mean_n: mean,
        std_dev_n: if n > 1 { std } else { 0.0 },
        largest_n: values.last().copied().unwrap_or(f64::NAN),
        percentiles: qs
            .into_iter()
            .map(|q| PeakPercentileOutput {
                level_nondim: q.level,
                value_n: q.value,
                low_n: q.low,
                high_n: q.high,
                safe_side_n: None,
            })
            .collect(),
    }
}

/// Re-runs the completed sample whose largest winch tension is nearest
/// `target_n` at half its time step; `None` when that run does not reach
/// the end of the exposure.
pub fn step_check(
    req: &DynamicsPeaksRequest,
    samples: &[&PeakSampleOutput],
    target_n: f64,
) -> Result<Option<PeaksStepCheckOutput>, RequestError> {
    let Some(s) = samples.iter().min_by(|a, b| {
        (a.max_winch_tension_n - target_n)
            .abs()
            .total_cmp(&(b.max_winch_tension_n - target_n).abs())
    }) else {
        return Ok(None);
    };
    let mut check = req.sample_request(s.sample);
    let h = check
        .numerics
        .time_step_s
        .unwrap_or(super::validate::PEAKS_TIME_STEP_S);
    check.numerics.time_step_s = Some(0.5 * h);
    let prepared = check.prepare()?;
    let ran = run_prepared(&prepared, &crate::contract::run::NoProgress)?;
    let run = &ran.run;
    if run.outcome != Outcome::Completed {
        return Ok(None);
    }
    let (w, t) = (run.peak_winch_tension.value, run.peak_tension.value);
    let relative =
        ((s.max_winch_tension_n - w).abs() / w.abs()).max((s.max_tension_n - t).abs() / t.abs());
    Ok(Some(PeaksStepCheckOutput {
        sample: s.sample,
        time_step_s: h,
        check_time_step_s: 0.5 * h,
        max_winch_tension_n: s.max_winch_tension_n,
        check_max_winch_tension_n: w,
        max_tension_n: s.max_tension_n,
        check_max_tension_n: t,
        relative_error_estimate_nondim: relative,
    }))
}

/// The answer from every sample (in sample order).
pub fn summarise(
    req: &DynamicsPeaksRequest,
    samples: Vec<PeakSampleOutput>,
) -> Result<DynamicsPeaksResponse, RequestError> {
    let prepared = req.prepare()?;
    if samples.len() != req.samples || samples.iter().enumerate().any(|(i, s)| s.sample != i) {
        return Err(RequestError::Malformed(format!(
            "{} sample results for {} samples",
            samples.len(),
            req.samples
        )));
    }
    let p = &prepared.problem;
    let segments = prepared.config.segments;
    let intensity = p.turbulence.map_or(0.0, |t| t.intensity);
    let gust_factor = 1.0 + req.peak_factor_nondim * intensity;
    let mean_eq = equilibrium_at(p, req.tether_length_m, 0.0, segments);
    let mut gust_problem = p.clone();
    gust_problem.flow = scaled_profile(&p.flow, gust_factor);
    let gust_eq = equilibrium_at(&gust_problem, req.tether_length_m, 0.0, segments);
    let completed: Vec<&PeakSampleOutput> = samples.iter().filter(|s| s.completed).collect();
    if completed.is_empty() {
        return Err(InvalidInput::new(
            "numerics.time_step_s",
            "no sample ran to the end of the exposure (the implicit step failed): try a smaller time step",
        )
        .into());
    }
    let winch: Vec<f64> = completed.iter().map(|s| s.max_winch_tension_n).collect();
    let anywhere: Vec<f64> = completed.iter().map(|s| s.max_tension_n).collect();
    let levels = &req.percentiles_nondim;
    let max_winch_tension = distribution(winch.clone(), levels, req.confidence_nondim);
    let max_tension = distribution(anywhere, levels, req.confidence_nondim);
    let above = gust_eq.as_ref().map(|g| {
        let events = winch.iter().filter(|&&t| t > g.winch_tension_n).count();
        probability_output(events, winch.len())
    });
    let strength = req
        .cable
        .breaking_strength()
        .ok()
        .flatten()
        .map(|b| b / req.required_safety_factor_nondim);
    let quasi_static = PeaksQuasiStaticOutput {
        mean_wind_winch_tension_n: mean_eq.as_ref().map(|e| e.winch_tension_n),
        gust_factor_nondim: gust_factor,
        gust_check_winch_tension_n: gust_eq.as_ref().map(|e| e.winch_tension_n),
        gust_check_max_tension_n: gust_eq.as_ref().map(|e| e.max_tension_n),
    };
    let mut explanation = format!(
        "{} of {} samples of {:.0} s ran to the end. The largest winch tension has median {:.1} N",
        completed.len(),
        samples.len(),
        req.exposure_s,
        crate::numerics::uncertainty::percentiles::type7(
            &{
                let mut w = winch.clone();
                w.sort_unstable_by(f64::total_cmp);
                w
            },
            0.5
        )
    );
    if let Some(top) = max_winch_tension.percentiles.last() {
        explanation.push_str(&format!(
            " and {:.0} % point {:.1} N",
            100.0 * top.level_nondim,
            top.value_n
        ));
    }
    if let Some(t) = quasi_static.mean_wind_winch_tension_n {
        explanation.push_str(&format!(
            "; the static tension is {t:.1} N in the mean wind"
        ));
    }
    if let (Some(g), Some(pa)) = (quasi_static.gust_check_winch_tension_n, &above) {
        explanation.push_str(&format!(
            " and {g:.1} N at the gust check (× {gust_factor:.2} wind); {} of {} maxima exceed it.",
            pa.event_samples,
            winch.len()
        ));
    } else {
        explanation.push('.');
    }
    let top = max_winch_tension
        .percentiles
        .iter()
        .map(|p| p.value_n)
        .next_back()
        .unwrap_or(f64::NAN);
    let step_check = step_check(req, &completed, top)?;
    let (mut max_winch_tension, mut max_tension) = (max_winch_tension, max_tension);
    if let Some(c) = &step_check {
        for p in max_winch_tension
            .percentiles
            .iter_mut()
            .chain(max_tension.percentiles.iter_mut())
        {
            p.safe_side_n = Some(p.value_n * (1.0 + c.relative_error_estimate_nondim));
        }
    }
    match &step_check {
        Some(c) => explanation.push_str(&format!(
            " Step error, measured on sample {} at half the step ({} s): {:.2} % of its maxima.",
            c.sample,
            c.check_time_step_s,
            100.0 * c.relative_error_estimate_nondim
        )),
        None => explanation.push_str(
            " The step check (one sample at half the step) did not run to the end: the step error is not known.",
        ),
    }
    let slack_samples = samples.iter().filter(|s| s.slack).count();
    Ok(DynamicsPeaksResponse {
        step_check,
        completed_samples: completed.len(),
        slack_samples,
        samples,
        max_winch_tension,
        max_tension,
        quasi_static,
        probability_above_gust_check: above,
        exposure_s: req.exposure_s,
        seed: req.turbulence_seed()?,
        confidence_nondim: req.confidence_nondim,
        allowable_tension_n: strength,
        method: "monte_carlo".into(),
        explanation,
    })
}

/// The whole answer in one process.
pub fn peaks(
    req: &DynamicsPeaksRequest,
    parallelism: Parallelism,
    progress: &dyn Progress,
) -> Result<DynamicsPeaksResponse, RequestError> {
    let samples = peak_samples(req, 0..req.samples, parallelism, progress)?;
    summarise(req, samples)
}

/// One chunk's result: the samples `range` as JSON text.
pub fn peaks_chunk(
    req: &DynamicsPeaksRequest,
    range: std::ops::Range<usize>,
    parallelism: Parallelism,
    progress: &dyn Progress,
) -> Result<String, RequestError> {
    crate::contract::finite::to_string(&peak_samples(req, range, parallelism, progress)?)
}

/// The answer from the chunks' results, in chunk order.
pub fn peaks_from_chunks(
    req: &DynamicsPeaksRequest,
    parts: &[String],
) -> Result<DynamicsPeaksResponse, RequestError> {
    let mut samples = Vec::with_capacity(req.samples);
    for part in parts {
        let chunk: Vec<PeakSampleOutput> = serde_json::from_str(part)
            .map_err(|e| RequestError::Malformed(format!("a chunk result: {e}")))?;
        samples.extend(chunk);
    }
    summarise(req, samples)
}
