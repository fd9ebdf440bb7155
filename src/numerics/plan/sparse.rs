//! Loads along a fine, monotone sequence of lengths from exact equilibria at
//! a checked subset of them: the plan's grid (4000 segments) needs the
//! steady-wind loads at every node, but they are smooth functions of the
//! length, so shooting them at every node is wasted work.
//!
//! The nodes are solved at a coarse stride (about [`COARSE_INTERVALS`]
//! intervals), then every interval is checked at its midpoint: the midpoint
//! is solved too and compared with the cubic (Lagrange) interpolant through
//! the four nearest solved nodes. An interval whose check differs by more
//! than the tolerance of any component, or that touches a node outside the
//! smooth regime (a slack tether, a shooting that failed, a non-finite
//! value), is split at its midpoint and checked again; a split reaches
//! single grid steps, where every node is solved. Every other node is then
//! interpolated through its four nearest solved nodes (which include the
//! midpoint checked, so its error is about 1/16 of the checked one); one
//! whose stencil holds a node outside the smooth regime is solved instead.
//!
//! The tolerance is the caller's, per component: [`super::air`] uses
//! [`RELATIVE_TOLERANCE`] (1e-6) of its force scale (the full buoyancy plus
//! the longest tether's weight: 1 mN per kN) and of the longest length.
//! That is the level of the equilibrium's own discretisation error in a
//! sheared wind: with 100 fixed RK4 steps the drag of a power-law wind,
//! whose derivative is singular at the ground, is integrated to about
//! 1e-6 of the tension, and that error varies unevenly with the length
//! (a tighter tolerance only refines into that noise: at 1e-8 a plan of
//! the windows bench solves 160 nodes of 4001 per quantity, at 1e-6 about
//! 100, in a uniform wind 33). `tests/verification_plan_sparse.rs` compares
//! every node of a grid with its own shooting.

use rayon::prelude::*;

/// Intervals of the first, coarse stride.
pub const COARSE_INTERVALS: usize = 16;
/// Below this many lengths every one is solved.
pub const MIN_SPARSE_LENGTHS: usize = 64;
/// The interpolation tolerance relative to the caller's scales.
pub const RELATIVE_TOLERANCE: f64 = 1e-6;
/// Solved nodes per chunk of a batch (each chunk in order with its own
/// continuation state).
const CHUNK: usize = 8;

/// The loads at one length and whether they lie in the smooth regime.
#[derive(Clone, Copy, Debug)]
pub struct Solved<const N: usize> {
    pub values: [f64; N],
    /// Smooth in the length around this node (not slack, converged):
    /// interpolation may use it.
    pub smooth: bool,
}

/// `f` at every length of `lengths` (monotone, strictly), solved at a
/// checked subset and interpolated elsewhere within `tolerance` per
/// component. Lengths that are few, or not strictly monotone, are all
/// solved, in chunks on rayon, each chunk in order with its own state `A`.
pub fn sparse_along<A: Default, const N: usize>(
    lengths: &[f64],
    tolerance: [f64; N],
    f: impl Fn(f64, &mut A) -> Solved<N> + Sync,
) -> Vec<[f64; N]> {
    let n = lengths.len();
    let increasing = lengths.windows(2).all(|w| w[1] > w[0]);
    let decreasing = lengths.windows(2).all(|w| w[1] < w[0]);
    if n < MIN_SPARSE_LENGTHS || !(increasing || decreasing) {
        return solve_batch(lengths, &(0..n).collect::<Vec<_>>(), &f)
            .into_iter()
            .map(|s| s.values)
            .collect();
    }
    if decreasing {
        // The same nodes from the shorter end, whichever the direction: a
        // retrieval over the same lengths solves the very same subset.
        let up: Vec<f64> = lengths.iter().rev().copied().collect();
        let mut out = increasing_sparse(&up, tolerance, &f);
        out.reverse();
        return out;
    }
    increasing_sparse(lengths, tolerance, &f)
}

/// Solves `f` at `lengths[i]` for every `i` of `at` (in order), in chunks.
fn solve_batch<A: Default, const N: usize>(
    lengths: &[f64],
    at: &[usize],
    f: &(impl Fn(f64, &mut A) -> Solved<N> + Sync),
) -> Vec<Solved<N>> {
    at.par_chunks(CHUNK)
        .flat_map_iter(|chunk| {
            let mut state = A::default();
            chunk
                .iter()
                .map(|&i| f(lengths[i], &mut state))
                .collect::<Vec<_>>()
        })
        .collect()
}

/// The four solved nodes nearest to index `i` around the gap `(a, b)` that
/// holds it: `a`, `b` and one more on each side where there is one (two on
/// one side at an end). `None` with fewer than four solved nodes.
fn stencil(known: &[usize], a_pos: usize) -> Option<[usize; 4]> {
    // known[a_pos] = a, known[a_pos + 1] = b
    let m = known.len();
    if m < 4 {
        return None;
    }
    let first = a_pos.saturating_sub(1).min(m - 4);
    Some([
        known[first],
        known[first + 1],
        known[first + 2],
        known[first + 3],
    ])
}

/// Cubic Lagrange through the stencil's nodes, at `x`.
fn lagrange<const N: usize>(xs: [f64; 4], ys: [[f64; N]; 4], x: f64) -> [f64; N] {
    let mut out = [0.0; N];
    for i in 0..4 {
        let mut w = 1.0;
        for j in 0..4 {
            if j != i {
                w *= (x - xs[j]) / (xs[i] - xs[j]);
            }
        }
        for (o, y) in out.iter_mut().zip(ys[i]) {
            *o += w * y;
        }
    }
    out
}

fn increasing_sparse<A: Default, const N: usize>(
    x: &[f64],
    tolerance: [f64; N],
    f: &(impl Fn(f64, &mut A) -> Solved<N> + Sync),
) -> Vec<[f64; N]> {
    let last = x.len() - 1;
    let stride = (last / COARSE_INTERVALS).max(1);
    let mut anchors: Vec<usize> = (0..last).step_by(stride).collect();
    anchors.push(last);
    let mut solved: Vec<Option<Solved<N>>> = vec![None; x.len()];
    for (&i, s) in anchors.iter().zip(solve_batch(x, &anchors, f)) {
        solved[i] = Some(s);
    }
    // Gaps still to check, and gaps accepted for interpolation.
    let mut pending: Vec<(usize, usize)> = anchors
        .windows(2)
        .filter(|w| w[1] - w[0] >= 2)
        .map(|w| (w[0], w[1]))
        .collect();
    let mut accepted: Vec<(usize, usize)> = Vec::new();
    while !pending.is_empty() {
        let mids: Vec<usize> = pending.iter().map(|&(a, b)| (a + b) / 2).collect();
        let known: Vec<usize> = (0..x.len()).filter(|&i| solved[i].is_some()).collect();
        let checks: Vec<Option<[f64; N]>> = pending
            .iter()
            .zip(&mids)
            .map(|(&(a, _), &m)| {
                let a_pos = known.binary_search(&a).ok()?;
                let st = stencil(&known, a_pos)?;
                let nodes = st.map(|k| solved[k].expect("a known node"));
                nodes
                    .iter()
                    .all(|s| s.smooth)
                    .then(|| lagrange(st.map(|k| x[k]), nodes.map(|s| s.values), x[m]))
            })
            .collect();
        for (&m, s) in mids.iter().zip(solve_batch(x, &mids, f)) {
            solved[m] = Some(s);
        }
        let mut next = Vec::new();
        for ((&(a, b), &m), check) in pending.iter().zip(&mids).zip(checks) {
            let at = solved[m].expect("just solved");
            let within = check.is_some_and(|c| {
                at.smooth
                    && c.iter()
                        .zip(at.values)
                        .zip(tolerance)
                        .all(|((c, v), t)| (c - v).abs() <= t)
            });
            if within {
                accepted.push((a, b));
                continue;
            }
            for (lo, hi) in [(a, m), (m, b)] {
                if hi - lo >= 2 {
                    next.push((lo, hi));
                }
            }
        }
        pending = next;
    }
    // Interpolate the rest; a stencil outside the smooth regime is solved.
    let known: Vec<usize> = (0..x.len()).filter(|&i| solved[i].is_some()).collect();
    let mut out: Vec<[f64; N]> = vec![[f64::NAN; N]; x.len()];
    let mut unsure = Vec::new();
    for (a, b) in accepted {
        for i in a + 1..b {
            if solved[i].is_some() {
                continue;
            }
            let a_pos = known.partition_point(|&k| k < i) - 1;
            let st = stencil(&known, a_pos).expect("an accepted gap has a stencil");
            let nodes = st.map(|k| solved[k].expect("a known node"));
            if nodes.iter().all(|s| s.smooth) {
                out[i] = lagrange(st.map(|k| x[k]), nodes.map(|s| s.values), x[i]);
            } else {
                unsure.push(i);
            }
        }
    }
    for (&i, s) in unsure.iter().zip(solve_batch(x, &unsure, f)) {
        solved[i] = Some(s);
    }
    for (o, s) in out.iter_mut().zip(&solved) {
        if let Some(s) = s {
            *o = s.values;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn smooth(x: f64, _: &mut ()) -> Solved<2> {
        Solved {
            values: [x.sin() * 1000.0, (0.001 * x).exp()],
            smooth: true,
        }
    }

    #[test]
    fn smooth_functions_are_interpolated_within_the_tolerance() {
        let x: Vec<f64> = (0..=4000).map(|i| 3.0 + 0.25 * i as f64).collect();
        let tol = [1e-6, 1e-9];
        let got = sparse_along(&x, tol, smooth);
        for (xi, g) in x.iter().zip(&got) {
            let want = smooth(*xi, &mut ()).values;
            // the midpoint check bounds the error of a gap at the
            // coarser stencil; the finer one is about 16× better
            assert!((g[0] - want[0]).abs() <= tol[0], "{xi}: {g:?} vs {want:?}");
            assert!((g[1] - want[1]).abs() <= tol[1], "{xi}: {g:?} vs {want:?}");
        }
    }

    #[test]
    fn a_jump_outside_the_smooth_regime_is_solved_exactly() {
        // A slack-like regime: −1000 beyond x = 517.3, flagged not smooth.
        let f = |x: f64, _: &mut ()| Solved {
            values: [if x > 517.3 { -1000.0 } else { 1000.0 - x }],
            smooth: x <= 517.3,
        };
        let x: Vec<f64> = (0..=4000).map(|i| 0.25 * i as f64).collect();
        let got = sparse_along(&x, [1e-9], f);
        for (xi, g) in x.iter().zip(&got) {
            let want = f(*xi, &mut ()).values[0];
            assert!((g[0] - want).abs() <= 1e-9, "at {xi}: {} vs {want}", g[0]);
        }
    }

    #[test]
    fn decreasing_lengths_give_the_increasing_answer_reversed() {
        let up: Vec<f64> = (0..=1000).map(|i| 1.0 + i as f64).collect();
        let down: Vec<f64> = up.iter().rev().copied().collect();
        let a = sparse_along(&up, [1e-6, 1e-9], smooth);
        let mut b = sparse_along(&down, [1e-6, 1e-9], smooth);
        b.reverse();
        assert_eq!(a, b);
    }
}
