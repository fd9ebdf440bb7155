//! The jerk-limited (S-curve) schedule: the speed-profile pass's schedule
//! with its velocity averaged over a sliding window of width `τ`,
//!
//! ```text
//! L̇_j(t) = (1/τ) ∫_{t−τ}^{t} L̇(t') dt',   L̈_j(t) = (L̇(t) − L̇(t − τ))/τ,
//! L⃛_j(t) = (L̈(t) − L̈(t − τ))/τ
//! ```
//!
//! (the schedule held at rest before its start and after its end). The
//! average keeps `|L̇_j| ≤ v_max`, `|L̈_j| ≤ a_max`, the distance, and rest
//! at both ends; it lasts `τ` longer. `τ` is the smallest width with
//! `max_t |L̈(t) − L̈(t − τ)| ≤ j_max τ` (fixed-point iteration from the
//! largest jump of `L̈` over `j_max`), so `|L⃛_j| ≤ j_max` everywhere.
//! For the winch trapezoid (accelerate, cruise longer than `τ`, brake)
//! `τ = a_max/j_max` and the result is the classical 7-segment S-curve,
//! of duration `D/v + v/a + a/j`.
//!
//! The averaged states are not those the pass checked, so the S-curve is
//! checked against every constraint (at its knots and at
//! [`CHECK_SUBDIVISIONS`] points inside each interval, with the pass's
//! loads interpolated between its nodes: exact in calm air, where they
//! are linear in `L`); while it falls short, the pass is rerun with the
//! stability margin raised (and the allowable tension lowered) by twice
//! the shortfall, at most [`MAX_TIGHTENINGS`] times.

use crate::numerics::plan::air::{Air, RestLoads};
use crate::numerics::plan::pass::{Grid, Knot, PlanOutcome, Schedule, pass_on, static_check};
use crate::numerics::plan::{BindingLimit, PlanProblem, STABILITY_MARGIN};

/// Reruns of the pass with a tighter margin.
pub const MAX_TIGHTENINGS: usize = 12;
/// Points checked inside each interval of the S-curve.
pub const CHECK_SUBDIVISIONS: usize = 4;
/// Fixed-point iterations on the window width.
const WINDOW_ITERATIONS: usize = 50;

/// Acceleration of the schedule at `t`, right-continuous, 0 outside it.
fn accel(s: &Schedule, t: f64) -> f64 {
    if t < 0.0 || t >= s.duration_s {
        return 0.0;
    }
    s.at(t).acceleration_m_s2
}

/// `max_t |L̈(t) − L̈(t − τ)|` (the difference is piecewise constant, with
/// breaks at the knots and the knots shifted by `τ`).
fn window_oscillation(s: &Schedule, tau: f64) -> f64 {
    s.knots
        .iter()
        .flat_map(|k| [k.time_s, k.time_s + tau])
        .map(|b| (accel(s, b) - accel(s, b - tau)).abs())
        .fold(0.0, f64::max)
}

/// The window width for `max_jerk` (s).
pub fn window_s(s: &Schedule, max_jerk: f64) -> f64 {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    let mut jump = 0.0f64;
    let mut prev = 0.0;
    for k in &s.knots {
        let a = if k.time_s >= s.duration_s {
            0.0
        } else {
            k.acceleration_m_s2
        };
        jump = jump.max((a - prev).abs());
        prev = a;
        lo = lo.min(a);
        hi = hi.max(a);
    }
    let range = (hi.max(0.0) - lo.min(0.0)).max(0.0);
    let mut tau = jump / max_jerk;
    for _ in 0..WINDOW_ITERATIONS {
        if tau <= 0.0 {
            return 0.0;
        }
        let need = window_oscillation(s, tau) / max_jerk;
        if need <= tau * (1.0 + 1e-12) {
            return tau;
        }
        tau = need;
    }
    // Always enough: the window's oscillation never exceeds the range.
    range / max_jerk
}

/// The schedule averaged over a window of `tau` seconds (module docs).
pub fn average(s: &Schedule, tau: f64) -> Schedule {
    if tau <= 0.0 {
        return s.clone();
    }
    let end = s.duration_s + tau;
    let mut breaks: Vec<f64> = s
        .knots
        .iter()
        .flat_map(|k| [k.time_s, k.time_s + tau])
        .filter(|&t| (0.0..=end).contains(&t))
        .collect();
    breaks.push(0.0);
    breaks.push(end);
    breaks.sort_by(f64::total_cmp);
    let eps = 1e-12 * end.max(1.0);
    breaks.dedup_by(|a, b| (*a - *b).abs() <= eps);
    let l_at = |t: f64| s.at(t).length_m;
    let v_at = |t: f64| {
        if t <= 0.0 || t >= s.duration_s {
            0.0
        } else {
            s.at(t).rate_m_s
        }
    };
    let l0 = s.knots.first().map_or(0.0, |k| k.length_m);
    let l_end = s.knots.last().map_or(l0, |k| k.length_m);
    let mut knots = Vec::with_capacity(breaks.len());
    let mut length = l0;
    for (i, &b) in breaks.iter().enumerate() {
        let rate = (l_at(b) - l_at(b - tau)) / tau;
        let acc = (v_at(b) - v_at(b - tau)) / tau;
        let next = breaks.get(i + 1).copied();
        let jerk = match next {
            Some(nb) if nb > b => {
                let mid = 0.5 * (b + nb);
                (accel(s, mid) - accel(s, mid - tau)) / tau
            }
            _ => 0.0,
        };
        let label_at = (b + 0.5 * tau).min(end) - tau;
        let limit = {
            let t = label_at.clamp(0.0, s.duration_s);
            let k = s
                .knots
                .partition_point(|kn| kn.time_s <= t)
                .saturating_sub(1);
            s.knots[k].limit
        };
        let last = next.is_none();
        knots.push(Knot {
            time_s: b,
            length_m: if last { l_end } else { length },
            rate_m_s: if last { 0.0 } else { rate },
            acceleration_m_s2: if last { 0.0 } else { acc },
            jerk_m_s3: jerk,
            limit,
        });
        if let Some(nb) = next {
            let d = nb - b;
            length += rate * d + 0.5 * acc * d * d + jerk * d * d * d / 6.0;
        }
    }
    Schedule {
        knots,
        duration_s: end,
        worst_violation_n: s.worst_violation_n,
        averaging_window_s: tau,
    }
}

/// Largest stability shortfall below `ε(1 − r)F` and largest excess over
/// the allowable tension (N) of a schedule, with the loads of `grid`.
pub(crate) fn shortfalls(p: &PlanProblem, grid: &Grid, s: &Schedule) -> (f64, f64) {
    let sy = &p.system;
    let rho_a = sy.mass_per_length_kg_m;
    let rest = grid.rest_tensions.as_ref().map(|r| {
        (
            r.iter().map(|x| x.0).collect::<Vec<f64>>(),
            r.iter().map(|x| x.1).collect::<Vec<f64>>(),
        )
    });
    let mut stab = f64::NEG_INFINITY;
    let mut tension = f64::NEG_INFINITY;
    let mut check = |t: f64| {
        let k = s.at(t);
        let l = k.length_m;
        stab = stab.max(Grid::shortfall_n(
            rho_a,
            grid.stability_at(l),
            k.rate_m_s * k.rate_m_s,
            k.acceleration_m_s2,
        ));
        if let (Some(allow), Some((w, top))) = (p.allowable_tension_n, &rest) {
            let r = RestLoads {
                stability_tension_n: 0.0,
                winch_tension_n: grid.interpolate(w, l),
                top_tension_n: grid.interpolate(top, l),
                altitude_m: l,
                ascent: crate::numerics::plan::ascent::AscentDrag::NONE,
            };
            tension = tension.max(r.max_tension_at_n(sy, l, k.acceleration_m_s2) - allow);
        }
    };
    for w in s.knots.windows(2) {
        let (a, b) = (w[0].time_s, w[1].time_s);
        for q in 0..CHECK_SUBDIVISIONS {
            check(a + (b - a) * q as f64 / CHECK_SUBDIVISIONS as f64);
        }
    }
    check(s.duration_s);
    (stab, tension)
}

/// The fastest jerk-limited schedule found by averaging the pass (module
/// docs), checked and tightened until it keeps every limit.
pub fn jerk_limited(p: &PlanProblem, air: &Air, max_jerk: f64) -> PlanOutcome {
    let reserve = p.reserve_buoyancy_n();
    let check_grid = Grid::with_air(p, STABILITY_MARGIN, air);
    let mut margin = STABILITY_MARGIN;
    let mut q = *p;
    let mut last = (0.0, 0.0);
    for _ in 0..=MAX_TIGHTENINGS {
        if q.allowable_tension_n != p.allowable_tension_n
            && let Some(b) = static_check(&q, air)
        {
            return PlanOutcome::Infeasible(b);
        }
        let grid = check_grid.remargined(&q, STABILITY_MARGIN, margin);
        let base = match pass_on(&q, &grid, margin, air) {
            PlanOutcome::Feasible(s) => s,
            infeasible => return infeasible,
        };
        let tau = window_s(&base, max_jerk);
        let mut smooth = average(&base, tau);
        let (stab, tension) = shortfalls(p, &check_grid, &smooth);
        if stab <= 1e-9 * reserve && tension <= 1e-9 * p.system.net_buoyancy_n {
            smooth.worst_violation_n = stab;
            return PlanOutcome::Feasible(smooth);
        }
        last = (stab, tension);
        if stab > 0.0 {
            margin += 2.0 * stab / reserve + 1e-6;
        }
        if tension > 0.0
            && let Some(a) = q.allowable_tension_n.as_mut()
        {
            *a -= 2.0 * tension + 1e-6 * p.system.net_buoyancy_n;
        }
        if margin >= 1.0 {
            break;
        }
    }
    PlanOutcome::Infeasible(BindingLimit::Jerk {
        max_jerk_m_s3: max_jerk,
        stability_shortfall_n: last.0,
        tension_excess_n: last.1,
    })
}
