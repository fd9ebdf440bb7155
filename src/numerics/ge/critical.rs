//! Critical time of a deployment of the GE cable (thesis ch. 7.2–7.4).
//!
//! The cable is marched by Newmark–Newton ([`super::solver`]) from its
//! static equilibrium at `L0` under the net buoyancy, with an optional
//! sideways tip force `F0` that rises linearly over `ramp_s` and is
//! released at `hold_s` (the initial perturbation of Fig. 7.4; app. C of
//! the thesis ramps it over the first quarter time unit and drops it; the
//! default [`TipPerturbation::held`] ramps over 0.25 s and holds to 1 s). About each checked
//! state the local QEP `λ²M + λC + K = 0` (7.3) is solved; the state is
//! locally unstable when `max Re λ > tol`, with
//! `tol = max(growth_tolerance_1_s, 1e-9·ρ(λ))` (`ρ` the spectral radius:
//! the roundoff level of the scaled companion).
//!
//! **Locating the onset between steps.** The QEP is solved every
//! `check_every` steps, and the state of the last stable check is kept.
//! At the first unstable check the march is repeated from that stored
//! state with the same step (the integrator is deterministic, so it
//! retraces the same states) and the QEP is solved at every step of the
//! bracket. `t*` is then the zero of `max Re λ − tol`, linearly
//! interpolated between the last stable and the first unstable step, and
//! `h* = L(t*)`. The test suite shows `t*` does not move when the step and
//! the check interval are refined.
//!
//! **Time stepping.** The march uses [`CriticalConfig::scheme`]: by
//! default generalized-α with `ρ∞ = 0`, which removes the unresolved
//! (axial, high bending) modes that a start from rest or a released tip
//! push sets ringing — with average acceleration they are kept at full
//! amplitude, Newton can fail on them (F0 = 400 N at 12–40 m/s), and a
//! QEP about such a state can report a false early onset. Resolved modes
//! keep second-order accuracy (`tests/verification_ge_integrators.rs`).
//! A step whose Newton iteration fails is halved and retried, at most
//! [`CriticalConfig::max_step_cuts`] levels deep; the cuts are counted in
//! [`GeCriticalTime::step_cuts`].
//!
//! Outcomes (stable for the whole horizon, unstable at the first instant,
//! Newton failure) are values of [`GeOnset`], not errors.

use super::GeModel;
use super::element::TipLoad;
use super::solver::{
    self, BaseMotion, Damping, Drive, EndLoads, Integrator, LengthHistory, LoadShape, NewtonConfig,
    NewtonFailure, Scheme, State,
};
use super::stability;
use super::start::steady_payout_velocity;
pub use super::start::{StartState, root_axial_force_n};
use crate::numerics::aero::Aerodynamics;
use crate::numerics::params::{InvalidInput, require_non_negative, require_positive};
use crate::numerics::profile::Profile;
use crate::numerics::qep::Spectrum;

/// Sideways force on the aerostat at the start of the deployment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TipPerturbation {
    /// Peak force along `E2` (N).
    pub force_n: f64,
    /// Linear rise time (s).
    pub ramp_s: f64,
    /// Release time (s), `≥ ramp_s`.
    pub hold_s: f64,
}

impl TipPerturbation {
    /// The default shape: a ramp over 0.25 s (as in app. C), held to 1 s,
    /// then released.
    pub fn held(force_n: f64) -> Self {
        Self {
            force_n,
            ramp_s: 0.25,
            hold_s: 1.0,
        }
    }

    pub fn validate(&self) -> Result<(), InvalidInput> {
        crate::numerics::params::require_finite("perturbation.force_n", self.force_n)?;
        require_non_negative("perturbation.ramp_s", self.ramp_s)?;
        require_non_negative("perturbation.hold_s", self.hold_s)?;
        if self.hold_s < self.ramp_s {
            return Err(InvalidInput::new(
                "perturbation.hold_s",
                format!("must be at least ramp_s = {} s", self.ramp_s),
            ));
        }
        Ok(())
    }
}

/// What is deployed: the profile, the net buoyancy and the perturbation.
#[derive(Clone, Debug, PartialEq)]
pub struct CriticalProblem {
    pub profile: Profile,
    /// Net buoyancy `F` (N), along the cable at the aerostat.
    pub net_buoyancy_n: f64,
    pub perturbation: Option<TipPerturbation>,
    /// Air flow on the aerostat (ch. 7.5), if any.
    pub aero: Option<Aerodynamics>,
    /// The cable's state when the winch starts.
    pub start: StartState,
}

impl CriticalProblem {
    /// The run's drive (length, end loads, air flow; no damping, fixed platform).
    pub fn drive(&self) -> Drive {
        let steady = TipLoad {
            force_n: [self.net_buoyancy_n, 0.0],
            moment_n_m: 0.0,
        };
        let loads = match self.perturbation {
            Some(p) if p.force_n != 0.0 => EndLoads {
                steady,
                varying: TipLoad {
                    force_n: [0.0, p.force_n],
                    moment_n_m: 0.0,
                },
                shape: LoadShape::Held {
                    ramp_s: p.ramp_s,
                    hold_s: p.hold_s,
                },
            },
            _ => EndLoads::steady(steady),
        };
        Drive {
            length: LengthHistory::Profile(self.profile.clone()),
            loads,
            damping: Damping::default(),
            base: BaseMotion::default(),
            aero: self.aero.clone(),
        }
    }
}

/// Settings of the search.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CriticalConfig {
    /// Newmark step (s).
    pub time_step_s: f64,
    /// Solve the QEP every this many steps (≥ 1) before bracketing.
    pub check_every: usize,
    /// Absolute floor of the growth-rate tolerance (1/s).
    pub growth_tolerance_1_s: f64,
    /// Give up (stable) after this long (s); the profile's stop time caps it too.
    pub horizon_s: f64,
    pub newton: NewtonConfig,
    /// Time-stepping scheme. The default dissipates the unresolved axial
    /// modes (generalized-α, `ρ∞ = 0`), which a start from rest sets
    /// ringing and which otherwise show up as a false early onset.
    pub scheme: Scheme,
    /// When Newton fails, the step is halved and retried, at most this
    /// many levels deep (`Δt / 2^max_step_cuts`); 0: no retry.
    pub max_step_cuts: u32,
}

/// Most halvings of one step the search may make.
pub const MAX_STEP_CUTS: u32 = 12;

impl Default for CriticalConfig {
    /// Coarse but converged for Table 7.1 data at 20 elements (see the
    /// refinement test): Δt = 0.02 s, QEP every 25 steps (0.5 s).
    fn default() -> Self {
        Self {
            time_step_s: 0.02,
            check_every: 25,
            growth_tolerance_1_s: 1e-6,
            horizon_s: 2000.0,
            newton: NewtonConfig::default(),
            scheme: Scheme::DISSIPATIVE_DEFAULT,
            max_step_cuts: 8,
        }
    }
}

impl CriticalConfig {
    pub fn validate(&self) -> Result<(), InvalidInput> {
        require_positive("numerics.time_step_s", self.time_step_s)?;
        require_positive("numerics.horizon_s", self.horizon_s)?;
        require_non_negative("numerics.growth_tolerance_1_s", self.growth_tolerance_1_s)?;
        self.scheme.validate("numerics.rho_infinity_nondim")?;
        if self.max_step_cuts > MAX_STEP_CUTS {
            return Err(InvalidInput::new(
                "numerics.max_step_cuts",
                format!(
                    "must be at most {MAX_STEP_CUTS}, got {}",
                    self.max_step_cuts
                ),
            ));
        }
        if self.check_every == 0 {
            return Err(InvalidInput::new(
                "numerics.check_every_steps",
                "must be at least 1",
            ));
        }
        let steps = self.horizon_s / self.time_step_s;
        if steps > solver::MAX_STEPS as f64 {
            return Err(InvalidInput::new(
                "numerics.time_step_s",
                format!(
                    "the horizon would take {steps:.0} steps; at most {} are allowed",
                    solver::MAX_STEPS
                ),
            ));
        }
        Ok(())
    }
}

/// When the deployment first becomes locally unstable.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GeOnset {
    /// Unstable at `t = 0` (`max Re λ` in 1/s).
    Immediate { max_real_1_s: f64 },
    /// First unstable at `time_s`, length `length_m`.
    During { time_s: f64, length_m: f64 },
    /// Stable until the end of the search.
    Never { until_s: f64 },
    /// The march failed before any instability was seen.
    NewtonFailed(NewtonFailure),
    /// The eigenvalue iteration failed at `time_s`.
    SpectrumFailed { time_s: f64 },
    /// Cancelled by the caller at `time_s`.
    Cancelled { time_s: f64 },
}

/// One QEP check along the march.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GrowthSample {
    pub time_s: f64,
    pub length_m: f64,
    /// `max Re λ` (1/s).
    pub max_real_1_s: f64,
    /// Tolerance applied (1/s).
    pub tolerance_1_s: f64,
    /// Sideways tip displacement (m).
    pub tip_deflection_m: f64,
    /// Axial force in the element at the guide (N): see [`root_axial_force_n`].
    pub root_axial_force_n: f64,
}

/// Result of one search.
#[derive(Clone, Debug, PartialEq)]
pub struct GeCriticalTime {
    pub onset: GeOnset,
    /// The coarse checks (every `check_every` steps), then the bracket.
    pub checks: Vec<GrowthSample>,
    /// Time steps taken, the bracket's repeated march included.
    pub steps: usize,
    /// QEP solves.
    pub qep_solves: usize,
    /// Steps halved and retried after a Newton failure.
    pub step_cuts: usize,
    /// Axial force in the element at the guide at `t*` (N), interpolated
    /// like `t*`; `None` unless the onset is `During`.
    pub onset_root_axial_force_n: Option<f64>,
}

impl GeCriticalTime {
    /// `t*` (s): `Some(0)` when unstable at once, `None` otherwise.
    pub fn time_s(&self) -> Option<f64> {
        match self.onset {
            GeOnset::Immediate { .. } => Some(0.0),
            GeOnset::During { time_s, .. } => Some(time_s),
            _ => None,
        }
    }

    /// `h* = L(t*)` (m).
    pub fn length_m(&self, profile: &Profile) -> Option<f64> {
        match self.onset {
            GeOnset::Immediate { .. } => Some(profile.initial_length_m()),
            GeOnset::During { length_m, .. } => Some(length_m),
            _ => None,
        }
    }
}

/// The straight static equilibrium at the start of `problem`, with a
/// consistent initial acceleration.
pub fn initial_state(
    model: &GeModel,
    problem: &CriticalProblem,
    newton: NewtonConfig,
) -> Result<State, NewtonFailure> {
    let drive = problem.drive();
    let kin = problem.profile.kinematics(0.0);
    let load = drive.tip_load(model, 0.0);
    let q = solver::static_solve(model, kin, load, 2, newton)?;
    let v = match problem.start {
        StartState::AtRest => vec![0.0; q.len()],
        StartState::SteadyPayout => steady_payout_velocity(model, kin, &q),
    };
    let a = solver::initial_acceleration(model, &drive, 0.0, &q, &v).ok_or(NewtonFailure {
        time_s: 0.0,
        iterations: 0,
        residual_norm: f64::NAN,
    })?;
    Ok(State {
        time_s: 0.0,
        q,
        v,
        a,
    })
}

fn growth(
    model: &GeModel,
    drive: &Drive,
    state: &State,
    config: &CriticalConfig,
) -> Option<GrowthSample> {
    let t = state.time_s;
    let kin = drive.length.kinematics(t);
    let spectrum: Spectrum = stability::drive_spectrum(model, drive, state).ok()?;
    let top = model.elements;
    Some(GrowthSample {
        time_s: t,
        length_m: kin.length_m,
        max_real_1_s: spectrum.max_real,
        tolerance_1_s: spectrum.tolerance().max(config.growth_tolerance_1_s),
        tip_deflection_m: state.q[GeModel::dof(top, 1)],
        root_axial_force_n: root_axial_force_n(model, kin.length_m, &state.q),
    })
}

impl GrowthSample {
    pub fn unstable(&self) -> bool {
        self.max_real_1_s > self.tolerance_1_s
    }
}

/// Critical time of `problem` on `model`. `cancel()` is polled every few
/// hundred steps; returning `true` stops the search.
pub fn critical_time(
    model: &GeModel,
    problem: &CriticalProblem,
    config: &CriticalConfig,
    cancel: &(dyn Fn() -> bool + Sync),
) -> Result<GeCriticalTime, InvalidInput> {
    critical_time_observed(model, problem, config, cancel, &|_| {})
}

/// [`critical_time`], also calling `march(fraction)` with the fraction of
/// the horizon marched so far (simulated time / horizon, 0 to 1) each time
/// `cancel()` is polled.
pub fn critical_time_observed(
    model: &GeModel,
    problem: &CriticalProblem,
    config: &CriticalConfig,
    cancel: &(dyn Fn() -> bool + Sync),
    march: &(dyn Fn(f64) + Sync),
) -> Result<GeCriticalTime, InvalidInput> {
    config.validate()?;
    require_positive("net_buoyancy_n", problem.net_buoyancy_n)?;
    if let Some(p) = problem.perturbation {
        p.validate()?;
    }
    let drive = problem.drive();
    let mut out = GeCriticalTime {
        onset: GeOnset::Never { until_s: 0.0 },
        checks: Vec::new(),
        steps: 0,
        qep_solves: 0,
        step_cuts: 0,
        onset_root_axial_force_n: None,
    };
    let start = match initial_state(model, problem, config.newton) {
        Ok(s) => s,
        Err(f) => {
            out.onset = GeOnset::NewtonFailed(f);
            return Ok(out);
        }
    };
    let first = match growth(model, &drive, &start, config) {
        Some(g) => g,
        None => {
            out.onset = GeOnset::SpectrumFailed { time_s: 0.0 };
            return Ok(out);
        }
    };
    out.qep_solves += 1;
    out.checks.push(first);
    if first.unstable() {
        out.onset = GeOnset::Immediate {
            max_real_1_s: first.max_real_1_s,
        };
        return Ok(out);
    }
    let horizon = problem
        .profile
        .stop_time_s()
        .map_or(config.horizon_s, |s| s.min(config.horizon_s));
    let total_steps = (horizon / config.time_step_s).ceil() as usize;
    let dt = config.time_step_s;
    let mut integrator =
        Integrator::new(model, &drive, start.clone(), dt, config.newton).with_scheme(config.scheme);
    let mut stable_state = start;
    let mut stable_sample = first;
    let mut step = 0;
    while step < total_steps {
        if step % 256 == 0 {
            march(step as f64 / total_steps as f64);
        }
        if step % 16 == 0 && cancel() {
            out.onset = GeOnset::Cancelled {
                time_s: integrator.state.time_s,
            };
            return Ok(out);
        }
        match integrator.step_with_cuts(config.max_step_cuts) {
            Ok(s) => out.step_cuts += s.cuts,
            Err(f) => {
                out.onset = GeOnset::NewtonFailed(f);
                return Ok(out);
            }
        }
        step += 1;
        out.steps += 1;
        if step % config.check_every != 0 && step != total_steps {
            continue;
        }
        let Some(sample) = growth(model, &drive, &integrator.state, config) else {
            out.onset = GeOnset::SpectrumFailed {
                time_s: integrator.state.time_s,
            };
            return Ok(out);
        };
        out.qep_solves += 1;
        out.checks.push(sample);
        if !sample.unstable() {
            stable_state = integrator.state.clone();
            stable_sample = sample;
            continue;
        }
        // Bracket: retrace from the last stable check, every step.
        let mut fine = Integrator::new(model, &drive, stable_state.clone(), dt, config.newton)
            .with_scheme(config.scheme);
        let mut before = stable_sample;
        let after = loop {
            if cancel() {
                out.onset = GeOnset::Cancelled {
                    time_s: fine.state.time_s,
                };
                return Ok(out);
            }
            match fine.step_with_cuts(config.max_step_cuts) {
                Ok(s) => out.step_cuts += s.cuts,
                Err(f) => {
                    out.onset = GeOnset::NewtonFailed(f);
                    return Ok(out);
                }
            }
            out.steps += 1;
            let Some(s) = growth(model, &drive, &fine.state, config) else {
                out.onset = GeOnset::SpectrumFailed {
                    time_s: fine.state.time_s,
                };
                return Ok(out);
            };
            out.qep_solves += 1;
            out.checks.push(s);
            if s.unstable() || fine.state.time_s >= sample.time_s - 0.5 * dt {
                break s;
            }
            before = s;
        };
        let (g0, g1) = (
            before.max_real_1_s - before.tolerance_1_s,
            after.max_real_1_s - after.tolerance_1_s,
        );
        let frac = if g1 > g0 {
            (-g0 / (g1 - g0)).clamp(0.0, 1.0)
        } else {
            1.0
        };
        let time_s = before.time_s + frac * (after.time_s - before.time_s);
        out.onset_root_axial_force_n = Some(
            before.root_axial_force_n
                + frac * (after.root_axial_force_n - before.root_axial_force_n),
        );
        out.onset = GeOnset::During {
            time_s,
            length_m: problem.profile.kinematics(time_s).length_m,
        };
        return Ok(out);
    }
    out.onset = GeOnset::Never {
        until_s: integrator.state.time_s,
    };
    Ok(out)
}
