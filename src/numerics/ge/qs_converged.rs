//! Converged, conservative quasi-static GE onsets (issue 21, SPEC §5
//! applied to the GE criterion): the critical length at a payout rate and
//! the critical rate at a length, in the continuum limit of the mesh, with
//! an estimate of the discretisation error and the safe side of it.
//!
//! **Why.** The FE divergence root of the sliding GE cable converges at
//! first order, from above: in calm air `K` is symmetric and the FE space
//! is a subspace of the continuum's, so the smallest Rayleigh quotient of
//! `K` (and with it the onset, where it passes zero) is over-estimated, by
//! an amount of the order of the first element (the effective tension
//! vanishes at the guide at onset, as for the string of
//! [`crate::numerics::string::converged`]). Measured (thesis tether,
//! `EI = 1000 N m²`): the critical rate at 1300 m is 29.89 / 25.52 / 21.26
//! / 19.15 m/s at 10 / 20 / 40 / 80 elements: the default 20-element answer
//! errs on the unsafe side by about a third.
//!
//! **Method.** Nested meshes `n_k = n₀ 2^k` (`n₀ =` [`BASE_ELEMENTS`]),
//! each level the last with every element bisected: in calm air graded
//! toward the guide (geometric growth from a first element of a quarter
//! of the closed form's bending layer `(EI_eff/b)^(1/3)`, see
//! [`super::airy_onset`] and [`FIRST_ELEMENT_IN_LAYERS`]), in wind (or
//! with [`ConvergenceConfig::graded_in_calm_air`] off) uniform; on each
//! the divergence root (the parameter where the
//! divergence count of [`divergence_indicator`] changes), refined by the
//! safeguarded Illinois regula falsi of [`super::qs_critical`] on
//! `det K` to [`level_rtol`] (`10⁻⁴` of the tolerance: the roots' own error
//! stays out of the estimate). The base level looks first just above the
//! closed form's root in calm air (FE roots lie above the continuum), else
//! scans the range; a finer
//! level looks first just below the coarser root, by the step the levels'
//! ratio predicts, and keeps the base level's lower-end count; each state
//! is solved once per level, and its Newton starts from the nearest
//! equilibrium already found (on finer levels the coarser ones prolonged
//! onto the mesh; in wind only one within [`NEAR`] of it: see
//! `Level::equilibrium`). Richardson removes the first order,
//! `R_k = 2 q_k − q_{k−1}`, and the error of `R_k` is estimated by
//! `|R_k − R_{k−1}|` (three times the true error when the remainder is
//! second order). Levels are added until the estimate is below the
//! tolerance (relative, default [`DEFAULT_RELATIVE_TOLERANCE`]) or
//! [`MAX_CONVERGED_ELEMENTS`] is reached.
//!
//! **Cost.** A state is an equilibrium (banded Newton, O(n)) and a band
//! `LDLᵀ`/LU; a level costs about ten states, so a search costs about
//! ten states on each mesh, dominated by the finest. Measured (thesis
//! tether, calm air, 10 m/s): on uniform meshes EI = 10⁻² N m² stops at
//! 80 elements, 1 and 1000 N m² at 320 (the levels turn from first to
//! second order as the elements resolve the bending layer); on the graded
//! meshes every EI from 10⁻³ to 10³ N m² stops at 80 (three levels), the
//! roots converging at second order from the base mesh on (1323.09 /
//! 1322.65 / 1322.55 m at 20 / 40 / 80 elements for EI = 1000 N m², the
//! closed form 1322.51 m; uniform: 1353.6 / 1334.6 / 1326.4 m), in 22 to
//! 32 equilibria, about 6× fewer instructions than the uniform search.
//! First-order Richardson on second-order levels undershoots: its value
//! lies below the limit and its error estimate is about three times the
//! true error (safe, and said so by `order ≈ 2`).
//!
//! **Conservative.** The answer handed out ([`ConvergedOnset::safe_value`])
//! is the best estimate minus its error, and never above the finest mesh's
//! root (itself an upper bound in calm air).
//!
//! **Bending layer.** At the guide the bending stiffness acts over the
//! heavy-column layer `ℓ = (EI/(ρA g))^(1/3)` (11 m at `EI = 1000 N m²`,
//! 1.1 m at 1 N m², 0.11 m at 10⁻³ N m² for the thesis tether). While the
//! elements are much longer than `ℓ` the FE cable behaves like the string
//! and the extrapolation tends to the string's continuum limit, which is
//! *below* the GE one (bending lifts the boundary, as `EI^(1/3)`): the
//! answer then stays on the safe side by up to the bending lift (about
//! `2ℓ` of length); once `h ≲ ℓ` the levels follow the GE limit itself.
//!
//! **Calm air and wind.** In calm air at a constant rate the damping is
//! positive definite while paying out and `K` symmetric, so by the
//! Kelvin–Tait–Chetaev theorem the divergence root *is* the onset: no
//! eigenvalues are solved. In wind `K` is not symmetric and a flutter
//! onset may come first: with [`ConvergenceConfig::qep_in_wind`] and
//! [`ConvergenceConfig::tracked_wind_onset`] the search is that of
//! [`super::qs_wind_onset`] (the first
//! crossing of the tracked critical eigenvalue, divergence or flutter,
//! on every level, states continued along the parameter;
//! [`ConvergedOnset::kind`], [`ConvergedOnset::frequency_rad_s`]); else
//! the base mesh's QEP just below its divergence root checks for a
//! growing oscillation ([`ConvergedSearch::flutter`]); without
//! `qep_in_wind`, the divergence alone (the sign change of `det K`,
//! [`super::quasi_static::divergence_indicator`]) on uniform meshes.

use super::GeModel;
use super::air_load::AirLoads;
use super::element::TipLoad;
use super::qs_critical::{
    OnsetState, QsSearchConfig, along_length, along_rate, nearest, onset_state, search_onset_from,
};
pub use super::qs_levels::{
    BASE_ELEMENTS, ConvergedOnset, ConvergedOutcome, ConvergedSearch, ConvergenceConfig,
    DEFAULT_RELATIVE_TOLERANCE, MAX_CONVERGED_ELEMENTS, MAX_RELATIVE_TOLERANCE,
    MIN_RELATIVE_TOLERANCE, NEAR, OnsetKind, ROOT_RTOL, level_rtol, richardson, with_elements,
};
use super::qs_levels::{prolong, summarise};
pub use super::qs_mesh::{
    CalmGuess, FIRST_ELEMENT_IN_LAYERS, bisect_nodes, calm_length_guess, calm_rate_guess,
    graded_nodes,
};
use super::qs_root::{Scan, refine_root, scan_change};
use super::qs_wind::{branch_equilibrium, continuum_start};
use super::quasi_static::{QsConfig, divergence_indicator, wind_equilibrium, wind_stability};
use super::stability::StateMotion;
use crate::numerics::params::{InvalidInput, Kinematics, require_finite, require_positive};

/// Scan points of the first level.
const SCAN_POINTS: usize = 16;

/// One level's divergence root.
enum LevelRoot {
    Root {
        at: f64,
        /// Equilibria found on this level, by parameter.
        known: Vec<(f64, Vec<f64>)>,
        /// The lower end's count.
        c_lo: usize,
    },
    Immediate,
    Never,
    Failed,
    Cancelled,
}

/// Where a finer level's root is looked for first: just below the coarser
/// root `prev`, by about `expected_move` (the next step of the levels'
/// sequence, from the ratio of the last two).
#[derive(Clone, Copy)]
struct Hint {
    prev: f64,
    expected_move: f64,
}

struct Level<'a, K: Fn(f64) -> Kinematics> {
    model: GeModel,
    load: TipLoad,
    air: &'a AirLoads,
    kin: &'a K,
    known: Vec<(f64, Vec<f64>)>,
    /// Indicators already evaluated on this level, by parameter.
    seen: Vec<(f64, Option<(usize, f64)>)>,
    equilibria: usize,
}

impl<K: Fn(f64) -> Kinematics> Level<'_, K> {
    fn equilibrium(&mut self, p: f64) -> Option<Vec<f64>> {
        self.equilibria += 1;
        // In wind a Newton started from a state far along the parameter
        // (the scan's previous point, ~100 m shorter) can land on a
        // spurious compressed branch whose `det K` is negative: the
        // 20-element "divergence" at 142 m in an 8 m/s wind that no finer
        // mesh reproduced (issue 21) was one. There the state is solved
        // afresh (straight, then continued in the dynamic pressure) unless
        // a known one lies within `NEAR` of it.
        let calm = self.air.is_calm();
        let start = nearest(&self.known, p)
            .filter(|k| calm || (k.0 - p).abs() <= NEAR * p.abs().max(k.0.abs()))
            .map(|k| k.1.clone());
        // In wind: only the branch reached by paying out (`qs_wind`).
        let q = if calm {
            wind_equilibrium(
                &self.model,
                (self.kin)(p),
                self.load,
                self.air,
                &QsConfig::default(),
                start.as_deref(),
            )
            .ok()?
            .q
        } else {
            branch_equilibrium(
                &self.model,
                (self.kin)(p),
                self.load,
                self.air,
                &QsConfig::default(),
                start.as_deref(),
            )?
        };
        self.known.push((p, q.clone()));
        Some(q)
    }

    fn count(&mut self, p: f64) -> Option<usize> {
        self.inertia(p).map(|x| x.0)
    }

    /// The divergence count and `ln |det|` at `p` ([`divergence_indicator`]),
    /// each state solved once.
    fn inertia(&mut self, p: f64) -> Option<(usize, f64)> {
        if let Some(x) = self.seen.iter().find(|x| x.0 == p) {
            return x.1;
        }
        let x = self.equilibrium(p).and_then(|q| {
            divergence_indicator(&self.model, (self.kin)(p), self.load, self.air, &q)
        });
        self.seen.push((p, x));
        x
    }

    fn state(&mut self, p: f64) -> OnsetState {
        match self.equilibrium(p) {
            Some(q) => onset_state(&self.model, (self.kin)(p), &q),
            None => OnsetState::default(),
        }
    }

    /// The divergence root in `[lo, hi]` to relative width `rtol`;
    /// `c_lo`: the lower end's count when known (a finer level keeps the
    /// base level's), `hint`: where a finer level looks first.
    fn root(
        mut self,
        (lo, hi): (f64, f64),
        c_lo: Option<usize>,
        hint: Option<Hint>,
        rtol: f64,
        cancel: &dyn Fn() -> bool,
    ) -> (LevelRoot, usize) {
        let c_lo = match c_lo {
            Some(c) => c,
            None => {
                let Some(c) = self.count(lo) else {
                    return (LevelRoot::Failed, self.equilibria);
                };
                if c > 0 && self.air.is_calm() {
                    return (LevelRoot::Immediate, self.equilibria);
                }
                c
            }
        };
        let mut bracket = None;
        if let Some(Hint {
            prev,
            expected_move,
        }) = hint
        {
            // FE roots converge from above: the finer root is expected at
            // `prev − m`; bracket it by `[prev − 1.5 m, prev − 0.5 m]`,
            // widened by 4× steps where it is not.
            let m = expected_move.abs().max(1e-4 * prev.abs()).max(1e-12);
            let mut b = (prev - 0.5 * m).clamp(lo, hi);
            if self.count(b) == Some(c_lo) {
                // above the guess: up to the coarser root, then the scan
                let top = prev.min(hi);
                if top > b && self.count(top) != Some(c_lo) {
                    bracket = Some((b, top));
                }
            } else {
                let mut d = m;
                loop {
                    if cancel() {
                        return (LevelRoot::Cancelled, self.equilibria);
                    }
                    let a = (b - d).max(lo);
                    if self.count(a) == Some(c_lo) {
                        bracket = Some((a, b));
                        break;
                    }
                    if a <= lo {
                        // unstable down to the lower end on this mesh
                        return (LevelRoot::Immediate, self.equilibria);
                    }
                    b = a;
                    d *= 4.0;
                }
            }
        }
        if bracket.is_none() {
            self.count(lo);
            match scan_change(
                (lo, hi),
                SCAN_POINTS,
                |p| Some(self.count(p) == Some(c_lo)),
                cancel,
            ) {
                Scan::Bracket { a, b, .. } => bracket = Some((a, b)),
                Scan::Unchanged => return (LevelRoot::Never, self.equilibria),
                Scan::Cancelled => return (LevelRoot::Cancelled, self.equilibria),
            }
        }
        let Some((a, b)) = bracket else {
            return (LevelRoot::Never, self.equilibria);
        };
        let ends = (self.inertia(a), self.inertia(b));
        let Some((a, b)) = refine_root((a, b), ends, rtol, |p| self.inertia(p), cancel) else {
            return (LevelRoot::Cancelled, self.equilibria);
        };
        let e = self.equilibria;
        (
            LevelRoot::Root {
                at: 0.5 * (a + b),
                known: self.known,
                c_lo,
            },
            e,
        )
    }
}

/// Where the next level looks for its root: below the last by the last
/// step times the ratio of the last two (first order: a half), 1 % on
/// the first refinement.
fn hint(roots: &[(usize, f64)], guess: Option<&CalmGuess>) -> Option<Hint> {
    let k = roots.len();
    let q = |i: usize| roots[i].1;
    match (k, guess) {
        // the closed form: the base root just above it (FE roots are
        // above the continuum), looked for in [g − 10⁻⁴ g, g + 2·10⁻³ g]
        (0, Some(g)) => {
            let (d, e) = (2e-3 * g.root.abs(), 1e-4 * g.root.abs());
            Some(Hint {
                prev: g.root + d,
                expected_move: 2.0 * (d + e),
            })
        }
        (0, None) => None,
        // graded meshes converge at second order: the next root about
        // three quarters of the way to the closed form
        (1, Some(g)) if q(0) > g.root => Some(Hint {
            prev: q(0),
            expected_move: 0.75 * (q(0) - g.root),
        }),
        (1, _) => Some(Hint {
            prev: q(0),
            expected_move: 1e-2 * q(0),
        }),
        (2, Some(_)) => Some(Hint {
            prev: q(1),
            expected_move: 0.25 * (q(0) - q(1)),
        }),
        (2, None) => Some(Hint {
            prev: q(1),
            expected_move: 0.5 * (q(0) - q(1)),
        }),
        _ => {
            let (d1, d2) = (q(k - 3) - q(k - 2), q(k - 2) - q(k - 1));
            let ratio = if d1 != 0.0 {
                (d2 / d1).clamp(0.1, 1.0)
            } else {
                0.5
            };
            Some(Hint {
                prev: q(k - 1),
                expected_move: ratio * d2,
            })
        }
    }
}

/// The converged divergence onset along `p ∈ [lo, hi]` of the state
/// `kin(p)` (module docs); `model` gives the section, tip and gravity
/// (its mesh is replaced by the levels').
#[allow(clippy::too_many_arguments)]
pub fn converged_onset(
    model: &GeModel,
    net_buoyancy_n: f64,
    air: &AirLoads,
    config: &ConvergenceConfig,
    (lo, hi): (f64, f64),
    kin: impl Fn(f64) -> Kinematics,
    cancel: &dyn Fn() -> bool,
    start: Option<&[f64]>,
    guess: Option<CalmGuess>,
) -> Result<ConvergedSearch, InvalidInput> {
    config.validate()?;
    // graded meshes in calm air only (wind: uniform, unchanged)
    let guess = guess.filter(|_| air.is_calm() && config.graded_in_calm_air);
    let mut nodes = guess.map(|g| graded_nodes(config.base_elements, g.first_element));
    require_positive("net_buoyancy_n", net_buoyancy_n)?;
    require_finite("range.min", lo)?;
    require_finite("range.max", hi)?;
    if hi < lo {
        return Err(InvalidInput::new(
            "range.max",
            format!("must be at least the lower end {lo}, got {hi}"),
        ));
    }
    let load = TipLoad {
        force_n: [net_buoyancy_n, 0.0],
        moment_n_m: 0.0,
    };
    if !air.is_calm() && config.qep_in_wind && config.tracked_wind_onset {
        return super::qs_wind_onset::wind_onset(
            model,
            load,
            air,
            config,
            (lo, hi),
            &kin,
            cancel,
            start,
        );
    }
    let mut equilibria = 0;
    let flutter_check = !air.is_calm() && config.qep_in_wind;
    let mut flutter = None;
    let mut roots: Vec<(usize, f64)> = Vec::new();
    let mut first_elements: Vec<f64> = Vec::new();
    let mut known: Vec<(f64, Vec<f64>)> = start
        .filter(|q| q.len() == 3 * config.base_elements && nodes.is_none())
        .map(|q| vec![(lo, q.to_vec())])
        .unwrap_or_default();
    let mut n = config.base_elements;
    let mut finest: Option<GeModel> = None;
    let mut finest_known = Vec::new();
    let mut c_base = None;
    let rtol = level_rtol(config.relative_tolerance);
    let outcome = loop {
        let m = match &nodes {
            Some(z) => model.with_nodes(z)?,
            None => with_elements(model, n)?,
        };
        let level = Level {
            model: m.clone(),
            load,
            air,
            kin: &kin,
            known: std::mem::take(&mut known),
            seen: Vec::new(),
            equilibria: 0,
        };
        let (r, e) = level.root(
            (lo, hi),
            c_base,
            hint(
                &roots,
                guess.as_ref().filter(|g| (lo..=hi).contains(&g.root)),
            ),
            rtol,
            cancel,
        );
        equilibria += e;
        match r {
            LevelRoot::Root { at, known: k, c_lo } => {
                c_base = Some(c_lo);
                roots.push((n, at));
                first_elements.push(m.ops.len(0));
                known = k.iter().map(|(p, q)| (*p, prolong(q, n))).collect();
                finest = Some(m);
                finest_known = k;
            }
            LevelRoot::Immediate => break ConvergedOutcome::Immediate,
            LevelRoot::Failed => break ConvergedOutcome::Failed { at: lo },
            LevelRoot::Cancelled => break ConvergedOutcome::Cancelled,
            LevelRoot::Never => {
                if roots.is_empty() {
                    break ConvergedOutcome::Never { up_to: hi };
                }
                // Stable to hi on a finer mesh although a coarser one
                // diverged: keep the levels found.
                break ConvergedOutcome::During(summarise(&roots, config, false));
            }
        }
        let values: Vec<f64> = roots.iter().map(|r| r.1).collect();
        let (value, err, _) = richardson(&values);
        if roots.len() >= 3 && err <= config.relative_tolerance * value.abs() {
            break ConvergedOutcome::During(summarise(&roots, config, true));
        }
        if 2 * n > config.max_elements {
            break ConvergedOutcome::During(summarise(&roots, config, false));
        }
        n *= 2;
        nodes = nodes.map(|z| bisect_nodes(&z));
    };
    // In wind: the base mesh's QEP just below its own divergence root
    // (or at the upper end without one) must be free of growing
    // oscillations; else a flutter onset comes first and the QEP search
    // of the base mesh is reported instead (not converged).
    if flutter_check && !matches!(outcome, ConvergedOutcome::Cancelled) {
        let base = with_elements(model, config.base_elements)?;
        let probe = match (&outcome, roots.first()) {
            (_, Some(&(_, r))) => r * (1.0 - 1e-3),
            (ConvergedOutcome::Never { up_to }, None) => *up_to,
            _ => lo,
        };
        let k = kin(probe);
        let branch = continuum_start(&base, air, net_buoyancy_n, k.length_m).map(|s| s.0);
        let start_q = start
            .filter(|q| q.len() == base.dofs())
            .or(branch.as_deref());
        let ok = match wind_stability(
            &base,
            k,
            load,
            air,
            StateMotion::AtRest,
            &QsConfig::default(),
            start_q,
        ) {
            Ok(w) => {
                let tol = w.spectrum.tolerance();
                w.spectrum
                    .eigenvalues
                    .iter()
                    .filter(|e| e.im != 0.0)
                    .all(|e| e.re <= tol)
            }
            Err(_) => false,
        };
        equilibria += 1;
        if !ok {
            let s = search_onset_from(
                &base,
                net_buoyancy_n,
                air,
                StateMotion::AtRest,
                &QsSearchConfig::default(),
                (lo, hi),
                &kin,
                cancel,
                start_q,
            )?;
            equilibria += s.equilibria;
            flutter = Some(s.onset);
        }
    }
    let outcome = match outcome {
        ConvergedOutcome::During(mut c) => {
            c.first_elements = first_elements.clone();
            if let Some(m) = finest {
                let mut level = Level {
                    model: m,
                    load,
                    air,
                    kin: &kin,
                    known: finest_known,
                    seen: Vec::new(),
                    equilibria: 0,
                };
                c.at_safe = level.state(c.safe_value.max(lo));
                equilibria += level.equilibria;
            }
            ConvergedOutcome::During(c)
        }
        o => o,
    };
    Ok(ConvergedSearch {
        outcome,
        flutter,
        equilibria,
    })
}

/// Converged quasi-static critical length of a payout at constant rate
/// `rate_m_s` between `min_length_m` and `max_length_m`.
#[allow(clippy::too_many_arguments)]
pub fn converged_critical_length(
    model: &GeModel,
    net_buoyancy_n: f64,
    air: &AirLoads,
    rate_m_s: f64,
    config: &ConvergenceConfig,
    (min_length_m, max_length_m): (f64, f64),
    cancel: &dyn Fn() -> bool,
) -> Result<ConvergedSearch, InvalidInput> {
    require_positive("min_length_m", min_length_m)?;
    require_finite("rate_m_s", rate_m_s)?;
    converged_onset(
        model,
        net_buoyancy_n,
        air,
        config,
        (min_length_m, max_length_m),
        along_length(rate_m_s, 0.0),
        cancel,
        None,
        calm_length_guess(model, net_buoyancy_n, rate_m_s),
    )
}

/// Converged quasi-static critical payout rate at one length (searched on
/// `[10⁻³, 1] · max_rate_m_s`, as [`super::qs_critical::critical_rate`]).
#[allow(clippy::too_many_arguments)]
pub fn converged_critical_rate(
    model: &GeModel,
    net_buoyancy_n: f64,
    air: &AirLoads,
    length_m: f64,
    max_rate_m_s: f64,
    config: &ConvergenceConfig,
    cancel: &dyn Fn() -> bool,
    start: Option<&[f64]>,
) -> Result<ConvergedSearch, InvalidInput> {
    require_positive("length_m", length_m)?;
    require_positive("max_rate_m_s", max_rate_m_s)?;
    converged_onset(
        model,
        net_buoyancy_n,
        air,
        config,
        (1e-3 * max_rate_m_s, max_rate_m_s),
        along_rate(length_m),
        cancel,
        start,
        calm_rate_guess(model, net_buoyancy_n, length_m),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::ge::element::node;

    #[test]
    fn richardson_removes_a_first_order_error() {
        // q_k = 5 + 3/n_k + 7/n_k², n_k = 20·2^k
        let q: Vec<f64> = (0..4)
            .map(|k| {
                let n = 20.0 * 2f64.powi(k);
                5.0 + 3.0 / n + 7.0 / (n * n)
            })
            .collect();
        let (v, e, order) = richardson(&q);
        assert!((v - 5.0).abs() < e, "value {v}, error {e}");
        assert!((order - 1.0).abs() < 0.1, "order {order}");
    }

    #[test]
    fn prolongation_is_exact_on_linear_fields() {
        let n = 3;
        let q: Vec<f64> = (1..=n)
            .flat_map(|k| {
                let z = k as f64 / n as f64;
                [2.0 * z, -z, 0.5 * z]
            })
            .collect();
        let f = prolong(&q, n);
        for k in 1..=2 * n {
            let z = k as f64 / (2 * n) as f64;
            let v = node(&f, k);
            assert!((v[0] - 2.0 * z).abs() < 1e-15 && (v[1] + z).abs() < 1e-15);
            assert!((v[2] - 0.5 * z).abs() < 1e-15);
        }
    }
}
