//! The JSON contract of the GE variant of `POST /api/v1/critical`
//! (`"model": {"kind": "geometrically_exact", ...}`): request and response
//! bodies ([`dto`]: SI, field names end in their unit), validation naming the
//! field, the runner [`ge_critical`], and the dispatch on `model.kind`
//! ([`AnyCriticalRequest`]) beside the linear string's body. The cable
//! model it prepares is shared with the GE stability query
//! ([`super::stability`]).
//!
//! * `marching` (default): one [`critical_time`] search of any deployment
//!   profile (march, local QEP every few steps, onset bracketed step by
//!   step), with the dissipative time stepping and step cuts of the chart
//!   searches, the closed forms for a constant rate and whether they apply;
//! * `quasi_static` (constant-rate profiles): the quasi-static GE critical
//!   length in calm air ([`crate::numerics::ge::qs_critical`]), served in
//!   the shape of the marching answer, with `t* = (h* − L0)/v`.
//!
//! Without `model.elements` (issue 21, SPEC §5) the critical length is
//! the converged one of [`crate::numerics::ge::qs_converged`] (nested
//! meshes from 20 elements, first-order Richardson, to the default
//! relative tolerance) and `max_elevation_m` and `critical_time_s` are its
//! safe side, best estimate minus the error estimate, with both stated.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

mod dto;
pub use dto::*;
pub(super) use dto::{default_gravity, default_initial_length, default_load_steps, default_modes};

use crate::contract::ge::numerics::{
    self as ge_numerics, GeOnsetKind, IntegratorOutput, newton_config,
};
use crate::contract::ge::simulate::stiffness_ratio_of;
use crate::contract::ge::{GeAerostatInput, GeModelInput};
use crate::contract::string::dto::{CriticalRequest, CriticalResponse};
use crate::contract::system::CableInput;
use crate::contract::system::input::ProfileInput;
use crate::contract::{Progress, RequestError, run};
use crate::numerics::ge::air_load::AirLoads;
use crate::numerics::ge::chart::closed_form_verdict;
use crate::numerics::ge::critical::{
    CriticalConfig, CriticalProblem, GeOnset, TipPerturbation, critical_time,
};
use crate::numerics::ge::extensible::ExtensibleString;
use crate::numerics::ge::qs_converged::{
    ConvergedOnset, ConvergedOutcome, ConvergedSearch, ConvergenceConfig, converged_critical_length,
};
use crate::numerics::ge::qs_critical::{
    QsOnset, QsSearch, QsSearchConfig, critical_length, lift_limit_length_m,
};
use crate::numerics::ge::{GeModel, TipBody};
use crate::numerics::params::{
    InvalidInput, require_finite, require_non_negative, require_positive,
};

/// The cable model of a GE request.
pub(super) struct Prepared {
    pub(super) model: GeModel,
    pub(super) initial_length_m: f64,
    pub(super) net_buoyancy_n: f64,
}

pub(super) fn prepare(
    cable: &CableInput,
    aerostat: &GeAerostatInput,
    initial_length_m: f64,
    gravity_m_s2: f64,
    model: &GeModelInput,
) -> Result<Prepared, InvalidInput> {
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
    let section = model.section(cable, l0, Some(buoyancy))?;
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
    check_bending_while_moving(&p.model, &profile, horizon, p.initial_length_m)?;
    let problem = CriticalProblem {
        profile,
        net_buoyancy_n: p.net_buoyancy_n,
        perturbation,
        aero: None,
        start: req.start_state.into(),
    };
    Ok((p.model, problem, config))
}

/// Refuses a cable whose bending stiffness the payout cancels: on the
/// moving mesh the rotary inertia of the material sliding through the
/// guide enters as `EI − I_ρ v²`, and where that is not positive the
/// bending equation is ill-posed (every short wave grows at once; the
/// spectrum of the start state is not finite). `I_ρ = A_ρ L0²/γ̃`.
fn check_bending_while_moving(
    model: &GeModel,
    profile: &crate::numerics::profile::Profile,
    horizon_s: f64,
    initial_length_m: f64,
) -> Result<(), InvalidInput> {
    let n = 2048;
    let fastest = (0..=n)
        .map(|i| {
            profile
                .kinematics(horizon_s * i as f64 / n as f64)
                .rate_m_s
                .abs()
        })
        .fold(0.0f64, f64::max);
    let s = &model.section;
    let ei = s.bending_stiffness_n_m2;
    let inertia_term = s.rotary_inertia_kg_m * fastest * fastest;
    if inertia_term >= ei {
        let least =
            s.mass_per_length_kg_m * initial_length_m * initial_length_m * fastest * fastest / ei;
        return Err(InvalidInput::new(
            "model.inertia_ratio",
            format!(
                "makes the rotary inertia I_ρ = A_ρ L0²/γ̃ = {:.4e} kg m, so at the profile's fastest rate {fastest:.4} m/s \
                 I_ρ v² = {inertia_term:.4e} N m² is not below the bending stiffness EI = {ei:.4e} N m²: the bending \
                 stiffness of the paying-out cable, EI − I_ρ v² = {:.4e} N m², is not positive and the model is ill-posed \
                 (every short bending wave grows at once). Give an inertia_ratio above A_ρ L0² v²/EI = {least:.4e}, \
                 or omit it to use the solid section of cable.diameter_m",
                s.rotary_inertia_kg_m,
                ei - inertia_term,
            ),
        ));
    }
    Ok(())
}

/// Runs a GE critical-time search; `progress.cancelled()` stops it.
pub fn ge_critical(
    req: &GeCriticalRequest,
    progress: &dyn Progress,
) -> Result<GeCriticalResponse, RequestError> {
    let (model, problem, config) = prepare_critical(req)?;
    if req.method == GeCriticalMethod::QuasiStatic {
        return quasi_static_critical(req, &model, &problem, progress);
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
        bending_closed_form_elevation_m: None,
        closed_form_applies: applies,
        closed_form_note: note,
        onset_root_axial_force_n: r.onset_root_axial_force_n,
        explanation,
        steps: r.steps,
        qep_solves: r.qep_solves,
        step_cuts: r.step_cuts,
        integrator: IntegratorOutput::new(config.scheme, config.max_step_cuts),
        start_state: req.start_state,
        stiffness_ratio: stiffness_ratio_of(&model.section, req.initial_length_m),
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

pub(super) fn is_ge(body: &[u8]) -> Result<bool, RequestError> {
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

/// `Some(x)` for a finite closed-form bound; `None` where it does not
/// exist (zero gravity: the string's bound F/(ρA g) is infinite).
pub(crate) fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
}

// ---------------------------------------------------------------- quasi-static method

/// A converged search as the onset of a search on one mesh (its safe side).
fn as_search(c: &ConvergedSearch) -> QsSearch {
    let onset = match &c.outcome {
        ConvergedOutcome::During(o) => QsOnset::During { at: o.safe_value },
        ConvergedOutcome::Immediate => QsOnset::Immediate {
            max_real_1_s: f64::NAN,
        },
        ConvergedOutcome::Never { up_to } => QsOnset::Never { up_to: *up_to },
        ConvergedOutcome::Failed { at } => QsOnset::EquilibriumFailed {
            at: *at,
            failure: crate::numerics::ge::solver::NewtonFailure {
                time_s: 0.0,
                iterations: 0,
                residual_norm: f64::NAN,
            },
        },
        ConvergedOutcome::Cancelled => QsOnset::Cancelled,
    };
    QsSearch {
        onset,
        bracket: None,
        divergence: true,
        qep_solves: 0,
        equilibria: c.equilibria,
        at_onset: match &c.outcome {
            ConvergedOutcome::During(o) => Some(o.at_safe),
            _ => None,
        },
    }
}

/// The quasi-static answer of a GE critical-time request (already checked by `prepare_critical`).
pub fn quasi_static_critical(
    req: &GeCriticalRequest,
    model: &GeModel,
    problem: &CriticalProblem,
    progress: &dyn Progress,
) -> Result<GeCriticalResponse, RequestError> {
    let l0 = problem.profile.initial_length_m();
    let k0 = problem.profile.kinematics(0.0);
    let v = k0.rate_m_s;
    let f = problem.net_buoyancy_n;
    let air = AirLoads::calm();
    let lift_limit = lift_limit_length_m(model, f, &air);
    let upper = match problem.profile.stop_time_s() {
        Some(t) => problem.profile.kinematics(t).length_m,
        None => (1.5 * lift_limit).max(l0),
    };
    let config = QsSearchConfig {
        state: crate::numerics::ge::quasi_static::QsConfig {
            newton: newton_config(&req.newton)?,
            ..Default::default()
        },
        ..QsSearchConfig::default()
    };
    let cancel = || progress.cancelled();
    // Converged without `model.elements` (module docs); paying out only
    // (a retrieval's onset is not a divergence).
    let converged: Option<ConvergedOnset>;
    let r = if req.model.elements.is_none() && v > 0.0 {
        let c = converged_critical_length(
            model,
            f,
            &air,
            v,
            &ConvergenceConfig::default(),
            (l0, upper.max(l0)),
            &cancel,
        )?;
        converged = match &c.outcome {
            ConvergedOutcome::During(o) => Some(o.clone()),
            _ => None,
        };
        as_search(&c)
    } else {
        converged = None;
        critical_length(
            model,
            f,
            &air,
            v,
            0.0,
            req.start_state.into(),
            &config,
            (l0, upper.max(l0)),
            &cancel,
        )?
    };
    let is_converged = req.model.elements.is_none() && v > 0.0;
    let time_at = |l: f64| {
        if v != 0.0 {
            ((l - l0) / v).max(0.0)
        } else {
            0.0
        }
    };
    let (onset, t, h, ended, explanation) = match r.onset {
        QsOnset::Cancelled => return Err(RequestError::Cancelled),
        QsOnset::Immediate { max_real_1_s } => (
            GeOnsetKind::Immediate,
            Some(0.0),
            Some(l0),
            None,
            format!(
                "unstable at t = 0: the quasi-static state at L0 = {l0} m has a growth rate {max_real_1_s:.3e} 1/s"
            ),
        ),
        QsOnset::During { at } => (
            GeOnsetKind::During,
            Some(time_at(at)),
            Some(at),
            None,
            match &converged {
                Some(c) => format!(
                    "quasi-static, converged: stable until the cable is {at:.2} m long (t* = {:.3} s at {v} m/s), \
                     the safe side of the continuum estimate {:.2} ± {:.2} m (meshes of {} to {} elements{}); \
                     a real eigenvalue crosses zero there (divergence)",
                    time_at(at),
                    c.value,
                    c.error_estimate,
                    c.levels.first().map_or(0, |l| l.0),
                    c.levels.last().map_or(0, |l| l.0),
                    if c.converged {
                        ""
                    } else {
                        ", tolerance not met: the finest mesh was reached"
                    }
                ),
                None => format!(
                    "quasi-static: stable until the cable is {at:.2} m long (t* = {:.3} s at {v} m/s){}",
                    time_at(at),
                    if r.divergence {
                        "; a real eigenvalue crosses zero there (divergence)"
                    } else {
                        ""
                    }
                ),
            },
        ),
        QsOnset::Never { up_to } => (
            GeOnsetKind::Never,
            None,
            None,
            Some(time_at(up_to)),
            format!("quasi-static: stable up to {up_to:.1} m, the end of the search"),
        ),
        QsOnset::EquilibriumFailed { at, failure } => (
            GeOnsetKind::NewtonFailed,
            None,
            None,
            Some(time_at(at)),
            format!(
                "no quasi-static equilibrium at {at:.1} m: Newton stopped after {} iterations (residual {:.3e} N)",
                failure.iterations, failure.residual_norm
            ),
        ),
        QsOnset::SpectrumFailed { at } => (
            GeOnsetKind::SpectrumFailed,
            None,
            None,
            Some(time_at(at)),
            format!("the eigenvalue iteration failed at {at:.1} m"),
        ),
    };
    let rho_a = model.section.mass_per_length_kg_m;
    let closed = |ea: f64| {
        ExtensibleString {
            net_buoyancy_n: f,
            aerostat_mass_kg: model.tip.mass_kg,
            mass_per_length_kg_m: rho_a,
            axial_stiffness_n: ea,
            gravity_m_s2: model.gravity_m_s2,
        }
        .critical_length_m(v.abs())
        .unwrap_or(0.0)
    };
    let scale = model.section.time_scale_s(l0);
    let defaults = CriticalConfig::default();
    Ok(GeCriticalResponse {
        onset,
        critical_time_s: t,
        critical_time_nondim: t.map(|t| t / scale),
        max_elevation_m: h,
        ended_at_s: ended,
        string_closed_form_elevation_m: (v > 0.0).then(|| closed(f64::INFINITY)).and_then(finite),
        extensible_closed_form_elevation_m: (v > 0.0)
            .then(|| closed(model.section.axial_stiffness_n))
            .and_then(finite),
        bending_closed_form_elevation_m: (v > 0.0)
            .then(|| {
                crate::numerics::ge::airy_onset::AiryOnset::of_model(model, f).critical_length_m(v)
            })
            .flatten()
            .and_then(finite),
        closed_form_applies: v > 0.0,
        closed_form_note: (v <= 0.0).then(|| "no closed form for a retrieval".to_string()),
        onset_root_axial_force_n: match r.onset {
            QsOnset::During { .. } => r.at_onset.map(|s| s.root_axial_force_n),
            _ => None,
        },
        explanation,
        steps: 0,
        qep_solves: r.qep_solves,
        step_cuts: 0,
        integrator: IntegratorOutput::new(defaults.scheme, defaults.max_step_cuts),
        start_state: req.start_state,
        stiffness_ratio: stiffness_ratio_of(&model.section, req.initial_length_m),
        elements: model.elements,
        time_scale_s: scale,
        wave_speed_m_s: (f / rho_a).sqrt(),
        method: GeCriticalMethod::QuasiStatic,
        quasi_static_bracket_m: r.bracket.map(|(a, b)| [a, b]),
        quasi_static_equilibrium_solves: Some(r.equilibria),
        converged: is_converged.then(|| converged.as_ref().is_some_and(|c| c.converged)),
        relative_tolerance_nondim: is_converged
            .then_some(ConvergenceConfig::default().relative_tolerance),
        max_elevation_estimate_m: converged.as_ref().map(|c| c.value),
        max_elevation_error_m: converged.as_ref().map(|c| c.error_estimate),
        critical_time_error_s: converged.as_ref().map(|c| c.error_estimate / v),
        mesh_levels: converged.as_ref().map(|c| {
            c.levels
                .iter()
                .zip(c.first_elements.iter().chain(std::iter::repeat(&f64::NAN)))
                .map(|(&(elements, h), &first)| GeMeshLevelOutput {
                    elements,
                    first_element_m: first * h,
                    max_elevation_m: h,
                })
                .collect()
        }),
    })
}
