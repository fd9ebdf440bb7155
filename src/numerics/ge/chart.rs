//! Deployment charts of the GE cable (thesis Figs 7.2–7.4, 7.6–7.7): `t*`
//! and `h* = L(t*)` against a grid of constant rates, one series per
//! stiffness ratio `E*`, tip perturbation `F0`, net buoyancy and (with
//! wind) amplitude `A0` of the perturbed flow (7.4). Every
//! point is an independent [`critical_time`](super::critical::critical_time) search from `L0`; the points
//! fan out on rayon when asked ([`Parallelism::Rayon`]) and the result is
//! the same bit for bit as the serial sweep.

use std::sync::atomic::{AtomicUsize, Ordering};

use rayon::prelude::*;

use super::critical::{
    CriticalConfig, CriticalProblem, GeOnset, StartState, TipPerturbation, critical_time_observed,
};
use super::extensible::ExtensibleString;
use super::{GeModel, Section, TipBody};
use crate::numerics::aero::{Aerodynamics, AerostatBody, AirFlow, ForceModel, SteadyFlow};
use crate::numerics::parallel::Parallelism;
use crate::numerics::params::{InvalidInput, require_non_negative, require_positive};
use crate::numerics::profile::Profile;

/// Largest number of points (rates × series) of one GE chart.
pub const MAX_GE_CHART_POINTS: usize = 2_000;

/// The cable and aerostat of a GE chart (SI); `E*` varies per series.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GeChartSystem {
    pub mass_per_length_kg_m: f64,
    pub bending_stiffness_n_m2: f64,
    /// `γ̃ = A_ρ L0² / I_ρ`.
    pub inertia_ratio: f64,
    pub aerostat_mass_kg: f64,
    pub link_length_m: f64,
    pub initial_length_m: f64,
    pub gravity_m_s2: f64,
    pub elements: usize,
}

impl GeChartSystem {
    /// Table 7.1 with 20 elements.
    pub fn table_7_1() -> Self {
        Self {
            mass_per_length_kg_m: 7800.0 * 1e-5,
            bending_stiffness_n_m2: 1000.0,
            inertia_ratio: 1.0,
            aerostat_mass_kg: 10.0,
            link_length_m: 0.0,
            initial_length_m: 1.0,
            gravity_m_s2: 9.81,
            elements: 20,
        }
    }

    /// The discretised cable for one stiffness ratio.
    pub fn model(&self, stiffness_ratio: f64) -> Result<GeModel, InvalidInput> {
        let section = Section::from_ratios(
            self.bending_stiffness_n_m2,
            stiffness_ratio,
            self.inertia_ratio,
            self.mass_per_length_kg_m,
            self.initial_length_m,
        )?;
        GeModel::new(
            section,
            self.elements,
            TipBody {
                mass_kg: self.aerostat_mass_kg,
                link_length_m: self.link_length_m,
            },
            self.gravity_m_s2,
        )
    }
}

/// Air flow on the aerostat for a chart (thesis ch. 7.5): a steady
/// profile `u0(z)`, perturbed as (7.4) `u0 (1 + A0 sin(k z))` with one
/// series per amplitude `A0` (0: the steady profile itself).
#[derive(Clone, Debug, PartialEq)]
pub struct GeChartWind {
    pub base_flow: SteadyFlow,
    pub force_model: ForceModel,
    pub body: AerostatBody,
    pub amplitudes: Vec<f64>,
    /// `k` of (7.4) (1/m); the thesis uses 0.01.
    pub wavenumber_1_m: f64,
}

impl GeChartWind {
    /// An illustrative tabulated boundary-layer profile (speed rising from
    /// 0 at the ground to 8 m/s at 600 m, then uniform) — the shape of the
    /// thesis's Fig. 7.5(a), *not* its data (Teixeira et al. 2008, which is
    /// not reproduced here). Thesis aerostat: sphere of radius 1 m in air
    /// of 1.12 kg/m³, inviscid (thesis) force model; `k = 0.01 /m`.
    pub fn illustrative(amplitudes: Vec<f64>) -> Self {
        let table = [
            (0.0, 0.0),
            (50.0, 3.0),
            (100.0, 4.2),
            (200.0, 5.6),
            (400.0, 7.2),
            (600.0, 8.0),
            (2000.0, 8.0),
        ];
        Self {
            base_flow: SteadyFlow::tabulated(&table, "wind.profile").expect("valid table"),
            force_model: ForceModel::Thesis,
            body: AerostatBody::new(1.0, 1.12, None).expect("valid body"),
            amplitudes,
            wavenumber_1_m: 0.01,
        }
    }

    fn aerodynamics(
        &self,
        amplitude: f64,
        aerostat_mass_kg: f64,
    ) -> Result<Aerodynamics, InvalidInput> {
        let flow = if amplitude == 0.0 {
            AirFlow::Steady(self.base_flow.clone())
        } else {
            AirFlow::perturbed(self.base_flow.clone(), amplitude, self.wavenumber_1_m)?
        };
        Aerodynamics::new(flow, self.force_model, self.body, aerostat_mass_kg)
    }
}

/// What the chart sweeps.
#[derive(Clone, Debug, PartialEq)]
pub struct GeChartRequest {
    pub system: GeChartSystem,
    pub rates_m_s: Vec<f64>,
    pub stiffness_ratios: Vec<f64>,
    /// Peak tip perturbations `F0` (N); 0 is the unperturbed cable.
    pub perturbation_forces_n: Vec<f64>,
    /// Rise and release times of the perturbation (s).
    pub perturbation_ramp_s: f64,
    pub perturbation_hold_s: f64,
    pub net_buoyancies_n: Vec<f64>,
    /// Air flow; `None`: still air.
    pub wind: Option<GeChartWind>,
    pub config: CriticalConfig,
    /// The cable's state when the winch starts (every point).
    pub start: StartState,
}

/// One point of a series.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GeChartPoint {
    pub rate_m_s: f64,
    /// `t*` (s): 0 when unstable at once, `None` when stable over the horizon
    /// or when the march failed (see `onset`).
    pub critical_time_s: Option<f64>,
    /// `h* = L(t*)` (m).
    pub max_elevation_m: Option<f64>,
    /// `(F/ρA − v²)/g` (m), the string's continuum bound, clipped at zero.
    pub string_closed_form_m: f64,
    /// The same bound for this series' axial stiffness, quasi-static
    /// ([`super::extensible`]), clipped at zero (m).
    pub extensible_closed_form_m: f64,
    pub onset: GeOnset,
    pub steps: usize,
    pub qep_solves: usize,
    /// Steps halved and retried after a Newton failure.
    pub step_cuts: usize,
    /// Whether the closed forms describe this onset.
    pub closed_form: ClosedFormVerdict,
}

/// Relative departure of the onset from the quasi-static state, in the
/// critical length, beyond which the closed forms are flagged as not
/// applying ([`closed_form_verdict`]).
pub const CLOSED_FORM_TOLERANCE: f64 = 0.02;

/// Whether the quasi-static closed forms printed beside a GE onset
/// describe it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ClosedFormVerdict {
    /// The onset is the quasi-static loss of tension the closed forms
    /// describe (or the search ended without one).
    Applies,
    /// Air flow loads the aerostat; the closed forms are for still air.
    Wind,
    /// The axial force at the guide at `t*` departs from the quasi-static
    /// (steady-payout) tension by `departure_n`, which alone moves the
    /// onset by `length_shift_m`: the onset is set by a start-up transient
    /// (axial ringing, the tip perturbation), not by the steady loss of
    /// tension.
    Transient {
        departure_n: f64,
        length_shift_m: f64,
        closed_form_m: f64,
    },
}

impl ClosedFormVerdict {
    pub fn applies(&self) -> bool {
        matches!(self, Self::Applies)
    }

    /// Why the closed forms do not apply, in words.
    pub fn reason(&self) -> Option<String> {
        match *self {
            Self::Applies => None,
            Self::Wind => {
                Some("air flow loads the aerostat; the closed forms are for still air".to_string())
            }
            Self::Transient {
                departure_n,
                length_shift_m,
                closed_form_m,
            } => Some(format!(
                "the onset is a start-up transient: at t* the axial force at the guide departs from \
                 the quasi-static tension by {departure_n:+.1} N, which alone moves the onset by \
                 {length_shift_m:.1} m ({:.1} % of the quasi-static {closed_form_m:.1} m, more than \
                 {:.0} %); the closed forms assume a steady payout",
                100.0 * length_shift_m.abs() / closed_form_m.max(f64::MIN_POSITIVE),
                100.0 * CLOSED_FORM_TOLERANCE
            )),
        }
    }
}

/// Judges the closed forms against a constant-rate onset: with wind they
/// never apply; otherwise the axial force `N` in the element at the guide
/// at `t*` is compared with the steady-payout tension `N_qs` there
/// ([`ExtensibleString::tension_n`]), and the closed forms apply when the
/// departure moves the critical length by at most
/// [`CLOSED_FORM_TOLERANCE`] of the quasi-static one:
/// `|N − N_qs| (1 + β)/(μ g) ≤ tol · L*`.
pub fn closed_form_verdict(
    model: &GeModel,
    rate_m_s: f64,
    net_buoyancy_n: f64,
    windy: bool,
    result: &super::critical::GeCriticalTime,
) -> ClosedFormVerdict {
    if windy {
        return ClosedFormVerdict::Wind;
    }
    let (GeOnset::During { length_m, .. }, Some(force)) =
        (result.onset, result.onset_root_axial_force_n)
    else {
        return ClosedFormVerdict::Applies;
    };
    let string = ExtensibleString {
        net_buoyancy_n,
        aerostat_mass_kg: model.tip.mass_kg,
        mass_per_length_kg_m: model.section.mass_per_length_kg_m,
        axial_stiffness_n: model.section.axial_stiffness_n,
        gravity_m_s2: model.gravity_m_s2,
    };
    let x = 0.5 * length_m / model.elements as f64;
    let departure_n = force - string.tension_n(rate_m_s, length_m, x);
    let length_shift_m = departure_n * string.length_per_tension_m_n(rate_m_s);
    let closed_form_m = string.critical_length_m(rate_m_s).unwrap_or(0.0);
    if length_shift_m.abs() <= CLOSED_FORM_TOLERANCE * closed_form_m.max(length_m) {
        ClosedFormVerdict::Applies
    } else {
        ClosedFormVerdict::Transient {
            departure_n,
            length_shift_m,
            closed_form_m,
        }
    }
}

/// One series: a stiffness ratio, perturbation, buoyancy and flow amplitude.
#[derive(Clone, Debug, PartialEq)]
pub struct GeChartSeries {
    pub stiffness_ratio: f64,
    pub perturbation_force_n: f64,
    pub net_buoyancy_n: f64,
    /// `A0` of (7.4); `None` in still air.
    pub wind_amplitude: Option<f64>,
    pub points: Vec<GeChartPoint>,
}

impl GeChartRequest {
    /// Table 7.1, unperturbed, one buoyancy (1000 N).
    pub fn table_7_1(rates_m_s: Vec<f64>, stiffness_ratios: Vec<f64>) -> Self {
        Self {
            system: GeChartSystem::table_7_1(),
            rates_m_s,
            stiffness_ratios,
            perturbation_forces_n: vec![0.0],
            perturbation_ramp_s: 0.25,
            perturbation_hold_s: 1.0,
            net_buoyancies_n: vec![1000.0],
            wind: None,
            config: CriticalConfig::default(),
            start: StartState::AtRest,
        }
    }

    pub fn wind_amplitudes(&self) -> Vec<Option<f64>> {
        match &self.wind {
            None => vec![None],
            Some(w) => w.amplitudes.iter().map(|&a| Some(a)).collect(),
        }
    }

    pub fn point_count(&self) -> usize {
        self.rates_m_s
            .len()
            .saturating_mul(self.wind_amplitudes().len())
            .saturating_mul(self.stiffness_ratios.len())
            .saturating_mul(self.perturbation_forces_n.len())
            .saturating_mul(self.net_buoyancies_n.len())
    }

    pub fn validate(&self) -> Result<(), InvalidInput> {
        for (field, list) in [
            ("rates_m_s", &self.rates_m_s),
            ("stiffness_ratios", &self.stiffness_ratios),
            ("perturbation_forces_n", &self.perturbation_forces_n),
            ("net_buoyancies_n", &self.net_buoyancies_n),
        ] {
            if list.is_empty() {
                return Err(InvalidInput::new(field, "must list at least one value"));
            }
        }
        for (i, &v) in self.rates_m_s.iter().enumerate() {
            require_positive(&format!("rates_m_s[{i}]"), v)?;
            if v > 1e4 {
                return Err(InvalidInput::new(
                    format!("rates_m_s[{i}]"),
                    format!("must be at most 1e4 m/s, got {v}"),
                ));
            }
        }
        for (i, &v) in self.stiffness_ratios.iter().enumerate() {
            require_positive(&format!("stiffness_ratios[{i}]"), v)?;
        }
        for (i, &v) in self.perturbation_forces_n.iter().enumerate() {
            require_non_negative(&format!("perturbation_forces_n[{i}]"), v)?;
        }
        for (i, &v) in self.net_buoyancies_n.iter().enumerate() {
            require_positive(&format!("net_buoyancies_n[{i}]"), v)?;
        }
        TipPerturbation {
            force_n: 0.0,
            ramp_s: self.perturbation_ramp_s,
            hold_s: self.perturbation_hold_s,
        }
        .validate()?;
        if let Some(w) = &self.wind {
            if w.amplitudes.is_empty() {
                return Err(InvalidInput::new(
                    "wind.amplitudes",
                    "must list at least one value",
                ));
            }
            crate::numerics::params::require_finite("wind.wavenumber_1_m", w.wavenumber_1_m)?;
            for (i, &a) in w.amplitudes.iter().enumerate() {
                crate::numerics::params::require_finite(&format!("wind.amplitudes[{i}]"), a)?;
                w.aerodynamics(a, self.system.aerostat_mass_kg)
                    .map_err(|e| InvalidInput::new(format!("wind.amplitudes[{i}]"), e.reason))?;
            }
        }
        self.config.validate()?;
        let total = self.point_count();
        if total > MAX_GE_CHART_POINTS {
            return Err(InvalidInput::new(
                "rates_m_s",
                format!(
                    "the chart would have {total} points; at most {MAX_GE_CHART_POINTS} are allowed"
                ),
            ));
        }
        for (i, &es) in self.stiffness_ratios.iter().enumerate() {
            self.system
                .model(es)
                .map_err(|e| InvalidInput::new(format!("stiffness_ratios[{i}]"), e.reason))?;
        }
        Ok(())
    }
}

/// One point: constant-rate lengthening from `L0`, no target.
#[allow(clippy::too_many_arguments)]
pub fn chart_point(
    model: &GeModel,
    system: &GeChartSystem,
    rate_m_s: f64,
    net_buoyancy_n: f64,
    perturbation: Option<TipPerturbation>,
    aero: Option<Aerodynamics>,
    config: &CriticalConfig,
    start: StartState,
    cancel: &(dyn Fn() -> bool + Sync),
) -> Result<GeChartPoint, InvalidInput> {
    chart_point_observed(
        model,
        system,
        rate_m_s,
        net_buoyancy_n,
        perturbation,
        aero,
        config,
        start,
        cancel,
        &|_| {},
    )
}

/// [`chart_point`], reporting the fraction of its march (see
/// [`critical_time_observed`]).
#[allow(clippy::too_many_arguments)]
pub fn chart_point_observed(
    model: &GeModel,
    system: &GeChartSystem,
    rate_m_s: f64,
    net_buoyancy_n: f64,
    perturbation: Option<TipPerturbation>,
    aero: Option<Aerodynamics>,
    config: &CriticalConfig,
    start: StartState,
    cancel: &(dyn Fn() -> bool + Sync),
    march: &(dyn Fn(f64) + Sync),
) -> Result<GeChartPoint, InvalidInput> {
    let profile = Profile::constant_rate(system.initial_length_m, rate_m_s, None)?;
    let windy = aero.is_some();
    let problem = CriticalProblem {
        profile: profile.clone(),
        net_buoyancy_n,
        perturbation,
        aero,
        start,
    };
    let r = critical_time_observed(model, &problem, config, cancel, march)?;
    let string = |axial_stiffness_n: f64| {
        ExtensibleString {
            net_buoyancy_n,
            aerostat_mass_kg: model.tip.mass_kg,
            mass_per_length_kg_m: system.mass_per_length_kg_m,
            axial_stiffness_n,
            gravity_m_s2: system.gravity_m_s2,
        }
        .critical_length_m(rate_m_s)
        .unwrap_or(0.0)
    };
    Ok(GeChartPoint {
        rate_m_s,
        critical_time_s: r.time_s(),
        max_elevation_m: r.length_m(&profile),
        string_closed_form_m: string(f64::INFINITY),
        extensible_closed_form_m: string(model.section.axial_stiffness_n),
        onset: r.onset,
        steps: r.steps,
        qep_solves: r.qep_solves,
        step_cuts: r.step_cuts,
        closed_form: closed_form_verdict(model, rate_m_s, net_buoyancy_n, windy, &r),
    })
}

/// Units of progress per chart point: `progress(done, total)` counts
/// thousandths of points, so that a chart of a few slow points (about a
/// second each) shows progress within each point (its simulated time over
/// its horizon), not only as points finish.
pub const PROGRESS_UNITS_PER_POINT: usize = 1000;

/// Computes the chart. `progress(done, total)` is called as the searches
/// advance, in [`PROGRESS_UNITS_PER_POINT`]ths of a point (from worker
/// threads, in no particular order; `done` never decreases); `cancel()` is
/// polled during each search.
pub fn deployment_chart(
    request: &GeChartRequest,
    parallelism: Parallelism,
    progress: &(dyn Fn(usize, usize) + Sync),
    cancel: &(dyn Fn() -> bool + Sync),
) -> Result<Vec<GeChartSeries>, InvalidInput> {
    let flat = chart_points_range(
        request,
        0..request.point_count(),
        parallelism,
        progress,
        cancel,
    )?;
    Ok(chart_series(request, flat))
}

/// The series of a chart (stiffness ratio, perturbation force, buoyancy,
/// wind amplitude; index of the model), in the order of the flat points.
fn series_keys(request: &GeChartRequest) -> Vec<(usize, f64, f64, f64, Option<f64>)> {
    let mut series_keys = Vec::new();
    for (m, &es) in request.stiffness_ratios.iter().enumerate() {
        for &f0 in &request.perturbation_forces_n {
            for &fb in &request.net_buoyancies_n {
                for a0 in request.wind_amplitudes() {
                    series_keys.push((m, es, f0, fb, a0));
                }
            }
        }
    }
    series_keys
}

/// Groups the flat points `0..point_count()` (series-major) into series.
pub fn chart_series(request: &GeChartRequest, flat: Vec<GeChartPoint>) -> Vec<GeChartSeries> {
    let rates = request.rates_m_s.len().max(1);
    series_keys(request)
        .iter()
        .zip(flat.chunks(rates))
        .map(|(&(_, es, f0, fb, a0), pts)| GeChartSeries {
            stiffness_ratio: es,
            perturbation_force_n: f0,
            net_buoyancy_n: fb,
            wind_amplitude: a0,
            points: pts.to_vec(),
        })
        .collect()
}

/// The points `range` of the chart, numbered series-major (point `i` is
/// rate `i % rates` of series `i / rates`): each point is independent of
/// the others, so any split of `0..point_count()` gives the same points
/// (the chunks of a distributed job). Progress counts thousandths of the
/// range's points.
pub fn chart_points_range(
    request: &GeChartRequest,
    range: std::ops::Range<usize>,
    parallelism: Parallelism,
    progress: &(dyn Fn(usize, usize) + Sync),
    cancel: &(dyn Fn() -> bool + Sync),
) -> Result<Vec<GeChartPoint>, InvalidInput> {
    request.validate()?;
    let models = request
        .stiffness_ratios
        .iter()
        .map(|&es| request.system.model(es))
        .collect::<Result<Vec<_>, _>>()?;
    let series_keys = series_keys(request);
    let rates = &request.rates_m_s;
    let range = range.start.min(request.point_count())..range.end.min(request.point_count());
    let total = range.len();
    let done = AtomicUsize::new(0);
    let units = PROGRESS_UNITS_PER_POINT;
    let total_units = total * units;
    let point = |index: usize| -> Result<GeChartPoint, InvalidInput> {
        // Units of this point reported so far (only this closure's thread adds).
        let mine = AtomicUsize::new(0);
        let advance = |to: usize| {
            let before = mine.load(Ordering::Relaxed);
            if to > before {
                mine.store(to, Ordering::Relaxed);
                let now = done.fetch_add(to - before, Ordering::Relaxed) + (to - before);
                progress(now, total_units);
            }
        };
        let march = |fraction: f64| {
            advance(((fraction.clamp(0.0, 1.0) * units as f64) as usize).min(units - 1));
        };
        let (s, r) = (index / rates.len(), index % rates.len());
        let (m, _, f0, fb, a0) = series_keys[s];
        let aero = match (&request.wind, a0) {
            (Some(w), Some(a)) => Some(w.aerodynamics(a, request.system.aerostat_mass_kg)?),
            _ => None,
        };
        let perturbation = (f0 > 0.0).then_some(TipPerturbation {
            force_n: f0,
            ramp_s: request.perturbation_ramp_s,
            hold_s: request.perturbation_hold_s,
        });
        let p = chart_point_observed(
            &models[m],
            &request.system,
            rates[r],
            fb,
            perturbation,
            aero,
            &request.config,
            request.start,
            cancel,
            &march,
        );
        advance(units);
        p
    };
    match parallelism {
        Parallelism::Serial => range.map(point).collect(),
        Parallelism::Rayon => range.into_par_iter().map(point).collect(),
    }
}
