//! Two-degree-of-freedom reduced model of the geometrically exact cable
//! (thesis ch. 8.4, (8.8)–(8.9)): one `sin(πζ/2)` mode each for the
//! transverse displacement `u₂` and the section rotation `θ`, small
//! rotations of size `ε`. Non-dimensional (GE scaling of thesis §5.6).
//!
//! At a frozen length `l` and rate `ṽ` (slow deployment) the model is
//!
//! ```text
//! l² ü + ṽ l u̇ + [(π²/4) l E* − ṽ² β] u + E* l ε θ              = 0
//! l² θ̈ + ṽ l θ̇ + [ε π²/4 + E* l ε − ṽ² β] θ − E* l u            = 0,   β = 1/2 + π²/12
//! ```
//!
//! which at `l = 1`, `ṽ = 0` is (8.8). Its two natural frequencies
//! `ω_GE⁽¹⁾ ≤ ω_GE⁽²⁾` coincide with the Euler–Bernoulli-like frequency
//! `(π/2)√E*` and zero at `ε = 0`, and turn complex when the discriminant
//! `((k₁₁ − k₂₂)/2)² + k₁₂k₂₁` goes negative (near `ε ≈ 0.6` for `E* = 5`).
//! Resonance bands of a deployment are the ranges swept by each frequency
//! between the initial and the final length.

use std::f64::consts::PI;

const BETA: f64 = 0.5 + PI * PI / 12.0;

/// The two natural frequencies at one frozen state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ReducedFrequencies {
    /// Both real: `first ≤ second` (rad per unit t̄).
    Real { first: f64, second: f64 },
    /// A complex pair `ω² = re ± i·im`: the small-rotation expansion fails.
    Complex {
        omega_squared_re: f64,
        omega_squared_im: f64,
    },
}

/// Stiffness of the frozen model divided by `l²`, row-major `[k11, k12, k21, k22]`.
fn stiffness(stiffness_ratio: f64, epsilon: f64, length: f64, rate: f64) -> [f64; 4] {
    let (e, l, v2) = (stiffness_ratio, length, rate * rate);
    let l2 = l * l;
    [
        (PI * PI / 4.0 * l * e - v2 * BETA) / l2,
        e * l * epsilon / l2,
        -e * l / l2,
        (epsilon * PI * PI / 4.0 + e * l * epsilon - v2 * BETA) / l2,
    ]
}

/// Natural frequencies of the two-DOF model at length `l`, rate `ṽ`
/// (the `ṽ l` damping is left out: it shifts the frequencies at `O(ṽ²)`).
pub fn natural_frequencies(
    stiffness_ratio: f64,
    epsilon: f64,
    length: f64,
    rate: f64,
) -> ReducedFrequencies {
    let [k11, k12, k21, k22] = stiffness(stiffness_ratio, epsilon, length, rate);
    let mean = 0.5 * (k11 + k22);
    let disc = (0.5 * (k11 - k22)).powi(2) + k12 * k21;
    if disc < 0.0 {
        return ReducedFrequencies::Complex {
            omega_squared_re: mean,
            omega_squared_im: (-disc).sqrt(),
        };
    }
    let root = disc.sqrt();
    ReducedFrequencies::Real {
        first: (mean - root).max(0.0).sqrt(),
        second: (mean + root).max(0.0).sqrt(),
    }
}

/// Smallest `ε` in `(0, ε_max]` at which the frequencies turn complex
/// (constant length `l = 1`, at rest), by bisection on the discriminant.
pub fn complex_onset_epsilon(stiffness_ratio: f64, epsilon_max: f64) -> Option<f64> {
    let complex = |eps: f64| {
        matches!(
            natural_frequencies(stiffness_ratio, eps, 1.0, 0.0),
            ReducedFrequencies::Complex { .. }
        )
    };
    let steps = 1000;
    let mut prev = 0.0;
    for i in 1..=steps {
        let eps = epsilon_max * i as f64 / steps as f64;
        if complex(eps) {
            let (mut lo, mut hi) = (prev, eps);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if complex(mid) { hi = mid } else { lo = mid }
            }
            return Some(hi);
        }
        prev = eps;
    }
    None
}

/// One instant of a constant-rate deployment from `l = 1`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrequencySample {
    /// `t̄`.
    pub time: f64,
    /// `l = 1 + ṽ t̄`.
    pub length: f64,
    pub frequencies: ReducedFrequencies,
}

/// The frozen-length frequencies of (8.9) along a constant-rate deployment
/// from `l = 1` over `t̄ ∈ [0, duration]` (thesis Figs 8.6(a), 8.7(a)),
/// `samples + 1` instants; stops early if the cable would vanish.
pub fn frequency_evolution(
    stiffness_ratio: f64,
    epsilon: f64,
    rate: f64,
    duration: f64,
    samples: usize,
) -> Vec<FrequencySample> {
    let samples = samples.max(1);
    (0..=samples)
        .map(|i| duration * i as f64 / samples as f64)
        .map(|time| (time, 1.0 + rate * time))
        .take_while(|&(_, l)| l > 0.0)
        .map(|(time, length)| FrequencySample {
            time,
            length,
            frequencies: natural_frequencies(stiffness_ratio, epsilon, length, rate),
        })
        .collect()
}

/// A frequency band `[low, high]` (rad per unit t̄).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Band {
    pub low: f64,
    pub high: f64,
}

impl Band {
    pub fn contains(&self, omega: f64) -> bool {
        (self.low..=self.high).contains(&omega)
    }
}

/// Resonance bands of a constant-rate deployment from `l = 1` over
/// `t̄ ∈ [0, duration]`: each natural frequency sweeps from its value at the
/// initial length to its value at the final one. `None` if the frequencies
/// are complex anywhere along the way.
pub fn resonance_bands(
    stiffness_ratio: f64,
    epsilon: f64,
    rate: f64,
    duration: f64,
) -> Option<[Band; 2]> {
    let samples = 200;
    let mut lows = [f64::INFINITY; 2];
    let mut highs = [0.0f64; 2];
    for i in 0..=samples {
        let t = duration * i as f64 / samples as f64;
        let l = 1.0 + rate * t;
        if l <= 0.0 {
            return None;
        }
        match natural_frequencies(stiffness_ratio, epsilon, l, rate) {
            ReducedFrequencies::Real { first, second } => {
                for (k, w) in [first, second].into_iter().enumerate() {
                    lows[k] = lows[k].min(w);
                    highs[k] = highs[k].max(w);
                }
            }
            ReducedFrequencies::Complex { .. } => return None,
        }
    }
    Some([
        Band {
            low: lows[0],
            high: highs[0],
        },
        Band {
            low: lows[1],
            high: highs[1],
        },
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn at_zero_epsilon_one_frequency_is_the_bending_one_and_the_other_vanishes() {
        let ReducedFrequencies::Real { first, second } = natural_frequencies(5.0, 0.0, 1.0, 0.0)
        else {
            panic!()
        };
        assert!(first.abs() < 1e-12);
        assert!((second - 0.5 * PI * 5.0f64.sqrt()).abs() < 1e-12);
        // small ε splits them: a low "sub-frequency" appears, the upper stays near (π/2)√E*
        let ReducedFrequencies::Real { first, second } = natural_frequencies(5.0, 0.2, 1.0, 0.0)
        else {
            panic!()
        };
        assert!(first > 0.5 && first < second);
        assert!((second / (0.5 * PI * 5.0f64.sqrt()) - 1.0).abs() < 0.1);
    }

    #[test]
    fn frequencies_turn_complex_near_epsilon_0_6_for_e_star_5() {
        let onset = complex_onset_epsilon(5.0, 2.0).unwrap();
        // closed form: (π²E*/4 − ε(π²/4 + E*))²/4 = E*² ε  →  ε ≈ 0.604
        assert!((onset - 0.604).abs() < 0.005, "onset ε = {onset}");
        assert!(matches!(
            natural_frequencies(5.0, 0.55, 1.0, 0.0),
            ReducedFrequencies::Real { .. }
        ));
        assert!(matches!(
            natural_frequencies(5.0, 0.65, 1.0, 0.0),
            ReducedFrequencies::Complex { .. }
        ));
    }

    #[test]
    fn lengthening_lowers_and_shortening_raises_both_frequencies() {
        let at = |l: f64| match natural_frequencies(5.0, 0.2, l, 0.005) {
            ReducedFrequencies::Real { first, second } => (first, second),
            c => panic!("{c:?}"),
        };
        let (a, b) = (at(1.0), at(1.5));
        assert!(b.0 < a.0 && b.1 < a.1);
        let bands = resonance_bands(5.0, 0.2, 0.005, 100.0).unwrap();
        assert!(
            (bands[1].high - at(1.0).1).abs() < 1e-9 && (bands[1].low - at(1.5).1).abs() < 1e-9
        );
        let shortening = resonance_bands(5.0, 0.2, -0.005, 100.0).unwrap();
        assert!(
            shortening[1].high > bands[1].high,
            "shortening sweeps upward"
        );
        // a faster deployment over the same time widens the bands
        let fast = resonance_bands(5.0, 0.2, 0.05, 100.0).unwrap();
        assert!(fast[0].high - fast[0].low > bands[0].high - bands[0].low);
    }
}
