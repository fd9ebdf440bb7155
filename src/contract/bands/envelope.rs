//! `POST /api/v1/envelope/bands` (SPEC §6 + §8, issue 14): the operating
//! envelope under uncertain inputs.
//!
//! The nominal envelope is `POST /api/v1/envelope`'s answer to the request
//! without `uncertainty`. Each sample replaces the uncertain numbers of the
//! resolved tether, aerostat and air (presets filled in first) and solves
//! the same envelope, cell by cell, with the same solver and judgement
//! ([`crate::numerics::tether::envelope`]); per cell the samples give:
//!
//! * the probability that the **tension limit** is exceeded: the largest
//!   tension above breaking strength / required safety factor (null
//!   without a breaking strength);
//! * with `payout_rate_m_s`, the probability that the cell is
//!   **unstable** (the envelope's criterion: smallest tension below
//!   `ρA v²`, or slack);
//! * the probability that the cell is **outside** the envelope (any limit);
//! * the 5/50/95 % band of the largest tension.
//!
//! A sample equal to the request solves the nominal envelope exactly.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::contract::bands::common::{
    self, FieldRange, ProbabilityOutput, UncertainField, UncertaintyParams,
};
use crate::contract::bands::dto::{PercentileBand, RejectedSamplesOutput, UncertainInput};
use crate::contract::envelope::dto::{EnvelopeRequest, EnvelopeResponse};
use crate::contract::{Progress, RequestError, parse_value};
use crate::numerics::parallel::Parallelism;
use crate::numerics::params::InvalidInput;
use crate::numerics::tether::envelope::EnvelopeProblem;
use crate::numerics::tether::{EquilibriumConfig, EquilibriumProblem};
use crate::numerics::uncertainty;

/// Most sample × cell equilibria of one envelope bands request (a job).
pub const MAX_ENVELOPE_BAND_EVALUATIONS: usize = 2_000_000;

/// `POST /api/v1/envelope/bands`: an envelope request (every field of
/// `POST /api/v1/envelope`) and `uncertainty`.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({
    "cable": {"preset": "dyneema", "diameter_m": 0.006},
    "aerostat": {"net_buoyancy_n": 2000.0, "mass_kg": 100.0, "drag_coefficient_nondim": 0.3,
                 "reference_area_m2": 20.0},
    "wind": {"flow": {"kind": "power_law", "coefficient_m_s": 8.0, "exponent_nondim": 0.14, "reference_height_m": 10.0},
             "air_density_kg_m3": 1.225},
    "wind_speeds_m_s": {"min": 0.0, "max": 30.0, "count": 7},
    "tether_lengths_m": {"min": 100.0, "max": 3000.0, "count": 6},
    "required_safety_factor_nondim": 5.0,
    "payout_rate_m_s": 5.0,
    "uncertainty": {
        "samples": 200,
        "seed": 7,
        "inputs": [
            {"field": "aerostat.net_buoyancy_n", "distribution": "normal", "mean": 2000.0, "std_dev": 100.0},
            {"field": "aerostat.drag_coefficient_nondim", "distribution": "uniform", "low": 0.25, "high": 0.4}
        ]
    }
}))]
pub struct EnvelopeBandsRequest {
    #[serde(flatten)]
    pub envelope: EnvelopeRequest,
    #[serde(flatten)]
    pub params: UncertaintyParams,
}

/// One cell of the banded envelope.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct EnvelopeCellBandOutput {
    pub wind_speed_m_s: f64,
    pub tether_length_m: f64,
    /// P(largest tension > breaking strength / required safety factor); null without a breaking strength.
    pub probability_tension_exceeded: Option<ProbabilityOutput>,
    /// P(unstable at the payout rate); null without `payout_rate_m_s`.
    pub probability_unstable: Option<ProbabilityOutput>,
    /// P(outside the envelope: any limit).
    pub probability_outside: ProbabilityOutput,
    /// Largest tension (N) across the samples.
    pub max_tension_n: PercentileBand,
}

/// The answer of `POST /api/v1/envelope/bands`.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct EnvelopeBandsResponse {
    /// The nominal envelope (the request's own values).
    pub envelope: EnvelopeResponse,
    /// Row by row as `envelope.points`: one row per wind speed.
    pub cells: Vec<EnvelopeCellBandOutput>,
    pub samples: usize,
    pub valid_samples: usize,
    pub rejected_samples: Vec<RejectedSamplesOutput>,
    pub seed: u64,
    pub inputs: Vec<UncertainInput>,
    pub confidence_level_nondim: f64,
    pub method: String,
}

const METHOD: &str = "Monte Carlo (sample i draws from its own counter-based stream of (seed, i)): each sample \
solves the whole envelope with its own tether, aerostat and air numbers (the same equilibrium solver and \
judgement as the nominal envelope). Probabilities with the Wilson 95 % interval; percentiles with the \
distribution-free order-statistic 95 % interval.";

/// A numeric input of the envelope that may be uncertain (the resolved
/// value: a preset's fills count as given).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EnvelopeField {
    NetBuoyancy,
    DragCoefficient,
    LiftCoefficient,
    ReferenceArea,
    MassPerLength,
    Diameter,
    NormalDragCoefficient,
    AxialStiffness,
    BreakingStrength,
    AirDensity,
    Gravity,
}

impl EnvelopeField {
    const ALL: [Self; 11] = [
        Self::NetBuoyancy,
        Self::DragCoefficient,
        Self::LiftCoefficient,
        Self::ReferenceArea,
        Self::MassPerLength,
        Self::Diameter,
        Self::NormalDragCoefficient,
        Self::AxialStiffness,
        Self::BreakingStrength,
        Self::AirDensity,
        Self::Gravity,
    ];

    fn set(self, p: &mut EquilibriumProblem, v: f64) {
        match self {
            Self::NetBuoyancy => p.body.net_buoyancy_n = v,
            Self::DragCoefficient => p.body.drag_coefficient = v,
            Self::LiftCoefficient => p.body.lift_coefficient = v,
            Self::ReferenceArea => p.body.reference_area_m2 = v,
            Self::MassPerLength => p.cable.mass_per_length_kg_m = v,
            Self::Diameter => p.cable.diameter_m = v,
            Self::NormalDragCoefficient => p.cable.normal_drag_coefficient = v,
            Self::AxialStiffness => p.cable.axial_stiffness_n = Some(v),
            Self::BreakingStrength => p.cable.breaking_strength_n = Some(v),
            Self::AirDensity => p.air_density_kg_m3 = v,
            Self::Gravity => p.gravity_m_s2 = v,
        }
    }

    /// Does the resolved problem have this number?
    fn present(self, p: &EquilibriumProblem) -> bool {
        match self {
            Self::AxialStiffness => p.cable.axial_stiffness_n.is_some(),
            Self::BreakingStrength => p.cable.breaking_strength_n.is_some(),
            _ => true,
        }
    }
}

impl UncertainField for EnvelopeField {
    fn path(self) -> &'static str {
        match self {
            Self::NetBuoyancy => "aerostat.net_buoyancy_n",
            Self::DragCoefficient => "aerostat.drag_coefficient_nondim",
            Self::LiftCoefficient => "aerostat.lift_coefficient_nondim",
            Self::ReferenceArea => "aerostat.reference_area_m2",
            Self::MassPerLength => "cable.mass_per_length_kg_m",
            Self::Diameter => "cable.diameter_m",
            Self::NormalDragCoefficient => "cable.normal_drag_coefficient_nondim",
            Self::AxialStiffness => "cable.axial_stiffness_n",
            Self::BreakingStrength => "cable.breaking_strength_n",
            Self::AirDensity => "wind.air_density_kg_m3",
            Self::Gravity => "gravity_m_s2",
        }
    }
    fn range(self) -> FieldRange {
        // The bounds of the equilibrium request's schema.
        match self {
            Self::NetBuoyancy => FieldRange::open_below(0.0, 1e8, "N"),
            Self::DragCoefficient => FieldRange::between(0.0, 10.0, ""),
            Self::LiftCoefficient => FieldRange::between(-10.0, 10.0, ""),
            Self::ReferenceArea => FieldRange::open_below(0.0, 1e5, "m²"),
            Self::MassPerLength => FieldRange::open_below(0.0, 1000.0, "kg/m"),
            Self::Diameter => FieldRange::open_below(0.0, 1.0, "m"),
            Self::NormalDragCoefficient => FieldRange::between(0.0, 10.0, ""),
            Self::AxialStiffness => FieldRange::open_below(0.0, 1e12, "N"),
            Self::BreakingStrength => FieldRange::open_below(0.0, 1e9, "N"),
            Self::AirDensity => FieldRange::open_below(0.0, 5.0, "kg/m³"),
            Self::Gravity => FieldRange::open_below(0.0, 100.0, "m/s²"),
        }
    }
}

/// Parses an envelope bands body: the envelope part exactly as
/// `POST /api/v1/envelope` parses it (unknown fields refused),
/// `uncertainty` on its own.
pub fn parse_envelope_bands(body: &[u8]) -> Result<EnvelopeBandsRequest, RequestError> {
    let (rest, params) = common::split_uncertainty(body)?;
    let envelope: EnvelopeRequest = parse_value(&rest)?;
    let params: UncertaintyParams = parse_value(&serde_json::Value::Object(params))?;
    Ok(EnvelopeBandsRequest { envelope, params })
}

/// The validated request, ready to run.
pub struct PreparedEnvelopeBands {
    fields: Vec<EnvelopeField>,
    ensemble: uncertainty::Ensemble,
}

/// Sample × cell equilibria of the request (for admission limits).
pub fn envelope_band_evaluations(req: &EnvelopeBandsRequest) -> usize {
    req.params
        .uncertainty
        .samples
        .saturating_mul(req.envelope.points())
}

/// Every check that needs no solve.
pub fn prepare_envelope_bands(
    req: &EnvelopeBandsRequest,
) -> Result<PreparedEnvelopeBands, RequestError> {
    let (problem, _) = req.envelope.problem()?;
    if req.envelope.uses_ge() {
        return Err(InvalidInput::new(
            "stability.method",
            "envelope bands judge stability by the string criterion only; quasi_static_ge is not supported here",
        )
        .into());
    }
    let u = &req.params.uncertainty;
    let ensemble = common::ensemble_of(u)?;
    let total = envelope_band_evaluations(req);
    if total > MAX_ENVELOPE_BAND_EVALUATIONS {
        return Err(InvalidInput::new(
            "uncertainty.samples",
            format!(
                "{} samples × {} cells = {total} equilibria; at most {MAX_ENVELOPE_BAND_EVALUATIONS} are allowed",
                u.samples,
                req.envelope.points()
            ),
        )
        .into());
    }
    let fields = common::resolve_fields(&u.inputs, &ensemble, |path| {
        let Some(f) = EnvelopeField::ALL.into_iter().find(|f| f.path() == path) else {
            return Err(format!(
                "`{path}` is not a numeric input of the envelope that can be uncertain: one of {}",
                EnvelopeField::ALL
                    .iter()
                    .map(|f| f.path())
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        };
        if !f.present(&problem.base) {
            return Err(format!(
                "`{path}` is not given in this request (nor by its preset): give it to make it uncertain"
            ));
        }
        Ok(f)
    })?;
    Ok(PreparedEnvelopeBands { fields, ensemble })
}

/// What one sample gives at one cell.
#[derive(Clone, Copy, Debug)]
struct CellValue {
    max_tension_n: f64,
    tension_exceeded: bool,
    unstable: bool,
    outside: bool,
}

/// Answers an envelope bands request. Progress counts the samples (the
/// nominal envelope comes first, cancellable).
pub fn envelope_bands(
    req: &EnvelopeBandsRequest,
    parallelism: Parallelism,
    progress: &dyn Progress,
) -> Result<EnvelopeBandsResponse, RequestError> {
    let prep = prepare_envelope_bands(req)?;
    let (problem, config) = req.envelope.problem()?;
    let nominal =
        crate::contract::envelope::envelope(&req.envelope, parallelism, &common::Silent(progress))?;
    if progress.cancelled() {
        return Err(RequestError::Cancelled);
    }
    let samples = 0..prep.ensemble.samples;
    let cells = sample_cells(&prep, &problem, &config, samples, parallelism, progress)?;
    let results = common::collect_samples(prep.fields.len(), cells)?;
    Ok(summarise(req, &prep, &problem, nominal, results))
}

/// Each sample of `range`: its envelope's cells, or the first field whose
/// draw is out of range.
fn sample_cells(
    prep: &PreparedEnvelopeBands,
    problem: &EnvelopeProblem,
    config: &EquilibriumConfig,
    range: std::ops::Range<usize>,
    parallelism: Parallelism,
    progress: &dyn Progress,
) -> Result<Vec<common::SampleOutcome<Vec<CellValue>>>, RequestError> {
    let required = problem.limits.required_safety_factor;
    let never = |_: usize, _: usize| {};
    let cancelled = || progress.cancelled();
    common::run_ensemble_range(
        &prep.ensemble,
        &prep.fields,
        range,
        parallelism,
        progress,
        |values| {
            let mut p = problem.clone();
            for (&f, &v) in prep.fields.iter().zip(values) {
                f.set(&mut p.base, v);
            }
            // Every draw is in its field's range; should the envelope's
            // own validation still refuse the sample, it is rejected.
            let env = match p.solve(config, Parallelism::Serial, &never, &cancelled) {
                Ok(Some(env)) => env,
                Ok(None) => return None,
                Err(e) => return Some(Err(common::culprit(&prep.fields, &e))),
            };
            Some(Ok(env
                .points
                .iter()
                .map(|pt| CellValue {
                    max_tension_n: pt.equilibrium.max_tension_n,
                    tension_exceeded: pt.equilibrium.safety_factor.is_some_and(|f| f < required),
                    unstable: pt.verdict.stable == Some(false),
                    outside: pt.verdict.limit.is_some(),
                })
                .collect::<Vec<_>>()))
        },
    )
}

/// One sample on the wire between a chunk and its job: per cell the
/// largest tension as its IEEE-754 bits and the three verdicts, so that
/// the answer put together from chunks is the single-process one exactly.
#[derive(Serialize, Deserialize)]
enum WireSample {
    Ok(Vec<(u64, bool, bool, bool)>),
    Rejected(usize),
}

/// The samples `range` of an envelope bands request as JSON text (one
/// chunk of a distributed job; the nominal envelope is left to the
/// assembly).
pub fn envelope_bands_chunk(
    req: &EnvelopeBandsRequest,
    range: std::ops::Range<usize>,
    parallelism: Parallelism,
    progress: &dyn Progress,
) -> Result<String, RequestError> {
    let prep = prepare_envelope_bands(req)?;
    let (problem, config) = req.envelope.problem()?;
    if progress.cancelled() {
        return Err(RequestError::Cancelled);
    }
    let cells = sample_cells(&prep, &problem, &config, range, parallelism, progress)?;
    let wire: Vec<WireSample> = cells
        .iter()
        .map(|r| match r {
            Ok(cells) => WireSample::Ok(
                cells
                    .iter()
                    .map(|c| {
                        (
                            c.max_tension_n.to_bits(),
                            c.tension_exceeded,
                            c.unstable,
                            c.outside,
                        )
                    })
                    .collect(),
            ),
            Err(k) => WireSample::Rejected(*k),
        })
        .collect();
    Ok(serde_json::to_string(&wire).expect("samples serialise"))
}

/// The envelope bands answer from its chunks ([`envelope_bands_chunk`] of
/// consecutive ranges covering every sample, in order) and the nominal
/// envelope, computed here.
pub fn envelope_bands_from_chunks(
    req: &EnvelopeBandsRequest,
    parts: &[String],
) -> Result<EnvelopeBandsResponse, RequestError> {
    let prep = prepare_envelope_bands(req)?;
    let (problem, _) = req.envelope.problem()?;
    let nominal = crate::contract::envelope::envelope(
        &req.envelope,
        Parallelism::Rayon,
        &crate::contract::error::NoProgress,
    )?;
    let cell_count = nominal.points.len();
    let mut cells = Vec::with_capacity(prep.ensemble.samples);
    for part in parts {
        let wire: Vec<WireSample> = serde_json::from_str(part).map_err(|e| {
            RequestError::Malformed(format!("a chunk of the envelope bands job: {e}"))
        })?;
        for w in wire {
            cells.push(match w {
                WireSample::Ok(values) if values.len() == cell_count => Ok(values
                    .into_iter()
                    .map(|(t, tension_exceeded, unstable, outside)| CellValue {
                        max_tension_n: f64::from_bits(t),
                        tension_exceeded,
                        unstable,
                        outside,
                    })
                    .collect()),
                WireSample::Rejected(k) if k < prep.fields.len() => Err(k),
                _ => {
                    return Err(RequestError::Malformed(format!(
                        "a chunk of the envelope bands job holds a sample that is neither {cell_count} cells nor a rejection on an input of the request"
                    )));
                }
            });
        }
    }
    if cells.len() != prep.ensemble.samples {
        return Err(RequestError::Malformed(format!(
            "the chunks of the envelope bands job hold {} samples, not {}",
            cells.len(),
            prep.ensemble.samples
        )));
    }
    let results = common::collect_samples(prep.fields.len(), cells)?;
    Ok(summarise(req, &prep, &problem, nominal, results))
}

/// The answer from the nominal envelope and every sample's cells.
fn summarise(
    req: &EnvelopeBandsRequest,
    prep: &PreparedEnvelopeBands,
    problem: &EnvelopeProblem,
    nominal: EnvelopeResponse,
    results: common::EnsembleResults<Vec<CellValue>>,
) -> EnvelopeBandsResponse {
    let valid = &results.valid;
    let n = valid.len();
    let rated = problem.base.cable.breaking_strength_n.is_some()
        || prep.fields.contains(&EnvelopeField::BreakingStrength);
    let judged_stability = problem.limits.payout_rate_m_s.is_some();
    let mut column = vec![0.0; n];
    let cells = nominal
        .points
        .iter()
        .enumerate()
        .map(|(j, pt)| {
            let count = |f: fn(&CellValue) -> bool| valid.iter().filter(|s| f(&s[j])).count();
            for (c, s) in column.iter_mut().zip(valid) {
                *c = s[j].max_tension_n;
            }
            EnvelopeCellBandOutput {
                wind_speed_m_s: pt.wind_speed_m_s,
                tether_length_m: pt.tether_length_m,
                probability_tension_exceeded: rated
                    .then(|| common::probability_output(count(|c| c.tension_exceeded), n)),
                probability_unstable: judged_stability
                    .then(|| common::probability_output(count(|c| c.unstable), n)),
                probability_outside: common::probability_output(count(|c| c.outside), n),
                max_tension_n: common::band_of(&mut column),
            }
        })
        .collect();
    let u = &req.params.uncertainty;
    EnvelopeBandsResponse {
        envelope: nominal,
        cells,
        samples: u.samples,
        valid_samples: n,
        rejected_samples: common::rejected_output(&prep.fields, &results.rejected),
        seed: u.seed,
        inputs: u.inputs.clone(),
        confidence_level_nondim: uncertainty::CONFIDENCE,
        method: METHOD.into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contract::error::NoProgress;
    use serde_json::{Value, json};

    fn body(extra: Value) -> Vec<u8> {
        let mut v = json!({
            "cable": {"preset": "dyneema", "diameter_m": 0.006},
            "aerostat": {"net_buoyancy_n": 2000.0, "mass_kg": 100.0, "drag_coefficient_nondim": 0.3,
                         "reference_area_m2": 20.0},
            "wind": {"flow": {"kind": "uniform", "speed_m_s": 0.0}},
            "wind_speeds_m_s": {"min": 0.0, "max": 10.0, "count": 3},
            "tether_lengths_m": {"min": 100.0, "max": 1000.0, "count": 3},
            "payout_rate_m_s": 5.0,
            "uncertainty": {"samples": 20, "seed": 3, "inputs": [
                {"field": "aerostat.net_buoyancy_n", "distribution": "normal", "mean": 2000.0, "std_dev": 100.0}
            ]}
        });
        for (k, x) in extra.as_object().unwrap() {
            v[k] = x.clone();
        }
        serde_json::to_vec(&v).unwrap()
    }

    fn field_of(b: Vec<u8>) -> String {
        let err = parse_envelope_bands(&b)
            .and_then(|r| prepare_envelope_bands(&r).map(drop))
            .expect_err("invalid");
        err.body().error.field.unwrap()
    }

    #[test]
    fn errors_name_their_field() {
        assert_eq!(field_of(body(json!({"rates_m_s": 1.0}))), "rates_m_s");
        assert_eq!(
            field_of(body(json!({"uncertainty": {"inputs": [
                {"field": "aerostat.mass_kg", "distribution": "normal", "mean": 1.0, "std_dev": 0.1}]}}))),
            "uncertainty.inputs[0].field"
        );
        assert_eq!(
            field_of(body(json!({"uncertainty": {"inputs": [
                {"field": "cable.diameter_m", "distribution": "normal", "mean": 0.006, "std_dev": 0.003}]}}))),
            "uncertainty.inputs[0]"
        );
        assert_eq!(
            field_of(body(
                json!({"uncertainty": {"seed": 9007199254740992_u64, "inputs": [
                {"field": "cable.diameter_m", "distribution": "normal", "mean": 0.006, "std_dev": 0.0001}]}})
            )),
            "uncertainty.seed"
        );
    }

    /// A zero-width input reproduces the nominal envelope's tensions and
    /// verdicts exactly.
    #[test]
    fn zero_width_reproduces_the_envelope() {
        let b = body(json!({"uncertainty": {"samples": 4, "inputs": [
            {"field": "aerostat.net_buoyancy_n", "distribution": "normal", "mean": 2000.0, "std_dev": 0.0}]}}));
        let r = envelope_bands(
            &parse_envelope_bands(&b).unwrap(),
            Parallelism::Serial,
            &NoProgress,
        )
        .unwrap();
        for (c, p) in r.cells.iter().zip(&r.envelope.points) {
            let t = p.max_tension_n;
            assert_eq!(
                (
                    c.max_tension_n.p05,
                    c.max_tension_n.p50,
                    c.max_tension_n.p95
                ),
                (t, t, t)
            );
            let outside = c.probability_outside.probability_nondim;
            assert_eq!(outside, if p.feasible { 0.0 } else { 1.0 });
            let unstable = c.probability_unstable.as_ref().unwrap().probability_nondim;
            assert_eq!(unstable, if p.stable == Some(false) { 1.0 } else { 0.0 });
        }
    }
}
