//! The string-model deployment chart (`POST /api/v1/charts`, model
//! `linear_string`) in chunks of rates, for distributed `chart` jobs.
//!
//! The items are the chart's rates (each with every buoyancy): a chunk
//! computes the points of its rates with the same point evaluation as the
//! single-process chart ([`crate::numerics::string::chart::deployment_chart_cancellable`];
//! each point is independent of the others), and carries every number as
//! its IEEE-754 bits, so that the chart put together from the chunks in
//! order ([`chart_from_chunks`]) is the single-process answer, byte for
//! byte.

use serde::{Deserialize, Serialize};

use crate::contract::dto::{ChartPointOutput, ChartRequest, ChartResponse, ChartSeriesOutput};
use crate::contract::run::chart_elements;
use crate::contract::{Progress, RequestError};
use crate::numerics::parallel::Parallelism;
use crate::numerics::params::AerostatSystem;
use crate::numerics::string::chart;

/// The rates of the chart, in order.
fn rates(req: &ChartRequest) -> Result<Vec<f64>, RequestError> {
    Ok(req.params.rates_m_s.rates("rates_m_s")?)
}

/// The buoyancies of the series: the request's list, else the aerostat's.
fn buoyancies(req: &ChartRequest, sys: &AerostatSystem) -> Vec<f64> {
    if req.params.net_buoyancies_n.is_empty() {
        vec![sys.net_buoyancy_n]
    } else {
        req.params.net_buoyancies_n.clone()
    }
}

/// Items of a chunked chart: its rates.
pub fn chart_rate_count(req: &ChartRequest) -> usize {
    req.params.rates_m_s.count()
}

/// One series of a chunk on the wire: the buoyancy and, per point, its
/// eight numbers, all as bits.
#[derive(Serialize, Deserialize)]
struct WireSeries {
    net_buoyancy_n: u64,
    points: Vec<[u64; 8]>,
}

/// The points of the rates `range` (every series) as JSON text: one chunk
/// of a distributed chart job. Cancellation is polled before every point.
pub fn chart_chunk(
    req: &ChartRequest,
    range: std::ops::Range<usize>,
    parallelism: Parallelism,
    progress: &dyn Progress,
) -> Result<String, RequestError> {
    let sys = req.system.model()?.system;
    let rates = rates(req)?;
    let range = range.start.min(rates.len())..range.end.min(rates.len());
    let buoyancies = buoyancies(req, &sys);
    let report = |done: usize, total: usize| progress.report(done, total);
    let cancel = || progress.cancelled();
    let series = chart::deployment_chart_cancellable(
        &sys,
        req.system.discretisation()?,
        &rates[range],
        &buoyancies,
        parallelism,
        &report,
        &cancel,
    )?
    .ok_or(RequestError::Cancelled)?;
    if progress.cancelled() {
        return Err(RequestError::Cancelled);
    }
    let wire: Vec<WireSeries> = series
        .into_iter()
        .map(|s| WireSeries {
            net_buoyancy_n: s.net_buoyancy_n.to_bits(),
            points: s
                .points
                .into_iter()
                .map(|p| {
                    [
                        p.rate_m_s,
                        p.critical_time_s,
                        p.max_elevation_m,
                        p.closed_form_elevation_m,
                        p.critical_time_error_s,
                        p.max_elevation_error_m,
                        s.net_buoyancy_n
                            - sys.mass_per_length_kg_m * sys.gravity_m_s2 * p.max_elevation_m,
                        sys.mass_per_length_kg_m * p.rate_m_s * p.rate_m_s,
                    ]
                    .map(f64::to_bits)
                })
                .collect(),
        })
        .collect();
    Ok(serde_json::to_string(&wire).expect("chart chunks serialise"))
}

/// The chart from its chunks ([`chart_chunk`] of consecutive rate ranges
/// covering every rate, in order).
pub fn chart_from_chunks(
    req: &ChartRequest,
    parts: &[String],
) -> Result<ChartResponse, RequestError> {
    let sys = req.system.model()?.system;
    let count = chart_rate_count(req);
    let mut series: Vec<ChartSeriesOutput> = Vec::new();
    for part in parts {
        let wire: Vec<WireSeries> = serde_json::from_str(part)
            .map_err(|e| RequestError::Malformed(format!("a chunk of the chart job: {e}")))?;
        if !series.is_empty() && wire.len() != series.len() {
            return Err(RequestError::Malformed(format!(
                "a chunk of the chart job holds {} series, not {}",
                wire.len(),
                series.len()
            )));
        }
        for (i, w) in wire.into_iter().enumerate() {
            if series.len() <= i {
                let f = f64::from_bits(w.net_buoyancy_n);
                series.push(ChartSeriesOutput {
                    net_buoyancy_n: f,
                    wave_speed_m_s: (f / sys.mass_per_length_kg_m).sqrt(),
                    points: Vec::with_capacity(count),
                });
            }
            series[i].points.extend(w.points.into_iter().map(|b| {
                let [r, t, h, c, te, he, w, k] = b.map(f64::from_bits);
                ChartPointOutput {
                    rate_m_s: r,
                    critical_time_s: t,
                    max_elevation_m: h,
                    closed_form_elevation_m: c,
                    critical_time_error_s: te,
                    max_elevation_error_m: he,
                    winch_tension_at_onset_n: w,
                    kinematic_tension_n: k,
                }
            }));
        }
    }
    if let Some(s) = series.iter().find(|s| s.points.len() != count) {
        return Err(RequestError::Malformed(format!(
            "the chunks of the chart job hold {} rates, not {count}",
            s.points.len()
        )));
    }
    let discretisation = req.system.discretisation()?;
    Ok(ChartResponse {
        series,
        elements: chart_elements(discretisation),
        converged: req.system.model.elements.is_none(),
    })
}
