//! The figures an operator acts on from a dynamic run (SPEC §5, §11;
//! issue 31 item 2), compared between runs at halved steps: the peak and
//! the minimum winch tension, the peak tension anywhere along the tether
//! and the lowest aerostat altitude ([`Figures`]), their changes
//! ([`changes`]), whether they agree within a tolerance ([`within`]), the
//! observed order of convergence in the step ([`observed_order`]) and the
//! safe side of each ([`SAFE_SIGN`]).
//!
//! **Estimate.** With `q(h)` a figure at step `h` and `q*` its limit, a
//! method of order `p` in its asymptotic range has
//! `|q(h) − q*| ≈ |q(2h) − q(h)|/(2^p − 1) ≤ |q(2h) − q(h)|` for every
//! `p ≥ 1`: the change from the run at twice the step bounds the error of
//! the run at `h`. Generalized-α is second order in smooth motion; a peak
//! taken over the steps adds a sampling error of the same order near a
//! smooth maximum and of first order at a wave front, so `p ≥ 1` is the
//! assumption. Where it fails (a slack tether snapping taut: the changes
//! do not decrease as the step is halved, no order is observed) the
//! estimate is not a bound, which is why the default ladder refuses rather
//! than answer when the changes stay above the tolerance.
//!
//! **Scale.** A change is judged against the figure's scale: the tension
//! figures against the largest of them (the peak tension anywhere, so a
//! minimum winch tension near zero, a slack tether, is judged on the
//! tension scale of the run and not on its own), the altitude against
//! itself.

use super::run::Run;

/// How many figures.
pub const FIGURES: usize = 4;
/// Their names in the JSON contract, in order.
pub const NAMES: [&str; FIGURES] = [
    "peak_winch_tension_n",
    "min_winch_tension_n",
    "peak_tension_n",
    "min_aerostat_altitude_m",
];
/// The safe side of each figure: `+1` a peak (safe value = value + error),
/// `−1` a minimum (safe value = value − error).
pub const SAFE_SIGN: [f64; FIGURES] = [1.0, -1.0, 1.0, -1.0];
/// Default relative tolerance of the figures (of their scale).
pub const DEFAULT_TOLERANCE: f64 = 0.01;
/// Tightest and loosest tolerance a request may ask.
pub const MIN_TOLERANCE: f64 = 1e-4;
pub const MAX_TOLERANCE: f64 = 0.1;

/// The four figures of one run and when each happened (s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Figures {
    /// In the order of [`NAMES`] (N, N, N, m).
    pub values: [f64; FIGURES],
    pub times_s: [f64; FIGURES],
}

impl Figures {
    /// The figures of a run (every step checked).
    pub fn of(run: &Run) -> Self {
        let e = [
            run.peak_winch_tension,
            run.min_winch_tension,
            run.peak_tension,
            run.min_aerostat_altitude,
        ];
        Self {
            values: e.map(|x| x.value),
            times_s: e.map(|x| x.time_s),
        }
    }

    /// The scale each figure's change is judged against (see the module docs).
    pub fn scales(&self) -> [f64; FIGURES] {
        let v = &self.values;
        let tension = v[0].abs().max(v[1].abs()).max(v[2].abs()).max(1e-9);
        [tension, tension, tension, v[3].abs().max(1e-9)]
    }
}

/// `|a − b|` figure by figure.
pub fn changes(a: &Figures, b: &Figures) -> [f64; FIGURES] {
    std::array::from_fn(|i| (a.values[i] - b.values[i]).abs())
}

/// The changes relative to the scales of `fine`.
pub fn relative_changes(coarse: &Figures, fine: &Figures) -> [f64; FIGURES] {
    let d = changes(coarse, fine);
    let s = fine.scales();
    std::array::from_fn(|i| d[i] / s[i])
}

/// Whether every figure changed by at most `tolerance` of its scale
/// (a non-finite figure never agrees).
pub fn within(coarse: &Figures, fine: &Figures, tolerance: f64) -> bool {
    relative_changes(coarse, fine)
        .iter()
        .all(|r| r.is_finite() && *r <= tolerance)
}

/// The order `log₂(|q(4h) − q(2h)| / |q(2h) − q(h)|)` observed on three
/// runs at halved steps; `None` when it cannot be measured: a change
/// below `floor` (converged to roundoff) or the changes not decreasing
/// (not in the asymptotic range).
pub fn observed_order(coarse: f64, mid: f64, fine: f64, floor: f64) -> Option<f64> {
    let (a, b) = ((coarse - mid).abs(), (mid - fine).abs());
    if !(a.is_finite() && b.is_finite()) || a <= floor || b <= floor || a <= b {
        return None;
    }
    Some((a / b).log2())
}

/// A figure with its error estimate and its safe side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimated {
    pub value: f64,
    pub error_estimate: f64,
    /// `value ± error_estimate` on the safe side ([`SAFE_SIGN`]).
    pub safe_value: f64,
    pub time_s: f64,
}

/// The figures of `fine` with the error estimate from `coarse` (see the
/// module docs), plus `extra` (another estimated error, e.g. from the
/// segments), figure by figure.
pub fn estimate(coarse: &Figures, fine: &Figures, extra: [f64; FIGURES]) -> [Estimated; FIGURES] {
    let d = changes(coarse, fine);
    std::array::from_fn(|i| {
        let error_estimate = d[i] + extra[i];
        Estimated {
            value: fine.values[i],
            error_estimate,
            safe_value: fine.values[i] + SAFE_SIGN[i] * error_estimate,
            time_s: fine.times_s[i],
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn f(v: [f64; 4]) -> Figures {
        Figures {
            values: v,
            times_s: [0.0; 4],
        }
    }

    #[test]
    fn orders_and_safe_sides() {
        // q(h) = 1 + h²: halving from h = 0.4 gives order 2 exactly.
        let q = |h: f64| 1.0 + h * h;
        let p = observed_order(q(0.4), q(0.2), q(0.1), 1e-12).unwrap();
        assert!((p - 2.0).abs() < 1e-9, "{p}");
        // Changes that grow: no order.
        assert_eq!(observed_order(1.0, 1.1, 1.5, 1e-12), None);
        let e = estimate(
            &f([100.0, 10.0, 120.0, 500.0]),
            &f([101.0, 9.0, 121.0, 498.0]),
            [0.5; 4],
        );
        assert_eq!(e[0].safe_value, 101.0 + 1.5);
        assert_eq!(e[1].safe_value, 9.0 - 1.5);
        assert_eq!(e[3].safe_value, 498.0 - 2.5);
        // The minimum winch tension is judged on the tension scale (121 N).
        assert!(within(
            &f([100.0, 0.0, 120.0, 500.0]),
            &f([100.5, 1.0, 120.0, 500.0]),
            0.01
        ));
        assert!(!within(
            &f([100.0, 0.0, 120.0, 500.0]),
            &f([100.0, 2.0, 120.0, 500.0]),
            0.01
        ));
    }
}
