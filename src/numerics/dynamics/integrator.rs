//! The generalized-α step (see the module docs of [`super`]) and the wind
//! the integrator evaluates the forces in.
//!
//! One Newton iteration is: the predictor of `R`, `Ṙ` at the α-point from
//! the current `a_{n+1}`; one evaluation of the forces that sends the
//! Jacobian straight into the iteration matrix
//! `(1 − α_m) M − (1 − α_f)(β h² ∂P/∂R + γ h ∂P/∂Ṙ)`
//! ([`model::IterationMatrix`]); one block-tridiagonal solve. No work array
//! is allocated after the start.

use super::blocks::{V2, add_identity, norm};
use super::limits::MAX_HALVINGS;
use super::model::{self, Evaluation, IterationMatrix, NoJacobian, Parameters, evaluate_with};
use super::problem::LengthSchedule;
use super::state::Statistics;
use super::wind::{GustHistory, TurbulenceField};
use crate::numerics::tether::wind::WindProfile;

/// The integrator's constants.
#[derive(Clone, Copy, Debug)]
pub(super) struct Alpha {
    pub am: f64,
    pub af: f64,
    pub gamma: f64,
    pub beta: f64,
}

impl Alpha {
    pub fn new(rho_inf: f64) -> Self {
        let am = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0);
        let af = rho_inf / (rho_inf + 1.0);
        let gamma = 0.5 - am + af;
        let beta = 0.25 * (1.0 - am + af).powi(2);
        Self {
            am,
            af,
            gamma,
            beta,
        }
    }
}

/// The wind: steady flow, uniform changes, turbulence.
pub(super) struct Air<'a> {
    pub flow: &'a WindProfile,
    pub gusts: &'a [GustHistory],
    pub field: Option<TurbulenceField>,
}

/// The wind at one instant: the uniform change summed once, not per node.
#[derive(Clone, Copy)]
pub(super) struct AirAt<'a> {
    flow: &'a WindProfile,
    change_m_s: f64,
    field: Option<&'a TurbulenceField>,
    t: f64,
}

impl Air<'_> {
    pub fn at(&self, t: f64) -> AirAt<'_> {
        AirAt {
            flow: self.flow,
            change_m_s: self.gusts.iter().map(|g| g.change_m_s(t)).sum(),
            field: self.field.as_ref(),
            t,
        }
    }
}

impl AirAt<'_> {
    /// `U(z) + ΔU(t) + u′(x, z, t)` (m/s).
    #[inline]
    pub fn speed(&self, x: f64, z: f64) -> f64 {
        let mut u = self.flow.speed_m_s(z) + self.change_m_s;
        if let Some(f) = self.field {
            u += f.sample(x, z, self.t);
        }
        u
    }
}

/// How one try of a step ended.
enum Try {
    Accepted,
    /// Newton failed.
    Failed,
    /// A segment changed between slack and taut: retry in halves.
    Refine,
}

/// The state at the end of a sub-step inside one outer step (a step that
/// was refined or halved): what the recorder's extremes need, which the
/// outer step's end alone would miss (a snap peaks within milliseconds).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct InsideState {
    pub time_s: f64,
    pub winch_tension_n: f64,
    /// The largest segment tension (N).
    pub max_tension_n: f64,
    pub aerostat_altitude_m: f64,
}

/// The integrator and its work arrays.
pub(super) struct Stepper<'a> {
    pub p: Parameters,
    pub alpha: Alpha,
    pub schedule: &'a LengthSchedule,
    pub air: &'a Air<'a>,
    pub tol: f64,
    pub max_it: usize,
    pub x: Vec<V2>,
    pub v: Vec<V2>,
    pub a: Vec<V2>,
    pub t: f64,
    pub ev: Evaluation,
    an: Vec<V2>,
    xa: Vec<V2>,
    va: Vec<V2>,
    matrix: IterationMatrix,
    rhs: Vec<V2>,
    /// `θ`, the contraction of the last Newton iteration that measured one.
    contraction: f64,
    /// Which segments were taut at the last accepted step (its α-point).
    taut: Vec<bool>,
    /// Until when steps are refined after a rate jump (s).
    fine_until_s: f64,
    /// The sub-step ends passed since the caller last took them.
    pub inside: Vec<InsideState>,
    pub stats: Statistics,
}

impl<'a> Stepper<'a> {
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        p: Parameters,
        alpha: Alpha,
        schedule: &'a LengthSchedule,
        air: &'a Air<'a>,
        tol: f64,
        max_it: usize,
        x: Vec<V2>,
        v: Vec<V2>,
        t: f64,
    ) -> Self {
        let n = p.segments;
        Self {
            alpha,
            schedule,
            air,
            tol,
            max_it: max_it.max(1),
            x,
            v,
            a: vec![[0.0; 2]; n],
            t,
            ev: Evaluation::new(n),
            an: vec![[0.0; 2]; n],
            xa: vec![[0.0; 2]; n],
            va: vec![[0.0; 2]; n],
            matrix: IterationMatrix::new(n),
            rhs: vec![[0.0; 2]; n],
            contraction: 1.0,
            taut: vec![true; n],
            fine_until_s: f64::NEG_INFINITY,
            inside: Vec::new(),
            stats: Statistics::default(),
            p,
        }
    }

    /// Evaluates the forces of the state at `self.t` (no Jacobian): what
    /// the outputs and observers read.
    pub fn evaluate_current(&mut self) {
        let air = self.air.at(self.t);
        let wind = |x: f64, z: f64| air.speed(x, z);
        evaluate_with(
            &self.p,
            self.schedule.at(self.t),
            &self.x,
            &self.v,
            &wind,
            &mut NoJacobian,
            &mut self.ev,
        );
    }

    /// Accelerations consistent with the state at `self.t`: `M a = P`.
    pub fn initial_acceleration(&mut self) {
        self.evaluate_current();
        for k in 0..self.p.segments {
            let m = self.ev.mass[k];
            let f = self.ev.force[k];
            self.a[k] = [f[0] / m, f[1] / m];
        }
        for (taut, &t) in self.taut.iter_mut().zip(&self.ev.tension) {
            *taut = t > 0.0;
        }
    }

    /// Carries the state through a jump of the winch rate at `self.t`
    /// from `rate_before` to the schedule's rate now (a stop, a start, a
    /// rate table's step). The material velocity `V = Ṙ + ζ̇ R_ζ` is
    /// continuous through it (material does not change its velocity
    /// because the winch did), but `ζ̇ = (1 − ζ) L̇/L` jumps, so the mesh
    /// velocities jump by `ΔṘ = −(1 − ζ) ΔL̇/L R_ζ`: the impulse of the
    /// convective term `−ζ̈ R_ζ` whose `L̈` is a Dirac `ΔL̇ δ(t)` that no
    /// finite step sees. Only the material at the winch takes the new
    /// rate (`V_0 = L̇ (1 + ε_1) t_1`), so a stop sends a tension wave up
    /// the tether and the slack and snap that follow it. The acceleration
    /// is then made consistent with the new state (`M a = P`), the
    /// generalized-α method restarting as from an initial condition.
    pub fn rate_jump(&mut self, rate_before_m_s: f64) {
        let now = self.schedule.at(self.t);
        let jump = now.rate_m_s - rate_before_m_s;
        let n = self.p.segments;
        if jump != 0.0 {
            let dz = 1.0 / n as f64;
            let x = &self.x;
            let node = |i: usize| if i == 0 { [0.0; 2] } else { x[i - 1] };
            for i in 1..n {
                let zeta = i as f64 * dz;
                let c = -(1.0 - zeta) * jump / now.length_m * 0.5 / dz;
                let (rp, rm) = (node(i + 1), node(i - 1));
                self.v[i - 1][0] += c * (rp[0] - rm[0]);
                self.v[i - 1][1] += c * (rp[1] - rm[1]);
            }
            self.stats.rate_jumps += 1;
            // The wave the jump sends is followed for two round trips.
            let c = (self.p.axial_stiffness_n / self.p.mass_per_length_kg_m).sqrt();
            self.fine_until_s = self.t + 4.0 * now.length_m / c;
        }
        self.initial_acceleration();
    }

    /// One step of `h`; `false` if Newton failed (the state is unchanged).
    ///
    /// Newton stops on its estimated error, as in Hairer & Wanner
    /// ("Solving Ordinary Differential Equations II", 2nd ed., §IV.8): with
    /// `δ_k` the largest velocity correction of iteration `k` and
    /// `θ = δ_k/δ_{k−1}` the observed contraction, the error left is about
    /// `θ/(1 − θ) δ_k`; the step is accepted when that (or `δ_k` itself) is
    /// below the tolerance. The first iteration of a step uses the last
    /// measured `θ`, raised to the power 0.8 (their safeguard), so a step
    /// whose predictor is already close costs one iteration, not two.
    fn try_step(&mut self, h: f64) -> Try {
        let Alpha {
            am,
            af,
            gamma,
            beta,
        } = self.alpha;
        let Self {
            p,
            schedule,
            air,
            x,
            v,
            a,
            ev,
            an,
            xa,
            va,
            matrix,
            rhs,
            stats,
            contraction,
            taut,
            ..
        } = self;
        let n = p.segments;
        an.copy_from_slice(a);
        let ta = self.t + (1.0 - af) * h;
        let len = schedule.at(ta);
        let refine_above = 2.0 * Self::shortest_step_of(p, len.length_m);
        // A step that starts with a slack segment is no longer than the
        // snap: the segment can snap taut and go slack again within one
        // axial period, unseen by a comparison at the step's ends (the
        // 1000 m tether hauled in to 400 m and stopped, at 0.1 s steps,
        // gained energy from such steps until it held 2 MN, "completed").
        if h > refine_above && (self.t < self.fine_until_s || taut.iter().any(|&t| !t)) {
            return Try::Refine;
        }
        let air_at = air.at(ta);
        let wind = |x: f64, z: f64| air_at.speed(x, z);
        // R_{n+1−α_f} = R_n + (1 − α_f)(h Ṙ_n + h²((½ − β) a_n + β a_{n+1})), likewise Ṙ.
        let (wxa, wxn) = ((1.0 - af) * h * h * (0.5 - beta), (1.0 - af) * h * h * beta);
        let (wva, wvn) = ((1.0 - af) * h * (1.0 - gamma), (1.0 - af) * h * gamma);
        let wxv = (1.0 - af) * h;
        matrix.position_weight = -(1.0 - af) * beta * h * h;
        matrix.velocity_weight = -(1.0 - af) * gamma * h;
        let mut theta = contraction.max(1e-4).powf(0.8);
        let mut last = f64::INFINITY;
        for it in 0..self.max_it {
            for ((((xa, va), x), v), (a, an)) in xa
                .iter_mut()
                .zip(va.iter_mut())
                .zip(x.iter())
                .zip(v.iter())
                .zip(a.iter().zip(an.iter()))
            {
                for c in 0..2 {
                    xa[c] = x[c] + wxv * v[c] + wxa * a[c] + wxn * an[c];
                    va[c] = v[c] + wva * a[c] + wvn * an[c];
                }
            }
            evaluate_with(p, len, xa, va, &wind, matrix, ev);
            stats.newton_iterations += 1;
            for k in 0..n {
                let m = ev.mass[k];
                let (f, an, a) = (ev.force[k], an[k], a[k]);
                rhs[k] = [
                    f[0] - m * ((1.0 - am) * an[0] + am * a[0]),
                    f[1] - m * ((1.0 - am) * an[1] + am * a[1]),
                ];
                add_identity(&mut matrix.diag[k], (1.0 - am) * m);
            }
            if !model::solve_tridiagonal(&matrix.lower, &mut matrix.diag, &matrix.upper, rhs) {
                return Try::Failed;
            }
            let mut big2 = 0.0f64;
            for (an, d) in an.iter_mut().zip(rhs.iter()) {
                an[0] += d[0];
                an[1] += d[1];
                big2 = big2.max(d[0] * d[0] + d[1] * d[1]);
            }
            if !big2.is_finite() {
                return Try::Failed;
            }
            let delta = big2.sqrt() * gamma * h;
            if it > 0 && last > 0.0 {
                theta = delta / last;
                *contraction = theta;
            }
            last = delta;
            let converged =
                delta <= self.tol || (theta < 1.0 && theta / (1.0 - theta) * delta <= self.tol);
            if converged {
                // A segment that went slack or snapped taut within the step:
                // the force changed its law inside it, which a step longer
                // than the snap does not follow (the energy of such steps is
                // not bounded: the 1000 m tether stopped at 2 m/s gained
                // meganewtons). Such steps are refined to the snap's time.
                if h > refine_above
                    && ev.tension[..n]
                        .iter()
                        .zip(taut.iter())
                        .any(|(&t, &was)| (t > 0.0) != was)
                {
                    return Try::Refine;
                }
                for (was, &t) in taut.iter_mut().zip(&ev.tension) {
                    *was = t > 0.0;
                }
                let (ha, hn) = (h * h * (0.5 - beta), h * h * beta);
                let (ga, gn) = (h * (1.0 - gamma), h * gamma);
                for (((x, v), a), an) in x.iter_mut().zip(v.iter_mut()).zip(a.iter()).zip(an.iter())
                {
                    for c in 0..2 {
                        x[c] += h * v[c] + ha * a[c] + hn * an[c];
                        v[c] += ga * a[c] + gn * an[c];
                    }
                }
                a.copy_from_slice(an);
                self.t += h;
                return Try::Accepted;
            }
        }
        Try::Failed
    }

    /// The shortest step a slack–taut change refines to (s): a sixteenth
    /// of the period `2π l/c` of one segment's axial vibration
    /// (`c = √(EA/ρA)`, `l = L/N`), the time over which a slack segment
    /// snaps taut.
    pub fn shortest_step_of(p: &Parameters, length_m: f64) -> f64 {
        let l = length_m / p.segments as f64;
        let c = (p.axial_stiffness_n / p.mass_per_length_kg_m).sqrt();
        2.0 * std::f64::consts::PI * l / c / 16.0
    }

    /// A step of `h`, halving on failure (at most [`MAX_HALVINGS`] times)
    /// and where a segment changes between slack and taut (down to
    /// [`Self::shortest_step_s`]).
    pub fn step(&mut self, h: f64, depth: usize) -> bool {
        match self.try_step(h) {
            Try::Accepted => {
                self.stats.steps += 1;
                true
            }
            Try::Refine => {
                self.stats.refinements += 1;
                // The coarse step's acceleration is algorithmic (the
                // α-method's), not the state's: carried into steps a
                // thousand times shorter it rings (a 5.5 kN snap read as
                // 5.5 to 7.4 kN as the outer step changed). Re-solved here.
                self.initial_acceleration();
                self.step(0.5 * h, depth) && {
                    self.note_inside();
                    self.step(0.5 * h, depth)
                }
            }
            Try::Failed => {
                if depth >= MAX_HALVINGS {
                    return false;
                }
                self.stats.halvings += 1;
                self.step(0.5 * h, depth + 1) && {
                    self.note_inside();
                    self.step(0.5 * h, depth + 1)
                }
            }
        }
    }

    /// Keeps the state at a sub-step's end inside an outer step (its
    /// forces evaluated afresh: the Newton iterations evaluate at the
    /// step's α-point).
    fn note_inside(&mut self) {
        self.evaluate_current();
        let n = self.p.segments;
        let max_tension_n = self.ev.tension[..n]
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max);
        let w = self.ev.winch_force;
        self.inside.push(InsideState {
            time_s: self.t,
            winch_tension_n: norm(w),
            max_tension_n,
            aerostat_altitude_m: self.x[n - 1][1],
        });
    }
}
