//! The answer parts every domain shares: the system's scales and
//! non-dimensional groups ([`Groups`], [`groups`]) and one eigenvalue of
//! the QEP ([`EigenvalueOutput`]).

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::numerics::params::AerostatSystem;

/// Scales and non-dimensional groups of the system.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct Groups {
    /// Wave speed sqrt(F/ρA) (m/s).
    pub wave_speed_m_s: f64,
    /// Time scale L0/c (s).
    pub time_scale_s: f64,
    /// F̃ = F/(ρA g L0).
    pub buoyancy_ratio_nondim: f64,
    /// m̃ = m/(ρA L0).
    pub mass_ratio_nondim: f64,
    /// F/(ρA g) (m): no rate is safe above it.
    pub static_lift_limit_m: f64,
}

/// One eigenvalue λ of λ²M + λC + K = 0.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct EigenvalueOutput {
    /// Re λ (1/s): growth rate if positive.
    pub re_1_s: f64,
    /// Im λ (rad/s): circular frequency.
    pub im_1_s: f64,
    /// Re λ in units of 1/t̄.
    pub re_nondim: f64,
    /// Im λ in units of 1/t̄.
    pub im_nondim: f64,
    /// Im λ / 2π (Hz).
    pub frequency_hz: f64,
}

pub fn groups(s: &AerostatSystem) -> Groups {
    Groups {
        wave_speed_m_s: s.wave_speed_m_s(),
        time_scale_s: s.time_scale_s(),
        buoyancy_ratio_nondim: s.buoyancy_ratio(),
        mass_ratio_nondim: s.mass_ratio(),
        static_lift_limit_m: s.static_lift_limit_m(),
    }
}
