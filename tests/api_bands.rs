//! `POST /api/v1/bands` and the `bands` job kind (issue 14): the route's
//! answer is the contract's, the OpenAPI example succeeds as is, bad input
//! is a 422 naming the field, large ensembles point to jobs, and a job runs
//! to the same answer with progress.

use axum::http::StatusCode;
use serde_json::{Value, json};
use tetherplan::api::{self};
use tetherplan::config::Limits;
use tetherplan::contract::bands;
use tetherplan::contract::run::NoProgress;
use tetherplan::jobs::store::JobStatus;
use tetherplan::jobs::try_execute_next;
use tetherplan::numerics::parallel::Parallelism;

mod common;
use common::{app, error, send_text as send};

fn body(samples: usize) -> Value {
    json!({
        "cable": {"density_kg_m3": 7800.0, "area_m2": 1e-5},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
        "rates_m_s": {"min": 5.0, "max": 40.0, "count": 8},
        "target_elevation_m": 1200.0,
        "uncertainty": {"samples": samples, "seed": 99, "inputs": [
            {"field": "aerostat.net_buoyancy_n", "distribution": "lognormal", "mean": 1000.0, "std_dev": 40.0},
            {"field": "cable.area_m2", "distribution": "uniform", "low": 0.97e-5, "high": 1.03e-5}
        ]}
    })
}

fn direct(v: &Value) -> String {
    let req = bands::parse_bands(&serde_json::to_vec(v).unwrap()).unwrap();
    serde_json::to_string(&bands::bands(&req, Parallelism::Rayon, &NoProgress).unwrap()).unwrap()
}

#[tokio::test]
async fn the_route_answers_like_the_contract() {
    let (app, _) = app();
    let b = body(300);
    let (status, text) = send(&app, "POST", "/api/v1/bands", Some(&b)).await;
    assert_eq!(status, StatusCode::OK, "{text}");
    assert_eq!(text, direct(&b));
    let v: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(v["points"].as_array().unwrap().len(), 8);
    assert_eq!(v["seed"], 99);
    assert_eq!(v["inputs"], b["uncertainty"]["inputs"]);
    assert_eq!(v["converged"], true);
    let p = &v["points"][3];
    assert!(p["max_elevation_m"]["p05"].as_f64() < p["max_elevation_m"]["p95"].as_f64());
    assert!(p["probability_unsafe"]["probability_nondim"].is_number());
}

/// The request example of the OpenAPI document succeeds as is.
#[tokio::test]
async fn the_openapi_example_succeeds() {
    let doc: Value = serde_json::from_str(&api::openapi::openapi_json()).unwrap();
    let schema = &doc["components"]["schemas"]["BandsRequest"];
    let example = if schema["example"].is_object() {
        schema["example"].clone()
    } else {
        schema["examples"][0].clone()
    };
    assert!(example.is_object(), "no example in {schema}");
    let (app, _) = app();
    let (status, text) = send(&app, "POST", "/api/v1/bands", Some(&example)).await;
    assert_eq!(status, StatusCode::OK, "{text}");
}

#[tokio::test]
async fn bad_input_is_a_422_naming_the_field() {
    let (app, _) = app();
    let cases = [
        (
            json!({"field": "aerostat.buoyancy", "distribution": "normal", "mean": 1.0, "std_dev": 1.0}),
            "uncertainty.inputs[0].field",
        ),
        (
            json!({"field": "cable.mass_per_length_kg_m", "distribution": "normal", "mean": 0.078, "std_dev": 0.001}),
            "uncertainty.inputs[0].field",
        ),
        (
            json!({"field": "aerostat.net_buoyancy_n", "distribution": "triangular", "mean": 1.0}),
            "uncertainty.inputs[0].distribution",
        ),
        (
            json!({"field": "aerostat.net_buoyancy_n", "distribution": "normal", "mean": 1000.0, "std_dev": 600.0}),
            "uncertainty.inputs[0]",
        ),
    ];
    for (input, field) in cases {
        let mut b = body(10);
        b["uncertainty"]["inputs"] = json!([input]);
        let (status, text) = send(&app, "POST", "/api/v1/bands", Some(&b)).await;
        assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{text}");
        assert_eq!(
            error(&text),
            ("invalid_input".into(), Some(field.into())),
            "{text}"
        );
    }
    let mut b = body(10);
    b["extra_m"] = json!(1.0);
    let (status, text) = send(&app, "POST", "/api/v1/bands", Some(&b)).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY);
    assert_eq!(error(&text).1.as_deref(), Some("extra_m"));
    let mut b = body(10);
    b["uncertainty"]["method"] = json!("sobol");
    let (status, text) = send(&app, "POST", "/api/v1/bands", Some(&b)).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY);
    assert_eq!(
        error(&text).1.as_deref(),
        Some("uncertainty.method"),
        "{text}"
    );
}

#[tokio::test]
async fn large_ensembles_point_to_jobs() {
    let (app, _) = app();
    let mut b = body(100_000);
    b["rates_m_s"]["count"] = json!(3);
    let (status, text) = send(&app, "POST", "/api/v1/bands", Some(&b)).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY);
    assert_eq!(
        error(&text),
        ("too_large".into(), Some("uncertainty.samples".into()))
    );
    assert!(text.contains("\\\"kind\\\": \\\"bands\\\""), "{text}");
}

#[tokio::test]
async fn a_bands_job_runs_to_the_synchronous_answer_with_progress() {
    let (app, queue) = app();
    let b = body(400);
    let (status, text) = send(
        &app,
        "POST",
        "/api/v1/jobs",
        Some(&json!({"kind": "bands", "request": b})),
    )
    .await;
    assert_eq!(status, StatusCode::ACCEPTED, "{text}");
    let id = serde_json::from_str::<Value>(&text).unwrap()["id"]
        .as_i64()
        .unwrap();
    let ran = try_execute_next(&queue).unwrap().unwrap();
    assert_eq!((ran.id, ran.status), (id, JobStatus::Done));
    let (_, text) = send(&app, "GET", &format!("/api/v1/jobs/{id}"), None).await;
    let v: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(v["kind"], "bands");
    assert_eq!(v["progress"], 1.0);
    let answer: Value = serde_json::from_str(&direct(&b)).unwrap();
    assert_eq!(v["result"], answer);
    // invalid input is refused at submission
    let mut bad = body(10);
    bad["uncertainty"]["seed"] = json!(1u64 << 60);
    let (status, text) = send(
        &app,
        "POST",
        "/api/v1/jobs",
        Some(&json!({"kind": "bands", "request": bad})),
    )
    .await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY);
    assert_eq!(error(&text).1.as_deref(), Some("request.uncertainty.seed"));
}

/// `tetherplan bands` reads the same JSON from stdin and prints the same
/// answer; bad input exits 2 with the error body.
#[test]
fn the_cli_prints_the_same_answer() {
    use std::io::Write;
    use std::process::{Command, Stdio};
    let run = |b: &Value| {
        let mut child = Command::new(env!("CARGO_BIN_EXE_tetherplan"))
            .arg("bands")
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        child
            .stdin
            .take()
            .unwrap()
            .write_all(&serde_json::to_vec(b).unwrap())
            .unwrap();
        let out = child.wait_with_output().unwrap();
        (
            out.status.code().unwrap(),
            serde_json::from_slice::<Value>(&out.stdout).unwrap(),
        )
    };
    let b = body(200);
    let (code, v) = run(&b);
    assert_eq!(code, 0);
    assert_eq!(v, serde_json::from_str::<Value>(&direct(&b)).unwrap());
    let mut bad = body(200);
    bad["uncertainty"]["inputs"][0]["field"] = json!("aerostat.colour");
    let (code, v) = run(&bad);
    assert_eq!(code, 2);
    assert_eq!(v["error"]["field"], "uncertainty.inputs[0].field");
}

// ------------------------------------------- plan and envelope bands

fn plan_body(samples: usize) -> Value {
    json!({
        "cable": {"mass_per_length_kg_m": 0.078, "breaking_strength_n": 5200.0},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
        "target_elevation_m": 1200.0,
        "winch": {"max_rate_m_s": 40.0, "max_acceleration_m_s2": 2.0},
        "samples": 41,
        "uncertainty": {"samples": samples, "seed": 5, "inputs": [
            {"field": "aerostat.net_buoyancy_n", "distribution": "normal", "mean": 1000.0, "std_dev": 50.0}
        ]}
    })
}

fn envelope_body(samples: usize) -> Value {
    json!({
        "cable": {"preset": "dyneema", "diameter_m": 0.006},
        "aerostat": {"net_buoyancy_n": 2000.0, "mass_kg": 100.0, "drag_coefficient_nondim": 0.3,
                     "reference_area_m2": 20.0},
        "wind": {"flow": {"kind": "uniform", "speed_m_s": 0.0}},
        "wind_speeds_m_s": {"min": 0.0, "max": 20.0, "count": 3},
        "tether_lengths_m": {"min": 100.0, "max": 2000.0, "count": 4},
        "payout_rate_m_s": 5.0,
        "uncertainty": {"samples": samples, "seed": 5, "inputs": [
            {"field": "aerostat.net_buoyancy_n", "distribution": "normal", "mean": 2000.0, "std_dev": 100.0},
            {"field": "cable.breaking_strength_n", "distribution": "lognormal", "mean": 9000.0, "std_dev": 900.0}
        ]}
    })
}

fn without_timing(mut v: Value) -> Value {
    if v["plan"].is_object() {
        v["plan"]["compute_time_s"] = json!(0.0);
    }
    v
}

#[tokio::test]
async fn plan_and_envelope_bands_routes_answer_like_the_contract() {
    let (app, _) = app();
    let b = plan_body(300);
    let (status, text) = send(&app, "POST", "/api/v1/plan/bands", Some(&b)).await;
    assert_eq!(status, StatusCode::OK, "{text}");
    let req = bands::parse_plan_bands(&serde_json::to_vec(&b).unwrap()).unwrap();
    let direct = bands::plan_bands(&req, Parallelism::Rayon, &NoProgress).unwrap();
    let got: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(
        without_timing(got.clone()),
        without_timing(serde_json::to_value(&direct).unwrap())
    );
    assert_eq!(
        got["instants"].as_array().unwrap().len(),
        got["plan"]["schedule"].as_array().unwrap().len()
    );
    assert!(got["probability_over_rating"]["probability_nondim"].is_number());

    let b = envelope_body(50);
    let (status, text) = send(&app, "POST", "/api/v1/envelope/bands", Some(&b)).await;
    assert_eq!(status, StatusCode::OK, "{text}");
    let req = bands::parse_envelope_bands(&serde_json::to_vec(&b).unwrap()).unwrap();
    let direct = bands::envelope_bands(&req, Parallelism::Rayon, &NoProgress).unwrap();
    assert_eq!(text, serde_json::to_string(&direct).unwrap());
    let got: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(got["cells"].as_array().unwrap().len(), 12);
    assert!(got["cells"][0]["probability_tension_exceeded"]["probability_nondim"].is_number());
}

#[tokio::test]
async fn plan_and_envelope_bands_refuse_bad_input_naming_the_field() {
    let (app, _) = app();
    let mut b = plan_body(10);
    b["uncertainty"]["inputs"][0]["field"] = json!("initial_length_m");
    let (status, text) = send(&app, "POST", "/api/v1/plan/bands", Some(&b)).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{text}");
    assert_eq!(
        error(&text).1.as_deref(),
        Some("uncertainty.inputs[0].field")
    );
    let mut b = plan_body(10);
    b["jerk"] = json!(1.0);
    let (status, text) = send(&app, "POST", "/api/v1/plan/bands", Some(&b)).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{text}");
    assert_eq!(error(&text).1.as_deref(), Some("jerk"));
    let mut b = envelope_body(10);
    b["uncertainty"]["inputs"][1]["field"] = json!("cable.axial_stiffness_n");
    b["cable"] =
        json!({"mass_per_length_kg_m": 0.02, "diameter_m": 0.006, "breaking_strength_n": 9000.0});
    let (status, text) = send(&app, "POST", "/api/v1/envelope/bands", Some(&b)).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{text}");
    assert_eq!(
        error(&text).1.as_deref(),
        Some("uncertainty.inputs[1].field")
    );
    // too large to answer synchronously: a job
    let b = envelope_body(5000);
    let (status, text) = send(&app, "POST", "/api/v1/envelope/bands", Some(&b)).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{text}");
    assert_eq!(
        error(&text),
        ("too_large".into(), Some("uncertainty.samples".into()))
    );
    assert!(text.contains("envelope_bands"), "{text}");
}

#[tokio::test]
async fn plan_and_envelope_bands_jobs_run_to_the_synchronous_answer() {
    let (app, queue) = app();
    for (kind, b, path) in [
        ("plan_bands", plan_body(200), "/api/v1/plan/bands"),
        (
            "envelope_bands",
            envelope_body(30),
            "/api/v1/envelope/bands",
        ),
    ] {
        let (status, text) = send(
            &app,
            "POST",
            "/api/v1/jobs",
            Some(&json!({"kind": kind, "request": b})),
        )
        .await;
        assert_eq!(status, StatusCode::ACCEPTED, "{text}");
        let id = serde_json::from_str::<Value>(&text).unwrap()["id"]
            .as_i64()
            .unwrap();
        let ran = try_execute_next(&queue).unwrap().unwrap();
        assert_eq!((ran.id, ran.status), (id, JobStatus::Done));
        let (_, text) = send(&app, "GET", &format!("/api/v1/jobs/{id}"), None).await;
        let v: Value = serde_json::from_str(&text).unwrap();
        assert_eq!(v["kind"], kind);
        assert_eq!(v["progress"], 1.0);
        let (_, sync) = send(&app, "POST", path, Some(&b)).await;
        let sync: Value = serde_json::from_str(&sync).unwrap();
        assert_eq!(without_timing(v["result"].clone()), without_timing(sync));
    }
}

/// The size estimates of the two job kinds bound their real answers.
#[test]
fn plan_and_envelope_bands_estimates_bound_the_answers() {
    use tetherplan::jobs::kinds::JobSubmission;
    let limits = Limits::default();
    for (kind, b) in [
        ("plan_bands", plan_body(50)),
        ("envelope_bands", envelope_body(20)),
    ] {
        let body = serde_json::to_vec(&json!({"kind": kind, "request": b})).unwrap();
        let JobSubmission::One(item) = JobSubmission::parse(&body, &limits).unwrap() else {
            panic!()
        };
        let estimate = item.estimate().result_bytes;
        let real = JobSubmission::parse(&body, &limits)
            .unwrap()
            .run(&NoProgress)
            .unwrap()
            .len() as u64;
        assert!(real <= estimate, "{kind}: {real} > {estimate}");
    }
}
