//! Transient response of the linear string (SPEC §2, thesis ch. 3.5, 4.3,
//! 4.4, app. A): Newmark average acceleration on the time-varying
//! `M, C, K` of the deployment, with the aerostat loaded by the air flow,
//! and the pieces the frequency response builds on (its runs, one per
//! frequency, are in the `frequency_response` module beside this one).
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

use crate::numerics::aero::Aerodynamics;
use crate::numerics::newmark::{Newmark, NewmarkParameters, NewmarkState, StepError};
use crate::numerics::params::{
    InvalidInput, Kinematics, NondimState, require_finite, require_positive,
};
use crate::numerics::profile::Profile;
use crate::numerics::qep::{self, QepError};
use crate::numerics::string::StringModel;
use crate::numerics::string::operators::{MatrixCoefficients, SecondOrderSystem, StringOperators};
use crate::numerics::string::rest_modes::{rest_eigenvalue, rest_mode_shape, rest_system};
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

pub(crate) fn run_planned(
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

#[cfg(test)]
mod tests;
