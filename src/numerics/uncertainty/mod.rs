//! Uncertainty bands (SPEC §8): seeded Monte Carlo over uncertain inputs,
//! percentiles with their sampling error, exceedance probabilities.
//!
//! The layer knows nothing of charts, plans or envelopes: an [`Ensemble`]
//! (sample count, seed, one [`Distribution`] per uncertain input) draws
//! the values of sample `i` from its own counter-based stream
//! ([`sampling::uniform01`]), hands them to the caller's `eval`, and
//! returns the results **indexed by sample**. Because a sample's values
//! depend only on `(seed, i)` and the results are collected in sample
//! order, the ensemble is bit-identical whether it runs serially, on any
//! number of rayon threads, or split by sample range over several workers.
//! [`Summariser`] then turns one output's column into 5/50/95 % points
//! with distribution-free confidence intervals ([`percentiles`]).
//!
//! Monte Carlo, not quasi-Monte Carlo: the error of every percentile is
//! stated from order statistics, which needs independent draws.

pub mod percentiles;
pub mod sampling;

use std::sync::atomic::{AtomicUsize, Ordering};

use rayon::prelude::*;

pub use percentiles::{Probability, Quantile};
pub use sampling::Distribution;

use crate::numerics::parallel::Parallelism;
use crate::numerics::params::InvalidInput;

/// Most samples of one ensemble.
pub const MAX_SAMPLES: usize = 100_000;
/// Most uncertain inputs of one ensemble.
pub const MAX_INPUTS: usize = 16;
/// Confidence level of every interval.
pub const CONFIDENCE: f64 = 0.95;
/// The percentile levels of a band: 5, 50 and 95 %.
pub const LEVELS: [f64; 3] = [0.05, 0.5, 0.95];

/// A seeded Monte Carlo ensemble.
#[derive(Clone, Debug, PartialEq)]
pub struct Ensemble {
    pub samples: usize,
    pub seed: u64,
    pub inputs: Vec<Distribution>,
}

impl Ensemble {
    /// Checks the sample count and every distribution (fields named from
    /// `prefix`, e.g. `uncertainty`).
    pub fn new(
        prefix: &str,
        samples: usize,
        seed: u64,
        inputs: Vec<Distribution>,
    ) -> Result<Self, InvalidInput> {
        if samples == 0 || samples > MAX_SAMPLES {
            return Err(InvalidInput::new(
                format!("{prefix}.samples"),
                format!("must be between 1 and {MAX_SAMPLES}, got {samples}"),
            ));
        }
        if inputs.is_empty() || inputs.len() > MAX_INPUTS {
            return Err(InvalidInput::new(
                format!("{prefix}.inputs"),
                format!(
                    "must list 1 to {MAX_INPUTS} uncertain inputs, got {}",
                    inputs.len()
                ),
            ));
        }
        for (i, d) in inputs.iter().enumerate() {
            d.validate(&format!("{prefix}.inputs[{i}]"))?;
        }
        Ok(Self {
            samples,
            seed,
            inputs,
        })
    }

    /// The input values of sample `i`.
    pub fn values(&self, sample: usize) -> Vec<f64> {
        let mut v = Vec::with_capacity(self.inputs.len());
        sampling::draw(self.seed, sample as u64, &self.inputs, &mut v);
        v
    }

    /// Evaluates `eval(values)` for every sample; the results in sample
    /// order (the same at any thread count). `progress(done, total)` is
    /// called as samples finish; once `cancelled()` the remaining samples
    /// are skipped and the answer is `None`.
    pub fn run<T: Send>(
        &self,
        parallelism: Parallelism,
        progress: &(dyn Fn(usize, usize) + Sync),
        cancelled: &(dyn Fn() -> bool + Sync),
        eval: impl Fn(&[f64]) -> T + Sync,
    ) -> Option<Vec<T>> {
        self.run_range(0..self.samples, parallelism, progress, cancelled, eval)
    }

    /// [`Ensemble::run`] over the samples `range` only (one chunk of a
    /// distributed job): sample `i` draws the same values whatever the
    /// range, so the chunks put together are the whole run.
    pub fn run_range<T: Send>(
        &self,
        range: std::ops::Range<usize>,
        parallelism: Parallelism,
        progress: &(dyn Fn(usize, usize) + Sync),
        cancelled: &(dyn Fn() -> bool + Sync),
        eval: impl Fn(&[f64]) -> T + Sync,
    ) -> Option<Vec<T>> {
        let range = range.start.min(self.samples)..range.end.min(self.samples);
        let total = range.len();
        let done = AtomicUsize::new(0);
        let one = |i: usize| -> Option<T> {
            if cancelled() {
                return None;
            }
            let out = eval(&self.values(i));
            progress(done.fetch_add(1, Ordering::Relaxed) + 1, total);
            Some(out)
        };
        let out: Vec<Option<T>> = match parallelism {
            Parallelism::Serial => range.map(one).collect(),
            Parallelism::Rayon => range.into_par_iter().map(one).collect(),
        };
        out.into_iter().collect()
    }
}

/// 5/50/95 % points of one output with their intervals, its mean and
/// standard deviation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Band {
    pub quantiles: [Quantile; 3],
    pub mean: f64,
    pub std_dev: f64,
    /// Values summarised.
    pub count: usize,
}

/// Summarises columns of `n` values: the order-statistic indices of
/// [`LEVELS`] are computed once.
pub struct Summariser {
    n: usize,
    intervals: [(Option<usize>, Option<usize>); 3],
}

impl Summariser {
    pub fn new(n: usize) -> Self {
        Self {
            n,
            intervals: LEVELS.map(|p| percentiles::order_statistic_interval(n, p, CONFIDENCE)),
        }
    }

    /// The band of `values` (`values.len()` must be the `n` given; sorted
    /// in place). The mean is summed in the order given.
    pub fn band(&self, values: &mut [f64]) -> Band {
        debug_assert_eq!(values.len(), self.n);
        let (mean, std_dev) = percentiles::mean_std(values);
        let q = percentiles::quantiles(values, &LEVELS, &self.intervals);
        Band {
            quantiles: [q[0], q[1], q[2]],
            mean,
            std_dev,
            count: values.len(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ensemble() -> Ensemble {
        Ensemble::new(
            "uncertainty",
            3000,
            42,
            vec![
                Distribution::Normal {
                    mean: 1.0,
                    std_dev: 0.1,
                },
                Distribution::Uniform {
                    low: 2.0,
                    high: 3.0,
                },
            ],
        )
        .unwrap()
    }

    #[test]
    fn serial_and_parallel_runs_agree_bit_for_bit() {
        let e = ensemble();
        let f = |v: &[f64]| (v[0] * v[1]).sin();
        let serial = e
            .run(Parallelism::Serial, &|_, _| {}, &|| false, f)
            .unwrap();
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let par = pool
                .install(|| e.run(Parallelism::Rayon, &|_, _| {}, &|| false, f))
                .unwrap();
            assert_eq!(
                serial.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                par.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
            );
        }
    }

    #[test]
    fn cancelled_runs_give_nothing() {
        assert!(
            ensemble()
                .run(Parallelism::Rayon, &|_, _| {}, &|| true, |v| v[0])
                .is_none()
        );
    }

    #[test]
    fn bad_ensembles_name_the_field() {
        let e = Ensemble::new(
            "u",
            0,
            1,
            vec![Distribution::Uniform {
                low: 0.0,
                high: 1.0,
            }],
        );
        assert_eq!(e.unwrap_err().field, "u.samples");
        let e = Ensemble::new(
            "u",
            10,
            1,
            vec![Distribution::Normal {
                mean: 1.0,
                std_dev: -1.0,
            }],
        );
        assert_eq!(e.unwrap_err().field, "u.inputs[0].std_dev");
        let e = Ensemble::new(
            "u",
            10,
            1,
            vec![Distribution::Uniform {
                low: 1.0,
                high: 0.0,
            }],
        );
        assert_eq!(e.unwrap_err().field, "u.inputs[0].high");
    }

    /// The 5/50/95 % points of a normal input land on μ + σΦ⁻¹(p) within
    /// their stated intervals.
    #[test]
    fn band_of_a_normal_input_covers_its_true_percentiles() {
        let e = ensemble();
        let mut xs = e
            .run(Parallelism::Serial, &|_, _| {}, &|| false, |v| v[0])
            .unwrap();
        let band = Summariser::new(xs.len()).band(&mut xs);
        for q in band.quantiles {
            let truth = 1.0 + 0.1 * sampling::inverse_normal_cdf(q.level);
            assert!(
                q.low.unwrap() <= truth && truth <= q.high.unwrap(),
                "{q:?} vs {truth}"
            );
            assert!(q.error().unwrap() < 0.02);
        }
        assert!((band.mean - 1.0).abs() < 4.0 * 0.1 / (3000f64).sqrt());
    }
}
