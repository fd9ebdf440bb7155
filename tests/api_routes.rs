//! Route tests: the router driven with `tower::ServiceExt::oneshot`, an
//! in-memory job store, and the worker step function to drain the queue.

use std::sync::Arc;
use std::time::{Duration, Instant};

use axum::Router;
use axum::body::Body;
use axum::http::{Request, StatusCode, header};
use serde_json::{Value, json};
use tetherplan::api::{self};
use tetherplan::config::Limits;
use tetherplan::contract::dto::*;
use tetherplan::contract::run::{self, NoProgress};
use tetherplan::contract::{self};
use tetherplan::jobs::store::{JobBackend, JobStatus, JobStore};
use tetherplan::jobs::{JobQueue, try_execute_next};
use tetherplan::numerics::parallel::Parallelism;

mod common;
use common::{Answer, with};

/// Thesis Table A1: steel cable, F = 1000 N, m = 10 kg, L0 = 1 m.
fn system(elements: usize) -> Value {
    json!({
        "cable": {"density_kg_m3": 7800.0, "area_m2": 1e-5},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
        "initial_length_m": 1.0,
        "gravity_m_s2": 9.81,
        "model": {"kind": "linear_string", "elements": elements}
    })
}

fn critical_body() -> Value {
    with(
        system(50),
        json!({"profile": {"kind": "constant_rate", "rate_m_s": 10.0}}),
    )
}

fn chart_body(count: usize, elements: usize) -> Value {
    with(
        system(elements),
        json!({"rates_m_s": {"min": 1.0, "max": 120.0, "count": count}, "net_buoyancies_n": [1000.0, 1500.0]}),
    )
}

fn app_with(limits: Limits) -> (Router, Arc<JobQueue>) {
    common::app_with(2, limits)
}

fn app() -> (Router, Arc<JobQueue>) {
    app_with(Limits::default())
}

async fn send(
    app: &Router,
    method: &str,
    uri: &str,
    content_type: Option<&str>,
    body: Vec<u8>,
) -> Answer {
    let mut req = Request::builder().method(method).uri(uri);
    if let Some(ct) = content_type {
        req = req.header(header::CONTENT_TYPE, ct);
    }
    common::request(app, req, Body::from(body)).await
}

async fn post(app: &Router, uri: &str, body: &Value) -> Answer {
    send(
        app,
        "POST",
        uri,
        Some("application/json"),
        serde_json::to_vec(body).unwrap(),
    )
    .await
}

async fn get(app: &Router, uri: &str) -> Answer {
    send(app, "GET", uri, None, vec![]).await
}

async fn delete(app: &Router, uri: &str) -> Answer {
    send(app, "DELETE", uri, None, vec![]).await
}

/// `text` (an answer) and `direct` (the core's answer) are the same JSON.
/// Both go through the same text → value parse, so 17-digit floats compare
/// exactly.
fn assert_same_json(text: &str, direct: &impl serde::Serialize) {
    let a: Value = serde_json::from_str(text).unwrap();
    let b: Value = serde_json::from_str(&serde_json::to_string(direct).unwrap()).unwrap();
    assert!(
        a == b,
        "answers differ:\n{}\n{}",
        &text[..text.len().min(400)],
        &serde_json::to_string(direct).unwrap()[..400.min(text.len())]
    );
}

/// The verbatim text of a job's `result`.
fn result_text(job_text: &str) -> String {
    #[derive(serde::Deserialize)]
    struct Job<'a> {
        #[serde(borrow)]
        result: &'a serde_json::value::RawValue,
    }
    serde_json::from_str::<Job>(job_text)
        .unwrap()
        .result
        .get()
        .to_string()
}

/// The verbatim texts of the item results of a batch job.
fn batch_item_texts(job_text: &str) -> Vec<String> {
    #[derive(serde::Deserialize)]
    struct Item<'a> {
        #[serde(borrow)]
        result: &'a serde_json::value::RawValue,
    }
    #[derive(serde::Deserialize)]
    struct Items<'a> {
        #[serde(borrow)]
        items: Vec<Item<'a>>,
    }
    #[derive(serde::Deserialize)]
    struct Job<'a> {
        #[serde(borrow)]
        result: Items<'a>,
    }
    serde_json::from_str::<Job>(job_text)
        .unwrap()
        .result
        .items
        .iter()
        .map(|i| i.result.get().to_string())
        .collect()
}

fn parse<T: contract::system::input::SystemRequest>(v: &Value) -> T {
    contract::parse(&serde_json::to_vec(v).unwrap()).unwrap()
}

#[tokio::test]
async fn healthz_answers() {
    let (app, _) = app();
    let a = get(&app, "/healthz").await;
    assert_eq!(a.status, StatusCode::OK);
    assert_eq!(a.json()["status"], "ok");
}

#[tokio::test]
async fn critical_matches_the_thesis() {
    let (app, _) = app();
    let a = post(&app, "/api/v1/critical", &critical_body()).await;
    assert_eq!(a.status, StatusCode::OK, "{}", a.text);
    let r: CriticalResponse = serde_json::from_str(&a.text).unwrap();
    let h = r.max_elevation_m.unwrap();
    assert!((h - 1310.0).abs() < 0.5, "h* = {h}");
    let closed = r.closed_form_elevation_m.unwrap();
    assert!((closed - 1296.69).abs() < 0.01, "closed form {closed}");
    assert_eq!(r.onset, "during");
    assert_same_json(&a.text, &run::critical(&parse(&critical_body())).unwrap());
}

#[tokio::test]
async fn stability_safe_rate_and_chart_answer_like_the_core() {
    let (app, _) = app();
    let st = with(
        system(50),
        json!({"state": {"length_m": 500.0, "rate_m_s": 10.0}, "modes": 4}),
    );
    let a = post(&app, "/api/v1/stability", &st).await;
    assert_eq!(a.status, StatusCode::OK, "{}", a.text);
    let r: StabilityResponse = serde_json::from_str(&a.text).unwrap();
    assert!(r.stable, "500 m at 10 m/s is below h* = 1310 m");
    assert_eq!(r.eigenvalues.len(), 4);
    assert!(r.eigenvalues.windows(2).all(|w| w[0].im_1_s <= w[1].im_1_s));
    assert_same_json(&a.text, &run::stability(&parse(&st)).unwrap());

    let sr = with(system(50), json!({"target_elevation_m": 1200.0}));
    let a = post(&app, "/api/v1/safe-rate", &sr).await;
    assert_eq!(a.status, StatusCode::OK, "{}", a.text);
    let r: SafeRateResponse = serde_json::from_str(&a.text).unwrap();
    let v = r.max_rate_m_s.unwrap();
    // Continuum: sqrt(F/ρA − g H) = sqrt(12820.5 − 11772) ≈ 32.4 m/s.
    let closed = r.closed_form_rate_m_s.unwrap();
    assert!((closed - 32.38).abs() < 0.05, "closed form {closed}");
    assert!(v > 0.0 && v < r.groups.wave_speed_m_s, "v = {v}");
    assert_same_json(&a.text, &run::safe_rate(&parse(&sr)).unwrap());

    let ch = chart_body(40, 50);
    let a = post(&app, "/api/v1/charts", &ch).await;
    assert_eq!(a.status, StatusCode::OK, "{}", a.text);
    let r: ChartResponse = serde_json::from_str(&a.text).unwrap();
    assert_eq!(r.series.len(), 2);
    assert_eq!(r.series[0].points.len(), 40);
    assert_same_json(
        &a.text,
        &run::chart(&parse(&ch), Parallelism::Serial, &NoProgress).unwrap(),
    );
}

/// (route, body, status, field named by the error).
fn bad_inputs() -> Vec<(&'static str, Vec<u8>, StatusCode, Option<&'static str>)> {
    let v = |x: Value| serde_json::to_vec(&x).unwrap();
    let crit = critical_body();
    let unprocessable = StatusCode::UNPROCESSABLE_ENTITY;
    let mut cases = vec![];
    for route in [
        "/api/v1/stability",
        "/api/v1/critical",
        "/api/v1/safe-rate",
        "/api/v1/charts",
        "/api/v1/jobs",
    ] {
        cases.push((
            route,
            b"{\"cable\": ".to_vec(),
            StatusCode::BAD_REQUEST,
            Some("body"),
        ));
        cases.push((
            route,
            b"not json".to_vec(),
            StatusCode::BAD_REQUEST,
            Some("body"),
        ));
        cases.push((
            route,
            b"{\"x\": NaN}".to_vec(),
            StatusCode::BAD_REQUEST,
            Some("body"),
        ));
        cases.push((
            route,
            b"{\"x\": 1e999}".to_vec(),
            StatusCode::BAD_REQUEST,
            Some("body"),
        ));
        cases.push((route, b"".to_vec(), StatusCode::BAD_REQUEST, Some("body")));
        cases.push((route, v(json!([1, 2])), unprocessable, None));
        cases.push((route, v(json!(null)), unprocessable, None));
    }
    let sys_cases: Vec<(Value, &str)> = vec![
        (json!({"aerostat": {"net_buoyancy_n": 1000.0}}), "cable"),
        (
            json!({"cable": {"mass_per_length_kg_m": 0.078}}),
            "aerostat",
        ),
        (
            with(
                system(50),
                json!({"cable": {"mass_per_length_kg_m": "heavy"}}),
            ),
            "cable.mass_per_length_kg_m",
        ),
        (
            with(
                system(50),
                json!({"cable": {"mass_per_length_kg_m": -0.078}}),
            ),
            "cable.mass_per_length_kg_m",
        ),
        (
            with(system(50), json!({"cable": {}})),
            "cable.mass_per_length_kg_m",
        ),
        (
            with(system(50), json!({"aerostat": {"net_buoyancy_n": -1000.0}})),
            "aerostat.net_buoyancy_n",
        ),
        (
            with(system(50), json!({"aerostat": {"net_buoyancy_n": "NaN"}})),
            "aerostat.net_buoyancy_n",
        ),
        (
            with(
                system(50),
                json!({"aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": -1.0}}),
            ),
            "aerostat.mass_kg",
        ),
        (
            with(system(50), json!({"initial_length_m": 0.0})),
            "initial_length_m",
        ),
        (
            with(system(50), json!({"gravity_m_s2": -9.81})),
            "gravity_m_s2",
        ),
        (system(0), "model.elements"),
        (system(1_000_000), "model.elements"),
        (
            with(system(50), json!({"model": {"elements": -3}})),
            "model.elements",
        ),
        (
            with(system(50), json!({"model": {"kind": "rubber_band"}})),
            "model.kind",
        ),
    ];
    let params: [(&str, Value); 4] = [
        ("/api/v1/stability", json!({"state": {"length_m": 500.0}})),
        (
            "/api/v1/critical",
            json!({"profile": {"kind": "constant_rate", "rate_m_s": 10.0}}),
        ),
        ("/api/v1/safe-rate", json!({"target_elevation_m": 1200.0})),
        (
            "/api/v1/charts",
            json!({"rates_m_s": {"min": 1.0, "max": 100.0, "count": 10}}),
        ),
    ];
    for (route, p) in &params {
        for (sys, field) in &sys_cases {
            cases.push((
                route,
                v(with(sys.clone(), p.clone())),
                unprocessable,
                Some(field),
            ));
        }
    }
    let s = || system(50);
    let specific: Vec<(&str, Value, &str)> = vec![
        ("/api/v1/stability", s(), "state"),
        (
            "/api/v1/stability",
            with(s(), json!({"state": {"length_m": -5.0}})),
            "state.length_m",
        ),
        (
            "/api/v1/stability",
            with(
                s(),
                json!({"state": {"length_m": 500.0, "rate_m_s": "fast"}}),
            ),
            "state.rate_m_s",
        ),
        (
            "/api/v1/stability",
            with(s(), json!({"state": {"length_m": 500.0}, "modes": 0})),
            "modes",
        ),
        (
            "/api/v1/stability",
            with(
                s(),
                json!({"state": {"length_m": 500.0}, "modes": 1_000_000}),
            ),
            "modes",
        ),
        (
            "/api/v1/stability",
            with(system(1500), json!({"state": {"length_m": 500.0}})),
            "model.elements",
        ),
        ("/api/v1/critical", s(), "profile"),
        (
            "/api/v1/critical",
            with(s(), json!({"profile": {"kind": "warp", "rate_m_s": 1.0}})),
            "profile.kind",
        ),
        (
            "/api/v1/critical",
            with(s(), json!({"profile": {"kind": "constant_rate"}})),
            "profile.rate_m_s",
        ),
        (
            "/api/v1/critical",
            with(
                s(),
                json!({"profile": {"kind": "constant_rate", "rate_m_s": 1e9}}),
            ),
            "profile.rate_m_s",
        ),
        (
            "/api/v1/critical",
            with(
                s(),
                json!({"profile": {"kind": "constant_acceleration", "acceleration_m_s2": 0.0}}),
            ),
            "profile.acceleration_m_s2",
        ),
        (
            "/api/v1/critical",
            with(
                system(1500),
                json!({"profile": {"kind": "constant_acceleration", "acceleration_m_s2": 0.5}}),
            ),
            "model.elements",
        ),
        ("/api/v1/safe-rate", s(), "target_elevation_m"),
        (
            "/api/v1/safe-rate",
            with(s(), json!({"target_elevation_m": -1.0})),
            "target_elevation_m",
        ),
        (
            "/api/v1/safe-rate",
            with(s(), json!({"target_elevation_m": [1]})),
            "target_elevation_m",
        ),
        ("/api/v1/charts", s(), "rates_m_s"),
        (
            "/api/v1/charts",
            with(
                s(),
                json!({"rates_m_s": {"min": 1.0, "max": 100.0, "count": 0}}),
            ),
            "rates_m_s.count",
        ),
        (
            "/api/v1/charts",
            with(
                s(),
                json!({"rates_m_s": {"min": -1.0, "max": 100.0, "count": 10}}),
            ),
            "rates_m_s.min",
        ),
        (
            "/api/v1/charts",
            with(
                s(),
                json!({"rates_m_s": {"min": 10.0, "max": 1.0, "count": 10}}),
            ),
            "rates_m_s.max",
        ),
        (
            "/api/v1/charts",
            with(
                s(),
                json!({"rates_m_s": {"min": 1.0, "max": 100.0, "count": 1_000_000}}),
            ),
            "rates_m_s.count",
        ),
        (
            "/api/v1/charts",
            with(
                s(),
                json!({"rates_m_s": {"min": 1.0, "max": 100.0, "count": 10_000_000_000u64}}),
            ),
            "rates_m_s.count",
        ),
        (
            "/api/v1/charts",
            with(
                system(2000),
                json!({"rates_m_s": {"min": 1.0, "max": 100.0, "count": 5000}}),
            ),
            "rates_m_s.count",
        ),
        (
            "/api/v1/charts",
            with(
                s(),
                json!({"rates_m_s": {"min": 1.0, "max": 100.0, "count": 10}, "net_buoyancies_n": [1000.0, -5.0]}),
            ),
            "net_buoyancies_n[1]",
        ),
        (
            "/api/v1/charts",
            with(
                s(),
                json!({"rates_m_s": {"min": 1.0, "max": 100.0, "count": 100}, "net_buoyancies_n": vec![1000.0; 50_000]}),
            ),
            "rates_m_s.count",
        ),
        ("/api/v1/jobs", json!({"request": crit.clone()}), "kind"),
        ("/api/v1/jobs", json!({"kind": "critical"}), "request"),
        (
            "/api/v1/jobs",
            json!({"kind": "teleport", "request": crit.clone()}),
            "kind",
        ),
        (
            "/api/v1/jobs",
            json!({"kind": "critical", "request": s()}),
            "request.profile",
        ),
        (
            "/api/v1/jobs",
            json!({"kind": "critical", "request": with(crit.clone(), json!({"cable": {"mass_per_length_kg_m": -1.0}}))}),
            "request.cable.mass_per_length_kg_m",
        ),
        (
            "/api/v1/jobs",
            json!({"kind": "chart", "request": with(s(), json!({"rates_m_s": {"min": 1.0, "max": 100.0, "count": 2_000_000}}))}),
            "request.rates_m_s.count",
        ),
        (
            "/api/v1/jobs",
            json!({"kind": "safe_rate", "request": with(s(), json!({"target_elevation_m": 0.5}))}),
            "request.target_elevation_m",
        ),
        (
            "/api/v1/jobs",
            json!({"kind": "stability", "request": with(s(), json!({"state": {"length_m": 5.0}, "modes": 0}))}),
            "request.modes",
        ),
        (
            "/api/v1/jobs",
            json!({"kind": "batch", "request": []}),
            "request",
        ),
        (
            "/api/v1/jobs",
            json!({"kind": "batch", "request": {"kind": "critical"}}),
            "request",
        ),
        (
            "/api/v1/jobs",
            json!({"kind": "batch", "request": [{"kind": "critical", "request": crit.clone()}, {"kind": "critical", "request": s()}]}),
            "request[1].request.profile",
        ),
        (
            "/api/v1/jobs",
            json!({"kind": "batch", "request": [{"kind": "batch", "request": []}]}),
            "request[0].kind",
        ),
    ];
    for (route, body, field) in specific {
        cases.push((route, v(body), unprocessable, Some(field)));
    }
    cases
}

#[tokio::test]
async fn bad_input_on_every_route_is_a_4xx_naming_the_field() {
    let (app, queue) = app();
    let mut wrong = vec![];
    for (route, body, status, field) in bad_inputs() {
        let shown = String::from_utf8_lossy(&body[..body.len().min(300)]).into_owned();
        let a = send(&app, "POST", route, Some("application/json"), body).await;
        let e = a.error();
        let field_ok = match field {
            Some(f) => {
                e.field.as_deref() == Some(f)
                    && (e.code == "malformed_json" || e.message.contains(f))
            }
            None => e.field.is_some(),
        };
        if a.status != status || !field_ok {
            wrong.push(format!(
                "{route} {shown}\n  expected {status} {field:?}, got {}: {}",
                a.status, a.text
            ));
        }
    }
    assert!(
        wrong.is_empty(),
        "{} wrong answers:\n{}",
        wrong.len(),
        wrong.join("\n")
    );
    // Nothing invalid was stored.
    assert!(queue.store.list(None, 10).unwrap().is_empty());
}

#[tokio::test]
async fn transport_errors_use_the_error_body() {
    let limits = Limits {
        max_body_bytes: 4096,
        ..Limits::default()
    };
    let (app, _) = app_with(limits);
    let big = format!("{{\"pad\": \"{}\"}}", "x".repeat(10_000));
    for route in [
        "/api/v1/stability",
        "/api/v1/critical",
        "/api/v1/safe-rate",
        "/api/v1/charts",
        "/api/v1/jobs",
    ] {
        let a = send(
            &app,
            "POST",
            route,
            Some("application/json"),
            big.clone().into_bytes(),
        )
        .await;
        assert_eq!(a.status, StatusCode::PAYLOAD_TOO_LARGE, "{route}");
        assert_eq!(a.error().code, "payload_too_large");

        let a = send(
            &app,
            "POST",
            route,
            Some("text/plain"),
            serde_json::to_vec(&critical_body()).unwrap(),
        )
        .await;
        assert_eq!(a.status, StatusCode::UNSUPPORTED_MEDIA_TYPE, "{route}");
        assert_eq!(a.error().field.as_deref(), Some("content-type"));

        let a = send(
            &app,
            "POST",
            route,
            None,
            serde_json::to_vec(&critical_body()).unwrap(),
        )
        .await;
        assert_eq!(a.status, StatusCode::UNSUPPORTED_MEDIA_TYPE, "{route}");
        a.error();
    }
    let a = get(&app, "/api/v1/critical").await;
    assert_eq!(a.status, StatusCode::METHOD_NOT_ALLOWED);
    assert_eq!(a.error().code, "method_not_allowed");
    let a = get(&app, "/api/v1/nothing-here").await;
    assert_eq!(a.status, StatusCode::NOT_FOUND);
    assert_eq!(a.error().code, "not_found");
}

#[tokio::test]
async fn too_many_solves_in_flight_is_503_with_retry_after() {
    let (app, _) = app_with(Limits {
        max_in_flight: 0,
        ..Limits::default()
    });
    let a = post(&app, "/api/v1/critical", &critical_body()).await;
    assert_eq!(a.status, StatusCode::SERVICE_UNAVAILABLE);
    assert_eq!(a.headers[header::RETRY_AFTER], "1");
    assert_eq!(a.error().code, "overloaded");
}

#[tokio::test]
async fn a_slow_solve_times_out_with_504() {
    let (app, _) = app_with(Limits {
        solve_timeout: Duration::from_millis(1),
        ..Limits::default()
    });
    let a = post(&app, "/api/v1/charts", &chart_body(10_000, 50)).await;
    assert_eq!(a.status, StatusCode::GATEWAY_TIMEOUT, "{}", a.text);
    let e = a.error();
    assert_eq!(e.code, "timeout");
    assert!(e.message.contains("/api/v1/jobs"));
}

#[tokio::test]
async fn sync_chart_limit_points_to_jobs() {
    let (app, _) = app();
    let a = post(&app, "/api/v1/charts", &chart_body(10_001, 50)).await;
    assert_eq!(a.status, StatusCode::UNPROCESSABLE_ENTITY);
    let e = a.error();
    assert_eq!(
        (e.code.as_str(), e.field.as_deref()),
        ("too_large", Some("rates_m_s.count"))
    );
    assert!(e.message.contains("POST /api/v1/jobs"), "{}", e.message);
    // 20 000 points (2 series × 10 000) is the largest synchronous chart.
    assert_eq!(
        post(&app, "/api/v1/charts", &chart_body(10_000, 50))
            .await
            .status,
        StatusCode::OK
    );
}

async fn submit(app: &Router, body: &Value) -> i64 {
    let a = post(app, "/api/v1/jobs", body).await;
    assert_eq!(a.status, StatusCode::ACCEPTED, "{}", a.text);
    let v = a.json();
    assert_eq!(v["status"], "queued");
    let id = v["id"].as_i64().unwrap();
    assert_eq!(a.headers[header::LOCATION], format!("/api/v1/jobs/{id}"));
    id
}

#[tokio::test]
async fn a_chart_job_runs_to_the_synchronous_answer() {
    let (app, queue) = app();
    let body = chart_body(3000, 50);
    let id = submit(&app, &json!({"kind": "chart", "request": body})).await;
    let v = get(&app, &format!("/api/v1/jobs/{id}")).await.json();
    assert_eq!(
        (
            v["status"].as_str(),
            v["kind"].as_str(),
            v["progress"].as_f64()
        ),
        (Some("queued"), Some("chart"), Some(0.0))
    );
    assert!(v.get("result").is_none());

    let ran = try_execute_next(&queue).unwrap().unwrap();
    assert_eq!((ran.id, ran.status), (id, JobStatus::Done));
    assert!(try_execute_next(&queue).unwrap().is_none());

    let a = get(&app, &format!("/api/v1/jobs/{id}")).await;
    let v = a.json();
    let text = result_text(&a.text);
    assert_eq!(v["status"], "done");
    assert_eq!(v["progress"], 1.0);
    assert_eq!(v["attempts"], 1);
    assert_eq!(
        text,
        serde_json::to_string(&run::chart(&parse(&body), Parallelism::Rayon, &NoProgress).unwrap())
            .unwrap(),
        "verbatim"
    );
    let listed = get(&app, "/api/v1/jobs").await.json();
    assert_eq!(listed["jobs"][0]["id"], id);
    assert!(
        listed["jobs"][0].get("result").is_none(),
        "lists carry no answers"
    );
    let done = get(&app, "/api/v1/jobs?status=done&limit=5").await.json();
    assert_eq!(done["jobs"].as_array().unwrap().len(), 1);
    let bad = get(&app, "/api/v1/jobs?status=sleeping").await;
    assert_eq!(bad.status, StatusCode::BAD_REQUEST);
    bad.error();
    for limit in ["0", "1001", "-1", "many"] {
        let bad = get(&app, &format!("/api/v1/jobs?limit={limit}")).await;
        assert_eq!(bad.status, StatusCode::BAD_REQUEST, "limit={limit}");
        assert_eq!(bad.error().code, "invalid_query");
    }
}

#[tokio::test]
async fn every_kind_and_a_batch_run_as_jobs() {
    let (app, queue) = app();
    let st = with(
        system(50),
        json!({"state": {"length_m": 500.0, "rate_m_s": 10.0}}),
    );
    let sr = with(system(50), json!({"target_elevation_m": 1200.0}));
    let ids = [
        submit(&app, &json!({"kind": "stability", "request": st})).await,
        submit(
            &app,
            &json!({"kind": "critical", "request": critical_body()}),
        )
        .await,
        submit(&app, &json!({"kind": "safe_rate", "request": sr})).await,
        submit(
            &app,
            &json!({"kind": "batch", "request": [
                {"kind": "critical", "request": critical_body()},
                {"kind": "chart", "request": chart_body(10, 50)},
            ]}),
        )
        .await,
    ];
    while try_execute_next(&queue).unwrap().is_some() {}
    let result = |v: &String| result_text(v);
    let job = |id| {
        let app = app.clone();
        async move { get(&app, &format!("/api/v1/jobs/{id}")).await.text }
    };
    let v = job(ids[0]).await;
    assert_same_json(&result(&v), &run::stability(&parse(&st)).unwrap());
    let v = job(ids[1]).await;
    assert_same_json(
        &result(&v),
        &run::critical(&parse(&critical_body())).unwrap(),
    );
    let v = job(ids[2]).await;
    assert_same_json(&result(&v), &run::safe_rate(&parse(&sr)).unwrap());
    let text = job(ids[3]).await;
    let items_text = batch_item_texts(&text);
    let v: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(v["kind"], "batch");
    let items = v["result"]["items"].as_array().unwrap();
    assert_eq!(items.len(), 2);
    assert_eq!(items[0]["kind"], "critical");
    assert!((items[0]["result"]["max_elevation_m"].as_f64().unwrap() - 1310.0).abs() < 0.5);
    assert_same_json(
        &items_text[1],
        &run::chart(
            &parse(&chart_body(10, 50)),
            Parallelism::Serial,
            &NoProgress,
        )
        .unwrap(),
    );
}

#[tokio::test]
async fn unknown_jobs_are_404_and_finished_ones_cannot_be_cancelled() {
    let (app, queue) = app();
    for uri in ["/api/v1/jobs/999", "/api/v1/jobs/abc", "/api/v1/jobs/-1"] {
        let a = get(&app, uri).await;
        assert_eq!(a.status, StatusCode::NOT_FOUND, "{uri}");
        assert_eq!(a.error().code, "not_found");
        assert_eq!(
            delete(&app, uri).await.status,
            StatusCode::NOT_FOUND,
            "{uri}"
        );
    }
    let id = submit(
        &app,
        &json!({"kind": "critical", "request": critical_body()}),
    )
    .await;
    try_execute_next(&queue).unwrap();
    let a = delete(&app, &format!("/api/v1/jobs/{id}")).await;
    assert_eq!(a.status, StatusCode::CONFLICT);
    assert_eq!(a.error().code, "conflict");
}

#[tokio::test]
async fn delete_cancels_a_queued_job() {
    let (app, queue) = app();
    let id = submit(
        &app,
        &json!({"kind": "chart", "request": chart_body(100, 50)}),
    )
    .await;
    let a = delete(&app, &format!("/api/v1/jobs/{id}")).await;
    assert_eq!(a.status, StatusCode::OK);
    let v = a.json();
    assert_eq!(v["status"], "cancelled");
    assert_eq!(v["error"]["error"]["code"], "cancelled");
    assert!(
        try_execute_next(&queue).unwrap().is_none(),
        "a cancelled job does not run"
    );
    assert_eq!(
        get(&app, &format!("/api/v1/jobs/{id}")).await.json()["status"],
        "cancelled"
    );
}

/// Waits until the job is running with some progress recorded.
fn wait_running(queue: &JobQueue, id: i64) {
    let start = Instant::now();
    loop {
        let rec = queue.store.get(id).unwrap().unwrap();
        if rec.status == JobStatus::Running && rec.progress > 0.0 {
            return;
        }
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "job {id} never showed progress: {rec:?}"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn delete_stops_a_running_job_between_chunks() {
    let (app, queue) = app();
    // 2 × 5000 points at 1000 elements: several seconds of work.
    let id = submit(
        &app,
        &json!({"kind": "chart", "request": chart_body(5000, 1000)}),
    )
    .await;
    let worker = {
        let queue = queue.clone();
        std::thread::spawn(move || try_execute_next(&queue).unwrap().unwrap())
    };
    let q = queue.clone();
    tokio::task::spawn_blocking(move || wait_running(&q, id))
        .await
        .unwrap();
    let progress = get(&app, &format!("/api/v1/jobs/{id}")).await.json()["progress"]
        .as_f64()
        .unwrap();
    assert!(
        progress > 0.0 && progress < 1.0,
        "GET shows progress: {progress}"
    );
    let cancelled_at = Instant::now();
    assert_eq!(
        delete(&app, &format!("/api/v1/jobs/{id}")).await.status,
        StatusCode::OK
    );
    let ran = tokio::task::spawn_blocking(move || worker.join().unwrap())
        .await
        .unwrap();
    assert_eq!(ran.status, JobStatus::Cancelled);
    assert!(
        cancelled_at.elapsed() < Duration::from_secs(3),
        "stopped after {:?}",
        cancelled_at.elapsed()
    );
    let v = get(&app, &format!("/api/v1/jobs/{id}")).await.json();
    assert_eq!(v["status"], "cancelled");
    assert!(v.get("result").is_none());
}

#[test]
fn shutdown_requeues_the_running_job_and_a_restart_finishes_it() {
    let dir = std::env::temp_dir().join(format!("tetherplan-requeue-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let db = dir.join("jobs.db");
    let _ = std::fs::remove_file(&db);
    let body = chart_body(5000, 1000);
    let submission = serde_json::to_vec(&json!({"kind": "chart", "request": body})).unwrap();
    let id = {
        let store = JobStore::open(&db).unwrap();
        assert_eq!(store.journal_mode().unwrap(), "wal");
        let queue = Arc::new(JobQueue::new(store, 2, Limits::default()));
        let (id, kind) = queue.submit(&submission).unwrap();
        assert_eq!(kind, "chart");
        let worker = {
            let queue = queue.clone();
            std::thread::spawn(move || try_execute_next(&queue).unwrap().unwrap())
        };
        wait_running(&queue, id);
        queue.shutdown();
        let ran = worker.join().unwrap();
        assert_eq!((ran.id, ran.status), (id, JobStatus::Queued));
        id
    };
    let queue = JobQueue::new(JobStore::open(&db).unwrap(), 2, Limits::default());
    let ran = try_execute_next(&queue).unwrap().unwrap();
    assert_eq!((ran.id, ran.status), (id, JobStatus::Done));
    let rec = queue.store.get(id).unwrap().unwrap();
    assert_eq!(rec.attempts, 2);
    let sync =
        serde_json::to_string(&run::chart(&parse(&body), Parallelism::Rayon, &NoProgress).unwrap())
            .unwrap();
    assert_eq!(rec.result.unwrap(), sync);
    let _ = std::fs::remove_dir_all(&dir);
}

/// A job left running by a dead process (here: an earlier life of this
/// one) is claimable again as soon as the store is reopened.
#[test]
fn a_job_left_running_by_a_dead_process_is_requeued_on_open() {
    let dir = std::env::temp_dir().join(format!("tetherplan-crash-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let db = dir.join("jobs.db");
    let _ = std::fs::remove_file(&db);
    let store = JobStore::open(&db).unwrap();
    let id = store.insert_simple("critical", "{}", 10).unwrap();
    assert_eq!(store.claim_next().unwrap().unwrap().id, id);
    assert_eq!(store.status(id).unwrap(), Some(JobStatus::Running));
    drop(store);
    let store = JobStore::open(&db).unwrap();
    let again = store.claim_next().unwrap().unwrap();
    assert_eq!((again.id, again.attempts), (id, 2));
    let _ = std::fs::remove_dir_all(&dir);
}

#[tokio::test]
async fn a_full_queue_is_429_with_retry_after() {
    let (app, queue) = app_with(Limits {
        max_pending_jobs: 2,
        ..Limits::default()
    });
    let job = json!({"kind": "critical", "request": critical_body()});
    submit(&app, &job).await;
    submit(&app, &job).await;
    let a = post(&app, "/api/v1/jobs", &job).await;
    assert_eq!(a.status, StatusCode::TOO_MANY_REQUESTS);
    assert_eq!(a.headers[header::RETRY_AFTER], "5");
    assert_eq!(a.error().code, "queue_full");
    assert_eq!(
        queue.store.list(None, 10).unwrap().len(),
        2,
        "the refused job is not stored"
    );
    // Finished jobs leave room.
    try_execute_next(&queue).unwrap();
    submit(&app, &job).await;
}

#[tokio::test]
async fn docs_and_openapi_are_served() {
    let (app, _) = app();
    let a = get(&app, "/openapi.json").await;
    assert_eq!(a.status, StatusCode::OK);
    assert_eq!(
        a.json(),
        serde_json::to_value(api::openapi::openapi()).unwrap()
    );
    let a = get(&app, "/docs/").await;
    assert_eq!(a.status, StatusCode::OK);
    assert!(
        a.text.contains("swagger"),
        "{}",
        &a.text[..a.text.len().min(300)]
    );
}

fn simulate_body() -> Value {
    with(
        with(system(30), json!({"initial_length_m": 100.0})),
        json!({"profile": {"kind": "constant_rate", "rate_m_s": 1.0}, "duration_s": 5.0, "samples": 20,
               "initial": {"kind": "shape", "tip_deflection_m": 0.1}}),
    )
}

fn ge_simulate_body() -> Value {
    json!({"cable": {"density_kg_m3": 7800.0, "area_m2": 1e-5},
           "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0}, "initial_length_m": 1.0,
           "model": {"kind": "geometrically_exact", "elements": 10, "bending_stiffness_n_m2": 1000.0,
                     "stiffness_ratio": 1e5, "inertia_ratio": 1.0},
           "time_step_s": 0.000883, "duration_s": 0.0883})
}

fn frequency_response_body(count: usize) -> Value {
    with(
        system(20),
        json!({"profile": {"kind": "constant_rate", "rate_m_s": 1.0}, "duration_s": 10.0, "samples": 10,
               "aero": {"radius_m": 0.5}, "wind_amplitude_m_s": 10.0,
               "frequencies_rad_s": {"min": 1.0, "max": 4.0, "count": count}}),
    )
}

#[tokio::test]
async fn simulate_answers_for_both_models_and_names_bad_fields() {
    let (app, _) = app();
    let a = post(&app, "/api/v1/simulate", &simulate_body()).await;
    assert_eq!(a.status, StatusCode::OK, "{}", a.text);
    let v: Value = serde_json::from_str(&a.text).unwrap();
    assert_eq!(v["outcome"], "completed");
    let length = v["length_m"].as_array().unwrap();
    assert_eq!(length.len(), 20);
    assert!(
        (length[19].as_f64().unwrap() - 105.0).abs() < 1e-6,
        "100 m + 1 m/s × 5 s"
    );
    let direct = contract::transient::simulate(&parse(&simulate_body()), &NoProgress).unwrap();
    assert_same_json(&a.text, &direct);

    let a = post(&app, "/api/v1/simulate", &ge_simulate_body()).await;
    assert_eq!(a.status, StatusCode::OK, "{}", a.text);
    let v: Value = serde_json::from_str(&a.text).unwrap();
    assert_eq!(v["outcome"]["status"], "completed");
    assert_eq!(v["steps"], 100);

    let mut bad = ge_simulate_body();
    bad["model"]["stiffness_ratio"] = json!(-1.0);
    let a = post(&app, "/api/v1/simulate", &bad).await;
    assert_eq!(a.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert_eq!(a.error().field.as_deref(), Some("model.stiffness_ratio"));
    let mut bad = simulate_body();
    bad["duration_s"] = json!("long");
    let a = post(&app, "/api/v1/simulate", &bad).await;
    assert_eq!(a.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert_eq!(a.error().field.as_deref(), Some("duration_s"));
}

#[tokio::test]
async fn frequency_response_answers_and_large_sweeps_go_to_jobs() {
    let (app, queue) = app();
    let a = post(
        &app,
        "/api/v1/frequency-response",
        &frequency_response_body(4),
    )
    .await;
    assert_eq!(a.status, StatusCode::OK, "{}", a.text);
    let v: Value = serde_json::from_str(&a.text).unwrap();
    assert_eq!(v["frequencies_rad_s"], json!([1.0, 2.0, 3.0, 4.0]));
    assert_eq!(v["envelope_m"].as_array().unwrap().len(), 4);

    let a = post(
        &app,
        "/api/v1/frequency-response",
        &frequency_response_body(64),
    )
    .await;
    assert_eq!(a.status, StatusCode::UNPROCESSABLE_ENTITY);
    let e = a.error();
    assert_eq!(e.code, "too_large");
    assert_eq!(e.field.as_deref(), Some("frequencies_rad_s.count"));

    // the same sweep, and a simulation, as jobs: results equal the direct answers
    let fr = frequency_response_body(6);
    let id = submit(&app, &json!({"kind": "frequency_response", "request": fr})).await;
    let sim = submit(
        &app,
        &json!({"kind": "simulate", "request": simulate_body()}),
    )
    .await;
    while try_execute_next(&queue).unwrap().is_some() {}
    let text = get(&app, &format!("/api/v1/jobs/{id}")).await.text;
    let direct =
        contract::transient::frequency_response(&parse(&fr), Parallelism::Serial, &NoProgress)
            .unwrap();
    assert_same_json(&result_text(&text), &direct);
    let text = get(&app, &format!("/api/v1/jobs/{sim}")).await.text;
    let direct = contract::transient::simulate(&parse(&simulate_body()), &NoProgress).unwrap();
    assert_same_json(&result_text(&text), &direct);

    // bad input is refused at submission, naming the field inside the request
    let mut bad = frequency_response_body(6);
    bad["frequencies_rad_s"]["max"] = json!(0.5);
    let a = post(
        &app,
        "/api/v1/jobs",
        &json!({"kind": "frequency_response", "request": bad}),
    )
    .await;
    assert_eq!(a.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert_eq!(
        a.error().field.as_deref(),
        Some("request.frequencies_rad_s.max")
    );
}
