//! The JSON contract of the GE variants of `POST /api/v1/critical` and
//! `POST /api/v1/stability` (`"model": {"kind": "geometrically_exact", ...}`):
//! request and response bodies (SI; field names end in their unit),
//! validation naming the field, the runners [`ge_critical`] and
//! [`ge_stability`], and the dispatch on `model.kind` ([`AnyCriticalRequest`],
//! [`AnyStabilityRequest`]) beside the linear string's bodies.
//!
//! * critical: one [`critical_time`] search of any deployment profile
//!   (march, local QEP every few steps, onset bracketed step by step), with
//!   the dissipative time stepping and step cuts of the chart searches,
//!   the closed forms for a constant rate and whether they apply;
//! * stability: the straight quasi-static equilibrium at the state's
//!   length, rate and acceleration, then the local QEP (7.3) about it
//!   ([`state_stability`]).

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::contract::dto::{
    CableInput, CriticalRequest, CriticalResponse, EigenvalueOutput, ProfileInput,
    StabilityRequest, StabilityResponse, StateInput,
};
use crate::contract::ge::{GeAerostatInput, GeModelInput, NewtonInput};
use crate::contract::ge_charts::{GeChartNumericsInput, GeOnsetKind, newton_config};
use crate::contract::ge_numerics::{self, IntegratorOutput, StartStateInput};
use crate::contract::{Progress, RequestError, run};
use crate::numerics::ge::chart::closed_form_verdict;
use crate::numerics::ge::critical::{
    CriticalConfig, CriticalProblem, GeOnset, TipPerturbation, critical_time,
};
use crate::numerics::ge::element::TipLoad;
use crate::numerics::ge::extensible::ExtensibleString;
use crate::numerics::ge::stability::{GeStateFailure, state_stability};
use crate::numerics::ge::{GeModel, TipBody};
use crate::numerics::params::{
    InvalidInput, Kinematics, require_finite, require_non_negative, require_positive,
};

/// Largest element count of a GE critical-time search or stability query
/// (a dense QEP of size 6n per check).
pub const MAX_GE_QEP_ELEMENTS: usize = 200;
/// Largest `(horizon / Δt) × elements` of one GE critical-time search.
pub const MAX_CRITICAL_WORK: f64 = 5e8;
/// Largest |F0| (N).
pub const MAX_PERTURBATION_N: f64 = 1e6;
/// Largest state length of a GE stability query, in initial lengths.
pub const MAX_LENGTH_RATIO: f64 = 1e6;

fn default_initial_length() -> f64 {
    1.0
}
fn default_gravity() -> f64 {
    9.81
}
fn default_ramp() -> f64 {
    0.25
}
fn default_hold() -> f64 {
    1.0
}
fn default_modes() -> usize {
    3
}
fn default_load_steps() -> usize {
    2
}

/// A sideways push on the aerostat at the start (thesis Fig. 7.4).
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct GePerturbationInput {
    /// Peak force F0 across the guide (N).
    #[schema(example = 400.0, minimum = -1e6, maximum = 1e6)]
    pub force_n: f64,
    /// Linear rise time (s).
    #[serde(default = "default_ramp")]
    #[schema(example = 0.25, minimum = 0.0, maximum = 1e4)]
    pub ramp_s: f64,
    /// Release time (s), at least `ramp_s`.
    #[serde(default = "default_hold")]
    #[schema(example = 1.0, minimum = 0.0, maximum = 1e4)]
    pub hold_s: f64,
}

/// `POST /api/v1/critical` with `"model": {"kind": "geometrically_exact"}`:
/// t* and h* of the GE cable for a deployment profile.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({
    "cable": {"mass_per_length_kg_m": 0.078},
    "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
    "initial_length_m": 1.0,
    "gravity_m_s2": 9.81,
    "model": {"kind": "geometrically_exact", "elements": 20, "bending_stiffness_n_m2": 1000.0,
              "stiffness_ratio": 1e5, "inertia_ratio": 1.0},
    "profile": {"kind": "constant_rate", "rate_m_s": 40.0},
    "start_state": "at_rest"
}))]
pub struct GeCriticalRequest {
    pub cable: CableInput,
    pub aerostat: GeAerostatInput,
    /// Initial length L0 (m), the length scale of E* and γ̃.
    #[serde(default = "default_initial_length")]
    #[schema(example = 1.0, minimum = 0.001, maximum = 10000.0)]
    pub initial_length_m: f64,
    #[serde(default = "default_gravity")]
    #[schema(example = 9.81, minimum = 0.0, maximum = 100.0)]
    pub gravity_m_s2: f64,
    pub model: GeModelInput,
    pub profile: ProfileInput,
    /// Sideways push on the aerostat at the start; none: unperturbed.
    #[serde(default)]
    pub perturbation: Option<GePerturbationInput>,
    /// The cable's motion when the winch starts.
    #[serde(default)]
    pub start_state: StartStateInput,
    /// Step, QEP interval, horizon, scheme (default: generalized-α, ρ∞ = 0), step cuts.
    #[serde(default)]
    pub numerics: Option<GeChartNumericsInput>,
    #[serde(default)]
    pub newton: Option<NewtonInput>,
    /// `marching` (default): march the deployment and solve the local QEP
    /// along it. `quasi_static`: the fast quasi-static answer for a
    /// constant rate — the quasi-static equilibrium at each length, its
    /// stiffness inertia bisected to the divergence root, confirmed by the
    /// local QEP on either side (within 0.01 % of the marching h* for
    /// Table 7.1 data); `numerics` (time stepping) and `perturbation` are
    /// refused with it.
    #[serde(default)]
    pub method: GeCriticalMethod,
}

/// How a GE critical time is found.
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, ToSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum GeCriticalMethod {
    /// March the deployment (generalized-α), local QEP every few steps.
    #[default]
    Marching,
    /// Quasi-static: equilibrium and local QEP at each length, no march
    /// (constant-rate profiles only).
    QuasiStatic,
}

/// The answer of a GE critical-time search.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct GeCriticalResponse {
    pub onset: GeOnsetKind,
    /// t* (s): 0 if unstable at once; null unless `immediate`/`during`.
    pub critical_time_s: Option<f64>,
    /// t* / (L0 √(I_ρ/EI)).
    pub critical_time_nondim: Option<f64>,
    /// h* = L(t*) (m).
    pub max_elevation_m: Option<f64>,
    /// Time at which the search ended without an onset (s).
    pub ended_at_s: Option<f64>,
    /// Constant rate only: the string's continuum bound (F/ρA − v²)/g (m),
    /// clipped at 0; null for other profiles.
    pub string_closed_form_elevation_m: Option<f64>,
    /// Constant rate only: the quasi-static bound of an extensible string of
    /// this axial stiffness (m), clipped at 0.
    pub extensible_closed_form_elevation_m: Option<f64>,
    /// Whether the closed forms describe this onset: false without a
    /// closed form (profiles other than a constant rate), with a tip
    /// perturbation still acting at t*, or when the onset is a start-up
    /// transient (the axial force at the guide departs from the
    /// steady-payout tension enough to move h* by more than 2 %).
    pub closed_form_applies: bool,
    /// Why the closed forms do not apply, when they do not.
    pub closed_form_note: Option<String>,
    /// Axial force in the element at the guide at t* (N).
    pub onset_root_axial_force_n: Option<f64>,
    /// Plain-language account of the answer.
    pub explanation: String,
    pub steps: usize,
    pub qep_solves: usize,
    /// Steps halved and retried after a Newton failure.
    pub step_cuts: usize,
    pub integrator: IntegratorOutput,
    pub start_state: StartStateInput,
    pub stiffness_ratio: f64,
    pub elements: usize,
    /// L0 √(I_ρ/EI) (s).
    pub time_scale_s: f64,
    /// √(F/ρA) (m/s).
    pub wave_speed_m_s: f64,
    /// The method that produced this answer.
    #[serde(default)]
    pub method: GeCriticalMethod,
    /// Quasi-static only: the final bracket of h* (stable, unstable) (m).
    #[serde(default)]
    pub quasi_static_bracket_m: Option<[f64; 2]>,
    /// Quasi-static only: equilibria solved.
    #[serde(default)]
    pub quasi_static_equilibrium_solves: Option<usize>,
    /// Quasi-static without `model.elements`: the critical length is
    /// converged (nested meshes from `elements`, Richardson) and
    /// `max_elevation_m` / `critical_time_s` are its safe side (best
    /// estimate minus the error estimate); null otherwise.
    #[serde(default)]
    pub converged: Option<bool>,
    /// Converged only: the relative tolerance of the search.
    #[serde(default)]
    pub relative_tolerance_nondim: Option<f64>,
    /// Converged only: the best estimate of the continuum h* (m).
    #[serde(default)]
    pub max_elevation_estimate_m: Option<f64>,
    /// Converged only: the estimated discretisation error of that estimate (m).
    #[serde(default)]
    pub max_elevation_error_m: Option<f64>,
    /// Converged only: the same error in t* (s), `max_elevation_error_m / v`.
    #[serde(default)]
    pub critical_time_error_s: Option<f64>,
    /// Converged only: `(elements, divergence root h* in m)` of each mesh.
    #[serde(default)]
    pub mesh_levels: Option<Vec<GeMeshLevelOutput>>,
}

/// One mesh of a converged quasi-static search.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct GeMeshLevelOutput {
    pub elements: usize,
    /// The divergence root on this mesh (m).
    pub max_elevation_m: f64,
}

/// The cable model of a GE request.
struct Prepared {
    model: GeModel,
    initial_length_m: f64,
    net_buoyancy_n: f64,
}

fn prepare(
    cable: &CableInput,
    aerostat: &GeAerostatInput,
    initial_length_m: f64,
    gravity_m_s2: f64,
    model: &GeModelInput,
) -> Result<Prepared, InvalidInput> {
    let rho_a = cable.mass_per_length()?;
    let l0 = require_positive("initial_length_m", initial_length_m)?;
    let g = require_non_negative("gravity_m_s2", gravity_m_s2)?;
    let buoyancy = aerostat.net_buoyancy("aerostat")?;
    if !(1..=MAX_GE_QEP_ELEMENTS).contains(&model.elements()) {
        return Err(InvalidInput::new(
            "model.elements",
            format!(
                "must be between 1 and {MAX_GE_QEP_ELEMENTS} for a GE stability or critical-time answer, got {}",
                model.elements()
            ),
        ));
    }
    let section = model.section(rho_a, l0)?;
    let tip = TipBody {
        mass_kg: aerostat.mass("aerostat")?,
        link_length_m: aerostat.link_length("aerostat")?,
    };
    Ok(Prepared {
        model: GeModel::new(section, model.elements(), tip, g)?,
        initial_length_m: l0,
        net_buoyancy_n: buoyancy,
    })
}

/// The core problem and settings of a GE critical request, checked.
pub fn prepare_critical(
    req: &GeCriticalRequest,
) -> Result<(GeModel, CriticalProblem, CriticalConfig), InvalidInput> {
    let p = prepare(
        &req.cable,
        &req.aerostat,
        req.initial_length_m,
        req.gravity_m_s2,
        &req.model,
    )?;
    let profile = req.profile.profile(p.initial_length_m)?;
    if let ProfileInput::ConstantRate { rate_m_s, .. } = req.profile
        && rate_m_s == 0.0
    {
        return Err(InvalidInput::new(
            "profile.rate_m_s",
            "must be nonzero: a zero rate never changes the length (ask for the stability of that state instead)",
        ));
    }
    if req.method == GeCriticalMethod::QuasiStatic {
        if !matches!(req.profile, ProfileInput::ConstantRate { .. }) {
            return Err(InvalidInput::new(
                "method",
                "quasi_static needs a constant_rate profile (use marching for other profiles)",
            ));
        }
        if req.perturbation.is_some() {
            return Err(InvalidInput::new(
                "perturbation",
                "a tip perturbation needs the marching method: the quasi-static answer has no time history",
            ));
        }
        if req.numerics.is_some() {
            return Err(InvalidInput::new(
                "numerics",
                "time-stepping settings apply to the marching method only",
            ));
        }
    }
    let perturbation = match &req.perturbation {
        None => None,
        Some(x) => {
            require_finite("perturbation.force_n", x.force_n)?;
            if x.force_n.abs() > MAX_PERTURBATION_N {
                return Err(InvalidInput::new(
                    "perturbation.force_n",
                    format!(
                        "must be between -{MAX_PERTURBATION_N:.0e} and {MAX_PERTURBATION_N:.0e} N, got {}",
                        x.force_n
                    ),
                ));
            }
            for (field, v) in [
                ("perturbation.ramp_s", x.ramp_s),
                ("perturbation.hold_s", x.hold_s),
            ] {
                if !(0.0..=1e4).contains(&v) {
                    return Err(InvalidInput::new(
                        field,
                        format!("must be between 0 and 1e4 s, got {v}"),
                    ));
                }
            }
            let t = TipPerturbation {
                force_n: x.force_n,
                ramp_s: x.ramp_s,
                hold_s: x.hold_s,
            };
            t.validate()?;
            Some(t)
        }
    };
    let defaults = CriticalConfig::default();
    let config = match &req.numerics {
        None => CriticalConfig {
            newton: newton_config(&req.newton)?,
            ..defaults
        },
        Some(n) => {
            if !(1..=100_000).contains(&n.check_every_steps) {
                return Err(InvalidInput::new(
                    "numerics.check_every_steps",
                    format!("must be between 1 and 100000, got {}", n.check_every_steps),
                ));
            }
            CriticalConfig {
                time_step_s: require_positive("numerics.time_step_s", n.time_step_s)?,
                check_every: n.check_every_steps,
                growth_tolerance_1_s: require_non_negative(
                    "numerics.growth_tolerance_1_s",
                    n.growth_tolerance_1_s,
                )?,
                horizon_s: require_positive("numerics.horizon_s", n.horizon_s)?,
                newton: newton_config(&req.newton)?,
                scheme: ge_numerics::scheme(n.scheme, n.rho_infinity_nondim, "numerics")?,
                max_step_cuts: ge_numerics::step_cuts(n.max_step_cuts, "numerics")?,
            }
        }
    };
    config.validate()?;
    let horizon = profile
        .stop_time_s()
        .map_or(config.horizon_s, |s| s.min(config.horizon_s));
    let work = horizon / config.time_step_s * p.model.elements as f64;
    if work > MAX_CRITICAL_WORK {
        return Err(InvalidInput::new(
            "numerics.time_step_s",
            format!(
                "{:.0} steps × {} elements exceeds the work limit {MAX_CRITICAL_WORK:.0e}",
                horizon / config.time_step_s,
                p.model.elements
            ),
        ));
    }
    let problem = CriticalProblem {
        profile,
        net_buoyancy_n: p.net_buoyancy_n,
        perturbation,
        aero: None,
        start: req.start_state.into(),
    };
    Ok((p.model, problem, config))
}

/// Runs a GE critical-time search; `progress.cancelled()` stops it.
pub fn ge_critical(
    req: &GeCriticalRequest,
    progress: &dyn Progress,
) -> Result<GeCriticalResponse, RequestError> {
    let (model, problem, config) = prepare_critical(req)?;
    if req.method == GeCriticalMethod::QuasiStatic {
        return crate::contract::ge_quasi_static::quasi_static_critical(
            req, &model, &problem, progress,
        );
    }
    let cancel = || progress.cancelled();
    let r = critical_time(&model, &problem, &config, &cancel)?;
    if matches!(r.onset, GeOnset::Cancelled { .. }) {
        return Err(RequestError::Cancelled);
    }
    let l0 = problem.profile.initial_length_m();
    let scale = model.section.time_scale_s(l0);
    let rho_a = model.section.mass_per_length_kg_m;
    let rate = match req.profile {
        ProfileInput::ConstantRate { rate_m_s, .. } if rate_m_s > 0.0 => Some(rate_m_s),
        _ => None,
    };
    let closed = |axial_stiffness_n: f64, v: f64| {
        ExtensibleString {
            net_buoyancy_n: problem.net_buoyancy_n,
            aerostat_mass_kg: model.tip.mass_kg,
            mass_per_length_kg_m: rho_a,
            axial_stiffness_n,
            gravity_m_s2: model.gravity_m_s2,
        }
        .critical_length_m(v)
        .unwrap_or(0.0)
    };
    // a push still acting at t* is not in the closed forms
    let pushed_at_onset = match (problem.perturbation, r.time_s()) {
        (Some(p), Some(t)) => p.force_n != 0.0 && t <= p.hold_s,
        _ => false,
    };
    let (applies, note) = match rate {
        None => (
            false,
            Some("no closed form for this profile: the closed forms are for a constant rate".into()),
        ),
        Some(_) if pushed_at_onset => (
            false,
            Some("the tip perturbation still acts at t*; the closed forms are for an unperturbed cable".into()),
        ),
        Some(v) => {
            let verdict = closed_form_verdict(&model, v, problem.net_buoyancy_n, false, &r);
            (verdict.applies(), verdict.reason())
        }
    };
    let (onset, ended_at_s) = onset_kind(r.onset);
    let explanation = match r.onset {
        GeOnset::Immediate { max_real_1_s } => format!(
            "unstable at t = 0: the local QEP of the start state has a growth rate {max_real_1_s:.3e} 1/s"
        ),
        GeOnset::During { time_s, length_m } => {
            format!("stable until t* = {time_s:.3} s, when the cable is {length_m:.1} m long")
        }
        GeOnset::Never { until_s } => format!(
            "stable for the whole search (checked up to t = {until_s:.3} s, length {:.1} m)",
            problem.profile.kinematics(until_s).length_m
        ),
        GeOnset::NewtonFailed(f) => format!(
            "the march failed at t = {:.4} s: Newton did not converge after {} iterations (residual {:.3e} N) even with the step cut {} times; no onset was seen before",
            f.time_s, f.iterations, f.residual_norm, config.max_step_cuts
        ),
        GeOnset::SpectrumFailed { time_s } => {
            format!(
                "the eigenvalue iteration failed at t = {time_s:.4} s; no onset was seen before"
            )
        }
        GeOnset::Cancelled { time_s } => format!("cancelled at t = {time_s:.3} s"),
    };
    let t = r.time_s();
    Ok(GeCriticalResponse {
        onset,
        critical_time_s: t,
        critical_time_nondim: t.map(|t| t / scale),
        max_elevation_m: r.length_m(&problem.profile),
        ended_at_s,
        string_closed_form_elevation_m: rate.and_then(|v| finite(closed(f64::INFINITY, v))),
        extensible_closed_form_elevation_m: rate
            .and_then(|v| finite(closed(model.section.axial_stiffness_n, v))),
        closed_form_applies: applies,
        closed_form_note: note,
        onset_root_axial_force_n: r.onset_root_axial_force_n,
        explanation,
        steps: r.steps,
        qep_solves: r.qep_solves,
        step_cuts: r.step_cuts,
        integrator: IntegratorOutput::new(config.scheme, config.max_step_cuts),
        start_state: req.start_state,
        stiffness_ratio: req.model.stiffness_ratio,
        elements: model.elements,
        time_scale_s: scale,
        wave_speed_m_s: (problem.net_buoyancy_n / rho_a).sqrt(),
        method: GeCriticalMethod::Marching,
        quasi_static_bracket_m: None,
        quasi_static_equilibrium_solves: None,
        converged: None,
        relative_tolerance_nondim: None,
        max_elevation_estimate_m: None,
        max_elevation_error_m: None,
        critical_time_error_s: None,
        mesh_levels: None,
    })
}

/// The output kind of a core onset, with the time a search ended without one.
pub fn onset_kind(onset: GeOnset) -> (GeOnsetKind, Option<f64>) {
    match onset {
        GeOnset::Immediate { .. } => (GeOnsetKind::Immediate, None),
        GeOnset::During { .. } => (GeOnsetKind::During, None),
        GeOnset::Never { until_s } => (GeOnsetKind::Never, Some(until_s)),
        GeOnset::NewtonFailed(f) => (GeOnsetKind::NewtonFailed, Some(f.time_s)),
        GeOnset::SpectrumFailed { time_s } => (GeOnsetKind::SpectrumFailed, Some(time_s)),
        GeOnset::Cancelled { time_s } => (GeOnsetKind::Cancelled, Some(time_s)),
    }
}

// ---------------------------------------------------------------- stability

/// `POST /api/v1/stability` with `"model": {"kind": "geometrically_exact"}`:
/// the local QEP of the GE cable about its quasi-static equilibrium at one
/// deployment state.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({
    "cable": {"mass_per_length_kg_m": 0.078},
    "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
    "initial_length_m": 1.0,
    "gravity_m_s2": 9.81,
    "model": {"kind": "geometrically_exact", "elements": 20, "bending_stiffness_n_m2": 1000.0,
              "stiffness_ratio": 1e5, "inertia_ratio": 1.0},
    "state": {"length_m": 500.0, "rate_m_s": 10.0, "acceleration_m_s2": 0.0},
    "modes": 3
}))]
pub struct GeStabilityRequest {
    pub cable: CableInput,
    pub aerostat: GeAerostatInput,
    /// Initial length L0 (m), the length scale of E* and γ̃.
    #[serde(default = "default_initial_length")]
    #[schema(example = 1.0, minimum = 0.001, maximum = 10000.0)]
    pub initial_length_m: f64,
    #[serde(default = "default_gravity")]
    #[schema(example = 9.81, minimum = 0.0, maximum = 100.0)]
    pub gravity_m_s2: f64,
    pub model: GeModelInput,
    pub state: StateInput,
    /// How many modes (Im λ ≥ 0, by frequency) to list.
    #[serde(default = "default_modes")]
    #[schema(example = 3, minimum = 1, maximum = 4000)]
    pub modes: usize,
    /// How the cable moves at the state: with the reel-out rate
    /// (`at_rest`, as a search from rest starts) or in steady payout.
    #[serde(default)]
    pub cable_motion: StartStateInput,
    /// Load increments of the equilibrium solve.
    #[serde(default = "default_load_steps")]
    #[schema(example = 2, minimum = 1, maximum = 100)]
    pub load_steps: usize,
    #[serde(default)]
    pub newton: Option<NewtonInput>,
}

/// How a GE stability query ended.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, ToSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum GeStabilityOutcome {
    /// The equilibrium converged and the QEP was solved.
    Solved,
    /// Newton did not find the equilibrium (e.g. the cable's weight
    /// exceeds the lift: no straight equilibrium).
    EquilibriumFailed,
    /// The eigenvalue iteration failed.
    SpectrumFailed,
}

/// The equilibrium about which the QEP was solved.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct GeEquilibriumOutput {
    /// Axial displacement of the cable top (m): the stretch.
    pub tip_axial_displacement_m: f64,
    /// Axial force in the element at the guide (N).
    pub root_axial_force_n: f64,
    /// The steady-payout (quasi-static) tension there (N).
    pub quasi_static_root_tension_n: f64,
}

#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct GeStabilityResponse {
    pub outcome: GeStabilityOutcome,
    /// Every Re λ ≤ tolerance; null unless `solved`.
    pub stable: Option<bool>,
    /// Largest Re λ (1/s).
    pub max_real_1_s: Option<f64>,
    /// Largest Re λ × L0 √(I_ρ/EI).
    pub max_real_nondim: Option<f64>,
    /// Tolerance on Re λ used for the verdict (1/s).
    pub tolerance_1_s: Option<f64>,
    /// The first `modes` eigenvalues with Im λ ≥ 0, by frequency.
    pub eigenvalues: Vec<EigenvalueOutput>,
    pub equilibrium: Option<GeEquilibriumOutput>,
    /// Why the answer is missing, when it is.
    pub explanation: String,
    pub length_m: f64,
    pub rate_m_s: f64,
    pub acceleration_m_s2: f64,
    pub cable_motion: StartStateInput,
    /// The string continuum bound (F/ρA − v²)/g at this rate (m), clipped
    /// at 0; null without gravity (the weight sets the bound: none at g = 0).
    pub string_closed_form_elevation_m: Option<f64>,
    /// The extensible string's quasi-static bound at this rate (m), clipped
    /// at 0; null without gravity.
    pub extensible_closed_form_elevation_m: Option<f64>,
    pub stiffness_ratio: f64,
    pub elements: usize,
    /// L0 √(I_ρ/EI) (s).
    pub time_scale_s: f64,
    /// √(F/ρA) (m/s).
    pub wave_speed_m_s: f64,
}

/// Every check of a GE stability query (no solve).
fn stability_inputs(
    req: &GeStabilityRequest,
) -> Result<
    (
        Prepared,
        Kinematics,
        crate::numerics::ge::solver::NewtonConfig,
    ),
    InvalidInput,
> {
    let p = prepare(
        &req.cable,
        &req.aerostat,
        req.initial_length_m,
        req.gravity_m_s2,
        &req.model,
    )?;
    let length = require_positive("state.length_m", req.state.length_m)?;
    if length > MAX_LENGTH_RATIO * p.initial_length_m {
        return Err(InvalidInput::new(
            "state.length_m",
            format!(
                "must be at most {MAX_LENGTH_RATIO:.0e} initial lengths ({:.3e} m), got {length}",
                MAX_LENGTH_RATIO * p.initial_length_m
            ),
        ));
    }
    let kin = Kinematics {
        length_m: length,
        rate_m_s: require_finite("state.rate_m_s", req.state.rate_m_s)?,
        acceleration_m_s2: require_finite("state.acceleration_m_s2", req.state.acceleration_m_s2)?,
    };
    if req.modes == 0 || req.modes > run::MAX_MODES {
        return Err(InvalidInput::new(
            "modes",
            format!(
                "must be between 1 and {}, got {}",
                run::MAX_MODES,
                req.modes
            ),
        ));
    }
    if !(1..=100).contains(&req.load_steps) {
        return Err(InvalidInput::new(
            "load_steps",
            format!("must be between 1 and 100, got {}", req.load_steps),
        ));
    }
    Ok((p, kin, newton_config(&req.newton)?))
}

/// Checks a GE stability query without solving it (job submission).
pub fn validate_stability(req: &GeStabilityRequest) -> Result<(), InvalidInput> {
    stability_inputs(req).map(drop)
}

/// The answer of a GE stability query.
pub fn ge_stability(req: &GeStabilityRequest) -> Result<GeStabilityResponse, RequestError> {
    let (p, kin, newton) = stability_inputs(req)?;
    let model = &p.model;
    let load = TipLoad {
        force_n: [p.net_buoyancy_n, 0.0],
        moment_n_m: 0.0,
    };
    let scale = model.section.time_scale_s(p.initial_length_m);
    let rho_a = model.section.mass_per_length_kg_m;
    let string = |axial_stiffness_n: f64| ExtensibleString {
        net_buoyancy_n: p.net_buoyancy_n,
        aerostat_mass_kg: model.tip.mass_kg,
        mass_per_length_kg_m: rho_a,
        axial_stiffness_n,
        gravity_m_s2: model.gravity_m_s2,
    };
    let v = kin.rate_m_s.abs();
    let mut out = GeStabilityResponse {
        outcome: GeStabilityOutcome::Solved,
        stable: None,
        max_real_1_s: None,
        max_real_nondim: None,
        tolerance_1_s: None,
        eigenvalues: Vec::new(),
        equilibrium: None,
        explanation: String::new(),
        length_m: kin.length_m,
        rate_m_s: kin.rate_m_s,
        acceleration_m_s2: kin.acceleration_m_s2,
        cable_motion: req.cable_motion,
        string_closed_form_elevation_m: finite(
            string(f64::INFINITY).critical_length_m(v).unwrap_or(0.0),
        ),
        extensible_closed_form_elevation_m: finite(
            string(model.section.axial_stiffness_n)
                .critical_length_m(v)
                .unwrap_or(0.0),
        ),
        stiffness_ratio: req.model.stiffness_ratio,
        elements: model.elements,
        time_scale_s: scale,
        wave_speed_m_s: (p.net_buoyancy_n / rho_a).sqrt(),
    };
    match state_stability(
        model,
        kin,
        load,
        req.cable_motion.into(),
        req.load_steps,
        newton,
    ) {
        Err(GeStateFailure::Equilibrium(f)) => {
            out.outcome = GeStabilityOutcome::EquilibriumFailed;
            out.explanation = format!(
                "no straight equilibrium found at {:.1} m: Newton stopped after {} iterations with residual {:.3e} N (is the cable heavier than the lift?)",
                kin.length_m, f.iterations, f.residual_norm
            );
        }
        Err(GeStateFailure::Spectrum(e)) => {
            out.outcome = GeStabilityOutcome::SpectrumFailed;
            out.explanation = format!("the eigenvalue problem could not be solved: {e}");
        }
        Ok(s) => {
            let sp = &s.spectrum;
            let tol = sp.tolerance();
            let stable = sp.max_real <= tol;
            out.stable = Some(stable);
            out.max_real_1_s = Some(sp.max_real);
            out.max_real_nondim = Some(sp.max_real * scale);
            out.tolerance_1_s = Some(tol);
            out.eigenvalues = sp
                .modes()
                .into_iter()
                .take(req.modes)
                .map(|e| EigenvalueOutput {
                    re_1_s: e.re,
                    im_1_s: e.im,
                    re_nondim: e.re * scale,
                    im_nondim: e.im * scale,
                    frequency_hz: e.im / (2.0 * std::f64::consts::PI),
                })
                .collect();
            let x = 0.5 * kin.length_m / model.elements as f64;
            out.equilibrium = Some(GeEquilibriumOutput {
                tip_axial_displacement_m: s.state.q[GeModel::dof(model.elements, 0)],
                root_axial_force_n: s.root_axial_force_n,
                quasi_static_root_tension_n: string(model.section.axial_stiffness_n).tension_n(
                    v,
                    kin.length_m,
                    x,
                ),
            });
            out.explanation = if stable {
                format!(
                    "stable: every eigenvalue has Re λ ≤ {tol:.3e} 1/s at {:.1} m",
                    kin.length_m
                )
            } else {
                format!(
                    "unstable: an eigenvalue grows at Re λ = {:.3e} 1/s at {:.1} m",
                    sp.max_real, kin.length_m
                )
            };
        }
    }
    Ok(out)
}

// ---------------------------------------------------------------- dispatch

/// `POST /api/v1/critical` for either model: `model.kind` picks the linear
/// string (`linear_string`, the default) or the GE cable (`geometrically_exact`).
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(untagged)]
pub enum AnyCriticalRequest {
    /// `model.kind = "geometrically_exact"`.
    GeometricallyExact(Box<GeCriticalRequest>),
    /// `model.kind = "linear_string"` (or absent).
    LinearString(CriticalRequest),
}

/// The answer of [`AnyCriticalRequest`].
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(untagged)]
pub enum AnyCriticalResponse {
    GeometricallyExact(Box<GeCriticalResponse>),
    LinearString(CriticalResponse),
}

/// `POST /api/v1/stability` for either model.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(untagged)]
pub enum AnyStabilityRequest {
    /// `model.kind = "geometrically_exact"`.
    GeometricallyExact(Box<GeStabilityRequest>),
    /// `model.kind = "linear_string"` (or absent).
    LinearString(StabilityRequest),
}

/// The answer of [`AnyStabilityRequest`].
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(untagged)]
pub enum AnyStabilityResponse {
    GeometricallyExact(Box<GeStabilityResponse>),
    LinearString(StabilityResponse),
}

fn is_ge(body: &[u8]) -> Result<bool, RequestError> {
    let value: serde_json::Value =
        serde_json::from_slice(body).map_err(|e| RequestError::Malformed(e.to_string()))?;
    Ok(value.pointer("/model/kind").and_then(|k| k.as_str()) == Some("geometrically_exact"))
}

/// Parses a critical-time body, choosing the model by `model.kind`.
pub fn parse_critical(body: &[u8]) -> Result<AnyCriticalRequest, RequestError> {
    if is_ge(body)? {
        let req: Box<GeCriticalRequest> = crate::contract::parse_ge(body, "the GE critical time")?;
        req.check_ranges()?;
        Ok(AnyCriticalRequest::GeometricallyExact(req))
    } else {
        crate::contract::parse(body).map(AnyCriticalRequest::LinearString)
    }
}

/// Parses a stability body, choosing the model by `model.kind`.
pub fn parse_stability(body: &[u8]) -> Result<AnyStabilityRequest, RequestError> {
    if is_ge(body)? {
        let req: Box<GeStabilityRequest> = crate::contract::parse_ge(body, "GE stability")?;
        req.check_ranges()?;
        Ok(AnyStabilityRequest::GeometricallyExact(req))
    } else {
        crate::contract::parse(body).map(AnyStabilityRequest::LinearString)
    }
}

/// Runs either critical-time search.
pub fn critical_any(
    req: &AnyCriticalRequest,
    progress: &dyn Progress,
) -> Result<AnyCriticalResponse, RequestError> {
    match req {
        AnyCriticalRequest::GeometricallyExact(r) => {
            ge_critical(r, progress).map(|r| AnyCriticalResponse::GeometricallyExact(Box::new(r)))
        }
        AnyCriticalRequest::LinearString(r) => {
            run::critical(r).map(AnyCriticalResponse::LinearString)
        }
    }
}

/// Runs either stability query.
pub fn stability_any(req: &AnyStabilityRequest) -> Result<AnyStabilityResponse, RequestError> {
    match req {
        AnyStabilityRequest::GeometricallyExact(r) => {
            ge_stability(r).map(|r| AnyStabilityResponse::GeometricallyExact(Box::new(r)))
        }
        AnyStabilityRequest::LinearString(r) => {
            run::stability(r).map(AnyStabilityResponse::LinearString)
        }
    }
}

/// `Some(x)` for a finite closed-form bound; `None` where it does not
/// exist (zero gravity: the string's bound F/(ρA g) is infinite).
pub(crate) fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
}
