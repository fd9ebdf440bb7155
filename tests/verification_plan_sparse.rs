//! The plan's loads along its grid, solved at a checked subset of the nodes
//! and interpolated elsewhere (`numerics::plan::sparse`), against the
//! shooting of every node: within the stated tolerance,
//! [`RELATIVE_TOLERANCE`] of the force scale (full buoyancy plus the longest
//! tether's weight), in a sheared wind with gusts, and across the jump of a
//! tether that goes slack.

use tetherplan::numerics::aero::SteadyFlow;
use tetherplan::numerics::params::AerostatSystem;
use tetherplan::numerics::plan::air::{Air, SteadyWind};
use tetherplan::numerics::plan::sparse::RELATIVE_TOLERANCE;
use tetherplan::numerics::plan::{PlanProblem, Winch};
use tetherplan::numerics::tether::{Body, Cable, WindProfile};

fn power_law(at_10_m: f64) -> WindProfile {
    // U(z) = U10 (z/10)^0.16 as a · z^p
    WindProfile::Flow(SteadyFlow::PowerLaw {
        coefficient: at_10_m / 10f64.powf(0.16),
        exponent: 0.16,
    })
}

fn case(net_buoyancy_n: f64, wind_m_s: f64, target_m: f64) -> (PlanProblem, Air) {
    let system = AerostatSystem::new(0.078, net_buoyancy_n, 10.0, 1.0, 9.81).unwrap();
    let p = PlanProblem::new(
        system,
        target_m,
        Winch::new(3.0, 0.5).unwrap(),
        0.1,
        Some(5000.0),
    )
    .unwrap();
    let cable = Cable {
        mass_per_length_kg_m: 0.078,
        diameter_m: 0.005,
        normal_drag_coefficient: 1.2,
        axial_stiffness_n: None,
        breaking_strength_n: Some(20000.0),
    };
    let body = Body {
        net_buoyancy_n,
        drag_coefficient: 0.3,
        lift_coefficient: 0.0,
        reference_area_m2: 20.0,
    };
    let wind = SteadyWind::new(cable, body, power_law(wind_m_s), 1.225)
        .with_gust(power_law(1.4 * wind_m_s));
    (p, Air::Wind(Box::new(wind)))
}

/// Largest |sparse − shooting| over the grid, for S and for (T_w, T_t),
/// relative to the force scale; and the count of slack (unstable) nodes.
fn worst(net_buoyancy_n: f64, wind_m_s: f64, target_m: f64) -> (f64, f64, usize) {
    let (p, air) = case(net_buoyancy_n, wind_m_s, target_m);
    let lengths: Vec<f64> = (0..=4000)
        .map(|i| 1.0 + (target_m - 1.0) * i as f64 / 4000.0)
        .collect();
    let scale = net_buoyancy_n + 0.078 * 9.81 * target_m;
    let sparse_s = air.stability_tensions_n(&p, &lengths);
    let sparse_t = air.operating_tensions_n(&p, &lengths);
    let Air::Wind(w) = &air else { unreachable!() };
    let (mut ds, mut dt, mut unstable) = (0.0f64, 0.0f64, 0);
    for (i, &l) in lengths.iter().enumerate() {
        let s = w.stability_tension_n(&p, l);
        let (tw, tt) = w.limit_tensions(&p.system, l);
        if s <= -p.reserve_buoyancy_n() {
            unstable += 1;
        }
        ds = ds.max((sparse_s[i] - s).abs() / scale);
        dt = dt.max((sparse_t[i].0 - tw).abs().max((sparse_t[i].1 - tt).abs()) / scale);
    }
    eprintln!(
        "F {net_buoyancy_n} N, U10 {wind_m_s} m/s: S within {ds:.2e}, tensions within {dt:.2e} of {scale:.0} N; {unstable} slack nodes"
    );
    (ds, dt, unstable)
}

#[test]
fn sheared_gusty_wind_every_node_within_the_tolerance() {
    let (ds, dt, unstable) = worst(1000.0, 8.0, 1000.0);
    assert_eq!(unstable, 0);
    assert!(ds <= RELATIVE_TOLERANCE, "S off by {ds:e} of the scale");
    assert!(
        dt <= RELATIVE_TOLERANCE,
        "tensions off by {dt:e} of the scale"
    );
}

#[test]
fn a_tether_that_goes_slack_is_solved_across_the_jump() {
    // 600 N against 0.765 N/m: the lower tether reaches the ground near
    // 700 m in this wind (reserve 540 N), so S jumps to −(1 − r)F there.
    let (ds, dt, unstable) = worst(600.0, 4.0, 1000.0);
    assert!(unstable > 100 && unstable < 3000, "{unstable} slack nodes");
    assert!(ds <= RELATIVE_TOLERANCE, "S off by {ds:e} of the scale");
    assert!(
        dt <= RELATIVE_TOLERANCE,
        "tensions off by {dt:e} of the scale"
    );
}
