//! The plan's haul-down forecast from a forecast source (issue 32): the
//! first member's periods, each fitted as the windows request fits it, read
//! at the aerostat's altitude — `(time from the first period, wind, gust)`,
//! the points of `haul_down.forecast`. In a forecast that gives gusts, a
//! period without one (a report group without `G`) has the mean as its gust.

use crate::contract::plan::dto::WindForecastPointInput;
use crate::contract::windows::dto::{DEFAULT_ROUGHNESS_LENGTH_M, ForecastInput};
use crate::contract::windows::source::parse_forecast;
use crate::numerics::forecast::profile::fit_hour;
use crate::numerics::params::InvalidInput;

/// The forecast's wind and gust at `height_m` against time (s from its first period).
pub fn haul_down_points(
    source: &ForecastInput,
    height_m: f64,
) -> Result<Vec<WindForecastPointInput>, InvalidInput> {
    let z0 = source
        .roughness_length_m
        .unwrap_or(DEFAULT_ROUGHNESS_LENGTH_M);
    if !(z0.is_finite() && (1e-6..=10.0).contains(&z0)) {
        return Err(InvalidInput::new(
            "haul_down.source.roughness_length_m",
            format!("must be between 1e-6 and 10, got {z0}"),
        ));
    }
    let renamed = |e: InvalidInput| InvalidInput {
        field: e.field.replacen("forecast.", "haul_down.source.", 1),
        reason: e.reason,
    };
    let f = parse_forecast(source).map_err(renamed)?;
    let periods = &f.members[0].periods;
    let t0 = periods.first().map_or(0.0, |p| p.start_s);
    // A forecast that gives gusts, but not in every period, reports none
    // where they are not significant (a METAR or TAF group without `G`):
    // there the gust is the mean, as the windows judge such an hour.
    let reports_gusts = periods.iter().any(|p| p.gust.is_some());
    let mut out: Vec<WindForecastPointInput> = Vec::with_capacity(periods.len());
    for p in periods {
        let h = fit_hour(&p.winds, p.gust, z0).map_err(|_| {
            InvalidInput::new(
                format!("haul_down.source.data ({})", p.time),
                "has no usable wind speed",
            )
        })?;
        let u = h.flow.speed_m_s(height_m);
        let g = match (h.gust_ratio_nondim, h.gust_at_reference_m_s) {
            (Some(r), _) => Some(r * u),
            (None, g) => g,
        }
        .or(reports_gusts.then_some(u));
        // Overlapping periods (a TAF's TEMPO) are read in start order; a
        // period starting with the one before keeps the stronger wind.
        let t = p.start_s - t0;
        match out.last_mut() {
            Some(last) if last.time_s >= t => {
                last.wind_speed_m_s = last.wind_speed_m_s.max(u);
                last.gust_m_s = match (last.gust_m_s, g) {
                    (Some(a), Some(b)) => Some(a.max(b)),
                    (a, b) => a.or(b),
                };
            }
            _ => out.push(WindForecastPointInput {
                time_s: t,
                wind_speed_m_s: u,
                gust_m_s: g,
            }),
        }
    }
    Ok(out)
}
