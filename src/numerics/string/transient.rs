//! Transient response of the linear string (SPEC §2, thesis ch. 3.5, 4.3,
//! 4.4, app. A): Newmark average acceleration on the time-varying
//! `M, C, K` of the deployment, with the aerostat loaded by the air flow,
//! and the frequency response built from many such runs.
//!
//! The run is non-dimensional inside (`t̄ = t c/L0`, `η = y/L0`); the tip
//! load enters the last equation as `F/F_net` (the natural boundary
//! condition (2.17) with the flow force of (4.4)). Outputs are SI and
//! decimated to a requested number of samples; each sample also carries the
//! envelope `max |y_tip|` since the previous one, so decimation never hides
//! a peak.
//!
//! Energy (3.14), in units of `F L0` then converted to J:
//!
//! ```text
//! Ẽ = ½ l q̇ᵀ𝕄q̇ + l̇ q̇ᵀℂq + ½ (l̇²/l) qᵀ𝕊₂q + ½ m̃_tip q̇_tip² + ½ qᵀ(T_top 𝕊₀ + T_slope 𝕊₁)q
//!   + ½ (l + m̃) l̇²
//! ```
//!
//! (operators of [`super::operators`]); the last term is the kinetic energy of
//! the axial motion, reported apart as well (`vibration` excludes it).

use std::sync::atomic::{AtomicUsize, Ordering};

use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

use crate::numerics::aero::{Aerodynamics, AirFlow};
use crate::numerics::newmark::{Newmark, NewmarkParameters, NewmarkState, StepError};
use crate::numerics::parallel::Parallelism;
use crate::numerics::params::{
    InvalidInput, Kinematics, NondimState, require_finite, require_positive,
};
use crate::numerics::profile::Profile;
use crate::numerics::qep::{self, QepError};
use crate::numerics::string::StringModel;
use crate::numerics::string::operators::{MatrixCoefficients, SecondOrderSystem, StringOperators};
use crate::numerics::tridiag::Tridiagonal;

/// Most time steps one run may take.
pub const MAX_STEPS: usize = 5_000_000;
/// Most `steps × elements` one run may cost.
pub const MAX_WORK: usize = 500_000_000;
/// Most output samples of one run.
pub const MAX_SAMPLES: usize = 100_000;
/// Most eigenvalue evaluations along one run.
pub const MAX_EIGEN_EVALUATIONS: usize = 10_000;
/// Most `evaluations × (2n)³` of the eigenvalue tracking of one run (dense
/// QEP solves cost `O((2n)³)`: about a minute at this bound).
pub const MAX_EIGEN_WORK: f64 = 5e10;
/// Most forcing frequencies of one frequency response.
pub const MAX_FREQUENCIES: usize = 1_024;
/// Most `steps × elements × frequencies` of one frequency response.
pub const MAX_RESPONSE_WORK: usize = 20_000_000_000;
/// Steps per period of the fastest resolved motion when the step is automatic.
pub const STEPS_PER_PERIOD: f64 = 64.0;
/// Steps per ramp of the profile when the step is automatic.
pub const STEPS_PER_RAMP: f64 = 8.0;
/// The run stops as diverged when `|η|` exceeds this (deflections of
/// `1e100 L0` are far outside the linear model, and near overflow).
pub const DIVERGENCE_LIMIT: f64 = 1e100;
/// The run stops, diverged, when any deflection exceeds this multiple of
/// the cable length at that instant: far past the linear model (whose
/// deflections are small against the length), so the growth after onset
/// is shown up to a stated magnitude instead of to overflow.
pub const MAGNITUDE_CAP_LENGTHS: f64 = 1000.0;
/// The run stops when the length falls below this fraction of `L0`.
pub const MIN_LENGTH_FRACTION: f64 = 1e-3;

/// How the cable starts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum InitialState {
    /// Straight and at rest (moves only under loads).
    Rest,
    /// `y(ζ, 0) = a ζ⁴` at rest, `a = tip_deflection_m` (thesis app. A).
    Shape { tip_deflection_m: f64 },
    /// Mode `mode` (1-based) of the cable at rest at the initial length
    /// (`l̇ = l̈ = 0`), scaled to the tip deflection, at rest.
    Mode { mode: usize, tip_deflection_m: f64 },
    /// At rest; a horizontal force on the aerostat for `duration_s`, then
    /// released (thesis ch. 7, `F0`).
    TipForce { force_n: f64, duration_s: f64 },
}

/// Eigenvalues along the run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EigenTracking {
    /// Interval between evaluations (s).
    pub interval_s: f64,
    /// How many modes to keep (by frequency).
    pub count: usize,
}

/// What to run.
#[derive(Clone, Debug, PartialEq)]
pub struct TransientConfig {
    pub duration_s: f64,
    /// `None`: automatic ([`STEPS_PER_PERIOD`] per period of the first mode
    /// at the start and at the end, and of the forcing).
    pub time_step_s: Option<f64>,
    /// Number of output samples (≥ 2; at most steps + 1 are returned).
    pub samples: usize,
    pub initial: InitialState,
    pub aero: Option<Aerodynamics>,
    pub eigen: Option<EigenTracking>,
}

/// Progress and cancellation for long runs (called from the integrating
/// thread; `report` may come from several threads in a sweep).
pub trait Observer: Sync {
    fn report(&self, _done: usize, _total: usize) {}
    fn cancelled(&self) -> bool {
        false
    }
}

/// An observer that ignores everything.
pub struct Silent;

impl Observer for Silent {}

/// One output sample (SI).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    pub time_s: f64,
    pub length_m: f64,
    pub rate_m_s: f64,
    pub tip_deflection_m: f64,
    pub tip_velocity_m_s: f64,
    /// `max |y_tip|` over the steps since the previous sample (m).
    pub tip_envelope_m: f64,
    /// Total energy (3.14) (J).
    pub energy_j: f64,
    /// Energy without the axial kinetic term `½(ρA L + m) L̇²` (J).
    pub vibration_energy_j: f64,
    /// Aerodynamic force on the aerostat (N).
    pub tip_force_n: f64,
}

/// One eigenvalue in SI.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModeSi {
    pub re_1_s: f64,
    pub im_1_s: f64,
}

/// Eigenvalues at one instant of the run.
#[derive(Clone, Debug, PartialEq)]
pub struct EigenSample {
    pub time_s: f64,
    pub length_m: f64,
    /// Largest `Re λ` (1/s).
    pub max_real_1_s: f64,
    pub stable: bool,
    /// The first modes (`Im λ ≥ 0`) by frequency.
    pub modes: Vec<ModeSi>,
}

/// How the run ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RunOutcome {
    Completed,
    /// A deflection exceeded [`MAGNITUDE_CAP_LENGTHS`] × the length (then
    /// [`TransientRun::stopped_at_cap`]) or [`DIVERGENCE_LIMIT`], or a step failed.
    Diverged {
        time_s: f64,
    },
    /// The length fell below [`MIN_LENGTH_FRACTION`] of `L0`.
    LengthCollapsed {
        time_s: f64,
    },
    Cancelled {
        time_s: f64,
    },
}

/// Result of a run.
#[derive(Clone, Debug, PartialEq)]
pub struct TransientRun {
    pub samples: Vec<Sample>,
    pub eigen: Vec<EigenSample>,
    pub outcome: RunOutcome,
    pub time_step_s: f64,
    /// Steps taken.
    pub steps: usize,
    /// Non-dimensional state at the end (`t̄`, `η`, `η̇`, `η̈`).
    pub final_state: NewmarkState,
    pub final_kinematics: Kinematics,
    /// Tip mass used, `m̃ + ½ m_f/(ρA L0)`.
    pub tip_mass_nondim: f64,
    /// The run stopped because a deflection passed [`MAGNITUDE_CAP_LENGTHS`]
    /// × the length; the cap at that instant is
    /// `MAGNITUDE_CAP_LENGTHS × final_kinematics.length_m`.
    pub stopped_at_cap: bool,
}

/// Errors of a run: bad input or a failed eigenvalue solve.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum TransientError {
    #[error(transparent)]
    Invalid(#[from] InvalidInput),
    #[error(transparent)]
    Qep(#[from] QepError),
}

/// Validated plan of a run: the step and the step count.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepPlan {
    pub time_step_s: f64,
    pub steps: usize,
}

/// Fills `out` with `M, C, K` for the coefficients (no allocation).
fn assemble_into(ops: &StringOperators, c: &MatrixCoefficients, out: &mut SecondOrderSystem) {
    let terms_k = [
        (c.conv_stiffness, &ops.conv),
        (-c.quad_stiffness, &ops.stiff_2),
        (c.tension_top, &ops.stiff_0),
        (c.tension_slope, &ops.stiff_1),
    ];
    let n = ops.dim();
    for i in 0..n {
        out.mass.diag[i] = c.mass_scale * ops.mass.diag[i];
        out.damping.diag[i] = c.damping_scale * ops.conv.diag[i];
        out.stiffness.diag[i] = terms_k.iter().map(|(a, t)| a * t.diag[i]).sum();
    }
    for i in 0..n - 1 {
        out.mass.lower[i] = c.mass_scale * ops.mass.lower[i];
        out.mass.upper[i] = c.mass_scale * ops.mass.upper[i];
        out.damping.lower[i] = c.damping_scale * ops.conv.lower[i];
        out.damping.upper[i] = c.damping_scale * ops.conv.upper[i];
        out.stiffness.lower[i] = terms_k.iter().map(|(a, t)| a * t.lower[i]).sum();
        out.stiffness.upper[i] = terms_k.iter().map(|(a, t)| a * t.upper[i]).sum();
    }
    out.mass.diag[n - 1] += c.tip_mass;
}

fn zero_system(n: usize) -> SecondOrderSystem {
    SecondOrderSystem {
        mass: Tridiagonal::zeros(n),
        damping: Tridiagonal::zeros(n),
        stiffness: Tridiagonal::zeros(n),
    }
}

/// Everything needed to evaluate the system at a time.
struct Evaluator<'a> {
    model: &'a StringModel,
    profile: &'a Profile,
    aero: Option<&'a Aerodynamics>,
    tip_force: Option<(f64, f64)>,
    added_mass_nondim: f64,
}

/// System and load at `t_s` with the tip velocity `tip_velocity` (non-dim)
/// for linearising the drag; returns the kinematics and the tip force (N).
impl Evaluator<'_> {
    fn evaluate(
        &self,
        t_s: f64,
        tip_velocity: f64,
        sys: &mut SecondOrderSystem,
        load: &mut [f64],
    ) -> (Kinematics, NondimState, f64) {
        let system = &self.model.system;
        let k = self.profile.kinematics(t_s);
        let s = system.to_nondim(k);
        let mut c = self.model.coefficients(s);
        c.tip_mass += self.added_mass_nondim;
        assemble_into(&self.model.operators, &c, sys);
        let last = load.len() - 1;
        load[last] = 0.0;
        let f_net = system.net_buoyancy_n;
        let mut force_n = 0.0;
        if let Some(aero) = self.aero {
            let c_wave = system.wave_speed_m_s();
            let tl = aero.tip_load(k.length_m, t_s, tip_velocity * c_wave);
            // ẏ = c η̇: damping (N s/m) → c/F per unit η̇
            sys.damping.diag[last] += tl.damping_n_s_m * c_wave / f_net;
            load[last] += tl.force_n / f_net;
            force_n = tl.force_n - tl.damping_n_s_m * tip_velocity * c_wave;
        }
        if let Some((f0, hold)) = self.tip_force
            && t_s < hold
        {
            load[last] += f0 / f_net;
            force_n += f0;
        }
        (k, s, force_n)
    }
}

/// Non-dimensional energy (3.14): `(total, vibration)`.
pub fn energy_nondim(
    ops: &StringOperators,
    c: &MatrixCoefficients,
    s: NondimState,
    mass_ratio: f64,
    q: &[f64],
    qd: &[f64],
) -> (f64, f64) {
    let n = q.len();
    let mut vib = 0.5 * s.length * ops.mass.quadratic_form(qd);
    let mut tmp = vec![0.0; n];
    ops.conv.mul_vec(q, &mut tmp);
    vib += s.rate * qd.iter().zip(&tmp).map(|(a, b)| a * b).sum::<f64>();
    vib += 0.5 * c.quad_stiffness * ops.stiff_2.quadratic_form(q);
    vib += 0.5 * c.tip_mass * qd[n - 1] * qd[n - 1];
    vib += 0.5
        * (c.tension_top * ops.stiff_0.quadratic_form(q)
            + c.tension_slope * ops.stiff_1.quadratic_form(q));
    let axial = 0.5 * (s.length + mass_ratio) * s.rate * s.rate;
    (vib + axial, vib)
}

/// The `k`-th (1-based) eigenvalue `ω²` of the symmetric pencil `(K, M)` of
/// a cable at rest (`l̇ = l̈ = 0`), by bisection on the inertia of
/// `K − σM` (the number of negative pivots is the number of eigenvalues
/// below `σ`): `O(n)` per step, no dense solve.
pub fn rest_eigenvalue(sys: &SecondOrderSystem, k: usize) -> Option<f64> {
    let n = sys.mass.dim();
    if k == 0 || k > n {
        return None;
    }
    let below = |sigma: f64| {
        Tridiagonal::combination(&[(1.0, &sys.stiffness), (-sigma, &sys.mass)]).negative_pivots()
    };
    let (mut lo, mut hi) = (-1.0, 1.0);
    while below(lo) >= k {
        lo *= 2.0;
        if lo < -1e300 {
            return None;
        }
    }
    while below(hi) < k {
        hi *= 2.0;
        if hi > 1e300 {
            return None;
        }
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi || hi - lo <= 1e-15 * hi.abs().max(lo.abs()) {
            break;
        }
        if below(mid) >= k { hi = mid } else { lo = mid }
    }
    Some(0.5 * (lo + hi))
}

fn rest_system(model: &StringModel, length: f64, added_mass_nondim: f64) -> SecondOrderSystem {
    let mut c = model.coefficients(NondimState {
        length,
        rate: 0.0,
        acceleration: 0.0,
    });
    c.tip_mass += added_mass_nondim;
    model.operators.assemble(&c)
}

/// First natural frequency (rad/s) of the cable at rest at `length_m`;
/// `None` if the cable cannot hold that length at rest. Used to pick the
/// automatic step.
fn first_frequency_1_s(
    model: &StringModel,
    k: Kinematics,
    added_mass_nondim: f64,
) -> Result<Option<f64>, QepError> {
    let length = k.length_m / model.system.initial_length_m;
    let lambda = rest_eigenvalue(&rest_system(model, length, added_mass_nondim), 1);
    Ok(lambda
        .filter(|&l| l > 0.0)
        .map(|l| model.system.eigenvalue_to_si(l.sqrt())))
}

/// Validates the configuration and fixes the time step.
pub fn plan(
    model: &StringModel,
    profile: &Profile,
    config: &TransientConfig,
) -> Result<StepPlan, TransientError> {
    let duration = require_positive("duration_s", config.duration_s)?;
    if config.samples < 2 || config.samples > MAX_SAMPLES {
        return Err(InvalidInput::new(
            "samples",
            format!(
                "must be between 2 and {MAX_SAMPLES}, got {}",
                config.samples
            ),
        )
        .into());
    }
    if let Some(e) = config.eigen {
        require_positive("eigenvalues.interval_s", e.interval_s)?;
        if e.count == 0 || e.count > model.elements() {
            return Err(InvalidInput::new(
                "eigenvalues.count",
                format!(
                    "must be between 1 and the number of elements ({}), got {}",
                    model.elements(),
                    e.count
                ),
            )
            .into());
        }
        let evaluations = duration / e.interval_s;
        let per_solve = (2.0 * model.elements() as f64).powi(3);
        if (evaluations + 1.0) * per_solve > MAX_EIGEN_WORK {
            return Err(InvalidInput::new(
                "eigenvalues.interval_s",
                format!(
                    "{:.0} eigenvalue solves on {} elements exceed the work limit; use an interval of at least {:.4} s or fewer elements",
                    evaluations + 1.0,
                    model.elements(),
                    duration / (MAX_EIGEN_WORK / per_solve - 1.0).max(1e-300)
                ),
            )
            .into());
        }
        if evaluations > MAX_EIGEN_EVALUATIONS as f64 {
            return Err(InvalidInput::new(
                "eigenvalues.interval_s",
                format!(
                    "would need {evaluations:.0} eigenvalue solves; at most {MAX_EIGEN_EVALUATIONS} are allowed (use at least {:.4} s)",
                    duration / MAX_EIGEN_EVALUATIONS as f64
                ),
            )
            .into());
        }
    }
    match config.initial {
        InitialState::Rest => {}
        InitialState::Shape { tip_deflection_m } => {
            require_finite("initial.tip_deflection_m", tip_deflection_m)?;
        }
        InitialState::Mode {
            mode,
            tip_deflection_m,
        } => {
            require_finite("initial.tip_deflection_m", tip_deflection_m)?;
            if mode == 0 || mode > model.elements() {
                return Err(InvalidInput::new(
                    "initial.mode",
                    format!(
                        "must be between 1 and the number of elements ({}), got {mode}",
                        model.elements()
                    ),
                )
                .into());
            }
        }
        InitialState::TipForce {
            force_n,
            duration_s,
        } => {
            require_finite("initial.force_n", force_n)?;
            require_positive("initial.duration_s", duration_s)?;
        }
    }
    let added = added_mass_nondim(model, config.aero.as_ref());
    let dt = match config.time_step_s {
        Some(dt) => require_positive("time_step_s", dt)?,
        None => {
            let mut omega: f64 = 0.0;
            let start = profile.kinematics(0.0);
            let end = profile.kinematics(duration);
            for k in [start, end] {
                if k.length_m > 0.01 * model.system.initial_length_m
                    && let Some(w) = first_frequency_1_s(model, k, added)?
                {
                    omega = omega.max(w);
                }
            }
            if let Some(w) = config
                .aero
                .as_ref()
                .and_then(|a| a.flow.forcing_frequency_rad_s())
            {
                omega = omega.max(w);
            }
            let by_period = if omega > 0.0 {
                2.0 * std::f64::consts::PI / omega / STEPS_PER_PERIOD
            } else {
                f64::INFINITY
            };
            let by_ramp = profile
                .shortest_ramp_s()
                .map_or(f64::INFINITY, |r| r / STEPS_PER_RAMP);
            by_period.min(by_ramp).min(duration / 200.0)
        }
    };
    if let Some(ramp) = profile.shortest_ramp_s()
        && dt > 0.5 * ramp
    {
        return Err(InvalidInput::new(
            "time_step_s",
            format!("{dt} s does not resolve the profile's shortest ramp of {ramp} s (use at most {} s)", 0.5 * ramp),
        )
        .into());
    }
    let steps_f = (duration / dt).ceil();
    if steps_f > MAX_STEPS as f64 || steps_f * model.elements() as f64 > MAX_WORK as f64 {
        return Err(InvalidInput::new(
            if config.time_step_s.is_some() { "time_step_s" } else { "duration_s" },
            format!(
                "the run would take {steps_f:.0} steps of {dt:.3e} s on {} elements; at most {MAX_STEPS} steps and \
                 {MAX_WORK} step-elements are allowed (shorten duration_s, lengthen the step or use fewer elements)",
                model.elements()
            ),
        )
        .into());
    }
    let steps = (steps_f as usize).max(1);
    Ok(StepPlan {
        time_step_s: duration / steps as f64,
        steps,
    })
}

fn added_mass_nondim(model: &StringModel, aero: Option<&Aerodynamics>) -> f64 {
    let sys = &model.system;
    aero.map_or(0.0, |a| {
        a.added_mass_kg() / (sys.mass_per_length_kg_m * sys.initial_length_m)
    })
}

/// Mode `mode` (1-based, by frequency) of the cable at rest at length `l`
/// (`l̇ = l̈ = 0`, `K` symmetric), by shifted inverse iteration; normalised
/// to a unit tip deflection. Returns the shape and `ω` (1/t̄).
pub fn rest_mode_shape(
    model: &StringModel,
    length: f64,
    added_mass_nondim: f64,
    mode: usize,
) -> Result<(Vec<f64>, f64), QepError> {
    let sys = rest_system(model, length, added_mass_nondim);
    let eig = |k: usize| rest_eigenvalue(&sys, k);
    let w2 = eig(mode).ok_or(QepError::NoConvergence)?;
    // Shift just below the target, by a small fraction of the gap to its
    // neighbours, so inverse iteration converges to this mode alone.
    let gap = [mode.checked_sub(1).and_then(eig), eig(mode + 1)]
        .into_iter()
        .flatten()
        .map(|v| (v - w2).abs())
        .filter(|g| *g > 0.0)
        .fold(f64::INFINITY, f64::min);
    let shift = w2 - 1e-3 * gap.min(w2.abs().max(1e-300));
    let omega = w2.max(0.0).sqrt();
    let shifted = Tridiagonal::combination(&[(1.0, &sys.stiffness), (-shift, &sys.mass)]);
    let n = model.elements();
    let mut x = vec![1.0; n];
    let mut y = vec![0.0; n];
    for _ in 0..30 {
        sys.mass.mul_vec(&x, &mut y);
        shifted.solve_columns_in_place(&mut y, 1);
        let norm = y.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        if !(norm.is_finite() && norm > 0.0) {
            return Err(QepError::NonFinite);
        }
        for (xi, yi) in x.iter_mut().zip(&y) {
            *xi = yi / norm;
        }
    }
    let tip = x[n - 1];
    if tip == 0.0 {
        return Err(QepError::NonFinite);
    }
    Ok((x.iter().map(|v| v / tip).collect(), omega))
}

/// Runs the transient response.
pub fn simulate(
    model: &StringModel,
    profile: &Profile,
    config: &TransientConfig,
    observer: &dyn Observer,
) -> Result<TransientRun, TransientError> {
    let plan = plan(model, profile, config)?;
    run_planned(model, profile, config, plan, observer, true)
}

fn run_planned(
    model: &StringModel,
    profile: &Profile,
    config: &TransientConfig,
    plan: StepPlan,
    observer: &dyn Observer,
    report_progress: bool,
) -> Result<TransientRun, TransientError> {
    let sys = model.system;
    let ops = &*model.operators;
    let n = model.elements();
    let ts = sys.time_scale_s();
    let l0 = sys.initial_length_m;
    let energy_scale = sys.net_buoyancy_n * l0;
    let added = added_mass_nondim(model, config.aero.as_ref());
    let tip_force = match config.initial {
        InitialState::TipForce {
            force_n,
            duration_s,
        } => Some((force_n, duration_s)),
        _ => None,
    };
    let eval = Evaluator {
        model,
        profile,
        aero: config.aero.as_ref(),
        tip_force,
        added_mass_nondim: added,
    };

    let mut state = NewmarkState::at_rest(n, 0.0);
    match config.initial {
        InitialState::Shape { tip_deflection_m } => {
            let a = tip_deflection_m / l0;
            for (i, q) in state.displacement.iter_mut().enumerate() {
                let zeta = ops.mesh.node_coordinate(i + 1);
                *q = a * zeta.powi(4);
            }
        }
        InitialState::Mode {
            mode,
            tip_deflection_m,
        } => {
            let l = profile.kinematics(0.0).length_m / l0;
            let (shape, _) = rest_mode_shape(model, l, added, mode)?;
            for (q, w) in state.displacement.iter_mut().zip(shape) {
                *q = w * tip_deflection_m / l0;
            }
        }
        InitialState::Rest | InitialState::TipForce { .. } => {}
    }

    let mut matrices = zero_system(n);
    let mut load = vec![0.0; n];
    let mut nm = Newmark::new(n, NewmarkParameters::AVERAGE_ACCELERATION);
    let (mut kin, mut s, mut force_n) = eval.evaluate(0.0, 0.0, &mut matrices, &mut load);
    let failed = |e: StepError| match e {
        StepError::SingularMatrix { time } | StepError::NonFinite { time } => time,
    };
    let mut outcome = RunOutcome::Completed;
    if let Err(e) = nm.initialise(
        &matrices.mass,
        &matrices.damping,
        &matrices.stiffness,
        &load,
        &mut state,
    ) {
        outcome = RunOutcome::Diverged {
            time_s: failed(e) * ts,
        };
    }

    let samples_wanted = config.samples.min(plan.steps + 1);
    let sample_step = |j: usize| -> usize {
        ((j as f64) * plan.steps as f64 / (samples_wanted - 1) as f64).round() as usize
    };
    let mut samples = Vec::with_capacity(samples_wanted);
    let mut next_sample = 0usize;
    let mut envelope: f64 = 0.0;
    let mut eigen = Vec::new();
    let mut next_eigen_s = 0.0;
    let dt_s = plan.time_step_s;
    let dt = dt_s / ts;
    let report_every = (plan.steps / 200).max(1);

    let record = |step: usize,
                  kin: Kinematics,
                  s: NondimState,
                  force_n: f64,
                  envelope: f64,
                  state: &NewmarkState,
                  samples: &mut Vec<Sample>| {
        let mut c = model.coefficients(s);
        c.tip_mass += added;
        let (total, vib) = energy_nondim(
            ops,
            &c,
            s,
            sys.mass_ratio(),
            &state.displacement,
            &state.velocity,
        );
        samples.push(Sample {
            time_s: step as f64 * dt_s,
            length_m: kin.length_m,
            rate_m_s: kin.rate_m_s,
            tip_deflection_m: state.displacement[n - 1] * l0,
            tip_velocity_m_s: state.velocity[n - 1] * sys.wave_speed_m_s(),
            tip_envelope_m: envelope * l0,
            energy_j: total * energy_scale,
            vibration_energy_j: vib * energy_scale,
            tip_force_n: force_n,
        });
    };
    let track = |time_s: f64,
                 kin: Kinematics,
                 matrices: &SecondOrderSystem,
                 count: usize|
     -> Result<EigenSample, QepError> {
        let spectrum = qep::solve(matrices)?;
        Ok(EigenSample {
            time_s,
            length_m: kin.length_m,
            max_real_1_s: sys.eigenvalue_to_si(spectrum.max_real),
            stable: spectrum.is_stable(),
            modes: spectrum
                .modes()
                .into_iter()
                .take(count)
                .map(|e| ModeSi {
                    re_1_s: sys.eigenvalue_to_si(e.re),
                    im_1_s: sys.eigenvalue_to_si(e.im),
                })
                .collect(),
        })
    };

    let mut step = 0usize;
    let mut stopped_at_cap = false;
    loop {
        // Observe the state at `step`.
        let tip = state.displacement[n - 1].abs();
        envelope = envelope.max(tip);
        if let Some(e) = config.eigen
            && step as f64 * dt_s >= next_eigen_s - 1e-9 * dt_s
            && matches!(outcome, RunOutcome::Completed)
        {
            eigen.push(track(step as f64 * dt_s, kin, &matrices, e.count)?);
            next_eigen_s += e.interval_s;
        }
        if next_sample < samples_wanted && step == sample_step(next_sample) {
            record(step, kin, s, force_n, envelope, &state, &mut samples);
            envelope = 0.0;
            next_sample += 1;
        }
        if step == plan.steps || !matches!(outcome, RunOutcome::Completed) {
            break;
        }
        if step.is_multiple_of(report_every) && report_progress {
            observer.report(step, plan.steps);
        }
        // Cancellation is polled often (bounded stop time), progress rarely.
        if step.is_multiple_of(report_every.min(64)) && observer.cancelled() {
            outcome = RunOutcome::Cancelled {
                time_s: step as f64 * dt_s,
            };
            break;
        }
        // Advance.
        let t_next = (step + 1) as f64 * dt_s;
        let v_pred = nm.predicted_velocity(dt, &state, n - 1);
        let next = eval.evaluate(t_next, v_pred, &mut matrices, &mut load);
        if next.0.length_m < MIN_LENGTH_FRACTION * l0 {
            // stop at the last state with a length (its sample stays finite)
            outcome = RunOutcome::LengthCollapsed { time_s: t_next };
            break;
        }
        (kin, s, force_n) = next;
        if let Err(e) = nm.step(
            dt,
            &matrices.mass,
            &matrices.damping,
            &matrices.stiffness,
            &load,
            &mut state,
        ) {
            outcome = RunOutcome::Diverged {
                time_s: failed(e) * ts,
            };
            break;
        }
        // Keep the time exact on the grid (no drift from summing dt).
        state.time = (step + 1) as f64 * dt;
        step += 1;
        let cap = (MAGNITUDE_CAP_LENGTHS * s.length).min(DIVERGENCE_LIMIT);
        if state.displacement.iter().any(|q| q.abs() > cap) {
            outcome = RunOutcome::Diverged { time_s: t_next };
            stopped_at_cap = true;
        }
    }
    // A run that ended early still reports its last state.
    if samples
        .last()
        .is_none_or(|smp| smp.time_s < step as f64 * dt_s)
        && state.is_finite()
    {
        record(step, kin, s, force_n, envelope, &state, &mut samples);
    }
    if report_progress {
        observer.report(step, plan.steps);
    }
    Ok(TransientRun {
        samples,
        eigen,
        outcome,
        time_step_s: dt_s,
        steps: step,
        final_state: state,
        final_kinematics: kin,
        tip_mass_nondim: sys.mass_ratio() + added,
        stopped_at_cap,
    })
}

/// Energies of the modes of the cable at rest at length `length` (non-dim),
/// for a state `(q, q̇)` measured from the static equilibrium under the tip
/// load `tip_load` (non-dim, `F/F_net`): `(ω_k [1/t̄], E_k [F L0])`, by
/// frequency. They sum to `½q̇ᵀMq̇ + ½(q−q_s)ᵀK(q−q_s)` and are constant in
/// time once the length is fixed and the load steady and undamped.
/// `None` if `length ≤ 0` or the state has the wrong size.
pub fn modal_energies(
    model: &StringModel,
    length: f64,
    tip_mass_nondim: f64,
    tip_load: f64,
    q: &[f64],
    qd: &[f64],
) -> Option<Vec<(f64, f64)>> {
    let n = model.elements();
    if length.is_nan() || length <= 0.0 || q.len() != n || qd.len() != n {
        return None;
    }
    let s = NondimState {
        length,
        rate: 0.0,
        acceleration: 0.0,
    };
    let mut c = model.coefficients(s);
    c.tip_mass = tip_mass_nondim;
    let sys = model.operators.assemble(&c);
    let dense = |t: &Tridiagonal| DMatrix::from_fn(n, n, |i, j| t.get(i, j));
    let (m, k) = (dense(&sys.mass), dense(&sys.stiffness));
    // static equilibrium K q_s = f
    let mut qs = vec![0.0; n];
    qs[n - 1] = tip_load;
    sys.stiffness.solve_columns_in_place(&mut qs, 1);
    let l = nalgebra::Cholesky::new(m)?.l();
    let l_inv = l.clone().try_inverse()?;
    let a = &l_inv * &k * l_inv.transpose();
    let a = (&a + a.transpose()) * 0.5;
    let eig = nalgebra::SymmetricEigen::new(a);
    let dq = DVector::from_iterator(n, q.iter().zip(&qs).map(|(a, b)| a - b));
    let dv = DVector::from_column_slice(qd);
    let xi = eig.eigenvectors.transpose() * (l.transpose() * dq);
    let xid = eig.eigenvectors.transpose() * (l.transpose() * dv);
    let mut out: Vec<(f64, f64)> = (0..n)
        .map(|i| {
            let lam = eig.eigenvalues[i];
            (
                lam.max(0.0).sqrt(),
                0.5 * xid[i] * xid[i] + 0.5 * lam * xi[i] * xi[i],
            )
        })
        .collect();
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    Some(out)
}

/// Frequency response: one run per forcing frequency of a uniform flow
/// `u = U0 sin(ω t)`, reporting the tip envelope against time.
#[derive(Clone, Debug, PartialEq)]
pub struct FrequencyResponse {
    pub frequencies_rad_s: Vec<f64>,
    /// Sample times (s), common to all runs.
    pub time_s: Vec<f64>,
    /// `envelope_m[i][j]`: `max |y_tip|` for frequency `i` over the window
    /// ending at `time_s[j]`.
    pub envelope_m: Vec<Vec<f64>>,
    /// Largest tip deflection of each run (m) and when (s).
    pub peak_m: Vec<f64>,
    pub peak_time_s: Vec<f64>,
    pub outcomes: Vec<RunOutcome>,
    pub time_step_s: f64,
    pub steps: usize,
}

/// Runs the frequency response. `config.aero` gives the force model and
/// the body; its flow is replaced by `U0 sin(ω t)` for each `ω`. All runs
/// share one time step (set by the highest frequency when automatic), so
/// the sample times agree. `observer.report(done, total)` counts finished
/// runs. Parallel and serial results are identical.
pub fn frequency_response(
    model: &StringModel,
    profile: &Profile,
    config: &TransientConfig,
    amplitude_m_s: f64,
    frequencies_rad_s: &[f64],
    parallelism: Parallelism,
    observer: &dyn Observer,
) -> Result<FrequencyResponse, TransientError> {
    require_finite("wind_amplitude_m_s", amplitude_m_s)?;
    if frequencies_rad_s.is_empty() || frequencies_rad_s.len() > MAX_FREQUENCIES {
        return Err(InvalidInput::new(
            "frequencies_rad_s.count",
            format!(
                "must be between 1 and {MAX_FREQUENCIES}, got {}",
                frequencies_rad_s.len()
            ),
        )
        .into());
    }
    let Some(aero) = config.aero.as_ref() else {
        return Err(InvalidInput::new(
            "aero",
            "a frequency response needs the aerostat's aerodynamics",
        )
        .into());
    };
    let with_frequency = |w: f64| -> Result<TransientConfig, InvalidInput> {
        let mut c = config.clone();
        c.eigen = None;
        let mut a = aero.clone();
        a.flow = AirFlow::sinusoidal(amplitude_m_s, w)?;
        c.aero = Some(a);
        Ok(c)
    };
    let w_max = frequencies_rad_s.iter().copied().fold(0.0, f64::max);
    for (i, &w) in frequencies_rad_s.iter().enumerate() {
        with_frequency(w)
            .map_err(|e| InvalidInput::new(format!("frequencies_rad_s[{i}]"), e.reason))?;
    }
    let plan = plan(model, profile, &with_frequency(w_max)?)?;
    let work = plan.steps as f64 * model.elements() as f64 * frequencies_rad_s.len() as f64;
    if work > MAX_RESPONSE_WORK as f64 {
        return Err(InvalidInput::new(
            "frequencies_rad_s.count",
            format!(
                "{} runs of {} steps on {} elements exceed the limit of {MAX_RESPONSE_WORK} step-elements",
                frequencies_rad_s.len(),
                plan.steps,
                model.elements()
            ),
        )
        .into());
    }
    let total = frequencies_rad_s.len();
    let done = AtomicUsize::new(0);
    observer.report(0, total);
    let one = |w: f64| -> Result<TransientRun, TransientError> {
        let c = with_frequency(w)?;
        let run = run_planned(model, profile, &c, plan, observer, false)?;
        observer.report(done.fetch_add(1, Ordering::Relaxed) + 1, total);
        Ok(run)
    };
    let runs: Vec<Result<TransientRun, TransientError>> = match parallelism {
        Parallelism::Serial => frequencies_rad_s.iter().map(|&w| one(w)).collect(),
        Parallelism::Rayon => frequencies_rad_s.par_iter().map(|&w| one(w)).collect(),
    };
    let runs = runs.into_iter().collect::<Result<Vec<_>, _>>()?;
    let time_s = runs[0].samples.iter().map(|s| s.time_s).collect();
    let mut out = FrequencyResponse {
        frequencies_rad_s: frequencies_rad_s.to_vec(),
        time_s,
        envelope_m: vec![],
        peak_m: vec![],
        peak_time_s: vec![],
        outcomes: vec![],
        time_step_s: plan.time_step_s,
        steps: plan.steps,
    };
    for run in runs {
        let (peak, at) = run.samples.iter().fold((0.0f64, 0.0), |(p, t), s| {
            if s.tip_envelope_m > p {
                (s.tip_envelope_m, s.time_s)
            } else {
                (p, t)
            }
        });
        out.envelope_m
            .push(run.samples.iter().map(|s| s.tip_envelope_m).collect());
        out.peak_m.push(peak);
        out.peak_time_s.push(at);
        out.outcomes.push(run.outcome);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::params::AerostatSystem;

    #[test]
    fn in_place_assembly_matches_the_operators() {
        let model = StringModel::new(AerostatSystem::thesis(), 7).unwrap();
        let c = model.coefficients(NondimState {
            length: 3.0,
            rate: 0.2,
            acceleration: 0.01,
        });
        let want = model.operators.assemble(&c);
        let mut got = zero_system(7);
        assemble_into(&model.operators, &c, &mut got);
        for (a, b) in [
            (&got.mass, &want.mass),
            (&got.damping, &want.damping),
            (&got.stiffness, &want.stiffness),
        ] {
            for (x, y) in a
                .diag
                .iter()
                .chain(&a.lower)
                .chain(&a.upper)
                .zip(b.diag.iter().chain(&b.lower).chain(&b.upper))
            {
                assert!((x - y).abs() < 1e-12 * y.abs().max(1.0));
            }
        }
    }

    #[test]
    fn rejects_bad_configurations_naming_the_field() {
        let model = StringModel::new(AerostatSystem::thesis(), 10).unwrap();
        let profile = Profile::constant_rate(1.0, 1.0, None).unwrap();
        let base = TransientConfig {
            duration_s: 10.0,
            time_step_s: Some(0.01),
            samples: 100,
            initial: InitialState::Rest,
            aero: None,
            eigen: None,
        };
        let field = |c: TransientConfig| match plan(&model, &profile, &c) {
            Err(TransientError::Invalid(e)) => e.field,
            other => panic!("expected invalid input, got {other:?}"),
        };
        assert_eq!(
            field(TransientConfig {
                duration_s: -1.0,
                ..base.clone()
            }),
            "duration_s"
        );
        assert_eq!(
            field(TransientConfig {
                samples: 1,
                ..base.clone()
            }),
            "samples"
        );
        assert_eq!(
            field(TransientConfig {
                time_step_s: Some(1e-9),
                ..base.clone()
            }),
            "time_step_s"
        );
        assert_eq!(
            field(TransientConfig {
                eigen: Some(EigenTracking {
                    interval_s: 1e-4,
                    count: 3
                }),
                ..base.clone()
            }),
            "eigenvalues.interval_s"
        );
        assert_eq!(
            field(TransientConfig {
                initial: InitialState::Mode {
                    mode: 0,
                    tip_deflection_m: 0.1
                },
                ..base
            }),
            "initial.mode"
        );
    }

    /// A tip force switched on at t = 0 on a cable of fixed length: the tip
    /// swings about the static deflection `K⁻¹f` (up to about twice it, the
    /// step response of the dominant first mode) and, once released,
    /// oscillates about zero.
    #[test]
    fn held_tip_force_swings_about_the_static_deflection() {
        let model = StringModel::new(AerostatSystem::thesis(), 20).unwrap();
        let profile = Profile::constant_rate(1.0, 0.0, None).unwrap();
        let (force, hold) = (10.0, 3.0);
        let cfg = TransientConfig {
            duration_s: 6.0,
            time_step_s: Some(1e-3),
            samples: 6001,
            initial: InitialState::TipForce {
                force_n: force,
                duration_s: hold,
            },
            aero: None,
            eigen: None,
        };
        let r = simulate(&model, &profile, &cfg, &Silent).unwrap();
        let sys = model.matrices(NondimState {
            length: 1.0,
            rate: 0.0,
            acceleration: 0.0,
        });
        let mut q = vec![0.0; 20];
        q[19] = force / 1000.0;
        sys.stiffness.solve_columns_in_place(&mut q, 1);
        let static_m = q[19];
        let held: Vec<f64> = r
            .samples
            .iter()
            .filter(|s| s.time_s < hold)
            .map(|s| s.tip_deflection_m)
            .collect();
        let max = held.iter().cloned().fold(f64::MIN, f64::max);
        let min = held.iter().cloned().fold(f64::MAX, f64::min);
        assert!(
            min > -0.05 * static_m && (max / (2.0 * static_m) - 1.0).abs() < 0.05,
            "{min} {max} {static_m}"
        );
        assert!(
            r.samples
                .iter()
                .filter(|s| s.time_s < hold)
                .all(|s| s.tip_force_n == force)
        );
        assert!(
            r.samples
                .iter()
                .filter(|s| s.time_s > hold)
                .all(|s| s.tip_force_n == 0.0)
        );
        let released: Vec<f64> = r
            .samples
            .iter()
            .filter(|s| s.time_s > hold)
            .map(|s| s.tip_deflection_m)
            .collect();
        let mean = released.iter().sum::<f64>() / released.len() as f64;
        assert!(mean.abs() < 0.3 * static_m, "released mean {mean}");
    }

    #[test]
    fn rest_eigenvalues_by_inertia_match_the_qep() {
        let model = StringModel::new(AerostatSystem::thesis(), 30).unwrap();
        let sys = rest_system(&model, 250.0, 0.3);
        let spectrum = qep::solve(&sys).unwrap();
        for (k, mode) in spectrum.modes().iter().take(4).enumerate() {
            let w = rest_eigenvalue(&sys, k + 1).unwrap().sqrt();
            assert!(
                (w / mode.im - 1.0).abs() < 1e-9,
                "mode {}: {w} vs {}",
                k + 1,
                mode.im
            );
        }
        let (shape, w) = rest_mode_shape(&model, 250.0, 0.3, 2).unwrap();
        assert!((w / spectrum.modes()[1].im - 1.0).abs() < 1e-9);
        // K φ = ω² M φ
        let (mut kx, mut mx) = (vec![0.0; 30], vec![0.0; 30]);
        sys.stiffness.mul_vec(&shape, &mut kx);
        sys.mass.mul_vec(&shape, &mut mx);
        let scale = kx.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        for (a, b) in kx.iter().zip(&mx) {
            assert!((a - w * w * b).abs() < 1e-8 * scale);
        }
    }
}
