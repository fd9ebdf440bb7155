//! The plan's answer pieces: the schedule sampled with its loads (in the
//! mean wind and, with gusts, in the gust), the phases, the transient
//! check and the method as stated in the answer.

use crate::contract::plan::dto::*;
use crate::contract::plan::ge::CALM_GE_MATERIAL_DENSITY_KG_M3;
use crate::numerics::plan::PlanProblem;
use crate::numerics::plan::air::Air;
use crate::numerics::plan::ge_stability as ge_plan;
use crate::numerics::plan::retrieval::TransientCheck;
use crate::numerics::plan::schedule::{PlanOptions, Schedule};
use crate::numerics::string::transient::RunOutcome;

pub(super) fn outcome_name(o: &RunOutcome) -> &'static str {
    match o {
        RunOutcome::Completed => "completed",
        RunOutcome::Diverged { .. } => "diverged",
        RunOutcome::LengthCollapsed { .. } => "length_collapsed",
        RunOutcome::Cancelled { .. } => "cancelled",
    }
}

pub(super) fn check_output(c: &TransientCheck) -> TransientCheckOutput {
    TransientCheckOutput {
        elements: c.elements,
        time_step_s: c.time_step_s,
        steps: c.steps,
        run_duration_s: c.run_duration_s,
        initial_tip_deflection_m: c.initial_tip_deflection_m,
        peak_tip_deflection_m: c.peak_tip_deflection_m,
        final_tip_amplitude_m: c.final_tip_amplitude_m,
        amplification_nondim: c.amplification,
        outcome: outcome_name(&c.outcome).into(),
    }
}

pub(super) fn samples_output(
    p: &PlanProblem,
    air: &Air,
    s: &Schedule,
    count: usize,
) -> Vec<PlanSampleOutput> {
    if !air.is_calm() {
        return wind_samples_output(p, air, s, count);
    }
    s.samples(count)
        .into_iter()
        .map(|(t, k)| {
            let ceiling = p.rate_ceiling_m_s(k.length_m, k.acceleration_m_s2);
            PlanSampleOutput {
                time_s: t,
                length_m: k.length_m,
                altitude_m: k.length_m,
                rate_m_s: k.rate_m_s,
                acceleration_m_s2: k.acceleration_m_s2,
                winch_tension_n: p.winch_tension_n(k.length_m, k.acceleration_m_s2),
                max_tension_n: p.max_tension_n(k.length_m, k.acceleration_m_s2),
                rate_ceiling_m_s: ceiling,
                stability_margin_m_s: ceiling - k.rate_m_s.abs(),
                effective_tension_margin_n: p.effective_tension_n(
                    k.length_m,
                    k.rate_m_s,
                    k.acceleration_m_s2,
                ),
                gust_altitude_m: None,
                gust_winch_tension_n: None,
                gust_max_tension_n: None,
            }
        })
        .collect()
}

/// Samples with the loads of the steady-wind equilibrium at each length.
pub(super) fn wind_samples_output(
    p: &PlanProblem,
    air: &Air,
    s: &Schedule,
    count: usize,
) -> Vec<PlanSampleOutput> {
    let sy = &p.system;
    let samples = s.samples(count);
    let lengths: Vec<f64> = samples.iter().map(|(_, k)| k.length_m).collect();
    samples
        .into_iter()
        .zip(air.rest_loads_at(p, &lengths))
        .map(|((t, k), (r, g))| {
            let (l, a) = (k.length_m, k.acceleration_m_s2);
            let ceiling = r.rate_ceiling_m_s(sy, l, a);
            PlanSampleOutput {
                time_s: t,
                length_m: l,
                altitude_m: r.altitude_m,
                rate_m_s: k.rate_m_s,
                acceleration_m_s2: a,
                winch_tension_n: r.winch_tension_at_n(sy, l, a),
                max_tension_n: r.max_tension_at_n(sy, l, a),
                rate_ceiling_m_s: ceiling,
                stability_margin_m_s: ceiling - k.rate_m_s.abs(),
                effective_tension_margin_n: r.effective_tension_n(sy, l, k.rate_m_s, a),
                gust_altitude_m: g.map(|g| g.altitude_m),
                gust_winch_tension_n: g.map(|g| g.winch_tension_at_n(sy, l, a)),
                gust_max_tension_n: g.map(|g| g.max_tension_at_n(sy, l, a)),
            }
        })
        .collect()
}

/// Largest `|ΔL̈/Δt|` between consecutive knots and inside them (m/s³).
pub(super) fn peak_jerk(s: &Schedule) -> f64 {
    s.knots
        .iter()
        .map(|k| k.jerk_m_s3.abs())
        .fold(0.0, f64::max)
}

pub(super) fn phases_output(s: &Schedule) -> Vec<PlanPhaseOutput> {
    s.phases()
        .into_iter()
        .map(|ph| {
            let dt = ph.end.time_s - ph.start.time_s;
            PlanPhaseOutput {
                start_time_s: ph.start.time_s,
                end_time_s: ph.end.time_s,
                start_length_m: ph.start.length_m,
                end_length_m: ph.end.length_m,
                start_rate_m_s: ph.start.rate_m_s,
                end_rate_m_s: ph.end.rate_m_s,
                mean_acceleration_m_s2: if dt > 0.0 {
                    (ph.end.rate_m_s - ph.start.rate_m_s) / dt
                } else {
                    0.0
                },
                limit: ph.limit.name().into(),
                instruction: ph.limit.instruction().into(),
            }
        })
        .collect()
}

const METHOD: &str = "Time-optimal speed-profile pass along the length (forward/backward, as in time-optimal \
path planning): constant acceleration on each of 4000 length segments; a backward pass from rest at the target \
gives the largest viable rate at each length (a two-variable LP per segment), a forward pass from rest takes the \
largest admissible acceleration. Constraints at both ends of every segment (hence on all of it, since they are \
linear in length there): winch rate and acceleration, the tension rating on the largest axial tension F − mL̈, and \
stability with the lift reserve r in its converged continuum form (the FE critical length converges to it from \
above, SPEC §5): effective roller tension (1−r)F − mL̈ − ρA(g+L̈)L − ρA L̇² ≥ ε(1−r)F with ε = 1e-3. The schedule \
is then run on the FE string (Newmark, first-mode disturbance) and the oscillation growth compared with WKB \
(thesis (3.12)).";

/// The method, with the jerk limit and the wind criterion when they apply.
pub(super) fn method(opts: &PlanOptions) -> String {
    let mut m = METHOD.to_string();
    if opts.max_jerk_m_s3.is_some() {
        m.push_str(
            " Jerk limit: the schedule's velocity is averaged over a sliding window τ, the smallest with \
             |L̈(t) − L̈(t−τ)| ≤ j τ (so |dL̈/dt| ≤ j; for the winch trapezoid this is the classical 7-segment \
             S-curve, duration D/v + v/a + a/j), then checked against every limit at its knots and inside its \
             intervals; while it falls short the pass is rerun with a larger stability margin (and a lower \
             allowable tension).",
        );
    }
    if let Air::Wind(w) = &opts.air {
        m.push_str(&format!(
            " Wind: target_elevation_m is the altitude in this wind (the tether length that flies there is found \
             by bisection on the equilibrium altitude); the tensions are those of the steady-wind equilibrium \
             (winch and aerostat, full buoyancy) less the inertia of the payout; stability: {}. The transient \
             check runs the schedule on the calm-air string.",
            w.criterion_name
        ));
        if let Some(ge) = &w.ge {
            m.push_str(&format!(
                " Quasi-static GE: {} elements for the critical-rate table ({} lengths, each by a scan of {} rates \
                 and {} bisections, divergence by the inertia of the stiffness) and the divergence check, {} \
                 elements for the QEP (flutter) check of the samples; a failed check lowers S by 2 %, 8 %, 32 % of \
                 (1−r)F and re-plans. Without wind the GE criterion runs on the straight tether in still air, the \
                 tether diameter (for its rotary inertia ρA d²/16) from ρA at {} kg/m³.",
                ge.options.elements,
                ge.options.table_lengths,
                ge_plan::SCAN_POINTS,
                ge_plan::BISECTIONS,
                ge.options.check_elements,
                CALM_GE_MATERIAL_DENSITY_KG_M3
            ));
        }
    }
    m
}
