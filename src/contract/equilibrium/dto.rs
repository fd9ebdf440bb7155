//! Request and response bodies of `POST /api/v1/equilibrium` and the parts
//! the envelope shares with it (tether, aerostat, air). SI units; every
//! bound in the schema is the bound the validation applies.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

pub(crate) use crate::contract::system::default_safety_factor;
pub use crate::contract::system::{
    AerostatInput, BodyPresetName, CableInput, CablePresetName, WindFlowInput, WindInput,
    WindPointInput,
};

/// The tether of the equilibrium and the envelope: the one [`CableInput`].
pub type TetherCableInput = CableInput;
/// The aerostat of the equilibrium and the envelope: the one [`AerostatInput`].
pub type TetherAerostatInput = AerostatInput;

pub(crate) fn default_gravity() -> f64 {
    9.81
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
    "wind": {"flow": {"kind": "log_law", "speed_m_s": 8.0, "roughness_length_m": 0.03},
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
    /// The rest of the system (accepted and checked; the equilibrium has no use for them).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub winch: Option<crate::contract::system::WinchInput>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 1.0, minimum = 0.001, maximum = 10000.0)]
    pub initial_length_m: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 0.05, minimum = 0.0, maximum = 0.9)]
    pub lift_reserve_nondim: Option<f64>,
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

/// The state of the tether in one steady wind (the mean, or the gust).
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct EquilibriumStateOutput {
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
}

/// The tether in the gust (SPEC §10): the static equilibrium at the gust
/// speed, exactly the mean-wind answer for a mean wind of that speed.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct EquilibriumGustOutput {
    /// Gust speed over the mean at every height, `1 + k I` or `gust_m_s / U(z_ref)`.
    pub gust_factor_nondim: f64,
    /// Height the gust speed refers to (m).
    pub reference_height_m: f64,
    /// Gust speed at the reference height (m/s).
    pub reference_speed_m_s: f64,
    #[serde(flatten)]
    pub state: EquilibriumStateOutput,
    pub numerics: EquilibriumNumerics,
}

/// The mean-wind state (its fields at the top level), the gust state
/// beside it (with `wind.gust`), and the inputs as resolved.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct EquilibriumResponse {
    #[serde(flatten)]
    pub state: EquilibriumStateOutput,
    pub required_safety_factor_nondim: f64,
    /// Breaking strength / required factor (N); null without a breaking strength.
    pub allowable_tension_n: Option<f64>,
    /// With `wind.gust`: the same figures in the gust; absent without gusts.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gust: Option<EquilibriumGustOutput>,
    pub cable: ResolvedCableOutput,
    pub aerostat: ResolvedAerostatOutput,
    pub numerics: EquilibriumNumerics,
}

/// The mean state's fields read as the answer's own (`answer.winch_tension_n`),
/// as they are in its JSON.
impl std::ops::Deref for EquilibriumResponse {
    type Target = EquilibriumStateOutput;

    fn deref(&self) -> &EquilibriumStateOutput {
        &self.state
    }
}
