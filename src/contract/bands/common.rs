//! What the plan and envelope bands share with the chart bands: the
//! `uncertainty` parameter (ensemble, seed, distributions), uncertain
//! fields resolved against a table of the request's numeric fields, the
//! ensemble run with out-of-range draws counted and left out, and the
//! outputs (percentile bands, probabilities with their Wilson interval).

use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};
use utoipa::ToSchema;

use crate::contract::bands::dto::{
    PercentileBand, RejectedSamplesOutput, UncertainInput, UncertaintyInput,
};
use crate::contract::{Progress, RequestError};
use crate::numerics::parallel::Parallelism;
use crate::numerics::params::{InvalidInput, Range, compact};
use crate::numerics::uncertainty::{self, Distribution, Ensemble};

/// Largest fraction of a distribution allowed outside its field's range.
pub const MAX_OUT_OF_RANGE: f64 = 0.01;
/// Largest seed (2^53 − 1: exact in every JSON reader).
pub const MAX_SEED: u64 = (1 << 53) - 1;

/// The `uncertainty` parameter of a plan or envelope bands request.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct UncertaintyParams {
    /// The uncertain inputs and the sampling.
    pub uncertainty: UncertaintyInput,
}

/// A probability estimated from the samples, with its sampling error.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct ProbabilityOutput {
    /// Fraction of the valid samples in which the event happens.
    pub probability_nondim: f64,
    /// Its standard error `√(p(1 − p)/n)`.
    pub standard_error_nondim: f64,
    /// Wilson score 95 % interval (proper at 0 and 1 events).
    pub low_nondim: f64,
    pub high_nondim: f64,
    /// Samples in which it happens.
    pub event_samples: usize,
}

/// `k` events in `n` valid samples.
pub fn probability_output(events: usize, n: usize) -> ProbabilityOutput {
    let p = uncertainty::percentiles::probability(events, n, uncertainty::CONFIDENCE);
    ProbabilityOutput {
        probability_nondim: p.value,
        standard_error_nondim: p.standard_error,
        low_nondim: p.low,
        high_nondim: p.high,
        event_samples: events,
    }
}

/// The physical range of an uncertain field: a drawn value outside it is
/// a rejected sample; a distribution whose parameters lie outside it, or
/// with more than [`MAX_OUT_OF_RANGE`] of its mass outside it, is refused.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FieldRange {
    pub min: f64,
    /// `> min` rather than `≥ min`.
    pub min_open: bool,
    pub max: f64,
    pub unit: &'static str,
}

impl FieldRange {
    /// `[min, max]` of a validated range.
    pub const fn closed(r: Range) -> Self {
        Self {
            min: r.min,
            min_open: false,
            max: r.max,
            unit: r.unit,
        }
    }

    /// `(min, max]`.
    pub const fn open_below(min: f64, max: f64, unit: &'static str) -> Self {
        Self {
            min,
            min_open: true,
            max,
            unit,
        }
    }

    /// `[min, max]`.
    pub const fn between(min: f64, max: f64, unit: &'static str) -> Self {
        Self {
            min,
            min_open: false,
            max,
            unit,
        }
    }

    /// Is `v` in the range (finite)?
    pub fn contains(&self, v: f64) -> bool {
        v.is_finite()
            && (if self.min_open {
                v > self.min
            } else {
                v >= self.min
            })
            && v <= self.max
    }

    /// The range in words (`must be greater than 0 and at most 1e7 N`).
    pub fn words(&self) -> String {
        let unit = if self.unit.is_empty() {
            String::new()
        } else {
            format!(" {}", self.unit)
        };
        format!(
            "must be {} {} and at most {}{unit}",
            if self.min_open {
                "greater than"
            } else {
                "at least"
            },
            compact(self.min),
            compact(self.max)
        )
    }

    /// Probability mass of `d` outside the range (NaN-free: 1 when the
    /// distribution's numbers overflow).
    pub fn mass_outside(&self, d: &Distribution) -> f64 {
        let below = if self.min_open {
            d.cdf(self.min)
        } else {
            d.cdf(self.min.next_down())
        };
        let outside = below + (1.0 - d.cdf(self.max));
        if outside.is_finite() {
            outside.clamp(0.0, 1.0)
        } else {
            1.0
        }
    }
}

/// A numeric field of a request that may be uncertain.
pub trait UncertainField: Copy + Send + Sync + PartialEq {
    /// The request path (`aerostat.net_buoyancy_n`).
    fn path(self) -> &'static str;
    /// The physical range of a drawn value.
    fn range(self) -> FieldRange;
    /// Is a drawn value physical?
    fn in_range(self, v: f64) -> bool {
        self.range().contains(v)
    }
    /// The range in words (`must be greater than 0 and at most 1e7 N`).
    fn range_words(self) -> String {
        self.range().words()
    }
    /// Probability mass of `d` outside the range.
    fn mass_outside(self, d: &Distribution) -> f64 {
        self.range().mass_outside(d)
    }
}

/// Refuses a distribution of `path` whose own numbers (mean, low, high)
/// lie outside `range`, naming the parameter (`uncertainty.inputs[0].mean`),
/// or that puts more than [`MAX_OUT_OF_RANGE`] of its mass outside it.
pub fn check_distribution(
    at: &str,
    path: &str,
    range: FieldRange,
    d: &Distribution,
) -> Result<(), RequestError> {
    let params: Vec<(&str, f64)> = match *d {
        Distribution::Normal { mean, .. } | Distribution::Lognormal { mean, .. } => {
            vec![("mean", mean)]
        }
        Distribution::Uniform { low, high } => vec![("low", low), ("high", high)],
    };
    for (name, v) in params {
        if !range.contains(v) {
            return Err(InvalidInput::new(
                format!("{at}.{name}"),
                format!(
                    "must lie in the range of {path} ({}), got {}",
                    range.words(),
                    compact(v)
                ),
            )
            .into());
        }
    }
    let outside = range.mass_outside(d);
    if !(outside <= MAX_OUT_OF_RANGE) {
        return Err(InvalidInput::new(
            at,
            format!(
                "puts {:.2} % of its draws outside the range of {path} ({}); at most {} % may fall outside: narrow it, or use a lognormal",
                100.0 * outside,
                range.words(),
                100.0 * MAX_OUT_OF_RANGE
            ),
        )
        .into());
    }
    Ok(())
}

/// The field a failed draw counts against: the uncertain field the
/// validation error names, else the first uncertain field.
pub fn culprit<F: UncertainField>(fields: &[F], error: &InvalidInput) -> usize {
    fields
        .iter()
        .position(|f| f.path() == error.field)
        .unwrap_or(0)
}

/// The ensemble of `uncertainty` (sample count, seed, distributions).
pub fn ensemble_of(u: &UncertaintyInput) -> Result<Ensemble, RequestError> {
    if u.seed > MAX_SEED {
        return Err(InvalidInput::new(
            "uncertainty.seed",
            format!("must be at most {MAX_SEED} (2^53 − 1), got {}", u.seed),
        )
        .into());
    }
    Ok(Ensemble::new(
        "uncertainty",
        u.samples,
        u.seed,
        u.inputs.iter().map(distribution).collect(),
    )?)
}

/// Resolves each input's `field` with `lookup` (`Err(why)` names what is
/// accepted), refusing duplicates and distributions with more than
/// [`MAX_OUT_OF_RANGE`] of their mass outside the field's range.
pub fn resolve_fields<F: UncertainField>(
    inputs: &[UncertainInput],
    ensemble: &Ensemble,
    lookup: impl Fn(&str) -> Result<F, String>,
) -> Result<Vec<F>, RequestError> {
    let mut fields: Vec<F> = Vec::with_capacity(inputs.len());
    for (i, input) in inputs.iter().enumerate() {
        let at = format!("uncertainty.inputs[{i}]");
        let path = input.field();
        let f = lookup(path).map_err(|why| InvalidInput::new(format!("{at}.field"), why))?;
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
    Ok(fields)
}

/// The results of an ensemble: the valid samples' outputs in sample order
/// and the count of samples left out per field.
pub struct EnsembleResults<T> {
    pub valid: Vec<T>,
    pub rejected: Vec<usize>,
}

/// Runs `eval(values)` for every sample whose draws are all in range (a
/// sample with an out-of-range draw is counted against its first such
/// field). `eval` returning `None` means cancelled, `Some(Err(k))` a
/// sample whose combination of draws is invalid (counted against field
/// `k`: a failed draw is an outcome, never a panic).
pub fn run_ensemble<F: UncertainField, T: Send>(
    ensemble: &Ensemble,
    fields: &[F],
    parallelism: Parallelism,
    progress: &dyn Progress,
    eval: impl Fn(&[f64]) -> Option<SampleOutcome<T>> + Sync,
) -> Result<EnsembleResults<T>, RequestError> {
    let results = run_ensemble_range(
        ensemble,
        fields,
        0..ensemble.samples,
        parallelism,
        progress,
        eval,
    )?;
    collect_samples(fields.len(), results)
}

/// One sample's outcome: its output, or the index of the first field
/// whose draw is out of range.
pub type SampleOutcome<T> = Result<T, usize>;

/// [`run_ensemble`] over the samples `range` only (one chunk of a
/// distributed job): each sample's outcome, in sample order, uncounted.
pub fn run_ensemble_range<F: UncertainField, T: Send>(
    ensemble: &Ensemble,
    fields: &[F],
    range: std::ops::Range<usize>,
    parallelism: Parallelism,
    progress: &dyn Progress,
    eval: impl Fn(&[f64]) -> Option<SampleOutcome<T>> + Sync,
) -> Result<Vec<SampleOutcome<T>>, RequestError> {
    let results: Vec<Result<Option<SampleOutcome<T>>, usize>> = ensemble
        .run_range(
            range,
            parallelism,
            &|done, total| progress.report(done, total),
            &|| progress.cancelled(),
            |values| {
                for (k, (&f, &v)) in fields.iter().zip(values).enumerate() {
                    if !f.in_range(v) {
                        return Err(k);
                    }
                }
                Ok(eval(values))
            },
        )
        .ok_or(RequestError::Cancelled)?;
    results
        .into_iter()
        .map(|r| match r {
            Ok(Some(t)) => Ok(t),
            Ok(None) => Err(RequestError::Cancelled),
            Err(k) => Ok(Err(k)),
        })
        .collect()
}

/// The valid outputs (in sample order) and the rejected counts per field
/// from every sample's outcome; an error when no sample is valid.
pub fn collect_samples<T>(
    fields: usize,
    results: Vec<SampleOutcome<T>>,
) -> Result<EnsembleResults<T>, RequestError> {
    let mut rejected = vec![0usize; fields];
    let mut valid = Vec::with_capacity(results.len());
    for r in results {
        match r {
            Ok(t) => valid.push(t),
            Err(k) => rejected[k] += 1,
        }
    }
    if valid.is_empty() {
        return Err(InvalidInput::new(
            "uncertainty.inputs",
            "every sample drew a value outside its field's physical range",
        )
        .into());
    }
    Ok(EnsembleResults { valid, rejected })
}

/// The `rejected_samples` output.
pub fn rejected_output<F: UncertainField>(
    fields: &[F],
    rejected: &[usize],
) -> Vec<RejectedSamplesOutput> {
    fields
        .iter()
        .zip(rejected)
        .filter(|(_, c)| **c > 0)
        .map(|(f, &count)| RejectedSamplesOutput {
            field: f.path().into(),
            count,
            reason: format!("{} {}", f.path(), f.range_words()),
        })
        .collect()
}

/// The 5/50/95 % band of `values` (sorted in place).
pub fn band_of(values: &mut [f64]) -> PercentileBand {
    percentile_band(uncertainty::Summariser::new(values.len()).band(values))
}

/// Splits a JSON body into the request part and the `uncertainty` part.
pub fn split_uncertainty(body: &[u8]) -> Result<(Value, Map<String, Value>), RequestError> {
    let value: Value =
        serde_json::from_slice(body).map_err(|e| RequestError::Malformed(e.to_string()))?;
    let Value::Object(mut obj) = value else {
        return Err(InvalidInput::new("body", "must be a JSON object").into());
    };
    let mut params = Map::new();
    if let Some(u) = obj.remove("uncertainty") {
        params.insert("uncertainty".into(), u);
    }
    Ok((Value::Object(obj), params))
}

/// Progress that reports nothing but passes cancellation on (the nominal
/// answer before the samples, whose count is the progress).
pub struct Silent<'a>(pub &'a dyn Progress);

impl Progress for Silent<'_> {
    fn report(&self, _: usize, _: usize) {}
    fn cancelled(&self) -> bool {
        self.0.cancelled()
    }
}

/// The sampling distribution of an uncertain input.
pub(crate) fn distribution(input: &UncertainInput) -> Distribution {
    match *input {
        UncertainInput::Normal { mean, std_dev, .. } => Distribution::Normal { mean, std_dev },
        UncertainInput::Uniform { low, high, .. } => Distribution::Uniform { low, high },
        UncertainInput::Lognormal { mean, std_dev, .. } => {
            Distribution::Lognormal { mean, std_dev }
        }
    }
}

/// The 5/50/95 % band of a quantity with each percentile's sampling error.
pub(crate) fn percentile_band(b: uncertainty::Band) -> PercentileBand {
    let [q05, q50, q95] = b.quantiles;
    PercentileBand {
        p05: q05.value,
        p50: q50.value,
        p95: q95.value,
        p05_error: q05.error(),
        p50_error: q50.error(),
        p95_error: q95.error(),
        p05_low: q05.low,
        p05_high: q05.high,
        p50_low: q50.low,
        p50_high: q50.high,
        p95_low: q95.low,
        p95_high: q95.high,
        mean: b.mean,
        std_dev: b.std_dev,
    }
}
