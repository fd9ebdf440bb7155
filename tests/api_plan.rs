//! `POST /api/v1/plan` and `tetherplan plan`: the documented example posts
//! as is, the route answers what the contract answers, unknown fields and
//! bad values are refused with their field path, and the CLI prints the
//! same plan.

use std::io::Write;
use std::process::{Command, Stdio};
use std::sync::Arc;

use axum::http::StatusCode;
use serde_json::{Value, json};
use tetherplan::config::Limits;
use tetherplan::jobs::JobQueue;

mod common;
use common::send;

fn app() -> axum::Router {
    app_and_queue().0
}

fn app_and_queue() -> (axum::Router, Arc<JobQueue>) {
    common::app_with(1, Limits::default())
}

async fn post(body: &Value) -> (StatusCode, Value) {
    common::post(&app(), "/api/v1/plan", body).await
}

/// The request example of the OpenAPI document.
fn example() -> Value {
    let doc: Value = serde_json::from_str(&tetherplan::api::openapi::openapi_json()).unwrap();
    doc["components"]["schemas"]["PlanRequest"]["example"].clone()
}

#[tokio::test]
async fn the_documented_example_succeeds_as_is() {
    let body = example();
    assert!(body.is_object(), "PlanRequest has an example");
    let (status, r) = post(&body).await;
    assert_eq!(status, StatusCode::OK, "{r}");
    assert_eq!(r["feasible"], true);
    assert_eq!(r["go"], true, "{}", r["reason"]);
    let d = r["duration_s"].as_f64().unwrap();
    assert!((d - 49.975).abs() < 0.01, "{d}");
    // Every input recorded, defaults filled in.
    assert_eq!(r["inputs"]["lift_reserve_nondim"], 0.05);
    assert_eq!(r["inputs"]["samples"], 201);
    assert!(r["schedule"].as_array().unwrap().len() >= 201);
    let h = &r["haul_down"];
    // 5 → 15 m/s over an hour: 12 m/s at 2520 s.
    assert!((h["wind_exceeds_limit_at_s"].as_f64().unwrap() - 2520.0).abs() < 1e-6);
    assert_eq!(h["go"], true);
}

#[tokio::test]
async fn unknown_fields_and_bad_values_name_their_path() {
    let mut body = example();
    body["winch"]["max_jerk_m_s3"] = json!(0.0);
    let (status, r) = post(&body).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{r}");
    assert_eq!(r["error"]["field"], "winch.max_jerk_m_s3", "{r}");

    let mut body = example();
    body["wind"] = json!({"flow": {"kind": "uniform", "speed_m_s": 5.0}, "cable_diameter_m": 0.006,
        "aerostat_drag_coefficient_nondim": -1.0, "aerostat_reference_area_m2": 20.0});
    let (status, r) = post(&body).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{r}");
    assert_eq!(
        r["error"]["field"], "wind.aerostat_drag_coefficient_nondim",
        "{r}"
    );

    let mut body = example();
    body["winch"]["max_jerk"] = json!(1.0);
    let (status, r) = post(&body).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{r}");
    assert_eq!(r["error"]["field"], "winch.max_jerk", "{r}");
    assert!(r["error"]["message"].as_str().unwrap().contains("max_jerk"));

    let mut body = example();
    body["lift_reserve_nondim"] = json!(1.5);
    let (status, r) = post(&body).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY);
    assert_eq!(r["error"]["field"], "lift_reserve_nondim");

    let mut body = example();
    body["haul_down"]["forecast"][1]["time_s"] = json!(0.0);
    let (status, r) = post(&body).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY);
    assert_eq!(r["error"]["field"], "haul_down.forecast[1].time_s");

    let mut body = example();
    body["target_elevation_m"] = json!(1.0);
    let (status, r) = post(&body).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY);
    assert_eq!(r["error"]["field"], "target_elevation_m");

    let mut body = example();
    body["surprise"] = json!(true);
    let (status, r) = post(&body).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(r["error"]["message"].as_str().unwrap().contains("surprise"));
}

/// `POST /api/v1/jobs` with `kind: plan` answers what `POST /api/v1/plan`
/// answers (all but the computation time), with a jerk limit and wind.
#[tokio::test]
async fn a_plan_job_answers_what_the_route_answers() {
    let (app, queue) = app_and_queue();
    let mut body = example();
    body["winch"]["max_jerk_m_s3"] = json!(1.0);
    body["wind"] = json!({"flow": {"kind": "uniform", "speed_m_s": 3.0}, "cable_diameter_m": 0.006,
        "aerostat_drag_coefficient_nondim": 0.47, "aerostat_reference_area_m2": 3.0});
    body["samples"] = json!(41);
    let (status, sync) = post(&body).await;
    assert_eq!(status, StatusCode::OK, "{sync}");
    assert_eq!(sync["feasible"], true, "{}", sync["reason"]);
    let (status, job) = send(
        &app,
        "POST",
        "/api/v1/jobs",
        Some(&json!({"kind": "plan", "request": body})),
    )
    .await;
    assert_eq!(status, StatusCode::ACCEPTED, "{job}");
    let id = job["id"].as_i64().unwrap();
    let q = queue.clone();
    tokio::task::spawn_blocking(move || tetherplan::jobs::try_execute_next(&q).unwrap().unwrap())
        .await
        .unwrap();
    let (status, view) = send(&app, "GET", &format!("/api/v1/jobs/{id}"), None).await;
    assert_eq!(status, StatusCode::OK);
    assert_eq!(view["status"], "done", "{view}");
    assert_eq!(view["kind"], "plan");
    assert_eq!(view["progress"].as_f64(), Some(1.0));
    let mut result = view["result"].clone();
    let mut sync = sync;
    for v in [&mut result, &mut sync] {
        v.as_object_mut().unwrap().remove("compute_time_s");
    }
    assert_eq!(result, sync);
    // A bad plan is refused at submission with its path.
    let mut bad = example();
    bad["winch"]["max_jerk_m_s3"] = json!(-1.0);
    let (status, r) = send(
        &app,
        "POST",
        "/api/v1/jobs",
        Some(&json!({"kind": "plan", "request": bad})),
    )
    .await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{r}");
    assert_eq!(r["error"]["field"], "request.winch.max_jerk_m_s3");
}

#[tokio::test]
async fn infeasible_is_an_answer_not_an_error() {
    let mut body = example();
    body["target_elevation_m"] = json!(1290.0);
    let (status, r) = post(&body).await;
    assert_eq!(status, StatusCode::OK);
    assert_eq!(r["feasible"], false);
    assert_eq!(r["binding_limit"], "static_lift_limit");
    assert!(r["reason"].as_str().unwrap().starts_with("no-go"));
}

#[test]
fn cli_prints_the_same_plan() {
    let mut child = Command::new(env!("CARGO_BIN_EXE_tetherplan"))
        .arg("plan")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(example().to_string().as_bytes())
        .unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success());
    let r: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(r["feasible"], true);
    assert!((r["duration_s"].as_f64().unwrap() - 49.975).abs() < 0.01);
}
