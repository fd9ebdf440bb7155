//! Unit tests of the transient run: in-place assembly, energy and steps.

use super::*;
use crate::numerics::params::AerostatSystem;
use crate::numerics::string::rest_modes::rest_eigenvalue;

#[test]
fn in_place_assembly_matches_the_operators() {
    let model = StringModel::new(AerostatSystem::thesis(), 7).unwrap();
    let c = model.coefficients(NondimState {
        length: 3.0,
        rate: 0.2,
        acceleration: 0.01,
    });
    let want = model.operators.assemble(&c);
    let mut got = zero_system(7);
    assemble_into(&model.operators, &c, &mut got);
    for (a, b) in [
        (&got.mass, &want.mass),
        (&got.damping, &want.damping),
        (&got.stiffness, &want.stiffness),
    ] {
        for (x, y) in a
            .diag
            .iter()
            .chain(&a.lower)
            .chain(&a.upper)
            .zip(b.diag.iter().chain(&b.lower).chain(&b.upper))
        {
            assert!((x - y).abs() < 1e-12 * y.abs().max(1.0));
        }
    }
}

#[test]
fn rejects_bad_configurations_naming_the_field() {
    let model = StringModel::new(AerostatSystem::thesis(), 10).unwrap();
    let profile = Profile::constant_rate(1.0, 1.0, None).unwrap();
    let base = TransientConfig {
        duration_s: 10.0,
        time_step_s: Some(0.01),
        samples: 100,
        initial: InitialState::Rest,
        aero: None,
        eigen: None,
    };
    let field = |c: TransientConfig| match plan(&model, &profile, &c) {
        Err(TransientError::Invalid(e)) => e.field,
        other => panic!("expected invalid input, got {other:?}"),
    };
    assert_eq!(
        field(TransientConfig {
            duration_s: -1.0,
            ..base.clone()
        }),
        "duration_s"
    );
    assert_eq!(
        field(TransientConfig {
            samples: 1,
            ..base.clone()
        }),
        "samples"
    );
    assert_eq!(
        field(TransientConfig {
            time_step_s: Some(1e-9),
            ..base.clone()
        }),
        "time_step_s"
    );
    assert_eq!(
        field(TransientConfig {
            eigen: Some(EigenTracking {
                interval_s: 1e-4,
                count: 3
            }),
            ..base.clone()
        }),
        "eigenvalues.interval_s"
    );
    assert_eq!(
        field(TransientConfig {
            initial: InitialState::Mode {
                mode: 0,
                tip_deflection_m: 0.1
            },
            ..base
        }),
        "initial.mode"
    );
}

/// A tip force switched on at t = 0 on a cable of fixed length: the tip
/// swings about the static deflection `K⁻¹f` (up to about twice it, the
/// step response of the dominant first mode) and, once released,
/// oscillates about zero.
#[test]
fn held_tip_force_swings_about_the_static_deflection() {
    let model = StringModel::new(AerostatSystem::thesis(), 20).unwrap();
    let profile = Profile::constant_rate(1.0, 0.0, None).unwrap();
    let (force, hold) = (10.0, 3.0);
    let cfg = TransientConfig {
        duration_s: 6.0,
        time_step_s: Some(1e-3),
        samples: 6001,
        initial: InitialState::TipForce {
            force_n: force,
            duration_s: hold,
        },
        aero: None,
        eigen: None,
    };
    let r = simulate(&model, &profile, &cfg, &Silent).unwrap();
    let sys = model.matrices(NondimState {
        length: 1.0,
        rate: 0.0,
        acceleration: 0.0,
    });
    let mut q = vec![0.0; 20];
    q[19] = force / 1000.0;
    sys.stiffness.solve_columns_in_place(&mut q, 1);
    let static_m = q[19];
    let held: Vec<f64> = r
        .samples
        .iter()
        .filter(|s| s.time_s < hold)
        .map(|s| s.tip_deflection_m)
        .collect();
    let max = held.iter().cloned().fold(f64::MIN, f64::max);
    let min = held.iter().cloned().fold(f64::MAX, f64::min);
    assert!(
        min > -0.05 * static_m && (max / (2.0 * static_m) - 1.0).abs() < 0.05,
        "{min} {max} {static_m}"
    );
    assert!(
        r.samples
            .iter()
            .filter(|s| s.time_s < hold)
            .all(|s| s.tip_force_n == force)
    );
    assert!(
        r.samples
            .iter()
            .filter(|s| s.time_s > hold)
            .all(|s| s.tip_force_n == 0.0)
    );
    let released: Vec<f64> = r
        .samples
        .iter()
        .filter(|s| s.time_s > hold)
        .map(|s| s.tip_deflection_m)
        .collect();
    let mean = released.iter().sum::<f64>() / released.len() as f64;
    assert!(mean.abs() < 0.3 * static_m, "released mean {mean}");
}

#[test]
fn rest_eigenvalues_by_inertia_match_the_qep() {
    let model = StringModel::new(AerostatSystem::thesis(), 30).unwrap();
    let sys = rest_system(&model, 250.0, 0.3);
    let spectrum = qep::solve(&sys).unwrap();
    for (k, mode) in spectrum.modes().iter().take(4).enumerate() {
        let w = rest_eigenvalue(&sys, k + 1).unwrap().sqrt();
        assert!(
            (w / mode.im - 1.0).abs() < 1e-9,
            "mode {}: {w} vs {}",
            k + 1,
            mode.im
        );
    }
    let (shape, w) = rest_mode_shape(&model, 250.0, 0.3, 2).unwrap();
    assert!((w / spectrum.modes()[1].im - 1.0).abs() < 1e-9);
    // K φ = ω² M φ
    let (mut kx, mut mx) = (vec![0.0; 30], vec![0.0; 30]);
    sys.stiffness.mul_vec(&shape, &mut kx);
    sys.mass.mul_vec(&shape, &mut mx);
    let scale = kx.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    for (a, b) in kx.iter().zip(&mx) {
        assert!((a - w * w * b).abs() < 1e-8 * scale);
    }
}
