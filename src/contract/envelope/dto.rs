//! Request and response bodies of `POST /api/v1/envelope`.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::contract::equilibrium::dto::{
    ResolvedAerostatOutput, ResolvedCableOutput, TetherAerostatInput, TetherCableInput,
    default_gravity, default_safety_factor, default_steps,
};
use crate::contract::system::grid::{LengthGrid, WindSpeedGrid};
use crate::contract::system::{WinchInput, WindInput};

/// `POST /api/v1/envelope`: equilibria over wind speed × tether length,
/// each judged against slack, tension, ceiling and (with a payout rate) stability.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({
    "cable": {"preset": "dyneema", "diameter_m": 0.006},
    "aerostat": {"net_buoyancy_n": 2000.0, "mass_kg": 100.0, "drag_coefficient_nondim": 0.3,
                 "reference_area_m2": 20.0},
    "wind": {"flow": {"kind": "log_law", "speed_m_s": 8.0, "reference_height_m": 10.0,
                      "roughness_length_m": 0.03},
             "air_density_kg_m3": 1.225},
    "wind_speeds_m_s": {"min": 0.0, "max": 30.0, "count": 40},
    "tether_lengths_m": {"min": 100.0, "max": 3000.0, "count": 50},
    "required_safety_factor_nondim": 5.0,
    "ceiling_m": 2500.0,
    "payout_rate_m_s": 5.0
}))]
pub struct EnvelopeRequest {
    pub cable: TetherCableInput,
    pub aerostat: TetherAerostatInput,
    /// The air: its density and the shape of its flow (uniform, log law or
    /// power law), scaled to each grid speed (the speed at the flow's
    /// reference height: `speed_m_s`, or a power law's `coefficient_m_s`).
    /// The flow's own speed is 0 to 150 m/s here, with a grid as well
    /// (it sets the gust ratio of `gust.gust_m_s`).
    pub wind: WindInput,
    /// Wind speeds (m/s, 0 to 150, at most 1000): a list or `{min, max, count}`;
    /// absent: the flow's own speed only (today's wind).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wind_speeds_m_s: Option<WindSpeedGrid>,
    /// Tether lengths (m, above 0 and at most 100 000, at most 1000): a list or `{min, max, count}`.
    pub tether_lengths_m: LengthGrid,
    #[serde(default = "default_gravity")]
    #[schema(example = 9.81, exclusive_minimum = 0.0, maximum = 100.0)]
    pub gravity_m_s2: f64,
    /// Required breaking strength / largest tension (default 5).
    #[serde(default = "default_safety_factor")]
    #[schema(example = 5.0, minimum = 1.0, maximum = 100.0)]
    pub required_safety_factor_nondim: f64,
    /// Highest allowed altitude (m); absent: none.
    #[serde(default)]
    #[schema(example = 2500.0, exclusive_minimum = 0.0, maximum = 100000.0)]
    pub ceiling_m: Option<f64>,
    /// Lowest allowed altitude (m): terrain or an airspace floor; with
    /// `wind.gust` the altitude in the gust must clear it. Absent: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 150.0, minimum = 0.0, maximum = 100000.0)]
    pub min_altitude_m: Option<f64>,
    /// Payout rate (m/s) for the stability limit; absent: stability not judged.
    #[serde(default)]
    #[schema(example = 5.0, minimum = 0.0, maximum = 1000.0)]
    pub payout_rate_m_s: Option<f64>,
    /// RK4 steps per equilibrium (default 100).
    #[serde(default = "default_steps")]
    #[schema(example = 100, minimum = 8, maximum = 100000)]
    pub integration_steps: usize,
    /// How stability is judged at `payout_rate_m_s`; absent: the string criterion.
    #[serde(default)]
    pub stability: Option<super::stability::EnvelopeStabilityInput>,
    /// The rest of the system (accepted and checked; the envelope has no use for them).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub winch: Option<WinchInput>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 1.0, minimum = 0.001, maximum = 10000.0)]
    pub initial_length_m: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 0.05, minimum = 0.0, maximum = 0.9)]
    pub lift_reserve_nondim: Option<f64>,
}

/// One grid point.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct EnvelopePointOutput {
    /// Wind at the reference height (m/s).
    pub wind_speed_m_s: f64,
    pub tether_length_m: f64,
    pub aerostat_altitude_m: f64,
    pub aerostat_downwind_m: f64,
    pub blowdown_angle_deg: f64,
    pub winch_tension_n: f64,
    pub top_tension_n: f64,
    pub max_tension_n: f64,
    pub min_tension_n: f64,
    pub safety_factor_nondim: Option<f64>,
    pub slack: bool,
    /// With a payout rate: `min T − ρA v²` (N).
    pub stability_margin_n: Option<f64>,
    /// With a payout rate: stable or not; null without one.
    pub stable: Option<bool>,
    /// With the quasi-static GE stability: max Re λ of the cell's local QEP
    /// (1/s); absent with the string criterion and for cells not solved
    /// (slack, not converged) or whose GE equilibrium failed (unstable).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_growth_rate_1_s: Option<f64>,
    /// Inside every limit (in the mean and, with `wind.gust`, in the gust).
    pub feasible: bool,
    /// The first limit violated, in the mean or in the gust: `slack`,
    /// `tension`, `ceiling`, `min_altitude`, `stability`, `not_converged`.
    pub binding_limit: Option<String>,
    /// With `wind.gust`: the same cell in the gust.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gust: Option<EnvelopeGustPointOutput>,
}

/// One grid point in the gust: the equilibrium at the gust speed, judged
/// against the same limits (with the quasi-static GE criterion the
/// stability is judged in the mean wind only).
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct EnvelopeGustPointOutput {
    /// Gust at the reference height (m/s): the row's wind times the gust factor.
    pub wind_speed_m_s: f64,
    pub aerostat_altitude_m: f64,
    pub aerostat_downwind_m: f64,
    pub blowdown_angle_deg: f64,
    /// Winch tension (N) in the gust's static equilibrium times
    /// `gust.dynamic_tension_factor_nondim`.
    pub winch_tension_n: f64,
    /// Top tension (N), times the dynamic factor.
    pub top_tension_n: f64,
    /// Largest tension (N), times the dynamic factor: the tension the
    /// rating is judged on.
    pub max_tension_n: f64,
    /// Largest tension of the static equilibrium in the gust (N), before the factor.
    pub static_max_tension_n: f64,
    /// Smallest tension of the static equilibrium in the gust (N), not
    /// factored (slack and stability are judged on it as it is).
    pub min_tension_n: f64,
    /// Breaking strength / `max_tension_n`; null without a breaking strength.
    pub safety_factor_nondim: Option<f64>,
    pub slack: bool,
    /// With a payout rate (string criterion): `min T − ρA v²` in the gust (N).
    pub stability_margin_n: Option<f64>,
    pub stable: Option<bool>,
    /// The first limit the gust alone violates; null: none.
    pub binding_limit: Option<String>,
    /// Whether the cell's binding limit is met in the gust (the mean is inside it, or meets a later one).
    pub binds: bool,
}

/// The gust the envelope was judged in.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct EnvelopeGustOutput {
    /// Gust over mean at every height: each row's gust is its wind times this.
    pub gust_factor_nondim: f64,
    /// Factor on the gust cells' static tensions (1.363 with a turbulence
    /// intensity, 1 for a gust given as a speed): the dynamic peak over the
    /// static check (`docs/gust_check.md`).
    pub dynamic_tension_factor_nondim: f64,
    /// Where that factor comes from and whether this wind lies within its measurement.
    pub dynamic_tension_note: String,
    /// How a cell is judged with gusts.
    pub rule: String,
}

/// The largest operating wind at one length.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct LengthLimitOutput {
    pub tether_length_m: f64,
    /// Largest grid wind up to which every grid wind is inside; null: not even the lowest.
    pub max_wind_speed_m_s: Option<f64>,
    /// Altitude at that wind (m).
    pub altitude_at_max_wind_m: Option<f64>,
    /// The limit met at the next wind; null: the whole grid is inside.
    pub binding_limit: Option<String>,
}

/// The highest altitude at one wind.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct WindLimitOutput {
    pub wind_speed_m_s: f64,
    /// Highest altitude inside the envelope (m); null: no length is inside.
    pub max_altitude_m: Option<f64>,
    /// The tether length that reaches it (m).
    pub tether_length_m: Option<f64>,
}

#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct EnvelopeResponse {
    pub wind_speeds_m_s: Vec<f64>,
    pub tether_lengths_m: Vec<f64>,
    /// Row by row: one row per wind speed, the lengths inside.
    pub points: Vec<EnvelopePointOutput>,
    pub max_wind_per_length: Vec<LengthLimitOutput>,
    pub max_altitude_per_wind: Vec<WindLimitOutput>,
    pub required_safety_factor_nondim: f64,
    pub ceiling_m: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_altitude_m: Option<f64>,
    pub payout_rate_m_s: Option<f64>,
    /// With `wind.gust`: the gust factor and the rule.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gust: Option<EnvelopeGustOutput>,
    /// What "stable" means here.
    pub stability_criterion: String,
    pub cable: ResolvedCableOutput,
    pub aerostat: ResolvedAerostatOutput,
    pub integration_steps: usize,
    /// With `stability.method = quasi_static_ge`: the model and, per wind
    /// speed, the maximum safe length/altitude and the critical payout rate.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quasi_static_ge: Option<super::stability::GeStabilityOutput>,
}
