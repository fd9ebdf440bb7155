//! The GE variant of `POST /api/v1/stability` (`"model": {"kind":
//! "geometrically_exact", ...}`): the straight quasi-static equilibrium at
//! the state's length, rate and acceleration, then the local QEP (7.3)
//! about it ([`state_stability`]); its request and response bodies,
//! validation naming the field, the runner [`ge_stability`], and the
//! dispatch on `model.kind` beside the linear string's body
//! ([`AnyStabilityRequest`]).

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::critical::{
    MAX_LENGTH_RATIO, Prepared, default_gravity, default_initial_length, default_load_steps,
    default_modes, finite, is_ge, prepare,
};
use crate::contract::error::RequestError;
use crate::contract::ge::numerics::{StartStateInput, newton_config};
use crate::contract::ge::simulate::{GeAerostatInput, GeModelInput, NewtonInput};
use crate::contract::string::dto::{StabilityRequest, StabilityResponse, StateInput};
use crate::contract::string::run;
use crate::contract::system::CableInput;
use crate::contract::system::output::EigenvalueOutput;
use crate::numerics::ge::GeModel;
use crate::numerics::ge::element::TipLoad;
use crate::numerics::ge::extensible::ExtensibleString;
use crate::numerics::ge::stability::{GeStateFailure, state_stability};
use crate::numerics::params::{InvalidInput, Kinematics, require_finite, require_positive};

/// `POST /api/v1/stability` with `"model": {"kind": "geometrically_exact"}`:
/// the local QEP of the GE cable about its quasi-static equilibrium at one
/// deployment state.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({
    "cable": {"mass_per_length_kg_m": 0.078},
    "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
    "initial_length_m": 1.0,
    "gravity_m_s2": 9.81,
    "model": {"kind": "geometrically_exact", "elements": 20, "bending_stiffness_n_m2": 1000.0,
              "stiffness_ratio": 1e5, "inertia_ratio": 1.0},
    "state": {"length_m": 500.0, "rate_m_s": 10.0, "acceleration_m_s2": 0.0},
    "modes": 3
}))]
pub struct GeStabilityRequest {
    pub cable: CableInput,
    pub aerostat: GeAerostatInput,
    /// Initial length L0 (m), the length scale of E* and γ̃.
    #[serde(default = "default_initial_length")]
    #[schema(example = 1.0, minimum = 0.001, maximum = 10000.0)]
    pub initial_length_m: f64,
    #[serde(default = "default_gravity")]
    #[schema(example = 9.81, minimum = 0.0, maximum = 100.0)]
    pub gravity_m_s2: f64,
    pub model: GeModelInput,
    pub state: StateInput,
    /// How many modes (Im λ ≥ 0, by frequency) to list.
    #[serde(default = "default_modes")]
    #[schema(example = 3, minimum = 1, maximum = 4000)]
    pub modes: usize,
    /// How the cable moves at the state: with the reel-out rate
    /// (`at_rest`, as a search from rest starts) or in steady payout.
    #[serde(default)]
    pub cable_motion: StartStateInput,
    /// Load increments of the equilibrium solve.
    #[serde(default = "default_load_steps")]
    #[schema(example = 2, minimum = 1, maximum = 100)]
    pub load_steps: usize,
    #[serde(default)]
    pub newton: Option<NewtonInput>,
}

/// How a GE stability query ended.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, ToSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum GeStabilityOutcome {
    /// The equilibrium converged and the QEP was solved.
    Solved,
    /// Newton did not find the equilibrium (e.g. the cable's weight
    /// exceeds the lift: no straight equilibrium).
    EquilibriumFailed,
    /// The eigenvalue iteration failed.
    SpectrumFailed,
}

/// The equilibrium about which the QEP was solved.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct GeEquilibriumOutput {
    /// Axial displacement of the cable top (m): the stretch.
    pub tip_axial_displacement_m: f64,
    /// Axial force in the element at the guide (N).
    pub root_axial_force_n: f64,
    /// The steady-payout (quasi-static) tension there (N).
    pub quasi_static_root_tension_n: f64,
}

#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct GeStabilityResponse {
    pub outcome: GeStabilityOutcome,
    /// Every Re λ ≤ tolerance; null unless `solved`.
    pub stable: Option<bool>,
    /// Largest Re λ (1/s).
    pub max_real_1_s: Option<f64>,
    /// Largest Re λ × L0 √(I_ρ/EI).
    pub max_real_nondim: Option<f64>,
    /// Tolerance on Re λ used for the verdict (1/s).
    pub tolerance_1_s: Option<f64>,
    /// The first `modes` eigenvalues with Im λ ≥ 0, by frequency.
    pub eigenvalues: Vec<EigenvalueOutput>,
    pub equilibrium: Option<GeEquilibriumOutput>,
    /// Why the answer is missing, when it is.
    pub explanation: String,
    pub length_m: f64,
    pub rate_m_s: f64,
    pub acceleration_m_s2: f64,
    pub cable_motion: StartStateInput,
    /// The string continuum bound (F/ρA − v²)/g at this rate (m), clipped
    /// at 0; null without gravity (the weight sets the bound: none at g = 0).
    pub string_closed_form_elevation_m: Option<f64>,
    /// The extensible string's quasi-static bound at this rate (m), clipped
    /// at 0; null without gravity.
    pub extensible_closed_form_elevation_m: Option<f64>,
    pub stiffness_ratio: f64,
    pub elements: usize,
    /// L0 √(I_ρ/EI) (s).
    pub time_scale_s: f64,
    /// √(F/ρA) (m/s).
    pub wave_speed_m_s: f64,
}

/// Every check of a GE stability query (no solve).
fn stability_inputs(
    req: &GeStabilityRequest,
) -> Result<
    (
        Prepared,
        Kinematics,
        crate::numerics::ge::solver::NewtonConfig,
    ),
    InvalidInput,
> {
    let p = prepare(
        &req.cable,
        &req.aerostat,
        req.initial_length_m,
        req.gravity_m_s2,
        &req.model,
    )?;
    let length = require_positive("state.length_m", req.state.length_m)?;
    if length > MAX_LENGTH_RATIO * p.initial_length_m {
        return Err(InvalidInput::new(
            "state.length_m",
            format!(
                "must be at most {MAX_LENGTH_RATIO:.0e} initial lengths ({:.3e} m), got {length}",
                MAX_LENGTH_RATIO * p.initial_length_m
            ),
        ));
    }
    let kin = Kinematics {
        length_m: length,
        rate_m_s: require_finite("state.rate_m_s", req.state.rate_m_s)?,
        acceleration_m_s2: require_finite("state.acceleration_m_s2", req.state.acceleration_m_s2)?,
    };
    if req.modes == 0 || req.modes > run::MAX_MODES {
        return Err(InvalidInput::new(
            "modes",
            format!(
                "must be between 1 and {}, got {}",
                run::MAX_MODES,
                req.modes
            ),
        ));
    }
    if !(1..=100).contains(&req.load_steps) {
        return Err(InvalidInput::new(
            "load_steps",
            format!("must be between 1 and 100, got {}", req.load_steps),
        ));
    }
    Ok((p, kin, newton_config(&req.newton)?))
}

/// Checks a GE stability query without solving it (job submission).
pub fn validate_stability(req: &GeStabilityRequest) -> Result<(), InvalidInput> {
    stability_inputs(req).map(drop)
}

/// The answer of a GE stability query.
pub fn ge_stability(req: &GeStabilityRequest) -> Result<GeStabilityResponse, RequestError> {
    let (p, kin, newton) = stability_inputs(req)?;
    let model = &p.model;
    let load = TipLoad {
        force_n: [p.net_buoyancy_n, 0.0],
        moment_n_m: 0.0,
    };
    let scale = model.section.time_scale_s(p.initial_length_m);
    let rho_a = model.section.mass_per_length_kg_m;
    let string = |axial_stiffness_n: f64| ExtensibleString {
        net_buoyancy_n: p.net_buoyancy_n,
        aerostat_mass_kg: model.tip.mass_kg,
        mass_per_length_kg_m: rho_a,
        axial_stiffness_n,
        gravity_m_s2: model.gravity_m_s2,
    };
    let v = kin.rate_m_s.abs();
    let mut out = GeStabilityResponse {
        outcome: GeStabilityOutcome::Solved,
        stable: None,
        max_real_1_s: None,
        max_real_nondim: None,
        tolerance_1_s: None,
        eigenvalues: Vec::new(),
        equilibrium: None,
        explanation: String::new(),
        length_m: kin.length_m,
        rate_m_s: kin.rate_m_s,
        acceleration_m_s2: kin.acceleration_m_s2,
        cable_motion: req.cable_motion,
        string_closed_form_elevation_m: finite(
            string(f64::INFINITY).critical_length_m(v).unwrap_or(0.0),
        ),
        extensible_closed_form_elevation_m: finite(
            string(model.section.axial_stiffness_n)
                .critical_length_m(v)
                .unwrap_or(0.0),
        ),
        stiffness_ratio: crate::contract::ge::simulate::stiffness_ratio_of(
            &model.section,
            req.initial_length_m,
        ),
        elements: model.elements,
        time_scale_s: scale,
        wave_speed_m_s: (p.net_buoyancy_n / rho_a).sqrt(),
    };
    match state_stability(
        model,
        kin,
        load,
        req.cable_motion.into(),
        req.load_steps,
        newton,
    ) {
        Err(GeStateFailure::Equilibrium(f)) => {
            out.outcome = GeStabilityOutcome::EquilibriumFailed;
            out.explanation = format!(
                "no straight equilibrium found at {:.1} m: Newton stopped after {} iterations with residual {:.3e} N (is the cable heavier than the lift?)",
                kin.length_m, f.iterations, f.residual_norm
            );
        }
        Err(GeStateFailure::Spectrum(e)) => {
            out.outcome = GeStabilityOutcome::SpectrumFailed;
            out.explanation = format!("the eigenvalue problem could not be solved: {e}");
        }
        Ok(s) => {
            let sp = &s.spectrum;
            let tol = sp.tolerance();
            let stable = sp.max_real <= tol;
            out.stable = Some(stable);
            out.max_real_1_s = Some(sp.max_real);
            out.max_real_nondim = Some(sp.max_real * scale);
            out.tolerance_1_s = Some(tol);
            out.eigenvalues = sp
                .modes()
                .into_iter()
                .take(req.modes)
                .map(|e| EigenvalueOutput {
                    re_1_s: e.re,
                    im_1_s: e.im,
                    re_nondim: e.re * scale,
                    im_nondim: e.im * scale,
                    frequency_hz: e.im / (2.0 * std::f64::consts::PI),
                })
                .collect();
            let x = 0.5 * kin.length_m / model.elements as f64;
            out.equilibrium = Some(GeEquilibriumOutput {
                tip_axial_displacement_m: s.state.q[GeModel::dof(model.elements, 0)],
                root_axial_force_n: s.root_axial_force_n,
                quasi_static_root_tension_n: string(model.section.axial_stiffness_n).tension_n(
                    v,
                    kin.length_m,
                    x,
                ),
            });
            out.explanation = if stable {
                format!(
                    "stable: every eigenvalue has Re λ ≤ {tol:.3e} 1/s at {:.1} m",
                    kin.length_m
                )
            } else {
                format!(
                    "unstable: an eigenvalue grows at Re λ = {:.3e} 1/s at {:.1} m",
                    sp.max_real, kin.length_m
                )
            };
        }
    }
    Ok(out)
}

// ---------------------------------------------------------------- dispatch

/// `POST /api/v1/stability` for either model.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(untagged)]
pub enum AnyStabilityRequest {
    /// `model.kind = "geometrically_exact"`.
    GeometricallyExact(Box<GeStabilityRequest>),
    /// `model.kind = "linear_string"` (or absent).
    LinearString(StabilityRequest),
}

/// The answer of [`AnyStabilityRequest`].
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(untagged)]
pub enum AnyStabilityResponse {
    GeometricallyExact(Box<GeStabilityResponse>),
    LinearString(StabilityResponse),
}

/// Parses a stability body, choosing the model by `model.kind`.
pub fn parse_stability(body: &[u8]) -> Result<AnyStabilityRequest, RequestError> {
    if is_ge(body)? {
        let req: Box<GeStabilityRequest> = crate::contract::parse_ge(body, "GE stability")?;
        req.check_ranges()?;
        Ok(AnyStabilityRequest::GeometricallyExact(req))
    } else {
        crate::contract::parse(body).map(AnyStabilityRequest::LinearString)
    }
}

/// Runs either stability query.
pub fn stability_any(req: &AnyStabilityRequest) -> Result<AnyStabilityResponse, RequestError> {
    match req {
        AnyStabilityRequest::GeometricallyExact(r) => {
            ge_stability(r).map(|r| AnyStabilityResponse::GeometricallyExact(Box::new(r)))
        }
        AnyStabilityRequest::LinearString(r) => {
            run::stability(r).map(AnyStabilityResponse::LinearString)
        }
    }
}
