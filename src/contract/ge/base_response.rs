//! The JSON contract of the GE base-excitation frequency response
//! (`POST /api/v1/frequency-response` with `"excitation": "base"`, thesis
//! ch. 8): request and response bodies (SI; non-dimensional values
//! beside them), validation naming the field, the runner
//! [`ge_base_frequency_response`], and the dispatch of a
//! frequency-response body to the base or the wind (linear string) kind.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::critical::default_initial_length;
use crate::contract::ge::numerics::newton_config;
use crate::contract::ge::{GeAerostatInput, GeModelInput, NewtonInput};
use crate::contract::system::CableInput;
use crate::contract::system::grid::BaseFrequencyGridInput;
use crate::contract::system::input::ProfileInput;
use crate::contract::{Progress, RequestError};
use crate::numerics::ge::base::{self, BaseExcitationProblem};
use crate::numerics::ge::element::TipLoad;
use crate::numerics::ge::reduced;
use crate::numerics::ge::solver::LengthHistory;
use crate::numerics::ge::{GeModel, TipBody};
use crate::numerics::parallel::Parallelism;
use crate::numerics::params::{InvalidInput, require_non_negative, require_positive};
use crate::numerics::profile::Profile;

/// Largest `frequencies × steps × elements` of one base-excitation sweep.
pub const MAX_RESPONSE_WORK: f64 = 2e9;

/// The excitation of a frequency response.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, ToSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum ExcitationKind {
    /// The platform moves R0 sin(ω0 t) across the guide (thesis ch. 8).
    Base,
}

/// `POST /api/v1/frequency-response` with `"excitation": "base"`: the GE
/// cable on a platform shaken across the guide; amplitude gain (8.3)
/// against ω0, with the two-DOF model's resonance bands (8.9).
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct GeBaseFrequencyResponseRequest {
    pub excitation: ExcitationKind,
    pub cable: CableInput,
    /// The aerostat; absent: the bare cantilever of thesis ch. 8.
    #[serde(default)]
    pub aerostat: Option<GeAerostatInput>,
    #[serde(default = "default_initial_length")]
    #[schema(example = 1.0, minimum = 0.001, maximum = 10000.0)]
    pub initial_length_m: f64,
    /// Gravity on the cable (m/s²); thesis ch. 8 has none.
    #[serde(default)]
    #[schema(example = 0.0, minimum = 0.0, maximum = 100.0)]
    pub gravity_m_s2: f64,
    pub model: GeModelInput,
    /// Deployment profile; absent: constant length.
    #[serde(default)]
    pub profile: Option<ProfileInput>,
    /// Platform amplitude R0 (m).
    #[schema(example = 0.001, minimum = 1e-9, maximum = 1000.0)]
    pub amplitude_m: f64,
    /// ω0 (rad/s): a list, or `{min, max, count}` evenly spaced.
    pub frequencies_rad_s: BaseFrequencyGridInput,
    /// The normalising run's ω (rad/s); default ω̄ = 0.01 as in (8.3).
    #[serde(default)]
    #[schema(minimum = 0.0, maximum = 10000.0)]
    pub reference_frequency_rad_s: Option<f64>,
    /// Duration of each run (s).
    #[schema(example = 0.883, minimum = 1e-6, maximum = 1e7)]
    pub duration_s: f64,
    /// Newmark step (s).
    #[schema(example = 0.000442, minimum = 1e-9, maximum = 1000.0)]
    pub time_step_s: f64,
    /// ε of the two-DOF model (8.8)–(8.9) for the predicted bands.
    #[serde(default = "default_epsilon")]
    #[schema(example = 0.2, minimum = 0.0, maximum = 10.0)]
    pub reduced_model_epsilon_nondim: f64,
    #[serde(default)]
    pub newton: Option<NewtonInput>,
}

fn default_epsilon() -> f64 {
    0.2
}

#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct BaseResponsePointOutput {
    pub frequency_rad_s: f64,
    /// ω̄ = ω L0 √(I_ρ/EI).
    pub frequency_nondim: f64,
    /// Amplitude gain (8.3) (dB); null when it has no finite value (the
    /// run or the reference run failed before moving the tip).
    pub gain_db: Option<f64>,
    /// max |u2(1,t) + r(t)| (m).
    pub max_tip_amplitude_m: f64,
    /// False if Newton failed before the end of the run.
    pub completed: bool,
}

#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct ResonanceBandOutput {
    pub low_rad_s: f64,
    pub high_rad_s: f64,
    pub low_nondim: f64,
    pub high_nondim: f64,
}

#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct GeBaseFrequencyResponseResponse {
    pub points: Vec<BaseResponsePointOutput>,
    pub reference: BaseResponsePointOutput,
    /// Predicted resonance bands of the two-DOF model (constant length or
    /// constant rate only; absent when its frequencies turn complex).
    pub reduced_model_bands: Option<Vec<ResonanceBandOutput>>,
    /// Local maxima of the gain (rad/s).
    pub peaks_rad_s: Vec<f64>,
    /// GE time scale L0 √(I_ρ/EI) (s).
    pub time_scale_s: f64,
    pub stiffness_ratio: f64,
    /// ṽ of a constant-rate profile.
    pub rate_nondim: Option<f64>,
    pub elements: usize,
}

/// Runs a base-excitation sweep.
pub fn ge_base_frequency_response(
    req: &GeBaseFrequencyResponseRequest,
    parallelism: Parallelism,
    progress: &dyn Progress,
) -> Result<GeBaseFrequencyResponseResponse, RequestError> {
    let l0 = require_positive("initial_length_m", req.initial_length_m)?;
    let g = require_non_negative("gravity_m_s2", req.gravity_m_s2)?;
    let m = &req.model;
    let buoyancy = match &req.aerostat {
        Some(a) => Some(a.net_buoyancy_ge("aerostat")?),
        None => None,
    };
    let section = m.section(&req.cable, l0, buoyancy)?;
    let (tip, steady) = match &req.aerostat {
        None => (TipBody::default(), TipLoad::default()),
        Some(a) => (
            TipBody {
                mass_kg: a.mass("aerostat")?,
                link_length_m: a.link_length("aerostat")?,
            },
            TipLoad {
                force_n: [a.net_buoyancy_ge("aerostat")?, 0.0],
                moment_n_m: 0.0,
            },
        ),
    };
    let model = GeModel::new(section, m.elements(), tip, g)?;
    let scale = section.time_scale_s(l0);
    let omegas = req
        .frequencies_rad_s
        .values("frequencies_rad_s", BaseFrequencyGridInput::BOUNDS)?;
    let duration = require_positive("duration_s", req.duration_s)?;
    let dt = require_positive("time_step_s", req.time_step_s)?;
    let steps = duration / dt;
    if steps < 1.0 {
        return Err(InvalidInput::new("time_step_s", "must not exceed duration_s").into());
    }
    let work = steps * (omegas.len() + 1) as f64 * m.elements() as f64;
    if steps * m.elements() as f64 > MAX_RESPONSE_WORK {
        return Err(InvalidInput::new(
            "time_step_s",
            format!(
                "one run alone needs {steps:.0} steps × {} elements, beyond the work limit {MAX_RESPONSE_WORK:.0e}: take a longer step or a shorter duration_s",
                m.elements()
            ),
        )
        .into());
    }
    if work > MAX_RESPONSE_WORK {
        return Err(InvalidInput::new(
            "frequencies_rad_s.count",
            format!(
                "{} runs × {steps:.0} steps × {} elements exceeds the work limit {MAX_RESPONSE_WORK:.0e}",
                omegas.len() + 1,
                m.elements()
            ),
        )
        .into());
    }
    let (length, rate) = match &req.profile {
        None => (LengthHistory::Constant(l0), Some(0.0)),
        Some(p) => {
            let profile = p.profile(l0)?;
            let rate = match profile {
                Profile::ConstantRate { rate_m_s, .. } => Some(rate_m_s),
                _ => None,
            };
            (LengthHistory::Profile(profile), rate)
        }
    };
    let reference = match req.reference_frequency_rad_s {
        None => 0.01 / scale,
        Some(w) => require_positive("reference_frequency_rad_s", w)?,
    };
    let epsilon = require_non_negative(
        "reduced_model_epsilon_nondim",
        req.reduced_model_epsilon_nondim,
    )?;
    let problem = BaseExcitationProblem {
        model,
        length,
        steady_tip_load: steady,
        amplitude_m: req.amplitude_m,
        frequencies_rad_s: omegas,
        reference_frequency_rad_s: reference,
        duration_s: duration,
        time_step_s: dt,
        newton: newton_config(&req.newton)?,
    };
    problem.validate().map_err(|e| {
        let field = match e.field.as_str() {
            "base.amplitude_m" => "amplitude_m".to_string(),
            "base.reference_frequency_rad_s" => "reference_frequency_rad_s".to_string(),
            "numerics.time_step_s" => "time_step_s".to_string(),
            f => f.to_string(),
        };
        InvalidInput::new(field, e.reason)
    })?;
    if progress.cancelled() {
        return Err(RequestError::Cancelled);
    }
    let cancel = || progress.cancelled();
    let report = |done: usize, total: usize| progress.report(done, total);
    let r = base::frequency_response(&problem, parallelism, &report, &cancel)?;
    if progress.cancelled() {
        return Err(RequestError::Cancelled);
    }
    let rate_nondim = rate.map(|v| v * scale / l0);
    let stiffness_ratio = crate::contract::ge::simulate::stiffness_ratio_of(&section, l0);
    let bands = rate_nondim.and_then(|v| {
        reduced::resonance_bands(stiffness_ratio, epsilon, v, duration / scale).map(|b| {
            b.iter()
                .map(|b| ResonanceBandOutput {
                    low_rad_s: b.low / scale,
                    high_rad_s: b.high / scale,
                    low_nondim: b.low,
                    high_nondim: b.high,
                })
                .collect()
        })
    });
    let out = |p: &base::ResponsePoint| BaseResponsePointOutput {
        frequency_rad_s: p.frequency_rad_s,
        frequency_nondim: p.frequency_rad_s * scale,
        gain_db: p.gain_db.is_finite().then_some(p.gain_db),
        max_tip_amplitude_m: p.max_tip_amplitude_m,
        completed: p.completed,
    };
    Ok(GeBaseFrequencyResponseResponse {
        points: r.points.iter().map(out).collect(),
        reference: out(&r.reference),
        reduced_model_bands: bands,
        peaks_rad_s: base::resonance_peaks(&r.points)
            .into_iter()
            .map(|i| r.points[i].frequency_rad_s)
            .collect(),
        time_scale_s: scale,
        stiffness_ratio,
        rate_nondim,
        elements: m.elements(),
    })
}

/// `POST /api/v1/frequency-response`: `"excitation": "base"` shakes the
/// platform under the GE cable (thesis ch. 8); otherwise (absent) the
/// linear string under a sinusoidal wind.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(untagged)]
pub enum AnyFrequencyResponseRequest {
    /// `excitation = "base"`.
    Base(Box<GeBaseFrequencyResponseRequest>),
    /// Wind forcing on the linear string.
    Wind(Box<crate::contract::transient::FrequencyResponseRequest>),
}

/// The answer of [`AnyFrequencyResponseRequest`].
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(untagged)]
pub enum AnyFrequencyResponseResponse {
    Base(GeBaseFrequencyResponseResponse),
    Wind(crate::contract::transient::FrequencyResponseResponse),
}

/// Parses a frequency-response body, choosing by `excitation`.
pub fn parse_frequency_response(body: &[u8]) -> Result<AnyFrequencyResponseRequest, RequestError> {
    let value: serde_json::Value =
        serde_json::from_slice(body).map_err(|e| RequestError::Malformed(e.to_string()))?;
    match value.get("excitation") {
        None => {
            crate::contract::parse(body).map(|r| AnyFrequencyResponseRequest::Wind(Box::new(r)))
        }
        Some(_) => {
            let req: Box<GeBaseFrequencyResponseRequest> =
                crate::contract::parse_ge(body, "the base-excitation frequency response")?;
            req.check_ranges()?;
            Ok(AnyFrequencyResponseRequest::Base(req))
        }
    }
}

/// Runs either frequency response.
pub fn frequency_response_any(
    req: &AnyFrequencyResponseRequest,
    parallelism: Parallelism,
    progress: &dyn Progress,
) -> Result<AnyFrequencyResponseResponse, RequestError> {
    match req {
        AnyFrequencyResponseRequest::Base(r) => {
            ge_base_frequency_response(r, parallelism, progress)
                .map(AnyFrequencyResponseResponse::Base)
        }
        AnyFrequencyResponseRequest::Wind(r) => {
            crate::contract::transient::frequency_response(r, parallelism, progress)
                .map(AnyFrequencyResponseResponse::Wind)
        }
    }
}
