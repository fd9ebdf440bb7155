//! Converged figures of a dynamics request (SPEC §5, §11; issue 31 item
//! 2): the peak and minimum winch tension, the peak tension anywhere and
//! the lowest aerostat altitude, each with an error estimate and its safe
//! side ([`crate::numerics::dynamics::converged`] says why the estimate is
//! what it is).
//!
//! **Default** (the request gives neither `numerics.segments` nor
//! `numerics.time_step_s`): runs at 0.2, 0.1, 0.05 s (a quarter of the
//! shortest gust or sinusoid period at most), stopping at the first whose
//! figures changed by at most the tolerance (default 1 % of their scale)
//! from the run before; then one run at half the segments at that step.
//! A damped tether (`internal_damping_n_s` > 0) whose winch changes its
//! rate or acceleration in the run goes on halving below 0.05 s, down to a
//! 32nd of its first axial period at the shortest length
//! ([`super::validate::MAX_EXTRA_LEVELS`] rungs at most): a 2 s ramp rings
//! axial waves the default steps do not resolve (the §10 tether paid out
//! 200 → 400 m, damped by 1e4 N s: 959.7, 883.0, 925.1, 931.1, 932.4,
//! 932.5 N from 0.05 s down to 0.0016 s). It answers only at its finest
//! rung, where the waves are resolved: above it, agreement can be by
//! chance.
//! The answer is that step's run; each figure's error estimate is its
//! change from the run at twice the step plus its change from the run at
//! half the segments. When the finest default step still changes by more
//! than the tolerance (measured: a slack tether snapping taut after an
//! abrupt winch stop, whose peaks change by 5–30 % at every halving down
//! to 0.4 ms), or the segments do, the request is refused naming
//! `numerics`, with the changes in the reason and the cause found in the
//! finest run: a slack tether that snapped taut (an instantaneous stop has
//! no converged peak: give the winch its deceleration), or axial waves the
//! default steps do not resolve (the step they need is named): no figure
//! is handed out as converged that is not.
//!
//! **Fixed** (the request gives either): that discretisation's run is the
//! answer, the run at twice its step and the one at half its segments
//! give the estimate, and `tolerance_enforced` is false.

use super::dto::*;
use super::run::{Ran, response, run_with};
use super::validate::{AXIAL_STEPS_PER_PERIOD, Prepared};
use crate::contract::{Progress, RequestError};
use crate::numerics::dynamics::converged::{
    Estimated, FIGURES, Figures, NAMES, changes, estimate, observed_order, within,
};
use crate::numerics::dynamics::{DynamicsConfig, Outcome};
use crate::numerics::params::InvalidInput;

fn level(ran: &Ran) -> RefinementOutput {
    let f = Figures::of(&ran.run);
    RefinementOutput {
        time_step_s: ran.config.duration_s / ran.steps as f64,
        segments: ran.config.segments,
        completed: ran.run.outcome == Outcome::Completed,
        peak_winch_tension_n: f.values[0],
        min_winch_tension_n: f.values[1],
        peak_tension_n: f.values[2],
        min_aerostat_altitude_m: f.values[3],
    }
}

fn output(e: Estimated) -> EstimatedFigureOutput {
    EstimatedFigureOutput {
        value: e.value,
        error_estimate: e.error_estimate,
        safe_value: e.safe_value,
        time_s: e.time_s,
    }
}

/// The runs' figures as words, for a refusal.
fn ladder_words(runs: &[(f64, usize, Figures)]) -> String {
    let mut s = String::new();
    for (i, name) in NAMES.iter().enumerate() {
        let values: Vec<String> = runs
            .iter()
            .map(|(h, n, f)| format!("{:.1} ({h} s, {n} segments)", f.values[i]))
            .collect();
        s.push_str(&format!("{name}: {}; ", values.join(" → ")));
    }
    s.trim_end_matches("; ").to_string()
}

/// Answers one dynamics request: its converged figures and the answer's
/// run, the account of both in its explanation.
pub fn dynamics(
    req: &DynamicsRequest,
    progress: &dyn Progress,
) -> Result<DynamicsResponse, RequestError> {
    let prepared = req.prepare()?;
    let (ran, converged) = run_converged(&prepared, progress)?;
    let words = explain(&converged);
    let mut answer = response(req, &prepared, &ran, converged);
    answer.explanation.push(' ');
    answer.explanation.push_str(&words);
    Ok(answer)
}

/// Why the default ladder's figures did not converge, from the finest
/// run (see the module docs): a slack tether that snapped taut, or the
/// tether's axial waves (first period `4L/c`, `c = √(EA/ρA)`, shortest at
/// the shortest length), rung by the winch's changes of rate or
/// acceleration, at steps too long for them. Measured on the §10 tether
/// paid out 200 → 1000 m with 2 s ramps in calm air: with
/// `internal_damping_n_s` 1e4 the peak winch tension is 932.13 and
/// 932.50 N at 0.0044 and 0.0022 s (a 16th and a 32nd of the period at
/// 200 m, 0.0707 s), against 959.7, 883.0, 925.1 N at 0.05, 0.025,
/// 0.0125 s; without damping it still changes by 1.1 % at 0.00625 s.
fn unconverged_cause(prepared: &Prepared, run: &crate::numerics::dynamics::Run) -> String {
    let tether = &prepared.problem.tether;
    let until = prepared.config.duration_s;
    let shortest = prepared.problem.length.shortest_m(until);
    let period = prepared.problem.shortest_axial_period_s(until);
    let damping = if tether.internal_damping_n_s > 0.0 {
        String::new()
    } else {
        ", with the tether's internal damping (`internal_damping_n_s`: none by default, so only the integrator damps the waves)".to_string()
    };
    match run.slack_events.first() {
        Some(first) => format!(
            "the tether went slack {} time(s) (first at {:.2} s) and snapped taut: the snap of an instantaneous winch stop has no converged peak (undamped, it changes with the segment count and converges only as about the square root of the segment length; damped, the damper's force at the stop is `c ΔV` over one segment's length, which grows as the segments shrink). Give the winch its deceleration (a `trapezoidal` profile's `ramp_down_s`){damping}",
            run.slack_events.len(),
            first.start_s
        ),
        None => format!(
            "the tether's axial waves (first period 4L/c = {period:.4} s at its shortest, {shortest:.0} m), rung by the winch's changes of rate or acceleration, are not resolved by the default steps: give numerics.time_step_s of at most {:.5} s (1/{} of that period){damping}",
            period / AXIAL_STEPS_PER_PERIOD,
            AXIAL_STEPS_PER_PERIOD
        ),
    }
}

/// Runs the ladder of `prepared` and gives the answer's run with its
/// converged figures, or refuses naming `numerics`.
pub fn run_converged(
    prepared: &Prepared,
    progress: &dyn Progress,
) -> Result<(Ran, DynamicsConvergedOutput), RequestError> {
    let ladder = &prepared.ladder;
    let total: usize = prepared.planned_runs().iter().map(|r| r.0).sum();
    let config_at = |h: f64, segments: usize| DynamicsConfig {
        time_step_s: h,
        segments,
        ..prepared.config.clone()
    };
    let mut done = 0usize;
    let mut refinements = Vec::new();
    let mut figures: Vec<(f64, usize, Figures)> = Vec::new();
    let mut answer: Option<Ran> = None;
    let mut met = false;
    for (k, &h) in ladder.time_steps_s.iter().enumerate() {
        let ran = run_with(
            prepared,
            config_at(h, ladder.segments),
            progress,
            done,
            total,
        )?;
        done += ran.steps;
        refinements.push(level(&ran));
        figures.push((h, ladder.segments, Figures::of(&ran.run)));
        answer = Some(ran);
        if k >= 1 {
            met = within(&figures[k - 1].2, &figures[k].2, ladder.tolerance);
            if ladder.enforced && met && h <= ladder.stop_at_or_below_s {
                break;
            }
        }
    }
    let answer = answer.expect("at least one run");
    let fine = figures.last().expect("a run").2;
    let coarse = figures[figures.len() - 2].2;
    if ladder.enforced && !met {
        let unfinished = refinements.iter().filter(|r| !r.completed).count();
        let why = if unfinished > 0 {
            format!(
                "{unfinished} of the runs did not reach the end (see `outcome` at a fixed discretisation)"
            )
        } else {
            unconverged_cause(prepared, &answer.run)
        };
        return Err(InvalidInput::new(
            "numerics",
            format!(
                "the figures did not converge to {} of their scale by the finest default step ({} s): {}. Likely cause: {why}. Give numerics.time_step_s (and numerics.segments) to have the answer at that discretisation with its error estimate, or a larger numerics.tolerance_nondim",
                ladder.tolerance,
                figures.last().expect("a run").0,
                ladder_words(&figures)
            ),
        )
        .into());
    }
    // The segment check at the answer's step.
    let mut segment_change = [0.0; FIGURES];
    if ladder.check_segments != ladder.segments {
        let h = answer.config.time_step_s;
        let ran = run_with(
            prepared,
            config_at(h, ladder.check_segments),
            progress,
            done,
            total,
        )?;
        refinements.push(level(&ran));
        let half = Figures::of(&ran.run);
        segment_change = changes(&half, &fine);
        let segments_met = within(&half, &fine, ladder.tolerance);
        if ladder.enforced && !segments_met {
            let mut runs = figures.clone();
            runs.push((h, ladder.check_segments, half));
            return Err(InvalidInput::new(
                "numerics",
                format!(
                    "the figures changed by more than {} of their scale between {} and {} segments at {h} s: {}. Likely cause: {}. Give numerics.segments (and numerics.time_step_s) to have the answer at that discretisation with its error estimate, or a larger numerics.tolerance_nondim",
                    ladder.tolerance,
                    ladder.check_segments,
                    ladder.segments,
                    ladder_words(&runs),
                    unconverged_cause(prepared, &answer.run)
                ),
            )
            .into());
        }
        met &= segments_met;
    }
    let e = estimate(&coarse, &fine, segment_change);
    let orders: [Option<f64>; FIGURES] = std::array::from_fn(|i| {
        let n = figures.len();
        (n >= 3)
            .then(|| {
                let floor = 1e-9 * fine.scales()[i];
                observed_order(
                    figures[n - 3].2.values[i],
                    figures[n - 2].2.values[i],
                    figures[n - 1].2.values[i],
                    floor,
                )
            })
            .flatten()
    });
    let out = DynamicsConvergedOutput {
        peak_winch_tension_n: output(e[0]),
        min_winch_tension_n: output(e[1]),
        peak_tension_n: output(e[2]),
        min_aerostat_altitude_m: output(e[3]),
        tolerance_nondim: ladder.tolerance,
        tolerance_enforced: ladder.enforced,
        tolerance_met: met,
        time_step_s: answer.config.duration_s / answer.steps as f64,
        segments: answer.config.segments,
        observed_orders: ObservedOrdersOutput {
            peak_winch_tension_nondim: orders[0],
            min_winch_tension_nondim: orders[1],
            peak_tension_nondim: orders[2],
            min_aerostat_altitude_nondim: orders[3],
        },
        refinements,
    };
    Ok((answer, out))
}

/// One sentence on how the figures were converged.
pub fn explain(c: &DynamicsConvergedOutput) -> String {
    let p = &c.peak_tension_n;
    let how = if c.tolerance_enforced {
        format!(
            "The step ({} s) and segments ({}) were chosen so that the figures changed by at most {} of their scale on halving the step",
            c.time_step_s, c.segments, c.tolerance_nondim
        )
    } else {
        format!(
            "The request fixed the step ({} s) and segments ({}): the error estimates come from the runs at twice the step and half the segments, the tolerance {} was not enforced ({})",
            c.time_step_s,
            c.segments,
            c.tolerance_nondim,
            if c.tolerance_met {
                "it is met"
            } else {
                "it is not met"
            }
        )
    };
    format!(
        "{how}; the peak tension anywhere is {:.1} ± {:.1} N, {:.1} N on the safe side (converged).",
        p.value, p.error_estimate, p.safe_value
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_match_the_output_fields() {
        let v = serde_json::to_value(ObservedOrdersOutput {
            peak_winch_tension_nondim: None,
            min_winch_tension_nondim: None,
            peak_tension_nondim: None,
            min_aerostat_altitude_nondim: None,
        })
        .unwrap();
        for name in crate::numerics::dynamics::converged::NAMES {
            let stem = name.rsplit_once('_').unwrap().0;
            assert!(v.get(format!("{stem}_nondim")).is_some(), "{name}");
        }
    }
}
