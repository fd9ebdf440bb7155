//! Reproducible random draws for Monte Carlo ensembles.
//!
//! **Streams.** A draw is a pure function of `(seed, sample, dimension)`:
//! `u = U(splitmix64(splitmix64(splitmix64(seed) ⊕ sample) ⊕ dimension))`
//! mapped to the open interval `(0, 1)` with 53 random bits. The SplitMix64
//! finaliser (Steele, Lea & Flood 2014, the generator of Java's
//! `SplittableRandom`) is a bijection of `u64` with full avalanche, so every
//! sample has its own stream and no draw depends on which thread computed
//! it or in what order: an ensemble is bit-identical at any thread count
//! and on any number of machines that split the sample range.
//!
//! **Distributions** turn one uniform into one value by the inverse CDF
//! (one dimension per uncertain input, so a quasi-random point set could
//! replace the uniforms later without touching the callers):
//! * `Normal { mean, std_dev }`: `mean + std_dev·Φ⁻¹(u)` (Wichura's AS241,
//!   relative accuracy about 1e-16);
//! * `Uniform { low, high }`: `low + (high − low)·u`;
//! * `Lognormal { mean, std_dev }` — **the mean and standard deviation of
//!   the variable itself** (as a datasheet gives them), not of its log:
//!   `σ² = ln(1 + (s/m)²)`, `μ = ln m − σ²/2`, `x = exp(μ + σ Φ⁻¹(u))`.
//!
//! A zero-width distribution (`std_dev = 0`, `low = high`) returns its
//! centre exactly (no rounding through `exp`/`ln`), so an ensemble of it
//! reproduces the deterministic answer bit for bit.

use crate::numerics::params::{
    InvalidInput, require_finite, require_non_negative, require_positive,
};

/// One step of SplitMix64: a bijective mix of a 64-bit word.
#[inline]
pub fn splitmix64(z: u64) -> u64 {
    let mut z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The uniform draw `u ∈ (0, 1)` of `sample` in `dimension` for `seed`.
#[inline]
pub fn uniform01(seed: u64, sample: u64, dimension: u64) -> f64 {
    let bits = splitmix64(splitmix64(splitmix64(seed) ^ sample) ^ dimension);
    // 53 bits, centred in their cell: never 0, never 1.
    ((bits >> 11) as f64 + 0.5) * (1.0 / (1u64 << 53) as f64)
}

/// A distribution of one uncertain input.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Distribution {
    Normal {
        mean: f64,
        std_dev: f64,
    },
    Uniform {
        low: f64,
        high: f64,
    },
    /// Mean and standard deviation of the variable (not of its log).
    Lognormal {
        mean: f64,
        std_dev: f64,
    },
}

impl Distribution {
    /// Checks the parameters; `field` prefixes the names in the error
    /// (`uncertainty.inputs[0]`).
    pub fn validate(&self, field: &str) -> Result<(), InvalidInput> {
        match *self {
            Self::Normal { mean, std_dev } => {
                require_finite(&format!("{field}.mean"), mean)?;
                require_non_negative(&format!("{field}.std_dev"), std_dev)?;
            }
            Self::Uniform { low, high } => {
                require_finite(&format!("{field}.low"), low)?;
                require_finite(&format!("{field}.high"), high)?;
                if high < low {
                    return Err(InvalidInput::new(
                        format!("{field}.high"),
                        format!("must be at least low = {low}, got {high}"),
                    ));
                }
            }
            Self::Lognormal { mean, std_dev } => {
                require_positive(&format!("{field}.mean"), mean)?;
                require_non_negative(&format!("{field}.std_dev"), std_dev)?;
            }
        }
        Ok(())
    }

    /// The value at probability level `u ∈ (0, 1)` (the inverse CDF).
    pub fn quantile(&self, u: f64) -> f64 {
        match *self {
            Self::Normal { mean, std_dev } => {
                if std_dev == 0.0 {
                    mean
                } else {
                    mean + std_dev * inverse_normal_cdf(u)
                }
            }
            Self::Uniform { low, high } => {
                if high == low {
                    low
                } else {
                    low + (high - low) * u
                }
            }
            Self::Lognormal { mean, std_dev } => {
                if std_dev == 0.0 {
                    mean
                } else {
                    let (mu, sigma) = lognormal_log_parameters(mean, std_dev);
                    (mu + sigma * inverse_normal_cdf(u)).exp()
                }
            }
        }
    }

    /// Mean of the distribution.
    pub fn mean(&self) -> f64 {
        match *self {
            Self::Normal { mean, .. } | Self::Lognormal { mean, .. } => mean,
            Self::Uniform { low, high } => 0.5 * (low + high),
        }
    }

    /// Standard deviation of the distribution.
    pub fn std_dev(&self) -> f64 {
        match *self {
            Self::Normal { std_dev, .. } | Self::Lognormal { std_dev, .. } => std_dev,
            Self::Uniform { low, high } => (high - low) / 12f64.sqrt(),
        }
    }

    /// Probability of a draw `≤ x` (absolute error below 1.2e-7).
    pub fn cdf(&self, x: f64) -> f64 {
        match *self {
            Self::Normal { mean, std_dev } => {
                if std_dev == 0.0 {
                    if x >= mean { 1.0 } else { 0.0 }
                } else {
                    normal_cdf((x - mean) / std_dev)
                }
            }
            Self::Uniform { low, high } => {
                if x < low {
                    0.0
                } else if x >= high {
                    1.0
                } else {
                    (x - low) / (high - low)
                }
            }
            Self::Lognormal { mean, std_dev } => {
                if x <= 0.0 {
                    0.0
                } else if std_dev == 0.0 {
                    if x >= mean { 1.0 } else { 0.0 }
                } else {
                    let (mu, sigma) = lognormal_log_parameters(mean, std_dev);
                    normal_cdf((x.ln() - mu) / sigma)
                }
            }
        }
    }
}

/// `(μ, σ)` of `ln X` for a lognormal `X` of mean `m` and std. dev. `s`.
pub fn lognormal_log_parameters(mean: f64, std_dev: f64) -> (f64, f64) {
    let var_log = (std_dev / mean).powi(2).ln_1p();
    (mean.ln() - 0.5 * var_log, var_log.sqrt())
}

/// The values of every input for one sample: input `d` uses dimension `d`.
pub fn draw(seed: u64, sample: u64, inputs: &[Distribution], out: &mut Vec<f64>) {
    out.clear();
    out.extend(
        inputs
            .iter()
            .enumerate()
            .map(|(d, dist)| dist.quantile(uniform01(seed, sample, d as u64))),
    );
}

/// Standard normal CDF `Φ(x)` via [`erfc`] (absolute error below 1.2e-7):
/// used to say how much of a distribution lies outside the physical range,
/// never to draw samples.
pub fn normal_cdf(x: f64) -> f64 {
    0.5 * erfc(-x / std::f64::consts::SQRT_2)
}

/// Complementary error function (Numerical Recipes' Chebyshev fit,
/// fractional error below 1.2e-7 everywhere): good enough for the
/// out-of-range fractions it serves.
fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let ans = t
        * (-z * z - 1.265_512_23
            + t * (1.000_023_68
                + t * (0.374_091_96
                    + t * (0.096_784_18
                        + t * (-0.186_288_06
                            + t * (0.278_868_07
                                + t * (-1.135_203_98
                                    + t * (1.488_515_87
                                        + t * (-0.822_152_23 + t * 0.170_872_77)))))))))
            .exp();
    if x >= 0.0 { ans } else { 2.0 - ans }
}

/// Inverse standard normal CDF `Φ⁻¹(p)`, `p ∈ (0, 1)` (Wichura 1988,
/// algorithm AS241 `PPND16`, relative accuracy about 1e-16).
pub fn inverse_normal_cdf(p: f64) -> f64 {
    if p <= 0.0 {
        return f64::NEG_INFINITY;
    }
    if p >= 1.0 {
        return f64::INFINITY;
    }
    let q = p - 0.5;
    if q.abs() <= 0.425 {
        let r = 0.180625 - q * q;
        return q
            * (((((((r * 2509.0809287301226727 + 33430.575583588128105) * r
                + 67265.770927008700853)
                * r
                + 45921.953931549871457)
                * r
                + 13731.693765509461125)
                * r
                + 1971.5909503065514427)
                * r
                + 133.14166789178437745)
                * r
                + 3.387132872796366608)
            / (((((((r * 5226.495278852545925 + 28729.085735721942674) * r
                + 39307.89580009271061)
                * r
                + 21213.794301586595867)
                * r
                + 5394.1960214247511077)
                * r
                + 687.1870074920579083)
                * r
                + 42.313330701600911252)
                * r
                + 1.0);
    }
    let mut r = if q < 0.0 { p } else { 1.0 - p };
    r = (-r.ln()).sqrt();
    let val = if r <= 5.0 {
        r -= 1.6;
        (((((((r * 7.7454501427834140764e-4 + 0.0227238449892691845833) * r
            + 0.24178072517745061177)
            * r
            + 1.27045825245236838258)
            * r
            + 3.64784832476320460504)
            * r
            + 5.7694972214606914055)
            * r
            + 4.6303378461565452959)
            * r
            + 1.42343711074968357734)
            / (((((((r * 1.05075007164441684324e-9 + 5.475938084995344946e-4) * r
                + 0.0151986665636164571966)
                * r
                + 0.14810397642748007459)
                * r
                + 0.68976733498510000455)
                * r
                + 1.6763848301838038494)
                * r
                + 2.05319162663775882187)
                * r
                + 1.0)
    } else {
        r -= 5.0;
        (((((((r * 2.01033439929228813265e-7 + 2.71155556874348757815e-5) * r
            + 0.0012426609473880784386)
            * r
            + 0.026532189526576123093)
            * r
            + 0.29656057182850489123)
            * r
            + 1.7848265399172913358)
            * r
            + 5.4637849111641143699)
            * r
            + 6.6579046435011037772)
            / (((((((r * 2.04426310338993978564e-15 + 1.4215117583164458887e-7) * r
                + 1.8463183175100546818e-5)
                * r
                + 7.868691311456132591e-4)
                * r
                + 0.0148753612908506148525)
                * r
                + 0.13692988092273580531)
                * r
                + 0.59983220655588793769)
                * r
                + 1.0)
    };
    if q < 0.0 { -val } else { val }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_normal_matches_published_quantiles() {
        // Values of Φ⁻¹ to 16 digits (tables / mpmath).
        for (p, z) in [
            (0.5, 0.0),
            (0.975, 1.959963984540054),
            (0.95, 1.6448536269514722),
            (0.841344746068543, 1.0),
            (0.999, 3.090232306167813),
            (1e-10, -6.361340902404056),
            (0.025, -1.959963984540054),
        ] {
            let got = inverse_normal_cdf(p);
            assert!(
                (got - z).abs() <= 1e-13 * z.abs().max(1.0),
                "Φ⁻¹({p}) = {got}, want {z}"
            );
        }
    }

    #[test]
    fn inverse_normal_inverts_the_cdf_and_is_odd() {
        for i in 1..200 {
            let p = i as f64 / 200.0;
            let z = inverse_normal_cdf(p);
            assert!((normal_cdf(z) - p).abs() < 2e-7, "p = {p}");
            // 1 − p is exact here (p = i/200 has few bits); the two branches agree
            assert!((z + inverse_normal_cdf(1.0 - p)).abs() <= 1e-15 * z.abs().max(1.0));
        }
    }

    #[test]
    fn uniforms_are_open_and_have_the_right_moments() {
        let n = 200_000u64;
        let (mut s, mut s2) = (0.0, 0.0);
        for i in 0..n {
            let u = uniform01(7, i, 3);
            assert!(u > 0.0 && u < 1.0);
            s += u;
            s2 += u * u;
        }
        let mean = s / n as f64;
        let var = s2 / n as f64 - mean * mean;
        // standard errors: 0.29/√n ≈ 6.5e-4 for the mean, ≈ 2e-4 for the variance
        assert!((mean - 0.5).abs() < 4.0 * 6.5e-4, "mean {mean}");
        assert!((var - 1.0 / 12.0).abs() < 4.0 * 2e-4, "variance {var}");
    }

    #[test]
    fn streams_of_different_samples_dimensions_and_seeds_differ() {
        assert_ne!(uniform01(1, 0, 0), uniform01(1, 1, 0));
        assert_ne!(uniform01(1, 0, 0), uniform01(1, 0, 1));
        assert_ne!(uniform01(1, 0, 0), uniform01(2, 0, 0));
        // neighbouring samples are uncorrelated (lag-1 correlation ~ 1/√n)
        let n = 100_000u64;
        let xs: Vec<f64> = (0..n).map(|i| uniform01(5, i, 0) - 0.5).collect();
        let c: f64 = xs.windows(2).map(|w| w[0] * w[1]).sum::<f64>() / n as f64 / (1.0 / 12.0);
        assert!(c.abs() < 4.0 / (n as f64).sqrt(), "lag-1 correlation {c}");
    }

    #[test]
    fn zero_width_distributions_return_their_centre_exactly() {
        for u in [1e-9, 0.3, 0.5, 0.999] {
            assert_eq!(
                Distribution::Normal {
                    mean: 1000.0,
                    std_dev: 0.0
                }
                .quantile(u),
                1000.0
            );
            assert_eq!(
                Distribution::Uniform {
                    low: 0.078,
                    high: 0.078
                }
                .quantile(u),
                0.078
            );
            assert_eq!(
                Distribution::Lognormal {
                    mean: 0.078,
                    std_dev: 0.0
                }
                .quantile(u),
                0.078
            );
        }
    }

    #[test]
    fn lognormal_has_the_stated_mean_and_std_dev() {
        let d = Distribution::Lognormal {
            mean: 2.0,
            std_dev: 0.5,
        };
        let n = 200_000u64;
        let xs: Vec<f64> = (0..n).map(|i| d.quantile(uniform01(11, i, 0))).collect();
        let mean = xs.iter().sum::<f64>() / n as f64;
        let sd = (xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt();
        // standard error of the mean 0.5/√n ≈ 1.1e-3
        assert!((mean - 2.0).abs() < 5e-3, "mean {mean}");
        assert!((sd - 0.5).abs() < 1e-2, "std dev {sd}");
        assert!(xs.iter().all(|&x| x > 0.0));
    }
}
