//! Steady horizontal wind profiles `U(z)` for the static tether (SPEC §6):
//! the air-flow kinds of [`crate::numerics::aero::SteadyFlow`] (uniform,
//! power law, tabulated) plus the neutral atmospheric surface-layer log law
//!
//! ```text
//! U(z) = U_ref ln(z/z0) / ln(z_ref/z0)   for z > z0,   0 below z0
//! ```
//!
//! (`z0` the aerodynamic roughness length: about 0.0002 m over open sea,
//! 0.03 m over open flat terrain, 0.1 m over farmland, 1 m over cities;
//! Wieringa 1992, "Updating the Davenport roughness classification",
//! J. Wind Eng. Ind. Aerodyn. 41–44).

use crate::numerics::aero::SteadyFlow;
use crate::numerics::params::{InvalidInput, require_finite, require_positive};

/// A steady wind profile.
#[derive(Clone, Debug, PartialEq)]
pub enum WindProfile {
    /// One of the existing steady flows.
    Flow(SteadyFlow),
    /// Log law through `(reference_height_m, reference_speed_m_s)`.
    LogLaw {
        reference_speed_m_s: f64,
        reference_height_m: f64,
        roughness_length_m: f64,
    },
}

impl WindProfile {
    /// Calm air.
    pub fn calm() -> Self {
        Self::Flow(SteadyFlow::Uniform { speed_m_s: 0.0 })
    }

    /// `U = speed` everywhere.
    pub fn uniform(speed_m_s: f64) -> Self {
        Self::Flow(SteadyFlow::Uniform { speed_m_s })
    }

    /// The log law; `field` prefixes the names in errors.
    pub fn log_law(
        reference_speed_m_s: f64,
        reference_height_m: f64,
        roughness_length_m: f64,
        field: &str,
    ) -> Result<Self, InvalidInput> {
        require_finite(&format!("{field}.reference_speed_m_s"), reference_speed_m_s)?;
        require_positive(&format!("{field}.reference_height_m"), reference_height_m)?;
        require_positive(&format!("{field}.roughness_length_m"), roughness_length_m)?;
        if roughness_length_m >= reference_height_m {
            return Err(InvalidInput::new(
                format!("{field}.roughness_length_m"),
                format!(
                    "must be below reference_height_m = {reference_height_m} m, got {roughness_length_m}"
                ),
            ));
        }
        Ok(Self::LogLaw {
            reference_speed_m_s,
            reference_height_m,
            roughness_length_m,
        })
    }

    /// `U(z)` (m/s); elevations below zero are read as zero.
    #[inline]
    pub fn speed_m_s(&self, z_m: f64) -> f64 {
        match self {
            Self::Flow(SteadyFlow::Uniform { speed_m_s }) => *speed_m_s,
            Self::Flow(flow) => flow.velocity_and_shear(z_m.max(0.0)).0,
            &Self::LogLaw {
                reference_speed_m_s,
                reference_height_m,
                roughness_length_m,
            } => {
                if z_m <= roughness_length_m {
                    0.0
                } else {
                    reference_speed_m_s * (z_m / roughness_length_m).ln()
                        / (reference_height_m / roughness_length_m).ln()
                }
            }
        }
    }

    /// The fastest `|U|` at any height from the ground to `z_m` (m/s):
    /// the uniform, power and log laws grow with height, a table is
    /// searched through its points.
    pub fn fastest_below_m_s(&self, z_m: f64) -> f64 {
        let at_top = self.speed_m_s(z_m).abs();
        match self {
            Self::Flow(SteadyFlow::Tabulated {
                elevations_m,
                speeds_m_s,
            }) => elevations_m
                .iter()
                .zip(speeds_m_s)
                .enumerate()
                .filter(|&(i, (&z, _))| i == 0 || z <= z_m)
                .map(|(_, (_, &u))| u.abs())
                .fold(at_top, f64::max),
            _ => at_top,
        }
    }

    /// Whether `U` does not depend on `z` (the shooting then needs no iteration).
    pub fn is_uniform(&self) -> bool {
        matches!(self, Self::Flow(SteadyFlow::Uniform { .. }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_law_passes_through_its_reference_and_vanishes_at_the_roughness_length() {
        let p = WindProfile::log_law(10.0, 10.0, 0.03, "wind.flow").unwrap();
        assert!((p.speed_m_s(10.0) - 10.0).abs() < 1e-12);
        assert_eq!(p.speed_m_s(0.03), 0.0);
        assert_eq!(p.speed_m_s(-1.0), 0.0);
        let want = 10.0 * (1000.0f64 / 0.03).ln() / (10.0f64 / 0.03).ln();
        assert!((p.speed_m_s(1000.0) - want).abs() < 1e-12);
        assert!(WindProfile::log_law(10.0, 10.0, 20.0, "wind.flow").is_err());
        assert!(WindProfile::uniform(3.0).is_uniform());
    }
}
