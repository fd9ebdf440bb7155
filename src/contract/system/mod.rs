//! One system, described once (SPEC §9): the objects every request that
//! describes the physical system uses — [`CableInput`], [`AerostatInput`],
//! [`WindInput`] (with its [`WindFlowInput`]), [`WinchInput`] — the one
//! grid type ([`GridInput`]), their validation ([`validate`]), the named
//! aerostat presets ([`presets`]), and the resolution of a request before
//! it is parsed ([`resolve`]): a stored named system merged under the
//! request, the old plan names refused naming their new place. The request
//! and answer parts every domain shares ([`input`]: `SystemInput`, the
//! model, the profile; [`output`]: the groups, an eigenvalue) live here too
//! (not re-exported: `input` and `output` build on this file).
//!
//! Today's `/equilibrium` names are the canonical ones. SI at the
//! boundary; every field name ends in its unit (`_nondim` for pure
//! numbers); every bound in the schema is the bound the validation applies.

pub mod bounds;
pub mod grid;
pub mod input;
pub mod moved;
pub mod output;
pub mod presets;
pub mod resolve;
pub mod validate;

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

pub use grid::GridInput;
pub use moved::{MOVED, refuse_moved};

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

/// The tether. Give its mass per length as `mass_per_length_kg_m`, or as
/// `density_kg_m3` with `area_m2`, or as a `preset` with its `diameter_m`
/// (a preset fills every field left out; fields given always win).
/// Anything in wind needs `diameter_m` (the width its drag acts on).
#[derive(Clone, Debug, Default, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct CableInput {
    /// A material preset (`null` is refused: leave the field out instead).
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "present_value"
    )]
    pub preset: Option<CablePresetName>,
    /// Diameter d (m): the reference width of the normal drag; required with a preset or in wind.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 0.006, exclusive_minimum = 0.0, maximum = 1.0)]
    pub diameter_m: Option<f64>,
    /// Mass per unit (unstretched) length ρA (kg/m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 0.078, minimum = 1e-5, maximum = 100.0)]
    pub mass_per_length_kg_m: Option<f64>,
    /// Material density ρ (kg/m³), with `area_m2` (e.g. 7800 for steel).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(minimum = 100.0, maximum = 30000.0)]
    pub density_kg_m3: Option<f64>,
    /// Cross-section area A (m²), with `density_kg_m3` (e.g. 1e-5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(minimum = 1e-9, maximum = 0.1)]
    pub area_m2: Option<f64>,
    /// Normal drag coefficient C_n (default 1.2, a cylinder in cross flow).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 1.2, minimum = 0.0, maximum = 10.0)]
    pub normal_drag_coefficient_nondim: Option<f64>,
    /// Axial stiffness EA (N); absent: inextensible (unless a preset gives it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 850000.0, exclusive_minimum = 0.0, maximum = 1e12)]
    pub axial_stiffness_n: Option<f64>,
    /// Bending stiffness EI (N m²), for the geometrically exact models; absent: the model's own default.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 1000.0, minimum = 1e-6, maximum = 1e12)]
    pub bending_stiffness_n_m2: Option<f64>,
    /// Breaking strength (N); absent (and no preset): the tension is NOT checked, and answers say so.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 30000.0, exclusive_minimum = 0.0, maximum = 1e9)]
    pub breaking_strength_n: Option<f64>,
}

/// An aerostat preset: a shape (`sphere` with `radius_m`, `streamlined`
/// with `volume_m3`) filling the coefficients and the reference area, or a
/// named aerostat filling every figure it has (each with its source:
/// `GET /api/v1/presets`). Fields given always win.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, ToSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum BodyPresetName {
    /// Spherical balloon: C_D 0.47, no lift, area π r² (with `radius_m`).
    Sphere,
    /// Finned streamlined hull: C_D 0.05, C_L 0.1 on V^(2/3) (with `volume_m3`).
    Streamlined,
    /// The thesis aerostat (Table 7.1): F = 1000 N, m = 10 kg; aerodynamics of a 1 m sphere.
    #[serde(rename = "thesis_table_7_1")]
    ThesisTable71,
    /// A small helium sphere, 3 m across: F ≈ 107 N, m = 4 kg.
    #[serde(rename = "helium_sphere_3m")]
    HeliumSphere3m,
    /// A streamlined finned hull of 250 m³: F ≈ 1600 N, m = 100 kg.
    #[serde(rename = "streamlined_hull_250m3")]
    StreamlinedHull250m3,
}

/// The aerostat. Give `net_buoyancy_n` (and `mass_kg`) or a named
/// preset; the drag data (`drag_coefficient_nondim` on
/// `reference_area_m2`, or a shape preset with its size) are needed in wind.
#[derive(Clone, Debug, Default, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct AerostatInput {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preset: Option<BodyPresetName>,
    /// Sphere radius (m), for `preset: sphere`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(exclusive_minimum = 0.0, maximum = 100.0)]
    pub radius_m: Option<f64>,
    /// Envelope volume (m³), for `preset: streamlined`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(exclusive_minimum = 0.0, maximum = 1e7)]
    pub volume_m3: Option<f64>,
    /// Net buoyancy F = buoyancy − weight (N): the upward pull on the tether.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 1000.0, minimum = 0.001, maximum = 1e7)]
    pub net_buoyancy_n: Option<f64>,
    /// Aerostat mass m (kg), default 0 (or the preset's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 10.0, minimum = 0.0, maximum = 1e6)]
    pub mass_kg: Option<f64>,
    /// Drag coefficient C_D on `reference_area_m2`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 0.3, minimum = 0.0, maximum = 10.0)]
    pub drag_coefficient_nondim: Option<f64>,
    /// Reference area A (m²) of the drag and lift coefficients.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 20.0, exclusive_minimum = 0.0, maximum = 1e5)]
    pub reference_area_m2: Option<f64>,
    /// Aerodynamic lift coefficient C_L on `reference_area_m2` (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 0.0, minimum = -10.0, maximum = 10.0)]
    pub lift_coefficient_nondim: Option<f64>,
    /// Added-mass coefficient C_a on the displaced air (default 0.5, a sphere), for the dynamics (SPEC §11).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 0.5, minimum = 0.0, maximum = 10.0)]
    pub added_mass_coefficient_nondim: Option<f64>,
    /// Geometrically exact models: length of the rigid link from the cable end to the aerostat's centre (m), default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 0.0, minimum = 0.0, maximum = 1000.0)]
    pub link_length_m: Option<f64>,
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
        #[schema(example = 6.0, minimum = -150.0, maximum = 150.0)]
        speed_m_s: f64,
    },
    /// U = a (z/z_ref)^p; a is the speed at the reference height (default 1 m).
    PowerLaw {
        #[schema(example = 3.0, minimum = -150.0, maximum = 150.0)]
        coefficient_m_s: f64,
        #[schema(example = 0.14, minimum = 0.0, maximum = 2.0)]
        exponent_nondim: f64,
        /// Height of the speed `coefficient_m_s` (m), default 1.
        #[serde(default = "one_metre")]
        #[schema(example = 10.0, exclusive_minimum = 0.0, maximum = 10000.0)]
        reference_height_m: f64,
    },
    /// Linear interpolation in (z, U), constant beyond the ends (1 to 10 000 points).
    Tabulated { points: Vec<WindPointInput> },
    /// U = U_ref ln(z/z0)/ln(z_ref/z0) above z0, 0 below.
    LogLaw {
        /// Speed at the reference height (m/s); `reference_speed_m_s` is accepted for it.
        #[serde(alias = "reference_speed_m_s")]
        #[schema(example = 6.0, minimum = -150.0, maximum = 150.0)]
        speed_m_s: f64,
        /// Reference height (m), default 10 (the meteorological standard).
        #[serde(default = "default_reference_height")]
        #[schema(example = 10.0, exclusive_minimum = 0.0, maximum = 10000.0)]
        reference_height_m: f64,
        /// Roughness length z0 (m): 0.0002 sea, 0.03 open terrain, 0.1 farmland, 1 city.
        #[schema(example = 0.03, minimum = 0.000001, maximum = 10.0)]
        roughness_length_m: f64,
    },
}

impl WindFlowInput {
    /// Whether the flow is calm everywhere (every speed zero).
    pub fn is_calm(&self) -> bool {
        match self {
            Self::Uniform { speed_m_s } => *speed_m_s == 0.0,
            Self::PowerLaw {
                coefficient_m_s, ..
            } => *coefficient_m_s == 0.0,
            Self::Tabulated { points } => points.iter().all(|p| p.speed_m_s == 0.0),
            Self::LogLaw { speed_m_s, .. } => *speed_m_s == 0.0,
        }
    }
}

/// An optional field whose value, when the key is given, may not be
/// `null`: in the schema it has no null form (the key is left out instead).
fn present_value<'de, D, T>(d: D) -> Result<Option<T>, D::Error>
where
    D: serde::Deserializer<'de>,
    T: Deserialize<'de>,
{
    match Option::<T>::deserialize(d)? {
        Some(v) => Ok(Some(v)),
        None => Err(serde::de::Error::custom(
            "is null: give a value or leave the field out",
        )),
    }
}

fn one_metre() -> f64 {
    1.0
}

pub(crate) fn default_reference_height() -> f64 {
    10.0
}

/// Gusts (SPEC §10): the gust speed at a height is the mean times
/// `1 + k I` (`turbulence_intensity_nondim` I = σ_u/U, `peak_factor_nondim`
/// k, default 3: about the 3-second gust over 10 minutes), or the gust
/// speed `gust_m_s` at the flow's reference height (a log or power law's
/// own, else 10 m, the anemometer height), which scales the whole profile.
/// Give one of `turbulence_intensity_nondim` and `gust_m_s`. The gust
/// enters the equilibrium exactly as a faster mean wind would; with I = 0
/// every answer equals the mean-wind one.
#[derive(Clone, Debug, Default, Deserialize, Serialize, ToSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct GustInput {
    /// Turbulence intensity I = σ_u / U (0 to 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 0.15, minimum = 0.0, maximum = 1.0)]
    pub turbulence_intensity_nondim: Option<f64>,
    /// Peak factor k of the gust factor 1 + k I (default 3), with `turbulence_intensity_nondim`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 3.0, minimum = 0.0, maximum = 10.0)]
    pub peak_factor_nondim: Option<f64>,
    /// Gust speed at the flow's reference height (m/s), at least the mean there.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 12.0, minimum = 0.0, maximum = 150.0)]
    pub gust_m_s: Option<f64>,
}

/// The air: its density, its steady flow and its gusts. Absent: calm air.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct WindInput {
    pub flow: WindFlowInput,
    /// Air density (kg/m³), default 1.225 (ISA sea level).
    #[serde(default = "default_air_density")]
    #[schema(example = 1.225, exclusive_minimum = 0.0, maximum = 5.0)]
    pub air_density_kg_m3: f64,
    /// Gusts on the mean flow (SPEC §10); absent: the mean wind only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gust: Option<GustInput>,
}

impl WindInput {
    /// Whether the air is calm everywhere, gusts included (a gust factor
    /// on a calm flow is calm; a gust speed above zero is not).
    pub fn is_calm(&self) -> bool {
        self.flow.is_calm()
            && self
                .gust
                .as_ref()
                .and_then(|g| g.gust_m_s)
                .is_none_or(|g| g == 0.0)
    }

    /// Refuses a non-zero wind in an analysis computed in calm air.
    pub fn require_calm(
        wind: Option<&Self>,
        analysis: &str,
    ) -> Result<(), crate::numerics::params::InvalidInput> {
        match wind {
            Some(w) if !w.flow.is_calm() => Err(crate::numerics::params::InvalidInput::new(
                "wind.flow",
                format!(
                    "this analysis ({analysis}) is in calm air; give a wind of zero speed or leave `wind` out \
                     (the plan, the equilibrium and the envelope take the wind)"
                ),
            )),
            Some(w)
                if w.gust
                    .as_ref()
                    .and_then(|g| g.gust_m_s)
                    .is_some_and(|g| g != 0.0) =>
            {
                Err(crate::numerics::params::InvalidInput::new(
                    "wind.gust.gust_m_s",
                    format!(
                        "this analysis ({analysis}) is in calm air; give no gust speed \
                         (the plan, the equilibrium and the envelope take the gusts)"
                    ),
                ))
            }
            _ => Ok(()),
        }
    }
}

pub(crate) fn default_air_density() -> f64 {
    1.225
}

/// Winch limits.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct WinchInput {
    /// Largest winch rate |L̇| (m/s).
    #[schema(example = 40.0, exclusive_minimum = 0.0, maximum = 1000.0)]
    pub max_rate_m_s: f64,
    /// Largest winch acceleration |L̈| (m/s²), speeding up and braking.
    #[schema(example = 2.0, exclusive_minimum = 0.0, maximum = 100.0)]
    pub max_acceleration_m_s2: f64,
    /// Largest rate of change of the winch acceleration (m/s³); absent: not
    /// limited. With it the schedule is an S-curve (the acceleration ramps).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 1.0, exclusive_minimum = 0.0, maximum = 10000.0)]
    pub max_jerk_m_s3: Option<f64>,
}

/// The safety factor operators require by default: 5 on fibrous tethers
/// (FAA 14 CFR 31.25 practice).
pub(crate) fn default_safety_factor() -> f64 {
    5.0
}

/// The lift reserve by default: 5 % of the net buoyancy.
pub(crate) fn default_lift_reserve() -> f64 {
    0.05
}

/// The top-level system keys every request takes (besides `cable`, `aerostat`).
pub const TOP_LEVEL_KEYS: &[&str] = &[
    "wind",
    "winch",
    "initial_length_m",
    "gravity_m_s2",
    "required_safety_factor_nondim",
    "lift_reserve_nondim",
];

/// A stored named system (`PUT /api/v1/systems/{name}`): the system
/// objects of SPEC §9, without `system`. Every part is optional; a request
/// that names the system gives (or overrides) the rest.
#[derive(Clone, Debug, Default, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({
    "cable": {"mass_per_length_kg_m": 0.078, "diameter_m": 0.006, "breaking_strength_n": 30000.0},
    "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0, "drag_coefficient_nondim": 0.3,
                 "reference_area_m2": 20.0},
    "winch": {"max_rate_m_s": 40.0, "max_acceleration_m_s2": 2.0},
    "required_safety_factor_nondim": 5.0,
    "lift_reserve_nondim": 0.05
}))]
pub struct SystemDescription {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cable: Option<CableInput>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aerostat: Option<AerostatInput>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wind: Option<WindInput>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub winch: Option<WinchInput>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 1.0, minimum = 0.001, maximum = 10000.0)]
    pub initial_length_m: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 9.81, minimum = 0.01, maximum = 100.0)]
    pub gravity_m_s2: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 5.0, minimum = 1.0, maximum = 100.0)]
    pub required_safety_factor_nondim: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 0.05, minimum = 0.0, maximum = 0.9)]
    pub lift_reserve_nondim: Option<f64>,
}
