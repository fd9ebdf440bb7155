//! `POST /api/v1/plan/bands` (SPEC §7 + §8, issue 14): a deployment plan
//! under uncertain inputs.
//!
//! The nominal plan is computed once, exactly as `POST /api/v1/plan`
//! answers the request without `uncertainty`. The winch then follows that
//! schedule whatever the true inputs are; each sample asks what the
//! schedule does to *its* system, at every instant the plan reports (the
//! `samples` evenly spaced instants plus every phase boundary, each with
//! the acceleration that starts there):
//!
//! * **unstable** — the effective roller tension with the sample's full
//!   buoyancy, `F − m L̈ − ρA (g + L̈) L − ρA L̇²`, falls below zero at
//!   some instant (the plan's stability criterion, SPEC §7, for the
//!   sample's inputs and no reserve: the sample *is* the realised system);
//! * **below reserve** — the plan's own criterion with the sample's inputs
//!   fails somewhere: `(1 − r)F − … < ε(1 − r)F` (the lift reserve was not
//!   enough);
//! * **over rating** — the largest tension along the cable exceeds the
//!   sample's breaking strength / safety factor at some instant.
//!
//! Each instant's value for a sample is the plan's own value there plus
//! the exact change of the calm-air expression under the sample's inputs
//! (every term is linear in `F`, `m`, `ρA` at a fixed schedule), so a
//! sample equal to the request reproduces the plan's numbers bit for bit.
//! Per instant: 5/50/95 % bands of the winch tension, the largest tension
//! and the stability margin (m/s, with the reserve, as the plan reports
//! it), for the page to shade around the plan's traces. Probabilities carry
//! their Wilson 95 % interval.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::contract::bands::common::{
    self, FieldRange, ProbabilityOutput, UncertainField, UncertaintyParams,
};
use crate::contract::bands::dto::{PercentileBand, RejectedSamplesOutput, UncertainInput};
use crate::contract::bands::run::{RawSystem, SystemField};
use crate::contract::plan::{PlanRequest, PlanResponse};
use crate::contract::{Progress, RequestError, parse_value};
use crate::numerics::parallel::Parallelism;
use crate::numerics::params::{AerostatSystem, InvalidInput};
use crate::numerics::plan::STABILITY_MARGIN;
use crate::numerics::uncertainty;

/// Most sample × instant values of one plan bands request (a job).
pub const MAX_PLAN_BAND_VALUES: usize = 20_000_000;

/// `POST /api/v1/plan/bands`: a plan request (every field of
/// `POST /api/v1/plan`) and `uncertainty`.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({
    "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
    "initial_length_m": 1.0,
    "target_elevation_m": 1200.0,
    "winch": {"max_rate_m_s": 40.0, "max_acceleration_m_s2": 2.0},
    "lift_reserve_nondim": 0.05,
    "cable": {"mass_per_length_kg_m": 0.078, "breaking_strength_n": 5200.0},
    "required_safety_factor_nondim": 5.0,
    "samples": 101,
    "uncertainty": {
        "samples": 1000,
        "seed": 7,
        "inputs": [
            {"field": "aerostat.net_buoyancy_n", "distribution": "normal", "mean": 1000.0, "std_dev": 50.0},
            {"field": "cable.mass_per_length_kg_m", "distribution": "normal", "mean": 0.078, "std_dev": 0.002}
        ]
    }
}))]
pub struct PlanBandsRequest {
    #[serde(flatten)]
    pub plan: PlanRequest,
    #[serde(flatten)]
    pub params: UncertaintyParams,
}

/// Bands of the plan's traces at one instant of the schedule.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct PlanInstantBandOutput {
    pub time_s: f64,
    /// Cable length of the schedule here (m).
    pub length_m: f64,
    /// Winch tension F − mL̈ − ρA(g + L̈)L (N) across the samples.
    pub winch_tension_n: PercentileBand,
    /// Largest tension along the cable (N) across the samples.
    pub max_tension_n: PercentileBand,
    /// Stability margin with the lift reserve (m/s), as the plan reports it, across the samples.
    pub stability_margin_m_s: PercentileBand,
}

/// The answer of `POST /api/v1/plan/bands`.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct PlanBandsResponse {
    /// The nominal plan (the request's own values), as `POST /api/v1/plan` answers it.
    pub plan: PlanResponse,
    /// One entry per instant of `plan.schedule` (empty when infeasible).
    pub instants: Vec<PlanInstantBandOutput>,
    /// P(some instant is unstable with the sample's full buoyancy); null when infeasible.
    pub probability_unstable: Option<ProbabilityOutput>,
    /// P(the plan's own criterion with the lift reserve fails somewhere for the sample's inputs).
    pub probability_below_reserve: Option<ProbabilityOutput>,
    /// P(the largest tension exceeds breaking strength / safety factor somewhere); null without `cable.breaking_strength_n`.
    pub probability_over_rating: Option<ProbabilityOutput>,
    /// P(unstable or over the rating somewhere).
    pub probability_unsafe: Option<ProbabilityOutput>,
    /// Smallest effective roller tension over the schedule with the sample's full buoyancy (N).
    pub min_effective_tension_n: Option<PercentileBand>,
    /// Largest tension over the schedule (N).
    pub peak_tension_n: Option<PercentileBand>,
    /// Samples drawn.
    pub samples: usize,
    /// Samples with every draw in range (the statistics are over these).
    pub valid_samples: usize,
    pub rejected_samples: Vec<RejectedSamplesOutput>,
    pub seed: u64,
    /// The uncertain inputs, as given.
    pub inputs: Vec<UncertainInput>,
    /// Confidence level of every interval (0.95).
    pub confidence_level_nondim: f64,
    /// How the probabilities were computed.
    pub method: String,
}

const METHOD: &str = "Monte Carlo (sample i draws from its own counter-based stream of (seed, i)): the nominal \
schedule is computed once; each sample evaluates it, at every reported instant, with its own inputs (each value \
is the plan's plus the exact change of the calm-air expression, linear in F, m and ρA at a fixed schedule). \
Unstable: F − mL̈ − ρA(g+L̈)L − ρA L̇² < 0 somewhere (the sample's full buoyancy). Below reserve: the plan's \
criterion (1−r)F − … ≥ ε(1−r)F fails somewhere. Over rating: the largest tension exceeds breaking strength / \
safety factor somewhere. Probabilities with the Wilson 95 % interval; percentiles with the distribution-free \
order-statistic 95 % interval.";

/// A numeric input of the plan that may be uncertain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PlanField {
    System(SystemField),
    BreakingStrength,
}

impl UncertainField for PlanField {
    fn path(self) -> &'static str {
        match self {
            Self::System(f) => f.path(),
            Self::BreakingStrength => "cable.breaking_strength_n",
        }
    }
    fn range(self) -> FieldRange {
        match self {
            Self::System(f) => f.valid_range(),
            Self::BreakingStrength => FieldRange::open_below(0.0, 1e9, "N"),
        }
    }
}

const PLAN_FIELDS: [&str; 7] = [
    "aerostat.net_buoyancy_n",
    "aerostat.mass_kg",
    "cable.mass_per_length_kg_m",
    "cable.density_kg_m3",
    "cable.area_m2",
    "gravity_m_s2",
    "cable.breaking_strength_n",
];

/// Parses a plan bands body: the plan part exactly as `POST /api/v1/plan`
/// parses it (unknown fields refused), `uncertainty` on its own.
pub fn parse_plan_bands(body: &[u8]) -> Result<PlanBandsRequest, RequestError> {
    let (rest, params) = common::split_uncertainty(body)?;
    let bytes = serde_json::to_vec(&rest).expect("values serialise");
    let plan = crate::contract::plan::parse_plan(&bytes)?;
    let params: UncertaintyParams = parse_value(&serde_json::Value::Object(params))?;
    Ok(PlanBandsRequest { plan, params })
}

/// The validated request, ready to run.
pub struct PreparedPlanBands {
    base: RawSystem,
    nominal: AerostatSystem,
    breaking_strength_n: Option<f64>,
    safety_factor: f64,
    fields: Vec<PlanField>,
    ensemble: uncertainty::Ensemble,
}

/// Every check that needs no solve.
pub fn prepare_plan_bands(req: &PlanBandsRequest) -> Result<PreparedPlanBands, RequestError> {
    crate::contract::plan::validate_plan(&req.plan)?;
    let system = req.plan.system_input();
    let nominal = system.model()?.system;
    let base = RawSystem::of(&system);
    let u = &req.params.uncertainty;
    let ensemble = common::ensemble_of(u)?;
    let instants = req.plan.samples.saturating_add(64);
    if u.samples.saturating_mul(instants) > MAX_PLAN_BAND_VALUES {
        return Err(InvalidInput::new(
            "uncertainty.samples",
            format!(
                "{} samples × about {instants} instants of the schedule exceed {MAX_PLAN_BAND_VALUES} values: fewer samples or a coarser `samples`",
                u.samples
            ),
        )
        .into());
    }
    let breaking_strength_n = req.plan.cable.breaking_strength()?;
    let rated = breaking_strength_n.is_some();
    let fields = common::resolve_fields(&u.inputs, &ensemble, |path| {
        let f = match path {
            "cable.breaking_strength_n" => PlanField::BreakingStrength,
            _ => match SystemField::from_path(path) {
                Some(f) if f != SystemField::InitialLength => PlanField::System(f),
                _ => {
                    return Err(format!(
                        "`{path}` is not a numeric input of the plan that can be uncertain: one of {} (the schedule starts at initial_length_m, so it is not uncertain)",
                        PLAN_FIELDS.join(", ")
                    ));
                }
            },
        };
        match f {
            PlanField::System(s) if !base.has(s) => Err(format!(
                "`{path}` is not given in this request: make the cable's given form uncertain"
            )),
            PlanField::BreakingStrength if !rated => Err(
                "`cable.breaking_strength_n` is uncertain but the request gives no breaking strength"
                    .into(),
            ),
            f => Ok(f),
        }
    })?;
    Ok(PreparedPlanBands {
        base,
        nominal,
        breaking_strength_n,
        safety_factor: req.plan.required_safety_factor_nondim,
        fields,
        ensemble,
    })
}

/// Sample × instant values of the request (for admission limits).
pub fn plan_band_values(req: &PlanBandsRequest) -> usize {
    req.params
        .uncertainty
        .samples
        .saturating_mul(req.plan.samples.saturating_add(64))
}

/// One sample's pass over the schedule.
struct SampleTrace {
    winch: Vec<f64>,
    max: Vec<f64>,
    margin: Vec<f64>,
    min_effective: f64,
    peak: f64,
    unstable: bool,
    below_reserve: bool,
    over_rating: bool,
}

/// The schedule's instants as the nominal plan reports them.
struct Instant {
    length: f64,
    rate: f64,
    accel: f64,
    winch: f64,
    max: f64,
    effective_reserve: f64,
    margin: f64,
}

fn trace(
    prep: &PreparedPlanBands,
    instants: &[Instant],
    reserve: f64,
    s: &AerostatSystem,
    breaking: Option<f64>,
) -> SampleTrace {
    let n = &prep.nominal;
    let d_f = s.net_buoyancy_n - n.net_buoyancy_n;
    let d_m = s.aerostat_mass_kg - n.aerostat_mass_kg;
    let d_ra = s.mass_per_length_kg_m - n.mass_per_length_kg_m;
    let allowable = breaking.map(|b| b / prep.safety_factor);
    let margin_floor = STABILITY_MARGIN * (1.0 - reserve) * s.net_buoyancy_n;
    let mut out = SampleTrace {
        winch: Vec::with_capacity(instants.len()),
        max: Vec::with_capacity(instants.len()),
        margin: Vec::with_capacity(instants.len()),
        min_effective: f64::INFINITY,
        peak: f64::NEG_INFINITY,
        unstable: false,
        below_reserve: false,
        over_rating: false,
    };
    for k in instants {
        let (l, v, a) = (k.length, k.rate, k.accel);
        // change of ρA(g + L̈): exactly 0 when the sample's ρA, g are the request's
        let d_weight = s.mass_per_length_kg_m * (s.gravity_m_s2 + a)
            - n.mass_per_length_kg_m * (n.gravity_m_s2 + a);
        let d_kinematic = d_ra * v * v;
        let d_winch = d_f - d_m * a - d_weight * l;
        let winch = k.winch + d_winch;
        let top = |sys: &AerostatSystem| sys.net_buoyancy_n - sys.aerostat_mass_kg * a;
        let calm_winch =
            |sys: &AerostatSystem| top(sys) - sys.mass_per_length_kg_m * (sys.gravity_m_s2 + a) * l;
        let max = k.max + (top(s).max(calm_winch(s)) - top(n).max(calm_winch(n)));
        let effective_reserve =
            k.effective_reserve + ((1.0 - reserve) * d_f - d_m * a - d_weight * l - d_kinematic);
        let effective = k.effective_reserve
            + reserve * n.net_buoyancy_n
            + (d_f - d_m * a - d_weight * l - d_kinematic);
        let ceiling = |e: f64, ra: f64| ((e + ra * v * v) / ra).max(0.0).sqrt();
        let margin = k.margin
            + (ceiling(effective_reserve, s.mass_per_length_kg_m)
                - ceiling(k.effective_reserve, n.mass_per_length_kg_m));
        out.unstable |= effective < 0.0;
        out.below_reserve |= effective_reserve < margin_floor - 1e-9 * s.net_buoyancy_n;
        if let Some(allow) = allowable {
            out.over_rating |= max > allow * (1.0 + 1e-9);
        }
        out.min_effective = out.min_effective.min(effective);
        out.peak = out.peak.max(max);
        out.winch.push(winch);
        out.max.push(max);
        out.margin.push(margin);
    }
    out
}

/// The nominal plan and its schedule's instants (cancellable).
fn nominal(
    req: &PlanBandsRequest,
    progress: &dyn Progress,
) -> Result<(PlanResponse, Vec<Instant>), RequestError> {
    let plan = crate::contract::plan::plan(&req.plan, &common::Silent(progress))?;
    if progress.cancelled() {
        return Err(RequestError::Cancelled);
    }
    let instants: Vec<Instant> = plan
        .schedule
        .iter()
        .map(|s| Instant {
            length: s.length_m,
            rate: s.rate_m_s,
            accel: s.acceleration_m_s2,
            winch: s.winch_tension_n,
            max: s.max_tension_n,
            effective_reserve: s.effective_tension_margin_n,
            margin: s.stability_margin_m_s,
        })
        .collect();
    Ok((plan, instants))
}

/// Each sample of `range`: its pass over the schedule, or the first field
/// whose draw is out of range.
fn sample_traces(
    req: &PlanBandsRequest,
    prep: &PreparedPlanBands,
    instants: &[Instant],
    range: std::ops::Range<usize>,
    parallelism: Parallelism,
    progress: &dyn Progress,
) -> Result<Vec<common::SampleOutcome<SampleTrace>>, RequestError> {
    let reserve = req.plan.lift_reserve_nondim;
    common::run_ensemble_range(
        &prep.ensemble,
        &prep.fields,
        range,
        parallelism,
        progress,
        |values| {
            let mut raw = prep.base;
            let mut breaking = prep.breaking_strength_n;
            for (&f, &v) in prep.fields.iter().zip(values) {
                match f {
                    PlanField::System(s) => raw.set(s, v),
                    PlanField::BreakingStrength => breaking = Some(v),
                }
            }
            // Each draw is in its field's range, but a combination (ρ·A)
            // may still fall outside: a rejected sample.
            Some(match raw.system() {
                Ok(sys) => Ok(trace(prep, instants, reserve, &sys, breaking)),
                Err(e) => Err(common::culprit(&prep.fields, &e)),
            })
        },
    )
}

/// Answers a plan bands request. Progress counts the samples (the
/// nominal plan comes first, cancellable).
pub fn plan_bands(
    req: &PlanBandsRequest,
    parallelism: Parallelism,
    progress: &dyn Progress,
) -> Result<PlanBandsResponse, RequestError> {
    let prep = prepare_plan_bands(req)?;
    let (plan, instants) = nominal(req, progress)?;
    let samples = 0..prep.ensemble.samples;
    let traces = sample_traces(req, &prep, &instants, samples, parallelism, progress)?;
    let results = common::collect_samples(prep.fields.len(), traces)?;
    Ok(summarise(req, &prep, plan, &instants, results))
}

/// One sample's pass on the wire between a chunk and its job: every
/// number as its IEEE-754 bits, so that the answer put together from
/// chunks is the single-process one exactly.
#[derive(Serialize, Deserialize)]
enum WireTrace {
    /// winch, max, margin per instant; min effective, peak; unstable,
    /// below reserve, over rating.
    Ok(Vec<u64>, Vec<u64>, Vec<u64>, u64, u64, [bool; 3]),
    Rejected(usize),
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

fn floats(v: Vec<u64>) -> Vec<f64> {
    v.into_iter().map(f64::from_bits).collect()
}

/// The samples `range` of a plan bands request as JSON text (one chunk of
/// a distributed job). Each chunk computes the nominal plan again (it is
/// deterministic) for the schedule its samples follow.
pub fn plan_bands_chunk(
    req: &PlanBandsRequest,
    range: std::ops::Range<usize>,
    parallelism: Parallelism,
    progress: &dyn Progress,
) -> Result<String, RequestError> {
    let prep = prepare_plan_bands(req)?;
    let (_, instants) = nominal(req, progress)?;
    let traces = sample_traces(req, &prep, &instants, range, parallelism, progress)?;
    let wire: Vec<WireTrace> = traces
        .iter()
        .map(|r| match r {
            Ok(t) => WireTrace::Ok(
                bits(&t.winch),
                bits(&t.max),
                bits(&t.margin),
                t.min_effective.to_bits(),
                t.peak.to_bits(),
                [t.unstable, t.below_reserve, t.over_rating],
            ),
            Err(k) => WireTrace::Rejected(*k),
        })
        .collect();
    Ok(serde_json::to_string(&wire).expect("samples serialise"))
}

/// The plan bands answer from its chunks ([`plan_bands_chunk`] of
/// consecutive ranges covering every sample, in order).
pub fn plan_bands_from_chunks(
    req: &PlanBandsRequest,
    parts: &[String],
) -> Result<PlanBandsResponse, RequestError> {
    let prep = prepare_plan_bands(req)?;
    let (plan, instants) = nominal(req, &crate::contract::error::NoProgress)?;
    let mut traces = Vec::with_capacity(prep.ensemble.samples);
    for part in parts {
        let wire: Vec<WireTrace> = serde_json::from_str(part)
            .map_err(|e| RequestError::Malformed(format!("a chunk of the plan bands job: {e}")))?;
        for w in wire {
            traces.push(match w {
                WireTrace::Ok(winch, max, margin, min_effective, peak, [u, b, o]) => {
                    if [winch.len(), max.len(), margin.len()] != [instants.len(); 3] {
                        return Err(RequestError::Malformed(format!(
                            "a chunk of the plan bands job has traces of another length than the {} instants of the schedule",
                            instants.len()
                        )));
                    }
                    Ok(SampleTrace {
                        winch: floats(winch),
                        max: floats(max),
                        margin: floats(margin),
                        min_effective: f64::from_bits(min_effective),
                        peak: f64::from_bits(peak),
                        unstable: u,
                        below_reserve: b,
                        over_rating: o,
                    })
                }
                WireTrace::Rejected(k) if k < prep.fields.len() => Err(k),
                WireTrace::Rejected(k) => {
                    return Err(RequestError::Malformed(format!(
                        "a chunk of the plan bands job rejects a sample on input {k}, which does not exist"
                    )));
                }
            });
        }
    }
    if traces.len() != prep.ensemble.samples {
        return Err(RequestError::Malformed(format!(
            "the chunks of the plan bands job hold {} samples, not {}",
            traces.len(),
            prep.ensemble.samples
        )));
    }
    let results = common::collect_samples(prep.fields.len(), traces)?;
    Ok(summarise(req, &prep, plan, &instants, results))
}

/// The answer from the nominal plan and every sample's pass.
fn summarise(
    req: &PlanBandsRequest,
    prep: &PreparedPlanBands,
    plan: PlanResponse,
    instants: &[Instant],
    results: common::EnsembleResults<SampleTrace>,
) -> PlanBandsResponse {
    let valid = &results.valid;
    let n = valid.len();
    let feasible = plan.feasible && !instants.is_empty();
    let count = |f: fn(&SampleTrace) -> bool| valid.iter().filter(|t| f(t)).count();
    let rated = prep.breaking_strength_n.is_some();
    let mut column = vec![0.0; n];
    let mut band = |pick: &dyn Fn(&SampleTrace) -> f64| {
        for (c, t) in column.iter_mut().zip(valid) {
            *c = pick(t);
        }
        common::band_of(&mut column)
    };
    let bands: Vec<PlanInstantBandOutput> = plan
        .schedule
        .iter()
        .enumerate()
        .map(|(j, s)| PlanInstantBandOutput {
            time_s: s.time_s,
            length_m: s.length_m,
            winch_tension_n: band(&|t| t.winch[j]),
            max_tension_n: band(&|t| t.max[j]),
            stability_margin_m_s: band(&|t| t.margin[j]),
        })
        .collect();
    let min_effective = feasible.then(|| band(&|t| t.min_effective));
    let peak = feasible.then(|| band(&|t| t.peak));
    let p = |k: usize| feasible.then(|| common::probability_output(k, n));
    let u = &req.params.uncertainty;
    PlanBandsResponse {
        instants: bands,
        probability_unstable: p(count(|t| t.unstable)),
        probability_below_reserve: p(count(|t| t.below_reserve)),
        probability_over_rating: if rated {
            p(count(|t| t.over_rating))
        } else {
            None
        },
        probability_unsafe: p(count(|t| t.unstable || t.over_rating)),
        min_effective_tension_n: min_effective,
        peak_tension_n: peak,
        samples: u.samples,
        valid_samples: n,
        rejected_samples: common::rejected_output(&prep.fields, &results.rejected),
        seed: u.seed,
        inputs: u.inputs.clone(),
        confidence_level_nondim: uncertainty::CONFIDENCE,
        method: METHOD.into(),
        plan,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contract::error::NoProgress;
    use serde_json::{Value, json};

    fn body(extra: Value) -> Vec<u8> {
        let mut v = json!({
            "cable": {"mass_per_length_kg_m": 0.078},
            "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
            "target_elevation_m": 1200.0,
            "winch": {"max_rate_m_s": 40.0, "max_acceleration_m_s2": 2.0},
            "samples": 51,
            "uncertainty": {"samples": 100, "seed": 3, "inputs": [
                {"field": "aerostat.net_buoyancy_n", "distribution": "normal", "mean": 1000.0, "std_dev": 50.0}
            ]}
        });
        for (k, x) in extra.as_object().unwrap() {
            v[k] = x.clone();
        }
        serde_json::to_vec(&v).unwrap()
    }

    fn field_of(b: Vec<u8>) -> String {
        let err = parse_plan_bands(&b)
            .and_then(|r| prepare_plan_bands(&r).map(drop))
            .expect_err("invalid");
        err.body().error.field.unwrap()
    }

    #[test]
    fn errors_name_their_field() {
        assert_eq!(field_of(body(json!({"wind_m_s": 1.0}))), "wind_m_s");
        assert_eq!(
            field_of(body(json!({"uncertainty": {"inputs": [
                {"field": "initial_length_m", "distribution": "normal", "mean": 1.0, "std_dev": 0.1}]}}))),
            "uncertainty.inputs[0].field"
        );
        assert_eq!(
            field_of(body(json!({"uncertainty": {"inputs": [
                {"field": "cable.breaking_strength_n", "distribution": "normal", "mean": 1e4, "std_dev": 1.0}]}}))),
            "uncertainty.inputs[0].field"
        );
        assert_eq!(
            field_of(body(
                json!({"uncertainty": {"samples": 10, "extra": 1, "inputs": []}})
            )),
            "uncertainty.extra"
        );
        assert_eq!(
            field_of(body(json!({"uncertainty": {"inputs": [
                {"field": "aerostat.mass_kg", "distribution": "normal", "mean": 10.0, "std_dev": 5.0}]}}))),
            "uncertainty.inputs[0]"
        );
        assert_eq!(
            field_of(body(
                json!({"winch": {"max_rate_m_s": -1.0, "max_acceleration_m_s2": 2.0}})
            )),
            "winch.max_rate_m_s"
        );
    }

    /// A sample equal to the request reproduces the plan's traces exactly.
    #[test]
    fn zero_width_reproduces_the_plan() {
        let b = body(json!({"uncertainty": {"samples": 5, "inputs": [
            {"field": "aerostat.net_buoyancy_n", "distribution": "normal", "mean": 1000.0, "std_dev": 0.0},
            {"field": "cable.mass_per_length_kg_m", "distribution": "uniform", "low": 0.078, "high": 0.078}]}}));
        let r = plan_bands(
            &parse_plan_bands(&b).unwrap(),
            Parallelism::Serial,
            &NoProgress,
        )
        .unwrap();
        assert_eq!(r.instants.len(), r.plan.schedule.len());
        for (b, s) in r.instants.iter().zip(&r.plan.schedule) {
            for (band, v) in [
                (&b.winch_tension_n, s.winch_tension_n),
                (&b.max_tension_n, s.max_tension_n),
                (&b.stability_margin_m_s, s.stability_margin_m_s),
            ] {
                assert_eq!((band.p05, band.p50, band.p95), (v, v, v));
            }
        }
        assert_eq!(r.probability_unstable.unwrap().event_samples, 0);
        assert_eq!(r.probability_below_reserve.unwrap().event_samples, 0);
    }
}
