//! Runs one request against the numerical core: validates and converts the
//! SI input, calls the core, and converts the outcome back to SI output.

use crate::contract::dto::*;
pub use crate::contract::error::{NoProgress, Progress, RequestError};
use crate::contract::system::output::groups;
use crate::numerics::parallel::Parallelism;
use crate::numerics::params::{InvalidInput, Kinematics, require_finite, require_positive};
use crate::numerics::string::chart;
use crate::numerics::string::converged::{self, ConvergedConfig, ConvergedSafeRate};
use crate::numerics::string::critical::{
    self, ImmediateCause, Onset, SafeRate, SearchConfig, SearchMethod,
};

/// Largest number of modes a stability answer lists.
pub const MAX_MODES: usize = 4000;

pub fn stability(req: &StabilityRequest) -> Result<StabilityResponse, RequestError> {
    let model = req.system.model()?;
    let sys = model.system;
    let k = Kinematics {
        length_m: require_positive("state.length_m", req.params.state.length_m)?,
        rate_m_s: require_finite("state.rate_m_s", req.params.state.rate_m_s)?,
        acceleration_m_s2: require_finite(
            "state.acceleration_m_s2",
            req.params.state.acceleration_m_s2,
        )?,
    };
    if req.params.modes == 0 || req.params.modes > MAX_MODES {
        return Err(InvalidInput::new(
            "modes",
            format!(
                "must be between 1 and {MAX_MODES}, got {}",
                req.params.modes
            ),
        )
        .into());
    }
    let s = sys.to_nondim(k);
    let spectrum = model.spectrum(s)?;
    let to_si = |v: f64| sys.eigenvalue_to_si(v);
    let eigenvalues = spectrum
        .modes()
        .into_iter()
        .take(req.params.modes)
        .map(|e| EigenvalueOutput {
            re_1_s: to_si(e.re),
            im_1_s: to_si(e.im),
            re_nondim: e.re,
            im_nondim: e.im,
            frequency_hz: to_si(e.im) / (2.0 * std::f64::consts::PI),
        })
        .collect();
    let discretisation = req.system.discretisation()?;
    let (critical_length_m, critical_length_error_m, stable) = match discretisation {
        chart::Discretisation::Converged { relative_tolerance } => {
            match converged::critical_length_at_state(
                &sys,
                k.rate_m_s,
                k.acceleration_m_s2,
                relative_tolerance,
            ) {
                Some(c) => (
                    Some(c.lower()),
                    Some(c.error_estimate),
                    spectrum.is_stable() && k.length_m < c.lower(),
                ),
                None => (None, None, spectrum.is_stable()),
            }
        }
        chart::Discretisation::Elements(_) => {
            let mesh = converged::critical_length_at_state_on(
                &model,
                k.rate_m_s,
                k.acceleration_m_s2,
                None,
            );
            let conv = converged::critical_length_at_state(
                &sys,
                k.rate_m_s,
                k.acceleration_m_s2,
                converged::DEFAULT_RELATIVE_TOLERANCE,
            );
            let error = match (mesh, conv) {
                (Some(m), Some(c)) => Some(converged::mesh_error_estimate(m, &c)),
                _ => None,
            };
            (mesh, error, spectrum.is_stable())
        }
    };
    Ok(StabilityResponse {
        stable,
        critical_length_m,
        critical_length_error_m,
        converged: req.system.model.elements.is_none(),
        max_real_1_s: to_si(spectrum.max_real),
        max_real_nondim: spectrum.max_real,
        tolerance_1_s: to_si(spectrum.tolerance()),
        eigenvalues,
        state: StateOutput {
            length_m: k.length_m,
            rate_m_s: k.rate_m_s,
            acceleration_m_s2: k.acceleration_m_s2,
            length_nondim: s.length,
            rate_nondim: s.rate,
            acceleration_nondim: s.acceleration,
        },
        groups: groups(&sys),
        elements: model.elements(),
    })
}

pub fn critical(req: &CriticalRequest) -> Result<CriticalResponse, RequestError> {
    critical_with(req, &NoProgress)
}

/// Slowest winch rate of a constant-rate critical-time search: below it
/// t* overflows (a subnormal rate gives t* = ∞).
pub const MIN_CRITICAL_RATE_M_S: f64 = 1e-6;

/// Every check of a critical-time request that needs no solve (the
/// synchronous route and a job submission alike).
pub fn check_critical(req: &CriticalRequest) -> Result<(), RequestError> {
    let model = req.system.model()?;
    req.params.profile.profile(model.system.initial_length_m)?;
    if let ProfileInput::ConstantRate { rate_m_s, .. } = req.params.profile {
        if rate_m_s == 0.0 {
            return Err(InvalidInput::new(
                "profile.rate_m_s",
                "must be nonzero: a zero rate never changes the length (ask for the stability of that state instead)",
            )
            .into());
        }
        if rate_m_s.abs() < MIN_CRITICAL_RATE_M_S {
            return Err(InvalidInput::new(
                "profile.rate_m_s",
                format!(
                    "must be at least {MIN_CRITICAL_RATE_M_S:e} m/s in magnitude (slower deployments never reach t* in finite numbers), got {rate_m_s:e}"
                ),
            )
            .into());
        }
    }
    Ok(())
}

/// [`critical`], stopping (`RequestError::Cancelled`) when `progress` is cancelled.
pub fn critical_with(
    req: &CriticalRequest,
    progress: &dyn Progress,
) -> Result<CriticalResponse, RequestError> {
    check_critical(req)?;
    let model = req.system.model()?;
    let sys = model.system;
    let profile = req.params.profile.profile(sys.initial_length_m)?;
    let discretisation = req.system.discretisation()?;
    let answer = match discretisation {
        chart::Discretisation::Converged { relative_tolerance } => {
            let c = converged::critical_time(
                &sys,
                &profile,
                ConvergedConfig {
                    relative_tolerance,
                    confirm_with_qep: req.params.confirm_with_qep,
                },
            )?;
            let t_err = c.time_s.map(|t| t.error_estimate);
            CriticalAnswer {
                onset: c.onset,
                method: c.method,
                confirmed: c.confirmed(),
                time_error_s: t_err,
                length_error_m: c.length_m.map(|l| l.error_estimate),
                order: c.time_s.map(|t| t.order).filter(|o| o.is_finite()),
                elements: c.elements,
                converged: true,
                probes: c.probes,
            }
        }
        chart::Discretisation::Elements(_) => {
            let result = critical::critical_time_cancellable(
                &model,
                &profile,
                SearchConfig {
                    confirm_with_qep: req.params.confirm_with_qep,
                },
                &|| progress.cancelled(),
            )?;
            let c = converged::critical_time(
                &sys,
                &profile,
                ConvergedConfig {
                    relative_tolerance: converged::DEFAULT_RELATIVE_TOLERANCE,
                    confirm_with_qep: false,
                },
            )?;
            let (time_error_s, length_error_m) = match (result.onset, c.time_s, c.length_m) {
                (Onset::During { time_s, length_m }, Some(t), Some(l)) => (
                    converged::mesh_error_estimate(time_s, &t),
                    converged::mesh_error_estimate(length_m, &l),
                ),
                // the mesh is stable for a while where the continuum is not
                (Onset::During { time_s, length_m }, _, _) => {
                    (time_s, length_m - sys.initial_length_m)
                }
                _ => (0.0, 0.0),
            };
            CriticalAnswer {
                onset: result.onset,
                method: result.method,
                confirmed: result.confirmed(),
                time_error_s: Some(time_error_s),
                length_error_m: Some(length_error_m),
                order: None,
                elements: model.elements(),
                converged: false,
                probes: result.probes,
            }
        }
    };
    let result = &answer;
    let closed_form = match req.params.profile {
        ProfileInput::ConstantRate { rate_m_s, .. } if rate_m_s > 0.0 => {
            Some(sys.closed_form_elevation_m(rate_m_s).max(0.0))
        }
        ProfileInput::ConstantAcceleration {
            acceleration_m_s2, ..
        } if acceleration_m_s2 > 0.0 => Some(
            sys.closed_form_elevation_accelerating_m(acceleration_m_s2)
                .max(0.0),
        ),
        _ => None,
    };
    let (onset, explanation, max_elevation_m) = match result.onset {
        Onset::Immediate(cause) => {
            let why = match cause {
                ImmediateCause::RateAboveWaveSpeed => format!(
                    "unstable at t = 0: the rate reaches the transverse wave speed of the cable (about {:.1} m/s at {} m)",
                    sys.wave_speed_m_s(),
                    sys.initial_length_m
                ),
                ImmediateCause::Shortening => {
                    "unstable at t = 0: a shortening cable has negative damping and is unstable at every instant".into()
                }
                ImmediateCause::UnstableInitialState => {
                    "unstable at t = 0: the initial state is already beyond the stability limit".into()
                }
            };
            ("immediate", why, Some(sys.initial_length_m))
        }
        Onset::During { time_s, length_m } => (
            "during",
            if result.converged {
                format!(
                    "stable until t* = {time_s:.3} s, when the cable is {length_m:.1} m long \
                     (converged; the safe side of a ±{:.2e} s discretisation error)",
                    result.time_error_s.unwrap_or(0.0)
                )
            } else {
                format!(
                    "stable until t* = {time_s:.3} s, when the cable is {length_m:.1} m long \
                     (on {} elements; estimated discretisation error ±{:.3} s)",
                    result.elements,
                    result.time_error_s.unwrap_or(0.0)
                )
            },
            Some(length_m),
        ),
        Onset::Never { until_s } => (
            "never",
            format!(
                "stable for the whole deployment (checked up to t = {until_s:.3} s, length {:.1} m)",
                profile.kinematics(until_s).length_m
            ),
            None,
        ),
    };
    let method = match result.method {
        SearchMethod::StiffnessInertia => "stiffness_inertia",
        SearchMethod::NegativeDamping => "negative_damping",
        SearchMethod::DivergenceConfirmedByQep => "divergence_confirmed_by_qep",
        SearchMethod::QepScan => "qep_scan",
    };
    let t = match result.onset {
        Onset::Immediate(_) => Some(0.0),
        Onset::During { time_s, .. } => Some(time_s),
        Onset::Never { .. } => None,
    };
    let strength = req.system.cable.breaking_strength()?;
    Ok(CriticalResponse {
        critical_time_s: t,
        critical_time_nondim: t.map(|t| t / sys.time_scale_s()),
        max_elevation_m,
        closed_form_elevation_m: closed_form,
        critical_time_error_s: t.map(|_| result.time_error_s.unwrap_or(0.0)),
        max_elevation_error_m: max_elevation_m.map(|_| result.length_error_m.unwrap_or(0.0)),
        converged: result.converged,
        convergence_order_nondim: result.order,
        onset: onset.into(),
        explanation,
        method: method.into(),
        confirmed_by_qep: result.confirmed,
        qep_probes: result
            .probes
            .iter()
            .map(|p| QepProbeOutput {
                time_s: p.time_s,
                length_m: p.length_m,
                max_real_1_s: p.max_real_1_s,
                stable: p.stable,
                expected_stable: p.expected_stable,
            })
            .collect(),
        tension_at_onset: t.map(|t| {
            crate::contract::tension::TensionOutput::at(&sys, profile.kinematics(t), strength)
        }),
        groups: groups(&sys),
        elements: result.elements,
    })
}

/// A critical-time answer, converged or on one mesh, ready to print.
struct CriticalAnswer {
    onset: Onset,
    method: SearchMethod,
    confirmed: bool,
    time_error_s: Option<f64>,
    length_error_m: Option<f64>,
    order: Option<f64>,
    elements: usize,
    converged: bool,
    probes: Vec<critical::QepProbe>,
}

pub fn safe_rate(req: &SafeRateRequest) -> Result<SafeRateResponse, RequestError> {
    let model = req.system.model()?;
    let sys = model.system;
    let target = require_positive("target_elevation_m", req.params.target_elevation_m)?;
    let closed = sys.net_buoyancy_n / sys.mass_per_length_kg_m - sys.gravity_m_s2 * target;
    let closed_form_rate_m_s = (closed > 0.0).then(|| closed.sqrt());
    let discretisation = req.system.discretisation()?;
    let tolerance = match discretisation {
        chart::Discretisation::Converged { relative_tolerance } => relative_tolerance,
        chart::Discretisation::Elements(_) => converged::DEFAULT_RELATIVE_TOLERANCE,
    };
    let conv = converged::safe_rate(&sys, target, tolerance)?;
    let (max_rate_m_s, max_rate_nondim, max_rate_error_m_s, reason, elements) =
        match (discretisation, conv) {
            (
                chart::Discretisation::Converged { .. },
                ConvergedSafeRate::Rate {
                    rate_m_s,
                    rate_nondim,
                    estimate,
                },
            ) => (
                Some(rate_m_s),
                Some(rate_nondim),
                Some(estimate.error_estimate),
                None,
                estimate.elements,
            ),
            (chart::Discretisation::Converged { .. }, ConvergedSafeRate::NoSafeRate { reason }) => {
                (
                    None,
                    None,
                    None,
                    Some(reason),
                    converged::graded_operators(0).dim(),
                )
            }
            (chart::Discretisation::Elements(n), conv) => {
                match critical::safe_rate(&model, target)? {
                    SafeRate::Rate {
                        rate_m_s,
                        rate_nondim,
                    } => {
                        let error = match conv {
                            ConvergedSafeRate::Rate { estimate, .. } => {
                                converged::mesh_error_estimate(rate_m_s, &estimate)
                            }
                            // the mesh finds a rate where the continuum has none
                            ConvergedSafeRate::NoSafeRate { .. } => rate_m_s,
                        };
                        (Some(rate_m_s), Some(rate_nondim), Some(error), None, n)
                    }
                    SafeRate::NoSafeRate { reason } => (None, None, None, Some(reason), n),
                }
            }
        };
    Ok(SafeRateResponse {
        max_rate_m_s,
        max_rate_nondim,
        closed_form_rate_m_s,
        max_rate_error_m_s,
        converged: req.system.model.elements.is_none(),
        time_to_target_s: max_rate_m_s.map(|v| (target - sys.initial_length_m) / v),
        reason,
        target_elevation_m: target,
        groups: groups(&sys),
        elements,
    })
}

/// Number of points a chart request asks for (for admission limits).
pub fn chart_points(req: &ChartRequest) -> usize {
    req.params
        .rates_m_s
        .count()
        .saturating_mul(req.params.net_buoyancies_n.len().max(1))
}

pub fn chart(
    req: &ChartRequest,
    parallelism: Parallelism,
    progress: &dyn Progress,
) -> Result<ChartResponse, RequestError> {
    let model = req.system.model()?;
    let sys = model.system;
    if chart_points(req) > chart::MAX_CHART_POINTS {
        return Err(InvalidInput::new(
            "rates_m_s.count",
            format!(
                "the chart would have {} points; at most {} are allowed",
                chart_points(req),
                chart::MAX_CHART_POINTS
            ),
        )
        .into());
    }
    let rates = req.params.rates_m_s.rates("rates_m_s")?;
    let buoyancies = if req.params.net_buoyancies_n.is_empty() {
        vec![sys.net_buoyancy_n]
    } else {
        req.params.net_buoyancies_n.clone()
    };
    let report = |done: usize, total: usize| progress.report(done, total);
    let discretisation = req.system.discretisation()?;
    let cancel = || progress.cancelled();
    let series = chart::deployment_chart_cancellable(
        &sys,
        discretisation,
        &rates,
        &buoyancies,
        parallelism,
        &report,
        &cancel,
    )?;
    let Some(series) = series else {
        return Err(RequestError::Cancelled);
    };
    if progress.cancelled() {
        return Err(RequestError::Cancelled);
    }
    Ok(ChartResponse {
        series: series
            .into_iter()
            .map(|s| ChartSeriesOutput {
                net_buoyancy_n: s.net_buoyancy_n,
                wave_speed_m_s: (s.net_buoyancy_n / sys.mass_per_length_kg_m).sqrt(),
                points: s
                    .points
                    .into_iter()
                    .map(|p| ChartPointOutput {
                        rate_m_s: p.rate_m_s,
                        critical_time_s: p.critical_time_s,
                        max_elevation_m: p.max_elevation_m,
                        closed_form_elevation_m: p.closed_form_elevation_m,
                        critical_time_error_s: p.critical_time_error_s,
                        max_elevation_error_m: p.max_elevation_error_m,
                        winch_tension_at_onset_n: s.net_buoyancy_n
                            - sys.mass_per_length_kg_m * sys.gravity_m_s2 * p.max_elevation_m,
                        kinematic_tension_n: sys.mass_per_length_kg_m * p.rate_m_s * p.rate_m_s,
                    })
                    .collect(),
            })
            .collect(),
        elements: chart_elements(discretisation),
        converged: req.system.model.elements.is_none(),
    })
}

/// Elements a chart reports: the uniform mesh, or the finest graded mesh
/// a converged point may use.
pub fn chart_elements(discretisation: chart::Discretisation) -> usize {
    match discretisation {
        chart::Discretisation::Elements(n) => n,
        chart::Discretisation::Converged { .. } => converged::graded_operators(0).dim(),
    }
}
