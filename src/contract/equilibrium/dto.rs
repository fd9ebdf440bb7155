//! Request and response bodies of `POST /api/v1/equilibrium` and the parts
//! the envelope shares with it (tether, aerostat, air). SI units; every
//! bound in the schema is the bound the validation applies.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

/// A tether material preset: fills every property not given from `diameter_m`.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, ToSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum CablePresetName {
    /// UHMWPE (Dyneema SK75/SK78) 12-strand braid.
    Dyneema,
    /// Aramid (Kevlar 29 class) braid.
    Aramid,
    /// Vectran HT braid.
    Vectran,
    /// Steel wire rope 6×36 IWRC, extra improved plow steel.
    Steel,
}

/// The tether. With `preset`, the fields left out come from the material
/// at `diameter_m`; fields given always win.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct TetherCableInput {
    #[serde(default)]
    pub preset: Option<CablePresetName>,
    /// Mass per unit (unstretched) length ρA (kg/m); required without a preset.
    #[serde(default)]
    #[schema(example = 0.02, exclusive_minimum = 0.0, maximum = 1000.0)]
    pub mass_per_length_kg_m: Option<f64>,
    /// Diameter d (m): the reference width of the normal drag.
    #[schema(example = 0.006, exclusive_minimum = 0.0, maximum = 1.0)]
    pub diameter_m: f64,
    /// Normal drag coefficient C_n (default 1.2, a cylinder in cross flow).
    #[serde(default)]
    #[schema(example = 1.2, minimum = 0.0, maximum = 10.0)]
    pub normal_drag_coefficient_nondim: Option<f64>,
    /// Axial stiffness EA (N); absent: inextensible (unless a preset gives it).
    #[serde(default)]
    #[schema(example = 850000.0, exclusive_minimum = 0.0, maximum = 1e12)]
    pub axial_stiffness_n: Option<f64>,
    /// Breaking strength (N), for the safety factor.
    #[serde(default)]
    #[schema(example = 30000.0, exclusive_minimum = 0.0, maximum = 1e9)]
    pub breaking_strength_n: Option<f64>,
}

/// An aerostat shape preset: fills the coefficients and the reference area
/// from `radius_m` (sphere) or `volume_m3` (streamlined).
#[derive(Clone, Copy, Debug, Deserialize, Serialize, ToSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum BodyPresetName {
    /// Spherical balloon: C_D 0.47, no lift, area π r².
    Sphere,
    /// Finned streamlined hull: C_D 0.05, C_L 0.1 on V^(2/3).
    Streamlined,
}

/// The aerostat's static loads. With `preset`, coefficients and area left
/// out come from the shape; fields given always win.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct TetherAerostatInput {
    #[serde(default)]
    pub preset: Option<BodyPresetName>,
    /// Sphere radius (m), for `preset: sphere`.
    #[serde(default)]
    #[schema(exclusive_minimum = 0.0, maximum = 100.0)]
    pub radius_m: Option<f64>,
    /// Envelope volume (m³), for `preset: streamlined`.
    #[serde(default)]
    #[schema(exclusive_minimum = 0.0, maximum = 1e7)]
    pub volume_m3: Option<f64>,
    /// Net buoyancy F = buoyancy − weight (N).
    #[schema(example = 2000.0, exclusive_minimum = 0.0, maximum = 1e8)]
    pub net_buoyancy_n: f64,
    /// Aerostat mass (kg); the statics need only F, the stability uses it.
    #[serde(default)]
    #[schema(example = 100.0, minimum = 0.0, maximum = 1e7)]
    pub mass_kg: f64,
    /// Drag coefficient C_D on `reference_area_m2`; required without a preset.
    #[serde(default)]
    #[schema(example = 0.3, minimum = 0.0, maximum = 10.0)]
    pub drag_coefficient_nondim: Option<f64>,
    /// Reference area A (m²); required without a preset.
    #[serde(default)]
    #[schema(example = 20.0, exclusive_minimum = 0.0, maximum = 1e5)]
    pub reference_area_m2: Option<f64>,
    /// Aerodynamic lift coefficient C_L on `reference_area_m2` (default 0).
    #[serde(default)]
    #[schema(example = 0.0, minimum = -10.0, maximum = 10.0)]
    pub lift_coefficient_nondim: Option<f64>,
}

/// One point of a tabulated wind profile.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct WindPointInput {
    #[schema(example = 100.0, minimum = 0.0, maximum = 100000.0)]
    pub elevation_m: f64,
    #[schema(example = 8.0, minimum = -150.0, maximum = 150.0)]
    pub speed_m_s: f64,
}

/// A steady horizontal wind profile U(z) (z above the winch).
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum WindFlowInput {
    /// U = speed.
    Uniform {
        #[schema(example = 8.0, minimum = -150.0, maximum = 150.0)]
        speed_m_s: f64,
    },
    /// U = a z^p; a is the speed at z = 1 m.
    PowerLaw {
        #[schema(example = 3.0, minimum = -150.0, maximum = 150.0)]
        coefficient_m_s: f64,
        #[schema(example = 0.14, minimum = 0.0, maximum = 2.0)]
        exponent_nondim: f64,
    },
    /// Linear interpolation in (z, U), constant beyond the ends (1 to 10 000 points).
    Tabulated { points: Vec<WindPointInput> },
    /// U = U_ref ln(z/z0)/ln(z_ref/z0) above z0, 0 below.
    LogLaw {
        /// Speed at the reference height (m/s).
        #[schema(example = 8.0, minimum = -150.0, maximum = 150.0)]
        reference_speed_m_s: f64,
        /// Reference height (m), default 10 (the meteorological standard).
        #[serde(default = "default_reference_height")]
        #[schema(example = 10.0, exclusive_minimum = 0.0, maximum = 10000.0)]
        reference_height_m: f64,
        /// Roughness length z0 (m): 0.0002 sea, 0.03 open terrain, 0.1 farmland, 1 city.
        #[schema(example = 0.03, minimum = 0.000001, maximum = 10.0)]
        roughness_length_m: f64,
    },
}

pub(crate) fn default_reference_height() -> f64 {
    10.0
}

/// The air: its flow and density.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct WindInput {
    pub flow: WindFlowInput,
    /// Air density (kg/m³), default 1.225 (ISA sea level).
    #[serde(default = "default_air_density")]
    #[schema(example = 1.225, exclusive_minimum = 0.0, maximum = 5.0)]
    pub air_density_kg_m3: f64,
}

pub(crate) fn default_air_density() -> f64 {
    1.225
}

pub(crate) fn default_gravity() -> f64 {
    9.81
}

pub(crate) fn default_safety_factor() -> f64 {
    5.0
}

pub(crate) fn default_steps() -> usize {
    100
}

fn default_shape_samples() -> usize {
    51
}

/// `POST /api/v1/equilibrium`: the static shape, altitude and tensions of
/// the tether in a steady wind.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({
    "cable": {"preset": "dyneema", "diameter_m": 0.006},
    "aerostat": {"net_buoyancy_n": 2000.0, "mass_kg": 100.0, "drag_coefficient_nondim": 0.3,
                 "reference_area_m2": 20.0, "lift_coefficient_nondim": 0.0},
    "tether_length_m": 1000.0,
    "wind": {"flow": {"kind": "log_law", "reference_speed_m_s": 8.0, "roughness_length_m": 0.03},
             "air_density_kg_m3": 1.225},
    "gravity_m_s2": 9.81,
    "required_safety_factor_nondim": 5.0
}))]
pub struct EquilibriumRequest {
    pub cable: TetherCableInput,
    pub aerostat: TetherAerostatInput,
    /// Unstretched tether length L (m).
    #[schema(example = 1000.0, exclusive_minimum = 0.0, maximum = 100000.0)]
    pub tether_length_m: f64,
    pub wind: WindInput,
    /// Gravitational acceleration (m/s²).
    #[serde(default = "default_gravity")]
    #[schema(example = 9.81, exclusive_minimum = 0.0, maximum = 100.0)]
    pub gravity_m_s2: f64,
    /// Safety factor the operator requires (breaking strength / largest
    /// tension); default 5 (fibre tethers, FAA 14 CFR 31.25 practice).
    #[serde(default = "default_safety_factor")]
    #[schema(example = 5.0, minimum = 1.0, maximum = 100.0)]
    pub required_safety_factor_nondim: f64,
    /// Payout rate (m/s) for the stability margin `min T − ρA v²`; absent: not judged.
    #[serde(default)]
    #[schema(example = 2.0, minimum = 0.0, maximum = 1000.0)]
    pub payout_rate_m_s: Option<f64>,
    /// Fourth-order Runge–Kutta steps over the tether (default 100: about 1e-11 relative).
    #[serde(default = "default_steps")]
    #[schema(example = 100, minimum = 8, maximum = 100000)]
    pub integration_steps: usize,
    /// Points of the returned shape, evenly spaced in s (default 51).
    #[serde(default = "default_shape_samples")]
    #[schema(example = 51, minimum = 2, maximum = 10001)]
    pub shape_samples: usize,
}

/// One point of the shape.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct ShapePointOutput {
    /// Unstretched arc length from the winch (m).
    pub s_m: f64,
    /// Downwind distance from the winch (m).
    pub x_m: f64,
    /// Height above the winch (m).
    pub z_m: f64,
    /// Tension (N).
    pub tension_n: f64,
}

/// The tether as used, presets resolved.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct ResolvedCableOutput {
    pub mass_per_length_kg_m: f64,
    pub diameter_m: f64,
    pub normal_drag_coefficient_nondim: f64,
    /// Null: inextensible.
    pub axial_stiffness_n: Option<f64>,
    pub breaking_strength_n: Option<f64>,
}

/// The aerostat as used, presets resolved.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct ResolvedAerostatOutput {
    pub net_buoyancy_n: f64,
    pub drag_coefficient_nondim: f64,
    pub lift_coefficient_nondim: f64,
    pub reference_area_m2: f64,
}

/// How the answer was computed.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct EquilibriumNumerics {
    /// RK4 steps over the tether.
    pub integration_steps: usize,
    /// Order of the integrator's global error (4).
    pub order_nondim: u32,
    /// Shooting passes on the altitude (1 or 2 in a uniform wind).
    pub shooting_iterations: usize,
    /// |z at the winch| of the last pass (m): the shooting residual.
    pub residual_m: f64,
    /// Whether the shooting met its tolerance (1e-11 L).
    pub converged: bool,
}

#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct EquilibriumResponse {
    /// Height of the aerostat above the winch (m).
    pub aerostat_altitude_m: f64,
    /// Downwind distance of the aerostat from the winch (m).
    pub aerostat_downwind_m: f64,
    /// Tension at the winch (N); the horizontal pull when the lower tether rests on the ground.
    pub winch_tension_n: f64,
    /// Tension at the aerostat (N).
    pub top_tension_n: f64,
    /// Largest tension along the tether (N).
    pub max_tension_n: f64,
    /// Smallest tension along the tether (N).
    pub min_tension_n: f64,
    /// Breaking strength / largest tension; null without a breaking strength.
    pub safety_factor_nondim: Option<f64>,
    pub required_safety_factor_nondim: f64,
    /// Breaking strength / required factor (N); null without a breaking strength.
    pub allowable_tension_n: Option<f64>,
    /// Whether the safety factor meets the required one; null without a breaking strength.
    pub meets_required_safety_factor: Option<bool>,
    /// Angle of the winch–aerostat line from the vertical (deg).
    pub blowdown_angle_deg: f64,
    /// Tether angle from the vertical at the winch (deg).
    pub winch_angle_from_vertical_deg: f64,
    /// Tether angle from the vertical at the aerostat (deg).
    pub top_angle_from_vertical_deg: f64,
    /// Horizontal and vertical winch force components (N).
    pub winch_horizontal_force_n: f64,
    pub winch_vertical_force_n: f64,
    /// Wind speed at the aerostat (m/s).
    pub aerostat_wind_speed_m_s: f64,
    /// Aerostat drag ½ρ C_D A U² (N).
    pub aerostat_drag_n: f64,
    /// Aerostat aerodynamic lift ½ρ C_L A U² (N).
    pub aerostat_lift_n: f64,
    /// Tension vanishes or the lower tether rests on the ground (an outcome, not an error).
    pub slack: bool,
    /// Unstretched length lying on the ground (m).
    pub grounded_length_m: f64,
    /// Stretched tether length (m).
    pub stretched_length_m: f64,
    /// With a payout rate: `min T − ρA v²` (N); positive is stable (continuum string criterion).
    pub stability_margin_n: Option<f64>,
    /// With a payout rate: whether the margin is positive and the tether taut.
    pub stable: Option<bool>,
    /// The first operating limit violated (`slack`, `tension`, `stability`, `not_converged`); null: none.
    pub binding_limit: Option<String>,
    /// Plain-language account of the answer.
    pub explanation: String,
    /// The shape from the winch up.
    pub shape: Vec<ShapePointOutput>,
    pub cable: ResolvedCableOutput,
    pub aerostat: ResolvedAerostatOutput,
    pub numerics: EquilibriumNumerics,
}
