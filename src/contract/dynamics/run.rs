//! One dynamic run through the contract: the static start, the march with
//! progress and cancellation, and the answer beside the quasi-static one
//! at the same wind.

use super::dto::*;
use super::validate::Prepared;
use crate::contract::{Progress, RequestError};
use crate::numerics::aero::SteadyFlow;
use crate::numerics::dynamics::limits::step_count;
use crate::numerics::dynamics::{
    DynamicsConfig, DynamicsError, DynamicsProblem, ENERGY_ALLOWANCE, ENERGY_FLOOR, Outcome, Run,
    StepView, simulate_from, static_start,
};
use crate::numerics::params::InvalidInput;
use crate::numerics::tether::{Equilibrium, EquilibriumConfig, WindProfile};

/// Points of the tabulated flow that stands for a sheared flow plus a
/// uniform change (quadratic spacing: dense near the ground).
const SHIFTED_FLOW_POINTS: usize = 400;

/// Steps between progress reports and cancellation checks.
const REPORT_EVERY: usize = 64;

impl From<DynamicsError> for RequestError {
    fn from(e: DynamicsError) -> Self {
        match e {
            DynamicsError::Invalid(i) => i.into(),
            DynamicsError::SlackStart => InvalidInput::new(
                "wind.flow",
                "leaves the tether slack at the start (part of it rests on the ground): the dynamic model starts from a taut static equilibrium; give less wind, more lift or a shorter tether",
            )
            .into(),
            DynamicsError::NoStaticEquilibrium { residual_n } => InvalidInput::new(
                "tether_length_m",
                format!(
                    "no static equilibrium of the lumped tether was found to start from (force left {residual_n:.3e} N); try more segments"
                ),
            )
            .into(),
        }
    }
}

/// `flow` with `change` added at every height: the same flow for a
/// uniform one, else a table up to `top_m` (linear between points;
/// quadratic spacing keeps a log law's ground layer).
pub fn shifted_flow(flow: &WindProfile, change: f64, top_m: f64) -> WindProfile {
    if let WindProfile::Flow(SteadyFlow::Uniform { speed_m_s }) = flow {
        return WindProfile::uniform(speed_m_s + change);
    }
    if change == 0.0 {
        return flow.clone();
    }
    let n = SHIFTED_FLOW_POINTS;
    let (elevations_m, speeds_m_s): (Vec<f64>, Vec<f64>) = (0..=n)
        .map(|k| {
            let z = top_m * (k as f64 / n as f64).powi(2);
            (z, flow.speed_m_s(z) + change)
        })
        .unzip();
    WindProfile::Flow(SteadyFlow::Tabulated {
        elevations_m,
        speeds_m_s,
    })
}

/// The §6 equilibrium of `problem` at `length_m` with the flow changed by
/// `change` (None: none found).
pub fn equilibrium_at(
    problem: &DynamicsProblem,
    length_m: f64,
    change: f64,
    segments: usize,
) -> Option<Equilibrium> {
    let mut eq = problem.static_problem(length_m);
    eq.wind = shifted_flow(&problem.flow, change, 1.5 * length_m + 10.0);
    eq.solve(&EquilibriumConfig {
        steps: segments.max(100),
        max_iterations: 60,
        keep_shape: false,
    })
    .ok()
}

/// A run, its configuration and steps, and the force its static start left (N).
pub struct Ran {
    pub run: Run,
    pub config: DynamicsConfig,
    pub steps: usize,
    pub start_residual_n: f64,
}

/// Runs a prepared problem from its static start, reporting steps done.
pub fn run_prepared(prepared: &Prepared, progress: &dyn Progress) -> Result<Ran, RequestError> {
    run_with(
        prepared,
        prepared.config.clone(),
        progress,
        0,
        prepared.steps,
    )
}

/// Runs `config` on the prepared problem from its static start; progress
/// counts `done_before` steps already made of `total`.
pub fn run_with(
    prepared: &Prepared,
    config: DynamicsConfig,
    progress: &dyn Progress,
    done_before: usize,
    total: usize,
) -> Result<Ran, RequestError> {
    let p = &prepared.problem;
    if progress.cancelled() {
        return Err(RequestError::Cancelled);
    }
    let start = static_start(p, config.segments)?;
    let start_residual_n = start.residual_n;
    let steps = step_count(config.duration_s, config.time_step_s) as usize;
    let mut done = 0usize;
    let mut observer = |_: &StepView| {
        done += 1;
        if done.is_multiple_of(REPORT_EVERY) {
            progress.report((done_before + done).min(total), total);
            return !progress.cancelled();
        }
        true
    };
    let run = simulate_from(p, &config, start.state, start.equilibrium, &mut observer)?;
    if let Outcome::Stopped { .. } = run.outcome {
        return Err(RequestError::Cancelled);
    }
    progress.report((done_before + steps).min(total), total);
    Ok(Ran {
        run,
        config,
        steps,
        start_residual_n,
    })
}

/// The largest and smallest wind change of the run (m/s).
fn wind_change_range(problem: &DynamicsProblem, run: &Run, duration_s: f64) -> (f64, f64) {
    let (mut hi, mut lo) = (0.0f64, 0.0f64);
    for g in &problem.gusts {
        let (h, l) = g.range_m_s(duration_s);
        hi += h;
        lo += l;
    }
    if problem.turbulence.is_some() {
        for s in &run.samples {
            let d = s.aerostat_wind_m_s - problem.flow.speed_m_s(s.aerostat_altitude_m);
            hi = hi.max(d);
            lo = lo.min(d);
        }
    }
    (hi, lo)
}

/// The answer of a run, with its converged figures.
pub fn response(
    req: &DynamicsRequest,
    prepared: &Prepared,
    ran: &Ran,
    converged: DynamicsConvergedOutput,
) -> DynamicsResponse {
    let run = &ran.run;
    let p = &prepared.problem;
    let c = &ran.config;
    let (max_change, min_change) = wind_change_range(p, run, c.duration_s);
    let at_max = equilibrium_at(
        p,
        p.length.at(run.peak_winch_tension.time_s).length_m,
        max_change,
        c.segments,
    );
    let at_min = equilibrium_at(
        p,
        p.length.at(run.min_winch_tension.time_s).length_m,
        min_change,
        c.segments,
    );
    let (outcome, stopped_at_s) = match run.outcome {
        Outcome::Completed | Outcome::Stopped { .. } => {
            (DynamicsOutcomeOutput::Completed, run.final_state.time_s)
        }
        Outcome::NewtonFailed { time_s } => (DynamicsOutcomeOutput::NewtonFailed, time_s),
        Outcome::Diverged { time_s } => (DynamicsOutcomeOutput::Diverged, time_s),
        Outcome::AerostatBelowWinch { time_s, .. } => {
            (DynamicsOutcomeOutput::AerostatBelowWinch, time_s)
        }
        Outcome::EnergyGained { time_s, .. } => (DynamicsOutcomeOutput::EnergyGained, time_s),
    };
    // A run that did not complete gives no final figure.
    let partial = outcome != DynamicsOutcomeOutput::Completed;
    let peak = run.peak_winch_tension.value;
    // The factors an operator acts on: from the safe side of the peaks.
    let safe_peak = converged.peak_winch_tension_n.safe_value;
    let dynamic_factor = at_max
        .as_ref()
        .filter(|e| e.winch_tension_n > 0.0 && !partial)
        .map(|e| safe_peak / e.winch_tension_n);
    let safety = prepared
        .breaking_strength_n
        .filter(|_| !partial)
        .map(|b| b / converged.peak_tension_n.safe_value);
    let min_altitude = run.min_aerostat_altitude.value;
    let params = p.parameters(c.segments);
    let quasi_static = QuasiStaticOutput {
        start_winch_tension_n: run
            .samples
            .first()
            .map_or(run.equilibrium.winch_tension_n, |s| s.winch_tension_n),
        start_aerostat_altitude_m: run
            .samples
            .first()
            .map_or(run.equilibrium.altitude_m, |s| s.aerostat_altitude_m),
        continuum_start_winch_tension_n: run.equilibrium.winch_tension_n,
        max_wind_change_m_s: max_change,
        min_wind_change_m_s: min_change,
        winch_tension_at_max_wind_n: at_max.as_ref().map(|e| e.winch_tension_n),
        max_tension_at_max_wind_n: at_max.as_ref().map(|e| e.max_tension_n),
        aerostat_altitude_at_max_wind_m: at_max.as_ref().map(|e| e.altitude_m),
        winch_tension_at_min_wind_n: at_min.as_ref().map(|e| e.winch_tension_n),
        slack_at_min_wind: at_min.as_ref().map(|e| e.slack),
    };
    let explanation = explain(run, &quasi_static, dynamic_factor, outcome, stopped_at_s);
    DynamicsResponse {
        outcome,
        stopped_at_s,
        figures_partial: partial,
        samples: run
            .samples
            .iter()
            .map(|s| DynamicsSampleOutput {
                time_s: s.time_s,
                winch_tension_n: s.winch_tension_n,
                top_tension_n: s.top_tension_n,
                aerostat_altitude_m: s.aerostat_altitude_m,
                aerostat_downwind_m: s.aerostat_downwind_m,
                tether_length_m: s.length_m,
                aerostat_wind_m_s: s.aerostat_wind_m_s,
                probe_wind_m_s: s.probe_wind_m_s,
            })
            .collect(),
        shapes: run
            .shapes
            .iter()
            .map(|s| DynamicsShapeOutput {
                time_s: s.time_s,
                nodes: s
                    .nodes
                    .iter()
                    .map(|n| DynamicsShapeNodeOutput {
                        s_m: n.s_m,
                        x_m: n.x_m,
                        z_m: n.z_m,
                        tension_n: n.tension_n,
                    })
                    .collect(),
            })
            .collect(),
        slack_events: run
            .slack_events
            .iter()
            .map(|e| SlackEventOutput {
                start_time_s: e.start_s,
                end_time_s: e.end_s,
                lowest_s_m: e.lowest_s_m,
            })
            .collect(),
        peak_winch_tension_n: peak,
        peak_winch_tension_time_s: run.peak_winch_tension.time_s,
        min_winch_tension_n: run.min_winch_tension.value,
        min_winch_tension_time_s: run.min_winch_tension.time_s,
        peak_tension_n: run.peak_tension.value,
        peak_tension_time_s: run.peak_tension.time_s,
        min_aerostat_altitude_m: min_altitude,
        wind_probe_height_m: run.wind_probe[1],
        wind_probe_downwind_m: run.wind_probe[0],
        quasi_static,
        converged,
        dynamic_factor_nondim: dynamic_factor,
        safety_factor_nondim: safety,
        required_safety_factor_nondim: req.required_safety_factor_nondim,
        meets_required_safety_factor: safety.map(|f| f >= req.required_safety_factor_nondim),
        explanation,
        numerics: DynamicsNumericsOutput {
            segments: c.segments,
            time_step_s: c.duration_s / ran.steps as f64,
            spectral_radius_nondim: c.spectral_radius,
            steps: run.statistics.steps,
            newton_iterations: run.statistics.newton_iterations,
            halvings: run.statistics.halvings,
            axial_stiffness_n: p.tether.axial_stiffness_n,
            aerostat_inertia_kg: params.aerostat_inertia_kg,
            start_residual_n: ran.start_residual_n,
            method: "generalized_alpha".into(),
        },
    }
}

fn explain(
    run: &Run,
    qs: &QuasiStaticOutput,
    factor: Option<f64>,
    outcome: DynamicsOutcomeOutput,
    stopped_at_s: f64,
) -> String {
    let mut s = String::new();
    if outcome != DynamicsOutcomeOutput::Completed {
        s.push_str(&format!(
            "The run did not complete (it stopped at t = {stopped_at_s:.2} s, reason below): the figures cover 0–{stopped_at_s:.2} s only and are not final; no dynamic or safety factor is given. "
        ));
    }
    s.push_str(&format!(
        "From rest at {:.1} N winch tension, the winch tension peaked at {:.1} N (t = {:.2} s) and fell to {:.1} N (t = {:.2} s).",
        qs.start_winch_tension_n,
        run.peak_winch_tension.value,
        run.peak_winch_tension.time_s,
        run.min_winch_tension.value,
        run.min_winch_tension.time_s
    ));
    match (qs.winch_tension_at_max_wind_n, factor) {
        (Some(t), Some(f)) => s.push_str(&format!(
            " The static tension at the largest wind ({:+.2} m/s) is {t:.1} N: the dynamic peak is {f:.3} times it.",
            qs.max_wind_change_m_s
        )),
        (Some(_), None) => {}
        _ => s.push_str(" No static equilibrium was found at the largest wind."),
    }
    if !run.slack_events.is_empty() {
        s.push_str(&format!(
            " The tether went slack {} time(s), first at t = {:.2} s.",
            run.slack_events.len(),
            run.slack_events[0].start_s
        ));
    }
    match outcome {
        DynamicsOutcomeOutput::Completed => {}
        DynamicsOutcomeOutput::NewtonFailed => s.push_str(&format!(
            " The run stopped at t = {stopped_at_s:.2} s: the implicit step did not converge even after halving (try a smaller numerics.time_step_s)."
        )),
        DynamicsOutcomeOutput::Diverged => s.push_str(&format!(
            " The run stopped at t = {stopped_at_s:.2} s: the state became non-finite."
        )),
        DynamicsOutcomeOutput::AerostatBelowWinch => s.push_str(&format!(
            " The run stopped at t = {stopped_at_s:.2} s: the aerostat went below the winch, which no real tether does (the model has no ground); the state left the physical."
        )),
        DynamicsOutcomeOutput::EnergyGained => {
            if let Outcome::EnergyGained {
                gained_j, put_in_j, ..
            } = run.outcome
            {
                s.push_str(&format!(
                    " The run stopped at t = {stopped_at_s:.2} s: the tether and aerostat held {gained_j:.4e} J more mechanical energy than at the start plus the most the winch and the air could have put in ({put_in_j:.4e} J), past the allowance of {:.0} % of that plus {:.0} % of the buoyancy's work down to the winch; the step made energy, so the state left the physical (try a smaller numerics.time_step_s).",
                    100.0 * ENERGY_ALLOWANCE,
                    100.0 * ENERGY_FLOOR
                ));
            }
        }
    }
    s
}
