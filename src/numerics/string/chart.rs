//! Deployment charts (thesis Fig. 4.2): critical time `t*` and maximum
//! safe elevation `h*` against a grid of constant rates, one series per net
//! buoyancy. Points are independent; they fan out on rayon when asked
//! (`Parallelism::Rayon`) and the result is the same bit for bit.

use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use rayon::prelude::*;

use crate::numerics::parallel::Parallelism;
use crate::numerics::params::{AerostatSystem, InvalidInput};
use crate::numerics::string::StringModel;
use crate::numerics::string::converged;
use crate::numerics::string::critical::{Onset, constant_rate_lengthening};
use crate::numerics::string::operators::StringOperators;

/// Largest number of points one chart may have.
pub const MAX_CHART_POINTS: usize = 1_000_000;

/// One point of a series.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChartPoint {
    pub rate_m_s: f64,
    /// `t*` (s); 0 when unstable at once.
    pub critical_time_s: f64,
    /// `h* = L(t*)` (m).
    pub max_elevation_m: f64,
    /// `(F/ρA − v²)/g` (m), clipped at zero.
    pub closed_form_elevation_m: f64,
    /// Estimated discretisation error of `critical_time_s` (s).
    pub critical_time_error_s: f64,
    /// Estimated discretisation error of `max_elevation_m` (m).
    pub max_elevation_error_m: f64,
    pub onset: Onset,
}

/// How the points are discretised.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Discretisation {
    /// Converged to this relative tolerance; `t*` and `h*` on the safe
    /// side of their error bound (see [`converged`]).
    Converged { relative_tolerance: f64 },
    /// This many uniform elements: that mesh's values, with their error
    /// against the converged answer.
    Elements(usize),
}

/// One series: a net buoyancy and its points in rate order.
#[derive(Clone, Debug, PartialEq)]
pub struct ChartSeries {
    pub net_buoyancy_n: f64,
    pub points: Vec<ChartPoint>,
}

/// `count` rates evenly spaced on `[min, max]`.
pub fn rate_grid(min_m_s: f64, max_m_s: f64, count: usize) -> Result<Vec<f64>, InvalidInput> {
    for (field, v) in [("rates_m_s.min", min_m_s), ("rates_m_s.max", max_m_s)] {
        crate::numerics::params::require_positive(field, v)?;
    }
    if max_m_s < min_m_s {
        return Err(InvalidInput::new(
            "rates_m_s.max",
            format!("must be at least rates_m_s.min = {min_m_s}"),
        ));
    }
    if count == 0 || count > MAX_CHART_POINTS {
        return Err(InvalidInput::new(
            "rates_m_s.count",
            format!("must be between 1 and {MAX_CHART_POINTS}, got {count}"),
        ));
    }
    if count == 1 {
        return Ok(vec![min_m_s]);
    }
    Ok((0..count)
        .map(|i| min_m_s + (max_m_s - min_m_s) * i as f64 / (count - 1) as f64)
        .collect())
}

/// Computes the chart. `progress(done, total)` is called as points finish
/// (from worker threads, in no particular order).
pub fn deployment_chart(
    base: &AerostatSystem,
    elements: usize,
    rates_m_s: &[f64],
    net_buoyancies_n: &[f64],
    parallelism: Parallelism,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Vec<ChartSeries>, InvalidInput> {
    deployment_chart_with(
        base,
        Discretisation::Elements(elements),
        rates_m_s,
        net_buoyancies_n,
        parallelism,
        progress,
    )
}

/// [`deployment_chart`] with the discretisation chosen: converged, or a
/// fixed uniform mesh.
pub fn deployment_chart_with(
    base: &AerostatSystem,
    discretisation: Discretisation,
    rates_m_s: &[f64],
    net_buoyancies_n: &[f64],
    parallelism: Parallelism,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Vec<ChartSeries>, InvalidInput> {
    let never = || false;
    deployment_chart_cancellable(
        base,
        discretisation,
        rates_m_s,
        net_buoyancies_n,
        parallelism,
        progress,
        &never,
    )
    .map(|series| series.expect("never cancelled"))
}

/// [`deployment_chart_with`], polled for cancellation before every point:
/// `Ok(None)` once `cancel()` has returned `true` (the remaining points
/// are skipped).
pub fn deployment_chart_cancellable(
    base: &AerostatSystem,
    discretisation: Discretisation,
    rates_m_s: &[f64],
    net_buoyancies_n: &[f64],
    parallelism: Parallelism,
    progress: &(dyn Fn(usize, usize) + Sync),
    cancel: &(dyn Fn() -> bool + Sync),
) -> Result<Option<Vec<ChartSeries>>, InvalidInput> {
    let elements = match discretisation {
        Discretisation::Elements(n) => {
            crate::numerics::string::validate_elements("model.elements", n)?
        }
        Discretisation::Converged { relative_tolerance } => {
            converged::validate_tolerance("numerics.relative_tolerance", relative_tolerance)?;
            crate::numerics::string::MIN_ELEMENTS
        }
    };
    if net_buoyancies_n.is_empty() {
        return Err(InvalidInput::new(
            "net_buoyancies_n",
            "must list at least one buoyancy",
        ));
    }
    let total = rates_m_s.len().saturating_mul(net_buoyancies_n.len());
    if total > MAX_CHART_POINTS {
        return Err(InvalidInput::new(
            "rates_m_s.count",
            format!("the chart would have {total} points; at most {MAX_CHART_POINTS} are allowed"),
        ));
    }
    let systems = net_buoyancies_n
        .iter()
        .enumerate()
        .map(|(i, &f)| {
            base.with_net_buoyancy(f)
                .map_err(|e| InvalidInput::new(format!("net_buoyancies_n[{i}]"), e.reason))
        })
        .collect::<Result<Vec<_>, _>>()?;
    for (i, &v) in rates_m_s.iter().enumerate() {
        crate::numerics::params::require_positive(&format!("rates_m_s[{i}]"), v)?;
    }
    let operators = Arc::new(StringOperators::new(elements));
    let done = AtomicUsize::new(0);
    let stopped = std::sync::atomic::AtomicBool::new(false);
    let point = |index: usize| -> ChartPoint {
        let (s, r) = (index / rates_m_s.len(), index % rates_m_s.len());
        if stopped.load(Ordering::Relaxed) || cancel() {
            stopped.store(true, Ordering::Relaxed);
            let nan = f64::NAN;
            return ChartPoint {
                rate_m_s: rates_m_s[r],
                critical_time_s: nan,
                max_elevation_m: nan,
                closed_form_elevation_m: nan,
                critical_time_error_s: nan,
                max_elevation_error_m: nan,
                onset: Onset::Never { until_s: nan },
            };
        }
        let p = match discretisation {
            Discretisation::Elements(_) => {
                let model = StringModel::with_operators(systems[s], operators.clone());
                chart_point_with_error(&model, rates_m_s[r])
            }
            Discretisation::Converged { relative_tolerance } => {
                converged_chart_point(&systems[s], rates_m_s[r], relative_tolerance)
            }
        };
        progress(done.fetch_add(1, Ordering::Relaxed) + 1, total);
        p
    };
    let flat: Vec<ChartPoint> = match parallelism {
        Parallelism::Serial => (0..total).map(point).collect(),
        Parallelism::Rayon => (0..total).into_par_iter().map(point).collect(),
    };
    if stopped.load(Ordering::Relaxed) {
        return Ok(None);
    }
    Ok(Some(
        systems
            .iter()
            .zip(flat.chunks(rates_m_s.len().max(1)))
            .map(|(sys, pts)| ChartSeries {
                net_buoyancy_n: sys.net_buoyancy_n,
                points: pts.to_vec(),
            })
            .collect(),
    ))
}

/// One chart point: constant-rate lengthening from `L0`, no target.
pub fn chart_point(model: &StringModel, rate_m_s: f64) -> ChartPoint {
    let sys = &model.system;
    let result = constant_rate_lengthening(model, rate_m_s, None);
    let (critical_time_s, max_elevation_m) = match result.onset {
        Onset::Immediate(_) => (0.0, sys.initial_length_m),
        Onset::During { time_s, length_m } => (time_s, length_m),
        Onset::Never { .. } => (f64::INFINITY, f64::INFINITY),
    };
    ChartPoint {
        rate_m_s,
        critical_time_s,
        max_elevation_m,
        closed_form_elevation_m: sys.closed_form_elevation_m(rate_m_s).max(0.0),
        critical_time_error_s: 0.0,
        max_elevation_error_m: 0.0,
        onset: result.onset,
    }
}

/// [`chart_point`] with the error of that mesh's `t*` and `h*` against the
/// converged answer ([`converged::mesh_error_estimate`]).
pub fn chart_point_with_error(model: &StringModel, rate_m_s: f64) -> ChartPoint {
    let mut p = chart_point(model, rate_m_s);
    let c = converged::constant_rate(
        &model.system,
        rate_m_s,
        None,
        converged::DEFAULT_RELATIVE_TOLERANCE,
    );
    if let (Onset::During { .. }, Some(t), Some(h)) = (p.onset, c.time_s, c.length_m) {
        p.critical_time_error_s = converged::mesh_error_estimate(p.critical_time_s, &t);
        p.max_elevation_error_m = converged::mesh_error_estimate(p.max_elevation_m, &h);
    } else if let Onset::During { .. } = p.onset {
        // the mesh is stable for a while where the continuum is not
        p.critical_time_error_s = p.critical_time_s;
        p.max_elevation_error_m = p.max_elevation_m - model.system.initial_length_m;
    }
    p
}

/// One converged chart point: `t*` and `h*` on the safe side of the bound.
pub fn converged_chart_point(
    sys: &AerostatSystem,
    rate_m_s: f64,
    relative_tolerance: f64,
) -> ChartPoint {
    let c = converged::constant_rate(sys, rate_m_s, None, relative_tolerance);
    let (critical_time_s, max_elevation_m) = match c.onset {
        Onset::Immediate(_) => (0.0, sys.initial_length_m),
        Onset::During { time_s, length_m } => (time_s, length_m),
        Onset::Never { .. } => (f64::INFINITY, f64::INFINITY),
    };
    ChartPoint {
        rate_m_s,
        critical_time_s,
        max_elevation_m,
        closed_form_elevation_m: sys.closed_form_elevation_m(rate_m_s).max(0.0),
        critical_time_error_s: c.time_error_s(),
        max_elevation_error_m: c.length_error_m(),
        onset: c.onset,
    }
}
