//! Tension of the vertical linear string during payout (SPEC §1 with §6's
//! tension outputs). The cable above the roller moves with the winch rate
//! `v = L̇` and acceleration `a = L̈`; the aerostat accelerates with it:
//!
//! ```text
//! T(L) = F − m a                          (aerostat: m a = F − T(L))
//! T(s) = F − m a − ρA (g + a)(L − s)      (cable element: ρA a = T' − ρA g)
//! T(0) = F − m a − ρA (g + a) L           (at the roller)
//! ```
//!
//! The kinematic term `ρA v²` is what stability compares the roller tension
//! with: at constant rate the continuum criterion `T(0) − ρA v² > 0` is the
//! closed-form `h* = (F/ρA − v²)/g` of SPEC §1.

use crate::numerics::params::{AerostatSystem, Kinematics};

/// Tensions at one deployment state (N).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StringTension {
    /// `F − m a` at the aerostat.
    pub top_n: f64,
    /// `F − m a − ρA(g + a)L` at the roller.
    pub winch_n: f64,
    /// `ρA v²`.
    pub kinematic_n: f64,
    /// `T(0) − ρA v²`: positive while the continuum criterion holds.
    pub effective_winch_n: f64,
    /// Largest tension along the cable (the larger end: T is linear in s).
    pub max_n: f64,
    /// Tension vanishes somewhere (`min T ≤ 0`).
    pub slack: bool,
}

impl StringTension {
    pub fn at(sys: &AerostatSystem, k: Kinematics) -> Self {
        let rho_a = sys.mass_per_length_kg_m;
        let top = sys.net_buoyancy_n - sys.aerostat_mass_kg * k.acceleration_m_s2;
        let winch = top - rho_a * (sys.gravity_m_s2 + k.acceleration_m_s2) * k.length_m;
        let kinematic = rho_a * k.rate_m_s * k.rate_m_s;
        Self {
            top_n: top,
            winch_n: winch,
            kinematic_n: kinematic,
            effective_winch_n: winch - kinematic,
            max_n: top.max(winch),
            slack: top.min(winch) <= 0.0,
        }
    }

    /// `T(s)` at unstretched arc length `s` from the roller.
    pub fn along(&self, length_m: f64, s_m: f64) -> f64 {
        self.winch_n + (self.top_n - self.winch_n) * (s_m / length_m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constant_rate_onset_is_where_the_effective_winch_tension_vanishes() {
        let sys = AerostatSystem::thesis();
        let v = 10.0;
        let h = sys.closed_form_elevation_m(v);
        let t = StringTension::at(
            &sys,
            Kinematics {
                length_m: h,
                rate_m_s: v,
                acceleration_m_s2: 0.0,
            },
        );
        assert!(t.effective_winch_n.abs() < 1e-9 * sys.net_buoyancy_n);
        assert_eq!(t.top_n, sys.net_buoyancy_n);
        assert!((t.along(h, h) - t.top_n).abs() < 1e-12);
        assert!((t.along(h, 0.0) - t.winch_n).abs() < 1e-12);
        // accelerating: the aerostat's inertia and the cable's both unload the roller
        let a = StringTension::at(
            &sys,
            Kinematics {
                length_m: 100.0,
                rate_m_s: 0.0,
                acceleration_m_s2: 2.0,
            },
        );
        let rho_a = sys.mass_per_length_kg_m;
        let want = sys.net_buoyancy_n
            - sys.aerostat_mass_kg * 2.0
            - rho_a * (sys.gravity_m_s2 + 2.0) * 100.0;
        assert!((a.winch_n - want).abs() < 1e-9);
    }
}
