//! The CLI reads the same JSON as the API and prints JSON.

use std::io::Write;
use std::process::{Command, Stdio};

fn run(args: &[&str], stdin: &str) -> (i32, serde_json::Value) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_tetherplan"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("binary runs");
    child
        .stdin
        .take()
        .unwrap()
        .write_all(stdin.as_bytes())
        .unwrap();
    let out = child.wait_with_output().unwrap();
    let json = serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "stdout is JSON ({e}): {}",
            String::from_utf8_lossy(&out.stdout)
        )
    });
    (out.status.code().unwrap(), json)
}

const REQUEST: &str = r#"{"cable": {"mass_per_length_kg_m": 0.078},
 "aerostat": {"net_buoyancy_n": 1000, "mass_kg": 10},
 "initial_length_m": 1,
 "model": {"kind": "linear_string", "elements": 50},
 "profile": {"kind": "constant_rate", "rate_m_s": 10}}"#;

#[test]
fn critical_from_stdin_and_from_a_file() {
    let (code, json) = run(&["critical"], REQUEST);
    assert_eq!(code, 0);
    let h = json["max_elevation_m"].as_f64().unwrap();
    assert!((h - 1310.0).abs() < 1.0, "{h}");
    let path = std::env::temp_dir().join(format!("tetherplan-cli-{}.json", std::process::id()));
    std::fs::write(&path, REQUEST).unwrap();
    let (code, from_file) = run(&["critical", "--input", path.to_str().unwrap()], "");
    std::fs::remove_file(&path).ok();
    assert_eq!(code, 0);
    assert_eq!(from_file, json);
}

#[test]
fn chart_safe_rate_and_stability() {
    let chart = REQUEST.replace(
        r#""profile": {"kind": "constant_rate", "rate_m_s": 10}"#,
        r#""rates_m_s": {"min": 10, "max": 20, "count": 2}, "net_buoyancies_n": [1000, 2000]"#,
    );
    let (code, json) = run(&["chart"], &chart);
    assert_eq!(code, 0);
    assert_eq!(json["series"].as_array().unwrap().len(), 2);
    let h = json["series"][0]["points"][0]["max_elevation_m"]
        .as_f64()
        .unwrap();
    assert!((h - 1310.0).abs() < 1.0);

    let safe = REQUEST.replace(
        r#""profile": {"kind": "constant_rate", "rate_m_s": 10}"#,
        r#""target_elevation_m": 1200"#,
    );
    let (code, json) = run(&["safe-rate"], &safe);
    assert_eq!(code, 0);
    assert!((json["max_rate_m_s"].as_f64().unwrap() - 34.49).abs() < 0.01);

    let stability = REQUEST.replace(
        r#""profile": {"kind": "constant_rate", "rate_m_s": 10}"#,
        r#""state": {"length_m": 1320, "rate_m_s": 10}, "modes": 2"#,
    );
    let (code, json) = run(&["stability"], &stability);
    assert_eq!(code, 0);
    assert_eq!(
        json["stable"], false,
        "1320 m at 10 m/s is past h* = 1310 m"
    );
}

#[test]
fn bad_input_prints_the_error_body_and_exits_2() {
    let (code, json) = run(
        &["critical"],
        &REQUEST.replace(r#""elements": 50"#, r#""elements": 1000000"#),
    );
    assert_eq!(code, 2);
    assert_eq!(json["error"]["field"], "model.elements");
    assert_eq!(json["error"]["code"], "invalid_input");
    let (code, json) = run(&["critical"], "{not json");
    assert_eq!(code, 2);
    assert_eq!(json["error"]["code"], "malformed_json");
}

#[test]
fn simulate_dispatches_on_the_model_kind() {
    // linear string: fixed length 100 m, tip shape released from rest
    let string = r#"{"cable": {"mass_per_length_kg_m": 0.078},
        "aerostat": {"net_buoyancy_n": 1000, "mass_kg": 10}, "initial_length_m": 100,
        "profile": {"kind": "constant_rate", "rate_m_s": 0}, "duration_s": 5, "samples": 50,
        "initial": {"kind": "shape", "tip_deflection_m": 0.1}}"#;
    let (code, json) = run(&["simulate"], string);
    assert_eq!(code, 0, "{json}");
    assert_eq!(json["outcome"], "completed");
    let tip = json["tip_deflection_m"].as_array().unwrap();
    assert_eq!(tip.len(), 50);
    assert!((tip[0].as_f64().unwrap() - 0.1).abs() < 1e-9);
    let energy: Vec<f64> = json["energy_j"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e.as_f64().unwrap())
        .collect();
    let drift = (energy.last().unwrap() - energy[0]).abs() / energy[0];
    assert!(
        drift < 1e-6,
        "energy at fixed length is conserved: drift {drift}"
    );

    // geometrically exact: Table 7.1 data, a held tip force
    let ge = r#"{"cable": {"density_kg_m3": 7800.0, "area_m2": 1e-5},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0}, "initial_length_m": 1.0,
        "model": {"kind": "geometrically_exact", "elements": 10, "bending_stiffness_n_m2": 1000.0,
                  "stiffness_ratio": 1e5, "inertia_ratio": 1.0},
        "time_step_s": 0.000883, "duration_s": 0.0883,
        "end_load": {"transverse_force_n": 400.0, "time": {"kind": "held", "ramp_s": 0.01, "hold_s": 0.03}}}"#;
    let (code, json) = run(&["simulate"], ge);
    assert_eq!(code, 0, "{json}");
    assert_eq!(json["outcome"]["status"], "completed");
    assert_eq!(json["steps"], 100);

    let (code, json) = run(
        &["simulate"],
        &ge.replace(r#""elements": 10"#, r#""elements": 0"#),
    );
    assert_eq!(code, 2);
    assert_eq!(json["error"]["field"], "model.elements");
}

#[test]
fn ge_chart_and_base_excitation_from_stdin() {
    // Table 7.1, 10 elements, two fast rates: t* a few seconds each.
    let chart = r#"{"cable": {"mass_per_length_kg_m": 0.078},
     "aerostat": {"net_buoyancy_n": 1000, "mass_kg": 10},
     "model": {"kind": "geometrically_exact", "elements": 10, "bending_stiffness_n_m2": 1000},
     "stiffness_ratios": [1e5],
     "rates_m_s": {"min": 100, "max": 150, "count": 2}}"#;
    let (code, json) = run(&["chart"], chart);
    assert_eq!(code, 0, "{json}");
    let points = &json["series"][0]["points"];
    assert_eq!(points[0]["onset"], "during");
    assert_eq!(
        points[1]["onset"], "immediate",
        "150 m/s is above the wave speed"
    );
    assert_eq!(points[1]["critical_time_s"], 0.0);
    let bad = chart.replace("[1e5]", "[0]");
    let (code, json) = run(&["chart"], &bad);
    assert_eq!(code, 2);
    assert_eq!(json["error"]["field"], "stiffness_ratios[0]");

    let base = r#"{"excitation": "base", "cable": {"mass_per_length_kg_m": 0.078},
     "model": {"kind": "geometrically_exact", "elements": 10, "bending_stiffness_n_m2": 1000,
               "stiffness_ratio": 5, "inertia_ratio": 1},
     "amplitude_m": 0.001, "frequencies_rad_s": {"min": 100, "max": 400, "count": 2},
     "duration_s": 0.1, "time_step_s": 0.0005}"#;
    let (code, json) = run(&["frequency-response"], base);
    assert_eq!(code, 0, "{json}");
    assert_eq!(json["points"].as_array().unwrap().len(), 2);
    assert_eq!(json["reduced_model_bands"].as_array().unwrap().len(), 2);
}

#[test]
fn dynamics_and_its_peaks_from_stdin() {
    use utoipa::PartialSchema;
    let example = |schema: utoipa::openapi::RefOr<utoipa::openapi::schema::Schema>| {
        serde_json::to_value(schema).unwrap()["example"].to_string()
    };
    let req = example(tetherplan::contract::dynamics::DynamicsRequest::schema());
    let (code, json) = run(&["dynamics"], &req);
    assert_eq!(code, 0, "{json}");
    assert_eq!(json["outcome"], "completed");
    assert!(
        json["peak_winch_tension_n"].as_f64().unwrap()
            > json["quasi_static"]["start_winch_tension_n"]
                .as_f64()
                .unwrap()
    );
    let (code, json) = run(
        &["dynamics"],
        &req.replace(r#""amplitude_m_s":6.0"#, r#""amplitude_m_s":600.0"#),
    );
    assert_eq!(code, 2, "{json}");
    assert_eq!(json["error"]["field"], "wind.time_history.amplitude_m_s");
    let req = example(tetherplan::contract::dynamics::DynamicsPeaksRequest::schema());
    let (code, json) = run(&["dynamics-peaks"], &req);
    assert_eq!(code, 0, "{json}");
    assert_eq!(json["samples"].as_array().unwrap().len(), 8);
}
