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

use tetherplan::numerics::ge::air_load::AirLoads;
use tetherplan::numerics::ge::chart::GeChartSystem;
use tetherplan::numerics::ge::element::TipLoad;
use tetherplan::numerics::ge::qs_critical::{QsOnset, QsSearchConfig, critical_length};
use tetherplan::numerics::ge::quasi_static::{QsConfig, wind_stability};
use tetherplan::numerics::ge::stability::{StateMotion, state_stability};
use tetherplan::numerics::ge::solver::NewtonConfig;
use tetherplan::numerics::params::Kinematics;
use tetherplan::numerics::tether::wind::WindProfile;

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

#[test]
fn explore_calm_critical_length() {
    let model = GeChartSystem::table_7_1().model(1e5).unwrap();
    for v in [12.0, 40.0] {
        let t0 = std::time::Instant::now();
        let r = critical_length(
            &model,
            1000.0,
            &AirLoads::calm(),
            v,
            0.0,
            StateMotion::AtRest,
            &QsSearchConfig::default(),
            (1.0, 1.5 * 1000.0 / (0.078 * 9.81)),
            &never,
        )
        .unwrap();
        println!("v {v}: {:?} in {:?}", r, t0.elapsed());
        let _ = QsOnset::Cancelled;
    }
    let kin = Kinematics { length_m: 500.0, rate_m_s: 10.0, acceleration_m_s2: 0.0 };
    let a = state_stability(&model, kin, buoyancy(), StateMotion::AtRest, 2, NewtonConfig::default()).unwrap();
    let b = wind_stability(&model, kin, buoyancy(), &AirLoads::calm(), StateMotion::AtRest, &QsConfig::default(), None).unwrap();
    assert_eq!(a.spectrum.eigenvalues, b.spectrum.eigenvalues);
    for u in [5.0, 15.0] {
        let t0 = std::time::Instant::now();
        let w = wind_stability(&model, kin, buoyancy(), &air(u), StateMotion::AtRest, &QsConfig::default(), None).unwrap();
        println!("wind {u}: alt {} down {} maxre {} steps {} it {} in {:?}", w.tip_altitude_m, w.tip_downwind_m, w.spectrum.max_real, w.continuation_steps, w.newton_iterations, t0.elapsed());
    }
}

#[test]
fn explore_det_root() {
    use tetherplan::numerics::ge::quasi_static::{stiffness_determinant_sign, wind_equilibrium};
    let model = GeChartSystem::table_7_1().model(1e5).unwrap();
    let v = 12.0;
    for l in [1280.0, 1290.0, 1300.0, 1310.0, 1320.0, 1330.0, 1340.0, 1345.0, 1349.0, 1350.0, 1360.0] {
        let kin = Kinematics { length_m: l, rate_m_s: v, acceleration_m_s2: 0.0 };
        let eq = wind_equilibrium(&model, kin, buoyancy(), &AirLoads::calm(), &QsConfig::default(), None).unwrap();
        let sg = stiffness_determinant_sign(&model, kin, buoyancy(), &AirLoads::calm(), &eq.q);
        let w = wind_stability(&model, kin, buoyancy(), &AirLoads::calm(), StateMotion::AtRest, &QsConfig::default(), None).unwrap();
        let mut reals: Vec<f64> = w.spectrum.eigenvalues.iter().filter(|e| e.im == 0.0).map(|e| e.re).collect();
        reals.sort_by(|a, b| b.total_cmp(a));
        println!("L {l}: det {sg} maxre {:.3e} tol {:.3e} reals {:?}", w.spectrum.max_real, w.spectrum.tolerance(), &reals[..reals.len().min(3)]);
    }
}

#[test]
fn explore_mesh() {
    for n in [10usize, 20, 40, 80] {
        let mut sys = GeChartSystem::table_7_1();
        sys.elements = n;
        let model = sys.model(1e5).unwrap();
        for v in [12.0, 40.0] {
            let t0 = std::time::Instant::now();
            let r = critical_length(&model, 1000.0, &AirLoads::calm(), v, 0.0, StateMotion::AtRest,
                &QsSearchConfig::default(), (1.0, 1.5 * 1000.0 / (0.078 * 9.81)), &never).unwrap();
            let cf = (1000.0 / 0.078 - v * v) / 9.81;
            if let QsOnset::During { at } = r.onset {
                println!("n {n} v {v}: L* {at:.3} closed {cf:.3} ({:+.3} %) div {} qep {} eq {} in {:?}", 100.0 * (at / cf - 1.0), r.divergence, r.qep_solves, r.equilibria, t0.elapsed());
            } else { println!("n {n} v {v}: {:?}", r.onset); }
        }
    }
}

#[test]
fn explore_det_only() {
    use tetherplan::numerics::ge::quasi_static::{stiffness_negative_count, wind_equilibrium};
    for n in [20usize, 40, 80, 160, 320, 640] {
        let mut sys = GeChartSystem::table_7_1();
        sys.elements = n;
        let model = sys.model(1e5).unwrap();
        for v in [12.0, 40.0] {
            let t0 = std::time::Instant::now();
            let cf = (1000.0 / 0.078 - v * v) / 9.81;
            let sign = |l: f64| {
                let kin = Kinematics { length_m: l, rate_m_s: v, acceleration_m_s2: 0.0 };
                let eq = wind_equilibrium(&model, kin, buoyancy(), &AirLoads::calm(), &QsConfig::default(), None).unwrap();
                stiffness_negative_count(&model, kin, buoyancy(), &AirLoads::calm(), &eq.q).unwrap()
            };
            let (mut a, mut b) = (0.9 * cf, 1.2 * cf);
            assert!(sign(a) == 0 && sign(b) > 0);
            for _ in 0..40 { let m = 0.5 * (a + b); if sign(m) == 0 { a = m } else { b = m } }
            println!("det n {n} v {v}: L* {a:.3} ({:+.3} %) in {:?}", 100.0 * (a / cf - 1.0), t0.elapsed());
        }
    }
}
