//! Verification of the static tether in wind (SPEC §6) against closed
//! forms, an independent integrator written here, and its own convergence.
//!
//! * calm air: winch tension `F − ρA g L`, altitude `L` (1e-9), elastic
//!   stretch `(F L − ρA g L²/2)/EA` (1e-9);
//! * aerostat drag only: the catenary (altitude, downwind distance, both
//!   tensions) within 1e-6;
//! * tether drag: RK4 step convergence at order 4, and agreement with a
//!   polar-form integrator (`T`, angle) written below;
//! * small wind: the linear string's blow-down `F_D/(ρA g) ln(F/(F − ρA g L))`.

use tetherplan::numerics::aero::SteadyFlow;
use tetherplan::numerics::tether::{
    Body, Cable, EquilibriumConfig, EquilibriumProblem, WindProfile, catenary_top,
};

const G: f64 = 9.81;

fn problem(u: f64, cn: f64, ea: Option<f64>) -> EquilibriumProblem {
    EquilibriumProblem {
        cable: Cable {
            mass_per_length_kg_m: 0.06,
            diameter_m: 0.008,
            normal_drag_coefficient: cn,
            axial_stiffness_n: ea,
            breaking_strength_n: Some(50_000.0),
        },
        body: Body {
            net_buoyancy_n: 3000.0,
            drag_coefficient: 0.4,
            lift_coefficient: 0.0,
            reference_area_m2: 30.0,
        },
        wind: WindProfile::uniform(u),
        air_density_kg_m3: 1.225,
        tether_length_m: 1500.0,
        gravity_m_s2: G,
    }
}

fn config(steps: usize) -> EquilibriumConfig {
    EquilibriumConfig {
        steps,
        ..EquilibriumConfig::default()
    }
}

#[test]
fn calm_air_winch_tension_and_altitude_to_1e_9() {
    for (l, f) in [(100.0, 500.0), (1500.0, 3000.0), (4000.0, 2500.0)] {
        let mut p = problem(0.0, 1.2, None);
        p.tether_length_m = l;
        p.body.net_buoyancy_n = f;
        let e = p.solve(&config(200)).unwrap();
        let w = 0.06 * G;
        assert!(
            ((e.winch_tension_n - (f - w * l)) / f).abs() < 1e-9,
            "{l}: {}",
            e.winch_tension_n
        );
        assert!((e.altitude_m - l).abs() < 1e-9 * l, "{l}: {}", e.altitude_m);
        assert!((e.top_tension_n - f).abs() < 1e-9 * f);
        assert_eq!(e.downwind_m, 0.0);
        assert!(!e.slack);
        // tension along the shape is linear
        for pt in &e.shape {
            assert!((pt.tension_n - (f - w * (l - pt.s_m))).abs() < 1e-9 * f);
        }
    }
    // a log law and a power law with no wind are calm air too
    for wind in [
        WindProfile::log_law(0.0, 10.0, 0.03, "w").unwrap(),
        WindProfile::Flow(SteadyFlow::power_law(0.0, 0.14).unwrap()),
    ] {
        let mut p = problem(0.0, 1.2, None);
        p.wind = wind;
        let e = p.solve(&config(50)).unwrap();
        assert!((e.altitude_m - 1500.0).abs() < 1e-9 * 1500.0);
        assert!(e.converged);
    }
}

#[test]
fn calm_air_elastic_stretch_to_1e_9() {
    for ea in [2e5, 1e6, 1e8] {
        let p = problem(0.0, 1.2, Some(ea));
        let e = p.solve(&config(64)).unwrap();
        let (f, w, l) = (3000.0, 0.06 * G, 1500.0);
        let stretch = (f * l - w * l * l / 2.0) / ea;
        assert!(
            (e.altitude_m - (l + stretch)).abs() < 1e-9 * l,
            "EA {ea}: {} vs {}",
            e.altitude_m,
            l + stretch
        );
        assert!((e.stretched_length_m - (l + stretch)).abs() < 1e-9 * l);
    }
}

#[test]
fn aerostat_drag_only_is_the_catenary_to_1e_6() {
    for (u, cl, l) in [
        (3.0, 0.0, 1500.0),
        (10.0, 0.0, 1500.0),
        (20.0, 0.0, 800.0),
        (12.0, 0.3, 2500.0),
    ] {
        let mut p = problem(u, 0.0, None);
        p.body.lift_coefficient = cl;
        p.tether_length_m = l;
        let e = p.solve(&config(200)).unwrap();
        let (h, v) = p.top_force_n(u);
        let w = 0.06 * G;
        assert!(v > w * l, "the case must stay airborne");
        let (x, z) = catenary_top(h, v, w, l);
        let tol = 1e-6;
        eprintln!(
            "catenary U = {u}: rel. err altitude {:.1e}, downwind {:.1e}",
            ((e.altitude_m - z) / z).abs(),
            ((e.downwind_m - x) / x).abs()
        );
        assert!(
            ((e.altitude_m - z) / z).abs() < tol,
            "{u}: z {} vs {z}",
            e.altitude_m
        );
        assert!(
            ((e.downwind_m - x) / x).abs() < tol,
            "{u}: x {} vs {x}",
            e.downwind_m
        );
        let top = h.hypot(v);
        let winch = h.hypot(v - w * l);
        assert!(((e.top_tension_n - top) / top).abs() < tol);
        assert!(((e.winch_tension_n - winch) / winch).abs() < tol);
    }
}

#[test]
fn aerostat_drag_only_in_a_power_law_wind_is_the_catenary_at_the_found_altitude() {
    // Height-dependent wind at the aerostat: the shooting must find the
    // altitude whose wind gives a catenary reaching that altitude.
    let mut p = problem(0.0, 0.0, None);
    p.wind = WindProfile::Flow(SteadyFlow::power_law(4.0, 0.14).unwrap());
    let e = p.solve(&config(200)).unwrap();
    assert!(e.converged && e.iterations < 15, "{} passes", e.iterations);
    let u = 4.0 * e.altitude_m.powf(0.14);
    assert!((e.aerostat_wind_m_s - u).abs() < 1e-9 * u);
    let (h, v) = p.top_force_n(u);
    let (x, z) = catenary_top(h, v, 0.06 * G, 1500.0);
    assert!(
        ((e.altitude_m - z) / z).abs() < 1e-6,
        "{} vs {z}",
        e.altitude_m
    );
    assert!(((e.downwind_m - x) / x).abs() < 1e-6);
}

/// Observed order from three step counts (N, 2N, 4N).
fn observed_order(
    p: &EquilibriumProblem,
    n: usize,
    pick: fn(&tetherplan::numerics::tether::Equilibrium) -> f64,
) -> f64 {
    let a = pick(&p.solve(&config(n)).unwrap());
    let b = pick(&p.solve(&config(2 * n)).unwrap());
    let c = pick(&p.solve(&config(4 * n)).unwrap());
    ((a - b) / (b - c)).abs().log2()
}

#[test]
fn tether_drag_converges_at_fourth_order_in_the_step() {
    // Strong tether drag: 15 m/s on 1500 m of 8 mm tether, elastic.
    let p = problem(15.0, 1.2, Some(1e6));
    let e = p.solve(&config(2000)).unwrap();
    let (h, v) = p.top_force_n(15.0);
    let (x_no_drag, _) = catenary_top(h, v, 0.06 * G, 1500.0);
    assert!(
        e.downwind_m > 1.2 * x_no_drag,
        "tether drag should matter: {} vs {x_no_drag}",
        e.downwind_m
    );
    for n in [8, 16] {
        let oz = observed_order(&p, n, |e| e.altitude_m);
        let ox = observed_order(&p, n, |e| e.downwind_m);
        let ot = observed_order(&p, n, |e| e.winch_tension_n);
        eprintln!(
            "observed order at N = {n}: altitude {oz:.3}, downwind {ox:.3}, winch tension {ot:.3}"
        );
        for (what, o) in [("altitude", oz), ("downwind", ox), ("winch tension", ot)] {
            assert!((3.6..=4.4).contains(&o), "{what} order {o} at N = {n}");
        }
    }
    // the default 200 steps are converged to 1e-9 relative
    let d = p.solve(&config(200)).unwrap();
    assert!(((d.altitude_m - e.altitude_m) / e.altitude_m).abs() < 1e-9);
    assert!(((d.downwind_m - e.downwind_m) / e.downwind_m).abs() < 1e-9);
}

/// An independent integrator in polar form: tension magnitude `T` and
/// angle `φ` from the vertical, from the top down, inextensible, uniform
/// wind `U`, Heun's scheme (second order) with many steps:
/// `dT/dσ = −w cos φ`, `T dφ/dσ = w sin φ + c |U cos φ| U cos φ`,
/// `dx/dσ = −sin φ`, `dz/dσ = −cos φ`.
fn polar_reference(p: &EquilibriumProblem, u: f64, steps: usize) -> (f64, f64, f64) {
    let w = p.cable.mass_per_length_kg_m * p.gravity_m_s2;
    let c = 0.5 * p.air_density_kg_m3 * p.cable.normal_drag_coefficient * p.cable.diameter_m;
    let (h, v) = p.top_force_n(u);
    let rhs = |y: [f64; 4]| {
        let [t, phi, _, _] = y;
        let un = u * phi.cos();
        [
            -w * phi.cos(),
            (w * phi.sin() + c * un.abs() * un) / t,
            -phi.sin(),
            -phi.cos(),
        ]
    };
    let mut y = [h.hypot(v), h.atan2(v), 0.0, 0.0];
    let dh = p.tether_length_m / steps as f64;
    for _ in 0..steps {
        let k1 = rhs(y);
        let mut m = y;
        for i in 0..4 {
            m[i] += dh * k1[i];
        }
        let k2 = rhs(m);
        for i in 0..4 {
            y[i] += 0.5 * dh * (k1[i] + k2[i]);
        }
    }
    (-y[3], -y[2], y[0])
}

#[test]
fn tether_drag_agrees_with_an_independent_polar_integrator() {
    for u in [5.0, 15.0, 25.0] {
        let p = problem(u, 1.2, None);
        let e = p.solve(&config(200)).unwrap();
        let (z, x, t0) = polar_reference(&p, u, 200_000);
        eprintln!(
            "polar check U = {u}: rel. diff altitude {:.1e}, downwind {:.1e}, winch tension {:.1e}",
            ((e.altitude_m - z) / z).abs(),
            ((e.downwind_m - x) / x).abs(),
            ((e.winch_tension_n - t0) / t0).abs()
        );
        assert!(
            ((e.altitude_m - z) / z).abs() < 1e-7,
            "{u}: {} vs {z}",
            e.altitude_m
        );
        assert!(
            ((e.downwind_m - x) / x).abs() < 1e-7,
            "{u}: {} vs {x}",
            e.downwind_m
        );
        assert!(((e.winch_tension_n - t0) / t0).abs() < 1e-7);
    }
}

#[test]
fn small_wind_matches_the_linear_string_blowdown() {
    // F_D/(ρA g) ln(F/(F − ρA g L)): the string under a small tip force.
    for u in [0.05, 0.2] {
        let p = problem(u, 0.0, None);
        let e = p.solve(&config(200)).unwrap();
        let (fd, f) = p.top_force_n(u);
        let w = 0.06 * G;
        let l = 1500.0;
        let want = fd / w * (f / (f - w * l)).ln();
        // the difference is O((F_D/F)²) relative
        let rel = ((e.downwind_m - want) / want).abs();
        eprintln!(
            "small wind U = {u}: F_D = {fd:.4} N, rel. diff from the string's blow-down {rel:.1e}"
        );
        assert!(
            rel < 10.0 * (fd / (f - w * l)).powi(2) + 1e-9,
            "{u}: {} vs {want} ({rel:e})",
            e.downwind_m
        );
        assert!(rel < 1e-4);
    }
}

#[test]
fn too_little_lift_rests_the_tether_on_the_ground() {
    // Calm: the lifted part is F/w long, the rest lies on the ground; slack.
    let mut p = problem(0.0, 1.2, None);
    p.tether_length_m = 8000.0; // w L = 4709 N > F
    let e = p.solve(&config(200)).unwrap();
    let lifted = 3000.0 / (0.06 * G);
    assert!(e.slack);
    assert!((e.altitude_m - lifted).abs() < 1e-8 * lifted);
    assert!((e.grounded_length_m - (8000.0 - lifted)).abs() < 1e-8 * lifted);
    assert_eq!(e.winch_tension_n, 0.0);
    // In wind: the lifted part is the catenary with a horizontal tangent at touchdown:
    // its length is V/w and z = (H/w)(√(1+(V/H)²) − 1).
    let mut p = problem(8.0, 0.0, None);
    p.tether_length_m = 8000.0;
    let e = p.solve(&config(400)).unwrap();
    let (h, v) = p.top_force_n(8.0);
    let w = 0.06 * G;
    let (x, z) = catenary_top(h, v, w, v / w);
    assert!(e.slack);
    assert!(
        ((e.altitude_m - z) / z).abs() < 1e-6,
        "{} vs {z}",
        e.altitude_m
    );
    let ground = 8000.0 - v / w;
    assert!(((e.grounded_length_m - ground) / ground).abs() < 1e-6);
    assert!(((e.downwind_m - (x + ground)) / (x + ground)).abs() < 1e-6);
    assert!(((e.winch_tension_n - h) / h).abs() < 1e-9);
}

#[test]
fn strong_shear_and_tabulated_winds_converge() {
    for wind in [
        WindProfile::log_law(12.0, 10.0, 0.1, "w").unwrap(),
        WindProfile::Flow(
            SteadyFlow::tabulated(
                &[(0.0, 2.0), (300.0, 15.0), (900.0, 5.0), (2000.0, 25.0)],
                "w",
            )
            .unwrap(),
        ),
    ] {
        let mut p = problem(0.0, 1.2, Some(5e5));
        p.wind = wind.clone();
        let e = p.solve(&config(200)).unwrap();
        assert!(e.converged, "{wind:?}: residual {}", e.residual_m);
        assert!(e.residual_m < 1e-9);
        assert!((e.aerostat_wind_m_s - wind.speed_m_s(e.altitude_m)).abs() < 1e-9);
    }
}
