//! The JSON contract of the GE deployment chart (`POST /api/v1/charts`
//! with `"model": {"kind": "geometrically_exact", ...}` and
//! `stiffness_ratios`): request and response bodies (SI; field names end
//! in their unit; non-dimensional values beside them), validation naming
//! the field, work bounds, the runner [`ge_chart`] and the dispatch of a
//! chart body to either model. The base-excitation frequency response is
//! [`super::base_response`]'s (re-exported here).

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

pub use super::base_response::{
    AnyFrequencyResponseRequest, AnyFrequencyResponseResponse, BaseResponsePointOutput,
    ExcitationKind, GeBaseFrequencyResponseRequest, GeBaseFrequencyResponseResponse,
    MAX_RESPONSE_WORK, ResonanceBandOutput, frequency_response_any, ge_base_frequency_response,
    parse_frequency_response,
};
use crate::contract::ge::numerics::{
    self as ge_numerics, IntegratorOutput, StartStateInput, default_check, default_dt,
    default_growth, default_horizon, newton_config,
};
pub use crate::contract::ge::numerics::{GeChartNumericsInput, GeOnsetKind};
use crate::contract::ge::{GeAerostatInput, GeModelKind, NewtonInput};
use crate::contract::string::dto::RateGrid;
use crate::contract::system::CableInput;
use crate::contract::system::WindFlowInput;
use crate::contract::{Progress, RequestError};
use crate::numerics::aero::{AerostatBody, ForceModel, SteadyFlow};
use crate::numerics::ge::chart::{
    self as ge_chart_core, GeChartRequest as CoreChart, GeChartSystem, GeChartWind,
};
use crate::numerics::ge::critical::{CriticalConfig, GeOnset};
use crate::numerics::parallel::Parallelism;
use crate::numerics::params::{InvalidInput, require_non_negative, require_positive};
use crate::numerics::tether::wind::WindProfile;

/// Largest `points × (horizon / Δt) × elements` of one GE chart.
pub const MAX_CHART_WORK: f64 = 5e9;
/// Largest element count of a GE chart (a dense QEP of size 6n per check).
pub const MAX_CHART_ELEMENTS: usize = 200;

/// The GE cable of a chart; `E*` varies per series (`stiffness_ratios`).
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct GeChartModelInput {
    pub kind: GeModelKind,
    /// Number of 2-node elements.
    #[serde(default = "default_elements")]
    #[schema(example = 20, minimum = 1, maximum = 200)]
    pub elements: usize,
    /// Bending stiffness EI (N m²), the same for every series.
    #[schema(example = 1000.0, minimum = 1e-6, maximum = 1e12)]
    pub bending_stiffness_n_m2: f64,
    /// γ̃ = A_ρ L0²/I_ρ.
    #[serde(default = "default_inertia_ratio")]
    #[schema(example = 1.0, minimum = 1e-6, maximum = 1e12)]
    pub inertia_ratio: f64,
}

fn default_elements() -> usize {
    20
}
fn default_inertia_ratio() -> f64 {
    1.0
}
fn default_initial_length() -> f64 {
    1.0
}
fn default_gravity() -> f64 {
    9.81
}

/// The initial sideways push on the aerostat (thesis Fig. 7.4).
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct PerturbationInput {
    /// Peak forces F0 (N), one series each; 0 is the unperturbed cable.
    #[schema(example = json!([0.0, 200.0, 400.0]), minimum = -1e8, maximum = 1e8)]
    pub forces_n: Vec<f64>,
    /// Linear rise time (s).
    #[serde(default = "default_ramp")]
    #[schema(example = 0.25, minimum = 0.0, maximum = 1e7)]
    pub ramp_s: f64,
    /// Release time (s), at least `ramp_s`.
    #[serde(default = "default_hold")]
    #[schema(example = 1.0, minimum = 0.0, maximum = 1e7)]
    pub hold_s: f64,
}

fn default_ramp() -> f64 {
    0.25
}
fn default_hold() -> f64 {
    1.0
}

/// How the flow loads the aerostat.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(tag = "kind", rename_all = "snake_case")]
#[serde(deny_unknown_fields)]
#[schema(as = GeForceModelInput)]
pub enum ForceModelInput {
    /// Inviscid sphere (thesis (4.4)).
    Thesis {},
    /// Quadratic drag plus added mass, with the aerostat's
    /// `drag_coefficient_nondim` and `reference_area_m2` (default: the
    /// sphere's frontal area).
    Drag {},
}

impl Default for ForceModelInput {
    fn default() -> Self {
        Self::Thesis {}
    }
}

/// Wind on the aerostat (thesis ch. 7.5), one series per A0 of (7.4):
/// the steady profile u0(z) is the one system's `wind.flow` (SPEC §9:
/// `uniform`, `power_law`, `tabulated`) in its `air_density_kg_m3`; the
/// drag model takes the aerostat's drag data.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({
    "flow": {"kind": "tabulated", "points": [
        {"elevation_m": 0.0, "speed_m_s": 0.0}, {"elevation_m": 50.0, "speed_m_s": 3.0},
        {"elevation_m": 100.0, "speed_m_s": 4.2}, {"elevation_m": 200.0, "speed_m_s": 5.6},
        {"elevation_m": 400.0, "speed_m_s": 7.2}, {"elevation_m": 600.0, "speed_m_s": 8.0}]},
    "air_density_kg_m3": 1.12, "force_model": {"kind": "thesis"}, "radius_m": 1.0,
    "amplitudes_nondim": [0.0, 0.5]
}))]
pub struct GeWindInput {
    /// The steady profile u0(z) (SPEC §9 `wind.flow`).
    pub flow: WindFlowInput,
    /// Air density (kg/m³), default 1.225 (ISA sea level; the thesis uses 1.12).
    #[serde(default = "crate::contract::system::default_air_density")]
    #[schema(example = 1.12, minimum = 1e-4, maximum = 100.0)]
    pub air_density_kg_m3: f64,
    /// Inviscid sphere (default) or drag with the aerostat's coefficient.
    #[serde(default)]
    pub force_model: ForceModelInput,
    /// Aerostat radius (m): the sphere of the thesis force model and the
    /// default drag area π r².
    #[serde(default = "default_radius")]
    #[schema(example = 1.0, minimum = 0.001, maximum = 1000.0)]
    pub radius_m: f64,
    /// A0 of u0(1 + A0 sin(k z)), one series each; 0 is the steady profile.
    #[serde(default = "default_amplitudes")]
    #[schema(example = json!([0.0, 0.5, 1.0]), minimum = -10.0, maximum = 10.0)]
    pub amplitudes_nondim: Vec<f64>,
    /// k (1/m).
    #[serde(default = "default_wavenumber")]
    #[schema(example = 0.01, minimum = 0.0, maximum = 1000.0)]
    pub wavenumber_1_m: f64,
}

fn default_radius() -> f64 {
    1.0
}
fn default_amplitudes() -> Vec<f64> {
    vec![0.0]
}
fn default_wavenumber() -> f64 {
    0.01
}

/// `POST /api/v1/charts` for the GE cable: t* and h* against rate, one
/// series per stiffness ratio E* × F0 × buoyancy × A0.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct GeChartRequest {
    pub cable: CableInput,
    pub aerostat: GeAerostatInput,
    /// Initial length L0 (m), the length scale of E* and γ̃.
    #[serde(default = "default_initial_length")]
    #[schema(example = 1.0, minimum = 0.001, maximum = 10000.0)]
    pub initial_length_m: f64,
    #[serde(default = "default_gravity")]
    #[schema(example = 9.81, minimum = 0.01, maximum = 100.0)]
    pub gravity_m_s2: f64,
    pub model: GeChartModelInput,
    /// E* = EA L0²/EI (= GA L0²/EI), one series each.
    #[schema(example = json!([1e3, 1e4, 1e5]), minimum = 1.0, maximum = 1e12)]
    pub stiffness_ratios: Vec<f64>,
    pub rates_m_s: RateGrid,
    /// Net buoyancies (N), one series each; default: the aerostat's.
    #[serde(default)]
    #[schema(minimum = 0.001, maximum = 1e7)]
    pub net_buoyancies_n: Vec<f64>,
    #[serde(default)]
    pub perturbation: Option<PerturbationInput>,
    #[serde(default)]
    pub wind: Option<GeWindInput>,
    #[serde(default)]
    pub numerics: Option<GeChartNumericsInput>,
    #[serde(default)]
    pub newton: Option<NewtonInput>,
    /// The cable's motion when the winch starts (every point).
    #[serde(default)]
    pub start_state: StartStateInput,
}

#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct GeChartPointOutput {
    pub rate_m_s: f64,
    /// ṽ = L̇ √(I_ρ/EI) (thesis §5.6).
    pub rate_nondim: f64,
    pub onset: GeOnsetKind,
    /// t* (s): 0 if unstable at once; absent unless `immediate`/`during`.
    pub critical_time_s: Option<f64>,
    /// h* = L(t*) (m).
    pub max_elevation_m: Option<f64>,
    /// String continuum bound (F/ρA − v²)/g (m), clipped at 0; null
    /// without gravity (no weight: no bound).
    pub string_closed_form_elevation_m: Option<f64>,
    /// Quasi-static bound for an extensible string of this series' axial
    /// stiffness EA = E*·EI/L0² (m), clipped at 0: above
    /// `string_closed_form_elevation_m` below the rate √((F+mg)/2ρA),
    /// below it above that rate; null without gravity.
    pub extensible_closed_form_elevation_m: Option<f64>,
    /// Time at which the search ended without an onset (s).
    pub ended_at_s: Option<f64>,
    pub steps: usize,
    pub qep_solves: usize,
    /// Steps halved and retried after a Newton failure.
    pub step_cuts: usize,
    /// Whether the closed forms beside this point describe its onset
    /// (false with wind, or when the onset is a start-up transient).
    pub closed_form_applies: bool,
    /// Why the closed forms do not apply, when they do not.
    pub closed_form_note: Option<String>,
}

#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct GeChartSeriesOutput {
    pub stiffness_ratio: f64,
    pub perturbation_force_n: f64,
    pub net_buoyancy_n: f64,
    /// A0 of (7.4); absent in still air.
    pub wind_amplitude_nondim: Option<f64>,
    pub points: Vec<GeChartPointOutput>,
}

#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct GeChartResponse {
    pub series: Vec<GeChartSeriesOutput>,
    pub elements: usize,
    /// GE time scale L0 √(I_ρ/EI) (s): t̄ = t / scale.
    pub time_scale_s: f64,
    /// √(F/ρA) of the first buoyancy (m/s).
    pub wave_speed_m_s: f64,
    /// The time-stepping scheme and its numerical dissipation.
    pub integrator: IntegratorOutput,
    pub start_state: StartStateInput,
}

/// The thesis's steady profile u0(z) from the §9 flow (`at`: its field).
fn steady_flow(flow: &WindFlowInput, at: &str) -> Result<SteadyFlow, InvalidInput> {
    match flow.profile(at)? {
        WindProfile::Flow(f) => Ok(f),
        WindProfile::LogLaw { .. } => Err(InvalidInput::new(
            format!("{at}.kind"),
            "the GE chart takes a uniform, power_law or tabulated flow (give a log law as its tabulated points)",
        )),
    }
}

fn wind(
    input: &GeWindInput,
    aerostat: &GeAerostatInput,
    area_default: f64,
) -> Result<GeChartWind, InvalidInput> {
    let base_flow = steady_flow(&input.flow, "wind.flow")?;
    let body = AerostatBody::new(
        require_positive("wind.radius_m", input.radius_m)?,
        require_positive("wind.air_density_kg_m3", input.air_density_kg_m3)?,
        None,
    )?;
    let force_model = match &input.force_model {
        ForceModelInput::Thesis {} => ForceModel::Thesis,
        ForceModelInput::Drag {} => ForceModel::Drag {
            drag_coefficient: match aerostat.drag_coefficient_nondim {
                Some(cd) => require_non_negative("aerostat.drag_coefficient_nondim", cd)?,
                None => {
                    return Err(InvalidInput::new(
                        "aerostat.drag_coefficient_nondim",
                        "is required by the drag force model (wind.force_model)",
                    ));
                }
            },
            reference_area_m2: match aerostat.reference_area_m2 {
                Some(a) => require_positive("aerostat.reference_area_m2", a)?,
                None => area_default * input.radius_m * input.radius_m,
            },
        },
    };
    if input.amplitudes_nondim.is_empty() {
        return Err(InvalidInput::new(
            "wind.amplitudes_nondim",
            "must list at least one value",
        ));
    }
    Ok(GeChartWind {
        base_flow,
        force_model,
        body,
        amplitudes: input.amplitudes_nondim.clone(),
        wavenumber_1_m: input.wavenumber_1_m,
    })
}

/// The GE chart's wind before SPEC §9, refused naming the new place.
fn refuse_old_wind(body: &[u8]) -> Result<(), RequestError> {
    let value: serde_json::Value =
        serde_json::from_slice(body).map_err(|e| RequestError::Malformed(e.to_string()))?;
    let moved = [
        (
            "/wind/profile",
            "wind.profile",
            "wind.flow (SPEC §9: uniform speed_m_s; power_law coefficient_m_s, exponent_nondim, reference_height_m; tabulated points; the thesis's illustrative profile is the tabulated flow of its points)",
        ),
        (
            "/wind/force_model/drag_coefficient",
            "wind.force_model.drag_coefficient",
            "aerostat.drag_coefficient_nondim",
        ),
        (
            "/wind/force_model/reference_area_m2",
            "wind.force_model.reference_area_m2",
            "aerostat.reference_area_m2",
        ),
    ];
    for (pointer, field, place) in moved {
        if value.pointer(pointer).is_some() {
            return Err(InvalidInput::new(field, format!("moved to {place}")).into());
        }
    }
    Ok(())
}

/// The core request, checked (every field named) and bounded.
pub fn prepare_chart(req: &GeChartRequest) -> Result<CoreChart, InvalidInput> {
    let rho_a = req.cable.mass_per_length()?;
    let l0 = require_positive("initial_length_m", req.initial_length_m)?;
    let g = require_non_negative("gravity_m_s2", req.gravity_m_s2)?;
    let m = &req.model;
    if !(1..=MAX_CHART_ELEMENTS).contains(&m.elements) {
        return Err(InvalidInput::new(
            "model.elements",
            format!(
                "must be between 1 and {MAX_CHART_ELEMENTS} for a GE chart, got {}",
                m.elements
            ),
        ));
    }
    let system = GeChartSystem {
        mass_per_length_kg_m: rho_a,
        bending_stiffness_n_m2: require_positive(
            "model.bending_stiffness_n_m2",
            m.bending_stiffness_n_m2,
        )?,
        inertia_ratio: require_positive("model.inertia_ratio", m.inertia_ratio)?,
        aerostat_mass_kg: req.aerostat.mass("aerostat")?,
        link_length_m: req.aerostat.link_length("aerostat")?,
        initial_length_m: l0,
        gravity_m_s2: g,
        elements: m.elements,
    };
    let rates = req.rates_m_s.rates("rates_m_s")?;
    let buoyancies = if req.net_buoyancies_n.is_empty() {
        vec![req.aerostat.net_buoyancy("aerostat")?]
    } else {
        req.net_buoyancies_n.clone()
    };
    let (forces, ramp, hold) = match &req.perturbation {
        None => (vec![0.0], default_ramp(), default_hold()),
        Some(p) => (p.forces_n.clone(), p.ramp_s, p.hold_s),
    };
    let defaults = GeChartNumericsInput {
        time_step_s: default_dt(),
        check_every_steps: default_check(),
        horizon_s: default_horizon(),
        growth_tolerance_1_s: default_growth(),
        scheme: ge_numerics::default_scheme(),
        rho_infinity_nondim: None,
        max_step_cuts: ge_numerics::default_max_step_cuts(),
    };
    let n = req.numerics.as_ref().unwrap_or(&defaults);
    if n.check_every_steps > 100_000 {
        return Err(InvalidInput::new(
            "numerics.check_every_steps",
            "must be at most 100000",
        ));
    }
    let config = CriticalConfig {
        time_step_s: n.time_step_s,
        check_every: n.check_every_steps,
        growth_tolerance_1_s: n.growth_tolerance_1_s,
        horizon_s: n.horizon_s,
        newton: newton_config(&req.newton)?,
        scheme: ge_numerics::scheme(n.scheme, n.rho_infinity_nondim, "numerics")?,
        max_step_cuts: ge_numerics::step_cuts(n.max_step_cuts, "numerics")?,
    };
    let core = CoreChart {
        system,
        rates_m_s: rates,
        stiffness_ratios: req.stiffness_ratios.clone(),
        perturbation_forces_n: forces,
        perturbation_ramp_s: ramp,
        perturbation_hold_s: hold,
        net_buoyancies_n: buoyancies,
        // A flow calm everywhere (the §9 system's still air) is the
        // still-air chart: no wind loads.
        wind: req
            .wind
            .as_ref()
            .filter(|w| !w.flow.is_calm())
            .map(|w| wind(w, &req.aerostat, std::f64::consts::PI))
            .transpose()?,
        config,
        start: req.start_state.into(),
    };
    // names the field: `perturbation.*`, `stiffness_ratios[i]`, …
    core.validate().map_err(|e| {
        let field = match e.field.as_str() {
            "perturbation_forces_n" => "perturbation.forces_n".to_string(),
            f if f.starts_with("perturbation_forces_n[") => {
                f.replacen("perturbation_forces_n", "perturbation.forces_n", 1)
            }
            f if f.starts_with("wind.amplitudes") => {
                f.replacen("wind.amplitudes", "wind.amplitudes_nondim", 1)
            }
            f => f.to_string(),
        };
        InvalidInput::new(field, e.reason)
    })?;
    let work = core.point_count() as f64
        * (config.horizon_s / config.time_step_s)
        * system.elements as f64;
    if work > MAX_CHART_WORK {
        return Err(InvalidInput::new(
            "numerics.horizon_s",
            format!(
                "{} points × {:.0} steps × {} elements exceeds the work limit {MAX_CHART_WORK:.0e}",
                core.point_count(),
                config.horizon_s / config.time_step_s,
                system.elements
            ),
        ));
    }
    Ok(core)
}

/// Number of points a GE chart asks for (admission limits).
pub fn chart_points(req: &GeChartRequest) -> usize {
    let n = |v: usize| v.max(1);
    req.rates_m_s
        .count()
        .saturating_mul(n(req.stiffness_ratios.len()))
        .saturating_mul(n(req.perturbation.as_ref().map_or(1, |p| p.forces_n.len())))
        .saturating_mul(n(req.net_buoyancies_n.len()))
        .saturating_mul(n(req
            .wind
            .as_ref()
            .map_or(1, |w| w.amplitudes_nondim.len())))
}

/// Computes a GE chart; progress counts points, cancellation stops the
/// running searches.
pub fn ge_chart(
    req: &GeChartRequest,
    parallelism: Parallelism,
    progress: &dyn Progress,
) -> Result<GeChartResponse, RequestError> {
    let total = prepare_chart(req)?.point_count();
    let points = ge_chart_points(req, 0..total, parallelism, progress)?;
    ge_chart_assemble(req, points)
}

/// The points `range` of a GE chart (numbered series-major, as
/// [`ge_chart_core::chart_points_range`]): one chunk of a distributed job.
pub fn ge_chart_points(
    req: &GeChartRequest,
    range: std::ops::Range<usize>,
    parallelism: Parallelism,
    progress: &dyn Progress,
) -> Result<Vec<GeChartPointOutput>, RequestError> {
    let core = prepare_chart(req)?;
    if progress.cancelled() {
        return Err(RequestError::Cancelled);
    }
    let cancel = || progress.cancelled();
    let report = |done: usize, total: usize| progress.report(done, total);
    let flat = ge_chart_core::chart_points_range(&core, range, parallelism, &report, &cancel)?;
    if progress.cancelled() {
        return Err(RequestError::Cancelled);
    }
    let model = core.system.model(core.stiffness_ratios[0])?;
    let scale = model.section.time_scale_s(core.system.initial_length_m);
    Ok(flat
        .into_iter()
        .map(|p| {
            let (onset, ended_at_s) = match p.onset {
                GeOnset::Immediate { .. } => (GeOnsetKind::Immediate, None),
                GeOnset::During { .. } => (GeOnsetKind::During, None),
                GeOnset::Never { until_s } => (GeOnsetKind::Never, Some(until_s)),
                GeOnset::NewtonFailed(f) => (GeOnsetKind::NewtonFailed, Some(f.time_s)),
                GeOnset::SpectrumFailed { time_s } => (GeOnsetKind::SpectrumFailed, Some(time_s)),
                GeOnset::Cancelled { time_s } => (GeOnsetKind::Cancelled, Some(time_s)),
            };
            GeChartPointOutput {
                rate_m_s: p.rate_m_s,
                rate_nondim: p.rate_m_s * scale / core.system.initial_length_m,
                onset,
                critical_time_s: p.critical_time_s,
                max_elevation_m: p.max_elevation_m,
                string_closed_form_elevation_m: crate::contract::ge_critical::finite(
                    p.string_closed_form_m,
                ),
                extensible_closed_form_elevation_m: crate::contract::ge_critical::finite(
                    p.extensible_closed_form_m,
                ),
                ended_at_s,
                steps: p.steps,
                qep_solves: p.qep_solves,
                step_cuts: p.step_cuts,
                closed_form_applies: p.closed_form.applies(),
                closed_form_note: p.closed_form.reason(),
            }
        })
        .collect())
}

/// The GE chart from its points `0..chart_points(req)` in order (those of
/// one process, or the chunks of a distributed job put together).
pub fn ge_chart_assemble(
    req: &GeChartRequest,
    points: Vec<GeChartPointOutput>,
) -> Result<GeChartResponse, RequestError> {
    let core = prepare_chart(req)?;
    let model = core.system.model(core.stiffness_ratios[0])?;
    let scale = model.section.time_scale_s(core.system.initial_length_m);
    let rates = core.rates_m_s.len().max(1);
    let mut points = points.into_iter();
    let mut series = Vec::new();
    for &es in &core.stiffness_ratios {
        for &f0 in &core.perturbation_forces_n {
            for &fb in &core.net_buoyancies_n {
                for a0 in core.wind_amplitudes() {
                    series.push(GeChartSeriesOutput {
                        stiffness_ratio: es,
                        perturbation_force_n: f0,
                        net_buoyancy_n: fb,
                        wind_amplitude_nondim: a0,
                        points: points.by_ref().take(rates).collect(),
                    });
                }
            }
        }
    }
    Ok(GeChartResponse {
        series,
        elements: core.system.elements,
        time_scale_s: scale,
        wave_speed_m_s: (core.net_buoyancies_n[0] / core.system.mass_per_length_kg_m).sqrt(),
        integrator: IntegratorOutput::new(core.config.scheme, core.config.max_step_cuts),
        start_state: req.start_state,
    })
}

// ---------------------------------------------------------------- dispatch

/// `POST /api/v1/charts` for either model: `model.kind` picks the linear
/// string (`linear_string`, the default) or the GE cable
/// (`geometrically_exact`, with `stiffness_ratios`).
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(untagged)]
pub enum AnyChartRequest {
    /// `model.kind = "geometrically_exact"`.
    GeometricallyExact(Box<GeChartRequest>),
    /// `model.kind = "linear_string"` (or absent).
    LinearString(crate::contract::dto::ChartRequest),
}

/// The answer of [`AnyChartRequest`].
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(untagged)]
pub enum AnyChartResponse {
    GeometricallyExact(GeChartResponse),
    LinearString(crate::contract::dto::ChartResponse),
}

/// Parses a chart body, choosing the model by `model.kind`.
pub fn parse_chart(body: &[u8]) -> Result<AnyChartRequest, RequestError> {
    let value: serde_json::Value =
        serde_json::from_slice(body).map_err(|e| RequestError::Malformed(e.to_string()))?;
    if value.pointer("/model/kind").and_then(|k| k.as_str()) == Some("geometrically_exact") {
        refuse_old_wind(body)?;
        let req: Box<GeChartRequest> =
            crate::contract::parse::parse_ge_keeping(body, "the GE chart", "wind")?;
        req.check_ranges()?;
        Ok(AnyChartRequest::GeometricallyExact(req))
    } else {
        crate::contract::parse(body).map(AnyChartRequest::LinearString)
    }
}
