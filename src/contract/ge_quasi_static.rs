//! The `quasi_static` method of the GE `POST /api/v1/critical`
//! (`"method": "quasi_static"`, constant-rate profiles): the quasi-static
//! GE critical length in calm air ([`crate::numerics::ge::qs_critical`]),
//! served in the shape of the marching answer, with `t* = (h* − L0)/v`.
//!
//! Without `model.elements` (issue 21, SPEC §5) the critical length is
//! the converged one of [`crate::numerics::ge::qs_converged`] (nested
//! meshes from 20 elements, first-order Richardson, to the default
//! relative tolerance) and `max_elevation_m` and `critical_time_s` are its
//! safe side, best estimate minus the error estimate, with both stated.

use crate::contract::ge_charts::GeOnsetKind;
use crate::contract::ge_charts::newton_config;
use crate::contract::ge_critical::{GeCriticalMethod, GeCriticalRequest, GeCriticalResponse};
use crate::contract::ge_numerics::IntegratorOutput;
use crate::contract::{Progress, RequestError};
use crate::numerics::ge::GeModel;
use crate::numerics::ge::air_load::AirLoads;
use crate::numerics::ge::critical::{CriticalConfig, CriticalProblem};
use crate::numerics::ge::extensible::ExtensibleString;
use crate::numerics::ge::qs_converged::{
    ConvergedOnset, ConvergedOutcome, ConvergedSearch, ConvergenceConfig,
    converged_critical_length,
};
use crate::numerics::ge::qs_critical::{
    QsOnset, QsSearch, QsSearchConfig, critical_length, lift_limit_length_m,
};

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
                    if c.converged { "" } else { ", tolerance not met: the finest mesh was reached" }
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
        string_closed_form_elevation_m: (v > 0.0)
            .then(|| closed(f64::INFINITY))
            .and_then(crate::contract::ge_critical::finite),
        extensible_closed_form_elevation_m: (v > 0.0)
            .then(|| closed(model.section.axial_stiffness_n))
            .and_then(crate::contract::ge_critical::finite),
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
        stiffness_ratio: req.model.stiffness_ratio,
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
                .map(|&(elements, h)| crate::contract::ge_critical::GeMeshLevelOutput {
                    elements,
                    max_elevation_m: h,
                })
                .collect()
        }),
    })
}
