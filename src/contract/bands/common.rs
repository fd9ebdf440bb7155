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
use crate::contract::bands::run::{MAX_OUT_OF_RANGE, MAX_SEED, distribution};
use crate::contract::{Progress, RequestError};
use crate::numerics::chart::Parallelism;
use crate::numerics::params::InvalidInput;
use crate::numerics::uncertainty::{self, Distribution, Ensemble};

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

/// A numeric field of a request that may be uncertain.
pub trait UncertainField: Copy + Send + Sync + PartialEq {
    /// The request path (`aerostat.net_buoyancy_n`).
    fn path(self) -> &'static str;
    /// Is a drawn value physical?
    fn in_range(self, v: f64) -> bool;
    /// The range in words (`must be greater than zero`).
    fn range_words(self) -> &'static str;
    /// Probability mass of `d` outside the range.
    fn mass_outside(self, d: &Distribution) -> f64;
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
        let outside = f.mass_outside(&ensemble.inputs[i]);
        if outside > MAX_OUT_OF_RANGE {
            return Err(InvalidInput::new(
                at,
                format!(
                    "puts {:.2} % of its draws outside the range of {path} ({}); at most {} % may fall outside: narrow it, or use a lognormal",
                    100.0 * outside,
                    f.range_words(),
                    100.0 * MAX_OUT_OF_RANGE
                ),
            )
            .into());
        }
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
/// field). `eval` returning `None` means cancelled.
pub fn run_ensemble<F: UncertainField, T: Send>(
    ensemble: &Ensemble,
    fields: &[F],
    parallelism: Parallelism,
    progress: &dyn Progress,
    eval: impl Fn(&[f64]) -> Option<T> + Sync,
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
    eval: impl Fn(&[f64]) -> Option<T> + Sync,
) -> Result<Vec<SampleOutcome<T>>, RequestError> {
    let results: Vec<Result<Option<T>, usize>> = ensemble
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
            Ok(Some(t)) => Ok(Ok(t)),
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
    crate::contract::bands::run::percentile_band(
        uncertainty::Summariser::new(values.len()).band(values),
    )
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

/// A field that must be `> 0` (or `≥ 0` with `zero_allowed`): the mass of
/// `d` outside.
pub fn mass_below_zero(d: &Distribution) -> f64 {
    d.cdf(0.0)
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
