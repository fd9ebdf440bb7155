//! The converged quasi-static GE onset in a steady wind (issue 21): the
//! first of divergence and flutter on nested uniform meshes, each state
//! on the branch reached by paying out ([`super::qs_wind`]) and continued
//! along the parameter, with Richardson, an error estimate and the safe
//! side of [`super::qs_converged`].
//!
//! **Each level.** The onset is where the critical eigenvalue `λ(p)` of
//! the local QEP crosses the imaginary axis: `Re λ(p) = 0`, a flutter when
//! `Im λ ≠ 0` there, a divergence when `λ` is real (then `det K = 0`). On
//! the base mesh ([`ConvergenceConfig::base_elements`]) the dense QEP
//! ([`super::stability::spectrum_of`]) is scanned along the range and
//! bisected to [`BASE_BRACKET`] relative; the eigenvalue of largest real
//! part at the unstable end is the critical one. From there, and on every
//! finer mesh (the coarser pair prolonged onto it), the pair is tracked
//! by Newton on the QEP ([`super::qs_flutter`], a complex band LU, O(n)),
//! and the root of `Re λ(p)` found by the safeguarded Illinois regula
//! falsi to [`super::qs_converged::level_rtol`]: no dense QEP on the
//! finer meshes.
//!
//! **Continuation.** Every equilibrium of a level is a Newton from its
//! neighbour along the parameter (steps of at most [`NEAR`] of the
//! parameter or [`MARCH_OF_RANGE`] of the range, halved on failure),
//! starting at the lower end from the continuum tether's shape: a Newton
//! from the continuum shape at a high payout rate fails or lands on
//! another state (the 2 m/s rate levels 57.7 / 57.7 / 59.9 / 56.4 m/s, not
//! converged).
//!
//! **Consistency.** `converged` needs the estimate within the tolerance
//! on three levels or more, the same kind of onset on each level, the
//! crossing frequency of the finer levels within [`FREQUENCY_RTOL`] of
//! the coarser one's, and the parity of `det K` just below each flutter
//! root that of the lower end (no divergence first).
//!
//! **The QEP onset in wind, measured** (issue 21; thesis tether,
//! EI = 1 N m², solid 5 mm section, 1000 m, the critical rate; the
//! branch continued in the rate in 4 % steps from 1 m/s, each Newton from
//! its neighbour; dense QEP every 1 m/s from 30 m/s, bisected to 10⁻⁶;
//! `tests/verification_ge_wind_onset.rs`, `measure_dense_onsets`):
//!
//! | wind | 20 el. | 40 el. | 80 el. | aerostat 5 % lower at |
//! |---|---|---|---|---|
//! | 8 m/s | none to 190 | none to 190 | none to 190 | 42 m/s |
//! | 2 m/s | 173.04 (ω 0.65) | 176.08 (ω 2.28) | 177.12 (ω 6.53) | 59 m/s |
//! | 0.5 m/s | 59.0 (jump) | 57.0 (jump) | 56.5 (div.) | — |
//! | 0.1 m/s | 58.56 (div.) | 56.81 (div.) | 56.12 (div.) | — |
//!
//! In 0.1 m/s the onset is a divergence (a real eigenvalue, `det K`
//! changing sign) converging from above at about first order (steps
//! 1.75, 0.69 m/s) toward the calm one (the string's `√(T_guide/ρA)` =
//! 54.9 m/s plus the bending lift). From about 0.5 m/s on the wind is an
//! imperfection of that bifurcation: the branch no longer loses
//! stability there but blows down (in 8 m/s the aerostat is 5 % lower at
//! 42 m/s and comes down to the guide's height near 175 m/s, on every mesh),
//! and the first QEP instability moves to 170–180 m/s, in a state far
//! from the tether's (1000 m paid out, aerostat 400 m lower), with a
//! crossing frequency that does not converge (0.65 / 2.28 / 6.53 rad/s):
//! a mesh artifact of a collapsed state, not a physical flutter. The
//! 20-element flutter at 59.58 m/s of the earlier search was not
//! reproduced on this branch (nor by `qs_critical::critical_rate_from`
//! from the continuum start: `Never` to 150 m/s). So the local QEP on the
//! wind branch is not a safe criterion near the string speed: the
//! linear onset jumps from ≈ 56 to ≈ 175 m/s between 0.1 and 2 m/s of
//! wind. The dense slow spectrum's `Re λ` is also only good to about
//! 10⁻⁶ 1/s on 20–40 elements (against a residual-checked Newton pair,
//! [`super::qs_flutter`]), above its stability tolerance (2.5·10⁻⁷ 1/s):
//! its verdict near `Re λ = 0` is roundoff.
//!
//! **Measured, the converged search** (`measure_converged_rate_search`;
//! critical rate at 1000 m, the thesis tether at EI = 1 N m²): in
//! 0.1 m/s a divergence, 58.537 / 56.822 / 56.121 / 55.625 / 55.364 m/s
//! at 20 … 320 elements, 55.103 ± 0.026 m/s, converged (calm air, graded:
//! 55.181 ± 0.005; the uniform levels do not resolve the 1.1 m bending
//! layer, so the wind value lies between it and the string's 54.87 m/s);
//! in 0.5 m/s 58.54 / 76.68 / 81.22 / 87.12 / 91.91 / 96.78 m/s, in 2 m/s
//! 115.92 / 114.87 / 122.76 m/s (limit points of the blown-down branch,
//! not converged: `converged: false`, safe value the lowest level); in
//! 8 m/s no onset to 150 m/s. One evaluation of the critical pair costs
//! 49 µs at 20 elements and 180 µs at 80 (criterion medians, bench
//! `ge_wind_qep`) against 2.1 ms and 56 ms for the dense QEP; a whole
//! search is dominated by the continued equilibria.

use super::GeModel;
use super::air_load::AirLoads;
use super::element::TipLoad;
use super::qs_critical::{nearest, onset_state};
use super::qs_flutter::{
    C64, EigenPair, prolong_vector, refine_eigenpair, refine_eigenpair_at_scale,
};
use super::qs_levels::{
    ConvergedOnset, ConvergedOutcome, ConvergedSearch, ConvergenceConfig, NEAR, OnsetKind,
    level_rtol, prolong, richardson, summarise, with_elements,
};
use super::qs_wind::{
    MAX_STEP_DISPLACEMENT, MAX_STEP_ROTATION_RAD, branch_equilibrium, continuum_start, on_branch,
};
use super::quasi_static::{
    QsConfig, StepLimit, divergence_indicator, newton_from, state_at, wind_matrices,
};
use super::solver::SystemMatrices;
use super::stability::{StateMotion, spectrum_of};
use crate::numerics::params::{InvalidInput, Kinematics};

/// Largest continuation step as a fraction of the searched range (beside
/// [`NEAR`] of the parameter).
pub const MARCH_OF_RANGE: f64 = 0.02;
/// Dense scan points of the base mesh.
pub const BASE_SCAN_POINTS: usize = 16;
/// Relative width of the base mesh's dense bracket before tracking.
pub const BASE_BRACKET: f64 = 1e-2;
/// Largest relative change of the crossing frequency between levels of
/// one converged flutter onset.
pub const FREQUENCY_RTOL: f64 = 0.1;
/// `|Im λ|` below this fraction of `max(|λ|, 1 s⁻¹)` at the root: a divergence.
const REAL_RTOL: f64 = 1e-8;
const MAX_STEPS: usize = 200;

struct WindLevel<'a, K: Fn(f64) -> Kinematics> {
    model: GeModel,
    load: TipLoad,
    air: &'a AirLoads,
    kin: &'a K,
    known: Vec<(f64, Vec<f64>)>,
    /// Starts prolonged from the coarser level, by parameter.
    guesses: Vec<(f64, Vec<f64>)>,
    /// The continuum tether's aerostat position by length (the branch test).
    tips: Vec<(f64, [f64; 2])>,
    step: f64,
    /// `|λ|` of the base mesh's critical eigenvalue: the scale of the
    /// tracked pair's changes (1/s).
    scale: f64,
    equilibria: usize,
}

impl<K: Fn(f64) -> Kinematics> WindLevel<'_, K> {
    /// The branch equilibrium at `p`, continued from the nearest known one
    /// (a coarser level's state prolonged is a start, not a state).
    fn equilibrium(&mut self, p: f64) -> Option<Vec<f64>> {
        let config = QsConfig::default();
        let cap_at = |s: &Self, x: f64| s.step.max(NEAR * x.abs());
        // from a start: a step-limited Newton alone, kept when on the
        // branch (no fallback to the continuum shape: past a limit point
        // that costs a continuation in the dynamic pressure and fails)
        let solve = |s: &mut Self, y: f64, start: Option<&[f64]>, full: bool| -> Option<Vec<f64>> {
            s.equilibria += 1;
            let k = (s.kin)(y);
            let q = match start {
                Some(q0) if !full => {
                    let mut q = q0.to_vec();
                    let limit = StepLimit {
                        rotation_rad: MAX_STEP_ROTATION_RAD,
                        displacement_m: MAX_STEP_DISPLACEMENT * k.length_m,
                    };
                    newton_from(&s.model, k, s.load, s.air, &config, &mut q, Some(limit)).ok()?;
                    let tip = match s.tips.iter().find(|t| t.0 == k.length_m) {
                        Some(t) => t.1,
                        None => {
                            let t =
                                continuum_start(&s.model, s.air, s.load.force_n[0], k.length_m)?.1;
                            s.tips.push((k.length_m, t));
                            t
                        }
                    };
                    on_branch(&s.model, k.length_m, &q, tip).then_some(q)?
                }
                _ => branch_equilibrium(&s.model, k, s.load, s.air, &config, start)?,
            };
            s.known.push((y, q.clone()));
            Some(q)
        };
        if let Some(k) = self.known.iter().find(|k| k.0 == p) {
            return Some(k.1.clone());
        }
        let known = nearest(&self.known, p).cloned();
        let guess = nearest(&self.guesses, p).cloned();
        // a start next to p: the nearest state, else a prolonged one
        for (s, full) in [(&known, false), (&guess, true)] {
            if let Some(s) = s
                && (s.0 - p).abs() <= cap_at(self, p)
                && let Some(q) = solve(self, p, Some(&s.1), full)
            {
                return Some(q);
            }
        }
        // else continued from the nearest state (or prolonged start)
        let (mut x, mut q) = match (known, guess) {
            (Some(k), _) => k,
            (None, Some(g)) => (g.0, solve(self, g.0, Some(&g.1), true)?),
            (None, None) => return solve(self, p, None, true),
        };
        let mut h = cap_at(self, x);
        let min = 1e-6 * h;
        let mut steps = 0;
        while x != p {
            steps += 1;
            if steps > MAX_STEPS || h < min {
                return None;
            }
            let cap = h.max(NEAR * x.abs()).min(cap_at(self, x));
            let y = if (p - x).abs() <= cap {
                p
            } else {
                x + cap * (p - x).signum()
            };
            match solve(self, y, Some(&q), false) {
                Some(qy) => (x, q) = (y, qy),
                None => h = 0.5 * cap,
            }
        }
        Some(q)
    }

    fn matrices(&mut self, p: f64) -> Option<SystemMatrices> {
        let q = self.equilibrium(p)?;
        let k = (self.kin)(p);
        let st = state_at(&self.model, k, self.load, self.air, StateMotion::AtRest, q).ok()?;
        Some(wind_matrices(&self.model, k, self.load, self.air, &st))
    }

    /// The dense verdict at `p`: `Some(eigenvalue of largest real part)`
    /// when unstable, `Some(None)` when stable, `None` without a state.
    fn dense(&mut self, p: f64) -> Option<Option<C64>> {
        let sys = self.matrices(p)?;
        let s = spectrum_of(&self.model, sys).ok()?;
        if s.max_real <= s.tolerance() {
            return Some(None);
        }
        let e = s
            .eigenvalues
            .iter()
            .filter(|e| e.im >= 0.0)
            .max_by(|a, b| a.re.total_cmp(&b.re))?;
        Some(Some(C64::new(e.re, e.im)))
    }

    fn parity(&mut self, p: f64) -> Option<usize> {
        let q = self.equilibrium(p)?;
        divergence_indicator(&self.model, (self.kin)(p), self.load, self.air, &q).map(|x| x.0)
    }

    /// The pair at `p` tracked from `from`.
    fn track(&mut self, p: f64, from: &EigenPair) -> Option<EigenPair> {
        let sys = self.matrices(p)?;
        // a real pair stays real in complex arithmetic: nudged off the
        // axis so that it can follow a pair that turns complex, and
        // restarted from inverse iteration when the Newton does not settle
        let nudge = C64::new(0.0, 1e-9 * from.lambda.norm().max(self.scale));
        let lambda = if from.lambda.im.abs() <= 1e-12 * from.lambda.norm() {
            from.lambda + nudge
        } else {
            from.lambda
        };
        refine_eigenpair_at_scale(&sys, lambda, Some(&from.vector), self.scale)
            .or_else(|| refine_eigenpair_at_scale(&sys, lambda, None, self.scale))
    }

    /// The root of `Re λ(p)` of the pair tracked from `(p0, pair0)`:
    /// bracketed from `p0` by steps of `move0` (doubled), then Illinois to
    /// relative width `rtol`; the root and the pair there.
    fn root(
        &mut self,
        (lo, hi): (f64, f64),
        (p0, pair0): (f64, EigenPair),
        bracket: Option<(f64, f64)>,
        move0: f64,
        rtol: f64,
        cancel: &dyn Fn() -> bool,
    ) -> Option<(f64, EigenPair)> {
        let mut pairs: Vec<(f64, EigenPair)> = vec![(p0, pair0)];
        // `Re λ`, or +∞ without a state: past a limit point of the branch
        // (where a real eigenvalue passes zero, `det K = 0`) there is no
        // equilibrium nearby and the state snaps: the unstable side.
        let eval = |s: &mut Self, p: f64, pairs: &mut Vec<(f64, EigenPair)>| -> f64 {
            let Some(from) = pairs
                .iter()
                .min_by(|a, b| (a.0 - p).abs().total_cmp(&(b.0 - p).abs()))
                .map(|x| x.1.clone())
            else {
                return f64::INFINITY;
            };
            match s.track(p, &from) {
                Some(e) => {
                    let re = e.lambda.re;
                    pairs.push((p, e));
                    re
                }
                None => f64::INFINITY,
            }
        };
        let ((mut a, mut fa), (mut b, mut fb)) = match bracket {
            Some((a, b)) => (
                (a, eval(self, a, &mut pairs)),
                (b, eval(self, b, &mut pairs)),
            ),
            None => {
                let f0 = pairs[0].1.lambda.re;
                let dir = if f0 > 0.0 { -1.0 } else { 1.0 };
                let mut d = move0.abs().max(1e-6 * p0.abs());
                let (mut x, mut fx) = (p0, f0);
                loop {
                    if cancel() {
                        return None;
                    }
                    let y = (x + dir * d).clamp(lo, hi);
                    if y == x {
                        return None;
                    }
                    let fy = eval(self, y, &mut pairs);
                    if (fy > 0.0) != (fx > 0.0) {
                        break if dir < 0.0 {
                            ((y, fy), (x, fx))
                        } else {
                            ((x, fx), (y, fy))
                        };
                    }
                    (x, fx) = (y, fy);
                    d *= 2.0;
                }
            }
        };
        if !(fa <= 0.0 && fb > 0.0) {
            return None;
        }
        let tol = rtol * a.abs().max(b.abs()).max(1e-300);
        let mut side = 0i8;
        for _ in 0..MAX_STEPS {
            if b - a <= tol {
                break;
            }
            if cancel() {
                return None;
            }
            let mut m = if fb.is_finite() {
                (a * fb - b * fa) / (fb - fa)
            } else {
                0.5 * (a + b)
            };
            if !(m > a && m < b) {
                m = 0.5 * (a + b);
            }
            let eps = 0.5 * tol;
            m = m.clamp(a + eps.min(0.5 * (b - a)), b - eps.min(0.5 * (b - a)));
            let fm = eval(self, m, &mut pairs);
            if fm <= 0.0 {
                (a, fa) = (m, fm);
                if side == -1 {
                    fb *= 0.5;
                }
                side = -1;
            } else {
                (b, fb) = (m, fm);
                if side == 1 {
                    fa *= 0.5;
                }
                side = 1;
            }
        }
        let r = 0.5 * (a + b);
        let pair = pairs
            .iter()
            .min_by(|x, y| (x.0 - r).abs().total_cmp(&(y.0 - r).abs()))?
            .1
            .clone();
        Some((r, pair))
    }
}

fn kind_of(lambda: C64) -> OnsetKind {
    if lambda.im.abs() <= REAL_RTOL * lambda.norm().max(1.0) {
        OnsetKind::Divergence
    } else {
        OnsetKind::Flutter
    }
}

/// The converged onset in wind along `p ∈ [lo, hi]` (module docs).
#[allow(clippy::too_many_arguments)]
pub(super) fn wind_onset<K: Fn(f64) -> Kinematics>(
    model: &GeModel,
    load: TipLoad,
    air: &AirLoads,
    config: &ConvergenceConfig,
    (lo, hi): (f64, f64),
    kin: &K,
    cancel: &dyn Fn() -> bool,
    start: Option<&[f64]>,
) -> Result<ConvergedSearch, InvalidInput> {
    let rtol = level_rtol(config.relative_tolerance);
    let step = MARCH_OF_RANGE * (hi - lo).abs().max(1e-9 * hi.abs());
    let mut n = config.base_elements;
    let mut level = WindLevel {
        model: with_elements(model, n)?,
        load,
        air,
        kin,
        known: start
            .filter(|q| q.len() == 3 * n)
            .map(|q| vec![(lo, q.to_vec())])
            .unwrap_or_default(),
        guesses: Vec::new(),
        tips: Vec::new(),
        step,
        scale: 0.0,
        equilibria: 0,
    };
    let mut equilibria = 0;
    let done = |outcome, e| {
        Ok(ConvergedSearch {
            outcome,
            flutter: None,
            equilibria: e,
        })
    };
    // the base mesh: dense scan and bisection
    let Some(c_lo) = level.parity(lo) else {
        return done(ConvergedOutcome::Failed { at: lo }, level.equilibria);
    };
    match level.dense(lo) {
        None => return done(ConvergedOutcome::Failed { at: lo }, level.equilibria),
        Some(Some(_)) => return done(ConvergedOutcome::Immediate, level.equilibria),
        Some(None) => {}
    }
    let mut a = lo;
    let mut found = None;
    for k in 1..=BASE_SCAN_POINTS {
        if cancel() {
            return done(ConvergedOutcome::Cancelled, level.equilibria);
        }
        let p = lo + (hi - lo) * k as f64 / BASE_SCAN_POINTS as f64;
        match level.dense(p) {
            Some(None) => a = p,
            Some(Some(e)) => {
                found = Some((p, e));
                break;
            }
            // no state on the branch: it ends between a and p
            None => {
                return branch_end(level, model, config, (a, p), rtol, cancel);
            }
        }
    }
    let Some((mut b, mut eb)) = found else {
        return done(ConvergedOutcome::Never { up_to: hi }, level.equilibria);
    };
    while b - a > BASE_BRACKET * b.abs() {
        if cancel() {
            return done(ConvergedOutcome::Cancelled, level.equilibria);
        }
        let m = 0.5 * (a + b);
        match level.dense(m) {
            Some(None) => a = m,
            Some(Some(e)) => (b, eb) = (m, e),
            None => break,
        }
    }
    let Some(sys_b) = level.matrices(b) else {
        return done(ConvergedOutcome::Failed { at: b }, level.equilibria);
    };
    let Some(pair_b) = refine_eigenpair(&sys_b, eb, None) else {
        return done(ConvergedOutcome::Failed { at: b }, level.equilibria);
    };
    level.scale = pair_b.lambda.norm();
    let Some((mut root, mut pair)) =
        level.root((lo, hi), (b, pair_b), Some((a, b)), 0.0, rtol, cancel)
    else {
        return done(ConvergedOutcome::Failed { at: a }, level.equilibria);
    };
    let kind = kind_of(pair.lambda);
    let mut consistent = true;
    let mut roots = vec![(n, root)];
    let mut frequencies = vec![pair.lambda.im.abs()];
    let mut firsts = vec![1.0 / n as f64];
    let outcome = loop {
        let values: Vec<f64> = roots.iter().map(|r| r.1).collect();
        let (value, err, _) = richardson(&values);
        let met = roots.len() >= 3 && err <= config.relative_tolerance * value.abs();
        if (met && consistent) || 2 * n > config.max_elements {
            break summarise(&roots, config, met && consistent);
        }
        if cancel() {
            equilibria += level.equilibria;
            return done(ConvergedOutcome::Cancelled, equilibria);
        }
        // the next level from this one's states near its root
        let window = 4.0 * (NEAR * root.abs() + step);
        let guesses: Vec<(f64, Vec<f64>)> = level
            .known
            .iter()
            .filter(|k| (k.0 - root).abs() <= window)
            .map(|(p, q)| (*p, prolong(q, n)))
            .collect();
        equilibria += level.equilibria;
        let x = prolong_vector(&pair.vector, n);
        n *= 2;
        level = WindLevel {
            model: with_elements(model, n)?,
            load,
            air,
            kin,
            known: Vec::new(),
            guesses,
            tips: std::mem::take(&mut level.tips),
            step,
            scale: level.scale,
            equilibria: 0,
        };
        let expected = match roots.len() {
            1 => 1e-2 * root.abs(),
            _ => 0.5 * (roots[roots.len() - 2].1 - root).abs(),
        };
        let start = level.track(
            root,
            &EigenPair {
                lambda: pair.lambda,
                vector: x,
            },
        );
        let next =
            start.and_then(|p0| level.root((lo, hi), (root, p0), None, expected, rtol, cancel));
        let Some((r, p)) = next else {
            // the tracked mode lost on this mesh: the levels so far, not converged
            break summarise(&roots, config, false);
        };
        let w0 = *frequencies.last().unwrap_or(&0.0);
        let w = p.lambda.im.abs();
        if kind_of(p.lambda) != kind
            || (kind == OnsetKind::Flutter && (w - w0).abs() > FREQUENCY_RTOL * w0)
            || level.parity(r * (1.0 - 1e-6)) != Some(c_lo)
        {
            consistent = false;
        }
        (root, pair) = (r, p);
        roots.push((n, root));
        frequencies.push(w);
        firsts.push(1.0 / n as f64);
    };
    let mut o: ConvergedOnset = outcome;
    o.kind = kind;
    o.frequency_rad_s = (kind == OnsetKind::Flutter).then(|| *frequencies.last().unwrap_or(&0.0));
    o.first_elements = firsts;
    let safe = o.safe_value.max(lo);
    if let Some(q) = level.equilibrium(safe) {
        o.at_safe = onset_state(&level.model, kin(safe), &q);
    }
    equilibria += level.equilibria;
    done(ConvergedOutcome::During(o), equilibria)
}

/// Where the branch ends (no branch state past it: the continuum tether
/// grounded, or a limit point) between `a` (a state) and `b` (none), on
/// every level: bisection on the existence of the state, nested meshes
/// from `level`'s, each level's window about the coarser end.
fn branch_end<K: Fn(f64) -> Kinematics>(
    mut level: WindLevel<'_, K>,
    model: &GeModel,
    config: &ConvergenceConfig,
    (mut a, mut b): (f64, f64),
    rtol: f64,
    cancel: &dyn Fn() -> bool,
) -> Result<ConvergedSearch, InvalidInput> {
    let mut equilibria = 0;
    let mut roots: Vec<(usize, f64)> = Vec::new();
    let mut n = level.model.elements;
    let outcome = loop {
        while b - a > rtol * b.abs() {
            if cancel() {
                return Ok(ConvergedSearch {
                    outcome: ConvergedOutcome::Cancelled,
                    flutter: None,
                    equilibria: equilibria + level.equilibria,
                });
            }
            let m = 0.5 * (a + b);
            if level.equilibrium(m).is_some() {
                a = m;
            } else {
                b = m;
            }
        }
        let root = 0.5 * (a + b);
        roots.push((n, root));
        let values: Vec<f64> = roots.iter().map(|r| r.1).collect();
        let (value, err, _) = richardson(&values);
        let met = roots.len() >= 3 && err <= config.relative_tolerance * value.abs();
        if met || 2 * n > config.max_elements {
            break summarise(&roots, config, met);
        }
        let window = NEAR * root.abs() + level.step;
        let guesses: Vec<(f64, Vec<f64>)> = level
            .known
            .iter()
            .filter(|k| k.0 <= root && root - k.0 <= 4.0 * window)
            .map(|(p, q)| (*p, prolong(q, n)))
            .collect();
        equilibria += level.equilibria;
        n *= 2;
        level = WindLevel {
            model: with_elements(model, n)?,
            guesses,
            known: Vec::new(),
            tips: std::mem::take(&mut level.tips),
            equilibria: 0,
            ..level
        };
        // a state below the coarser end, none above the window
        a = root - window;
        b = root + window;
        while level.equilibrium(a).is_none() {
            a -= window;
            if a <= 0.0 || cancel() {
                break;
            }
        }
        if level.equilibrium(b).is_some() {
            break summarise(&roots, config, false);
        }
    };
    let mut o = outcome;
    o.first_elements = roots.iter().map(|r| 1.0 / r.0 as f64).collect();
    let safe = o.safe_value;
    if let Some(q) = level.equilibrium(safe) {
        o.at_safe = onset_state(&level.model, (level.kin)(safe), &q);
    }
    equilibria += level.equilibria;
    Ok(ConvergedSearch {
        outcome: ConvergedOutcome::During(o),
        flutter: None,
        equilibria,
    })
}
