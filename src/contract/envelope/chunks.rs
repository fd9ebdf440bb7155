//! The envelope as a chunked job (issue 15): its items are the wind rows.
//!
//! A chunk is the envelope of the request's wind speeds `range` (the same
//! numbers, not a new grid), each row computed exactly as in one process:
//! rows are independent (the GE continuation runs along the lengths of one
//! row). The answer is put together from the chunks' answers: their
//! points, per-wind limits and GE per-wind limits in row order, and the
//! per-length limits, which need every row, recomputed from the points
//! with the rule the single-process answer uses ([`super::length_limits`]).
//! JSON carries every `f64` exactly (`float_roundtrip`), so the result is
//! byte for byte the single-process answer (tests/chunks_kinds.rs).

use super::dto::{EnvelopeRequest, EnvelopeResponse};
use super::{envelope_of, length_limits};
use crate::contract::{Progress, RequestError};
use crate::numerics::parallel::Parallelism;

/// Wind rows of the request.
pub fn envelope_row_count(req: &EnvelopeRequest) -> usize {
    req.wind_speeds_m_s.as_ref().map_or(1, |g| g.count())
}

/// The envelope of the wind rows `range`.
pub fn envelope_chunk(
    req: &EnvelopeRequest,
    range: std::ops::Range<usize>,
    parallelism: Parallelism,
    progress: &dyn Progress,
) -> Result<EnvelopeResponse, RequestError> {
    let (mut problem, config, spec) = req.ge_problem()?;
    let rows = problem.wind_speeds_m_s.get(range.clone()).ok_or_else(|| {
        RequestError::Malformed(format!(
            "chunk rows {range:?} outside the {} wind speeds",
            problem.wind_speeds_m_s.len()
        ))
    })?;
    problem.wind_speeds_m_s = rows.to_vec();
    envelope_of(req, &problem, &config, spec.as_ref(), parallelism, progress)
}

/// The whole envelope from the chunks' answers (JSON text, in row order).
pub fn envelope_from_chunks(
    req: &EnvelopeRequest,
    parts: &[String],
) -> Result<EnvelopeResponse, RequestError> {
    let (problem, _, _) = req.ge_problem()?;
    let bad = |e: serde_json::Error| RequestError::Malformed(format!("a chunk result: {e}"));
    let mut chunks = parts
        .iter()
        .map(|p| serde_json::from_str::<EnvelopeResponse>(p).map_err(bad));
    let mut out = chunks
        .next()
        .ok_or_else(|| RequestError::Malformed("no chunk result".into()))??;
    for chunk in chunks {
        let chunk = chunk?;
        out.points.extend(chunk.points);
        out.max_altitude_per_wind
            .extend(chunk.max_altitude_per_wind);
        if let (Some(all), Some(more)) = (&mut out.quasi_static_ge, chunk.quasi_static_ge) {
            all.per_wind.extend(more.per_wind);
        }
    }
    let expected = problem.wind_speeds_m_s.len() * problem.tether_lengths_m.len();
    if out.points.len() != expected
        || out.max_altitude_per_wind.len() != problem.wind_speeds_m_s.len()
    {
        return Err(RequestError::Malformed(format!(
            "the chunks hold {} points for {expected}",
            out.points.len()
        )));
    }
    out.max_wind_per_length = length_limits(
        &problem.wind_speeds_m_s,
        &problem.tether_lengths_m,
        &out.points,
    );
    out.wind_speeds_m_s = problem.wind_speeds_m_s;
    Ok(out)
}
