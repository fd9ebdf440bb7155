//! An independent check of the dynamic tether (SPEC §11) against MoorDyn
//! 2.7.2 (PyPI `moordyn`), run from a venv (`target/peers-venv`, made by
//! `.ci/run`; or the interpreter named by `TETHERPLAN_MOORDYN_PYTHON`).
//! Without it the test skips, except under `CI`, where it fails.
//!
//! The case (both codes): the bench tether of issue 23 (1000 m, 50
//! segments, 0.078 kg/m, 5 mm, C_n = 1.2, EA = 1 MN, c = 10 kN s; F = 1000 N,
//! m = 10 kg, C_D A = 6 m², C_a = 0.5) at rest upright in calm air; a
//! uniform wind ramps to 8 m/s over 30 s, and at 200 s a `1 − cos` gust of
//! +6 m/s over 20 s passes; 300 s. Air is mapped onto MoorDyn as in
//! `tests/peers/moordyn_tether.py` (drag on the unstretched length there, so
//! here too; no tangential drag, no line added mass, no Froude–Krylov).

use std::time::Instant;

use tetherplan::numerics::dynamics::{self, Outcome, reference};

#[path = "peers/moordyn_case.rs"]
mod moordyn_case;

/// Both time histories agree: winch and top tension within 2 % of the
/// peak winch / top tension, the aerostat's position within 0.5 % of the
/// length, at every kept sample of the 300 s on MoorDyn's 0.05 s grid
/// (measured worst in the output).
#[test]
fn gust_time_histories_agree_with_moordyn() {
    let Some(py) = moordyn_case::python() else {
        if std::env::var_os("CI").is_some() {
            panic!("MoorDyn venv missing: run .ci/run (target/peers-venv with pip moordyn==2.7.2)");
        }
        eprintln!("skipped: no MoorDyn venv (target/peers-venv)");
        return;
    };
    let p = reference::gust_case();
    let cfg = reference::gust_case_config();
    let md = moordyn_case::run(&py, &moordyn_case::gust_case_json(&p, cfg.segments));
    let md_time = &md.time_s;
    let md_winch = &md.winch_tension_n;
    let md_top = &md.top_tension_n;
    let md_x = &md.aerostat_downwind_m;
    let md_z = &md.aerostat_altitude_m;

    let clock = Instant::now();
    let run = dynamics::simulate(&p, &cfg).unwrap();
    let ours_s = clock.elapsed().as_secs_f64();
    assert_eq!(run.outcome, Outcome::Completed);
    let peak_winch = md_winch.iter().cloned().fold(0.0, f64::max);
    let peak_top = md_top.iter().cloned().fold(0.0, f64::max);
    let (mut dw, mut dt, mut dx, mut dz) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut compared = 0;
    for s in &run.samples {
        let i = (s.time_s / 0.05).round() as usize;
        if i >= md_time.len() || (md_time[i] - s.time_s).abs() > 1e-6 {
            continue;
        }
        compared += 1;
        dw = dw.max((s.winch_tension_n - md_winch[i]).abs());
        dt = dt.max((s.top_tension_n - md_top[i]).abs());
        dx = dx.max((s.aerostat_downwind_m - md_x[i]).abs());
        dz = dz.max((s.aerostat_altitude_m - md_z[i]).abs());
    }
    println!(
        "compared {compared} samples: winch {dw:.2} N ({:.2} % of {peak_winch:.1}), top {dt:.2} N ({:.2} % of {peak_top:.1}), downwind {dx:.3} m, altitude {dz:.3} m",
        100.0 * dw / peak_winch,
        100.0 * dt / peak_top
    );
    println!(
        "peak winch tension: tetherplan {:.2} N, MoorDyn {peak_winch:.2} N; CPU: MoorDyn {:.2} s (dtM 1 ms, RK2), tetherplan {ours_s:.3} s wall (h = {} s)",
        run.peak_winch_tension.value, md.cpu_s, cfg.time_step_s
    );
    // Every kept sample on MoorDyn's 0.05 s grid is compared.
    let kept = (cfg.duration_s / cfg.sample_interval_s.max(cfg.time_step_s)).round() as usize;
    assert!(
        compared >= kept.min(md_time.len() - 1),
        "{compared} of {kept}"
    );
    assert!(dw <= 0.02 * peak_winch, "winch {dw} N");
    assert!(dt <= 0.02 * peak_top, "top {dt} N");
    assert!(dx <= 5.0 && dz <= 5.0, "position {dx} m, {dz} m");
}
