//! Quasi-static GE stability in calm air and in a steady wind (issue 12
//! item 4), Table 7.1 data (ρA = 0.078 kg/m, F = 1000 N, m = 10 kg,
//! EI = 1000 N m², γ̃ = 1, L0 = 1 m), 20 elements unless stated:
//!
//! * calm air: `wind_stability` is `state_stability` bit for bit;
//! * a small wind tends to the calm answer (continuity, error ∝ U²);
//! * the blown-down GE shape agrees with the independent RK4 shooting of
//!   `tether::equilibrium` (a slender, nearly inextensible cable);
//! * the quasi-static critical length against the marching GE search and
//!   the string's closed form (within 2 % in h*).

use rayon::prelude::*;
use tetherplan::numerics::ge::air_load::AirLoads;
use tetherplan::numerics::ge::chart::GeChartSystem;
use tetherplan::numerics::ge::critical::{
    CriticalConfig, CriticalProblem, GeOnset, StartState, critical_time,
};
use tetherplan::numerics::ge::element::TipLoad;
use tetherplan::numerics::ge::qs_critical::{QsOnset, QsSearchConfig, critical_length};
use tetherplan::numerics::ge::quasi_static::{QsConfig, wind_stability};
use tetherplan::numerics::ge::solver::NewtonConfig;
use tetherplan::numerics::ge::stability::{StateMotion, state_stability};
use tetherplan::numerics::ge::{GeModel, Section, TipBody};
use tetherplan::numerics::params::Kinematics;
use tetherplan::numerics::profile::Profile;
use tetherplan::numerics::tether::wind::WindProfile;
use tetherplan::numerics::tether::{Body, Cable, EquilibriumConfig, EquilibriumProblem};

fn never() -> bool {
    false
}

fn buoyancy() -> TipLoad {
    TipLoad {
        force_n: [1000.0, 0.0],
        moment_n_m: 0.0,
    }
}

fn air(u: f64) -> AirLoads {
    AirLoads {
        wind: WindProfile::uniform(u),
        air_density_kg_m3: 1.225,
        cable_diameter_m: 0.0036,
        cable_normal_drag_coefficient: 1.2,
        aerostat_drag_area_m2: 0.3 * 3.0,
        aerostat_lift_area_m2: 0.0,
    }
}

fn table(elements: usize, stiffness_ratio: f64) -> GeModel {
    let mut sys = GeChartSystem::table_7_1();
    sys.elements = elements;
    sys.model(stiffness_ratio).unwrap()
}

fn qs_length(model: &GeModel, v: f64, air: &AirLoads) -> (f64, bool) {
    qs_length_with(model, v, air, &QsSearchConfig::default(), 1.0)
}

fn qs_length_with(
    model: &GeModel,
    v: f64,
    air: &AirLoads,
    config: &QsSearchConfig,
    from: f64,
) -> (f64, bool) {
    let r = critical_length(
        model,
        1000.0,
        air,
        v,
        0.0,
        StateMotion::AtRest,
        config,
        (from, 1.5 * 1000.0 / (0.078 * 9.81)),
        &never,
    )
    .unwrap();
    match r.onset {
        QsOnset::During { at } => (at, r.divergence),
        other => panic!("expected an onset, got {other:?}"),
    }
}

/// Calm air: the generalised state is `state_stability`, eigenvalue for
/// eigenvalue (same equilibrium solve, the air terms skipped).
#[test]
fn calm_air_is_state_stability_exactly() {
    let model = table(20, 1e5);
    for (l, v, a, motion) in [
        (500.0, 10.0, 0.0, StateMotion::AtRest),
        (1200.0, 12.0, 0.5, StateMotion::SteadyPayout),
        (50.0, 0.0, 0.0, StateMotion::AtRest),
    ] {
        let kin = Kinematics {
            length_m: l,
            rate_m_s: v,
            acceleration_m_s2: a,
        };
        let s =
            state_stability(&model, kin, buoyancy(), motion, 2, NewtonConfig::default()).unwrap();
        let w = wind_stability(
            &model,
            kin,
            buoyancy(),
            &AirLoads::calm(),
            motion,
            &QsConfig::default(),
            None,
        )
        .unwrap();
        assert_eq!(s.state.q, w.state.q);
        assert_eq!(s.state.a, w.state.a);
        assert_eq!(s.spectrum.eigenvalues, w.spectrum.eigenvalues);
        assert_eq!(s.root_axial_force_n, w.root_axial_force_n);
        assert_eq!(w.tip_downwind_m, 0.0);
    }
}

/// Small wind: the blow-down grows as U² (quadratic drag), and the
/// spectrum tends to the calm one (the aerodynamic damping is ∝ |U|).
#[test]
fn small_wind_tends_to_the_calm_answer() {
    let model = table(20, 1e5);
    let kin = Kinematics {
        length_m: 500.0,
        rate_m_s: 10.0,
        acceleration_m_s2: 0.0,
    };
    let calm = wind_stability(
        &model,
        kin,
        buoyancy(),
        &AirLoads::calm(),
        StateMotion::AtRest,
        &QsConfig::default(),
        None,
    )
    .unwrap();
    let at = |u: f64| {
        wind_stability(
            &model,
            kin,
            buoyancy(),
            &air(u),
            StateMotion::AtRest,
            &QsConfig::default(),
            None,
        )
        .unwrap()
    };
    let (w1, w2, w3) = (at(0.01), at(0.02), at(1e-4));
    let ratio = w2.tip_downwind_m / w1.tip_downwind_m;
    println!(
        "downwind at 0.01 / 0.02 m/s: {:.3e} / {:.3e} m (ratio {ratio:.4})",
        w1.tip_downwind_m, w2.tip_downwind_m
    );
    assert!((ratio - 4.0).abs() < 0.01, "{ratio}");
    let d1 = (w1.spectrum.max_real - calm.spectrum.max_real).abs();
    let d3 = (w3.spectrum.max_real - calm.spectrum.max_real).abs();
    println!(
        "max Re λ − calm: {d1:.3e} at 0.01 m/s, {d3:.3e} at 1e-4 m/s (calm {:.4e} 1/s)",
        calm.spectrum.max_real
    );
    assert!(d1 < 1e-6 * calm.spectrum.max_real.abs() && d3 < 1e-6 * calm.spectrum.max_real.abs());
    assert!((w3.tip_altitude_m - calm.tip_altitude_m).abs() < 1e-6);
}

/// The blown-down GE shape of a slender cable (EI = 1 N m², EA = 1e7 N)
/// against the independent RK4 shooting of `tether::equilibrium` with the
/// same loads (uniform and log-law wind, tether and aerostat drag): tip
/// altitude and downwind offset within 1e-4 of the tether length at 40
/// and 80 elements (measured: a few mm on 600 m).
#[test]
fn blown_down_shape_matches_the_tether_shooting() {
    let (rho_a, f, l, ea) = (0.05, 2000.0, 600.0, 1e7);
    let model_of = |n: usize| {
        GeModel::new(
            Section::new(ea, ea, 1.0, rho_a, 1e-4).unwrap(),
            n,
            TipBody {
                mass_kg: 50.0,
                link_length_m: 0.0,
            },
            9.81,
        )
        .unwrap()
    };
    for wind in [
        WindProfile::uniform(12.0),
        WindProfile::log_law(10.0, 10.0, 0.03, "wind").unwrap(),
    ] {
        let air = AirLoads {
            wind: wind.clone(),
            air_density_kg_m3: 1.225,
            cable_diameter_m: 0.006,
            cable_normal_drag_coefficient: 1.2,
            aerostat_drag_area_m2: 0.3 * 20.0,
            aerostat_lift_area_m2: 0.0,
        };
        let tether = EquilibriumProblem {
            cable: Cable {
                mass_per_length_kg_m: rho_a,
                diameter_m: 0.006,
                normal_drag_coefficient: 1.2,
                axial_stiffness_n: Some(ea),
                breaking_strength_n: None,
            },
            body: Body {
                net_buoyancy_n: f,
                drag_coefficient: 0.3,
                lift_coefficient: 0.0,
                reference_area_m2: 20.0,
            },
            wind,
            air_density_kg_m3: 1.225,
            tether_length_m: l,
            gravity_m_s2: 9.81,
        }
        .solve(&EquilibriumConfig::default())
        .unwrap();
        let kin = Kinematics {
            length_m: l,
            rate_m_s: 0.0,
            acceleration_m_s2: 0.0,
        };
        let load = TipLoad {
            force_n: [f, 0.0],
            moment_n_m: 0.0,
        };
        let errs: Vec<(f64, f64)> = [40usize, 80]
            .iter()
            .map(|&n| {
                let w = wind_stability(
                    &model_of(n),
                    kin,
                    load,
                    &air,
                    StateMotion::AtRest,
                    &QsConfig::default(),
                    None,
                )
                .unwrap();
                println!(
                    "{n} elements: GE ({:.3}, {:.3}) m, tether ({:.3}, {:.3}) m",
                    w.tip_altitude_m, w.tip_downwind_m, tether.altitude_m, tether.downwind_m
                );
                (
                    (w.tip_altitude_m - tether.altitude_m).abs(),
                    (w.tip_downwind_m - tether.downwind_m).abs(),
                )
            })
            .collect();
        assert!(tether.downwind_m > 50.0);
        for e in &errs {
            assert!(e.0 < 1e-4 * l && e.1 < 1e-4 * l, "{errs:?}");
        }
    }
}

/// Issue 12: the calm-air quasi-static GE h* against the marching GE
/// search (same mesh, 20 elements, E* = 1e5, from rest) within 2 %, at 12
/// and 40 m/s; the onset is the divergence root confirmed by the QEP.
#[test]
fn calm_quasi_static_matches_the_marching_search() {
    let rates = [12.0, 40.0];
    let model = table(20, 1e5);
    let marched: Vec<f64> = rates
        .par_iter()
        .map(|&v| {
            let problem = CriticalProblem {
                profile: Profile::constant_rate(1.0, v, None).unwrap(),
                net_buoyancy_n: 1000.0,
                perturbation: None,
                aero: None,
                start: StartState::AtRest,
            };
            match critical_time(&model, &problem, &CriticalConfig::default(), &never)
                .unwrap()
                .onset
            {
                GeOnset::During { length_m, .. } => length_m,
                other => panic!("{other:?}"),
            }
        })
        .collect();
    for (v, h_march) in rates.iter().zip(marched) {
        let (h_qs, divergence) = qs_length(&model, *v, &AirLoads::calm());
        let no_qep = QsSearchConfig {
            confirm_with_qep: false,
            ..QsSearchConfig::default()
        };
        let (h_inertia, _) = qs_length_with(&model, *v, &AirLoads::calm(), &no_qep, 1.0);
        assert!(
            (h_inertia / h_qs - 1.0).abs() < 2e-4,
            "{h_inertia} vs {h_qs}"
        );
        println!(
            "{v} m/s: quasi-static h* {h_qs:.2} m, marching {h_march:.2} m ({:+.3} %)",
            100.0 * (h_qs / h_march - 1.0)
        );
        assert!(divergence);
        assert!((h_qs / h_march - 1.0).abs() < 0.02);
    }
}

/// Issue 12: the calm-air quasi-static GE h*, mesh-converged (320
/// elements; the change from 160 is printed), against the string's
/// converged h* = (F/ρA − v²)/g within 2 % for E* ≥ 100. Bending adds the
/// heavy-column boundary layer at the guide, ∝ (EI/ρA g)^{1/3}: with the
/// Table 7.1 EI = 1000 N m² that is +2.0 % at 12 m/s and +2.5 % at 40 m/s
/// (printed, asserted below 3 %); with EI = 100 N m² (12 and 30 m/s: the
/// rotation wave speed √(EI/I_ρ) = 35.8 m/s caps the rate) it is within
/// 2 %, which is asserted.
#[test]
fn converged_calm_quasi_static_matches_the_string() {
    let cases: Vec<(f64, f64, f64)> = [100.0, 1e3, 1e5]
        .into_iter()
        .flat_map(|es| [(es, 12.0, 100.0), (es, 30.0, 100.0)])
        .chain([(1e5, 12.0, 1000.0), (1e5, 40.0, 1000.0)])
        .collect();
    let out: Vec<(f64, f64)> = cases
        .par_iter()
        .map(|&(es, v, ei)| {
            let mut sys = GeChartSystem::table_7_1();
            sys.bending_stiffness_n_m2 = ei;
            // inertia of K only (Kelvin–Tait–Chetaev, calm air, constant rate), from 100 m
            let config = QsSearchConfig {
                confirm_with_qep: false,
                ..QsSearchConfig::default()
            };
            sys.elements = 320;
            let fine = qs_length_with(
                &sys.model(es).unwrap(),
                v,
                &AirLoads::calm(),
                &config,
                100.0,
            )
            .0;
            sys.elements = 160;
            (
                fine,
                qs_length_with(
                    &sys.model(es).unwrap(),
                    v,
                    &AirLoads::calm(),
                    &config,
                    100.0,
                )
                .0,
            )
        })
        .collect();
    for (&(es, v, ei), &(fine, coarse)) in cases.iter().zip(&out) {
        let string = (1000.0 / 0.078 - v * v) / 9.81;
        let dev = fine / string - 1.0;
        println!(
            "E* {es:.0e}, EI {ei}, {v} m/s: QS GE h* {fine:.2} m (160 el.: {coarse:.2}), string {string:.2} m ({:+.2} %)",
            100.0 * dev
        );
        assert!((fine / coarse - 1.0).abs() < 2e-3);
        if ei <= 100.0 {
            assert!(dev.abs() < 0.02, "{dev}");
        } else {
            assert!(dev > 0.0 && dev < 0.03, "{dev}");
        }
    }
    // the bending offset scales as EI^{1/3} (heavy-column boundary layer): 12 m/s, E* = 1e5
    let string = (1000.0 / 0.078 - 144.0) / 9.81;
    let ratio = (out[6].0 - string) / (out[4].0 - string);
    println!(
        "offset EI = 1000 / EI = 100: {ratio:.3} (10^(1/3) = {:.3})",
        10f64.cbrt()
    );
    assert!((ratio / 10f64.cbrt() - 1.0).abs() < 0.05, "{ratio}");
}
