//! The quasi-static GE stability of a plan request (`stability.method =
//! quasi_static_ge`): its options, the still air it runs in without wind,
//! the check of a schedule and the GE block of the answer, over
//! [`crate::numerics::plan::ge_stability`].

use crate::contract::plan::dto::*;
use crate::numerics::ge::qs_converged::{BASE_ELEMENTS, ConvergenceConfig};
use crate::numerics::params::InvalidInput;
use crate::numerics::plan::air::{Air, SteadyWind};
use crate::numerics::plan::ge_stability::{self as ge_plan, GeStabilityOptions};
use crate::numerics::plan::schedule::Schedule;
use crate::numerics::plan::{BindingLimit, PlanProblem, STABILITY_MARGIN};
use crate::numerics::tether::string_onset;
use crate::numerics::tether::{Body, Cable, EquilibriumConfig};

/// Density of the tether's material assumed for its diameter in calm air
/// (the GE rotary inertia ρA d²/16 needs one; about that of aramid/UHMWPE).
pub const CALM_GE_MATERIAL_DENSITY_KG_M3: f64 = 1000.0;

/// Calm air for the GE criterion: the wind path with no wind (the
/// equilibrium is the straight tether), the diameter from ρA at
/// [`CALM_GE_MATERIAL_DENSITY_KG_M3`].
pub(super) fn calm_wind(mass_per_length_kg_m: f64) -> SteadyWind {
    let d = (4.0 * mass_per_length_kg_m / (std::f64::consts::PI * CALM_GE_MATERIAL_DENSITY_KG_M3))
        .sqrt();
    SteadyWind::new(
        Cable {
            mass_per_length_kg_m: 1.0,
            diameter_m: d,
            normal_drag_coefficient: 0.0,
            axial_stiffness_n: None,
            breaking_strength_n: None,
        },
        Body {
            net_buoyancy_n: 1.0,
            drag_coefficient: 0.0,
            lift_coefficient: 0.0,
            reference_area_m2: 1.0,
        },
        crate::numerics::tether::WindProfile::calm(),
        1.225,
    )
}

/// The tether's own EI (N m²): the cable's ([`crate::contract::system::CableInput::bending_stiffness`]),
/// in calm air without a diameter that of the diameter of [`calm_wind`].
fn tether_bending_stiffness(req: &PlanRequest) -> Result<f64, InvalidInput> {
    if let Some(ei) = req.cable.bending_stiffness("cable")? {
        return Ok(ei);
    }
    let rho_a = req.cable.mass_per_length()?;
    let d = calm_wind(rho_a).cable.diameter_m;
    crate::numerics::tether::presets::default_bending_stiffness_n_m2(
        None,
        d,
        req.cable.axial_stiffness("cable")?,
    )
    .map(|e| e.max(1e-6))
    .ok_or_else(|| {
        InvalidInput::new(
            "stability.bending_stiffness_n_m2",
            "is needed: give the tether's bending stiffness EI in N m² (or its diameter)",
        )
    })
}

/// The GE options of the request, if it asks for the GE criterion.
pub(super) fn ge_options(req: &PlanRequest) -> Result<Option<GeStabilityOptions>, InvalidInput> {
    let Some(st) = &req.stability else {
        return Ok(None);
    };
    let ei = match (st.bending_stiffness_n_m2, st.method) {
        (Some(ei), _) => ei,
        (None, PlanStabilityMethod::QuasiStaticGe) => tether_bending_stiffness(req)?,
        (None, _) => 1.0,
    };
    crate::numerics::params::ranges::BENDING_STIFFNESS_N_M2
        .check("stability.bending_stiffness_n_m2", ei)?;
    let converge =
        ConvergenceConfig::requested(st.elements.is_some(), st.relative_tolerance_nondim)?;
    let o = GeStabilityOptions {
        bending_stiffness_n_m2: ei,
        elements: st.elements.unwrap_or(BASE_ELEMENTS),
        check_elements: st.check_elements,
        table_lengths: st.table_samples,
        min_length_m: req.initial_length_m.min(req.target_elevation_m),
        converge,
    };
    o.validate()?;
    if !(2..=MAX_GE_CHECK_SAMPLES).contains(&st.check_samples) {
        return Err(InvalidInput::new(
            "stability.check_samples",
            format!(
                "must be between 2 and {MAX_GE_CHECK_SAMPLES}, got {}",
                st.check_samples
            ),
        ));
    }
    Ok((st.method == PlanStabilityMethod::QuasiStaticGe).then_some(o))
}

/// Most schedule samples checked by the GE QEP.
pub const MAX_GE_CHECK_SAMPLES: usize = 2000;
/// Re-plans with a lowered GE criterion after a failed check.
pub const MAX_GE_TIGHTENINGS: usize = 3;

/// Samples checked by the GE QEP.
pub(super) fn ge_check_count(req: &PlanRequest) -> usize {
    req.stability.as_ref().map_or(2, |s| s.check_samples)
}

/// The GE check of a schedule, when the criterion is the GE one and its
/// table was made.
pub(super) fn ge_check_of(air: &Air, s: &Schedule, count: usize) -> Option<ge_plan::ScheduleCheck> {
    let Air::Wind(w) = air else { return None };
    let (_, gm) = w.ge.as_ref()?.made_table()?;
    Some(ge_plan::check_samples(gm, &s.samples(count)))
}

/// The binding limit of a failed GE check: its worst failing sample.
pub(super) fn ge_binding(chk: &ge_plan::ScheduleCheck) -> BindingLimit {
    let bad = chk
        .samples
        .iter()
        .filter(|c| !c.ok)
        .max_by(|a, b| a.max_real_1_s.total_cmp(&b.max_real_1_s))
        .copied();
    match bad {
        Some(c) => BindingLimit::QuasiStaticGeCheck {
            time_s: c.time_s,
            length_m: c.kinematics.length_m,
            rate_m_s: c.kinematics.rate_m_s,
            max_real_1_s: c.max_real_1_s,
        },
        None => BindingLimit::QuasiStaticGeCheck {
            time_s: f64::NAN,
            length_m: f64::NAN,
            rate_m_s: f64::NAN,
            max_real_1_s: f64::NAN,
        },
    }
}

/// The GE block of the answer.
pub(super) fn ge_output(
    p: &PlanProblem,
    air: &Air,
    chk: Option<&ge_plan::ScheduleCheck>,
    tightenings: usize,
) -> Option<PlanGeStabilityOutput> {
    let Air::Wind(w) = air else { return None };
    let ge = w.ge.as_ref()?;
    let (t, _) = ge.made_table()?;
    let rho_a = p.system.mass_per_length_kg_m;
    let margin = STABILITY_MARGIN * p.reserve_buoyancy_n();
    Some(PlanGeStabilityOutput {
        bending_stiffness_n_m2: ge.options.bending_stiffness_n_m2,
        elements: ge.options.elements,
        converged: ge.options.converge.is_some(),
        relative_tolerance_nondim: ge.options.converge.map(|c| c.relative_tolerance),
        max_safe_length_m: t.max_safe_length_m,
        max_safe_length_error_m: t.max_safe_length_error_m,
        rate_cap_m_s: t.rate_cap_m_s,
        interpolation_error_n: t.interpolation_error_n,
        interpolation_error_length_m: t.interpolation_error_n / (rho_a * p.system.gravity_m_s2),
        interpolation_error_all_lengths_n: t.interpolation_error_all_lengths_n,
        table: t
            .rows
            .iter()
            .enumerate()
            .map(|(i, r)| PlanGeTableRowOutput {
                length_m: r.length_m,
                critical_rate_m_s: r.critical_rate_m_s,
                capped: r.capped,
                unstable: r.unstable,
                critical_rate_error_m_s: t.rate_error_m_s.get(i).copied(),
                plan_rate_ceiling_m_s: w
                    .ascent_drag(r.length_m)
                    .ceiling_m_s(rho_a, w.stability_tension_n(p, r.length_m) - margin),
                string_critical_rate_m_s: string_onset::critical_rate_m_s(
                    &w.problem(&p.system, p.reserve_buoyancy_n(), r.length_m),
                    &EquilibriumConfig::default(),
                )
                .ok()
                .flatten(),
            })
            .collect(),
        check: chk.map(|c| PlanGeCheckOutput {
            checked_samples: c.samples.len(),
            unstable_samples: c.failed,
            worst_max_real_1_s: c.worst.map(|x| x.max_real_1_s),
            worst_tolerance_1_s: c.worst.map(|x| x.tolerance_1_s),
            worst_time_s: c.worst.map(|x| x.time_s),
            worst_length_m: c.worst.map(|x| x.kinematics.length_m),
            worst_rate_m_s: c.worst.map(|x| x.kinematics.rate_m_s),
            worst_acceleration_m_s2: c.worst.map(|x| x.kinematics.acceleration_m_s2),
        }),
        tightening_steps: tightenings,
        offset_n: ge.offset_n,
        qep_solves: t.qep_solves,
        equilibrium_solves: t.equilibria,
    })
}
