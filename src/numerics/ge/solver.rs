//! Time integration: Newmark average acceleration (β = 1/4, γ = 1/2) by
//! default, or the dissipative generalized-α / HHT-α members of the same
//! family ([`Scheme`]), with Newton–Raphson on the residual of the
//! semi-discrete equations
//!
//! ```text
//! R(q, q̇, q̈, t) = M q̈ + C q̇ + K q + F_int(q) − F_body + T_aerostat(q, q̇, q̈) = 0
//! ```
//!
//! (thesis ch. 6.5, Fig. 6.1). The length `L(t)` comes from a deployment
//! profile; end loads may be held, ramped or pulsed; linear damping may be
//! switched on at a time. Newton stops when `‖R‖ ≤ atol + rtol·s`, with `s`
//! the largest of the norms of the inertia, internal, body and aerostat
//! terms, or when the Newton correction reaches the roundoff level of the
//! unknowns; failure to converge is a [`NewtonFailure`], not a panic.

use super::GeModel;
use super::banded::Band;
use super::diagnostics::{self, Energy};
use super::element::{self, HALF_BAND};
pub use super::equations::{
    AeroTip, BaseMotion, Damping, Drive, EndLoads, LengthHistory, LoadShape, NewtonConfig,
    NewtonFailure, Residual, State, SystemMatrices, drive_matrices, initial_acceleration, residual,
    static_solve, system_matrices,
};
use super::equations::{at_roundoff, newton_correction, norm, residual_with};
use super::stability;
use crate::numerics::params::Kinematics;
use crate::numerics::qep::Spectrum;

/// Largest number of time steps a run may take.
pub const MAX_STEPS: usize = 2_000_000;

/// Newmark parameters of the average-acceleration rule (the default).
pub const BETA: f64 = 0.25;
pub const GAMMA: f64 = 0.5;

/// The time-stepping scheme of the Newton–Newmark march.
///
/// Every scheme here is a member of the Chung–Hulbert generalized-α family
/// (J. Chung, G. M. Hulbert, J. Appl. Mech. 60 (1993) 371–375): the
/// residual is balanced at the intermediate instant `t_{n+1−α_f}`,
///
/// ```text
/// R(q_{n+1−α_f}, q̇_{n+1−α_f}, q̈_{n+1−α_m}, t_{n+1−α_f}) = 0,
/// x_{n+1−α} = (1 − α) x_{n+1} + α x_n,
/// q_{n+1} = q_n + Δt q̇_n + Δt² ((½ − β) q̈_n + β q̈_{n+1}),
/// q̇_{n+1} = q̇_n + Δt ((1 − γ) q̈_n + γ q̈_{n+1}).
/// ```
///
/// All are second-order accurate and unconditionally stable on linear
/// problems; they differ in the spectral radius `ρ∞` of the amplification
/// matrix as `ωΔt → ∞`: the fraction of an unresolved mode's amplitude
/// that survives one step. `ρ∞ = 1` dissipates nothing (trapezoidal);
/// `ρ∞ = 0` annihilates unresolved modes in one step. At low frequency
/// the dissipation is of third order in `ωΔt`, so resolved modes keep
/// their amplitude to second order (tested in `tests/verification_ge_integrators.rs`).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum Scheme {
    /// Newmark average acceleration (β = ¼, γ = ½, α_m = α_f = 0): energy
    /// conserving on linear problems, no dissipation (`ρ∞ = 1`).
    #[default]
    AverageAcceleration,
    /// Chung–Hulbert generalized-α with spectral radius `rho_infinity ∈ [0, 1]`:
    /// `α_m = (2ρ∞ − 1)/(ρ∞ + 1)`, `α_f = ρ∞/(ρ∞ + 1)`,
    /// `γ = ½ − α_m + α_f`, `β = ¼ (1 − α_m + α_f)²`.
    GeneralizedAlpha { rho_infinity: f64 },
    /// Hilber–Hughes–Taylor α (α_m = 0) with spectral radius
    /// `rho_infinity ∈ [½, 1]`: `α_f = (1 − ρ∞)/(1 + ρ∞)`,
    /// `γ = ½ + α_f`, `β = ¼ (1 + α_f)²`.
    HhtAlpha { rho_infinity: f64 },
}

/// The four coefficients of a [`Scheme`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SchemeCoefficients {
    pub alpha_m: f64,
    pub alpha_f: f64,
    pub beta: f64,
    pub gamma: f64,
}

impl Scheme {
    /// The dissipating scheme the critical-time search uses by default:
    /// generalized-α with `ρ∞ = 0` (asymptotic annihilation: a mode far
    /// above the step's resolution is gone after one step; `α_f = 0`, so
    /// the residual is balanced at `t_{n+1}`, the instant whose state the
    /// local QEP is solved about). Measured (Table 7.1, 20 elements,
    /// Δt = 0.02 s, `tests/verification_ge_search.rs`): with `ρ∞ = 0.5` a
    /// massless aerostat pushed with F0 = 400 N at 12 m/s shows a false
    /// onset at 1.04 s, just after the push is released (true t* 112.4 s);
    /// with `ρ∞ = 0.25` it needs a step cut; with `ρ∞ = 0` neither.
    pub const DISSIPATIVE_DEFAULT: Scheme = Scheme::GeneralizedAlpha { rho_infinity: 0.0 };

    pub fn coefficients(&self) -> SchemeCoefficients {
        match *self {
            Self::AverageAcceleration => SchemeCoefficients {
                alpha_m: 0.0,
                alpha_f: 0.0,
                beta: BETA,
                gamma: GAMMA,
            },
            Self::GeneralizedAlpha { rho_infinity: r } => {
                let alpha_m = (2.0 * r - 1.0) / (r + 1.0);
                let alpha_f = r / (r + 1.0);
                let d = 1.0 - alpha_m + alpha_f;
                SchemeCoefficients {
                    alpha_m,
                    alpha_f,
                    beta: 0.25 * d * d,
                    gamma: 0.5 - alpha_m + alpha_f,
                }
            }
            Self::HhtAlpha { rho_infinity: r } => {
                let alpha_f = (1.0 - r) / (1.0 + r);
                SchemeCoefficients {
                    alpha_m: 0.0,
                    alpha_f,
                    beta: 0.25 * (1.0 + alpha_f) * (1.0 + alpha_f),
                    gamma: 0.5 + alpha_f,
                }
            }
        }
    }

    /// Spectral radius at `ωΔt → ∞` (the stated dissipation).
    pub fn rho_infinity(&self) -> f64 {
        match *self {
            Self::AverageAcceleration => 1.0,
            Self::GeneralizedAlpha { rho_infinity } | Self::HhtAlpha { rho_infinity } => {
                rho_infinity
            }
        }
    }

    /// Checks `ρ∞` against the scheme's range (`field` names it).
    pub fn validate(&self, field: &str) -> Result<(), crate::numerics::params::InvalidInput> {
        let (lo, r) = match *self {
            Self::AverageAcceleration => return Ok(()),
            Self::GeneralizedAlpha { rho_infinity } => (0.0, rho_infinity),
            Self::HhtAlpha { rho_infinity } => (0.5, rho_infinity),
        };
        if !(lo..=1.0).contains(&r) {
            return Err(crate::numerics::params::InvalidInput::new(
                field,
                format!("must be between {lo} and 1, got {r}"),
            ));
        }
        Ok(())
    }
}

/// Advances one state by Newton-corrected steps of a [`Scheme`].
pub struct Integrator<'a> {
    pub model: &'a GeModel,
    pub drive: &'a Drive,
    pub state: State,
    pub time_step_s: f64,
    pub newton: NewtonConfig,
    pub scheme: Scheme,
}

/// A step taken with cuts: Newton iterations and how many times a failed
/// step was halved and retried.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CutStep {
    pub iterations: usize,
    pub cuts: usize,
}

impl<'a> Integrator<'a> {
    /// Average acceleration (the default [`Scheme`]).
    pub fn new(
        model: &'a GeModel,
        drive: &'a Drive,
        state: State,
        time_step_s: f64,
        newton: NewtonConfig,
    ) -> Self {
        Self {
            model,
            drive,
            state,
            time_step_s,
            newton,
            scheme: Scheme::default(),
        }
    }

    pub fn with_scheme(mut self, scheme: Scheme) -> Self {
        self.scheme = scheme;
        self
    }

    /// One step of `time_step_s`; when Newton fails, the step is retried
    /// as two halves, each of which may be halved again, at most
    /// `max_cuts` levels deep (the smallest step is `Δt / 2^max_cuts`).
    /// The state after success is at `t + Δt`, so the caller's step grid
    /// is kept. On failure the state is left where the last successful
    /// sub-step put it.
    pub fn step_with_cuts(&mut self, max_cuts: u32) -> Result<CutStep, NewtonFailure> {
        let dt = self.time_step_s;
        let t_end = self.state.time_s + dt;
        let out = self.advance(dt, max_cuts);
        self.time_step_s = dt;
        if out.is_ok() {
            self.state.time_s = t_end;
        }
        out
    }

    fn advance(&mut self, dt: f64, cuts_left: u32) -> Result<CutStep, NewtonFailure> {
        self.time_step_s = dt;
        match self.step() {
            Ok(iterations) => Ok(CutStep {
                iterations,
                cuts: 0,
            }),
            Err(f) if cuts_left == 0 => Err(f),
            Err(_) => {
                let first = self.advance(0.5 * dt, cuts_left - 1)?;
                let second = self.advance(0.5 * dt, cuts_left - 1)?;
                Ok(CutStep {
                    iterations: first.iterations + second.iterations,
                    cuts: 1 + first.cuts + second.cuts,
                })
            }
        }
    }

    /// One step; returns the number of Newton iterations (linear solves).
    /// The state is replaced only when Newton converges.
    pub fn step(&mut self) -> Result<usize, NewtonFailure> {
        let model = self.model;
        let n = model.dofs();
        let dt = self.time_step_s;
        let SchemeCoefficients {
            alpha_m,
            alpha_f,
            beta,
            gamma,
        } = self.scheme.coefficients();
        let t1 = self.state.time_s + dt;
        // the instant at which the residual is balanced
        let ta = t1 - alpha_f * dt;
        let kin = self.drive.length.kinematics(ta);
        let load = self.drive.tip_load(model, ta);
        let base = self.drive.base.acceleration_m_s2(ta);
        let mu = self.drive.damping.at(ta);
        let lin = element::linear_operators(model, kin, mu);
        let (qn, vn, an) = (&self.state.q, &self.state.v, &self.state.a);
        let alpha_a = 1.0 / (beta * dt * dt);
        let alpha_v = gamma / (beta * dt);
        // d(q, q̇, q̈ at the balance instant)/dq_{n+1}
        let (c_q, c_v, c_a) = (
            1.0 - alpha_f,
            (1.0 - alpha_f) * alpha_v,
            (1.0 - alpha_m) * alpha_a,
        );
        let mut q: Vec<f64> = (0..n)
            .map(|i| qn[i] + dt * vn[i] + 0.5 * dt * dt * an[i])
            .collect();
        let mut a = vec![0.0; n];
        let mut v = vec![0.0; n];
        let (mut qa, mut va, mut aa) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let update = |q: &[f64], a: &mut [f64], v: &mut [f64]| {
            for i in 0..n {
                a[i] = alpha_a * (q[i] - qn[i] - dt * vn[i]) - (0.5 / beta - 1.0) * an[i];
                v[i] = vn[i] + dt * ((1.0 - gamma) * an[i] + gamma * a[i]);
            }
        };
        let mut iterations = 0;
        let mut tangent = Band::zeros(n, HALF_BAND, HALF_BAND);
        loop {
            update(&q, &mut a, &mut v);
            if alpha_f == 0.0 && alpha_m == 0.0 {
                qa.copy_from_slice(&q);
                va.copy_from_slice(&v);
                aa.copy_from_slice(&a);
            } else {
                for i in 0..n {
                    qa[i] = (1.0 - alpha_f) * q[i] + alpha_f * qn[i];
                    va[i] = (1.0 - alpha_f) * v[i] + alpha_f * vn[i];
                    aa[i] = (1.0 - alpha_m) * a[i] + alpha_m * an[i];
                }
            }
            let aero = self.drive.aero_tip(model, ta, &qa, &va);
            let r = residual_with(model, &lin, kin, load, base, aero, &qa, &va, &aa);
            let rn = norm(&r.total);
            if rn <= self.newton.absolute_tolerance_n + self.newton.relative_tolerance * r.scale {
                break;
            }
            if iterations >= self.newton.max_iterations || !rn.is_finite() {
                return Err(NewtonFailure {
                    time_s: t1,
                    iterations,
                    residual_norm: rn,
                });
            }
            // S = c_q (K + K_int + K_tip) + c_v C + c_a M
            tangent.fill_zero();
            tangent.add_scaled(c_q, &lin.stiffness);
            tangent.add_scaled(c_v, &lin.damping);
            tangent.add_scaled(c_a, &lin.mass);
            let mut scratch = vec![0.0; n];
            if c_q == 1.0 {
                element::internal_forces(
                    model,
                    kin.length_m,
                    &qa,
                    &mut scratch,
                    Some(&mut tangent),
                    None,
                );
            } else {
                let mut k_int = Band::zeros(n, HALF_BAND, HALF_BAND);
                element::internal_forces(
                    model,
                    kin.length_m,
                    &qa,
                    &mut scratch,
                    Some(&mut k_int),
                    None,
                );
                tangent.add_scaled(c_q, &k_int);
            }
            let top = model.elements;
            let tip = element::tip_terms(
                model,
                kin,
                element::node(&qa, top),
                element::node(&va, top),
                element::node(&aa, top),
                load,
            );
            for i in 0..3 {
                for j in 0..3 {
                    let value =
                        c_q * tip.stiffness[i][j] + c_v * tip.damping[i][j] + c_a * tip.mass[i][j];
                    tangent.add(GeModel::dof(top, i), GeModel::dof(top, j), value);
                }
            }
            let y = GeModel::dof(top, 1);
            tangent.add(y, y, c_v * aero.damping_n_s_m + c_a * aero.added_mass_kg);
            let dq = newton_correction(tangent.clone(), &r.total, &mut q).ok_or(NewtonFailure {
                time_s: t1,
                iterations,
                residual_norm: rn,
            })?;
            iterations += 1;
            if at_roundoff(&dq, &q, kin.length_m) {
                update(&q, &mut a, &mut v);
                break;
            }
        }
        self.state = State {
            time_s: t1,
            q,
            v,
            a,
        };
        Ok(iterations)
    }
}

/// Settings of a transient run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RunConfig {
    pub time_step_s: f64,
    pub duration_s: f64,
    pub newton: NewtonConfig,
    /// Record a sample every this many steps (≥ 1); the last step is always recorded.
    pub record_every: usize,
    /// Solve the local QEP every this many steps (0: never).
    pub eigen_every: usize,
}

/// One recorded instant.
#[derive(Clone, Debug, PartialEq)]
pub struct Sample {
    pub time_s: f64,
    pub kinematics: Kinematics,
    /// Top of the cable (m): along the guide and across it.
    pub tip: [f64; 2],
    pub tip_rotation_rad: f64,
    /// The aerostat's mass point (m).
    pub aerostat: [f64; 2],
    pub energy: Energy,
    /// Angular momentum about the root (6.27) (N m s).
    pub angular_momentum_n_m_s: f64,
    /// Support reaction at the root on the cable: force (N), moment (N m).
    pub root_force_n: [f64; 2],
    pub root_moment_n_m: f64,
    /// Newton iterations of the step that produced this sample.
    pub newton_iterations: usize,
}

/// How a run ended.
#[derive(Clone, Debug, PartialEq)]
pub enum RunOutcome {
    Completed,
    NewtonFailed { step: usize, failure: NewtonFailure },
    Cancelled { step: usize, time_s: f64 },
}

/// The local QEP along the run.
#[derive(Clone, Debug)]
pub struct SpectrumSample {
    pub time_s: f64,
    pub length_m: f64,
    pub spectrum: Spectrum,
}

#[derive(Clone, Debug)]
pub struct RunResult {
    pub samples: Vec<Sample>,
    pub spectra: Vec<SpectrumSample>,
    pub outcome: RunOutcome,
    pub steps: usize,
    pub newton_iterations_total: usize,
    pub newton_iterations_max: usize,
    pub final_state: State,
    /// QEP solves that failed (eigenvalue iteration did not converge).
    pub spectrum_failures: usize,
}

impl RunResult {
    pub fn mean_newton_iterations(&self) -> f64 {
        if self.steps == 0 {
            0.0
        } else {
            self.newton_iterations_total as f64 / self.steps as f64
        }
    }
}

/// Diagnostics of a state.
pub fn sample(model: &GeModel, drive: &Drive, state: &State, newton_iterations: usize) -> Sample {
    let t = state.time_s;
    let kin = drive.length.kinematics(t);
    let mu = drive.damping.at(t);
    let top = model.elements;
    let (qt, vt) = (element::node(&state.q, top), element::node(&state.v, top));
    let (aerostat, _) = element::tip_point(model, kin, qt, vt);
    let reaction = diagnostics::root_reaction(model, kin, mu, &state.q, &state.v, &state.a);
    Sample {
        time_s: t,
        kinematics: kin,
        tip: [kin.length_m + qt[0], qt[1]],
        tip_rotation_rad: qt[2],
        aerostat,
        energy: diagnostics::energy(model, kin, &state.q, &state.v),
        angular_momentum_n_m_s: diagnostics::angular_momentum(model, kin, &state.q, &state.v),
        root_force_n: [reaction[0], reaction[1]],
        root_moment_n_m: reaction[2],
        newton_iterations,
    }
}

/// Runs from `initial` for `config.duration_s`. `observer(done, total)` is
/// called every few steps; returning `false` cancels.
pub fn run(
    model: &GeModel,
    drive: &Drive,
    initial: State,
    config: RunConfig,
    observer: &mut dyn FnMut(usize, usize) -> bool,
) -> RunResult {
    let steps_total = (config.duration_s / config.time_step_s).round() as usize;
    let every = config.record_every.max(1);
    let mut samples = vec![sample(model, drive, &initial, 0)];
    let mut spectra = Vec::new();
    let mut spectrum_failures = 0;
    let mut record_spectrum = |state: &State, spectra: &mut Vec<SpectrumSample>| {
        let kin = drive.length.kinematics(state.time_s);
        match stability::drive_spectrum(model, drive, state) {
            Ok(spectrum) => spectra.push(SpectrumSample {
                time_s: state.time_s,
                length_m: kin.length_m,
                spectrum,
            }),
            Err(_) => spectrum_failures += 1,
        }
    };
    if config.eigen_every > 0 {
        record_spectrum(&initial, &mut spectra);
    }
    let mut integrator = Integrator::new(model, drive, initial, config.time_step_s, config.newton);
    let (mut total, mut max) = (0, 0);
    let mut outcome = RunOutcome::Completed;
    // At most 64 steps between two polls: a cancelled run stops promptly.
    let report_every = (steps_total / 200).clamp(1, 64);
    let mut steps = 0;
    for step in 1..=steps_total {
        if step % report_every == 0 && !observer(step, steps_total) {
            outcome = RunOutcome::Cancelled {
                step,
                time_s: integrator.state.time_s,
            };
            break;
        }
        match integrator.step() {
            Ok(it) => {
                steps = step;
                total += it;
                max = max.max(it);
                if step % every == 0 || step == steps_total {
                    samples.push(sample(model, drive, &integrator.state, it));
                }
                if config.eigen_every > 0 && step % config.eigen_every == 0 {
                    record_spectrum(&integrator.state, &mut spectra);
                }
            }
            Err(failure) => {
                outcome = RunOutcome::NewtonFailed { step, failure };
                break;
            }
        }
    }
    observer(steps, steps_total);
    RunResult {
        samples,
        spectra,
        outcome,
        steps,
        newton_iterations_total: total,
        newton_iterations_max: max,
        final_state: integrator.state,
        spectrum_failures,
    }
}
