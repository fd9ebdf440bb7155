//! The JSON contract of a geometrically exact (GE) transient run
//! (`tetherplan simulate` with `"model": {"kind": "geometrically_exact"}`,
//! `POST /api/v1/simulate`): request and response bodies (SI; field names
//! end in their unit), validation naming the field, and [`simulate_ge`].
//! Newton non-convergence is an outcome in the response, not an error.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::contract::system::CableInput;
use crate::contract::system::input::ProfileInput;
use crate::contract::system::output::EigenvalueOutput;
use crate::contract::{Progress, RequestError};
use crate::numerics::ge::element::TipLoad;
use crate::numerics::ge::solver::{
    self, BaseMotion, Damping, Drive, EndLoads, LengthHistory, LoadShape, NewtonConfig, RunConfig,
    RunOutcome, State,
};
use crate::numerics::ge::{GeModel, TipBody};

pub use super::model::{DEFAULT_GE_ELEMENTS, GeModelInput, GeModelKind, stiffness_ratio_of};
use crate::numerics::params::{
    InvalidInput, require_finite, require_non_negative, require_positive,
};

/// Largest number of time steps of one run.
pub const MAX_STEPS: usize = solver::MAX_STEPS;
/// Largest `steps × elements` of one run (about a minute of one core).
pub const MAX_WORK: f64 = 2e8;
/// Largest number of recorded samples.
pub const MAX_SAMPLES: usize = 200_000;
/// Largest element count when eigenvalues are requested (dense QEP of size 6n).
pub const MAX_EIGEN_ELEMENTS: usize = 300;
/// Largest number of QEP solves along a run.
pub const MAX_SPECTRA: usize = 2000;

/// The aerostat of a GE run: the one [`crate::contract::system::AerostatInput`]
/// (with `link_length_m`, the rigid link from the cable end to its centre).
pub type GeAerostatInput = crate::contract::system::AerostatInput;

/// Time shape of the end load.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(tag = "kind", rename_all = "snake_case")]
#[serde(deny_unknown_fields)]
pub enum LoadTimeInput {
    /// On for the whole run.
    Constant {},
    /// Rises linearly over `ramp_s`, held until `hold_s`, then released.
    Held {
        #[schema(example = 0.1, minimum = 0.0, maximum = 1e7)]
        ramp_s: f64,
        #[schema(example = 0.5, minimum = 0.0, maximum = 1e7)]
        hold_s: f64,
    },
    /// Triangular pulse: peak at `peak_s`, zero again at `end_s`.
    Triangle {
        #[schema(example = 1.0, exclusive_minimum = 0.0, maximum = 1e7)]
        peak_s: f64,
        #[schema(example = 2.0, minimum = 0.0, maximum = 1e7)]
        end_s: f64,
    },
}

/// An extra end load on the aerostat (a perturbation), beside the buoyancy.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct EndLoadInput {
    /// Force along the guide axis (N).
    #[serde(default)]
    #[schema(minimum = -1e8, maximum = 1e8)]
    pub axial_force_n: f64,
    /// Force across the guide axis (N).
    #[serde(default)]
    #[schema(example = 400.0, minimum = -1e8, maximum = 1e8)]
    pub transverse_force_n: f64,
    /// Couple on the top section (N m).
    #[serde(default)]
    #[schema(minimum = -1e8, maximum = 1e8)]
    pub moment_n_m: f64,
    pub time: LoadTimeInput,
}

/// Newton–Raphson settings.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct NewtonInput {
    /// Relative residual tolerance.
    #[serde(default = "default_rtol")]
    #[schema(example = 1e-9, exclusive_minimum = 0.0, maximum = 0.1)]
    pub relative_tolerance: f64,
    /// Absolute residual tolerance (N).
    #[serde(default = "default_atol")]
    #[schema(example = 1e-10, minimum = 0.0)]
    pub absolute_tolerance_n: f64,
    /// Iteration cap per step.
    #[serde(default = "default_iterations")]
    #[schema(example = 30, minimum = 1, maximum = 200)]
    pub max_iterations: usize,
}

fn default_rtol() -> f64 {
    NewtonConfig::default().relative_tolerance
}
fn default_atol() -> f64 {
    NewtonConfig::default().absolute_tolerance_n
}
fn default_iterations() -> usize {
    NewtonConfig::default().max_iterations
}

/// How the GE cable starts: `initial` as in the linear string's simulate
/// (`{"kind": ...}`), with the kinds this model has.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, ToSchema, PartialEq, Eq)]
#[serde(tag = "kind", rename_all = "snake_case")]
#[serde(deny_unknown_fields)]
pub enum GeInitialStateInput {
    /// Static equilibrium under buoyancy and gravity at t = 0 (default).
    StaticEquilibrium {},
    /// Straight and unstrained, at rest.
    Rest {},
}

impl Default for GeInitialStateInput {
    fn default() -> Self {
        Self::StaticEquilibrium {}
    }
}

/// `simulate` with a GE model: a transient Newmark–Newton run.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct GeSimulateRequest {
    pub cable: CableInput,
    pub aerostat: GeAerostatInput,
    /// Initial cable length L0 (m), the length scale of E* and γ̃.
    #[serde(default = "default_initial_length")]
    #[schema(example = 1.0, minimum = 0.001, maximum = 10000.0)]
    pub initial_length_m: f64,
    /// Gravity on the cable (m/s²).
    #[serde(default = "default_gravity")]
    #[schema(example = 9.81, minimum = 0.0, maximum = 100.0)]
    pub gravity_m_s2: f64,
    pub model: GeModelInput,
    /// Deployment profile; none: constant length.
    #[serde(default)]
    pub profile: Option<ProfileInput>,
    /// Time step (s).
    #[schema(example = 0.000883, minimum = 1e-9, maximum = 1000.0)]
    pub time_step_s: f64,
    /// Duration of the run (s).
    #[schema(example = 8.83, minimum = 1e-6, maximum = 1e7)]
    pub duration_s: f64,
    #[serde(default)]
    pub end_load: Option<EndLoadInput>,
    /// Linear viscous damping per unit mass (1/s).
    #[serde(default)]
    #[schema(example = 0.0, minimum = 0.0, maximum = 1e6)]
    pub damping_per_s: f64,
    /// Time from which the damping acts (s).
    #[serde(default)]
    #[schema(example = 0.0, minimum = 0.0, maximum = 1e7)]
    pub damping_from_s: f64,
    /// How the cable starts (the same field as the linear string's
    /// `initial`); default: static equilibrium.
    #[serde(default)]
    pub initial: GeInitialStateInput,
    #[serde(default)]
    pub newton: Option<NewtonInput>,
    /// Record every this many steps.
    #[serde(default = "default_every")]
    #[schema(example = 10, minimum = 1)]
    pub output_every_steps: usize,
    /// Solve the local-stability QEP every this many steps (0: never).
    #[serde(default)]
    #[schema(example = 0, minimum = 0)]
    pub eigenvalues_every_steps: usize,
    /// Modes (Im λ ≥ 0, by frequency) listed per QEP solve.
    #[serde(default = "default_modes")]
    #[schema(example = 3, minimum = 1, maximum = 100)]
    pub modes: usize,
}

fn default_initial_length() -> f64 {
    1.0
}
fn default_gravity() -> f64 {
    9.81
}
fn default_every() -> usize {
    1
}
fn default_modes() -> usize {
    3
}

/// How the run ended.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
#[serde(tag = "status", rename_all = "snake_case")]
pub enum GeOutcome {
    /// Ran for the whole duration.
    Completed,
    /// Newton–Raphson did not converge at this step.
    NewtonFailed {
        step: usize,
        time_s: f64,
        /// Euclidean norm of the residual at the last iterate (N).
        residual_norm_n: f64,
        iterations: usize,
    },
}

/// Time series, one entry per recorded step (struct of arrays).
#[derive(Clone, Debug, Default, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct GeSeries {
    pub time_s: Vec<f64>,
    /// t̄ = t √(EI/I_ρ)/L0 (thesis ch. 5.6).
    pub time_nondim: Vec<f64>,
    pub length_m: Vec<f64>,
    pub rate_m_s: Vec<f64>,
    /// Cable top along the guide axis (m).
    pub tip_x_m: Vec<f64>,
    /// Cable top across the guide axis (m).
    pub tip_y_m: Vec<f64>,
    pub tip_rotation_rad: Vec<f64>,
    pub aerostat_x_m: Vec<f64>,
    pub aerostat_y_m: Vec<f64>,
    /// Kinetic energy (6.22), sliding included (J).
    pub kinetic_energy_j: Vec<f64>,
    /// Strain energy (6.24) (J).
    pub strain_energy_j: Vec<f64>,
    /// Kinetic + strain (J).
    pub total_energy_j: Vec<f64>,
    /// Kinetic energy relative to the rigid sliding, plus strain energy (J).
    pub oscillation_energy_j: Vec<f64>,
    /// Angular momentum about the root (6.27) (N m s).
    pub angular_momentum_n_m_s: Vec<f64>,
    /// Support moment at the root on the cable (N m).
    pub root_moment_n_m: Vec<f64>,
    pub root_force_axial_n: Vec<f64>,
    pub root_force_transverse_n: Vec<f64>,
    /// Newton iterations of the step.
    pub newton_iterations: Vec<usize>,
}

/// The local-stability QEP at one instant.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct GeSpectrumOutput {
    pub time_s: f64,
    pub length_m: f64,
    pub stable: bool,
    /// Largest Re λ (1/s).
    pub max_real_1_s: f64,
    /// Modes by frequency; `_nondim` in units of 1/t̄.
    pub eigenvalues: Vec<EigenvalueOutput>,
}

/// Derived quantities of the model.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct GeGroups {
    pub axial_stiffness_n: f64,
    pub shear_stiffness_n: f64,
    pub rotary_inertia_kg_m: f64,
    /// L0 √(I_ρ/EI) (s): t = t̄ · time_scale.
    pub time_scale_s: f64,
    pub time_step_nondim: f64,
}

#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct GeSimulateResponse {
    pub outcome: GeOutcome,
    /// First instant whose local-stability QEP (`spectra`, every
    /// `eigenvalues_every_steps`) is unstable (s); null when every one was
    /// stable or none was solved. The samples after it show growth past
    /// onset. (The GE cable's deflection is bounded by its stretched
    /// length, so a GE run needs no magnitude cap: it ends `completed` or
    /// `newton_failed`.)
    pub first_unstable_time_s: Option<f64>,
    /// Why the run ended: `completed` or `newton_failed`.
    pub stopped_reason: String,
    pub series: GeSeries,
    pub spectra: Vec<GeSpectrumOutput>,
    pub steps: usize,
    pub newton_iterations_total: usize,
    pub newton_iterations_mean: f64,
    pub newton_iterations_max: usize,
    /// QEP solves whose eigenvalue iteration failed (skipped).
    pub spectrum_failures: usize,
    pub groups: GeGroups,
    pub elements: usize,
}

struct Prepared {
    model: GeModel,
    drive: Drive,
    config: RunConfig,
    steady: TipLoad,
    initial: GeInitialStateInput,
    time_scale_s: f64,
}

fn prepare(req: &GeSimulateRequest) -> Result<Prepared, InvalidInput> {
    let l0 = require_positive("initial_length_m", req.initial_length_m)?;
    let g = require_non_negative("gravity_m_s2", req.gravity_m_s2)?;
    let buoyancy = req.aerostat.net_buoyancy_ge("aerostat")?;
    let m = &req.model;
    let section = m.section(&req.cable, l0, Some(buoyancy))?;
    let tip = TipBody {
        mass_kg: req.aerostat.mass("aerostat")?,
        link_length_m: req.aerostat.link_length("aerostat")?,
    };
    let model = GeModel::new(section, m.elements(), tip, g)?;

    let dt = require_positive("time_step_s", req.time_step_s)?;
    let duration = require_positive("duration_s", req.duration_s)?;
    let steps = (duration / dt).round();
    if steps < 1.0 {
        return Err(InvalidInput::new(
            "time_step_s",
            "must not exceed duration_s",
        ));
    }
    if steps > MAX_STEPS as f64 {
        return Err(InvalidInput::new(
            "duration_s",
            format!("needs {steps:.0} steps of time_step_s; at most {MAX_STEPS} are allowed"),
        ));
    }
    if steps * m.elements() as f64 > MAX_WORK {
        return Err(InvalidInput::new(
            "duration_s",
            format!(
                "{steps:.0} steps × {} elements exceeds the work limit {MAX_WORK:.0e}",
                m.elements()
            ),
        ));
    }
    if req.output_every_steps == 0 {
        return Err(InvalidInput::new(
            "output_every_steps",
            "must be at least 1",
        ));
    }
    if steps / req.output_every_steps as f64 > MAX_SAMPLES as f64 {
        return Err(InvalidInput::new(
            "output_every_steps",
            format!("would record more than {MAX_SAMPLES} samples"),
        ));
    }
    if req.eigenvalues_every_steps > 0 {
        if m.elements() > MAX_EIGEN_ELEMENTS {
            return Err(InvalidInput::new(
                "eigenvalues_every_steps",
                format!(
                    "eigenvalues need elements ≤ {MAX_EIGEN_ELEMENTS}, got {}",
                    m.elements()
                ),
            ));
        }
        if steps / req.eigenvalues_every_steps as f64 > MAX_SPECTRA as f64 {
            return Err(InvalidInput::new(
                "eigenvalues_every_steps",
                format!("would solve more than {MAX_SPECTRA} QEPs"),
            ));
        }
    }
    if !(1..=100).contains(&req.modes) {
        return Err(InvalidInput::new(
            "modes",
            format!("must be between 1 and 100, got {}", req.modes),
        ));
    }

    let length = match &req.profile {
        None => LengthHistory::Constant(l0),
        Some(p) => LengthHistory::Profile(p.profile(l0)?),
    };
    // the cable must keep a length over the whole run
    let shortest = (0..=100)
        .map(|k| length.kinematics(duration * k as f64 / 100.0).length_m)
        .fold(f64::INFINITY, f64::min);
    let end = length.kinematics(duration).length_m;
    if shortest.min(end) < 1e-3 * l0 {
        return Err(InvalidInput::new(
            "duration_s",
            format!(
                "the profile shortens the cable to {:.3e} m within the run",
                shortest.min(end)
            ),
        ));
    }

    let steady = TipLoad {
        force_n: [buoyancy, 0.0],
        moment_n_m: 0.0,
    };
    let (varying, shape) = match &req.end_load {
        None => (TipLoad::default(), LoadShape::Constant),
        Some(e) => {
            let load = TipLoad {
                force_n: [
                    require_finite("end_load.axial_force_n", e.axial_force_n)?,
                    require_finite("end_load.transverse_force_n", e.transverse_force_n)?,
                ],
                moment_n_m: require_finite("end_load.moment_n_m", e.moment_n_m)?,
            };
            let shape = match e.time {
                LoadTimeInput::Constant {} => LoadShape::Constant,
                LoadTimeInput::Held { ramp_s, hold_s } => {
                    let ramp_s = require_non_negative("end_load.time.ramp_s", ramp_s)?;
                    let hold_s = require_non_negative("end_load.time.hold_s", hold_s)?;
                    if hold_s < ramp_s {
                        return Err(InvalidInput::new(
                            "end_load.time.hold_s",
                            "must not be less than ramp_s",
                        ));
                    }
                    LoadShape::Held { ramp_s, hold_s }
                }
                LoadTimeInput::Triangle { peak_s, end_s } => {
                    let peak_s = require_positive("end_load.time.peak_s", peak_s)?;
                    let end_s = require_positive("end_load.time.end_s", end_s)?;
                    if end_s <= peak_s {
                        return Err(InvalidInput::new(
                            "end_load.time.end_s",
                            "must be greater than peak_s",
                        ));
                    }
                    LoadShape::Triangle { peak_s, end_s }
                }
            };
            (load, shape)
        }
    };
    let damping = Damping {
        per_s: require_non_negative("damping_per_s", req.damping_per_s)?,
        from_s: require_non_negative("damping_from_s", req.damping_from_s)?,
    };
    let newton = match &req.newton {
        None => NewtonConfig::default(),
        Some(n) => {
            let rtol = require_positive("newton.relative_tolerance", n.relative_tolerance)?;
            if rtol > 0.1 {
                return Err(InvalidInput::new(
                    "newton.relative_tolerance",
                    "must not exceed 0.1",
                ));
            }
            if !(1..=200).contains(&n.max_iterations) {
                return Err(InvalidInput::new(
                    "newton.max_iterations",
                    format!("must be between 1 and 200, got {}", n.max_iterations),
                ));
            }
            NewtonConfig {
                relative_tolerance: rtol,
                absolute_tolerance_n: require_non_negative(
                    "newton.absolute_tolerance_n",
                    n.absolute_tolerance_n,
                )?,
                max_iterations: n.max_iterations,
            }
        }
    };
    let time_scale_s = l0 * (section.rotary_inertia_kg_m / section.bending_stiffness_n_m2).sqrt();
    Ok(Prepared {
        model,
        drive: Drive {
            length,
            loads: EndLoads {
                steady,
                varying,
                shape,
            },
            damping,
            base: BaseMotion::default(),
            aero: None,
        },
        config: RunConfig {
            time_step_s: dt,
            duration_s: duration,
            newton,
            record_every: req.output_every_steps,
            eigen_every: req.eigenvalues_every_steps,
        },
        steady,
        initial: req.initial,
        time_scale_s,
    })
}

/// Runs a GE simulation. Invalid input is an `Err` naming the field; a
/// Newton failure is [`GeOutcome::NewtonFailed`] with the samples so far.
pub fn simulate_ge(
    req: &GeSimulateRequest,
    progress: &dyn Progress,
) -> Result<GeSimulateResponse, RequestError> {
    let p = prepare(req)?;
    let model = &p.model;
    let n = model.dofs();
    let kin0 = p.drive.length.kinematics(0.0);
    let q0 = match p.initial {
        GeInitialStateInput::Rest {} => vec![0.0; n],
        GeInitialStateInput::StaticEquilibrium {} => {
            let newton = NewtonConfig {
                max_iterations: p.config.newton.max_iterations.max(50),
                ..p.config.newton
            };
            match solver::static_solve(model, kin0, p.steady, 4, newton) {
                Ok(q) => q,
                Err(f) => {
                    return Ok(failed_before_start(&p, f));
                }
            }
        }
    };
    let v0 = vec![0.0; n];
    let Some(a0) = solver::initial_acceleration(model, &p.drive, 0.0, &q0, &v0) else {
        return Err(InvalidInput::new("aerostat.mass_kg", "the mass matrix is singular").into());
    };
    let initial = State {
        time_s: 0.0,
        q: q0,
        v: v0,
        a: a0,
    };
    let mut observer = |done: usize, total: usize| {
        progress.report(done, total);
        !progress.cancelled()
    };
    let result = solver::run(model, &p.drive, initial, p.config, &mut observer);
    let outcome = match result.outcome {
        RunOutcome::Completed => GeOutcome::Completed,
        RunOutcome::NewtonFailed { step, failure } => GeOutcome::NewtonFailed {
            step,
            time_s: failure.time_s,
            residual_norm_n: failure.residual_norm,
            iterations: failure.iterations,
        },
        RunOutcome::Cancelled { .. } => return Err(RequestError::Cancelled),
    };
    let ts = p.time_scale_s;
    let mut series = GeSeries::default();
    for s in &result.samples {
        series.time_s.push(s.time_s);
        series.time_nondim.push(s.time_s / ts);
        series.length_m.push(s.kinematics.length_m);
        series.rate_m_s.push(s.kinematics.rate_m_s);
        series.tip_x_m.push(s.tip[0]);
        series.tip_y_m.push(s.tip[1]);
        series.tip_rotation_rad.push(s.tip_rotation_rad);
        series.aerostat_x_m.push(s.aerostat[0]);
        series.aerostat_y_m.push(s.aerostat[1]);
        series.kinetic_energy_j.push(s.energy.kinetic_j);
        series.strain_energy_j.push(s.energy.strain_j);
        series.total_energy_j.push(s.energy.total_j());
        series.oscillation_energy_j.push(s.energy.oscillation_j);
        series.angular_momentum_n_m_s.push(s.angular_momentum_n_m_s);
        series.root_moment_n_m.push(s.root_moment_n_m);
        series.root_force_axial_n.push(s.root_force_n[0]);
        series.root_force_transverse_n.push(s.root_force_n[1]);
        series.newton_iterations.push(s.newton_iterations);
    }
    let spectra = result
        .spectra
        .iter()
        .map(|s| GeSpectrumOutput {
            time_s: s.time_s,
            length_m: s.length_m,
            stable: s.spectrum.is_stable(),
            max_real_1_s: s.spectrum.max_real,
            eigenvalues: s
                .spectrum
                .modes()
                .into_iter()
                .filter(|e| e.im > 0.0)
                .take(req.modes)
                .map(|e| EigenvalueOutput {
                    re_1_s: e.re,
                    im_1_s: e.im,
                    re_nondim: e.re * ts,
                    im_nondim: e.im * ts,
                    frequency_hz: e.im / (2.0 * std::f64::consts::PI),
                })
                .collect(),
        })
        .collect();
    let first_unstable_time_s = result
        .spectra
        .iter()
        .find(|s| !s.spectrum.is_stable())
        .map(|s| s.time_s);
    let stopped_reason = match outcome {
        GeOutcome::Completed => "completed",
        GeOutcome::NewtonFailed { .. } => "newton_failed",
    };
    Ok(GeSimulateResponse {
        first_unstable_time_s,
        stopped_reason: stopped_reason.into(),
        outcome,
        series,
        spectra,
        steps: result.steps,
        newton_iterations_total: result.newton_iterations_total,
        newton_iterations_mean: result.mean_newton_iterations(),
        newton_iterations_max: result.newton_iterations_max,
        spectrum_failures: result.spectrum_failures,
        groups: groups(&p),
        elements: model.elements,
    })
}

fn groups(p: &Prepared) -> GeGroups {
    let s = &p.model.section;
    GeGroups {
        axial_stiffness_n: s.axial_stiffness_n,
        shear_stiffness_n: s.shear_stiffness_n,
        rotary_inertia_kg_m: s.rotary_inertia_kg_m,
        time_scale_s: p.time_scale_s,
        time_step_nondim: p.config.time_step_s / p.time_scale_s,
    }
}

fn failed_before_start(p: &Prepared, f: solver::NewtonFailure) -> GeSimulateResponse {
    GeSimulateResponse {
        first_unstable_time_s: None,
        stopped_reason: "newton_failed".into(),
        outcome: GeOutcome::NewtonFailed {
            step: 0,
            time_s: 0.0,
            residual_norm_n: f.residual_norm,
            iterations: f.iterations,
        },
        series: GeSeries::default(),
        spectra: Vec::new(),
        steps: 0,
        newton_iterations_total: 0,
        newton_iterations_mean: 0.0,
        newton_iterations_max: 0,
        spectrum_failures: 0,
        groups: groups(p),
        elements: p.model.elements,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contract::error::NoProgress;

    fn table_7_1() -> serde_json::Value {
        serde_json::json!({
            "cable": {"density_kg_m3": 7800.0, "area_m2": 1e-5},
            "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
            "initial_length_m": 1.0,
            "model": {"kind": "geometrically_exact", "elements": 10,
                      "bending_stiffness_n_m2": 1000.0, "stiffness_ratio": 1e5, "inertia_ratio": 1.0},
            "time_step_s": 0.000883,
            "duration_s": 0.0883,
            "end_load": {"transverse_force_n": 400.0, "time": {"kind": "held", "ramp_s": 0.01, "hold_s": 0.03}},
            "eigenvalues_every_steps": 50,
            "output_every_steps": 5
        })
    }

    #[test]
    fn runs_table_7_1_and_reports_series() {
        let req: GeSimulateRequest =
            crate::contract::parse_plain(table_7_1().to_string().as_bytes()).unwrap();
        let out = simulate_ge(&req, &NoProgress).unwrap();
        assert_eq!(out.outcome, GeOutcome::Completed);
        assert_eq!(out.steps, 100);
        assert_eq!(out.series.time_s.len(), 21);
        assert_eq!(out.spectra.len(), 3);
        // t̄ scale √(I_ρ/EI) L0 = √(0.078/1000) s; Δt̄ = 0.1
        assert!((out.groups.time_step_nondim - 0.1).abs() < 1e-3);
        // the held force pushed the top sideways
        assert!(out.series.tip_y_m.iter().any(|y| y.abs() > 1e-3));
        // a short stiff cable at rest is stable
        assert!(out.spectra.iter().all(|s| s.stable));
        assert!(out.newton_iterations_mean >= 1.0);
        let json = serde_json::to_value(&out).unwrap();
        assert_eq!(json["outcome"]["status"], "completed");
    }

    #[test]
    fn lengthening_run_stays_stable_and_follows_the_profile() {
        let mut v = table_7_1();
        v["profile"] = serde_json::json!({"kind": "constant_rate", "rate_m_s": 10.0});
        v["duration_s"] = serde_json::json!(0.5);
        v["time_step_s"] = serde_json::json!(0.001);
        v["output_every_steps"] = serde_json::json!(50);
        v["eigenvalues_every_steps"] = serde_json::json!(250);
        let req: GeSimulateRequest = serde_json::from_value(v).unwrap();
        let out = simulate_ge(&req, &NoProgress).unwrap();
        assert_eq!(out.outcome, GeOutcome::Completed);
        let last = out.series.length_m.len() - 1;
        assert!((out.series.length_m[last] - 6.0).abs() < 1e-9);
        assert!((out.series.rate_m_s[last] - 10.0).abs() < 1e-12);
        // 10 m/s is far below the wave speed (113 m/s): stable throughout
        assert_eq!(out.spectra.len(), 3);
        assert!(out.spectra.iter().all(|s| s.stable), "{:?}", out.spectra);
    }

    #[test]
    fn rejects_bad_input_naming_the_field() {
        let mut v = table_7_1();
        v["model"]["stiffness_ratio"] = serde_json::json!(-1.0);
        let req: GeSimulateRequest = serde_json::from_value(v).unwrap();
        match simulate_ge(&req, &NoProgress) {
            Err(RequestError::Invalid(e)) => assert_eq!(e.field, "model.stiffness_ratio"),
            other => panic!("{other:?}"),
        }
        let mut v = table_7_1();
        v["model"]["elements"] = serde_json::json!(5000);
        let req: GeSimulateRequest = serde_json::from_value(v).unwrap();
        assert!(
            matches!(simulate_ge(&req, &NoProgress), Err(RequestError::Invalid(e)) if e.field == "model.elements")
        );
        let mut v = table_7_1();
        v["time_step_s"] = serde_json::json!(1e-9);
        let req: GeSimulateRequest = serde_json::from_value(v).unwrap();
        assert!(
            matches!(simulate_ge(&req, &NoProgress), Err(RequestError::Invalid(e)) if e.field == "duration_s")
        );
        let mut v = table_7_1();
        v["profile"] = serde_json::json!({"kind": "constant_rate", "rate_m_s": -20.0});
        let req: GeSimulateRequest = serde_json::from_value(v).unwrap();
        assert!(
            matches!(simulate_ge(&req, &NoProgress), Err(RequestError::Invalid(e)) if e.field == "duration_s")
        );
        let mut v = table_7_1();
        v["model"]["kind"] = serde_json::json!("linear_string");
        assert!(
            crate::contract::parse_plain::<GeSimulateRequest>(v.to_string().as_bytes()).is_err()
        );
    }

    #[test]
    fn newton_failure_is_an_outcome() {
        let mut v = table_7_1();
        v["newton"] = serde_json::json!({"relative_tolerance": 1e-16, "absolute_tolerance_n": 0.0, "max_iterations": 1});
        v["initial"] = serde_json::json!({"kind": "rest"});
        let req: GeSimulateRequest = serde_json::from_value(v).unwrap();
        let out = simulate_ge(&req, &NoProgress).unwrap();
        match out.outcome {
            GeOutcome::NewtonFailed {
                step,
                residual_norm_n,
                ..
            } => {
                assert_eq!(step, 1);
                assert!(residual_norm_n > 0.0);
            }
            GeOutcome::Completed => panic!("expected a failure"),
        }
    }
}
