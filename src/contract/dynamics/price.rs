//! What a dynamics request costs in CPU seconds (issue 34, item 2): unit
//! costs measured through the routes, the turbulence field sized as the
//! run sizes it.

use crate::contract::dynamics::validate::Prepared;
use crate::contract::price::Price;

// Dynamics unit costs, measured through `POST /api/v1/dynamics/peaks`
// (server CPU time from /proc, 2-core machine, release build), each set
// about 1.5 times the measurement:
//   200 samples, 100 m, 2 steps × 2 segments: 0.02 CPU-s (0.1 ms a sample);
//   1 000 samples, 500 m tether, 8 m/s, 2 × 2: 1.35 CPU-s (13 levels ×
//     1 024 times: 1.0e-8 s per field sample and log2);
//   200 samples, 500 m, 2 m/s, 2 × 2: 1.2 CPU-s (13 × 4 096: 9.4e-9);
//   200 samples, 2 000 m, 8 m/s, 2 × 2: 3.96 CPU-s (49 × 4 096: 8.2e-9);
// Raised 1.5 times again after the most expensive accepted many-sample
// request used 2.11 CPU-s at a price of 2.0 on a machine running the
// test suite (the cheap request's probe then saw 5.8-6.2 CPU-s spent).
//   20 samples, 200 steps × 200 segments: 0.18 CPU-s (1.9e-7 per
//     segment-step beside the field); 20 samples, 2 000 steps × 2
//     segments: 0.05 CPU-s (about 2e-7 per step).
/// Dynamics: each run's fixed cost (the §6 static start relaxed to the
/// discrete equilibrium, the quasi-static comparison), s.
pub const DYNAMICS_RUN_S: f64 = 3e-4;
/// Dynamics: one time step's fixed cost (generalized-α predictor, outputs), s.
pub const DYNAMICS_STEP_S: f64 = 6e-7;
/// Dynamics: one segment of one step (Newton on the block-tridiagonal
/// Jacobian, drag and turbulence at its node), s.
pub const DYNAMICS_SEGMENT_STEP_S: f64 = 4.2e-7;
/// Dynamics: one sample of one level of the turbulence field per
/// `log2` of the series length (its normal draws and FFT), s.
pub const DYNAMICS_FIELD_SAMPLE_S: f64 = 2.25e-8;

/// The turbulence field a run synthesises (levels × series samples), an
/// upper estimate from the request (as `numerics::dynamics::run` sizes it:
/// levels every 50 m to 1.2 × the longest length, the series of period
/// `duration + 2 top / U_c + 10 s` at 0.2 s, a power of two; `U_c` is
/// bounded below by the flow's slowest speed between half the first
/// length and the top).
pub fn turbulence_field(p: &Prepared) -> (f64, f64) {
    if p.problem.turbulence.is_none() {
        return (0.0, 0.0);
    }
    let c = &p.config;
    let top = p.problem.length.longest_m(c.duration_s) * 1.2;
    let low = 0.5 * p.problem.length.at(0.0).length_m;
    let levels = ((top / c.turbulence_level_spacing_m).ceil() + 1.0).clamp(4.0, 256.0);
    let slowest = (0..=64)
        .map(|i| {
            let z = low + (top - low) * i as f64 / 64.0;
            p.problem.flow.speed_m_s(z).abs()
        })
        .fold(f64::INFINITY, f64::min)
        .max(1e-6);
    let period = c.duration_s + 2.0 * top / slowest + 10.0;
    let wanted = (period / c.turbulence_time_step_s).ceil().max(4.0);
    let samples = if wanted.is_finite() && wanted < 1e15 {
        (wanted as u64).next_power_of_two() as f64
    } else {
        f64::INFINITY
    };
    (levels, samples)
}

/// CPU seconds of one run of `steps` × `segments` (each run synthesises
/// its turbulence field).
fn one_run_s(p: &Prepared, steps: usize, segments: usize) -> f64 {
    let steps = steps as f64;
    let segments = segments as f64;
    let (levels, samples) = turbulence_field(p);
    let field = if samples > 0.0 {
        levels * samples * samples.log2().max(1.0) * DYNAMICS_FIELD_SAMPLE_S
    } else {
        0.0
    };
    DYNAMICS_RUN_S + steps * DYNAMICS_STEP_S + steps * segments * DYNAMICS_SEGMENT_STEP_S + field
}

/// CPU seconds of one dynamics run at the prepared configuration (a
/// `/dynamics/peaks` sample).
pub fn dynamics_run_s(p: &Prepared) -> f64 {
    one_run_s(p, p.steps, p.config.segments)
}

/// CPU seconds of a `/dynamics` request: every run it may make (issue 31
/// item 2: the default ladder's 0.2, 0.1 and 0.05 s runs and the segment
/// check, priced in full although it stops early when the figures agree;
/// a fixed discretisation's run, the run at twice its step and the one at
/// half its segments).
pub fn dynamics_request_s(p: &Prepared) -> f64 {
    p.planned_runs()
        .iter()
        .map(|&(steps, segments)| one_run_s(p, steps, segments))
        .sum()
}

/// `POST /api/v1/dynamics`.
pub fn dynamics(p: &Prepared) -> Price {
    let runs = p.planned_runs();
    let words: Vec<String> = runs
        .iter()
        .map(|(steps, segments)| format!("{steps} × {segments}"))
        .collect();
    Price {
        cpu_s: dynamics_request_s(p),
        field: "duration_s".into(),
        counts: format!(
            "{} runs of steps × segments ({}){}",
            runs.len(),
            words.join(", "),
            field_words(p)
        ),
    }
}

/// `POST /api/v1/dynamics/peaks`: `samples` runs.
pub fn dynamics_peaks(p: &Prepared, samples: usize) -> Price {
    Price {
        cpu_s: dynamics_run_s(p) * samples as f64,
        field: "samples".into(),
        counts: format!(
            "{samples} samples of {} steps × {} segments{}",
            p.steps,
            p.config.segments,
            field_words(p)
        ),
    }
}

fn field_words(p: &Prepared) -> String {
    let (levels, samples) = turbulence_field(p);
    if samples > 0.0 {
        format!(" with a turbulence field of {levels:.0} levels × {samples:.0} times each")
    } else {
        String::new()
    }
}
