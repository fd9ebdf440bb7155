//! One run: from a start state, step by step, outputs recorded and an
//! observer told after every accepted step ([`simulate_from`]); from the
//! static start ([`simulate`]).

use super::blocks::{V2, norm};
use super::integrator::{Air, Alpha, Stepper};
use super::limits;
use super::model::{Evaluation, Length, Parameters};
use super::outputs::{Extreme, Recorder, Sample, Shape, SlackEvent};
use super::problem::{DynamicsConfig, DynamicsError, DynamicsProblem, validate_config};
use super::start::static_start;
pub use super::state::{Outcome, State, Statistics};
use super::wind::{self, TurbulenceField};
use crate::numerics::params::InvalidInput;
use crate::numerics::tether::equilibrium::Equilibrium;

/// The answer of a run.
#[derive(Clone, Debug, PartialEq)]
pub struct Run {
    pub outcome: Outcome,
    /// The §6 equilibrium of the steady flow at the initial length.
    pub equilibrium: Equilibrium,
    pub samples: Vec<Sample>,
    pub shapes: Vec<Shape>,
    pub slack_events: Vec<SlackEvent>,
    pub peak_winch_tension: Extreme,
    pub min_winch_tension: Extreme,
    /// Largest segment tension anywhere (N).
    pub peak_tension: Extreme,
    /// Lowest aerostat altitude at any step (m).
    pub min_aerostat_altitude: Extreme,
    pub final_state: State,
    pub statistics: Statistics,
    /// The fixed point `(x, z)` where [`Sample::probe_wind_m_s`] is read (m).
    pub wind_probe: V2,
}

/// What an observer sees after every accepted step.
pub struct StepView<'a> {
    pub time_s: f64,
    pub length: Length,
    pub positions: &'a [V2],
    pub velocities: &'a [V2],
    pub evaluation: &'a Evaluation,
    pub parameters: &'a Parameters,
}

/// Runs from the static start.
pub fn simulate(problem: &DynamicsProblem, config: &DynamicsConfig) -> Result<Run, DynamicsError> {
    let start = static_start(problem, config.segments)?;
    simulate_from(problem, config, start.state, start.equilibrium, &mut |_| {
        true
    })
}

/// Runs from `state` (at `state.time_s`); `observer` sees every accepted
/// step and stops the run by returning `false`.
pub fn simulate_from(
    problem: &DynamicsProblem,
    config: &DynamicsConfig,
    state: State,
    equilibrium: Equilibrium,
    observer: &mut dyn FnMut(&StepView) -> bool,
) -> Result<Run, DynamicsError> {
    problem.validate()?;
    validate_config(config)?;
    let n = config.segments;
    if state.positions.len() != n || state.velocities.len() != n {
        return Err(InvalidInput::new("segments", "the state does not match the mesh").into());
    }
    let field = match &problem.turbulence {
        Some(t) => {
            let top = problem.length.longest_m(config.duration_s) * 1.2;
            let len0 = problem.length.at(0.0).length_m;
            let z_top = state.positions[n - 1][1].max(0.5 * len0);
            let uc = problem.flow.speed_m_s(z_top).abs();
            let levels = ((top / config.turbulence_level_spacing_m).ceil() as usize + 1).max(4);
            let grid = wind::FieldGrid {
                time_step_s: config.turbulence_time_step_s,
                period_s: config.duration_s + 2.0 * top / uc.max(1e-6) + 10.0,
                top_m: top,
                levels,
                convection_m_s: uc,
            };
            Some(TurbulenceField::synthesise(t, &problem.flow, &grid)?)
        }
        None => None,
    };
    let air = Air {
        flow: &problem.flow,
        gusts: &problem.gusts,
        field,
    };
    let mut st = Stepper::new(
        problem.parameters(n),
        Alpha::new(config.spectral_radius),
        &problem.length,
        &air,
        config.newton_tolerance_m_s,
        config.max_newton_iterations,
        state.positions,
        state.velocities,
        state.time_s,
    );
    st.initial_acceleration();

    let steps = limits::step_count(config.duration_s, config.time_step_s) as usize;
    let h = config.duration_s / steps as f64;
    let start_top = st.x[n - 1];
    let wind_probe = [
        start_top[0],
        config.wind_probe_height_m.unwrap_or(start_top[1]),
    ];
    let mut rec = Recorder::new(
        st.t,
        config.sample_interval_s,
        &config.shape_times_s,
        h,
        wind_probe,
    );
    let mut outcome = Outcome::Completed;

    // The initial evaluation (by `initial_acceleration`) is of the start state.
    rec.record(
        st.t,
        st.schedule.at(st.t),
        &st.x,
        &st.ev,
        &air.at(st.t),
        false,
    );
    let t0 = st.t;
    // Where the winch rate or acceleration jumps: stepped onto exactly.
    let breaks = problem.length.breakpoints_s(t0 + config.duration_s);
    let mut next_break = breaks.partition_point(|&b| b <= t0 + 1e-9 * h);
    // A sub-step shorter than this is not taken: the jump is moved onto
    // the grid (the velocity jump is applied exactly either way).
    let shortest = 1e-6 * h;
    'steps: for i in 0..steps {
        let t_end = t0 + (i + 1) as f64 * h;
        loop {
            let brk = breaks
                .get(next_break)
                .copied()
                .filter(|&b| b <= t_end + shortest);
            let target = match brk {
                Some(b) if b < t_end - shortest => b,
                _ => t_end,
            };
            if target - st.t > shortest {
                if !st.step(target - st.t, 0) {
                    outcome = Outcome::NewtonFailed { time_s: st.t };
                    break 'steps;
                }
                st.t = target;
                if let Some(o) = unphysical(&st.x, st.t) {
                    outcome = o;
                    break 'steps;
                }
            }
            match brk {
                Some(b) => {
                    st.rate_jump(problem.length.rate_before_m_s(b));
                    next_break += 1;
                    if target < t_end {
                        // Every state the run passes through is checked.
                        rec.record(
                            st.t,
                            st.schedule.at(st.t),
                            &st.x,
                            &st.ev,
                            &air.at(st.t),
                            false,
                        );
                        continue;
                    }
                }
                None => {}
            }
            break;
        }
        // Outputs from the state at the step's end.
        st.evaluate_current();
        let length = st.schedule.at(st.t);
        rec.record(st.t, length, &st.x, &st.ev, &air.at(st.t), i + 1 == steps);
        let view = StepView {
            time_s: st.t,
            length,
            positions: &st.x,
            velocities: &st.v,
            evaluation: &st.ev,
            parameters: &st.p,
        };
        if !observer(&view) {
            outcome = Outcome::Stopped { time_s: st.t };
            break;
        }
    }
    Ok(Run {
        outcome,
        equilibrium,
        samples: rec.samples,
        shapes: rec.shapes,
        slack_events: rec.slack_events,
        peak_winch_tension: rec.peak_winch,
        min_winch_tension: rec.min_winch,
        peak_tension: rec.peak,
        min_aerostat_altitude: rec.min_altitude,
        statistics: st.stats,
        wind_probe,
        final_state: State {
            time_s: st.t,
            positions: st.x,
            velocities: st.v,
        },
    })
}

/// The aerostat's position as a vector (for observers).
pub fn aerostat(view: &StepView) -> V2 {
    view.positions[view.positions.len() - 1]
}

/// `|a|` re-exported for tests.
pub fn magnitude(v: V2) -> f64 {
    norm(v)
}

/// Whether the state has left the physical: a non-finite position, or the
/// aerostat below the winch (the model has no ground).
fn unphysical(x: &[V2], t: f64) -> Option<Outcome> {
    if x.iter().any(|r| !(r[0].is_finite() && r[1].is_finite())) {
        return Some(Outcome::Diverged { time_s: t });
    }
    let top = x[x.len() - 1];
    (top[1] < 0.0).then_some(Outcome::AerostatBelowWinch {
        time_s: t,
        altitude_m: top[1],
    })
}
