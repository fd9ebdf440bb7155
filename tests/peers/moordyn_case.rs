//! The MoorDyn 2.7.2 peer (`tests/peers/moordyn_tether.py`) driven from
//! Rust: where its interpreter is, the case it is given (read off a
//! [`DynamicsProblem`]), and the time history it answers. Shared by
//! `tests/peer_moordyn.rs` (accuracy) and `benches/dynamics.rs` (speed,
//! side by side), each including it with `#[path]`.

use std::path::PathBuf;
use std::process::{Command, Stdio};

use tetherplan::numerics::dynamics::{DynamicsProblem, reference};

/// The venv's interpreter (`target/peers-venv`, made by `.ci/run`), or the
/// one named by `TETHERPLAN_MOORDYN_PYTHON`; `None` when neither exists.
pub fn python() -> Option<PathBuf> {
    if let Ok(p) = std::env::var("TETHERPLAN_MOORDYN_PYTHON") {
        return Some(PathBuf::from(p));
    }
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/peers-venv/bin/python");
    p.exists().then_some(p)
}

/// The driver's case for the reference gust case `p` on `segments`
/// segments (MoorDyn at dtM = 1 ms with RK2, coupled every 0.05 s).
#[allow(dead_code)] // tests/peer_moordyn_winch.rs has cases of its own
pub fn gust_case_json(p: &DynamicsProblem, segments: usize) -> serde_json::Value {
    let (t, a) = (&p.tether, &p.aerostat);
    let (gust_start, gust_duration, gust_amplitude) = reference::GUST_CASE_GUST;
    serde_json::json!({
        "segments": segments, "length_m": reference::REFERENCE_LENGTH_M,
        "mass_per_length_kg_m": t.mass_per_length_kg_m, "diameter_m": t.diameter_m,
        "normal_drag_coefficient": t.normal_drag_coefficient,
        "axial_stiffness_n": t.axial_stiffness_n, "internal_damping_n_s": t.internal_damping_n_s,
        "net_buoyancy_n": a.net_buoyancy_n, "aerostat_mass_kg": a.mass_kg,
        "aerostat_drag_area_m2": a.drag_coefficient * a.reference_area_m2,
        "added_mass_coefficient": a.added_mass_coefficient,
        "air_density_kg_m3": p.air_density_kg_m3, "gravity_m_s2": p.gravity_m_s2,
        "md_time_step_s": 0.001, "md_tmax_ic_s": 200.0, "md_thresh_ic": 1e-6,
        "coupling_step_s": 0.05, "duration_s": reference::GUST_CASE_DURATION_S,
        "mean_m_s": reference::GUST_CASE_MEAN_M_S, "ramp_s": reference::GUST_CASE_RAMP_S,
        "gust_start_s": gust_start, "gust_duration_s": gust_duration,
        "gust_amplitude_m_s": gust_amplitude
    })
}

/// MoorDyn's answer: the time history every coupling step, and the CPU
/// time of its stepping loop (s; initialisation and Python start-up not
/// counted).
#[allow(dead_code)] // the bench reads only the CPU time
pub struct History {
    pub time_s: Vec<f64>,
    pub winch_tension_n: Vec<f64>,
    pub top_tension_n: Vec<f64>,
    pub aerostat_downwind_m: Vec<f64>,
    pub aerostat_altitude_m: Vec<f64>,
    pub cpu_s: f64,
}

/// Runs the driver with `case` under the interpreter `py`.
pub fn run(py: &PathBuf, case: &serde_json::Value) -> History {
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/peers/moordyn_tether.py");
    let mut child = Command::new(py)
        .arg(&script)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("start the MoorDyn driver");
    {
        use std::io::Write;
        let mut stdin = child.stdin.take().unwrap();
        stdin.write_all(case.to_string().as_bytes()).unwrap();
    }
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success(), "MoorDyn driver failed");
    let text = String::from_utf8(out.stdout).unwrap();
    // MoorDyn writes to stdout too: the answer is the last JSON line.
    let last = text.lines().rev().find(|l| l.starts_with('{')).unwrap();
    let md: serde_json::Value = serde_json::from_str(last).unwrap();
    let column = |name: &str| -> Vec<f64> {
        md[name]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    History {
        time_s: column("time_s"),
        winch_tension_n: column("winch_tension_n"),
        top_tension_n: column("top_tension_n"),
        aerostat_downwind_m: column("aerostat_downwind_m"),
        aerostat_altitude_m: column("aerostat_altitude_m"),
        cpu_s: md["cpu_s"].as_f64().unwrap(),
    }
}

/// The driver's case for a winch run of `p` (a tether paid out or hauled
/// in by the rate table `rate_points` `[t, L̇]`, linear between them and
/// held after, stopped at `stop_time_s` if given) from `length_m`, in a
/// uniform wind ramped from calm to `mean_m_s` over `ramp_s`; MoorDyn at
/// `md_time_step_s` with RK2, its rate set every 5 ms (the mean of each
/// 5 ms), recorded every `coupling_step_s`.
#[allow(dead_code, clippy::too_many_arguments)] // each test binary uses its own cases
pub fn winch_case_json(
    p: &DynamicsProblem,
    segments: usize,
    length_m: f64,
    mean_m_s: f64,
    ramp_s: f64,
    rate_points: &[[f64; 2]],
    stop_time_s: Option<f64>,
    duration_s: f64,
    md_time_step_s: f64,
    coupling_step_s: f64,
) -> serde_json::Value {
    let (t, a) = (&p.tether, &p.aerostat);
    let mut c = serde_json::json!({
        "segments": segments, "length_m": length_m,
        "mass_per_length_kg_m": t.mass_per_length_kg_m, "diameter_m": t.diameter_m,
        "normal_drag_coefficient": t.normal_drag_coefficient,
        "axial_stiffness_n": t.axial_stiffness_n, "internal_damping_n_s": t.internal_damping_n_s,
        "net_buoyancy_n": a.net_buoyancy_n, "aerostat_mass_kg": a.mass_kg,
        "aerostat_drag_area_m2": a.drag_coefficient * a.reference_area_m2,
        "added_mass_coefficient": a.added_mass_coefficient,
        "air_density_kg_m3": p.air_density_kg_m3, "gravity_m_s2": p.gravity_m_s2,
        "md_time_step_s": md_time_step_s, "md_tmax_ic_s": 200.0, "md_thresh_ic": 1e-6,
        "coupling_step_s": coupling_step_s, "rate_update_s": 0.005, "duration_s": duration_s,
        "mean_m_s": mean_m_s, "ramp_s": ramp_s,
        "gust_start_s": 1e9, "gust_duration_s": 1.0, "gust_amplitude_m_s": 0.0,
        "rate_points": rate_points,
    });
    if let Some(s) = stop_time_s {
        c["stop_time_s"] = serde_json::json!(s);
    }
    c
}
