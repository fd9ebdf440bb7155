//! The bounds of one dynamic run (mesh, steps, work, outputs) and their
//! checks, written once: the run checks its configuration with them, and
//! the contract checks a request with the same functions under its own
//! field names (`numerics.segments`, `sample_count`, …), so the two never
//! disagree. In a file of their own so the run's files import them without
//! importing the module's root.

use crate::numerics::params::{InvalidInput, compact, require_finite};

/// Fewest and most segments.
pub const MIN_SEGMENTS: usize = 2;
pub const MAX_SEGMENTS: usize = 1000;
/// Most time steps of one run.
pub const MAX_STEPS: usize = 20_000_000;
/// Most `steps × segments` of one run.
pub const MAX_WORK: f64 = 2e9;
/// Most halvings of a step whose Newton iteration fails.
pub const MAX_HALVINGS: usize = 6;
/// Fewest and most samples one run keeps (the first and the last at least).
pub const MIN_SAMPLES: usize = 2;
pub const MAX_SAMPLES: usize = 200_000;
/// Most shapes one run keeps.
pub const MAX_SHAPES: usize = 1000;

/// `value` within `[min, max]`, or an error naming `field`.
fn count_within(field: &str, value: usize, min: usize, max: usize) -> Result<usize, InvalidInput> {
    if value < min || value > max {
        return Err(InvalidInput::new(
            field,
            format!("must be between {min} and {max}, got {value}"),
        ));
    }
    Ok(value)
}

/// A segment count within `MIN_SEGMENTS..=MAX_SEGMENTS`.
pub fn check_segments(field: &str, segments: usize) -> Result<usize, InvalidInput> {
    count_within(field, segments, MIN_SEGMENTS, MAX_SEGMENTS)
}

/// The generalized-α spectral radius `ρ∞`, within `[0, 1]`.
pub fn check_spectral_radius(field: &str, rho: f64) -> Result<f64, InvalidInput> {
    require_finite(field, rho)?;
    if !(0.0..=1.0).contains(&rho) {
        return Err(InvalidInput::new(
            field,
            format!("must be at least 0 and at most 1, got {}", compact(rho)),
        ));
    }
    Ok(rho)
}

/// The steps a run of `duration_s` takes at steps of at most
/// `time_step_s`: the quotient rounded up (a remainder under 1e-9 of a
/// step dropped), at least one. As `f64`: a request may ask for more than
/// any count the run could hold.
pub fn step_count(duration_s: f64, time_step_s: f64) -> f64 {
    ((duration_s / time_step_s) - 1e-9).ceil().max(1.0)
}

/// The steps of a run ([`step_count`]) within `MAX_STEPS` and `MAX_WORK`
/// segment-steps; the error names `field` (the duration) and suggests a
/// longer `time_step_field`.
pub fn check_steps(
    field: &str,
    time_step_field: &str,
    duration_s: f64,
    time_step_s: f64,
    segments: usize,
) -> Result<usize, InvalidInput> {
    let steps = step_count(duration_s, time_step_s);
    if steps > MAX_STEPS as f64 || steps * segments as f64 > MAX_WORK {
        return Err(InvalidInput::new(
            field,
            format!(
                "needs {steps:.0} steps of {segments} segments; a run takes at most {MAX_STEPS} steps and {MAX_WORK:e} segment-steps (lengthen {time_step_field} or shorten the run)"
            ),
        ));
    }
    Ok(steps as usize)
}

/// A count of kept samples within `MIN_SAMPLES..=MAX_SAMPLES`.
pub fn check_sample_count(field: &str, count: usize) -> Result<usize, InvalidInput> {
    count_within(field, count, MIN_SAMPLES, MAX_SAMPLES)
}

/// A sample spacing that keeps at most `MAX_SAMPLES` samples over
/// `duration_s` (the run's form of [`check_sample_count`]).
pub fn check_sample_interval(
    field: &str,
    duration_s: f64,
    interval_s: f64,
) -> Result<f64, InvalidInput> {
    if duration_s / interval_s > MAX_SAMPLES as f64 {
        return Err(InvalidInput::new(
            field,
            format!("would keep more than {MAX_SAMPLES} samples"),
        ));
    }
    Ok(interval_s)
}

/// A count of evenly spaced shapes within `0..=MAX_SHAPES`.
pub fn check_shape_count(field: &str, count: usize) -> Result<usize, InvalidInput> {
    count_within(field, count, 0, MAX_SHAPES)
}

/// At most `MAX_SHAPES` shape times.
pub fn check_shape_times(field: &str, times: &[f64]) -> Result<(), InvalidInput> {
    if times.len() > MAX_SHAPES {
        return Err(InvalidInput::new(
            field,
            format!("at most {MAX_SHAPES} times, got {}", times.len()),
        ));
    }
    Ok(())
}
