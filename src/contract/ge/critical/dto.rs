//! The request and response bodies of the GE variant of
//! `POST /api/v1/critical` (SI; field names end in their unit), their
//! defaults and the limits the runner ([`super`]) checks them against.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::contract::ge::numerics::{
    GeChartNumericsInput, GeOnsetKind, IntegratorOutput, StartStateInput,
};
use crate::contract::ge::{GeAerostatInput, GeModelInput, NewtonInput};
use crate::contract::system::CableInput;
use crate::contract::system::input::ProfileInput;

/// Largest element count of a GE critical-time search or stability query
/// (a dense QEP of size 6n per check).
pub const MAX_GE_QEP_ELEMENTS: usize = 200;
/// Largest `(horizon / Δt) × elements` of one GE critical-time search.
pub const MAX_CRITICAL_WORK: f64 = 5e8;
/// Largest |F0| (N).
pub const MAX_PERTURBATION_N: f64 = 1e6;
/// Largest state length of a GE stability query, in initial lengths.
pub const MAX_LENGTH_RATIO: f64 = 1e6;

pub(in crate::contract::ge) fn default_initial_length() -> f64 {
    1.0
}
pub(in crate::contract::ge) fn default_gravity() -> f64 {
    9.81
}
fn default_ramp() -> f64 {
    0.25
}
fn default_hold() -> f64 {
    1.0
}
pub(in crate::contract::ge) fn default_modes() -> usize {
    3
}
pub(in crate::contract::ge) fn default_load_steps() -> usize {
    2
}

/// A sideways push on the aerostat at the start (thesis Fig. 7.4).
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct GePerturbationInput {
    /// Peak force F0 across the guide (N).
    #[schema(example = 400.0, minimum = -1e6, maximum = 1e6)]
    pub force_n: f64,
    /// Linear rise time (s).
    #[serde(default = "default_ramp")]
    #[schema(example = 0.25, minimum = 0.0, maximum = 1e4)]
    pub ramp_s: f64,
    /// Release time (s), at least `ramp_s`.
    #[serde(default = "default_hold")]
    #[schema(example = 1.0, minimum = 0.0, maximum = 1e4)]
    pub hold_s: f64,
}

/// `POST /api/v1/critical` with `"model": {"kind": "geometrically_exact"}`:
/// t* and h* of the GE cable for a deployment profile.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({
    "cable": {"mass_per_length_kg_m": 0.078},
    "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
    "initial_length_m": 1.0,
    "gravity_m_s2": 9.81,
    "model": {"kind": "geometrically_exact", "elements": 20, "bending_stiffness_n_m2": 1000.0,
              "stiffness_ratio": 1e5, "inertia_ratio": 1.0},
    "profile": {"kind": "constant_rate", "rate_m_s": 40.0},
    "start_state": "at_rest"
}))]
pub struct GeCriticalRequest {
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
    pub profile: ProfileInput,
    /// Sideways push on the aerostat at the start; none: unperturbed.
    #[serde(default)]
    pub perturbation: Option<GePerturbationInput>,
    /// The cable's motion when the winch starts.
    #[serde(default)]
    pub start_state: StartStateInput,
    /// Step, QEP interval, horizon, scheme (default: generalized-α, ρ∞ = 0), step cuts.
    #[serde(default)]
    pub numerics: Option<GeChartNumericsInput>,
    #[serde(default)]
    pub newton: Option<NewtonInput>,
    /// `marching` (default): march the deployment and solve the local QEP
    /// along it. `quasi_static`: the fast quasi-static answer for a
    /// constant rate — the quasi-static equilibrium at each length, its
    /// stiffness inertia bisected to the divergence root, confirmed by the
    /// local QEP on either side (within 0.01 % of the marching h* for
    /// Table 7.1 data); `numerics` (time stepping) and `perturbation` are
    /// refused with it.
    #[serde(default)]
    pub method: GeCriticalMethod,
}

/// How a GE critical time is found.
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, ToSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum GeCriticalMethod {
    /// March the deployment (generalized-α), local QEP every few steps.
    #[default]
    Marching,
    /// Quasi-static: equilibrium and local QEP at each length, no march
    /// (constant-rate profiles only).
    QuasiStatic,
}

/// The answer of a GE critical-time search.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct GeCriticalResponse {
    pub onset: GeOnsetKind,
    /// t* (s): 0 if unstable at once; null unless `immediate`/`during`.
    pub critical_time_s: Option<f64>,
    /// t* / (L0 √(I_ρ/EI)).
    pub critical_time_nondim: Option<f64>,
    /// h* = L(t*) (m).
    pub max_elevation_m: Option<f64>,
    /// Time at which the search ended without an onset (s).
    pub ended_at_s: Option<f64>,
    /// Constant rate only: the string's continuum bound (F/ρA − v²)/g (m),
    /// clipped at 0; null for other profiles.
    pub string_closed_form_elevation_m: Option<f64>,
    /// Constant rate only: the quasi-static bound of an extensible string of
    /// this axial stiffness (m), clipped at 0.
    pub extensible_closed_form_elevation_m: Option<f64>,
    /// Quasi-static constant-rate payout in calm air: the closed form of the
    /// GE onset (m), the string's bound lifted by the bending layer at the
    /// guide, `F − ρA g L − ρA v² = a₁ (EI_eff b²)^(1/3)` with `a₁` the first
    /// zero of Airy's Ai, `b = ρA g + 2ρA v²/L`, `EI_eff = EI − I_ρ v²`
    /// (neglected: shear flexibility, extensibility, the curvature of the
    /// tension over the layer); the converged answer's continuum limit
    /// meets it within `max_elevation_error_m`. Null for other methods and
    /// profiles, or without a bending layer (`EI_eff ≤ 0`).
    #[serde(default)]
    pub bending_closed_form_elevation_m: Option<f64>,
    /// Whether the closed forms describe this onset: false without a
    /// closed form (profiles other than a constant rate), with a tip
    /// perturbation still acting at t*, or when the onset is a start-up
    /// transient (the axial force at the guide departs from the
    /// steady-payout tension enough to move h* by more than 2 %).
    pub closed_form_applies: bool,
    /// Why the closed forms do not apply, when they do not.
    pub closed_form_note: Option<String>,
    /// Axial force in the element at the guide at t* (N).
    pub onset_root_axial_force_n: Option<f64>,
    /// Plain-language account of the answer.
    pub explanation: String,
    pub steps: usize,
    pub qep_solves: usize,
    /// Steps halved and retried after a Newton failure.
    pub step_cuts: usize,
    pub integrator: IntegratorOutput,
    pub start_state: StartStateInput,
    pub stiffness_ratio: f64,
    pub elements: usize,
    /// L0 √(I_ρ/EI) (s).
    pub time_scale_s: f64,
    /// √(F/ρA) (m/s).
    pub wave_speed_m_s: f64,
    /// The method that produced this answer.
    #[serde(default)]
    pub method: GeCriticalMethod,
    /// Quasi-static only: the final bracket of h* (stable, unstable) (m).
    #[serde(default)]
    pub quasi_static_bracket_m: Option<[f64; 2]>,
    /// Quasi-static only: equilibria solved.
    #[serde(default)]
    pub quasi_static_equilibrium_solves: Option<usize>,
    /// Quasi-static without `model.elements`: the critical length is
    /// converged (nested meshes from `elements`, Richardson) and
    /// `max_elevation_m` / `critical_time_s` are its safe side (best
    /// estimate minus the error estimate); null otherwise.
    #[serde(default)]
    pub converged: Option<bool>,
    /// Converged only: the relative tolerance of the search.
    #[serde(default)]
    pub relative_tolerance_nondim: Option<f64>,
    /// Converged only: the best estimate of the continuum h* (m).
    #[serde(default)]
    pub max_elevation_estimate_m: Option<f64>,
    /// Converged only: the estimated discretisation error of that estimate (m).
    #[serde(default)]
    pub max_elevation_error_m: Option<f64>,
    /// Converged only: the same error in t* (s), `max_elevation_error_m / v`.
    #[serde(default)]
    pub critical_time_error_s: Option<f64>,
    /// Converged only: `(elements, divergence root h* in m)` of each mesh.
    #[serde(default)]
    pub mesh_levels: Option<Vec<GeMeshLevelOutput>>,
}

/// One mesh of a converged quasi-static search.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct GeMeshLevelOutput {
    pub elements: usize,
    /// Length of the element at the guide at this root (m): `h*/elements`
    /// on a uniform mesh; less in calm air, where the meshes are graded
    /// toward the guide (geometrically growing elements, each level the
    /// last with every element bisected).
    pub first_element_m: f64,
    /// The divergence root on this mesh (m).
    pub max_elevation_m: f64,
}
