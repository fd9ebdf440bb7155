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
    body["wind"] = json!({"flow": {"kind": "uniform", "speed_m_s": 5.0}});
    body["aerostat"]["drag_coefficient_nondim"] = json!(-1.0);
    let (status, r) = post(&body).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{r}");
    assert_eq!(
        r["error"]["field"], "aerostat.drag_coefficient_nondim",
        "{r}"
    );

    // The plan's old names are refused naming their new place (SPEC §9).
    let mut body = example();
    body["wind"] =
        json!({"flow": {"kind": "uniform", "speed_m_s": 5.0}, "cable_diameter_m": 0.006});
    let (status, r) = post(&body).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{r}");
    assert_eq!(r["error"]["field"], "wind.cable_diameter_m", "{r}");
    assert_eq!(
        r["error"]["message"], "wind.cable_diameter_m: moved to cable.diameter_m",
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
    body["wind"] = json!({"flow": {"kind": "uniform", "speed_m_s": 3.0}});
    body["aerostat"]["drag_coefficient_nondim"] = json!(0.47);
    body["aerostat"]["reference_area_m2"] = json!(3.0);
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

/// The issue-20 scenario: to 1000 m altitude in a uniform 6 m/s wind
/// (0.078 kg/m, F = 1000 N, m = 10 kg, C_D 0.3 on 20 m², 6 mm tether).
fn windy(target_m: f64) -> Value {
    json!({
        "cable": {"mass_per_length_kg_m": 0.078, "diameter_m": 0.006},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0,
                     "drag_coefficient_nondim": 0.3, "reference_area_m2": 20.0},
        "wind": {"flow": {"kind": "uniform", "speed_m_s": 6.0}},
        "winch": {"max_rate_m_s": 40.0, "max_acceleration_m_s2": 2.0},
        "target_elevation_m": target_m,
        "samples": 41
    })
}

#[tokio::test]
async fn the_wind_blows_a_1000_m_plan_to_no_go_and_900_m_flies() {
    let (status, r) = post(&windy(1000.0)).await;
    assert_eq!(status, StatusCode::OK, "{r}");
    assert_eq!(r["go"], false, "{}", r["reason"]);
    assert_eq!(r["binding_limit"], "wind_blowdown");
    // The highest altitude in this wind with full buoyancy (issue 20: 977.9 m).
    let top = r["wind"]["reachable_altitude_m"].as_f64().unwrap();
    assert!((top - 977.9).abs() < 0.05, "{top}");
    assert_eq!(r["wind"]["target_length_m"], Value::Null);
    // No breaking strength: the answer says the tension is not checked, and
    // still reports the tension at the end (the top of the tether, at rest).
    assert_eq!(r["tension_checked"], false);
    assert!(
        r["reason"]
            .as_str()
            .unwrap()
            .contains("tension NOT checked")
    );
    let peak = r["limits"]["peak_tension_n"].as_f64().unwrap();
    assert!(peak > 1000.0 && peak < 1100.0, "{peak}");
    assert_eq!(r["limits"]["min_safety_factor_nondim"], Value::Null);

    let mut body = windy(900.0);
    body["cable"]["breaking_strength_n"] = json!(30000.0);
    let (status, r) = post(&body).await;
    assert_eq!(status, StatusCode::OK, "{r}");
    assert_eq!(r["go"], true, "{}", r["reason"]);
    assert_eq!(r["tension_checked"], true);
    let w = &r["wind"];
    let length = w["target_length_m"].as_f64().unwrap();
    let angle = w["blowdown_angle_deg"].as_f64().unwrap();
    assert!(length > 900.0, "{length}");
    // The winch–aerostat line: cos(angle) = altitude / straight distance.
    let down = w["target_downwind_m"].as_f64().unwrap();
    assert!(
        (angle - down.atan2(900.0).to_degrees()).abs() < 1e-6,
        "{angle} {down}"
    );
    assert!(angle > 5.0 && angle < 60.0, "{angle}");
    let peak = r["limits"]["peak_tension_n"].as_f64().unwrap();
    let sf = r["limits"]["min_safety_factor_nondim"].as_f64().unwrap();
    assert!((sf - 30000.0 / peak).abs() < 1e-9 * sf, "{sf} {peak}");
    // The schedule ends at the tether length the altitude needs.
    let last = r["schedule"].as_array().unwrap().last().unwrap().clone();
    assert!((last["length_m"].as_f64().unwrap() - length).abs() < 1e-6);
    assert!(
        (last["altitude_m"].as_f64().unwrap() - 900.0).abs() < 0.01,
        "{last}"
    );

    // In wind the drag data are required, each refused naming its field.
    let mut body = windy(900.0);
    body["aerostat"]
        .as_object_mut()
        .unwrap()
        .remove("drag_coefficient_nondim");
    let (status, r) = post(&body).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{r}");
    assert_eq!(r["error"]["field"], "aerostat.drag_coefficient_nondim");
    let mut body = windy(900.0);
    body["cable"].as_object_mut().unwrap().remove("diameter_m");
    let (status, r) = post(&body).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{r}");
    assert_eq!(r["error"]["field"], "cable.diameter_m");
}
