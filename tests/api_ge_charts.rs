//! Routes of the GE chart (`POST /api/v1/charts` with
//! `model.kind = geometrically_exact`) and the base-excitation frequency
//! response (`POST /api/v1/frequency-response` with `excitation = base`),
//! synchronous and as jobs: answers equal the contract's, bad input is a
//! 4xx naming the field.

use axum::http::StatusCode;
use serde_json::{Value, json};
use tetherplan::contract::ge_charts::{self, GeBaseFrequencyResponseRequest, GeChartRequest};
use tetherplan::contract::run::NoProgress;
use tetherplan::jobs::store::JobStatus;
use tetherplan::jobs::try_execute_next;
use tetherplan::numerics::parallel::Parallelism;

mod common;
use common::{app, error, get, post_text as post};

/// Table 7.1 cable and aerostat, fast rates so each point is short.
fn ge_chart_body(count: usize) -> Value {
    json!({
        "cable": {"density_kg_m3": 7800.0, "area_m2": 1e-5},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
        "initial_length_m": 1.0,
        "model": {"kind": "geometrically_exact", "elements": 10, "bending_stiffness_n_m2": 1000.0, "inertia_ratio": 1.0},
        "stiffness_ratios": [1e4, 1e5],
        "rates_m_s": {"min": 90.0, "max": 110.0, "count": count}
    })
}

/// The bare cantilever of ch. 8 (E* = 5), 3 frequencies, t̄ = 20.
fn base_body() -> Value {
    let scale = (0.078f64 / 1000.0).sqrt();
    json!({
        "excitation": "base",
        "cable": {"mass_per_length_kg_m": 0.078},
        "model": {"kind": "geometrically_exact", "elements": 10, "bending_stiffness_n_m2": 1000.0,
                  "stiffness_ratio": 5.0, "inertia_ratio": 1.0},
        "amplitude_m": 1e-3,
        "frequencies_rad_s": {"min": 1.0 / scale, "max": 3.5 / scale, "count": 3},
        "duration_s": 20.0 * scale,
        "time_step_s": 0.05 * scale,
        "profile": {"kind": "constant_rate", "rate_m_s": 0.005 / scale}
    })
}

/// A request as the route sees it (parsed from the JSON text).
fn from_text<T: serde::de::DeserializeOwned>(body: &Value) -> T {
    serde_json::from_slice(&serde_json::to_vec(body).unwrap()).unwrap()
}

/// An answer as the route writes it (serialised, parsed back).
fn as_text_value(v: &impl serde::Serialize) -> Value {
    serde_json::from_str(&serde_json::to_string(v).unwrap()).unwrap()
}

#[tokio::test]
async fn ge_chart_answers_like_the_contract_and_as_a_job() {
    let (app, queue) = app();
    let body = ge_chart_body(3);
    let (status, text) = post(&app, "/api/v1/charts", &body).await;
    assert_eq!(status, StatusCode::OK, "{text}");
    let req: GeChartRequest = from_text(&body);
    let direct = ge_charts::ge_chart(&req, Parallelism::Serial, &NoProgress).unwrap();
    let answer: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(answer, as_text_value(&direct));
    assert_eq!(answer["series"].as_array().unwrap().len(), 2);
    assert_eq!(answer["series"][1]["stiffness_ratio"], 1e5);
    // 110 m/s is just below the GE threshold (117 m/s): unstable within seconds
    let last = &answer["series"][1]["points"][2];
    assert_eq!(last["onset"], "during");
    assert!(last["critical_time_s"].as_f64().unwrap() < 3.0);

    // more than 8 points: 422 too_large, then as a job with progress
    let big = ge_chart_body(5);
    let (status, text) = post(&app, "/api/v1/charts", &big).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY);
    assert_eq!(
        error(&text),
        ("too_large".into(), Some("rates_m_s.count".into()))
    );
    let (status, text) = post(
        &app,
        "/api/v1/jobs",
        &json!({"kind": "chart", "request": big}),
    )
    .await;
    assert_eq!(status, StatusCode::ACCEPTED, "{text}");
    let id = serde_json::from_str::<Value>(&text).unwrap()["id"]
        .as_i64()
        .unwrap();
    let ran = try_execute_next(&queue).unwrap().unwrap();
    assert_eq!((ran.id, ran.status), (id, JobStatus::Done));
    let job = get(&app, &format!("/api/v1/jobs/{id}")).await;
    assert_eq!(job["progress"], 1.0);
    let req: GeChartRequest = from_text(&big);
    let direct = ge_charts::ge_chart(&req, Parallelism::Serial, &NoProgress).unwrap();
    assert_eq!(job["result"], as_text_value(&direct));
}

#[tokio::test]
async fn ge_bad_input_names_the_field() {
    let (app, _) = app();
    let cases = [
        (
            json!({"stiffness_ratios": [1e5, -1.0]}),
            "stiffness_ratios[1]",
        ),
        (
            json!({"model": {"kind": "geometrically_exact", "elements": 500, "bending_stiffness_n_m2": 1000.0}}),
            "model.elements",
        ),
        (
            json!({"perturbation": {"forces_n": [0.0, -5.0]}}),
            "perturbation.forces_n[1]",
        ),
        (
            json!({"perturbation": {"forces_n": [100.0], "ramp_s": 1.0, "hold_s": 0.5}}),
            "perturbation.hold_s",
        ),
        (
            json!({"wind": {"flow": {"kind": "tabulated", "points": []}, "force_model": {"kind": "thesis"}}}),
            "wind.flow.points",
        ),
        (
            json!({"numerics": {"time_step_s": 0.0}}),
            "numerics.time_step_s",
        ),
        (json!({"stiffness_ratios": "many"}), "stiffness_ratios"),
    ];
    for (patch, field) in cases {
        let mut body = ge_chart_body(2);
        for (k, v) in patch.as_object().unwrap() {
            body[k] = v.clone();
        }
        let (status, text) = post(&app, "/api/v1/charts", &body).await;
        assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{field}: {text}");
        assert_eq!(error(&text).1.as_deref(), Some(field), "{text}");
    }
    let mut body = base_body();
    body["excitation"] = json!("platform");
    let (status, text) = post(&app, "/api/v1/frequency-response", &body).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{text}");
    assert_eq!(error(&text).1.as_deref(), Some("excitation"));
    let mut body = base_body();
    body["amplitude_m"] = json!(-1.0);
    let (status, text) = post(&app, "/api/v1/frequency-response", &body).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{text}");
    assert_eq!(error(&text).1.as_deref(), Some("amplitude_m"));
}

#[tokio::test]
async fn base_excitation_answers_like_the_contract_and_as_a_job() {
    let (app, queue) = app();
    let body = base_body();
    let (status, text) = post(&app, "/api/v1/frequency-response", &body).await;
    assert_eq!(status, StatusCode::OK, "{text}");
    let req: GeBaseFrequencyResponseRequest = from_text(&body);
    let direct =
        ge_charts::ge_base_frequency_response(&req, Parallelism::Serial, &NoProgress).unwrap();
    let answer: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(answer, as_text_value(&direct));
    assert_eq!(answer["points"].as_array().unwrap().len(), 3);
    assert!((answer["rate_nondim"].as_f64().unwrap() - 0.005).abs() < 1e-12);
    let bands = answer["reduced_model_bands"].as_array().unwrap();
    assert_eq!(bands.len(), 2);
    assert!(bands[0]["low_nondim"].as_f64().unwrap() < bands[0]["high_nondim"].as_f64().unwrap());
    assert_eq!(answer["reference"]["gain_db"], 0.0);

    let (status, text) = post(
        &app,
        "/api/v1/jobs",
        &json!({"kind": "frequency_response", "request": body}),
    )
    .await;
    assert_eq!(status, StatusCode::ACCEPTED, "{text}");
    let ran = try_execute_next(&queue).unwrap().unwrap();
    assert_eq!(ran.status, JobStatus::Done);
    let job = get(&app, &format!("/api/v1/jobs/{}", ran.id)).await;
    assert_eq!(job["result"], answer);
}
