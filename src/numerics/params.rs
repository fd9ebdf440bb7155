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
            )?,
            net_buoyancy_n: require_positive("aerostat.net_buoyancy_n", net_buoyancy_n)?,
            aerostat_mass_kg: require_non_negative("aerostat.mass_kg", aerostat_mass_kg)?,
            initial_length_m: require_positive("initial_length_m", initial_length_m)?,
            gravity_m_s2: require_positive("gravity_m_s2", gravity_m_s2)?,
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
