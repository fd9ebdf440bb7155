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

use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::Instant;

use tetherplan::numerics::dynamics::{
    self, Aerostat, DynamicsConfig, DynamicsProblem, GustHistory, LengthSchedule, Outcome, Tether,
};
use tetherplan::numerics::tether::wind::WindProfile;

fn python() -> Option<PathBuf> {
    if let Ok(p) = std::env::var("TETHERPLAN_MOORDYN_PYTHON") {
        return Some(PathBuf::from(p));
    }
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/peers-venv/bin/python");
    p.exists().then_some(p)
}

fn case_json() -> serde_json::Value {
    serde_json::json!({
        "segments": 50, "length_m": 1000.0, "mass_per_length_kg_m": 0.078, "diameter_m": 0.005,
        "normal_drag_coefficient": 1.2, "axial_stiffness_n": 1e6, "internal_damping_n_s": 1e4,
        "net_buoyancy_n": 1000.0, "aerostat_mass_kg": 10.0, "aerostat_drag_area_m2": 6.0,
        "added_mass_coefficient": 0.5, "air_density_kg_m3": 1.225, "gravity_m_s2": 9.81,
        "md_time_step_s": 0.001, "md_tmax_ic_s": 200.0, "md_thresh_ic": 1e-6,
        "coupling_step_s": 0.05, "duration_s": 300.0,
        "mean_m_s": 8.0, "ramp_s": 30.0,
        "gust_start_s": 200.0, "gust_duration_s": 20.0, "gust_amplitude_m_s": 6.0
    })
}

fn problem() -> DynamicsProblem {
    DynamicsProblem {
        tether: Tether {
            mass_per_length_kg_m: 0.078,
            diameter_m: 0.005,
            normal_drag_coefficient: 1.2,
            tangential_drag_coefficient: 0.0,
            axial_stiffness_n: 1e6,
            internal_damping_n_s: 1e4,
            drag_on_stretched_length: false,
        },
        aerostat: Aerostat {
            net_buoyancy_n: 1000.0,
            mass_kg: 10.0,
            reference_area_m2: 20.0,
            drag_coefficient: 0.3,
            lift_coefficient: 0.0,
            added_mass_coefficient: 0.5,
        },
        flow: WindProfile::calm(),
        gusts: vec![
            GustHistory::Ramp {
                start_time_s: 0.0,
                duration_s: 30.0,
                change_m_s: 8.0,
            },
            GustHistory::OneMinusCosine {
                start_time_s: 200.0,
                duration_s: 20.0,
                amplitude_m_s: 6.0,
            },
        ],
        turbulence: None,
        air_density_kg_m3: 1.225,
        gravity_m_s2: 9.81,
        length: LengthSchedule::Fixed(1000.0),
    }
}

fn column(v: &serde_json::Value, name: &str) -> Vec<f64> {
    v[name]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// Both time histories agree: winch and top tension within 2 % of the
/// peak winch / top tension, the aerostat's position within 0.5 % of the
/// length, at every 0.05 s of the 300 s (measured worst in the output).
#[test]
fn gust_time_histories_agree_with_moordyn() {
    let Some(py) = python() else {
        if std::env::var_os("CI").is_some() {
            panic!("MoorDyn venv missing: run .ci/run (target/peers-venv with pip moordyn==2.7.2)");
        }
        eprintln!("skipped: no MoorDyn venv (target/peers-venv)");
        return;
    };
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/peers/moordyn_tether.py");
    let mut child = Command::new(&py)
        .arg(&script)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("start the MoorDyn driver");
    {
        use std::io::Write;
        let mut stdin = child.stdin.take().unwrap();
        stdin.write_all(case_json().to_string().as_bytes()).unwrap();
    }
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success(), "MoorDyn driver failed");
    let text = String::from_utf8(out.stdout).unwrap();
    let last = text.lines().rev().find(|l| l.starts_with('{')).unwrap();
    let md: serde_json::Value = serde_json::from_str(last).unwrap();
    let md_time = column(&md, "time_s");
    let md_winch = column(&md, "winch_tension_n");
    let md_top = column(&md, "top_tension_n");
    let md_x = column(&md, "aerostat_downwind_m");
    let md_z = column(&md, "aerostat_altitude_m");

    let p = problem();
    let cfg = DynamicsConfig {
        segments: 50,
        duration_s: 300.0,
        time_step_s: 0.05,
        sample_interval_s: 0.05,
        ..Default::default()
    };
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
        "peak winch tension: tetherplan {:.2} N, MoorDyn {peak_winch:.2} N; CPU: MoorDyn {:.2} s (dtM 1 ms, RK2), tetherplan {ours_s:.3} s wall (h = 0.05 s)",
        run.peak_winch_tension.value,
        md["cpu_s"].as_f64().unwrap()
    );
    assert!(compared >= 5900, "{compared}");
    assert!(dw <= 0.02 * peak_winch, "winch {dw} N");
    assert!(dt <= 0.02 * peak_top, "top {dt} N");
    assert!(dx <= 5.0 && dz <= 5.0, "position {dx} m, {dz} m");
}
