//! Validated physical parameters of the cable–aerostat system (SI) and the
//! non-dimensional groups of SPEC §1 / thesis §2.3:
//!
//! ```text
//! c = sqrt(F/ρA)  (wave speed)      t̄ = t c / L0      l = L/L0
//! ṽ = L̇ / c       ã = L̈ L0 / c²      F̃ = F/(ρA g L0)   m̃ = m/(ρA L0)
//! ```

use std::fmt;

/// Invalid input: the field (as named in the JSON contract) and why.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{field}: {reason}")]
pub struct InvalidInput {
    pub field: String,
    pub reason: String,
}

impl InvalidInput {
    pub fn new(field: impl Into<String>, reason: impl fmt::Display) -> Self {
        Self {
            field: field.into(),
            reason: reason.to_string(),
        }
    }
}

/// Checks that `value` is finite and `> 0`.
pub fn require_positive(field: &str, value: f64) -> Result<f64, InvalidInput> {
    if !value.is_finite() {
        return Err(InvalidInput::new(
            field,
            format!("must be a finite number, got {value}"),
        ));
    }
    if value <= 0.0 {
        return Err(InvalidInput::new(
            field,
            format!("must be greater than zero, got {value}"),
        ));
    }
    Ok(value)
}

/// Checks that `value` is finite and `>= 0`.
pub fn require_non_negative(field: &str, value: f64) -> Result<f64, InvalidInput> {
    if !value.is_finite() {
        return Err(InvalidInput::new(
            field,
            format!("must be a finite number, got {value}"),
        ));
    }
    if value < 0.0 {
        return Err(InvalidInput::new(
            field,
            format!("must not be negative, got {value}"),
        ));
    }
    Ok(value)
}

/// Checks that `value` is finite.
pub fn require_finite(field: &str, value: f64) -> Result<f64, InvalidInput> {
    if !value.is_finite() {
        return Err(InvalidInput::new(
            field,
            format!("must be a finite number, got {value}"),
        ));
    }
    Ok(value)
}

/// A closed range of physically plausible values of one input, with its
/// unit: the one place where the accepted magnitudes are written down (the
/// `#[schema(minimum, maximum)]` bounds of the JSON contract equal these;
/// `tests/contract_ranges.rs` checks it against the OpenAPI document).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Range {
    pub min: f64,
    pub max: f64,
    /// Unit as written in messages (`kg/m`); empty for pure numbers.
    pub unit: &'static str,
}

impl Range {
    pub const fn new(min: f64, max: f64, unit: &'static str) -> Self {
        Self { min, max, unit }
    }

    /// `value` if it is finite and within the range; otherwise an error
    /// naming `field` and stating the range.
    pub fn check(&self, field: &str, value: f64) -> Result<f64, InvalidInput> {
        if value.is_finite() && value >= self.min && value <= self.max {
            return Ok(value);
        }
        let unit = if self.unit.is_empty() {
            String::new()
        } else {
            format!(" {}", self.unit)
        };
        Err(InvalidInput::new(
            field,
            format!(
                "must be between {} and {}{unit}, got {}",
                compact(self.min),
                compact(self.max),
                compact(value)
            ),
        ))
    }
}

/// `1e-5`, `0.01`, `100`, `1e7`: short forms for messages.
pub fn compact(v: f64) -> String {
    if v != 0.0 && (v.abs() >= 1e5 || v.abs() < 1e-3) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// Plausible magnitudes of every physical input (SI). Chosen to contain
/// every real tethered aerostat and winch with margin, and to keep the
/// non-dimensional groups in the range where the solvers stay finite.
pub mod ranges {
    use super::Range;

    /// Cable mass per length ρA: from a thin fibre line to a heavy armoured cable.
    pub const MASS_PER_LENGTH_KG_M: Range = Range::new(1e-5, 100.0, "kg/m");
    /// Cable material density ρ.
    pub const DENSITY_KG_M3: Range = Range::new(100.0, 30_000.0, "kg/m³");
    /// Cable cross-section area A.
    pub const AREA_M2: Range = Range::new(1e-9, 0.1, "m²");
    /// Net buoyancy F of the linear string (must pull: > 0).
    pub const NET_BUOYANCY_N: Range = Range::new(1e-3, 1e7, "N");
    /// Net buoyancy of the geometrically exact cable (0: a bare cantilever).
    pub const GE_NET_BUOYANCY_N: Range = Range::new(0.0, 1e7, "N");
    /// Aerostat mass m.
    pub const AEROSTAT_MASS_KG: Range = Range::new(0.0, 1e6, "kg");
    /// Initial length L0, the length scale.
    pub const INITIAL_LENGTH_M: Range = Range::new(1e-3, 1e4, "m");
    /// Gravity of the linear string (the static limit F/(ρA g) needs g > 0).
    pub const GRAVITY_M_S2: Range = Range::new(0.01, 100.0, "m/s²");
    /// Gravity of the geometrically exact cable (0 allowed, thesis ch. 8).
    pub const GE_GRAVITY_M_S2: Range = Range::new(0.0, 100.0, "m/s²");
    /// A cable length (state, target): up to 100 km.
    pub const LENGTH_M: Range = Range::new(1e-3, 1e5, "m");
    /// A winch rate, either sign.
    pub const RATE_M_S: Range = Range::new(-1000.0, 1000.0, "m/s");
    /// A positive winch rate (chart grids).
    pub const POSITIVE_RATE_M_S: Range = Range::new(1e-6, 1000.0, "m/s");
    /// A winch acceleration, either sign.
    pub const ACCELERATION_M_S2: Range = Range::new(-1000.0, 1000.0, "m/s²");
    /// A time in a profile or a load history.
    pub const TIME_S: Range = Range::new(0.0, 1e7, "s");
    /// A run duration.
    pub const DURATION_S: Range = Range::new(1e-6, 1e7, "s");
    /// A time step.
    pub const TIME_STEP_S: Range = Range::new(1e-9, 1e3, "s");
    /// A wind speed, either sign.
    pub const WIND_SPEED_M_S: Range = Range::new(-200.0, 200.0, "m/s");
    /// A force on the aerostat, either sign.
    pub const FORCE_N: Range = Range::new(-1e8, 1e8, "N");
    /// A couple on the aerostat, either sign.
    pub const MOMENT_N_M: Range = Range::new(-1e8, 1e8, "N m");
    /// Aerostat radius.
    pub const RADIUS_M: Range = Range::new(1e-3, 1000.0, "m");
    /// Air or lifting-gas density.
    pub const GAS_DENSITY_KG_M3: Range = Range::new(1e-4, 100.0, "kg/m³");
    /// GE bending stiffness EI.
    pub const BENDING_STIFFNESS_N_M2: Range = Range::new(1e-6, 1e12, "N m²");
    /// GE ratios E* = EA L0²/EI and G A_s L0²/EI.
    pub const STIFFNESS_RATIO: Range = Range::new(1.0, 1e12, "");
    /// GE γ̃ = A_ρ L0²/I_ρ.
    pub const INERTIA_RATIO: Range = Range::new(1e-6, 1e12, "");
    /// A length of the rigid aerostat link.
    pub const LINK_LENGTH_M: Range = Range::new(0.0, 1000.0, "m");
    /// A forcing frequency.
    pub const FREQUENCY_RAD_S: Range = Range::new(0.0, 1e4, "rad/s");
    /// A platform amplitude of the base excitation.
    pub const BASE_AMPLITUDE_M: Range = Range::new(1e-9, 1000.0, "m");
    /// An elevation of a tabulated wind profile.
    pub const ELEVATION_M: Range = Range::new(0.0, 1e5, "m");
    /// A wind perturbation amplitude A0 of thesis (7.4).
    pub const AMPLITUDE_NONDIM: Range = Range::new(-10.0, 10.0, "");
    /// A wind perturbation wavenumber k.
    pub const WAVENUMBER_1_M: Range = Range::new(0.0, 1000.0, "1/m");
    /// A power-law wind exponent p of u = a z^p.
    pub const EXPONENT_NONDIM: Range = Range::new(0.0, 2.0, "");
    /// A drag coefficient C_D.
    pub const DRAG_COEFFICIENT_NONDIM: Range = Range::new(0.0, 100.0, "");
    /// A drag reference area.
    pub const REFERENCE_AREA_M2: Range = Range::new(1e-6, 1e6, "m²");
    /// A linear damping rate per unit mass, or a growth-rate tolerance.
    pub const RATE_1_S: Range = Range::new(0.0, 1e6, "1/s");
    /// ε of the two-DOF model of thesis (8.8).
    pub const EPSILON_NONDIM: Range = Range::new(0.0, 10.0, "");
    /// Initial tip deflection of a transient run, as a multiple of L0
    /// (either sign): beyond it the linear string is meaningless.
    pub const TIP_DEFLECTION_LENGTHS: f64 = 1.0;
}

/// The physical system: a heavy cable of changing length with the aerostat
/// at its top. All fields SI.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AerostatSystem {
    /// Cable mass per unit length `ρA` (kg/m).
    pub mass_per_length_kg_m: f64,
    /// Net buoyancy `F = F_b − m g` (N), the upward pull on the cable.
    pub net_buoyancy_n: f64,
    /// Aerostat mass `m` (kg).
    pub aerostat_mass_kg: f64,
    /// Initial (reference) cable length `L0` (m).
    pub initial_length_m: f64,
    /// Gravitational acceleration `g` (m/s²).
    pub gravity_m_s2: f64,
}

impl AerostatSystem {
    pub fn new(
        mass_per_length_kg_m: f64,
        net_buoyancy_n: f64,
        aerostat_mass_kg: f64,
        initial_length_m: f64,
        gravity_m_s2: f64,
    ) -> Result<Self, InvalidInput> {
        Ok(Self {
            mass_per_length_kg_m: require_positive(
                "cable.mass_per_length_kg_m",
                mass_per_length_kg_m,
            )
            .and_then(|v| ranges::MASS_PER_LENGTH_KG_M.check("cable.mass_per_length_kg_m", v))?,
            net_buoyancy_n: require_positive("aerostat.net_buoyancy_n", net_buoyancy_n)
                .and_then(|v| ranges::NET_BUOYANCY_N.check("aerostat.net_buoyancy_n", v))?,
            aerostat_mass_kg: ranges::AEROSTAT_MASS_KG
                .check("aerostat.mass_kg", aerostat_mass_kg)?,
            initial_length_m: ranges::INITIAL_LENGTH_M
                .check("initial_length_m", initial_length_m)?,
            gravity_m_s2: ranges::GRAVITY_M_S2.check("gravity_m_s2", gravity_m_s2)?,
        })
    }

    /// Table A1 of the thesis: steel cable ρ = 7800 kg/m³, A = 1e-5 m²,
    /// F = 1000 N, m = 10 kg, L0 = 1 m, g = 9.81 m/s².
    pub fn thesis() -> Self {
        Self::new(7800.0 * 1e-5, 1000.0, 10.0, 1.0, 9.81).expect("thesis data are valid")
    }

    pub fn with_net_buoyancy(self, net_buoyancy_n: f64) -> Result<Self, InvalidInput> {
        Self::new(
            self.mass_per_length_kg_m,
            net_buoyancy_n,
            self.aerostat_mass_kg,
            self.initial_length_m,
            self.gravity_m_s2,
        )
    }

    /// Transverse wave speed at tension `F`: `c = sqrt(F/ρA)` (m/s).
    pub fn wave_speed_m_s(&self) -> f64 {
        (self.net_buoyancy_n / self.mass_per_length_kg_m).sqrt()
    }

    /// Time scale `L0 / c` (s): `t = t̄ · time_scale`.
    pub fn time_scale_s(&self) -> f64 {
        self.initial_length_m / self.wave_speed_m_s()
    }

    /// `F̃ = F/(ρA g L0)`.
    pub fn buoyancy_ratio(&self) -> f64 {
        self.net_buoyancy_n
            / (self.mass_per_length_kg_m * self.gravity_m_s2 * self.initial_length_m)
    }

    /// `m̃ = m/(ρA L0)`.
    pub fn mass_ratio(&self) -> f64 {
        self.aerostat_mass_kg / (self.mass_per_length_kg_m * self.initial_length_m)
    }

    /// Length at which the cable weight equals the net buoyancy,
    /// `F/(ρA g)` (m): no rate is safe above it.
    pub fn static_lift_limit_m(&self) -> f64 {
        self.net_buoyancy_n / (self.mass_per_length_kg_m * self.gravity_m_s2)
    }

    /// Continuum bound on the elevation at constant rate `v`:
    /// `h* = (F/ρA − v²)/g` (m), where the roller-end effective tension
    /// `T(0) − l̇²/l` vanishes. Negative means unstable at any length.
    pub fn closed_form_elevation_m(&self, rate_m_s: f64) -> f64 {
        (self.net_buoyancy_n / self.mass_per_length_kg_m - rate_m_s * rate_m_s) / self.gravity_m_s2
    }

    /// Continuum estimate of the critical length for constant acceleration
    /// from rest at `L0`: root-end effective tension zero with
    /// `l̇² = 2 ã (l − 1)`, i.e. `l* = (1 + 2ã − m̃ ã)/(1/F̃ + 3ã)` (m).
    pub fn closed_form_elevation_accelerating_m(&self, acceleration_m_s2: f64) -> f64 {
        let a = self.to_nondim_acceleration(acceleration_m_s2);
        let l = (1.0 + 2.0 * a - self.mass_ratio() * a) / (1.0 / self.buoyancy_ratio() + 3.0 * a);
        l * self.initial_length_m
    }

    pub fn to_nondim(&self, k: Kinematics) -> NondimState {
        NondimState {
            length: k.length_m / self.initial_length_m,
            rate: k.rate_m_s / self.wave_speed_m_s(),
            acceleration: self.to_nondim_acceleration(k.acceleration_m_s2),
        }
    }

    pub fn to_nondim_acceleration(&self, acceleration_m_s2: f64) -> f64 {
        let c = self.wave_speed_m_s();
        acceleration_m_s2 * self.initial_length_m / (c * c)
    }

    /// Converts a non-dimensional eigenvalue (1/t̄) to 1/s.
    pub fn eigenvalue_to_si(&self, value: f64) -> f64 {
        value / self.time_scale_s()
    }
}

/// Length, rate and acceleration of the deployment at one instant (SI).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Kinematics {
    pub length_m: f64,
    pub rate_m_s: f64,
    pub acceleration_m_s2: f64,
}

/// Non-dimensional state `(l, l̇, l̈)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NondimState {
    pub length: f64,
    pub rate: f64,
    pub acceleration: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thesis_groups() {
        let s = AerostatSystem::thesis();
        assert!((s.wave_speed_m_s() - 113.227).abs() < 1e-3);
        assert!((s.closed_form_elevation_m(10.0) - 1296.688).abs() < 1e-3);
        assert!((s.buoyancy_ratio() - 1306.882).abs() < 1e-3);
        assert!((s.mass_ratio() - 128.205).abs() < 1e-3);
        // the accelerating estimate reduces to the static limit as ã → 0
        assert!(
            (s.closed_form_elevation_accelerating_m(1e-12) - s.static_lift_limit_m()).abs() < 1e-3
        );
    }

    #[test]
    fn rejects_bad_values_naming_the_field() {
        let e = AerostatSystem::new(f64::NAN, 1000.0, 10.0, 1.0, 9.81).unwrap_err();
        assert_eq!(e.field, "cable.mass_per_length_kg_m");
        let e = AerostatSystem::new(0.078, -5.0, 10.0, 1.0, 9.81).unwrap_err();
        assert_eq!(e.field, "aerostat.net_buoyancy_n");
        assert!(e.reason.contains("greater than zero"));
        let e = AerostatSystem::new(0.078, 1000.0, -1.0, 1.0, 9.81).unwrap_err();
        assert_eq!(e.field, "aerostat.mass_kg");
    }
}
