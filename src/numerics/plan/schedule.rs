//! The fastest safe schedule: a forward/backward speed-profile pass along
//! the path (time-optimal velocity planning with a state-dependent rate
//! ceiling), the SPEC §7 static-ceiling bound, and the best constant-rate
//! plan with the same limits.
//!
//! **Method.** Let `s ∈ [0, S]` be the distance paid out (or hauled in),
//! `L = L₀ + σ s` (`σ = ±1`), `u = ṡ²` and `α = s̈` (so `L̇ = σ ṡ`,
//! `L̈ = σ α`). On a uniform grid of `N` segments the schedule has constant
//! `α` per segment, so `u` is linear in `s` and every constraint below is
//! linear in `s` on a segment: checking both ends makes the whole segment
//! admissible (exactly, not only at the nodes). The constraints are
//!
//! ```text
//! stability   u + σ (m/ρA + L) α ≤ ((1 − r)(1 − ε)F − ρA g L)/ρA   (T_eff ≥ ε(1 − r)F)
//! winch       u ≤ v_max²,  |α| ≤ a_max
//! tension     max_x T(x) ≤ allowable   (a lower bound on L̈ at each L)
//! ```
//!
//! 1. *Backward pass* from rest at the target: `V_i` = the largest `u` at
//!    node `i` from which one admissible segment reaches `u ≤ V_{i+1}`
//!    (a two-variable LP in `(u_i, α)`, solved on its vertices): the
//!    viability limit.
//! 2. *Forward pass* from rest: on each segment take the largest
//!    admissible `α` with `u_{i+1} ≤ V_{i+1}`. The reachable set is
//!    monotone in `u_i`, so this greedy choice maximises `u` at every node:
//!    the minimum time on the grid. Time of a segment: `2h/(√u_i + √u_{i+1})`.
//!
//! The grid error of the duration is `O(h)`; with 4000 segments it is far
//! below the 3 % asked of the plan.

use crate::numerics::plan::air::Air;
use crate::numerics::plan::pass::{Grid, pass, static_check};
pub use crate::numerics::plan::pass::{Knot, Phase, PlanOutcome, Schedule, SegmentLimit};
use crate::numerics::plan::{PlanProblem, STABILITY_MARGIN};

/// How a plan is made beyond the problem: the air, and a jerk limit.
#[derive(Clone, Debug, Default)]
pub struct PlanOptions {
    pub air: Air,
    /// Largest rate of change of the winch acceleration (m/s³), if limited.
    pub max_jerk_m_s3: Option<f64>,
}

/// The fastest schedule (see the module docs), or why none exists: calm
/// air, no jerk limit.
pub fn fastest(p: &PlanProblem) -> PlanOutcome {
    fastest_with(p, &PlanOptions::default())
}

/// The fastest schedule in `options.air`; with a jerk limit, the S-curve
/// schedule of [`super::jerk`].
pub fn fastest_with(p: &PlanProblem, options: &PlanOptions) -> PlanOutcome {
    if let Some(b) = static_check(p, &options.air) {
        return PlanOutcome::Infeasible(b);
    }
    match options.max_jerk_m_s3 {
        None => pass(p, STABILITY_MARGIN, &options.air),
        Some(j) => super::jerk::jerk_limited(p, &options.air, j),
    }
}

/// The SPEC §7 orientation bound: the same pass with the static rate
/// ceiling `v ≤ √((1 − r)F/ρA − gL)` (acceleration terms and margin
/// dropped) and the winch limits. Exact for that problem on the grid.
/// `None` when the static ceiling is negative somewhere on the path.
///
/// Derivation check: with `C(L) = (1 − r)F/ρA − gL` and braking at
/// `a_max` to rest at `L_T`, `C(L) − 2a_max(L_T − L) = C(L_T) + (g −
/// 2a_max)(L_T − L) > 0` when `a_max < g/2`, and the ramps meet at
/// `u = a_max(L_T − L₀) < C` there too: the static ceiling never binds and
/// the bound is the winch trapezoid. Thesis data to 1200 m at 40 m/s and
/// 2 m/s²: 20 s up (400 m), 399 m at 40 m/s (9.975 s), 20 s down: 49.975 s
/// (the SPEC's 50.0 s). The plan equals it because the acceleration terms
/// do not bind either: at the end of the ramp (401 m, 40 m/s, +2 m/s²)
/// `T_eff = 950 − 20 − 0.078·11.81·401 − 0.078·1600 = 436 N > 0`.
pub fn static_ceiling_bound_s(p: &PlanProblem) -> Option<f64> {
    static_ceiling_bound_s_with(p, &Air::Calm)
}

/// [`static_ceiling_bound_s`] with the static ceiling `√(S(L)/ρA)` of
/// `air` (in wind: the stability criterion at rest on the equilibrium).
pub fn static_ceiling_bound_s_with(p: &PlanProblem, air: &Air) -> Option<f64> {
    let g = Grid::with_air(p, 0.0, air);
    let n = g.segments();
    let a_max = p.winch.max_acceleration_m_s2;
    let w2 = p.winch.max_rate_m_s.powi(2);
    if g.cap.iter().any(|&c| c < 0.0) {
        return None;
    }
    let mut v = vec![0.0; n + 1];
    for i in (0..n).rev() {
        v[i] = w2.min(g.cap[i]).min(v[i + 1] + 2.0 * g.h * a_max);
    }
    let mut u = 0.0f64;
    let mut t = 0.0;
    for i in 0..n {
        let next = if i + 1 == n {
            0.0
        } else {
            (u + 2.0 * g.h * a_max).min(v[i + 1])
        };
        let speed = u.sqrt() + next.sqrt();
        if speed <= 0.0 {
            return None;
        }
        t += 2.0 * g.h / speed;
        u = next;
    }
    Some(t)
}

/// A trapezoidal plan at one constant rate with ramps at the winch's
/// acceleration limit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConstantRatePlan {
    /// Cruise rate (m/s, magnitude).
    pub rate_m_s: f64,
    pub duration_s: f64,
}

/// Whether the trapezoid at path speed `v` keeps every constraint; in
/// wind with the loads of `grid` interpolated between its nodes.
fn trapezoid_ok(p: &PlanProblem, v: f64, grid: Option<&Grid>) -> bool {
    let a = p.winch.max_acceleration_m_s2;
    let sigma = p.direction();
    let l0 = p.system.initial_length_m;
    let total = (p.target_length_m - l0).abs();
    let ramp = v * v / (2.0 * a);
    if 2.0 * ramp > total * (1.0 + 1e-12) {
        return false;
    }
    let at = |s: f64| l0 + sigma * s;
    // (s_start, s_end, u_start, u_end, α). A constant rate is safe to the
    // target (SPEC §1 safe rate): the cruise is checked up to the target,
    // without credit for the braking that ends it.
    let phases = [
        (0.0, ramp, 0.0, v * v, a),
        (ramp, total, v * v, v * v, 0.0),
        (total - ramp, total, v * v, 0.0, -a),
    ];
    let f = STABILITY_MARGIN * p.reserve_buoyancy_n();
    phases.iter().all(|&(s0, s1, u0, u1, alpha)| {
        let acc = sigma * alpha;
        [(s0, u0), (s1, u1)].iter().all(|&(s, u)| {
            let l = at(s);
            let tol = 1e-9 * p.system.net_buoyancy_n;
            if let Some(g) = grid {
                let sy = &p.system;
                let rho_a = sy.mass_per_length_kg_m;
                // T_eff − εR = k ρA (cap − v² − x L̈)
                let ok = Grid::shortfall_n(rho_a, g.stability_at(l), u, acc) <= tol;
                let rated = match (p.allowable_tension_n, &g.rest_tensions) {
                    (Some(allow), Some(r)) => {
                        let w: Vec<f64> = r.iter().map(|x| x.0).collect();
                        let t: Vec<f64> = r.iter().map(|x| x.1).collect();
                        let rest = crate::numerics::plan::air::RestLoads {
                            stability_tension_n: 0.0,
                            winch_tension_n: g.interpolate(&w, l),
                            top_tension_n: g.interpolate(&t, l),
                            altitude_m: l,
                            ascent: crate::numerics::plan::ascent::AscentDrag::NONE,
                        };
                        rest.max_tension_at_n(sy, l, acc) <= allow * (1.0 + 1e-12)
                    }
                    _ => true,
                };
                return ok && rated;
            }
            p.effective_tension_n(l, u.sqrt(), acc) >= f - tol
                && p.allowable_tension_n
                    .is_none_or(|allow| p.max_tension_n(l, acc) <= allow * (1.0 + 1e-12))
        })
    })
}

/// The best constant-rate plan with the same limits: the largest cruise
/// rate that is stable at constant rate all the way to the target (the
/// SPEC §1 safe rate, with the reserve and the margin) and whose ramps at
/// the acceleration limit are admissible,
/// found by bisection (60 halvings). `None` when no rate is.
pub fn best_constant_rate(p: &PlanProblem) -> Option<ConstantRatePlan> {
    best_constant_rate_with(p, &PlanOptions::default())
}

/// Duration of a rest-to-rest move over `distance` cruising at `v` with
/// ramps limited by acceleration `a` and, if given, jerk `j`: the
/// trapezoid `D/v + v/a`, or the classical 7-segment S-curve
/// `D/v + v/a + a/j` when `v ≥ a²/j` and `D/v + 2√(v/j)` below
/// (the ramps then never reach `a`).
pub fn rest_to_rest_time_s(distance: f64, v: f64, a: f64, j: Option<f64>) -> f64 {
    match j {
        None => distance / v + v / a,
        Some(j) if v >= a * a / j => distance / v + v / a + a / j,
        Some(j) => distance / v + 2.0 * (v / j).sqrt(),
    }
}

/// [`best_constant_rate`] in `options.air` (loads interpolated on the
/// pass's grid) and, with a jerk limit, S-curve ramps
/// ([`rest_to_rest_time_s`]; their states lie between those of the
/// trapezoid's, which are the ones checked).
pub fn best_constant_rate_with(p: &PlanProblem, options: &PlanOptions) -> Option<ConstantRatePlan> {
    if static_check(p, &options.air).is_some() {
        return None;
    }
    let grid = (!options.air.is_calm()).then(|| Grid::with_air(p, STABILITY_MARGIN, &options.air));
    let grid = grid.as_ref();
    let trapezoid_ok = |p: &PlanProblem, v: f64| trapezoid_ok(p, v, grid);
    let a = p.winch.max_acceleration_m_s2;
    let total = (p.target_length_m - p.system.initial_length_m).abs();
    let top = p.winch.max_rate_m_s.min((a * total).sqrt());
    let v = if trapezoid_ok(p, top) {
        top
    } else {
        let (mut lo, mut hi) = (0.0, top);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if trapezoid_ok(p, mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    };
    // With a jerk limit the two S-curve ramps must fit in the distance:
    // each covers `v·(v/a + a/j)/2` (or `v√(v/j)` below `a²/j`).
    let v = match options.max_jerk_m_s3 {
        None => v,
        Some(j) => {
            let ramps = |v: f64| {
                if v >= a * a / j {
                    v * (v / a + a / j)
                } else {
                    2.0 * v * (v / j).sqrt()
                }
            };
            if ramps(v) <= total {
                v
            } else {
                let (mut lo, mut hi) = (0.0, v);
                for _ in 0..60 {
                    let mid = 0.5 * (lo + hi);
                    if ramps(mid) <= total {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                lo
            }
        }
    };
    (v > 0.0).then(|| ConstantRatePlan {
        rate_m_s: v,
        duration_s: rest_to_rest_time_s(total, v, a, options.max_jerk_m_s3),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::params::AerostatSystem;
    use crate::numerics::plan::{BindingLimit, Winch};

    fn thesis(target: f64, reserve: f64) -> PlanProblem {
        PlanProblem::new(
            AerostatSystem::thesis(),
            target,
            Winch::new(40.0, 2.0).unwrap(),
            reserve,
            None,
        )
        .unwrap()
    }

    #[test]
    fn thesis_bound_is_the_trapezoid() {
        // 1199 m at 40 m/s, 2 m/s²: 20 s up, 9.975 s cruise, 20 s down.
        let p = thesis(1200.0, 0.05);
        let bound = static_ceiling_bound_s(&p).unwrap();
        assert!((bound - 49.975).abs() < 1e-3, "{bound}");
        let PlanOutcome::Feasible(s) = fastest(&p) else {
            panic!("feasible")
        };
        assert!((s.duration_s - 49.975).abs() < 5e-3, "{}", s.duration_s);
        assert!(s.worst_violation_n <= 1e-9);
    }

    #[test]
    fn beyond_the_lift_limit_is_infeasible() {
        let p = thesis(1290.0, 0.05);
        match fastest(&p) {
            PlanOutcome::Infeasible(BindingLimit::StaticLift { limit_m, .. }) => {
                assert!((limit_m - 950.0 / (0.078 * 9.81) * (1.0 - STABILITY_MARGIN)).abs() < 1e-9)
            }
            other => panic!("{other:?}"),
        }
    }
}
