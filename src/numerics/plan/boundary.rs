//! The boundary of an admissible range of lengths: the lift limit (the
//! longest length whose rest state keeps its margin) and the length that
//! flies an altitude. Each is the crossing of a margin `f(L)` (admissible
//! where `f ≥ 0`) that costs one shooting per evaluation, so the search
//! takes few: false position with the Illinois modification (the end kept
//! twice running has its value halved, so both ends close in), a step
//! never closer than half the tolerance to an end (so the last steps land
//! on both sides of the crossing), and a bisection after any step that
//! did not halve the bracket (a margin that jumps, as at a slack tether,
//! where false position would crawl: at most twice bisection's count).
//! A smooth margin's crossing over a 1 000 m bracket takes about a dozen
//! evaluations to a micrometre (14 for `c − L²`); bisection took 48.

/// Largest number of evaluations (bisection alone needs
/// `log2(width / tolerance)`: 40 for 1 000 m to a nanometre).
pub const MAX_EVALUATIONS: usize = 64;

/// The bracket `(ok, not_ok)` around the crossing of `f` between `ok`
/// (where `f(ok) = f_ok ≥ 0`) and `not_ok` (`f_not_ok < 0`), narrowed to
/// `|ok − not_ok| ≤ tolerance` (either order of the ends). A non-finite
/// `f` counts as not admissible.
pub fn bracket_crossing(
    mut ok: f64,
    f_ok: f64,
    mut not_ok: f64,
    f_not_ok: f64,
    tolerance: f64,
    mut f: impl FnMut(f64) -> f64,
) -> (f64, f64) {
    // The values false position uses (halved by the Illinois rule).
    let (mut w_ok, mut w_not) = (f_ok, f_not_ok);
    let mut kept: Option<bool> = None;
    // The width before the last false-position step, if the last was one.
    let mut before_false_position: Option<f64> = None;
    for _ in 0..MAX_EVALUATIONS {
        let width = (not_ok - ok).abs();
        if width <= tolerance {
            break;
        }
        let stalled = before_false_position.is_some_and(|w| width > 0.5 * w);
        let smooth = w_ok.is_finite() && w_not.is_finite() && w_ok > w_not;
        let x = if stalled || !smooth {
            before_false_position = None;
            0.5 * (ok + not_ok)
        } else {
            before_false_position = Some(width);
            let x = ok + (not_ok - ok) * w_ok / (w_ok - w_not);
            let (lo, hi) = (ok.min(not_ok), ok.max(not_ok));
            let guard = (0.5 * tolerance).min(0.25 * width);
            x.clamp(lo + guard, hi - guard)
        };
        let fx = f(x);
        if fx >= 0.0 {
            ok = x;
            w_ok = fx;
            if kept == Some(false) {
                w_not *= 0.5;
            }
            kept = Some(false);
        } else {
            not_ok = x;
            w_not = if fx.is_nan() { f64::NEG_INFINITY } else { fx };
            if kept == Some(true) {
                w_ok *= 0.5;
            }
            kept = Some(true);
        }
    }
    (ok, not_ok)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A smooth decreasing margin: the crossing of `c − L²` to the
    /// tolerance, the admissible end on the admissible side, in a handful
    /// of evaluations.
    #[test]
    fn a_smooth_crossing_takes_few_evaluations() {
        let root = 617.283_f64;
        let mut n = 0;
        let (ok, not_ok) =
            bracket_crossing(0.0, root * root, 1000.0, root * root - 1e6, 1e-6, |l| {
                n += 1;
                root * root - l * l
            });
        assert!(ok <= root && not_ok > root, "{ok} {not_ok}");
        assert!(not_ok - ok <= 1e-6);
        assert!(n <= 16, "{n} evaluations");
    }

    /// A margin that jumps (a slack tether: −F beyond the crossing) is
    /// found as bisection finds it, within the evaluation cap.
    #[test]
    fn a_jump_is_bracketed_by_bisection() {
        let jump = 433.1;
        let f = |l: f64| if l < jump { 50.0 - 0.01 * l } else { -1000.0 };
        let mut n = 0;
        let (ok, not_ok) = bracket_crossing(0.0, f(0.0), 1000.0, f(1000.0), 1e-6, |l| {
            n += 1;
            f(l)
        });
        assert!(
            ok < jump && not_ok >= jump && not_ok - ok <= 1e-6,
            "{ok} {not_ok}"
        );
        assert!(n <= 2 * 30 + 2, "{n} evaluations");
    }

    /// The ends may come in either order: an increasing margin (the
    /// altitude of a length against a target altitude).
    #[test]
    fn an_increasing_margin_is_bracketed_from_above() {
        let (ok, not_ok) = bracket_crossing(1000.0, 700.0, 0.0, -300.0, 1e-9, |l| l - 300.0);
        assert!(
            ok >= 300.0 && not_ok < 300.0 && ok - not_ok <= 1e-9,
            "{ok} {not_ok}"
        );
        let (ok, _) = bracket_crossing(1000.0, 700.0, 0.0, f64::NAN, 1e-9, |l| {
            if l < 100.0 { f64::NAN } else { l - 300.0 }
        });
        assert!((ok - 300.0).abs() <= 1e-9);
    }
}
