//! Percentiles of an ensemble with their sampling error, and exceedance
//! probabilities with theirs.
//!
//! **Point estimate.** For `n` sorted values `x₀ ≤ … ≤ x_{n−1}` the
//! `p`-quantile is Hyndman & Fan's type 7 (R's default, NumPy's `linear`):
//! `h = (n − 1)p`, `x_⌊h⌋ + (h − ⌊h⌋)(x_⌊h⌋₊₁ − x_⌊h⌋)`. Equal values give
//! that value exactly.
//!
//! **Sampling error: distribution-free order-statistic interval.** The
//! number `B` of draws below the true quantile `ξ_p` is Binomial(n, p), so
//! `P(X_(l) ≤ ξ_p ≤ X_(u)) ≥ P(l ≤ B ≤ u − 1)` (1-based order statistics).
//! With the exact binomial tails, `l` is the largest with `P(B ≤ l − 1) ≤ α/2`
//! and `u` the smallest with `P(B ≥ u) ≤ α/2`: coverage at least `1 − α` for
//! any continuous distribution, with no normality assumption (David &
//! Nagaraja, *Order Statistics*, §7.1). When `n` is too small for a tail
//! (e.g. fewer than 72 samples for the 5 % point at 95 %), that end is
//! `None`: the error is unbounded and said so. The reported *error* is the
//! larger distance from the estimate to an end of the interval.
//!
//! **Probabilities.** `k` events in `n` draws: `p̂ = k/n`, standard error
//! `√(p̂(1 − p̂)/n)`, and the Wilson score interval (which stays inside
//! `[0, 1]` and is not degenerate at `k = 0` or `k = n`).

/// Two-sided normal quantile of a confidence level (`Φ⁻¹(1 − α/2)`).
pub fn two_sided_z(confidence: f64) -> f64 {
    crate::numerics::uncertainty::sampling::inverse_normal_cdf(0.5 + 0.5 * confidence)
}

/// One percentile of a sample with its confidence interval.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quantile {
    /// Probability level `p ∈ (0, 1)`.
    pub level: f64,
    /// Type-7 estimate.
    pub value: f64,
    /// Lower end of the order-statistic interval; `None` when `n` is too
    /// small for it.
    pub low: Option<f64>,
    /// Upper end; `None` when `n` is too small.
    pub high: Option<f64>,
}

impl Quantile {
    /// Sampling error: the larger distance from the estimate to an end of
    /// the interval; `None` when an end is missing or not finite.
    pub fn error(&self) -> Option<f64> {
        let (lo, hi) = (self.low?, self.high?);
        let e = (self.value - lo).max(hi - self.value);
        e.is_finite().then_some(e)
    }
}

/// 0-based indices of the order statistics bounding the `level`-quantile of
/// `n` draws with the given `confidence` (`None`: that end does not exist).
pub fn order_statistic_interval(
    n: usize,
    level: f64,
    confidence: f64,
) -> (Option<usize>, Option<usize>) {
    if n == 0 {
        return (None, None);
    }
    let alpha_half = 0.5 * (1.0 - confidence);
    let pmf = binomial_pmf(n, level);
    // lower: the largest l (1-based) with P(B ≤ l − 1) ≤ α/2
    let mut lower = None;
    let mut cdf = 0.0;
    for (k, &pk) in pmf.iter().enumerate().take(n) {
        cdf += pk;
        // cdf = P(B ≤ k): l = k + 1 qualifies
        if cdf <= alpha_half {
            lower = Some(k); // 0-based index of X_(k+1)
        } else {
            break;
        }
    }
    // upper: the smallest u (1-based) with P(B ≥ u) ≤ α/2
    let mut upper = None;
    let mut tail = 0.0;
    for k in (1..=n).rev() {
        tail += pmf[k];
        // tail = P(B ≥ k): u = k qualifies
        if tail <= alpha_half {
            upper = Some(k - 1); // 0-based index of X_(k)
        } else {
            break;
        }
    }
    (lower, upper)
}

/// `P(B = k)`, `k = 0..=n`, for `B ~ Binomial(n, p)` (log-space recursion:
/// no underflow trouble at large `n`).
pub fn binomial_pmf(n: usize, p: f64) -> Vec<f64> {
    let (lp, lq) = (p.ln(), (-p).ln_1p());
    let mut log = n as f64 * lq;
    let mut out = Vec::with_capacity(n + 1);
    out.push(log.exp());
    for k in 0..n {
        log += ((n - k) as f64 / (k + 1) as f64).ln() + lp - lq;
        out.push(log.exp());
    }
    out
}

/// Type-7 quantile of sorted values.
pub fn type7(sorted: &[f64], level: f64) -> f64 {
    let n = sorted.len();
    if n == 0 {
        return f64::NAN;
    }
    let h = (n - 1) as f64 * level;
    let i = (h.floor() as usize).min(n - 1);
    let (a, b) = (sorted[i], sorted[(i + 1).min(n - 1)]);
    if a == b {
        return a;
    }
    a + (h - i as f64) * (b - a)
}

/// Percentiles of `values` (sorted in place by `f64::total_cmp`) with
/// their order-statistic intervals; `intervals[j]` from
/// [`order_statistic_interval`] for `levels[j]` and `values.len()`.
pub fn quantiles(
    values: &mut [f64],
    levels: &[f64],
    intervals: &[(Option<usize>, Option<usize>)],
) -> Vec<Quantile> {
    values.sort_unstable_by(f64::total_cmp);
    levels
        .iter()
        .zip(intervals)
        .map(|(&level, &(lo, hi))| Quantile {
            level,
            value: type7(values, level),
            low: lo.map(|i| values[i]),
            high: hi.map(|i| values[i]),
        })
        .collect()
}

/// Mean and sample standard deviation, summed in the given order about
/// the first value (shifted data: exact when every value is the same, and
/// no cancellation when the spread is small against the mean).
pub fn mean_std(values: &[f64]) -> (f64, f64) {
    let n = values.len();
    if n == 0 {
        return (f64::NAN, f64::NAN);
    }
    let shift = values[0];
    if !shift.is_finite() {
        let mean = values.iter().sum::<f64>() / n as f64;
        return (mean, f64::NAN);
    }
    let d_mean = values.iter().map(|x| x - shift).sum::<f64>() / n as f64;
    let mean = shift + d_mean;
    if n == 1 {
        return (mean, 0.0);
    }
    let var = values
        .iter()
        .map(|x| (x - shift - d_mean).powi(2))
        .sum::<f64>()
        / (n - 1) as f64;
    (mean, var.sqrt())
}

/// An estimated probability with its sampling error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Probability {
    /// Events counted.
    pub events: usize,
    /// Draws.
    pub draws: usize,
    /// `events / draws`.
    pub value: f64,
    /// `√(p̂(1 − p̂)/n)`.
    pub standard_error: f64,
    /// Wilson score interval at the confidence level.
    pub low: f64,
    pub high: f64,
}

/// `k` events in `n` draws with the Wilson interval at `confidence`.
pub fn probability(events: usize, draws: usize, confidence: f64) -> Probability {
    if draws == 0 {
        return Probability {
            events,
            draws,
            value: f64::NAN,
            standard_error: f64::NAN,
            low: 0.0,
            high: 1.0,
        };
    }
    let n = draws as f64;
    let p = events as f64 / n;
    let z = two_sided_z(confidence);
    let z2 = z * z;
    let denom = 1.0 + z2 / n;
    let centre = (p + z2 / (2.0 * n)) / denom;
    let half = z / denom * (p * (1.0 - p) / n + z2 / (4.0 * n * n)).sqrt();
    Probability {
        events,
        draws,
        value: p,
        standard_error: (p * (1.0 - p) / n).sqrt(),
        low: if events == 0 {
            0.0
        } else {
            (centre - half).max(0.0)
        },
        high: if events == draws {
            1.0
        } else {
            (centre + half).min(1.0)
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::uncertainty::sampling::{inverse_normal_cdf, uniform01};

    #[test]
    fn binomial_pmf_sums_to_one_and_matches_a_small_case() {
        let pmf = binomial_pmf(4, 0.5);
        for (k, want) in [1.0, 4.0, 6.0, 4.0, 1.0].iter().enumerate() {
            assert!((pmf[k] - want / 16.0).abs() < 1e-15);
        }
        let big = binomial_pmf(100_000, 0.05);
        assert!((big.iter().sum::<f64>() - 1.0).abs() < 1e-9);
    }

    #[test]
    fn type7_matches_numpy_linear() {
        // numpy.percentile([1, 2, 3, 4, 10], [5, 50, 95]) = [1.2, 3.0, 8.8]
        let x = [1.0, 2.0, 3.0, 4.0, 10.0];
        assert!((type7(&x, 0.05) - 1.2).abs() < 1e-12);
        assert_eq!(type7(&x, 0.5), 3.0);
        assert!((type7(&x, 0.95) - 8.8).abs() < 1e-12);
        assert_eq!(type7(&[5.0; 7], 0.95), 5.0);
    }

    #[test]
    fn small_samples_have_no_tail_bound() {
        // 0.95^n > 0.025 for n < 72: no lower bound on the 5 % point
        assert_eq!(order_statistic_interval(71, 0.05, 0.95).0, None);
        assert!(order_statistic_interval(72, 0.05, 0.95).0.is_some());
        assert_eq!(order_statistic_interval(71, 0.95, 0.95).1, None);
        assert!(order_statistic_interval(72, 0.95, 0.95).1.is_some());
    }

    /// The interval covers the true quantile of a uniform in at least 95 %
    /// of 2000 independent ensembles of 500 (binomial sd of the count ≈ 10,
    /// so 1880 is 6 sd below the nominal 1900).
    #[test]
    fn order_statistic_intervals_cover_at_the_stated_level() {
        let (n, reps) = (500usize, 2000u64);
        for level in [0.05, 0.5, 0.95] {
            let iv = order_statistic_interval(n, level, 0.95);
            let mut covered = 0;
            for r in 0..reps {
                let mut xs: Vec<f64> = (0..n as u64).map(|i| uniform01(r, i, 9)).collect();
                let q = quantiles(&mut xs, &[level], &[iv])[0];
                if q.low.unwrap() <= level && level <= q.high.unwrap() {
                    covered += 1;
                }
            }
            assert!(
                covered >= 1880,
                "level {level}: covered {covered} of {reps}"
            );
            // and the interval is not wildly conservative
            assert!(
                covered <= 1980,
                "level {level}: covered {covered} of {reps}"
            );
        }
    }

    /// The half-width agrees with the asymptotic standard error of a
    /// quantile, z·√(p(1−p)/n)/f(ξ_p), for a large normal sample.
    #[test]
    fn interval_width_matches_the_asymptotic_standard_error() {
        let n = 20_000usize;
        let mut xs: Vec<f64> = (0..n as u64)
            .map(|i| inverse_normal_cdf(uniform01(3, i, 0)))
            .collect();
        let level = 0.05;
        let q = quantiles(
            &mut xs,
            &[level],
            &[order_statistic_interval(n, level, 0.95)],
        )[0];
        let xi = inverse_normal_cdf(level);
        let density = (-0.5 * xi * xi).exp() / (2.0 * std::f64::consts::PI).sqrt();
        let asymptotic = 1.959964 * (level * (1.0 - level) / n as f64).sqrt() / density;
        let half = 0.5 * (q.high.unwrap() - q.low.unwrap());
        assert!(
            (half / asymptotic - 1.0).abs() < 0.15,
            "half-width {half}, asymptotic {asymptotic}"
        );
    }

    #[test]
    fn mean_of_equal_values_is_exact() {
        let x = [1304.2932925304171; 100];
        assert_eq!(mean_std(&x), (1304.2932925304171, 0.0));
        let (m, s) = mean_std(&[1.0, 2.0, 3.0, 4.0]);
        assert_eq!(m, 2.5);
        assert!((s - (5.0f64 / 3.0).sqrt()).abs() < 1e-15);
    }

    #[test]
    fn wilson_interval_is_proper_at_the_ends() {
        let p = probability(0, 1000, 0.95);
        assert_eq!(p.value, 0.0);
        assert_eq!(p.low, 0.0);
        // rule of three: about 3/n at 95 %
        assert!(p.high > 0.0019 && p.high < 0.004, "{}", p.high);
        let p = probability(500, 1000, 0.95);
        assert!((p.high - p.low - 2.0 * 1.959964 * (0.25f64 / 1000.0).sqrt()).abs() < 1e-3);
    }
}
