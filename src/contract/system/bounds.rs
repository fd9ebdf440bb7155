//! The bounds of the system's fields (SPEC §9), written once: every route
//! that takes the system (the string's, the plan, the equilibrium, the
//! envelope, the dynamics, …) checks a field against the one [`Bound`]
//! here, so a value is refused for the same reason, in the same words,
//! whichever route it is posted to. The schema's `minimum`/`maximum` are
//! these numbers.
//!
//! Two message styles stay as they were: the [`Bound`]s say `must be above
//! 0 and at most 1, got 2` ([`require_range`]); the plausible magnitudes of
//! the numerical core ([`crate::numerics::params::ranges`], re-exported
//! below for the fields that use them) say `must be between 0.001 and 1e7
//! N, got 0`.

use crate::numerics::params::{InvalidInput, compact, require_finite};
use crate::numerics::tether::gust::{MAX_PEAK_FACTOR, MAX_TURBULENCE_INTENSITY};

pub use crate::numerics::params::ranges::{
    AEROSTAT_MASS_KG, GRAVITY_M_S2 as STRING_GRAVITY_M_S2, INITIAL_LENGTH_M, LINK_LENGTH_M,
    MASS_PER_LENGTH_KG_M, NET_BUOYANCY_N,
};

/// `value` finite and within `[min, max]`; `exclusive_min` excludes `min`.
pub(crate) fn require_range(
    field: &str,
    value: f64,
    min: f64,
    exclusive_min: bool,
    max: f64,
) -> Result<f64, InvalidInput> {
    require_finite(field, value)?;
    let low_ok = if exclusive_min {
        value > min
    } else {
        value >= min
    };
    if !low_ok || value > max {
        let low = if exclusive_min { "above" } else { "at least" };
        return Err(InvalidInput::new(
            field,
            format!(
                "must be {low} {} and at most {}, got {}",
                compact(min),
                compact(max),
                compact(value)
            ),
        ));
    }
    Ok(value)
}

/// A count within `[min, max]`.
pub(crate) fn require_count(
    field: &str,
    value: usize,
    min: usize,
    max: usize,
) -> Result<usize, InvalidInput> {
    if value < min || value > max {
        return Err(InvalidInput::new(
            field,
            format!("must be between {min} and {max}, got {value}"),
        ));
    }
    Ok(value)
}

/// The bound of one field: finite, at least `min` (above it when
/// `exclusive_min`), at most `max`. `name` is the field's own name; the
/// caller gives the path above it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bound {
    pub name: &'static str,
    pub min: f64,
    pub exclusive_min: bool,
    pub max: f64,
}

impl Bound {
    /// `[min, max]`.
    const fn closed(name: &'static str, min: f64, max: f64) -> Self {
        Self {
            name,
            min,
            exclusive_min: false,
            max,
        }
    }

    /// `(min, max]`.
    const fn above(name: &'static str, min: f64, max: f64) -> Self {
        Self {
            name,
            min,
            exclusive_min: true,
            max,
        }
    }

    /// A top-level field (`gravity_m_s2`).
    pub fn check(&self, value: f64) -> Result<f64, InvalidInput> {
        self.check_field(self.name, value)
    }

    /// A field under `at` (`cable` → `cable.diameter_m`).
    pub fn check_at(&self, at: &str, value: f64) -> Result<f64, InvalidInput> {
        self.check_field(&format!("{at}.{}", self.name), value)
    }

    /// The bound under another field's name (the same quantity: a power
    /// law's `coefficient_m_s` is a wind speed).
    pub fn check_field(&self, field: &str, value: f64) -> Result<f64, InvalidInput> {
        require_range(field, value, self.min, self.exclusive_min, self.max)
    }
}

/// The bound of a count: within `[min, max]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CountBound {
    pub name: &'static str,
    pub min: usize,
    pub max: usize,
}

impl CountBound {
    pub fn check(&self, value: usize) -> Result<usize, InvalidInput> {
        require_count(self.name, value, self.min, self.max)
    }
}

// The tether (`cable`; the mass per length: [`MASS_PER_LENGTH_KG_M`]).
pub const DIAMETER_M: Bound = Bound::above("diameter_m", 0.0, 1.0);
pub const DENSITY_KG_M3: Bound = Bound::closed("density_kg_m3", 100.0, 30_000.0);
pub const AREA_M2: Bound = Bound::closed("area_m2", 1e-9, 0.1);
pub const NORMAL_DRAG_COEFFICIENT: Bound =
    Bound::closed("normal_drag_coefficient_nondim", 0.0, 10.0);
pub const AXIAL_STIFFNESS_N: Bound = Bound::above("axial_stiffness_n", 0.0, 1e12);
pub const BENDING_STIFFNESS_N_M2: Bound = Bound::closed("bending_stiffness_n_m2", 1e-6, 1e12);
pub const BREAKING_STRENGTH_N: Bound = Bound::above("breaking_strength_n", 0.0, 1e9);

// The aerostat (net buoyancy, mass, link: [`NET_BUOYANCY_N`],
// [`AEROSTAT_MASS_KG`], [`LINK_LENGTH_M`]).
pub const RADIUS_M: Bound = Bound::above("radius_m", 0.0, 100.0);
pub const VOLUME_M3: Bound = Bound::above("volume_m3", 0.0, 1e7);
pub const DRAG_COEFFICIENT: Bound = Bound::closed("drag_coefficient_nondim", 0.0, 10.0);
pub const REFERENCE_AREA_M2: Bound = Bound::above("reference_area_m2", 0.0, 1e5);
pub const LIFT_COEFFICIENT: Bound = Bound::closed("lift_coefficient_nondim", -10.0, 10.0);
pub const ADDED_MASS_COEFFICIENT: Bound = Bound::closed("added_mass_coefficient_nondim", 0.0, 10.0);

// The air (`wind`, its `flow` and its `gust`).
pub const WIND_SPEED_M_S: Bound = Bound::closed("speed_m_s", -150.0, 150.0);
pub const EXPONENT: Bound = Bound::closed("exponent_nondim", 0.0, 2.0);
pub const REFERENCE_HEIGHT_M: Bound = Bound::above("reference_height_m", 0.0, 1e4);
/// Smallest roughness length z0 (m): below it ln(z/z0) overflows in
/// double precision long before any real surface (smooth ice ≈ 1e-5 m).
pub const MIN_ROUGHNESS_M: f64 = 1e-6;
pub const ROUGHNESS_LENGTH_M: Bound = Bound::closed("roughness_length_m", MIN_ROUGHNESS_M, 10.0);
pub const ELEVATION_M: Bound = Bound::closed("elevation_m", 0.0, 1e5);
pub const AIR_DENSITY_KG_M3: Bound = Bound::above("air_density_kg_m3", 0.0, 5.0);
pub const TURBULENCE_INTENSITY: Bound =
    Bound::closed("turbulence_intensity_nondim", 0.0, MAX_TURBULENCE_INTENSITY);
pub const PEAK_FACTOR: Bound = Bound::closed("peak_factor_nondim", 0.0, MAX_PEAK_FACTOR);
/// Largest gust speed accepted at the reference height (m/s): the flow's bound.
pub const MAX_GUST_M_S: f64 = 150.0;
pub const GUST_M_S: Bound = Bound::closed("gust_m_s", 0.0, MAX_GUST_M_S);

// The winch (`winch`).
pub const MAX_RATE_M_S: Bound = Bound::above("max_rate_m_s", 0.0, 1000.0);
pub const MAX_ACCELERATION_M_S2: Bound = Bound::above("max_acceleration_m_s2", 0.0, 100.0);
pub const MAX_JERK_M_S3: Bound = Bound::above("max_jerk_m_s3", 0.0, 10_000.0);

// The top-level numbers (the string's gravity and initial length:
// [`STRING_GRAVITY_M_S2`], [`INITIAL_LENGTH_M`]).
/// Gravity of the routes in wind (equilibrium, envelope, dynamics).
pub const GRAVITY_M_S2: Bound = Bound::above("gravity_m_s2", 0.0, 100.0);
pub const REQUIRED_SAFETY_FACTOR: Bound =
    Bound::closed("required_safety_factor_nondim", 1.0, 100.0);
pub const LIFT_RESERVE: Bound = Bound::closed("lift_reserve_nondim", 0.0, 0.9);

// The equilibrium's own settings, shared by the equilibrium and the envelope.
pub const PAYOUT_RATE_M_S: Bound = Bound::closed("payout_rate_m_s", 0.0, 1000.0);
pub const INTEGRATION_STEPS: CountBound = CountBound {
    name: "integration_steps",
    min: 8,
    max: 100_000,
};
