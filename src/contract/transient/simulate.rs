//! Transient runs of the linear string (SPEC §2): the JSON contract of
//! `POST /api/v1/simulate` (and the CLI subcommand and job kind that share
//! it), its validation, and the conversion to and from
//! [`crate::numerics::string::transient`]; the wind on the aerostat is
//! [`super::aero`]'s.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::aero::AeroInput;
use crate::contract::error::{Progress, RequestError};
use crate::contract::system::input::{ProfileInput, SystemInput};
use crate::contract::system::output::{EigenvalueOutput, Groups, groups};
use crate::numerics::aero::Aerodynamics;
use crate::numerics::params::{AerostatSystem, InvalidInput, require_finite};
use crate::numerics::string::reduced::ReducedModel;
use crate::numerics::string::transient::{
    self, EigenTracking, InitialState, MAGNITUDE_CAP_LENGTHS, Observer, RunOutcome,
    TransientConfig, TransientError, TransientRun,
};

fn default_samples() -> usize {
    1000
}

fn default_eigen_count() -> usize {
    3
}

/// How the cable starts.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(tag = "kind", rename_all = "snake_case")]
#[serde(deny_unknown_fields)]
pub enum InitialStateInput {
    /// Straight and at rest.
    Rest {},
    /// y = a ζ⁴ (ζ = x/L), at rest; a is the tip deflection.
    Shape {
        #[schema(example = 0.01)]
        tip_deflection_m: f64,
    },
    /// A natural mode of the cable at rest at its initial length, at rest.
    Mode {
        /// 1 = the lowest.
        #[schema(example = 1, minimum = 1)]
        mode: usize,
        #[schema(example = 0.01)]
        tip_deflection_m: f64,
    },
    /// From rest, a horizontal force on the aerostat held for a time, then released.
    TipForce {
        #[schema(example = 200.0, minimum = -1e8, maximum = 1e8)]
        force_n: f64,
        #[schema(example = 1.0, minimum = 1e-6, maximum = 1e7)]
        duration_s: f64,
    },
}

impl Default for InitialStateInput {
    fn default() -> Self {
        Self::Rest {}
    }
}

/// Eigenvalues along the run.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct EigenTrackingInput {
    /// Time between QEP solves (s).
    #[schema(example = 1.0, minimum = 1e-6, maximum = 1e7)]
    pub interval_s: f64,
    /// How many modes to report (by frequency).
    #[serde(default = "default_eigen_count")]
    #[schema(example = 3, minimum = 1)]
    pub count: usize,
}

/// `POST /api/v1/simulate`: a transient run.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
pub struct SimulateRequest {
    #[serde(flatten)]
    pub system: SystemInput,
    #[serde(flatten)]
    pub params: SimulateParams,
}

impl std::ops::Deref for SimulateRequest {
    type Target = SimulateParams;
    fn deref(&self) -> &SimulateParams {
        &self.params
    }
}

impl std::ops::DerefMut for SimulateRequest {
    fn deref_mut(&mut self) -> &mut SimulateParams {
        &mut self.params
    }
}

/// The fields of a transient run request besides the system.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct SimulateParams {
    pub profile: ProfileInput,
    /// Simulated time (s).
    #[schema(example = 150.0, minimum = 1e-6, maximum = 1e7)]
    pub duration_s: f64,
    /// Time step (s); default: 64 steps per period of the first mode (at the
    /// start and the end) and of the forcing, 8 per profile ramp.
    #[serde(default)]
    #[schema(minimum = 1e-9, maximum = 1000.0)]
    pub time_step_s: Option<f64>,
    /// Output samples, evenly spaced in time (2..=100000).
    #[serde(default = "default_samples")]
    #[schema(example = 1000, minimum = 2, maximum = 100000)]
    pub samples: usize,
    #[serde(default)]
    pub initial: InitialStateInput,
    /// Wind on the aerostat; none: no air.
    #[serde(default)]
    pub aero: Option<AeroInput>,
    /// Eigenvalues along the run; none: not computed.
    #[serde(default)]
    pub eigenvalues: Option<EigenTrackingInput>,
    /// Also return the one-mode reduced model (thesis ch. 3) beside the FE
    /// run; needs a `shape` or `mode` initial state.
    #[serde(default)]
    pub reduced_model: bool,
}

/// Eigenvalues at one instant of a run.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct EigenTrackOutput {
    pub time_s: f64,
    pub length_m: f64,
    /// Largest Re λ (1/s).
    pub max_real_1_s: f64,
    pub stable: bool,
    /// The first modes (Im λ ≥ 0) by frequency.
    pub eigenvalues: Vec<EigenvalueOutput>,
}

/// The one-mode model W = sin(πζ/2) beside the FE run, at the same times.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct ReducedOutput {
    /// WKB frequency ψ (rad/s); null where α/l + γ ≤ 0.
    pub frequency_rad_s: Vec<Option<f64>>,
    /// WKB amplitude A0 ∝ [ψ(2m̃ + l)]^(-1/2) of the tip (m), equal to the
    /// initial tip deflection at t = 0.
    pub wkb_amplitude_m: Vec<Option<f64>>,
    /// Leading-order energy of the mode ¼(α/l + γ)A0² (J).
    pub mode_energy_j: Vec<Option<f64>>,
    /// Tip deflection of the one-mode equation integrated in time (m).
    pub tip_deflection_m: Vec<f64>,
}

/// `POST /api/v1/simulate` answer: time series (SI).
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct SimulateResponse {
    pub time_s: Vec<f64>,
    pub length_m: Vec<f64>,
    pub rate_m_s: Vec<f64>,
    pub tip_deflection_m: Vec<f64>,
    pub tip_velocity_m_s: Vec<f64>,
    /// max |tip deflection| since the previous sample (m).
    pub tip_envelope_m: Vec<f64>,
    /// Total energy (thesis (3.14)) (J).
    pub energy_j: Vec<f64>,
    /// The same without the axial kinetic energy ½(ρA L + m) L̇² (J).
    pub vibration_energy_j: Vec<f64>,
    /// Aerodynamic (and held) force on the aerostat (N).
    pub tip_force_n: Vec<f64>,
    pub eigenvalues: Vec<EigenTrackOutput>,
    pub reduced: Option<ReducedOutput>,
    /// `completed`, `diverged` (deflection beyond 1e100 L0 or a failed
    /// step) or `length_collapsed` (shortened below 0.001 L0).
    pub outcome: String,
    /// When the run ended early (s).
    pub outcome_time_s: Option<f64>,
    pub explanation: String,
    /// First unstable instant of the deployment within the run (s): the
    /// critical time t* of the profile (the QEP criterion of `/critical`),
    /// or, where that search is too costly, the first unstable
    /// `eigenvalues` sample; null when stable over the run (or not known).
    /// The samples after it show growth past onset.
    pub first_unstable_time_s: Option<f64>,
    /// Cable length at `first_unstable_time_s` (m).
    pub first_unstable_length_m: Option<f64>,
    /// Why the run ended: `completed`, `magnitude_cap` (a deflection passed
    /// `magnitude_cap_m`), `step_failed` (non-finite or singular step),
    /// `length_collapsed`.
    pub stopped_reason: String,
    /// The deflection at which a run stops: `magnitude_cap_lengths_nondim`
    /// × the cable length, at the stop (or the end) of the run (m).
    pub magnitude_cap_m: f64,
    /// The cap as a multiple of the current cable length.
    pub magnitude_cap_lengths_nondim: f64,
    pub time_step_s: f64,
    pub steps: usize,
    /// Tension at the winch and the aerostat per output time (with the
    /// rate and acceleration terms), its extremes, slack and safety factor.
    pub tension: crate::contract::tension::TensionSeriesOutput,
    /// Displaced air mass m_f used by the aerodynamics (kg).
    pub displaced_air_mass_kg: Option<f64>,
    pub groups: Groups,
    pub elements: usize,
}

impl InitialStateInput {
    pub fn initial_state(&self) -> InitialState {
        match *self {
            Self::Rest {} => InitialState::Rest,
            Self::Shape { tip_deflection_m } => InitialState::Shape { tip_deflection_m },
            Self::Mode {
                mode,
                tip_deflection_m,
            } => InitialState::Mode {
                mode,
                tip_deflection_m,
            },
            Self::TipForce {
                force_n,
                duration_s,
            } => InitialState::TipForce {
                force_n,
                duration_s,
            },
        }
    }
}

/// Progress of the contract seen as a numerics observer.
pub(super) struct ProgressObserver<'a>(pub(super) &'a dyn Progress);

impl Observer for ProgressObserver<'_> {
    fn report(&self, done: usize, total: usize) {
        self.0.report(done, total);
    }
    fn cancelled(&self) -> bool {
        self.0.cancelled()
    }
}

pub(super) fn from_transient(e: TransientError) -> RequestError {
    match e {
        TransientError::Invalid(e) => RequestError::Invalid(e),
        TransientError::Qep(e) => RequestError::Numerical(e),
    }
}

pub(super) fn outcome_name(o: RunOutcome) -> (&'static str, Option<f64>) {
    match o {
        RunOutcome::Completed => ("completed", None),
        RunOutcome::Diverged { time_s } => ("diverged", Some(time_s)),
        RunOutcome::LengthCollapsed { time_s } => ("length_collapsed", Some(time_s)),
        RunOutcome::Cancelled { time_s } => ("cancelled", Some(time_s)),
    }
}

fn eigen_output(sys: &AerostatSystem, re_1_s: f64, im_1_s: f64) -> EigenvalueOutput {
    let ts = sys.time_scale_s();
    EigenvalueOutput {
        re_1_s,
        im_1_s,
        re_nondim: re_1_s * ts,
        im_nondim: im_1_s * ts,
        frequency_hz: im_1_s / (2.0 * std::f64::consts::PI),
    }
}

pub(super) fn config_from(
    duration_s: f64,
    time_step_s: Option<f64>,
    samples: usize,
    initial: &InitialStateInput,
    aero: Option<Aerodynamics>,
    eigen: Option<&EigenTrackingInput>,
) -> Result<TransientConfig, InvalidInput> {
    require_finite("duration_s", duration_s)?;
    Ok(TransientConfig {
        duration_s,
        time_step_s,
        samples,
        initial: initial.initial_state(),
        aero,
        eigen: eigen.map(|e| EigenTracking {
            interval_s: e.interval_s,
            count: e.count,
        }),
    })
}

/// A run as a request sets it up: the model, the profile and the
/// configuration (its time step fixed by [`transient::plan`]).
struct Setup {
    model: crate::numerics::string::StringModel,
    profile: crate::numerics::profile::Profile,
    config: TransientConfig,
}

fn setup(req: &SimulateRequest) -> Result<Setup, RequestError> {
    let model = req.system.model()?;
    let profile = req.profile.profile(model.system.initial_length_m)?;
    let aero = match &req.aero {
        Some(a) => Some(a.body().aerodynamics(
            a.flow.flow()?,
            model.system.aerostat_mass_kg,
            "aero",
        )?),
        None => None,
    };
    let config = config_from(
        req.duration_s,
        req.time_step_s,
        req.samples,
        &req.initial,
        aero,
        req.eigenvalues.as_ref(),
    )?;
    Ok(Setup {
        model,
        profile,
        config,
    })
}

/// The size of the run a request asks for: time steps and elements, as the
/// run fixes them (None: the request is invalid, and its run says why).
pub fn run_size(req: &SimulateRequest) -> Option<(usize, usize)> {
    let Setup {
        model,
        profile,
        config,
    } = setup(req).ok()?;
    let plan = transient::plan(&model, &profile, &config).ok()?;
    Some((plan.steps, model.elements()))
}

/// Runs a [`SimulateRequest`]. Progress counts time steps.
pub fn simulate(
    req: &SimulateRequest,
    progress: &dyn Progress,
) -> Result<SimulateResponse, RequestError> {
    let Setup {
        model,
        profile,
        config,
    } = setup(req)?;
    let sys = model.system;
    let breaking_strength_n = req.system.cable.breaking_strength()?;
    let initial_tip = match req.initial {
        InitialStateInput::Shape { tip_deflection_m }
        | InitialStateInput::Mode {
            tip_deflection_m, ..
        } => Some(tip_deflection_m),
        _ => None,
    };
    if req.reduced_model && initial_tip.is_none_or(|a| a == 0.0) {
        return Err(InvalidInput::new(
            "reduced_model",
            "the one-mode model needs an initial amplitude: use a `shape` or `mode` initial state with a nonzero tip deflection",
        )
        .into());
    }
    let displaced_air_mass_kg = config.aero.as_ref().map(|a| a.displaced_air_mass_kg);
    let run = transient::simulate(&model, &profile, &config, &ProgressObserver(progress))
        .map_err(from_transient)?;
    if matches!(run.outcome, RunOutcome::Cancelled { .. }) {
        return Err(RequestError::Cancelled);
    }
    let reduced = match initial_tip {
        Some(a0) if req.reduced_model => Some(reduced_output(&sys, &profile, &run, a0)?),
        _ => None,
    };
    let (outcome, outcome_time_s) = outcome_name(run.outcome);
    let explanation = match run.outcome {
        RunOutcome::Completed => format!(
            "ran {} steps of {:.4e} s to t = {} s",
            run.steps, run.time_step_s, req.duration_s
        ),
        RunOutcome::Diverged { time_s } if run.stopped_at_cap => format!(
            "the deflection passed {} × the cable length ({:.4e} m, far beyond the linear model) and the run stopped at t = {time_s:.3} s: the deployment is unstable",
            MAGNITUDE_CAP_LENGTHS,
            MAGNITUDE_CAP_LENGTHS * run.final_kinematics.length_m
        ),
        RunOutcome::Diverged { time_s } => format!(
            "a time step failed (the deflection grew without bound) and the run stopped at t = {time_s:.3} s: the deployment is unstable"
        ),
        RunOutcome::LengthCollapsed { time_s } => {
            format!(
                "the cable was shortened to (almost) zero length at t = {time_s:.3} s; the run stopped there"
            )
        }
        RunOutcome::Cancelled { .. } => unreachable!("handled above"),
    };
    let stopped_reason = match run.outcome {
        RunOutcome::Completed | RunOutcome::Cancelled { .. } => "completed",
        RunOutcome::Diverged { .. } if run.stopped_at_cap => "magnitude_cap",
        RunOutcome::Diverged { .. } => "step_failed",
        RunOutcome::LengthCollapsed { .. } => "length_collapsed",
    };
    let (first_unstable_time_s, first_unstable_length_m) =
        first_unstable(&model, &profile, &run, req.duration_s);
    let col = |f: fn(&transient::Sample) -> f64| run.samples.iter().map(f).collect::<Vec<f64>>();
    Ok(SimulateResponse {
        time_s: col(|s| s.time_s),
        length_m: col(|s| s.length_m),
        rate_m_s: col(|s| s.rate_m_s),
        tip_deflection_m: col(|s| s.tip_deflection_m),
        tip_velocity_m_s: col(|s| s.tip_velocity_m_s),
        tip_envelope_m: col(|s| s.tip_envelope_m),
        energy_j: col(|s| s.energy_j),
        vibration_energy_j: col(|s| s.vibration_energy_j),
        tip_force_n: col(|s| s.tip_force_n),
        eigenvalues: run
            .eigen
            .iter()
            .map(|e| EigenTrackOutput {
                time_s: e.time_s,
                length_m: e.length_m,
                max_real_1_s: e.max_real_1_s,
                stable: e.stable,
                eigenvalues: e
                    .modes
                    .iter()
                    .map(|m| eigen_output(&sys, m.re_1_s, m.im_1_s))
                    .collect(),
            })
            .collect(),
        reduced,
        outcome: outcome.into(),
        outcome_time_s,
        explanation,
        first_unstable_time_s,
        first_unstable_length_m,
        stopped_reason: stopped_reason.into(),
        magnitude_cap_m: MAGNITUDE_CAP_LENGTHS * run.final_kinematics.length_m,
        magnitude_cap_lengths_nondim: MAGNITUDE_CAP_LENGTHS,
        time_step_s: run.time_step_s,
        steps: run.steps,
        tension: crate::contract::tension::TensionSeriesOutput::of(
            &sys,
            &profile,
            &col(|s| s.time_s),
            breaking_strength_n,
        ),
        displaced_air_mass_kg,
        groups: groups(&sys),
        elements: model.elements(),
    })
}

/// Largest element count at which a simulate answer also runs the
/// critical-time search of its profile (dense QEP probes of size 2n).
pub const MAX_ONSET_SEARCH_ELEMENTS: usize = 400;

/// The first unstable instant of the run and the length then: the
/// profile's critical time when it falls within the run, else the first
/// unstable eigenvalue sample. A failed search is "not known" (null), not
/// an error: the run itself is the answer.
fn first_unstable(
    model: &crate::numerics::string::StringModel,
    profile: &crate::numerics::profile::Profile,
    run: &TransientRun,
    duration_s: f64,
) -> (Option<f64>, Option<f64>) {
    use crate::numerics::string::critical::{self, SearchConfig};
    if model.elements() <= MAX_ONSET_SEARCH_ELEMENTS
        && let Ok(ct) = critical::critical_time(
            model,
            profile,
            SearchConfig {
                confirm_with_qep: false,
            },
        )
    {
        return match ct.time_s() {
            Some(t) if t.is_finite() && t <= duration_s => {
                (Some(t), Some(profile.kinematics(t).length_m))
            }
            _ => (None, None),
        };
    }
    run.eigen
        .iter()
        .find(|e| !e.stable)
        .map_or((None, None), |e| (Some(e.time_s), Some(e.length_m)))
}

fn reduced_output(
    sys: &AerostatSystem,
    profile: &crate::numerics::profile::Profile,
    run: &TransientRun,
    tip_m: f64,
) -> Result<ReducedOutput, RequestError> {
    let reduced = ReducedModel::new(*sys);
    let (l0, ts, e_scale) = (
        sys.initial_length_m,
        sys.time_scale_s(),
        sys.net_buoyancy_n * sys.initial_length_m,
    );
    let l_start = profile.kinematics(0.0).length_m / l0;
    let a0 = tip_m / l0;
    let q = reduced
        .simulate(profile, a0, run.time_step_s, run.steps)
        .map_err(|e| {
            RequestError::Invalid(InvalidInput::new(
                "reduced_model",
                format!("the one-mode run failed: {e}"),
            ))
        })?;
    let mut out = ReducedOutput {
        frequency_rad_s: vec![],
        wkb_amplitude_m: vec![],
        mode_energy_j: vec![],
        tip_deflection_m: vec![],
    };
    for s in &run.samples {
        let l = s.length_m / l0;
        let amp = reduced.wkb_amplitude(l, l_start, a0.abs());
        out.frequency_rad_s
            .push(reduced.frequency(l).map(|w| w / ts));
        out.wkb_amplitude_m.push(amp.map(|a| a * l0));
        out.mode_energy_j
            .push(amp.map(|a| reduced.mode_energy(l, a) * e_scale));
        let step = (s.time_s / run.time_step_s).round() as usize;
        out.tip_deflection_m.push(if step == 0 {
            a0 * l0
        } else {
            q.get(step - 1).copied().unwrap_or(f64::NAN) * l0
        });
    }
    // JSON has no NaN: a sample past the reduced run (cannot happen) is 0.
    for v in &mut out.tip_deflection_m {
        if !v.is_finite() {
            *v = 0.0;
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contract::error::NoProgress;
    use crate::contract::parse;

    const SYSTEM: &str = r#""cable": {"density_kg_m3": 7800, "area_m2": 1e-5},
        "aerostat": {"net_buoyancy_n": 1000, "mass_kg": 10}, "initial_length_m": 1, "model": {"elements": 20}"#;

    #[test]
    fn simulate_round_trip_with_wind_eigenvalues_and_reduced_model() {
        let body = format!(
            r#"{{ {SYSTEM}, "profile": {{"kind": "trapezoidal", "cruise_rate_m_s": 10, "ramp_up_s": 2, "ramp_down_s": 2, "target_length_m": 101}},
                "duration_s": 15, "samples": 50, "initial": {{"kind": "mode", "mode": 1, "tip_deflection_m": 0.01}},
                "aero": {{"flow": {{"kind": "power_law", "coefficient_m_s": 0.1, "exponent_nondim": 0.3333}},
                          "model": {{"kind": "drag", "drag_coefficient_nondim": 0.5}}, "radius_m": 0.5}},
                "eigenvalues": {{"interval_s": 5, "count": 2}}, "reduced_model": true }}"#
        );
        let req: SimulateRequest = parse(body.as_bytes()).unwrap();
        let resp = simulate(&req, &NoProgress).unwrap();
        assert_eq!(resp.outcome, "completed");
        assert_eq!(resp.time_s.len(), 50);
        assert_eq!(resp.eigenvalues.len(), 4); // 0, 5, 10, 15 s
        assert_eq!(resp.eigenvalues[0].eigenvalues.len(), 2);
        let reduced = resp.reduced.as_ref().unwrap();
        assert_eq!(reduced.tip_deflection_m[0], 0.01);
        assert!((reduced.wkb_amplitude_m[0].unwrap() - 0.01).abs() < 1e-15);
        assert!((resp.length_m[49] - 101.0).abs() < 1e-9);
        assert!(resp.displaced_air_mass_kg.unwrap() > 0.6);
        // JSON out and back (floats to within the last digit)
        let json = serde_json::to_string(&resp).unwrap();
        let back: SimulateResponse = serde_json::from_str(&json).unwrap();
        assert_eq!(back.tip_deflection_m.len(), resp.tip_deflection_m.len());
        for (a, b) in back.energy_j.iter().zip(&resp.energy_j) {
            assert!((a - b).abs() <= 1e-15 * b.abs());
        }
    }

    #[test]
    fn simulate_rejects_bad_input_naming_the_field() {
        let field = |extra: &str| {
            let body = format!(
                r#"{{ {SYSTEM}, "profile": {{"kind": "constant_rate", "rate_m_s": 1}}, {extra} }}"#
            );
            // the range checks run at parsing, the rest at the run
            let req: SimulateRequest = match parse(body.as_bytes()) {
                Ok(r) => r,
                Err(RequestError::Invalid(e)) => return e.field,
                Err(e) => panic!("{e:?}"),
            };
            match simulate(&req, &NoProgress) {
                Err(RequestError::Invalid(e)) => e.field,
                other => panic!("expected invalid input, got {other:?}"),
            }
        };
        assert_eq!(field(r#""duration_s": -3"#), "duration_s");
        assert_eq!(field(r#""duration_s": 10, "samples": 1"#), "samples");
        assert_eq!(
            field(r#""duration_s": 1e7, "time_step_s": 1e-4"#),
            "time_step_s"
        );
        assert_eq!(
            field(r#""duration_s": 10, "reduced_model": true"#),
            "reduced_model"
        );
        assert_eq!(
            field(
                r#""duration_s": 10, "aero": {"flow": {"kind": "uniform", "speed_m_s": 1}, "radius_m": -1}"#
            ),
            "aero.radius_m"
        );
        assert_eq!(
            field(
                r#""duration_s": 10, "aero": {"flow": {"kind": "tabulated", "points": [{"elevation_m": 5, "speed_m_s": 1}, {"elevation_m": 1, "speed_m_s": 2}]}, "radius_m": 1}"#
            ),
            "aero.flow.points[1].elevation_m"
        );
        assert_eq!(
            field(
                r#""duration_s": 10, "aero": {"flow": {"kind": "uniform", "speed_m_s": 1}, "radius_m": 1, "model": {"kind": "drag", "drag_coefficient_nondim": -1}}"#
            ),
            "aero.model.drag_coefficient_nondim"
        );
        assert_eq!(
            field(r#""duration_s": 10, "eigenvalues": {"interval_s": 1, "count": 500}"#),
            "eigenvalues.count"
        );
        assert_eq!(
            field(
                r#""duration_s": 10, "initial": {"kind": "mode", "mode": 0, "tip_deflection_m": 0.1}"#
            ),
            "initial.mode"
        );
    }

    #[test]
    fn cancellation_is_an_error() {
        struct Cancel;
        impl Progress for Cancel {
            fn report(&self, _: usize, _: usize) {}
            fn cancelled(&self) -> bool {
                true
            }
        }
        let body = format!(
            r#"{{ {SYSTEM}, "profile": {{"kind": "constant_rate", "rate_m_s": 1}}, "duration_s": 10 }}"#
        );
        let req: SimulateRequest = parse(body.as_bytes()).unwrap();
        assert!(matches!(
            simulate(&req, &Cancel),
            Err(RequestError::Cancelled)
        ));
    }
}
