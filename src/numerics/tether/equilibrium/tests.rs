//! Unit tests of the static tether, and the test tether other modules
//! test against.

use super::*;

/// The test tether: 1000 m, 2000 N, no tether drag, in a uniform wind.
pub(crate) fn problem(wind: f64) -> EquilibriumProblem {
    EquilibriumProblem {
        cable: Cable {
            mass_per_length_kg_m: 0.05,
            diameter_m: 0.006,
            normal_drag_coefficient: 0.0,
            axial_stiffness_n: None,
            breaking_strength_n: Some(30_000.0),
        },
        body: Body {
            net_buoyancy_n: 2000.0,
            drag_coefficient: 0.3,
            lift_coefficient: 0.0,
            reference_area_m2: 20.0,
        },
        wind: WindProfile::uniform(wind),
        air_density_kg_m3: 1.225,
        tether_length_m: 1000.0,
        gravity_m_s2: 9.81,
    }
}

#[test]
fn calm_air_is_vertical_with_linear_tension() {
    let e = problem(0.0).solve(&EquilibriumConfig::default()).unwrap();
    assert!((e.altitude_m - 1000.0).abs() < 1e-9);
    assert_eq!(e.downwind_m, 0.0);
    assert!((e.winch_tension_n - (2000.0 - 0.05 * 9.81 * 1000.0)).abs() < 1e-9);
    assert!(!e.slack && e.converged);
    assert_eq!(e.shape.len(), 101);
    assert_eq!(e.shape[0].s_m, 0.0);
    assert!((e.safety_factor.unwrap() - 15.0).abs() < 1e-12);
}

#[test]
fn calm_air_too_heavy_rests_on_the_ground() {
    let mut p = problem(0.0);
    p.tether_length_m = 5000.0; // wL = 2452.5 N > F
    let e = p.solve(&EquilibriumConfig::default()).unwrap();
    assert!(e.slack);
    let lifted = 2000.0 / (0.05 * 9.81);
    assert!((e.altitude_m - lifted).abs() < 1e-8, "{}", e.altitude_m);
    assert!((e.grounded_length_m - (5000.0 - lifted)).abs() < 1e-8);
    assert_eq!(e.winch_tension_n, 0.0);
}

#[test]
fn drag_only_matches_the_catenary() {
    let p = problem(8.0);
    let e = p.solve(&EquilibriumConfig::default()).unwrap();
    let (h, v) = p.top_force_n(8.0);
    let (x, z) = catenary_top(h, v, p.weight_n_m(), 1000.0);
    assert!((e.altitude_m - z).abs() < 1e-6 * z, "{} {z}", e.altitude_m);
    assert!((e.downwind_m - x).abs() < 1e-6 * z, "{} {x}", e.downwind_m);
}
