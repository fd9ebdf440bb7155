//! Tether dynamics in the time domain (SPEC §11): a lumped-mass tether in
//! the vertical plane downwind, its unstretched length following a
//! deployment profile, the aerostat a point mass, in a wind that changes
//! in time ([`wind`]).
//!
//! * [`model`]: the moving-mesh lumped-mass equations (why no node is
//!   inserted at the winch, the forces, the Jacobian);
//! * [`blocks`]: 2×2 blocks and the block-tridiagonal solve;
//! * [`wind`]: discrete gusts, the sinusoid, seeded turbulence.
//!
//! **Step.** The generalized-α method of Chung & Hulbert (1993, J. Appl.
//! Mech. 60, 371–375) on `M(t) R̈ = P(t, R, Ṙ)`:
//!
//! ```text
//! α_m = (2ρ∞ − 1)/(ρ∞ + 1),  α_f = ρ∞/(ρ∞ + 1),  γ = ½ − α_m + α_f,  β = ¼(1 − α_m + α_f)²
//! R_{n+1} = R_n + h Ṙ_n + h² ((½ − β) a_n + β a_{n+1}),   Ṙ_{n+1} = Ṙ_n + h ((1 − γ) a_n + γ a_{n+1})
//! M((1 − α_m) a_{n+1} + α_m a_n) = P(t_{n+1−α_f}, R_{n+1−α_f}, Ṙ_{n+1−α_f})
//! ```
//!
//! second-order accurate and unconditionally stable for every spectral
//! radius `ρ∞ ∈ [0, 1]` at infinite frequency: modes with `ω h ≫ 1` (the
//! stiff axial waves of a 1000 m tether, `√(EA/ρA)` ≈ 3.6 km/s) are damped
//! by the factor `ρ∞` per step instead of limiting the step, so the step is
//! chosen for the motion of interest. `ρ∞ = 1` is the trapezoidal rule
//! (no numerical dissipation: the energy of the undamped, unforced tether
//! is conserved to `O(h²)`, checked in `tests/verification_dynamics.rs`).
//! Each step solves the residual in `a_{n+1}` by Newton's method with the
//! block-tridiagonal iteration matrix of [`model`] (`O(N)` per iteration);
//! a step whose Newton iteration fails is retried as two half steps (up to
//! [`MAX_HALVINGS`] times), and a run that still fails stops with
//! [`Outcome::NewtonFailed`]: an outcome, not an error.
//!
//! **Start.** The run starts at rest in the static equilibrium of the
//! steady flow: the shooting solution of SPEC §6
//! ([`crate::numerics::tether::equilibrium`]) integrated with `N` steps
//! places the nodes at `s_i = i L/N`, and a static Newton iteration on the
//! discrete forces (`P(R) = 0`, same assembly) removes the `O(N⁻²)`
//! difference between the continuum and the lumped model, so the run does
//! not start with a spurious transient.

pub mod blocks;
pub mod model;
pub mod wind;

use blocks::{B2, V2, ZERO, add_identity, add_to, norm, scale};
use model::{Evaluation, Length, Parameters, evaluate};
pub use wind::{GustHistory, SpectrumModel, Turbulence, TurbulenceField};

use crate::numerics::params::{InvalidInput, require_non_negative, require_positive};
use crate::numerics::profile::Profile;
use crate::numerics::tether::equilibrium::{
    Body, Cable, Equilibrium, EquilibriumConfig, EquilibriumProblem,
};
use crate::numerics::tether::wind::WindProfile;

/// Fewest and most segments.
pub const MIN_SEGMENTS: usize = 2;
pub const MAX_SEGMENTS: usize = 2000;
/// Most time steps of one run.
pub const MAX_STEPS: usize = 20_000_000;
/// Most `steps × segments` of one run.
pub const MAX_WORK: f64 = 2e9;
/// Most halvings of a step whose Newton iteration fails.
pub const MAX_HALVINGS: usize = 6;
/// Most samples one run keeps.
pub const MAX_SAMPLES: usize = 200_000;
/// Most shapes one run keeps.
pub const MAX_SHAPES: usize = 1000;

/// The tether's properties.
#[derive(Clone, Debug, PartialEq)]
pub struct Tether {
    /// ρA (kg/m).
    pub mass_per_length_kg_m: f64,
    /// Diameter `d` (m).
    pub diameter_m: f64,
    /// Normal drag coefficient `C_n`.
    pub normal_drag_coefficient: f64,
    /// Tangential (skin-friction) drag coefficient `C_t` on `π d`; 0: none.
    pub tangential_drag_coefficient: f64,
    /// `EA` (N).
    pub axial_stiffness_n: f64,
    /// Kelvin–Voigt damping `c` (N s): `T = EA ε + c ε̇`.
    pub internal_damping_n_s: f64,
    /// Drag on the stretched length (SPEC §6) or on the unstretched one (MoorDyn).
    pub drag_on_stretched_length: bool,
}

/// The aerostat.
#[derive(Clone, Debug, PartialEq)]
pub struct Aerostat {
    /// Net buoyancy `F` (N).
    pub net_buoyancy_n: f64,
    /// Structural mass `m` (kg).
    pub mass_kg: f64,
    pub reference_area_m2: f64,
    pub drag_coefficient: f64,
    pub lift_coefficient: f64,
    /// `C_a` on the displaced air mass.
    pub added_mass_coefficient: f64,
}

impl Aerostat {
    /// Displaced volume `V = (F + m g)/(ρ g)` (m³).
    pub fn displaced_volume_m3(&self, air_density: f64, gravity: f64) -> f64 {
        (self.net_buoyancy_n + self.mass_kg * gravity) / (air_density * gravity)
    }
}

/// The unstretched length in time.
#[derive(Clone, Debug, PartialEq)]
pub enum LengthSchedule {
    Fixed(f64),
    Profile(Profile),
}

impl LengthSchedule {
    pub fn at(&self, t: f64) -> Length {
        match self {
            Self::Fixed(l) => Length {
                length_m: *l,
                rate_m_s: 0.0,
                acceleration_m_s2: 0.0,
            },
            Self::Profile(p) => {
                let k = p.kinematics(t);
                Length {
                    length_m: k.length_m,
                    rate_m_s: k.rate_m_s,
                    acceleration_m_s2: k.acceleration_m_s2,
                }
            }
        }
    }

    /// The longest length over `[0, until]` (sampled; profiles are monotone between knots).
    pub fn longest_m(&self, until_s: f64) -> f64 {
        (0..=512)
            .map(|i| self.at(until_s * i as f64 / 512.0).length_m)
            .fold(0.0, f64::max)
    }
}

/// One dynamic problem (SI).
#[derive(Clone, Debug, PartialEq)]
pub struct DynamicsProblem {
    pub tether: Tether,
    pub aerostat: Aerostat,
    /// The steady flow `U(z)`.
    pub flow: WindProfile,
    /// Uniform changes `ΔU(t)`, summed.
    pub gusts: Vec<GustHistory>,
    pub turbulence: Option<Turbulence>,
    pub air_density_kg_m3: f64,
    pub gravity_m_s2: f64,
    pub length: LengthSchedule,
}

/// Discretisation, output and iteration settings.
#[derive(Clone, Debug, PartialEq)]
pub struct DynamicsConfig {
    pub segments: usize,
    pub time_step_s: f64,
    pub duration_s: f64,
    /// Spectral radius at infinite frequency `ρ∞ ∈ [0, 1]`.
    pub spectral_radius: f64,
    /// Time between kept samples (s); every step is still checked for peaks and slack.
    pub sample_interval_s: f64,
    /// Times at which the shape is kept (s).
    pub shape_times_s: Vec<f64>,
    /// Newton stops when every velocity correction is below this (m/s);
    /// positions are then corrected by less than `tol · β h/γ`.
    pub newton_tolerance_m_s: f64,
    pub max_newton_iterations: usize,
    /// Sample spacing of a turbulence series (s).
    pub turbulence_time_step_s: f64,
    /// Level spacing of a turbulence field (m), at most.
    pub turbulence_level_spacing_m: f64,
}

impl Default for DynamicsConfig {
    fn default() -> Self {
        Self {
            segments: 50,
            time_step_s: 0.05,
            duration_s: 600.0,
            spectral_radius: 0.8,
            sample_interval_s: 1.0,
            shape_times_s: vec![],
            newton_tolerance_m_s: 1e-6,
            max_newton_iterations: 30,
            turbulence_time_step_s: 0.2,
            turbulence_level_spacing_m: 50.0,
        }
    }
}

/// Nodal positions and velocities (nodes `1 … N`; the winch is the origin).
#[derive(Clone, Debug, PartialEq)]
pub struct State {
    pub time_s: f64,
    pub positions: Vec<V2>,
    pub velocities: Vec<V2>,
}

/// One kept sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    pub time_s: f64,
    /// `|τ(0)|` (N).
    pub winch_tension_n: f64,
    /// `|τ(L)|` (N).
    pub top_tension_n: f64,
    pub aerostat_altitude_m: f64,
    pub aerostat_downwind_m: f64,
    /// Unstretched length (m).
    pub length_m: f64,
    /// Wind at the aerostat (m/s).
    pub aerostat_wind_m_s: f64,
}

/// One node of a kept shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeNode {
    /// Unstretched arc length from the winch (m).
    pub s_m: f64,
    pub x_m: f64,
    pub z_m: f64,
    /// Tension of the segment below the node (the winch tension at `s = 0`) (N).
    pub tension_n: f64,
}

/// The shape at one time.
#[derive(Clone, Debug, PartialEq)]
pub struct Shape {
    pub time_s: f64,
    pub nodes: Vec<ShapeNode>,
}

/// A time interval during which some segment carries no tension.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlackEvent {
    pub start_s: f64,
    /// `None`: still slack at the end of the run.
    pub end_s: Option<f64>,
    /// Lowest slack point seen (unstretched arc length from the winch, m).
    pub lowest_s_m: f64,
}

/// An extreme and when it happened.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Extreme {
    pub value: f64,
    pub time_s: f64,
}

/// How a run ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Outcome {
    Completed,
    /// Newton failed even on the smallest sub-step.
    NewtonFailed {
        time_s: f64,
    },
    /// A non-finite state.
    Diverged {
        time_s: f64,
    },
    /// The observer asked to stop.
    Stopped {
        time_s: f64,
    },
}

/// Counters.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Statistics {
    pub steps: usize,
    pub newton_iterations: usize,
    pub halvings: usize,
}

/// The answer of a run.
#[derive(Clone, Debug, PartialEq)]
pub struct Run {
    pub outcome: Outcome,
    /// The §6 equilibrium of the steady flow at the initial length.
    pub equilibrium: Equilibrium,
    pub samples: Vec<Sample>,
    pub shapes: Vec<Shape>,
    pub slack_events: Vec<SlackEvent>,
    pub peak_winch_tension: Extreme,
    pub min_winch_tension: Extreme,
    /// Largest segment tension anywhere (N).
    pub peak_tension: Extreme,
    pub final_state: State,
    pub statistics: Statistics,
}

/// What an observer sees after every accepted step.
pub struct StepView<'a> {
    pub time_s: f64,
    pub length: Length,
    pub positions: &'a [V2],
    pub velocities: &'a [V2],
    pub evaluation: &'a Evaluation,
    pub parameters: &'a Parameters,
}

impl DynamicsProblem {
    /// `ΔU(t)`, the sum of the gusts (m/s).
    pub fn gust_change_m_s(&self, t: f64) -> f64 {
        self.gusts.iter().map(|g| g.change_m_s(t)).sum()
    }

    /// Checks the problem (fields as named in the JSON contract).
    pub fn validate(&self) -> Result<(), InvalidInput> {
        let t = &self.tether;
        require_positive("cable.mass_per_length_kg_m", t.mass_per_length_kg_m)?;
        require_positive("cable.diameter_m", t.diameter_m)?;
        require_non_negative(
            "cable.normal_drag_coefficient_nondim",
            t.normal_drag_coefficient,
        )?;
        require_non_negative(
            "cable.tangential_drag_coefficient_nondim",
            t.tangential_drag_coefficient,
        )?;
        require_positive("cable.axial_stiffness_n", t.axial_stiffness_n)?;
        require_non_negative("cable.internal_damping_n_s", t.internal_damping_n_s)?;
        let a = &self.aerostat;
        require_positive("aerostat.net_buoyancy_n", a.net_buoyancy_n)?;
        require_non_negative("aerostat.mass_kg", a.mass_kg)?;
        require_positive("aerostat.reference_area_m2", a.reference_area_m2)?;
        require_non_negative("aerostat.drag_coefficient_nondim", a.drag_coefficient)?;
        if !a.lift_coefficient.is_finite() {
            return Err(InvalidInput::new(
                "aerostat.lift_coefficient_nondim",
                "must be a finite number",
            ));
        }
        require_non_negative(
            "aerostat.added_mass_coefficient_nondim",
            a.added_mass_coefficient,
        )?;
        require_positive("wind.air_density_kg_m3", self.air_density_kg_m3)?;
        require_positive("gravity_m_s2", self.gravity_m_s2)?;
        if let LengthSchedule::Fixed(l) = self.length {
            require_positive("tether_length_m", l)?;
        }
        Ok(())
    }

    /// The discretised parameters.
    pub fn parameters(&self, segments: usize) -> Parameters {
        let rho = self.air_density_kg_m3;
        let t = &self.tether;
        let a = &self.aerostat;
        let volume = a.displaced_volume_m3(rho, self.gravity_m_s2);
        Parameters {
            segments,
            mass_per_length_kg_m: t.mass_per_length_kg_m,
            gravity_m_s2: self.gravity_m_s2,
            axial_stiffness_n: t.axial_stiffness_n,
            damping_n_s: t.internal_damping_n_s,
            normal_drag: 0.5 * rho * t.normal_drag_coefficient * t.diameter_m,
            tangential_drag: 0.5
                * rho
                * t.tangential_drag_coefficient
                * std::f64::consts::PI
                * t.diameter_m,
            drag_on_stretched_length: t.drag_on_stretched_length,
            net_buoyancy_n: a.net_buoyancy_n,
            aerostat_inertia_kg: a.mass_kg + a.added_mass_coefficient * rho * volume,
            aerostat_drag: 0.5 * rho * a.drag_coefficient * a.reference_area_m2,
            aerostat_lift: 0.5 * rho * a.lift_coefficient * a.reference_area_m2,
        }
    }

    /// The §6 problem of the steady flow at length `length_m`.
    pub fn static_problem(&self, length_m: f64) -> EquilibriumProblem {
        EquilibriumProblem {
            cable: Cable {
                mass_per_length_kg_m: self.tether.mass_per_length_kg_m,
                diameter_m: self.tether.diameter_m,
                normal_drag_coefficient: self.tether.normal_drag_coefficient,
                axial_stiffness_n: Some(self.tether.axial_stiffness_n),
                breaking_strength_n: None,
            },
            body: Body {
                net_buoyancy_n: self.aerostat.net_buoyancy_n,
                drag_coefficient: self.aerostat.drag_coefficient,
                lift_coefficient: self.aerostat.lift_coefficient,
                reference_area_m2: self.aerostat.reference_area_m2,
            },
            wind: self.flow.clone(),
            air_density_kg_m3: self.air_density_kg_m3,
            tether_length_m: length_m,
            gravity_m_s2: self.gravity_m_s2,
        }
    }
}

/// The outcome of a static solve.
#[derive(Clone, Debug, PartialEq)]
pub struct StaticStart {
    pub state: State,
    pub equilibrium: Equilibrium,
    pub iterations: usize,
    /// Largest nodal force imbalance left (N).
    pub residual_n: f64,
}

/// Why no run was made.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DynamicsError {
    #[error(transparent)]
    Invalid(#[from] InvalidInput),
    /// The steady equilibrium is slack: the lumped model has no ground.
    #[error("the tether is slack in the steady flow at the start (it rests on the ground)")]
    SlackStart,
    #[error("the static Newton iteration did not converge (residual {residual_n} N)")]
    NoStaticEquilibrium { residual_n: f64 },
}

fn validate_config(config: &DynamicsConfig) -> Result<(), InvalidInput> {
    if !(MIN_SEGMENTS..=MAX_SEGMENTS).contains(&config.segments) {
        return Err(InvalidInput::new(
            "segments",
            format!(
                "must be between {MIN_SEGMENTS} and {MAX_SEGMENTS}, got {}",
                config.segments
            ),
        ));
    }
    require_positive("time_step_s", config.time_step_s)?;
    require_positive("duration_s", config.duration_s)?;
    require_positive("sample_interval_s", config.sample_interval_s)?;
    if !(0.0..=1.0).contains(&config.spectral_radius) {
        return Err(InvalidInput::new(
            "spectral_radius",
            format!("must lie in [0, 1], got {}", config.spectral_radius),
        ));
    }
    let steps = (config.duration_s / config.time_step_s).ceil();
    if steps > MAX_STEPS as f64 || steps * config.segments as f64 > MAX_WORK {
        return Err(InvalidInput::new(
            "duration_s",
            format!(
                "needs {steps:.0} steps of {} segments: more than {MAX_STEPS} steps or {MAX_WORK:e} segment-steps",
                config.segments
            ),
        ));
    }
    if config.duration_s / config.sample_interval_s > MAX_SAMPLES as f64 {
        return Err(InvalidInput::new(
            "sample_interval_s",
            format!("would keep more than {MAX_SAMPLES} samples"),
        ));
    }
    if config.shape_times_s.len() > MAX_SHAPES {
        return Err(InvalidInput::new(
            "shape_times_s",
            format!("at most {MAX_SHAPES} shapes"),
        ));
    }
    Ok(())
}

/// The static start at `t = 0`: the §6 shooting solution relaxed to the
/// discrete equilibrium in the steady flow (plus `ΔU(0)`, without turbulence).
pub fn static_start(
    problem: &DynamicsProblem,
    segments: usize,
) -> Result<StaticStart, DynamicsError> {
    problem.validate()?;
    let len0 = problem.length.at(0.0);
    let eq_problem = problem.static_problem(len0.length_m);
    let equilibrium = eq_problem.solve(&EquilibriumConfig {
        steps: segments,
        max_iterations: 60,
        keep_shape: true,
    })?;
    if equilibrium.slack {
        return Err(DynamicsError::SlackStart);
    }
    let p = problem.parameters(segments);
    let mut pos: Vec<V2> = equilibrium.shape[1..]
        .iter()
        .map(|s| [s.x_m, s.z_m])
        .collect();
    let vel = vec![[0.0; 2]; segments];
    let at_rest = Length {
        rate_m_s: 0.0,
        acceleration_m_s2: 0.0,
        ..len0
    };
    let du = problem.gust_change_m_s(0.0);
    let flow = &problem.flow;
    let wind = |_x: f64, z: f64| flow.speed_m_s(z) + du;
    let mut ev = Evaluation::new(segments);
    let scale_n = problem.aerostat.net_buoyancy_n;
    let mut residual = f64::INFINITY;
    let mut lower = vec![ZERO; segments];
    let mut diag = vec![ZERO; segments];
    let mut upper = vec![ZERO; segments];
    let mut rhs = vec![[0.0; 2]; segments];
    for it in 0..100 {
        evaluate(&p, at_rest, &pos, &vel, &wind, true, &mut ev);
        residual = ev.force.iter().map(|f| norm(*f)).fold(0.0, f64::max);
        // Roundoff floor: a position known to ε|R| gives a force error of about EA ε |R| / l.
        let floor = 1e-11 * scale_n + 64.0 * f64::EPSILON * p.axial_stiffness_n * segments as f64;
        if residual <= floor {
            // Paying out (or hauling in) at t = 0: the material moves along
            // the tether at L̇, so Ṙ_i = V_i − ζ̇_i R_ζ = ζ_i L̇ R_ζ / L.
            let mut vel = vel;
            if len0.rate_m_s != 0.0 {
                let node = |i: usize| if i == 0 { [0.0; 2] } else { pos[i - 1] };
                let dz = 1.0 / segments as f64;
                for i in 1..=segments {
                    let d = if i < segments {
                        scale(0.5 / dz, blocks::sub(node(i + 1), node(i - 1)))
                    } else {
                        scale(1.0 / dz, blocks::sub(node(i), node(i - 1)))
                    };
                    vel[i - 1] = scale(i as f64 * dz * len0.rate_m_s / len0.length_m, d);
                }
            }
            return Ok(StaticStart {
                state: State {
                    time_s: 0.0,
                    positions: pos,
                    velocities: vel,
                },
                equilibrium,
                iterations: it,
                residual_n: residual,
            });
        }
        // K δ = −P with K = ∂P/∂R.
        for k in 0..segments {
            lower[k] = ev.kx[0][k];
            diag[k] = ev.kx[1][k];
            upper[k] = ev.kx[2][k];
            rhs[k] = scale(-1.0, ev.force[k]);
        }
        if !model::solve_tridiagonal(&lower, &mut diag, &upper, &mut rhs) {
            break;
        }
        // Damp large corrections (a tenth of a segment at most per pass).
        let seg = len0.length_m / segments as f64;
        let big = rhs.iter().map(|d| norm(*d)).fold(0.0, f64::max);
        let factor = if big > 0.1 * seg {
            0.1 * seg / big
        } else {
            1.0
        };
        for (x, d) in pos.iter_mut().zip(&rhs) {
            x[0] += factor * d[0];
            x[1] += factor * d[1];
        }
    }
    Err(DynamicsError::NoStaticEquilibrium {
        residual_n: residual,
    })
}

/// Runs from the static start.
pub fn simulate(problem: &DynamicsProblem, config: &DynamicsConfig) -> Result<Run, DynamicsError> {
    let start = static_start(problem, config.segments)?;
    simulate_from(problem, config, start.state, start.equilibrium, &mut |_| {
        true
    })
}

/// The integrator's constants.
#[derive(Clone, Copy, Debug)]
struct Alpha {
    am: f64,
    af: f64,
    gamma: f64,
    beta: f64,
}

impl Alpha {
    fn new(rho_inf: f64) -> Self {
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

/// The wind at a point and time.
struct Air<'a> {
    flow: &'a WindProfile,
    gusts: &'a [GustHistory],
    field: Option<TurbulenceField>,
}

impl Air<'_> {
    #[inline]
    fn speed(&self, x: f64, z: f64, t: f64) -> f64 {
        let mut u = self.flow.speed_m_s(z);
        for g in self.gusts {
            u += g.change_m_s(t);
        }
        if let Some(f) = &self.field {
            u += f.sample(x, z, t);
        }
        u
    }
}

/// The integrator and its work arrays.
struct Stepper<'a> {
    p: Parameters,
    alpha: Alpha,
    schedule: &'a LengthSchedule,
    air: &'a Air<'a>,
    tol: f64,
    max_it: usize,
    x: Vec<V2>,
    v: Vec<V2>,
    a: Vec<V2>,
    t: f64,
    ev: Evaluation,
    xn: Vec<V2>,
    vn: Vec<V2>,
    an: Vec<V2>,
    xa: Vec<V2>,
    va: Vec<V2>,
    lower: Vec<B2>,
    diag: Vec<B2>,
    upper: Vec<B2>,
    rhs: Vec<V2>,
    stats: Statistics,
}

impl Stepper<'_> {
    fn eval_at(&mut self, t: f64, use_alpha: bool, jac: bool) {
        let len = self.schedule.at(t);
        let air = self.air;
        let wind = |x: f64, z: f64| air.speed(x, z, t);
        let (pos, vel) = if use_alpha {
            (&self.xa, &self.va)
        } else {
            (&self.x, &self.v)
        };
        evaluate(&self.p, len, pos, vel, &wind, jac, &mut self.ev);
    }

    /// Accelerations consistent with the state at `self.t`: `M a = P`.
    fn initial_acceleration(&mut self) {
        self.eval_at(self.t, false, false);
        for k in 0..self.p.segments {
            self.a[k] = scale(1.0 / self.ev.mass[k], self.ev.force[k]);
        }
    }

    /// One step of `h`; `false` if Newton failed (the state is unchanged).
    fn try_step(&mut self, h: f64) -> bool {
        let n = self.p.segments;
        let Alpha {
            am,
            af,
            gamma,
            beta,
        } = self.alpha;
        self.an.copy_from_slice(&self.a);
        let ta = self.t + (1.0 - af) * h;
        for _ in 0..self.max_it {
            for k in 0..n {
                for c in 0..2 {
                    let xn = self.x[k][c]
                        + h * self.v[k][c]
                        + h * h * ((0.5 - beta) * self.a[k][c] + beta * self.an[k][c]);
                    let vn =
                        self.v[k][c] + h * ((1.0 - gamma) * self.a[k][c] + gamma * self.an[k][c]);
                    self.xn[k][c] = xn;
                    self.vn[k][c] = vn;
                    self.xa[k][c] = (1.0 - af) * xn + af * self.x[k][c];
                    self.va[k][c] = (1.0 - af) * vn + af * self.v[k][c];
                }
            }
            self.eval_at(ta, true, true);
            self.stats.newton_iterations += 1;
            let cx = (1.0 - af) * beta * h * h;
            let cvv = (1.0 - af) * gamma * h;
            for k in 0..n {
                let m = self.ev.mass[k];
                for c in 0..2 {
                    let am_k = (1.0 - am) * self.an[k][c] + am * self.a[k][c];
                    self.rhs[k][c] = -(m * am_k - self.ev.force[k][c]);
                }
                let mut d = ZERO;
                add_identity(&mut d, (1.0 - am) * m);
                add_to(&mut d, -cx, &self.ev.kx[1][k]);
                add_to(&mut d, -cvv, &self.ev.cv[1][k]);
                self.diag[k] = d;
                let mut lo = ZERO;
                add_to(&mut lo, -cx, &self.ev.kx[0][k]);
                add_to(&mut lo, -cvv, &self.ev.cv[0][k]);
                self.lower[k] = lo;
                let mut up = ZERO;
                add_to(&mut up, -cx, &self.ev.kx[2][k]);
                add_to(&mut up, -cvv, &self.ev.cv[2][k]);
                self.upper[k] = up;
            }
            if !model::solve_tridiagonal(&self.lower, &mut self.diag, &self.upper, &mut self.rhs) {
                return false;
            }
            let mut big = 0.0f64;
            for k in 0..n {
                self.an[k][0] += self.rhs[k][0];
                self.an[k][1] += self.rhs[k][1];
                big = big.max(norm(self.rhs[k]));
            }
            if !big.is_finite() {
                return false;
            }
            // Converged when every velocity correction is below `tol` (m/s).
            if big * gamma * h <= self.tol {
                for k in 0..n {
                    for c in 0..2 {
                        self.x[k][c] += h * self.v[k][c]
                            + h * h * ((0.5 - beta) * self.a[k][c] + beta * self.an[k][c]);
                        self.v[k][c] += h * ((1.0 - gamma) * self.a[k][c] + gamma * self.an[k][c]);
                    }
                }
                self.a.copy_from_slice(&self.an);
                self.t += h;
                return true;
            }
        }
        false
    }

    /// A step of `h`, halving on failure.
    fn step(&mut self, h: f64, depth: usize) -> bool {
        if self.try_step(h) {
            self.stats.steps += 1;
            return true;
        }
        if depth >= MAX_HALVINGS {
            return false;
        }
        self.stats.halvings += 1;
        self.step(0.5 * h, depth + 1) && self.step(0.5 * h, depth + 1)
    }
}

/// Runs from `state` (at `state.time_s`); `observer` sees every accepted
/// step and stops the run by returning `false`.
pub fn simulate_from(
    problem: &DynamicsProblem,
    config: &DynamicsConfig,
    state: State,
    equilibrium: Equilibrium,
    observer: &mut dyn FnMut(&StepView) -> bool,
) -> Result<Run, DynamicsError> {
    problem.validate()?;
    validate_config(config)?;
    let n = config.segments;
    if state.positions.len() != n || state.velocities.len() != n {
        return Err(InvalidInput::new("segments", "the state does not match the mesh").into());
    }
    let field = match &problem.turbulence {
        Some(t) => {
            let top = problem.length.longest_m(config.duration_s) * 1.2;
            let len0 = problem.length.at(0.0).length_m;
            let z_top = state.positions[n - 1][1].max(0.5 * len0);
            let uc = problem.flow.speed_m_s(z_top).abs();
            let levels = ((top / config.turbulence_level_spacing_m).ceil() as usize + 1).max(4);
            let grid = wind::FieldGrid {
                time_step_s: config.turbulence_time_step_s,
                period_s: config.duration_s + 2.0 * top / uc.max(1e-6) + 10.0,
                top_m: top,
                levels,
                convection_m_s: uc,
            };
            Some(TurbulenceField::synthesise(t, &problem.flow, &grid)?)
        }
        None => None,
    };
    let air = Air {
        flow: &problem.flow,
        gusts: &problem.gusts,
        field,
    };
    let p = problem.parameters(n);
    let mut st = Stepper {
        p,
        alpha: Alpha::new(config.spectral_radius),
        schedule: &problem.length,
        air: &air,
        tol: config.newton_tolerance_m_s,
        max_it: config.max_newton_iterations.max(1),
        x: state.positions,
        v: state.velocities,
        a: vec![[0.0; 2]; n],
        t: state.time_s,
        ev: Evaluation::new(n),
        xn: vec![[0.0; 2]; n],
        vn: vec![[0.0; 2]; n],
        an: vec![[0.0; 2]; n],
        xa: vec![[0.0; 2]; n],
        va: vec![[0.0; 2]; n],
        lower: vec![ZERO; n],
        diag: vec![ZERO; n],
        upper: vec![ZERO; n],
        rhs: vec![[0.0; 2]; n],
        stats: Statistics::default(),
    };
    st.initial_acceleration();

    let t0 = st.t;
    let end = t0 + config.duration_s;
    let mut samples = Vec::new();
    let mut shapes = Vec::new();
    let mut shape_times: Vec<f64> = config.shape_times_s.clone();
    shape_times.sort_by(f64::total_cmp);
    let mut next_shape = 0usize;
    let mut slack_events: Vec<SlackEvent> = Vec::new();
    let mut peak_winch = Extreme {
        value: f64::NEG_INFINITY,
        time_s: t0,
    };
    let mut min_winch = Extreme {
        value: f64::INFINITY,
        time_s: t0,
    };
    let mut peak = Extreme {
        value: f64::NEG_INFINITY,
        time_s: t0,
    };
    let mut next_sample = t0;
    let mut outcome = Outcome::Completed;
    let steps = ((config.duration_s / config.time_step_s) - 1e-9)
        .ceil()
        .max(1.0) as usize;
    let h = config.duration_s / steps as f64;

    // Record the state at the current time (the evaluation must be of the current state).
    let record = |st: &Stepper,
                  samples: &mut Vec<Sample>,
                  shapes: &mut Vec<Shape>,
                  slack_events: &mut Vec<SlackEvent>,
                  peak_winch: &mut Extreme,
                  min_winch: &mut Extreme,
                  peak: &mut Extreme,
                  next_sample: &mut f64,
                  next_shape: &mut usize,
                  force_sample: bool| {
        let t = st.t;
        let ev = &st.ev;
        let winch = norm(ev.winch_force);
        if winch > peak_winch.value {
            *peak_winch = Extreme {
                value: winch,
                time_s: t,
            };
        }
        if winch < min_winch.value {
            *min_winch = Extreme {
                value: winch,
                time_s: t,
            };
        }
        let len = st.schedule.at(t);
        let l = len.length_m / n as f64;
        let mut lowest_slack = None;
        for (j, &tj) in ev.tension.iter().enumerate() {
            if tj > peak.value {
                *peak = Extreme {
                    value: tj,
                    time_s: t,
                };
            }
            if tj <= 0.0 && lowest_slack.is_none() {
                lowest_slack = Some((j as f64 + 0.5) * l);
            }
        }
        match (lowest_slack, slack_events.last_mut()) {
            (Some(s), Some(e)) if e.end_s.is_none() => e.lowest_s_m = e.lowest_s_m.min(s),
            (Some(s), _) => slack_events.push(SlackEvent {
                start_s: t,
                end_s: None,
                lowest_s_m: s,
            }),
            (None, Some(e)) if e.end_s.is_none() => e.end_s = Some(t),
            _ => {}
        }
        let top = st.x[n - 1];
        if force_sample || t >= *next_sample - 1e-9 * config.sample_interval_s {
            samples.push(Sample {
                time_s: t,
                winch_tension_n: winch,
                top_tension_n: norm(ev.top_force),
                aerostat_altitude_m: top[1],
                aerostat_downwind_m: top[0],
                length_m: len.length_m,
                aerostat_wind_m_s: st.air.speed(top[0], top[1], t),
            });
            while *next_sample <= t + 1e-9 * config.sample_interval_s {
                *next_sample += config.sample_interval_s;
            }
        }
        while *next_shape < shape_times.len() && shape_times[*next_shape] <= t + 0.5 * h {
            let mut nodes = Vec::with_capacity(n + 1);
            nodes.push(ShapeNode {
                s_m: 0.0,
                x_m: 0.0,
                z_m: 0.0,
                tension_n: winch,
            });
            for (i, r) in st.x.iter().enumerate() {
                nodes.push(ShapeNode {
                    s_m: (i + 1) as f64 * l,
                    x_m: r[0],
                    z_m: r[1],
                    tension_n: ev.tension[i],
                });
            }
            shapes.push(Shape { time_s: t, nodes });
            *next_shape += 1;
        }
    };

    // The initial evaluation is of the start state.
    st.eval_at(st.t, false, false);
    record(
        &st,
        &mut samples,
        &mut shapes,
        &mut slack_events,
        &mut peak_winch,
        &mut min_winch,
        &mut peak,
        &mut next_sample,
        &mut next_shape,
        false,
    );
    for i in 0..steps {
        if !st.step(h, 0) {
            outcome = Outcome::NewtonFailed { time_s: st.t };
            break;
        }
        if st.x.iter().any(|r| !(r[0].is_finite() && r[1].is_finite())) {
            outcome = Outcome::Diverged { time_s: st.t };
            break;
        }
        // Outputs from the state at the step's end.
        st.eval_at(st.t, false, false);
        let last = i + 1 == steps;
        record(
            &st,
            &mut samples,
            &mut shapes,
            &mut slack_events,
            &mut peak_winch,
            &mut min_winch,
            &mut peak,
            &mut next_sample,
            &mut next_shape,
            last,
        );
        let view = StepView {
            time_s: st.t,
            length: st.schedule.at(st.t),
            positions: &st.x,
            velocities: &st.v,
            evaluation: &st.ev,
            parameters: &st.p,
        };
        if !observer(&view) {
            outcome = Outcome::Stopped { time_s: st.t };
            break;
        }
    }
    let _ = end;
    Ok(Run {
        outcome,
        equilibrium,
        samples,
        shapes,
        slack_events,
        peak_winch_tension: peak_winch,
        min_winch_tension: min_winch,
        peak_tension: peak,
        final_state: State {
            time_s: st.t,
            positions: st.x,
            velocities: st.v,
        },
        statistics: st.stats,
    })
}

/// The aerostat's position as a vector (for observers).
pub fn aerostat(view: &StepView) -> V2 {
    view.positions[view.positions.len() - 1]
}

/// `|a|` re-exported for tests.
pub fn magnitude(v: V2) -> f64 {
    norm(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(crate) fn problem(wind_m_s: f64) -> DynamicsProblem {
        DynamicsProblem {
            tether: Tether {
                mass_per_length_kg_m: 0.078,
                diameter_m: 0.005,
                normal_drag_coefficient: 1.2,
                tangential_drag_coefficient: 0.0,
                axial_stiffness_n: 1e6,
                internal_damping_n_s: 1e4,
                drag_on_stretched_length: true,
            },
            aerostat: Aerostat {
                net_buoyancy_n: 1000.0,
                mass_kg: 10.0,
                reference_area_m2: 20.0,
                drag_coefficient: 0.3,
                lift_coefficient: 0.0,
                added_mass_coefficient: 0.5,
            },
            flow: WindProfile::uniform(wind_m_s),
            gusts: vec![],
            turbulence: None,
            air_density_kg_m3: 1.225,
            gravity_m_s2: 9.81,
            length: LengthSchedule::Fixed(1000.0),
        }
    }

    #[test]
    fn static_start_is_close_to_the_shooting_solution() {
        let p = problem(8.0);
        let s = static_start(&p, 50).unwrap();
        let top = s.state.positions[49];
        // Roundoff floor of the discrete static Newton: about 1e-9 of the
        // ~1000 N tension (measured 6.3e-7 N).
        assert!(s.residual_n < 1e-5, "{}", s.residual_n);
        assert!(
            (top[1] - s.equilibrium.altitude_m).abs() < 1e-3 * 1000.0,
            "{} {}",
            top[1],
            s.equilibrium.altitude_m
        );
    }

    #[test]
    fn equilibrium_stays_put_for_a_minute() {
        let p = problem(8.0);
        let cfg = DynamicsConfig {
            duration_s: 60.0,
            ..Default::default()
        };
        let run = simulate(&p, &cfg).unwrap();
        assert_eq!(run.outcome, Outcome::Completed);
        let s0 = run.samples[0];
        let s1 = *run.samples.last().unwrap();
        assert!((s1.aerostat_altitude_m - s0.aerostat_altitude_m).abs() < 1e-6);
        // Relative 1e-7 of the tension (measured 7e-9 over 60 s: the static
        // start's roundoff floor carried by the integrator).
        assert!(
            (s1.winch_tension_n - s0.winch_tension_n).abs() < 1e-7 * s0.winch_tension_n.abs(),
            "{} {}",
            s0.winch_tension_n,
            s1.winch_tension_n
        );
    }
}
