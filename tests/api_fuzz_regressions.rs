//! The hostile-client corpus of issue 22, kept as regression tests: bodies
//! that once answered 500 (a panic per Monte-Carlo draw) or 200 with
//! `null` where the schema says number. Each is now refused with 422
//! naming the input and its range, at the synchronous route and at
//! `POST /api/v1/jobs` alike (one validation for both doors), or answered
//! with finite numbers. Duplicate JSON keys are refused naming the key.

use axum::body::Body;
use axum::http::{Request, StatusCode, header};
use serde_json::{Value, json};
use tetherplan::api;

mod common;
use common::{app, post, request};

/// The OpenAPI request example of `route` (what `/docs` sends).
fn example(route: &str) -> Value {
    let doc = serde_json::to_value(api::openapi::openapi()).unwrap();
    doc["paths"][route]["post"]["requestBody"]["content"]["application/json"]["example"].clone()
}

/// `v` with the value at the dotted `path` (`a.b[1].c`) set to `x`.
fn set(mut v: Value, path: &str, x: Value) -> Value {
    let mut node = &mut v;
    for part in path.split('.') {
        let (name, index) = match part.split_once('[') {
            Some((n, i)) => (n, Some(i.trim_end_matches(']').parse::<usize>().unwrap())),
            None => (part, None),
        };
        node = &mut node[name];
        if let Some(i) = index {
            node = &mut node[i];
        }
    }
    *node = x;
    v
}

/// (route, job kind, body, the field a refusal names).
fn corpus() -> Vec<(&'static str, &'static str, Value, &'static str)> {
    let eq = example("/api/v1/equilibrium");
    let log_law = |z0: f64| {
        set(
            eq.clone(),
            "wind.flow",
            json!({"kind": "log_law", "reference_speed_m_s": 8.0, "roughness_length_m": z0}),
        )
    };
    let crit = example("/api/v1/critical");
    let bands = example("/api/v1/bands");
    let plan_bands = example("/api/v1/plan/bands");
    let env_bands = example("/api/v1/envelope/bands");
    let plan = example("/api/v1/plan");
    vec![
        // null tensions and altitude, "Safety factor inf", meets: true
        (
            "/api/v1/equilibrium",
            "equilibrium",
            log_law(5e-324),
            "wind.flow.roughness_length_m",
        ),
        (
            "/api/v1/equilibrium",
            "equilibrium",
            log_law(1e-300),
            "wind.flow.roughness_length_m",
        ),
        // critical_time_s: null, "t* = inf s"
        (
            "/api/v1/critical",
            "critical",
            set(crit.clone(), "profile.rate_m_s", json!(5e-324)),
            "profile.rate_m_s",
        ),
        (
            "/api/v1/critical",
            "critical",
            set(crit.clone(), "profile.rate_m_s", json!(-1e-300)),
            "profile.rate_m_s",
        ),
        // null statistics
        (
            "/api/v1/bands",
            "bands",
            set(bands.clone(), "rates_m_s", json!([1e-300, 10.0])),
            "rates_m_s[0]",
        ),
        (
            "/api/v1/bands",
            "bands",
            set(
                bands.clone(),
                "rates_m_s",
                json!({"min": 1e-300, "max": 10.0, "count": 4}),
            ),
            "rates_m_s.min",
        ),
        // a panic per draw (29,158 log lines for one request)
        (
            "/api/v1/bands",
            "bands",
            set(bands.clone(), "uncertainty.inputs[0].mean", json!(1e300)),
            "uncertainty.inputs[0].mean",
        ),
        (
            "/api/v1/plan/bands",
            "plan_bands",
            set(
                plan_bands.clone(),
                "uncertainty.inputs[0].mean",
                json!(1e300),
            ),
            "uncertainty.inputs[0].mean",
        ),
        (
            "/api/v1/bands",
            "bands",
            set(bands.clone(), "uncertainty.inputs[1].mean", json!(1e-300)),
            "uncertainty.inputs[1].mean",
        ),
        (
            "/api/v1/plan/bands",
            "plan_bands",
            set(plan_bands.clone(), "uncertainty.inputs[1].mean", json!(5e2)),
            "uncertainty.inputs[1].mean",
        ),
        (
            "/api/v1/bands",
            "bands",
            set(bands.clone(), "uncertainty.inputs[0].std_dev", json!(1e300)),
            "uncertainty.inputs[0]",
        ),
        // null statistics
        (
            "/api/v1/envelope/bands",
            "envelope_bands",
            set(
                env_bands.clone(),
                "uncertainty.inputs[1].high",
                json!(1e300),
            ),
            "uncertainty.inputs[1].high",
        ),
        (
            "/api/v1/envelope/bands",
            "envelope_bands",
            set(
                env_bands.clone(),
                "uncertainty.inputs[0].mean",
                json!(5e-324),
            ),
            "uncertainty.inputs[0]",
        ),
        // null transient_check fields
        (
            "/api/v1/plan",
            "plan",
            set(plan.clone(), "target_elevation_m", json!(1e-300)),
            "target_elevation_m",
        ),
        (
            "/api/v1/plan",
            "plan",
            set(plan.clone(), "target_elevation_m", json!(5e-324)),
            "target_elevation_m",
        ),
        // 202 then a failed job before: refused at submission now
        (
            "/api/v1/critical",
            "critical",
            set(crit, "profile.rate_m_s", json!(0.0)),
            "profile.rate_m_s",
        ),
    ]
}

#[tokio::test]
async fn the_fuzz_corpus_is_refused_naming_the_input_at_both_doors() {
    let (app, _) = app();
    let cases = corpus();
    assert_eq!(cases.len(), 16);
    for (route, kind, body, field) in cases {
        let (status, sync) = post(&app, route, &body).await;
        assert_eq!(
            status,
            StatusCode::UNPROCESSABLE_ENTITY,
            "{route} {field}: {sync}"
        );
        assert_eq!(sync["error"]["field"], field, "{route}: {sync}");
        let message = sync["error"]["message"].as_str().unwrap();
        assert!(
            message.contains("must") || message.contains("puts"),
            "{route} {field}: the message states the range: {message}"
        );
        let (status, job) = post(
            &app,
            "/api/v1/jobs",
            &json!({"kind": kind, "request": body}),
        )
        .await;
        assert_eq!(
            status,
            StatusCode::UNPROCESSABLE_ENTITY,
            "POST /jobs {kind} {field}: {job}"
        );
        assert_eq!(
            job["error"]["field"],
            format!("request.{field}"),
            "POST /jobs {kind}: {job}"
        );
    }
}

/// Every number of `v` is a number: no `null` among the keys ending in a
/// unit that are not optional in the answer (`_m`, `_s`, `_n`, …), so
/// that a NaN or ∞ written as `null` shows.
fn assert_no_null_numbers(v: &Value, at: &str, optional: &[&str]) {
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                let here = format!("{at}.{k}");
                if x.is_null() && !optional.contains(&k.as_str()) {
                    panic!("{here} is null");
                }
                assert_no_null_numbers(x, &here, optional);
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                assert_no_null_numbers(x, &format!("{at}[{i}]"), optional);
            }
        }
        _ => {}
    }
}

/// GE stability at zero gravity (a bare cantilever, thesis ch. 8) is a
/// real answer; the string's closed forms F/(ρA g) do not exist there and
/// are null (the schema says so), not ∞ written as null.
#[tokio::test]
async fn ge_stability_without_gravity_answers_finite_numbers() {
    let (app, _) = app();
    let body = json!({
        "cable": {"mass_per_length_kg_m": 0.078},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
        "initial_length_m": 1.0,
        "gravity_m_s2": 0.0,
        "model": {"kind": "geometrically_exact", "elements": 10, "bending_stiffness_n_m2": 1000.0,
                  "stiffness_ratio": 1e5, "inertia_ratio": 1.0},
        "state": {"length_m": 50.0, "rate_m_s": 1.0}
    });
    let (status, ans) = post(&app, "/api/v1/stability", &body).await;
    assert_eq!(status, StatusCode::OK, "{ans}");
    assert!(ans["string_closed_form_elevation_m"].is_null(), "{ans}");
    assert!(ans["extensible_closed_form_elevation_m"].is_null(), "{ans}");
    assert!(ans["time_scale_s"].as_f64().unwrap().is_finite());
    assert_no_null_numbers(
        &ans,
        "",
        &[
            "string_closed_form_elevation_m",
            "extensible_closed_form_elevation_m",
            "stable",
            "max_real_1_s",
            "max_real_nondim",
            "tolerance_1_s",
            "equilibrium",
        ],
    );
    // with gravity the bounds are numbers
    let mut with_g = body.clone();
    with_g["gravity_m_s2"] = json!(9.81);
    let (status, ans) = post(&app, "/api/v1/stability", &with_g).await;
    assert_eq!(status, StatusCode::OK, "{ans}");
    assert!(ans["string_closed_form_elevation_m"].as_f64().unwrap() > 0.0);
}

async fn post_raw(app: &axum::Router, uri: &str, text: &str) -> common::Answer {
    let req = Request::builder()
        .method("POST")
        .uri(uri)
        .header(header::CONTENT_TYPE, "application/json");
    request(app, req, Body::from(text.to_string())).await
}

#[tokio::test]
async fn duplicate_json_keys_are_refused_naming_the_key() {
    let (app, _) = app();
    let critical = r#"{"cable": {"mass_per_length_kg_m": 0.078},
        "aerostat": {"net_buoyancy_n": 1000, "mass_kg": 10},
        "profile": {"kind": "constant_rate", "rate_m_s": 10, "rate_m_s": 0}}"#;
    let a = post_raw(&app, "/api/v1/critical", critical).await;
    assert_eq!(a.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", a.text);
    assert_eq!(a.field(), "profile.rate_m_s");
    assert!(a.error().message.contains("duplicate key `rate_m_s`"));
    // a duplicated top-level key, and inside a job submission
    let twice = r#"{"cable": {"mass_per_length_kg_m": 0.078}, "cable": {"mass_per_length_kg_m": 1},
        "aerostat": {"net_buoyancy_n": 1000, "mass_kg": 10}, "target_elevation_m": 1200}"#;
    let a = post_raw(&app, "/api/v1/safe-rate", twice).await;
    assert_eq!(a.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", a.text);
    assert_eq!(a.field(), "cable");
    let job = format!(r#"{{"kind": "critical", "kind": "stability", "request": {critical}}}"#);
    let a = post_raw(&app, "/api/v1/jobs", &job).await;
    assert_eq!(a.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", a.text);
    assert_eq!(a.field(), "kind");
    // the same body without the duplicate is answered
    let once = critical.replace(r#""rate_m_s": 10, "rate_m_s": 0"#, r#""rate_m_s": 10"#);
    let a = post_raw(&app, "/api/v1/critical", &once).await;
    assert_eq!(a.status, StatusCode::OK, "{}", a.text);
}

#[test]
fn the_cli_refuses_duplicate_keys_too() {
    use std::io::Write;
    use std::process::{Command, Stdio};
    let mut child = Command::new(env!("CARGO_BIN_EXE_tetherplan"))
        .args(["safe-rate"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(
            br#"{"cable": {"mass_per_length_kg_m": 0.078},
                "aerostat": {"net_buoyancy_n": 1000, "mass_kg": 10, "mass_kg": 20},
                "target_elevation_m": 1200}"#,
        )
        .unwrap();
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let body: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(body["error"]["field"], "aerostat.mass_kg", "{body}");
}

/// A draw whose fields are each in range but whose combination is not
/// (ρ·A below the smallest mass per length) is a rejected sample, not a
/// panic: density N(1000, 50) kg/m³ on A = 1.1e-8 m² gives ρA < 1e-5 kg/m
/// for ρ < 909.09, i.e. with probability Φ(−1.818) = 0.0345.
#[tokio::test]
async fn a_failed_draw_is_a_rejected_sample() {
    let (app, _) = app();
    let body = json!({
        "cable": {"density_kg_m3": 1000.0, "area_m2": 1.1e-8},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
        "rates_m_s": [5.0, 10.0],
        "uncertainty": {"samples": 400, "seed": 3, "inputs": [
            {"field": "cable.density_kg_m3", "distribution": "normal", "mean": 1000.0, "std_dev": 50.0}
        ]}
    });
    let (status, ans) = post(&app, "/api/v1/bands", &body).await;
    assert_eq!(status, StatusCode::OK, "{ans}");
    let rejected = &ans["rejected_samples"][0];
    assert_eq!(rejected["field"], "cable.density_kg_m3", "{ans}");
    let count = rejected["count"].as_f64().unwrap();
    let (n, p) = (400.0, 0.0345);
    let sigma = (n * p * (1.0 - p) as f64).sqrt();
    assert!(
        (count - n * p).abs() < 5.0 * sigma,
        "{count} rejected, expected {} ± {}",
        n * p,
        5.0 * sigma
    );
    assert_eq!(
        ans["valid_samples"].as_f64().unwrap() + count,
        400.0,
        "{ans}"
    );
}
