//! The forward/backward pass of the fastest schedule (the method of
//! [`super::schedule`]'s docs): the grid of the path with its constraints
//! per node ([`Grid`]: stability, winch and tension limits, in calm air or
//! a steady wind), the two-variable LP of a segment, the static check, the
//! schedule it gives ([`Schedule`], [`Knot`], [`Phase`]) and why a plan is
//! infeasible ([`PlanOutcome`]). Below both [`super::schedule`] (the
//! fastest plan, its bounds) and [`super::jerk`] (its S-curve).

use crate::numerics::params::AerostatSystem;
use crate::numerics::params::Kinematics;
use crate::numerics::plan::air::Air;
use crate::numerics::plan::{BindingLimit, PlanProblem};

/// Smallest `L̈` (m/s²) that keeps the top tension `T_t − m L̈` and the
/// winch tension `T_w − (m + ρA L) L̈` within `allow`.
pub(crate) fn tension_floor(s: &AerostatSystem, allow: f64, l: f64, winch: f64, top: f64) -> f64 {
    let m = s.aerostat_mass_kg;
    let top_floor = if m > 0.0 {
        (top - allow) / m
    } else if top > allow {
        f64::INFINITY
    } else {
        f64::NEG_INFINITY
    };
    top_floor.max((winch - allow) / (m + s.mass_per_length_kg_m * l))
}

/// What limits a segment of the schedule.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SegmentLimit {
    /// Speeding up at the winch's acceleration limit.
    Accelerate,
    /// At the winch's rate limit.
    Cruise,
    /// On the stability ceiling with the lift reserve.
    Stability,
    /// Tension rating.
    Tension,
    /// Slowing down at the winch's acceleration limit (to stop at the target).
    Brake,
}

impl SegmentLimit {
    pub fn name(self) -> &'static str {
        match self {
            Self::Accelerate => "winch_acceleration",
            Self::Cruise => "winch_rate",
            Self::Stability => "stability",
            Self::Tension => "tension",
            Self::Brake => "winch_braking",
        }
    }

    pub fn instruction(self) -> &'static str {
        match self {
            Self::Accelerate => "speed up at the winch's maximum acceleration",
            Self::Cruise => "hold the winch's maximum rate",
            Self::Stability => {
                "follow the stability ceiling (the rate the lift reserve and the climb allow)"
            }
            Self::Tension => "change speed no faster than the tension rating allows",
            Self::Brake => "slow down at the winch's maximum deceleration",
        }
    }
}

/// A knot of the schedule: the state at `time_s` and the constant
/// acceleration of the segment that starts there (0 at the last knot).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Knot {
    pub time_s: f64,
    pub length_m: f64,
    pub rate_m_s: f64,
    pub acceleration_m_s2: f64,
    /// Rate of change of the acceleration on the segment that starts here
    /// (m/s³; 0 in a schedule without a jerk limit).
    pub jerk_m_s3: f64,
    pub limit: SegmentLimit,
}

/// A stretch of the schedule under one limit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Phase {
    pub start: Knot,
    pub end: Knot,
    pub limit: SegmentLimit,
}

/// A piecewise constant-acceleration schedule from rest to rest.
#[derive(Clone, Debug, PartialEq)]
pub struct Schedule {
    pub knots: Vec<Knot>,
    pub duration_s: f64,
    /// Largest shortfall of `T_eff` below `ε(1 − r)F` at any segment end
    /// (N; ≤ 0 when every instant keeps the margin).
    pub worst_violation_n: f64,
    /// Width of the velocity average of a jerk-limited schedule (s; 0 without).
    pub averaging_window_s: f64,
}

impl Schedule {
    /// Kinematics at time `t_s` (clamped to the schedule).
    pub fn at(&self, t_s: f64) -> Kinematics {
        let t = t_s.clamp(0.0, self.duration_s);
        let k = self
            .knots
            .partition_point(|kn| kn.time_s <= t)
            .saturating_sub(1);
        let kn = self.knots[k];
        if k + 1 == self.knots.len() {
            return Kinematics {
                length_m: kn.length_m,
                rate_m_s: 0.0,
                acceleration_m_s2: 0.0,
            };
        }
        let tau = t - kn.time_s;
        let j = kn.jerk_m_s3;
        Kinematics {
            length_m: kn.length_m
                + kn.rate_m_s * tau
                + 0.5 * kn.acceleration_m_s2 * tau * tau
                + j * tau * tau * tau / 6.0,
            rate_m_s: kn.rate_m_s + kn.acceleration_m_s2 * tau + 0.5 * j * tau * tau,
            acceleration_m_s2: kn.acceleration_m_s2 + j * tau,
        }
    }

    /// Stretches under one limit, in time order.
    pub fn phases(&self) -> Vec<Phase> {
        let mut out: Vec<Phase> = Vec::new();
        for w in self.knots.windows(2) {
            match out.last_mut() {
                Some(p) if p.limit == w[0].limit => p.end = w[1],
                _ => out.push(Phase {
                    start: w[0],
                    end: w[1],
                    limit: w[0].limit,
                }),
            }
        }
        out
    }

    /// `count` evenly spaced times plus every phase boundary, sorted, with
    /// the kinematics there (the acceleration of the segment that starts).
    pub fn samples(&self, count: usize) -> Vec<(f64, Kinematics)> {
        let count = count.max(2);
        let mut times: Vec<f64> = (0..count)
            .map(|j| self.duration_s * j as f64 / (count - 1) as f64)
            .collect();
        for p in self.phases() {
            times.push(p.start.time_s);
        }
        times.sort_by(f64::total_cmp);
        let eps = 1e-9 * self.duration_s.max(1.0);
        times.dedup_by(|a, b| (*a - *b).abs() <= eps);
        times.into_iter().map(|t| (t, self.at(t))).collect()
    }
}

/// The answer of a pass.
#[derive(Clone, Debug, PartialEq)]
pub enum PlanOutcome {
    Feasible(Schedule),
    Infeasible(BindingLimit),
}

/// The grid of a problem and the per-node data of the constraints.
pub(crate) struct Grid {
    pub(crate) sigma: f64,
    pub(crate) h: f64,
    pub(crate) lengths: Vec<f64>,
    /// Stability right-hand side `(S(L) − ε(1 − r)F)/ρA` (m²/s²); calm
    /// air: `((1 − r)(1 − ε)F − ρA g L)/ρA`. Paying out with the
    /// aerostat's ascent drag: `(S − ε(1 − r)F − a₁v₀/2)/(k ρA)`.
    pub(crate) cap: Vec<f64>,
    /// `(m + ρA L)/(k ρA)` (m).
    pub(crate) x: Vec<f64>,
    /// The factor `k ≥ 1` on `ρA L̇²` that takes the aerostat's ascent
    /// drag in ([`crate::numerics::plan::ascent`]; `cap` is divided by it
    /// too): 1 without it.
    pub(crate) k: Vec<f64>,
    /// Smallest `L̈` the tension rating allows (m/s²).
    pub(crate) floor: Vec<f64>,
    /// Winch and top tension at rest, full buoyancy (N), when rated.
    pub(crate) rest_tensions: Option<Vec<(f64, f64)>>,
}

impl Grid {
    /// The grid with the loads of `air` at every node.
    pub(crate) fn with_air(p: &PlanProblem, margin: f64, air: &Air) -> Self {
        let s = &p.system;
        let l0 = s.initial_length_m;
        let sigma = p.direction();
        let n = p.grid_segments.max(1);
        let total = (p.target_length_m - l0).abs();
        let h = total / n as f64;
        let rho_a = s.mass_per_length_kg_m;
        // Node k from the shorter end, `lo + k (hi − lo)/n`, whichever the
        // direction: a retrieval between the same lengths (the haul-down's)
        // has the very same nodes, so their equilibria are cached once.
        let (lo, hi) = (l0.min(p.target_length_m), l0.max(p.target_length_m));
        let node = |k: usize| {
            if k == n {
                hi
            } else if k == 0 {
                lo
            } else {
                lo + total * k as f64 / n as f64
            }
        };
        let lengths: Vec<f64> = (0..=n)
            .map(|i| if sigma > 0.0 { node(i) } else { node(n - i) })
            .collect();
        let (mut cap, floor, rest_tensions): (Vec<f64>, _, _) = if air.is_calm() {
            let cap = lengths
                .iter()
                .map(|&l| {
                    (p.reserve_buoyancy_n() * (1.0 - margin) - rho_a * s.gravity_m_s2 * l) / rho_a
                })
                .collect();
            let floor = lengths.iter().map(|&l| p.tension_accel_floor(l)).collect();
            let rest = p
                .allowable_tension_n
                .map(|_| air.operating_tensions_n(p, &lengths));
            (cap, floor, rest)
        } else {
            let cap = air
                .stability_tensions_n(p, &lengths)
                .into_iter()
                .map(|st| (st - margin * p.reserve_buoyancy_n()) / rho_a)
                .collect();
            let rest = p
                .allowable_tension_n
                .map(|_| air.operating_tensions_n(p, &lengths));
            let floor = match (&rest, p.allowable_tension_n) {
                (Some(r), Some(allow)) => lengths
                    .iter()
                    .zip(r)
                    .map(|(&l, &(w, t))| tension_floor(s, allow, l, w, t))
                    .collect(),
                _ => vec![f64::NEG_INFINITY; lengths.len()],
            };
            (cap, floor, rest)
        };
        let mut x: Vec<f64> = lengths
            .iter()
            .map(|&l| s.aerostat_mass_kg / rho_a + l)
            .collect();
        let mut k = vec![1.0; lengths.len()];
        if sigma > 0.0 && !air.is_calm() {
            // Paying out: the ascent drag's linear form at each node.
            for (i, &l) in lengths.iter().enumerate() {
                let ascent = air.ascent_drag(l);
                if ascent.is_none() {
                    continue;
                }
                let (ki, budget) = ascent.linearised(rho_a, rho_a * cap[i]);
                k[i] = ki;
                cap[i] = budget / (rho_a * ki);
                x[i] /= ki;
            }
        }
        Self {
            sigma,
            h,
            lengths,
            cap,
            x,
            k,
            floor,
            rest_tensions,
        }
    }

    /// How far `T_eff` falls short of `ε(1 − r)F` at node data `(cap, x,
    /// k)` with `u = L̇²` and `L̈ = acc` (N; ≤ 0 admissible).
    pub(crate) fn shortfall_n(rho_a: f64, (cap, x, k): (f64, f64, f64), u: f64, acc: f64) -> f64 {
        rho_a * k * (u + x * acc - cap)
    }

    /// The node data `(cap, x, k)` interpolated at length `l`.
    pub(crate) fn stability_at(&self, l: f64) -> (f64, f64, f64) {
        (
            self.interpolate(&self.cap, l),
            self.interpolate(&self.x, l),
            self.interpolate(&self.k, l),
        )
    }

    /// The same grid with the stability margin moved from `from` to `to`
    /// and the tension floor recomputed for `p`'s allowable tension (no
    /// new loads are computed).
    pub(crate) fn remargined(&self, p: &PlanProblem, from: f64, to: f64) -> Self {
        let shift = (to - from) * p.reserve_buoyancy_n() / p.system.mass_per_length_kg_m;
        let floor = match (p.allowable_tension_n, &self.rest_tensions) {
            (Some(allow), Some(r)) => self
                .lengths
                .iter()
                .zip(r)
                .map(|(&l, &(w, t))| tension_floor(&p.system, allow, l, w, t))
                .collect(),
            _ => self.floor.clone(),
        };
        Self {
            sigma: self.sigma,
            h: self.h,
            lengths: self.lengths.clone(),
            cap: self
                .cap
                .iter()
                .zip(&self.k)
                .map(|(c, k)| c - shift / k)
                .collect(),
            x: self.x.clone(),
            k: self.k.clone(),
            floor,
            rest_tensions: self.rest_tensions.clone(),
        }
    }

    /// Linear interpolation of per-node data at length `l`.
    pub(crate) fn interpolate(&self, data: &[f64], l: f64) -> f64 {
        let n = self.segments();
        if self.h <= 0.0 {
            return data[0];
        }
        let u = ((l - self.lengths[0]) * self.sigma / self.h).clamp(0.0, n as f64);
        let i = (u.floor() as usize).min(n - 1);
        let f = u - i as f64;
        data[i] + (data[i + 1] - data[i]) * f
    }

    pub(crate) fn segments(&self) -> usize {
        self.lengths.len() - 1
    }

    /// Bounds on the path acceleration `α` of segment `i` from the winch
    /// and the tension rating at both ends.
    pub(crate) fn alpha_bounds(&self, i: usize, a_max: f64) -> (f64, f64) {
        let floor = self.floor[i].max(self.floor[i + 1]);
        if self.sigma > 0.0 {
            ((-a_max).max(floor), a_max)
        } else {
            (-a_max, a_max.min(-floor))
        }
    }
}

/// A line `u ≤ b − c α` (upper) or `u ≥ b − c α` (lower).
#[derive(Clone, Copy)]
struct Line {
    b: f64,
    c: f64,
}

impl Line {
    fn at(self, alpha: f64) -> f64 {
        self.b - self.c * alpha
    }
}

/// Maximises `u` subject to `u ≤` every upper line, `u ≥` every lower
/// line and `α ∈ [lo, hi]`: the optimum of a two-variable LP lies on a
/// vertex, so every candidate vertex is tried. `None` when infeasible.
fn max_u(upper: &[Line], lower: &[Line], lo: f64, hi: f64) -> Option<(f64, f64)> {
    if lo > hi {
        return None;
    }
    let mut candidates = vec![lo, hi];
    for (k, a) in upper.iter().enumerate() {
        for b in upper[k + 1..].iter().chain(lower) {
            let dc = a.c - b.c;
            if dc != 0.0 {
                let alpha = (a.b - b.b) / dc;
                if alpha > lo && alpha < hi {
                    candidates.push(alpha);
                }
            }
        }
    }
    let mut best: Option<(f64, f64)> = None;
    for alpha in candidates {
        let u = upper
            .iter()
            .map(|l| l.at(alpha))
            .fold(f64::INFINITY, f64::min);
        let need = lower
            .iter()
            .map(|l| l.at(alpha))
            .fold(f64::NEG_INFINITY, f64::max);
        let tol = 1e-12 * (1.0 + u.abs() + need.abs());
        if u + tol >= need && best.is_none_or(|(bu, _)| u > bu) {
            best = Some((u, alpha));
        }
    }
    best
}

/// Checks the end states (at rest) against the lift limit and the rating.
pub(crate) fn static_check(p: &PlanProblem, air: &Air) -> Option<BindingLimit> {
    let high = p.target_length_m.max(p.system.initial_length_m);
    let limit = air.lift_limit_m(p);
    if high > limit {
        if air.has_ge() {
            return Some(BindingLimit::QuasiStaticGe {
                length_m: high,
                limit_m: limit,
            });
        }
        return Some(BindingLimit::StaticLift {
            length_m: high,
            limit_m: limit,
        });
    }
    if let Some(allow) = p.allowable_tension_n {
        let ends = [p.system.initial_length_m, p.target_length_m];
        let t = if air.is_calm() {
            let low = p.target_length_m.min(p.system.initial_length_m);
            p.max_tension_n(low, 0.0)
        } else {
            ends.iter()
                .map(|&l| air.rest_loads(p, l).max_tension_at_n(&p.system, l, 0.0))
                .fold(f64::NEG_INFINITY, f64::max)
        };
        if t > allow {
            return Some(BindingLimit::Tension {
                tension_n: t,
                allowable_n: allow,
            });
        }
        // In the gust (SPEC §10): the same check at the gust speed.
        let gust = ends
            .iter()
            .filter_map(|&l| {
                air.gust_rest_loads(p, l)
                    .map(|r| r.max_tension_at_n(&p.system, l, 0.0))
            })
            .fold(f64::NEG_INFINITY, f64::max);
        if gust > allow {
            return Some(BindingLimit::GustTension {
                tension_n: gust,
                mean_tension_n: t,
                allowable_n: allow,
            });
        }
    }
    None
}

/// The forward/backward pass with the stability margin `margin` (fraction
/// of `(1 − r)F`), after the static check.
pub(crate) fn pass(p: &PlanProblem, margin: f64, air: &Air) -> PlanOutcome {
    pass_on(p, &Grid::with_air(p, margin, air), margin, air)
}

/// The pass on a prepared grid (its margin `margin`).
pub(crate) fn pass_on(p: &PlanProblem, g: &Grid, margin: f64, air: &Air) -> PlanOutcome {
    let n = g.segments();
    let a_max = p.winch.max_acceleration_m_s2;
    let w2 = p.winch.max_rate_m_s.powi(2);
    let (h, sigma) = (g.h, g.sigma);

    // Backward pass: the viability limit V.
    let mut v = vec![0.0; n + 1];
    for i in (0..n).rev() {
        let (lo, hi) = g.alpha_bounds(i, a_max);
        let upper = [
            Line { b: w2, c: 0.0 },
            Line {
                b: v[i + 1],
                c: 2.0 * h,
            },
            Line {
                b: g.cap[i],
                c: sigma * g.x[i],
            },
            Line {
                b: g.cap[i + 1],
                c: sigma * g.x[i + 1] + 2.0 * h,
            },
        ];
        let lower = [Line { b: 0.0, c: 0.0 }, Line { b: 0.0, c: 2.0 * h }];
        v[i] = max_u(&upper, &lower, lo, hi).map_or(0.0, |(u, _)| u.max(0.0));
    }

    // Forward pass: the largest admissible α on each segment.
    let mut u = vec![0.0; n + 1];
    let mut alpha = vec![0.0; n];
    for i in 0..n {
        let (mut lo, mut hi) = g.alpha_bounds(i, a_max);
        let ui = u[i];
        // coef·α ≤ rhs
        let rows = [
            (2.0 * h, v[i + 1] - ui),
            (sigma * g.x[i], g.cap[i] - ui),
            (sigma * g.x[i + 1] + 2.0 * h, g.cap[i + 1] - ui),
            (-2.0 * h, ui), // u_{i+1} ≥ 0
        ];
        for (coef, rhs) in rows {
            if coef > 0.0 {
                hi = hi.min(rhs / coef);
            } else if coef < 0.0 {
                lo = lo.max(rhs / coef);
            }
        }
        let a = if hi >= lo { hi } else { lo };
        alpha[i] = a;
        u[i + 1] = (ui + 2.0 * h * a).max(0.0);
    }
    u[n] = 0.0;
    if n > 0 {
        alpha[n - 1] = (u[n] - u[n - 1]) / (2.0 * h);
    }

    // Times, labels, and the check of every segment end.
    let f_scale = p.reserve_buoyancy_n();
    let rho_a = p.system.mass_per_length_kg_m;
    let mut knots = Vec::with_capacity(n + 1);
    let mut t = 0.0;
    let mut worst = f64::NEG_INFINITY;
    for i in 0..n {
        let a_phys = sigma * alpha[i];
        let (vi, vj) = (u[i].sqrt(), u[i + 1].sqrt());
        for (k, vel) in [(i, vi), (i + 1, vj)] {
            let short = if air.is_calm() {
                margin * f_scale - p.effective_tension_n(g.lengths[k], vel, a_phys)
            } else {
                Grid::shortfall_n(rho_a, (g.cap[k], g.x[k], g.k[k]), vel * vel, a_phys)
            };
            worst = worst.max(short);
        }
        let label = label(g, p, i, u[i], u[i + 1], alpha[i], w2, a_max);
        knots.push(Knot {
            time_s: t,
            length_m: g.lengths[i],
            rate_m_s: sigma * vi,
            acceleration_m_s2: a_phys,
            jerk_m_s3: 0.0,
            limit: label,
        });
        let speed = vi + vj;
        if speed <= 0.0 {
            return PlanOutcome::Infeasible(BindingLimit::StaticLift {
                length_m: g.lengths[i],
                limit_m: air.lift_limit_m(p),
            });
        }
        t += 2.0 * h / speed;
    }
    knots.push(Knot {
        time_s: t,
        length_m: p.target_length_m,
        rate_m_s: 0.0,
        acceleration_m_s2: 0.0,
        jerk_m_s3: 0.0,
        limit: knots.last().map_or(SegmentLimit::Brake, |k| k.limit),
    });
    PlanOutcome::Feasible(Schedule {
        knots: compress(knots),
        duration_s: t,
        worst_violation_n: worst,
        averaging_window_s: 0.0,
    })
}

/// Which limit is active on segment `i`.
#[allow(clippy::too_many_arguments)]
fn label(
    g: &Grid,
    p: &PlanProblem,
    i: usize,
    ui: f64,
    uj: f64,
    alpha: f64,
    w2: f64,
    a_max: f64,
) -> SegmentLimit {
    let tol_u = 1e-7 * (w2 + g.cap[0].abs());
    let tol_a = 1e-7 * a_max;
    let sigma = g.sigma;
    let stab = |k: usize, uu: f64| g.cap[k] - sigma * g.x[k] * alpha - uu;
    if (w2 - ui).abs() <= tol_u && (w2 - uj).abs() <= tol_u {
        return SegmentLimit::Cruise;
    }
    if alpha >= a_max - tol_a {
        return SegmentLimit::Accelerate;
    }
    if stab(i, ui) <= tol_u || stab(i + 1, uj) <= tol_u {
        return SegmentLimit::Stability;
    }
    if alpha <= -a_max + tol_a {
        return SegmentLimit::Brake;
    }
    if p.allowable_tension_n.is_some() {
        let (lo, hi) = g.alpha_bounds(i, a_max);
        if (sigma > 0.0 && lo > -a_max && alpha <= lo + tol_a)
            || (sigma < 0.0 && hi < a_max && alpha >= hi - tol_a)
        {
            return SegmentLimit::Tension;
        }
    }
    // Limited by the backward curve alone: the segment in which the rate
    // reaches the cruise rate, or starts braking for the target.
    if uj >= w2 - tol_u {
        SegmentLimit::Cruise
    } else if alpha >= 0.0 {
        SegmentLimit::Accelerate
    } else {
        SegmentLimit::Brake
    }
}

/// Drops knots inside runs of one acceleration and one limit.
fn compress(knots: Vec<Knot>) -> Vec<Knot> {
    let mut out: Vec<Knot> = Vec::with_capacity(knots.len());
    let last = knots.len().saturating_sub(1);
    for (i, k) in knots.into_iter().enumerate() {
        if let Some(prev) = out.last()
            && i != last
            && prev.limit == k.limit
            && prev.jerk_m_s3 == k.jerk_m_s3
            && (prev.acceleration_m_s2 - k.acceleration_m_s2).abs()
                <= 1e-9 * prev.acceleration_m_s2.abs().max(1e-12)
        {
            continue;
        }
        out.push(k);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lp_vertex_search_finds_the_optimum() {
        // u ≤ 4 − α, u ≤ 1 + α, α ∈ [−5, 5] → α = 1.5, u = 2.5
        let up = [Line { b: 4.0, c: 1.0 }, Line { b: 1.0, c: -1.0 }];
        let (u, a) = max_u(&up, &[], -5.0, 5.0).unwrap();
        assert!((u - 2.5).abs() < 1e-12 && (a - 1.5).abs() < 1e-12);
    }
}
