//! The string criterion of a blown-down tether paid out at a constant
//! rate: the closed-form companion of the quasi-static GE onset in wind
//! (issue 21: "where an analysis and a closed form both exist, return
//! both").
//!
//! A string (no bending) paid out at `v` out of a fixed guide is at the
//! edge of divergence where its effective tension `T − ρA v²` first
//! vanishes; along a heavy tether in steady wind the tension is smallest at
//! its lower end (the winch), so the criterion is
//!
//! ```text
//! T_min(L) = ρA v²        T_min = the smallest tension of the static,
//!                         blown-down tether (SPEC §6), at rest
//! ```
//!
//! In calm air `T_min = F − ρA g L` and this is the closed form
//! `h* = (F/ρA − v²)/g` of SPEC §1, exactly. In wind `T_min` comes from
//! the continuum tether of [`super::equilibrium`] (the same one the GE
//! branch converges to, `qs_wind`): the critical rate at a length is
//! `√(T_min/ρA)` and the critical length at a rate the root of
//! `T_min(L) − ρA v²`, bisected to `10⁻⁹` of the length.
//!
//! **Not a bound.** The string criterion is what the quasi-static GE onset
//! tends to as `EI → 0` in calm air (bending lifts it, as `EI^(1/3)`).
//! In wind the linearised drag is a non-conservative load and the GE
//! spectrum may flutter before the effective tension vanishes (issue 21
//! measured a 20-element flutter at 59.6 m/s against the string's
//! 61.1 m/s at 1000 m in 8 m/s), so the string value is returned beside
//! the converged GE answer as a reference, never as its safe side.

use super::equilibrium::{EquilibriumConfig, EquilibriumProblem};
use crate::numerics::params::InvalidInput;

/// Relative width of the bisected critical length.
pub const LENGTH_RTOL: f64 = 1e-9;

/// The string criterion's effective tension at rest (N): the smallest
/// tension of the static tether, `None` when it is slack (touches the
/// ground) or its shooting did not converge.
pub fn min_tension_n(
    problem: &EquilibriumProblem,
    config: &EquilibriumConfig,
) -> Result<Option<f64>, InvalidInput> {
    let eq = problem.solve(&EquilibriumConfig {
        keep_shape: false,
        ..*config
    })?;
    Ok((!eq.slack && eq.converged && eq.min_tension_n > 0.0).then_some(eq.min_tension_n))
}

/// The string's critical payout rate at the problem's length (m/s):
/// `√(T_min/ρA)`; `None` when the tether is slack or unsolved at rest.
pub fn critical_rate_m_s(
    problem: &EquilibriumProblem,
    config: &EquilibriumConfig,
) -> Result<Option<f64>, InvalidInput> {
    Ok(min_tension_n(problem, config)?.map(|t| (t / problem.cable.mass_per_length_kg_m).sqrt()))
}

/// Where the string criterion puts the onset along the length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StringLengthOnset {
    /// `T_min(L) = ρA v²` at this length (m).
    During { length_m: f64 },
    /// The effective tension stays positive up to the upper end.
    Never { up_to_m: f64 },
    /// Not positive at the lower end already.
    Immediate,
}

/// The string's critical length at payout rate `rate_m_s` over
/// `[lo_m, hi_m]`: the first length where `T_min(L) − ρA v²` is no longer
/// positive (a slack or unsolved tether counts as not positive), bisected
/// to [`LENGTH_RTOL`]. `T_min` falls with the length (every metre more
/// adds its weight below the aerostat), so the root is the only one.
pub fn critical_length(
    base: &EquilibriumProblem,
    rate_m_s: f64,
    (lo_m, hi_m): (f64, f64),
    config: &EquilibriumConfig,
) -> Result<StringLengthOnset, InvalidInput> {
    let kinetic = base.cable.mass_per_length_kg_m * rate_m_s * rate_m_s;
    let margin = |l: f64| -> Result<f64, InvalidInput> {
        let p = EquilibriumProblem {
            tether_length_m: l,
            ..base.clone()
        };
        Ok(min_tension_n(&p, config)?.map_or(-1.0, |t| t - kinetic))
    };
    if !(margin(lo_m)? > 0.0) {
        return Ok(StringLengthOnset::Immediate);
    }
    if margin(hi_m)? > 0.0 {
        return Ok(StringLengthOnset::Never { up_to_m: hi_m });
    }
    let (mut a, mut b) = (lo_m, hi_m);
    while b - a > LENGTH_RTOL * b {
        let m = 0.5 * (a + b);
        if margin(m)? > 0.0 {
            a = m;
        } else {
            b = m;
        }
    }
    Ok(StringLengthOnset::During {
        length_m: 0.5 * (a + b),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::tether::equilibrium::{Body, Cable};
    use crate::numerics::tether::wind::WindProfile;

    fn problem(wind: WindProfile, length_m: f64) -> EquilibriumProblem {
        EquilibriumProblem {
            cable: Cable {
                mass_per_length_kg_m: 0.078,
                diameter_m: 0.005,
                normal_drag_coefficient: 1.2,
                axial_stiffness_n: None,
                breaking_strength_n: None,
            },
            body: Body {
                net_buoyancy_n: 1000.0,
                drag_coefficient: 0.3,
                lift_coefficient: 0.0,
                reference_area_m2: 3.0,
            },
            wind,
            air_density_kg_m3: 1.225,
            tether_length_m: length_m,
            gravity_m_s2: 9.81,
        }
    }

    /// Calm air: the closed forms of SPEC §1, `v* = √((F − ρA g L)/ρA)`
    /// and `h* = (F/ρA − v²)/g` (1296.688 m at 10 m/s).
    #[test]
    fn calm_air_is_the_closed_form() {
        let c = EquilibriumConfig::default();
        let v = critical_rate_m_s(&problem(WindProfile::calm(), 1000.0), &c)
            .unwrap()
            .unwrap();
        let closed = ((1000.0 - 0.078 * 9.81 * 1000.0) / 0.078_f64).sqrt();
        assert!((v - closed).abs() <= 1e-9 * closed, "{v} vs {closed}");
        let StringLengthOnset::During { length_m } =
            critical_length(&problem(WindProfile::calm(), 1.0), 10.0, (1.0, 3000.0), &c).unwrap()
        else {
            panic!()
        };
        let closed = (1000.0 / 0.078 - 100.0) / 9.81;
        assert!((length_m - 1296.688).abs() < 1e-3, "{length_m}");
        assert!(
            (length_m - closed).abs() <= 1e-8 * closed,
            "{length_m} vs {closed}"
        );
    }

    /// In wind the criterion's length is where the static tether's smallest
    /// tension equals ρA v², and the rate there is v again (the two
    /// searches invert each other); the wind lowers the onset.
    #[test]
    fn wind_rate_and_length_invert_each_other() {
        let c = EquilibriumConfig::default();
        let wind = WindProfile::uniform(8.0);
        let v = critical_rate_m_s(&problem(wind.clone(), 1000.0), &c)
            .unwrap()
            .unwrap();
        let calm = critical_rate_m_s(&problem(WindProfile::calm(), 1000.0), &c)
            .unwrap()
            .unwrap();
        // the GE branch's guide force converges to this tether (qs_wind): the
        // 20-element GE figure was 61.1 m/s
        assert!(v > calm && (v - 61.14).abs() < 0.01, "{v} vs calm {calm}");
        let StringLengthOnset::During { length_m } =
            critical_length(&problem(wind.clone(), 1.0), v, (10.0, 5000.0), &c).unwrap()
        else {
            panic!()
        };
        assert!((length_m - 1000.0).abs() < 1e-4, "{length_m}");
    }

    /// Without drag on the cable the tether in a uniform wind is a
    /// catenary under the aerostat's pull `(H, F)`, `H = ½ρ C_D A U²`: the
    /// winch end (its smallest tension) carries `√(H² + (F − ρA g L)²)`.
    #[test]
    fn drag_free_cable_is_the_catenary() {
        let c = EquilibriumConfig {
            steps: 400,
            ..EquilibriumConfig::default()
        };
        let mut p = problem(WindProfile::uniform(8.0), 1000.0);
        p.cable.normal_drag_coefficient = 0.0;
        let v = critical_rate_m_s(&p, &c).unwrap().unwrap();
        let h = 0.5 * 1.225 * 0.3 * 3.0 * 64.0;
        let t0 = (h * h + (1000.0 - 0.078 * 9.81 * 1000.0_f64).powi(2)).sqrt();
        let closed = (t0 / 0.078).sqrt();
        assert!((v - closed).abs() <= 1e-8 * closed, "{v} vs {closed}");
    }

    #[test]
    fn outcomes_at_the_ends() {
        let c = EquilibriumConfig::default();
        let p = problem(WindProfile::calm(), 1.0);
        assert_eq!(
            critical_length(&p, 10.0, (1.0, 500.0), &c).unwrap(),
            StringLengthOnset::Never { up_to_m: 500.0 }
        );
        assert_eq!(
            critical_length(&p, 200.0, (1.0, 500.0), &c).unwrap(),
            StringLengthOnset::Immediate
        );
    }
}
