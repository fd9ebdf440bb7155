//! Parses, validates and runs a bands request.
//!
//! Each sample copies the request's system numbers, overwrites the
//! uncertain fields with the sample's draws, and evaluates every rate of
//! the chart exactly as `POST /api/v1/charts` does for that system (same
//! mesh, same critical-length search), so a zero-width distribution gives
//! the chart's own numbers bit for bit.
//!
//! Out-of-range draws: a distribution that puts more than
//! [`MAX_OUT_OF_RANGE`] of its mass outside its field's physical range
//! (e.g. a normal net buoyancy reaching 0) is refused up front (422 naming
//! `uncertainty.inputs[i]`): that is a mis-specified input, not an answer.
//! Below that, the rare invalid draws are counted per field
//! (`rejected_samples`) and left out; percentiles and probabilities are
//! over the valid samples (conditional on a physical draw).

use std::sync::Arc;

use serde_json::{Map, Value};

use crate::contract::bands::common::{
    FieldRange, UncertainField, check_distribution, culprit, distribution, percentile_band,
};
pub use crate::contract::bands::common::{MAX_OUT_OF_RANGE, MAX_SEED};
use crate::contract::bands::dto::*;
use crate::contract::system::GridInput;
use crate::contract::system::grid::BandsRateGridInput;
use crate::contract::system::input::SystemInput;
use crate::contract::{Progress, RequestError, parse_value};
use crate::numerics::parallel::Parallelism;
use crate::numerics::params::{AerostatSystem, InvalidInput, ranges, require_positive};
use crate::numerics::string::StringModel;
use crate::numerics::string::chart::{self, Discretisation};
use crate::numerics::string::critical::Onset;
use crate::numerics::string::operators::StringOperators;
use crate::numerics::uncertainty::{self, Ensemble, Summariser};

/// Most rates of one banded chart.
pub const MAX_BAND_RATES: usize = BandsRateGridInput::BOUNDS.max_count;
/// Most chart points (samples × rates) of one bands request (a job).
pub const MAX_BAND_EVALUATIONS: usize = 2_000_000;
/// The keys of the parameters; every other top-level key belongs to the
/// system.
const PARAM_KEYS: [&str; 3] = ["rates_m_s", "uncertainty", "target_elevation_m"];

/// A numeric field of the system that may be uncertain.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SystemField {
    NetBuoyancy,
    AerostatMass,
    MassPerLength,
    Density,
    Area,
    InitialLength,
    Gravity,
}

impl SystemField {
    pub const ALL: [Self; 7] = [
        Self::NetBuoyancy,
        Self::AerostatMass,
        Self::MassPerLength,
        Self::Density,
        Self::Area,
        Self::InitialLength,
        Self::Gravity,
    ];

    /// The request path.
    pub fn path(self) -> &'static str {
        match self {
            Self::NetBuoyancy => "aerostat.net_buoyancy_n",
            Self::AerostatMass => "aerostat.mass_kg",
            Self::MassPerLength => "cable.mass_per_length_kg_m",
            Self::Density => "cable.density_kg_m3",
            Self::Area => "cable.area_m2",
            Self::InitialLength => "initial_length_m",
            Self::Gravity => "gravity_m_s2",
        }
    }

    pub fn from_path(path: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|f| f.path() == path)
    }

    /// The validated range of the field (the system's own validation).
    pub(crate) fn valid_range(self) -> FieldRange {
        FieldRange::closed(match self {
            Self::NetBuoyancy => ranges::NET_BUOYANCY_N,
            Self::AerostatMass => ranges::AEROSTAT_MASS_KG,
            Self::MassPerLength => ranges::MASS_PER_LENGTH_KG_M,
            Self::Density => ranges::DENSITY_KG_M3,
            Self::Area => ranges::AREA_M2,
            Self::InitialLength => ranges::INITIAL_LENGTH_M,
            Self::Gravity => ranges::GRAVITY_M_S2,
        })
    }
}

impl UncertainField for SystemField {
    fn path(self) -> &'static str {
        SystemField::path(self)
    }
    fn range(self) -> FieldRange {
        self.valid_range()
    }
}

/// The system's numbers as the request gives them.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RawSystem {
    mass_per_length: Option<f64>,
    density: Option<f64>,
    area: Option<f64>,
    net_buoyancy: f64,
    mass: f64,
    initial_length: f64,
    gravity: f64,
}

impl RawSystem {
    pub(crate) fn of(s: &SystemInput) -> Self {
        let c = &s.cable;
        // A preset's mass per length counts as given.
        let from_preset =
            (c.mass_per_length_kg_m.is_none() && c.density_kg_m3.is_none() && c.area_m2.is_none())
                .then(|| c.mass_per_length().ok())
                .flatten();
        Self {
            mass_per_length: c.mass_per_length_kg_m.or(from_preset),
            density: c.density_kg_m3,
            area: c.area_m2,
            net_buoyancy: s.aerostat.net_buoyancy("aerostat").unwrap_or(f64::NAN),
            mass: s.aerostat.mass("aerostat").unwrap_or(f64::NAN),
            initial_length: s.initial_length_m,
            gravity: s.gravity_m_s2,
        }
    }

    pub(crate) fn has(&self, f: SystemField) -> bool {
        match f {
            SystemField::MassPerLength => self.mass_per_length.is_some(),
            SystemField::Density => self.density.is_some(),
            SystemField::Area => self.area.is_some(),
            _ => true,
        }
    }

    pub(crate) fn set(&mut self, f: SystemField, v: f64) {
        match f {
            SystemField::NetBuoyancy => self.net_buoyancy = v,
            SystemField::AerostatMass => self.mass = v,
            SystemField::MassPerLength => self.mass_per_length = Some(v),
            SystemField::Density => self.density = Some(v),
            SystemField::Area => self.area = Some(v),
            SystemField::InitialLength => self.initial_length = v,
            SystemField::Gravity => self.gravity = v,
        }
    }

    /// The validated system (the same arithmetic as `SystemInput::system`).
    pub(crate) fn system(&self) -> Result<AerostatSystem, InvalidInput> {
        let rho_a = match (self.mass_per_length, self.density, self.area) {
            (Some(m), _, _) => m,
            (None, Some(rho), Some(a)) => rho * a,
            _ => f64::NAN,
        };
        AerostatSystem::new(
            rho_a,
            self.net_buoyancy,
            self.mass,
            self.initial_length,
            self.gravity,
        )
    }
}

/// A validated bands request, ready to run.
pub struct Prepared {
    base: RawSystem,
    nominal: AerostatSystem,
    fields: Vec<SystemField>,
    ensemble: Ensemble,
    rates: Vec<f64>,
    target: Option<f64>,
    discretisation: Discretisation,
}

/// Chart points of the request: samples × rates (for admission limits).
pub fn evaluations(req: &BandsRequest) -> usize {
    req.params
        .rates_m_s
        .count()
        .saturating_mul(req.params.uncertainty.samples)
}

/// Every check that needs no solve.
pub fn prepare(req: &BandsRequest) -> Result<Prepared, RequestError> {
    let model = req.system.model()?;
    let discretisation = req.system.discretisation()?;
    let nominal = model.system;
    let base = RawSystem::of(&req.system);
    let p = &req.params;
    // The chart grid's range (a far slower rate has no finite t*), at most
    // MAX_BAND_RATES rates, a list or {min, max, count} alike.
    let grid = &p.rates_m_s;
    let count = grid.count();
    if count == 0 || count > MAX_BAND_RATES {
        return Err(InvalidInput::new(
            grid.count_field("rates_m_s"),
            match &grid.0 {
                GridInput::List(_) => format!("must list 1 to {MAX_BAND_RATES} rates, got {count}"),
                GridInput::Range(_) => {
                    format!("must be between 1 and {MAX_BAND_RATES}, got {count}")
                }
            },
        )
        .into());
    }
    if let GridInput::Range(g) = &grid.0 {
        ranges::POSITIVE_RATE_M_S.check("rates_m_s.min", g.min)?;
        ranges::POSITIVE_RATE_M_S.check("rates_m_s.max", g.max)?;
    }
    let rates = grid.rates("rates_m_s")?;
    let target = p
        .target_elevation_m
        .map(|t| require_positive("target_elevation_m", t))
        .transpose()?;
    let u = &p.uncertainty;
    if u.seed > MAX_SEED {
        return Err(InvalidInput::new(
            "uncertainty.seed",
            format!("must be at most {MAX_SEED} (2^53 − 1), got {}", u.seed),
        )
        .into());
    }
    let ensemble = Ensemble::new(
        "uncertainty",
        u.samples,
        u.seed,
        u.inputs.iter().map(distribution).collect(),
    )?;
    let total = u.samples.saturating_mul(rates.len());
    if total > MAX_BAND_EVALUATIONS {
        return Err(InvalidInput::new(
            "uncertainty.samples",
            format!(
                "{} samples × {} rates = {total} chart points; at most {MAX_BAND_EVALUATIONS} are allowed",
                u.samples,
                rates.len()
            ),
        )
        .into());
    }
    let mut fields: Vec<SystemField> = Vec::with_capacity(u.inputs.len());
    for (i, input) in u.inputs.iter().enumerate() {
        let at = format!("uncertainty.inputs[{i}]");
        let path = input.field();
        let Some(f) = SystemField::from_path(path) else {
            let known: Vec<&str> = SystemField::ALL.iter().map(|f| f.path()).collect();
            return Err(InvalidInput::new(
                format!("{at}.field"),
                format!(
                    "`{path}` is not a numeric field of the system that can be uncertain: one of {}",
                    known.join(", ")
                ),
            )
            .into());
        };
        if !base.has(f) {
            return Err(InvalidInput::new(
                format!("{at}.field"),
                format!(
                    "`{path}` is not given in this request (the cable is given as {}): make one of those uncertain",
                    if base.mass_per_length.is_some() {
                        "cable.mass_per_length_kg_m"
                    } else {
                        "cable.density_kg_m3 and cable.area_m2"
                    }
                ),
            )
            .into());
        }
        if let Some(j) = fields.iter().position(|&g| g == f) {
            return Err(InvalidInput::new(
                format!("{at}.field"),
                format!("`{path}` is already uncertain in uncertainty.inputs[{j}]"),
            )
            .into());
        }
        check_distribution(&at, path, f.range(), &ensemble.inputs[i])?;
        fields.push(f);
    }
    Ok(Prepared {
        base,
        nominal,
        fields,
        ensemble,
        rates,
        target,
        discretisation,
    })
}

/// `h*`, `t*` of one chart point, their discretisation errors (converged
/// points), and whether it is unstable at once.
#[derive(Clone, Copy, Debug, PartialEq)]
struct PointValue {
    elevation_m: f64,
    time_s: f64,
    elevation_error_m: f64,
    time_error_s: f64,
    immediate: bool,
}

/// The chart of one system at the request's rates, as `/charts` computes
/// it: converged (graded meshes, safe side of the error bound) when
/// `model.elements` is omitted, else that uniform mesh.
struct ChartEvaluator {
    discretisation: Discretisation,
    operators: Option<Arc<StringOperators>>,
}

impl ChartEvaluator {
    fn new(discretisation: Discretisation) -> Self {
        let operators = match discretisation {
            Discretisation::Elements(n) => Some(Arc::new(StringOperators::new(n))),
            Discretisation::Converged { .. } => None,
        };
        Self {
            discretisation,
            operators,
        }
    }

    fn chart(&self, sys: AerostatSystem, rates: &[f64]) -> Vec<PointValue> {
        let model = self
            .operators
            .as_ref()
            .map(|ops| StringModel::with_operators(sys, ops.clone()));
        rates
            .iter()
            .map(|&v| {
                let p = match (&model, self.discretisation) {
                    (Some(m), _) => chart::chart_point(m, v),
                    (None, Discretisation::Converged { relative_tolerance }) => {
                        chart::converged_chart_point(&sys, v, relative_tolerance)
                    }
                    (None, Discretisation::Elements(_)) => unreachable!("operators are built"),
                };
                PointValue {
                    elevation_m: p.max_elevation_m,
                    time_s: p.critical_time_s,
                    elevation_error_m: p.max_elevation_error_m,
                    time_error_s: p.critical_time_error_s,
                    immediate: matches!(p.onset, Onset::Immediate(_)),
                }
            })
            .collect()
    }
}

/// The banded chart. `progress` counts samples; cancellation is checked
/// before every sample.
pub fn bands(
    req: &BandsRequest,
    parallelism: Parallelism,
    progress: &dyn Progress,
) -> Result<BandsResponse, RequestError> {
    let prep = prepare(req)?;
    if progress.cancelled() {
        return Err(RequestError::Cancelled);
    }
    let results = sample_results(&prep, 0..prep.ensemble.samples, parallelism, progress)?;
    summarise(req, &prep, results)
}

/// Ok(points) or Err(index of the first input whose draw is out of range).
type SampleResult = Result<Vec<PointValue>, usize>;

/// The chart of each sample of `range`, in sample order.
fn sample_results(
    prep: &Prepared,
    range: std::ops::Range<usize>,
    parallelism: Parallelism,
    progress: &dyn Progress,
) -> Result<Vec<SampleResult>, RequestError> {
    let evaluator = ChartEvaluator::new(prep.discretisation);
    prep.ensemble
        .run_range(
            range,
            parallelism,
            &|done, total| progress.report(done, total),
            &|| progress.cancelled(),
            |values| {
                let mut raw = prep.base;
                for (k, (&f, &v)) in prep.fields.iter().zip(values).enumerate() {
                    if !f.in_range(v) {
                        return Err(k);
                    }
                    raw.set(f, v);
                }
                // Each draw is in its field's range, but a combination
                // (ρ·A) may still fall outside: a rejected sample.
                match raw.system() {
                    Ok(sys) => Ok(evaluator.chart(sys, &prep.rates)),
                    Err(e) => Err(culprit(&prep.fields, &e)),
                }
            },
        )
        .ok_or(RequestError::Cancelled)
}

/// The samples `range` of a bands request as JSON text (one chunk of a
/// distributed job; the numbers as their IEEE-754 bits, so that the
/// answer put together from chunks is the single-process one exactly).
pub fn bands_chunk(
    req: &BandsRequest,
    range: std::ops::Range<usize>,
    parallelism: Parallelism,
    progress: &dyn Progress,
) -> Result<String, RequestError> {
    let prep = prepare(req)?;
    let results = sample_results(&prep, range, parallelism, progress)?;
    let wire: Vec<WireSample> = results
        .iter()
        .map(|r| match r {
            Ok(points) => WireSample::Ok(
                points
                    .iter()
                    .map(|p| {
                        (
                            p.elevation_m.to_bits(),
                            p.time_s.to_bits(),
                            p.elevation_error_m.to_bits(),
                            p.time_error_s.to_bits(),
                            p.immediate,
                        )
                    })
                    .collect(),
            ),
            Err(k) => WireSample::Rejected(*k),
        })
        .collect();
    Ok(serde_json::to_string(&wire).expect("samples serialise"))
}

/// The bands answer from its chunks ([`bands_chunk`] of consecutive
/// ranges covering every sample, in order).
pub fn bands_from_chunks(
    req: &BandsRequest,
    parts: &[String],
) -> Result<BandsResponse, RequestError> {
    let prep = prepare(req)?;
    let mut results = Vec::with_capacity(prep.ensemble.samples);
    for part in parts {
        let wire: Vec<WireSample> = serde_json::from_str(part)
            .map_err(|e| RequestError::Malformed(format!("a chunk of the bands job: {e}")))?;
        results.extend(wire.into_iter().map(|w| {
            match w {
                WireSample::Ok(points) => Ok(points
                    .into_iter()
                    .map(|(h, t, he, te, immediate)| PointValue {
                        elevation_m: f64::from_bits(h),
                        time_s: f64::from_bits(t),
                        elevation_error_m: f64::from_bits(he),
                        time_error_s: f64::from_bits(te),
                        immediate,
                    })
                    .collect()),
                WireSample::Rejected(k) => Err(k),
            }
        }));
    }
    if results.len() != prep.ensemble.samples {
        return Err(RequestError::Malformed(format!(
            "the chunks of the bands job hold {} samples, not {}",
            results.len(),
            prep.ensemble.samples
        )));
    }
    summarise(req, &prep, results)
}

/// One sample on the wire between a chunk and its job.
#[derive(serde::Serialize, serde::Deserialize)]
enum WireSample {
    Ok(Vec<(u64, u64, u64, u64, bool)>),
    Rejected(usize),
}

/// The answer from every sample's chart, in sample order.
fn summarise(
    req: &BandsRequest,
    prep: &Prepared,
    results: Vec<SampleResult>,
) -> Result<BandsResponse, RequestError> {
    let evaluator = ChartEvaluator::new(prep.discretisation);
    let converged = matches!(prep.discretisation, Discretisation::Converged { .. });
    let nominal = evaluator.chart(prep.nominal, &prep.rates);
    let valid: Vec<&Vec<PointValue>> = results.iter().filter_map(|r| r.as_ref().ok()).collect();
    let mut rejected = vec![0usize; prep.fields.len()];
    for r in &results {
        if let Err(k) = r {
            rejected[*k] += 1;
        }
    }
    let n = valid.len();
    if n == 0 {
        return Err(InvalidInput::new(
            "uncertainty.inputs",
            "every sample drew a value outside its field's physical range",
        )
        .into());
    }
    let summariser = Summariser::new(n);
    let mut column = vec![0.0; n];
    let points = prep
        .rates
        .iter()
        .enumerate()
        .map(|(j, &rate)| {
            for (c, s) in column.iter_mut().zip(&valid) {
                *c = s[j].elevation_m;
            }
            let unsafe_samples = prep
                .target
                .map(|t| column.iter().filter(|&&h| h < t).count());
            let elevation = percentile_band(summariser.band(&mut column));
            for (c, s) in column.iter_mut().zip(&valid) {
                *c = s[j].time_s;
            }
            let time = percentile_band(summariser.band(&mut column));
            BandPointOutput {
                rate_m_s: rate,
                max_elevation_m: elevation,
                critical_time_s: time,
                nominal_max_elevation_m: nominal[j].elevation_m,
                nominal_critical_time_s: nominal[j].time_s,
                immediate_samples: valid.iter().filter(|s| s[j].immediate).count(),
                max_elevation_error_m: converged.then(|| {
                    valid
                        .iter()
                        .map(|s| s[j].elevation_error_m)
                        .fold(0.0, f64::max)
                }),
                critical_time_error_s: converged
                    .then(|| valid.iter().map(|s| s[j].time_error_s).fold(0.0, f64::max)),
                probability_unsafe: unsafe_samples.map(|k| {
                    let p = uncertainty::percentiles::probability(k, n, uncertainty::CONFIDENCE);
                    UnsafeProbabilityOutput {
                        probability_nondim: p.value,
                        standard_error_nondim: p.standard_error,
                        low_nondim: p.low,
                        high_nondim: p.high,
                        unsafe_samples: k,
                    }
                }),
            }
        })
        .collect();
    Ok(BandsResponse {
        points,
        samples: prep.ensemble.samples,
        valid_samples: n,
        rejected_samples: prep
            .fields
            .iter()
            .zip(&rejected)
            .filter(|(_, c)| **c > 0)
            .map(|(f, &count)| RejectedSamplesOutput {
                field: f.path().into(),
                count,
                reason: format!("{} {}", f.path(), f.range_words()),
            })
            .collect(),
        seed: prep.ensemble.seed,
        inputs: req.params.uncertainty.inputs.clone(),
        target_elevation_m: prep.target,
        confidence_level_nondim: uncertainty::CONFIDENCE,
        method: "monte_carlo".into(),
        elements: crate::contract::run::chart_elements(prep.discretisation),
        converged,
    })
}

/// Parses a bands body: the system part and the parameters separately (so
/// every error names its field), unknown fields refused in both.
pub fn parse_bands(body: &[u8]) -> Result<BandsRequest, RequestError> {
    let value: Value =
        serde_json::from_slice(body).map_err(|e| RequestError::Malformed(e.to_string()))?;
    let Value::Object(obj) = value else {
        return Err(InvalidInput::new("body", "must be a JSON object").into());
    };
    let (mut system_part, mut params_part) = (Map::new(), Map::new());
    for (k, v) in obj {
        if PARAM_KEYS.contains(&k.as_str()) {
            params_part.insert(k, v);
        } else {
            system_part.insert(k, v);
        }
    }
    let system_value = Value::Object(system_part);
    let system: SystemInput = parse_value(&system_value)?;
    let known = serde_json::to_value(&system).expect("the system serialises");
    reject_unknown(&system_value, &known, "")?;
    if let Some(rates) = params_part.get("rates_m_s") {
        parse_value::<BandsRateGridInput>(rates).map_err(|e| under("rates_m_s", e))?;
    }
    let params: BandsParams = parse_value(&Value::Object(params_part))?;
    Ok(BandsRequest { system, params })
}

/// Prefixes the field of an error from a sub-parse.
fn under(prefix: &str, e: RequestError) -> RequestError {
    match e {
        RequestError::Invalid(InvalidInput { field, reason }) => {
            let field = if field == "body" {
                prefix.to_string()
            } else if field.starts_with('[') {
                format!("{prefix}{field}")
            } else {
                format!("{prefix}.{field}")
            };
            RequestError::Invalid(InvalidInput { field, reason })
        }
        other => other,
    }
}

/// Refuses keys of `given` that the parsed value `known` does not have
/// (serde ignores them in the system part, which has no
/// `deny_unknown_fields` because other requests flatten it).
fn reject_unknown(given: &Value, known: &Value, prefix: &str) -> Result<(), InvalidInput> {
    if let (Value::Object(g), Value::Object(k)) = (given, known) {
        for (key, v) in g {
            let path = if prefix.is_empty() {
                key.clone()
            } else {
                format!("{prefix}.{key}")
            };
            match k.get(key) {
                None => {
                    return Err(InvalidInput::new(
                        path,
                        format!(
                            "unknown field `{key}`{}",
                            if prefix.is_empty() {
                                format!(
                                    ": a bands request has the system fields ({}) and {}",
                                    k.keys().map(String::as_str).collect::<Vec<_>>().join(", "),
                                    PARAM_KEYS.join(", ")
                                )
                            } else {
                                format!(
                                    ": expected one of {}",
                                    k.keys().map(String::as_str).collect::<Vec<_>>().join(", ")
                                )
                            }
                        ),
                    ));
                }
                Some(kv) => reject_unknown(v, kv, &path)?,
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests;
