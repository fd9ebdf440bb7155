//! Live flights over HTTP (issue 33): a flight per token, telemetry in
//! JSON, CSV and NMEA, a repeated batch stored once, late batches judged
//! in time order, acknowledgement, the events' replay after
//! `Last-Event-ID`, the re-plan, and a real server killed with SIGKILL
//! and restarted on the same database answering the same flight.

use std::time::Duration;

use axum::body::Body;
use axum::http::{Request, StatusCode, header};
use http_body_util::BodyExt;
use serde_json::{Value, json};
use tower::ServiceExt;

mod common;
use common::flights::{batch, comparable};
use common::http::ServeProcess;
use common::{app_with_tokens, request, send_as};

/// A calm-air plan to 300 m: allowed tension 20 000 / 5 = 4000 N, net
/// buoyancy 1000 N (slack below 50 N).
fn flight_body(name: &str) -> Value {
    json!({
        "name": name,
        "cable": {"mass_per_length_kg_m": 0.078, "breaking_strength_n": 20000.0},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
        "initial_length_m": 1.0,
        "target_elevation_m": 300.0,
        "winch": {"max_rate_m_s": 3.0, "max_acceleration_m_s2": 0.5},
        "lift_reserve_nondim": 0.05,
        "required_safety_factor_nondim": 5.0,
        "limits": {"max_operating_wind_m_s": 12.0, "max_gust_m_s": 18.0, "stale_after_s": 3600.0}
    })
}

async fn send_body(
    app: &axum::Router,
    token: &str,
    uri: &str,
    ct: &str,
    body: String,
) -> (StatusCode, Value) {
    let req = Request::builder()
        .method("POST")
        .uri(uri)
        .header(header::CONTENT_TYPE, ct)
        .header(header::AUTHORIZATION, format!("Bearer {token}"));
    let a = request(app, req, Body::from(body)).await;
    (
        a.status,
        serde_json::from_str(&a.text).unwrap_or(Value::Null),
    )
}

async fn as_json(
    app: &axum::Router,
    token: &str,
    method: &str,
    uri: &str,
    body: Option<&Value>,
) -> (StatusCode, Value) {
    let (s, t) = send_as(app, token, method, uri, body).await;
    (
        s,
        serde_json::from_str(&t).unwrap_or_else(|e| panic!("{e}: {t}")),
    )
}

fn check<'a>(flight: &'a Value, name: &str) -> &'a Value {
    flight["checks"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["name"] == name)
        .unwrap_or_else(|| panic!("no check {name}: {flight}"))
}

#[tokio::test]
async fn a_flight_belongs_to_its_token_and_its_monitor_raises_and_latches() {
    let (app, _) = app_with_tokens(&["alpha", "beta"]);
    let (s, created) = as_json(
        &app,
        "alpha",
        "POST",
        "/api/v1/flights",
        Some(&flight_body("one")),
    )
    .await;
    assert_eq!(s, StatusCode::CREATED, "{created}");
    assert_eq!(created["state"], "unavailable");
    assert_eq!(created["limits"]["allowable_tension_n"], 4000.0);
    assert!(created["plan"]["feasible"].as_bool().unwrap());
    let id = created["id"].as_i64().unwrap();
    let uri = format!("/api/v1/flights/{id}");

    // another token sees none of it
    let (s, _) = send_as(&app, "beta", "GET", &uri, None).await;
    assert_eq!(s, StatusCode::NOT_FOUND);
    let (_, list) = as_json(&app, "beta", "GET", "/api/v1/flights", None).await;
    assert_eq!(list["flights"], json!([]));
    for path in ["end", "telemetry", "alarms/acknowledge"] {
        let (s, _) = send_body(
            &app,
            "beta",
            &format!("{uri}/{path}"),
            "application/json",
            "[]".into(),
        )
        .await;
        assert_eq!(s, StatusCode::NOT_FOUND, "{path}");
    }
    let (_, list) = as_json(&app, "alpha", "GET", "/api/v1/flights", None).await;
    assert_eq!(list["flights"][0]["id"], id);
    // the committed plan, as the creation answered it; not to another token
    let (s, plan) = as_json(&app, "alpha", "GET", &format!("{uri}/plan"), None).await;
    assert_eq!(s, StatusCode::OK);
    assert_eq!(plan, created["plan"]);
    let (s, _) = send_as(&app, "beta", "GET", &format!("{uri}/plan"), None).await;
    assert_eq!(s, StatusCode::NOT_FOUND);

    // 1000 N for 2 s: normal; then 4400 N (past 4000: stop) for 2 s; then
    // 1000 N for 10 s: the stop clears after 5 s but stays latched
    let tele = format!("{uri}/telemetry");
    let (s, a) = send_body(
        &app,
        "alpha",
        &tele,
        "application/json",
        batch(0.0, 20, |_| 1000.0).to_string(),
    )
    .await;
    assert_eq!(
        (s, a["accepted"].as_u64()),
        (StatusCode::OK, Some(20)),
        "{a}"
    );
    assert_eq!(a["state"], "normal", "{a}");
    let (_, a) = send_body(
        &app,
        "alpha",
        &tele,
        "application/json",
        batch(2.0, 20, |_| 4400.0).to_string(),
    )
    .await;
    assert_eq!(a["state"], "stop", "{a}");
    let (_, a) = send_body(
        &app,
        "alpha",
        &tele,
        "application/json",
        batch(4.0, 100, |_| 1000.0).to_string(),
    )
    .await;
    assert_eq!(a["state"], "stop", "latched: {a}");
    let (_, f) = as_json(&app, "alpha", "GET", &uri, None).await;
    let tension = check(&f, "tension");
    assert_eq!(
        (tension["state"].as_str(), tension["stop_at"].as_f64()),
        (Some("stop"), Some(4000.0))
    );
    let stop = f["alarms"]
        .as_array()
        .unwrap()
        .iter()
        .find(|a| a["level"] == "stop")
        .unwrap()
        .clone();
    assert_eq!(stop["raised_at_s"], 3.0);
    assert_eq!(stop["cleared_at_s"], 9.0);
    assert_eq!(stop["acknowledged_at_s"], Value::Null);
    assert_eq!(f["samples_received"], 140);
    assert_eq!(f["last_sample_time_s"], 13.9);
    let (s, ack) = as_json(
        &app,
        "alpha",
        "POST",
        &format!("{uri}/alarms/acknowledge"),
        None,
    )
    .await;
    assert_eq!(s, StatusCode::OK);
    assert_eq!(ack["state"], "normal", "{ack}");
    assert_eq!(ack["acknowledged"], 2); // the caution and the stop

    // ended: telemetry refused
    let (s, _) = as_json(&app, "alpha", "POST", &format!("{uri}/end"), None).await;
    assert_eq!(s, StatusCode::OK);
    let (s, _) = send_body(
        &app,
        "alpha",
        &tele,
        "application/json",
        batch(20.0, 1, |_| 1.0).to_string(),
    )
    .await;
    assert_eq!(s, StatusCode::CONFLICT);
}

#[tokio::test]
async fn a_repeated_batch_stores_nothing_twice_and_a_late_one_is_judged_in_time_order() {
    let (app, _) = app_with_tokens(&["alpha"]);
    let (_, created) = as_json(
        &app,
        "alpha",
        "POST",
        "/api/v1/flights",
        Some(&flight_body("dup")),
    )
    .await;
    let uri = format!("/api/v1/flights/{}", created["id"]);
    let tele = format!("{uri}/telemetry");
    // a caution (3500 N > 3200 N) from t = 5 to 7 s
    let f = |t: f64| {
        if (5.0..7.0).contains(&t) {
            3500.0
        } else {
            1000.0
        }
    };
    let b1 = batch(0.0, 50, f).to_string();
    let b2 = batch(5.0, 50, f).to_string();
    let (_, a) = send_body(&app, "alpha", &tele, "application/json", b2.clone()).await;
    assert_eq!(
        (a["accepted"].as_u64(), a["duplicates"].as_u64()),
        (Some(50), Some(0))
    );
    // the earlier batch arrives late
    let (_, a) = send_body(&app, "alpha", &tele, "application/json", b1).await;
    assert_eq!(
        (a["accepted"].as_u64(), a["duplicates"].as_u64()),
        (Some(50), Some(0))
    );
    let (_, a) = send_body(&app, "alpha", &tele, "application/json", b2).await;
    assert_eq!(
        (a["accepted"].as_u64(), a["duplicates"].as_u64()),
        (Some(0), Some(50))
    );
    assert_eq!(a["samples_received"], 100);
    let (_, fl) = as_json(&app, "alpha", "GET", &uri, None).await;
    let alarms = fl["alarms"].as_array().unwrap();
    assert_eq!(alarms.len(), 1, "{fl}");
    assert_eq!(
        (
            alarms[0]["check"].as_str(),
            alarms[0]["level"].as_str(),
            alarms[0]["raised_at_s"].as_f64()
        ),
        (Some("tension"), Some("caution"), Some(6.0))
    );
    // CSV of the same names, one bad cell named by line and field
    let csv = "time_s,winch_tension_n,wind_speed_m_s\n10.0,1000,5\n10.1,lots,5\n10.2,1000,5\n";
    let (s, a) = send_body(&app, "alpha", &tele, "text/csv", csv.into()).await;
    assert_eq!(s, StatusCode::OK);
    assert_eq!(
        (a["accepted"].as_u64(), a["rejected"].as_u64()),
        (Some(2), Some(1))
    );
    assert_eq!(a["errors"][0]["line"], 3);
    assert_eq!(a["errors"][0]["field"], "winch_tension_n");
    // unknown fields are refused by name, the good samples kept
    let body =
        json!([{"time_s": 11.0, "winch_tension_n": 1000.0}, {"time_s": 11.1, "tension_n": 3.0}]);
    let (_, a) = send_body(&app, "alpha", &tele, "application/json", body.to_string()).await;
    assert_eq!(
        (a["accepted"].as_u64(), a["rejected"].as_u64()),
        (Some(1), Some(1))
    );
    assert_eq!(a["errors"][0]["field"], "tension_n");
    let (s, _) = send_body(&app, "alpha", &tele, "application/xml", "<a/>".into()).await;
    assert_eq!(s, StatusCode::UNSUPPORTED_MEDIA_TYPE);
}

fn nmea(body: &str) -> String {
    let c = body.bytes().fold(0u8, |a, b| a ^ b);
    format!("${body}*{c:02X}")
}

#[tokio::test]
async fn nmea_v_is_not_used_and_knots_are_converted() {
    let (app, _) = app_with_tokens(&["alpha"]);
    let (_, created) = as_json(
        &app,
        "alpha",
        "POST",
        "/api/v1/flights",
        Some(&flight_body("nmea")),
    )
    .await;
    let uri = format!("/api/v1/flights/{}", created["id"]);
    let lines = [
        format!("1.0,{}", nmea("WIMWV,090.0,R,20.0,N,V")), // 10.3 m/s, but flagged V
        format!("2.0,{}", nmea("WIMWV,090.0,R,10.0,N,A")),
    ];
    let (s, a) = send_body(
        &app,
        "alpha",
        &format!("{uri}/telemetry"),
        "text/plain",
        lines.join("\n"),
    )
    .await;
    assert_eq!(s, StatusCode::OK, "{a}");
    assert_eq!(
        (a["accepted"].as_u64(), a["rejected"].as_u64()),
        (Some(1), Some(1)),
        "{a}"
    );
    assert_eq!(
        (
            a["errors"][0]["line"].as_u64(),
            a["errors"][0]["field"].as_str()
        ),
        (Some(1), Some("data_valid"))
    );
    let (_, f) = as_json(&app, "alpha", "GET", &uri, None).await;
    // the 10-minute mean of the one valid sample: 10 kn exactly
    assert_eq!(
        check(&f, "wind")["value"].as_f64(),
        Some(10.0 * 1852.0 / 3600.0)
    );
}

#[tokio::test]
async fn events_replay_what_a_client_missed_after_last_event_id() {
    let (app, _) = app_with_tokens(&["alpha"]);
    let (_, created) = as_json(
        &app,
        "alpha",
        "POST",
        "/api/v1/flights",
        Some(&flight_body("sse")),
    )
    .await;
    let uri = format!("/api/v1/flights/{}", created["id"]);
    send_body(
        &app,
        "alpha",
        &format!("{uri}/telemetry"),
        "application/json",
        batch(0.0, 10, |_| 900.0).to_string(),
    )
    .await;
    let req = Request::builder()
        .uri(format!("{uri}/events"))
        .header(header::AUTHORIZATION, "Bearer alpha")
        .header("last-event-id", "7")
        .header(header::ACCEPT, "text/event-stream")
        .body(Body::empty())
        .unwrap();
    let resp = app.clone().oneshot(req).await.unwrap();
    assert_eq!(resp.status(), StatusCode::OK);
    assert_eq!(resp.headers()[header::CONTENT_TYPE], "text/event-stream");
    let mut body = resp.into_body();
    let mut text = String::new();
    while !text.contains("event: state") {
        let frame = tokio::time::timeout(Duration::from_secs(5), body.frame())
            .await
            .expect("an event within 5 s")
            .unwrap()
            .unwrap();
        if let Ok(d) = frame.into_data() {
            text.push_str(&String::from_utf8_lossy(&d));
        }
    }
    let data = text
        .lines()
        .find_map(|l| {
            l.strip_prefix("data: ")
                .filter(|d| d.contains("\"samples\""))
        })
        .unwrap_or_else(|| panic!("{text}"));
    let v: Value = serde_json::from_str(data).unwrap();
    let seqs: Vec<i64> = v["samples"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["seq"].as_i64().unwrap())
        .collect();
    assert_eq!(seqs, vec![8, 9, 10]);
    assert!(text.contains("id: 10"), "{text}");
}

#[tokio::test]
async fn a_client_that_does_not_accept_an_event_stream_gets_a_snapshot_that_ends() {
    let (app, _) = app_with_tokens(&["alpha"]);
    let (_, created) = as_json(
        &app,
        "alpha",
        "POST",
        "/api/v1/flights",
        Some(&flight_body("snap")),
    )
    .await;
    let uri = format!("/api/v1/flights/{}", created["id"]);
    send_body(
        &app,
        "alpha",
        &format!("{uri}/telemetry"),
        "application/json",
        batch(0.0, 3, |_| 900.0).to_string(),
    )
    .await;
    let (req, body) = common::json_request("GET", &format!("{uri}/events"), None);
    let req = req.header(header::AUTHORIZATION, "Bearer alpha");
    let a = tokio::time::timeout(Duration::from_secs(10), request(&app, req, body))
        .await
        .expect("the snapshot ends");
    assert_eq!(a.status, StatusCode::OK);
    assert!(
        a.text.contains("event: samples") && a.text.contains("id: 3"),
        "{}",
        a.text
    );
    assert_eq!(a.text.matches("event: state").count(), 1, "{}", a.text);
}

#[tokio::test]
async fn the_replan_starts_from_the_measured_length() {
    let (app, _) = app_with_tokens(&["alpha"]);
    let (_, created) = as_json(
        &app,
        "alpha",
        "POST",
        "/api/v1/flights",
        Some(&flight_body("replan")),
    )
    .await;
    let uri = format!("/api/v1/flights/{}", created["id"]);
    let (s, e) = send_as(&app, "alpha", "GET", &format!("{uri}/replan"), None).await;
    assert_eq!(s, StatusCode::UNPROCESSABLE_ENTITY, "{e}");
    let body = json!([{"time_s": 40.0, "tether_length_m": 100.0}]);
    send_body(
        &app,
        "alpha",
        &format!("{uri}/telemetry"),
        "application/json",
        body.to_string(),
    )
    .await;
    let (s, r) = as_json(&app, "alpha", "GET", &format!("{uri}/replan"), None).await;
    assert_eq!(s, StatusCode::OK, "{r}");
    assert_eq!(r["mode"], "continue", "{r}");
    assert_eq!(r["current_length_m"], 100.0);
    assert_eq!(r["plan"]["schedule"][0]["length_m"], 100.0);
}

#[test]
fn a_server_killed_with_sigkill_keeps_every_acknowledged_sample_and_its_state() {
    let dir = std::env::temp_dir().join(format!("tetherplan-flight-kill-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let mut server = ServeProcess::start(["--db".as_ref(), dir.join("flights.db").as_os_str()]);
    let (s, created) = server.send(
        "POST",
        "/api/v1/flights",
        "application/json",
        flight_body("kill").to_string().as_bytes(),
    );
    assert_eq!(s, 201, "{created}");
    let uri = format!("/api/v1/flights/{}", created["id"]);
    let tele = format!("{uri}/telemetry");
    // a stop, acknowledged while still past it, then a caution left raised
    let f = |t: f64| match t {
        t if (2.0..4.0).contains(&t) => 4400.0,
        t if t >= 12.0 => 3500.0,
        _ => 1000.0,
    };
    let mut accepted = 0;
    for k in 0..8 {
        let (s, a) = server.send(
            "POST",
            &tele,
            "application/json",
            batch(2.0 * k as f64, 20, f).to_string().as_bytes(),
        );
        assert_eq!(s, 200, "{a}");
        accepted += a["accepted"].as_u64().unwrap();
        if k == 1 {
            let (s, _) = server.send(
                "POST",
                &format!("{uri}/alarms/acknowledge"),
                "application/json",
                b"",
            );
            assert_eq!(s, 200);
        }
    }
    assert_eq!(accepted, 160);
    let (_, before) = server.send("GET", &uri, "application/json", b"");
    assert_eq!(before["state"], "caution", "{before}");
    assert_eq!(before["samples_received"], 160);
    // SIGKILL: no shutdown of any kind
    server.kill();
    let server = ServeProcess::start(["--db".as_ref(), dir.join("flights.db").as_os_str()]);
    let (s, after) = server.send("GET", &uri, "application/json", b"");
    assert_eq!(s, 200);
    assert_eq!(comparable(after.clone()), comparable(before.clone()));
    // and it goes on from there: the same batch again stores nothing
    let (_, a) = server.send(
        "POST",
        &tele,
        "application/json",
        batch(14.0, 20, f).to_string().as_bytes(),
    );
    assert_eq!(
        (a["accepted"].as_u64(), a["duplicates"].as_u64()),
        (Some(0), Some(20))
    );
    drop(server);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Creating a flight solves its plan like the solve routes: past the
/// server's solve timeout (zero here: no solve can start in time) it is
/// the plan route's own 504 `timeout`, word for word, and nothing is
/// stored; within it (the default) the same body is created.
#[tokio::test]
async fn a_flight_whose_plan_is_not_solved_in_time_is_the_solve_routes_timeout() {
    let limits = tetherplan::config::Limits {
        solve_timeout: Duration::ZERO,
        ..Default::default()
    };
    let (app, _) = common::app_with(2, limits);
    let body = flight_body("late");
    let (s, flight) = send_as(&app, "", "POST", "/api/v1/flights", Some(&body)).await;
    assert_eq!(s, StatusCode::GATEWAY_TIMEOUT, "{flight}");
    let mut plan = body.clone();
    plan.as_object_mut().unwrap().remove("name");
    plan.as_object_mut().unwrap().remove("limits");
    let (s, planned) = send_as(&app, "", "POST", "/api/v1/plan", Some(&plan)).await;
    assert_eq!(s, StatusCode::GATEWAY_TIMEOUT, "{planned}");
    let flight: Value = serde_json::from_str(&flight).unwrap();
    let planned: Value = serde_json::from_str(&planned).unwrap();
    assert_eq!(flight["error"]["code"], "timeout");
    assert_eq!(flight, planned);
    let (s, list) = send_as(&app, "", "GET", "/api/v1/flights", None).await;
    assert_eq!(s, StatusCode::OK);
    assert_eq!(
        serde_json::from_str::<Value>(&list).unwrap()["flights"],
        json!([])
    );

    let (app, _) = common::app();
    let (s, created) = send_as(&app, "", "POST", "/api/v1/flights", Some(&body)).await;
    assert_eq!(s, StatusCode::CREATED, "{created}");
}
