//! Synchronous work priced by what it costs (issue 34, item 2).
//!
//! For every priced shape of request (many tiny dynamics samples, a large
//! turbulence field, many steps, many segments, envelopes with many
//! integration steps, GE envelopes on a fixed mesh) the count that sets
//! its cost is stepped down from the largest the schema allows, by
//! factors of 1.5, until the server accepts it (a refusal is `422
//! too_large`, answered before any work). That request, the most
//! expensive of its shape the server answers synchronously within a factor
//! 1.5, must use at most [`SHARE_CPU_S`] CPU-seconds (the 2 CPU-second
//! budget of `tetherplan::price` with a factor 2 for the model) and answer
//! within half the 30 s solve timeout. Before the prices, 10 000
//! samples of 2 steps × 2 segments were accepted at 0.7 % of the limit and
//! took 11.3 CPU-seconds.
//!
//! The probe: four of the most expensive accepted many-sample requests at
//! once, and a 5 ms `/stability` call behind them, which must be answered
//! before the process has spent [`CHEAP_WAIT_CPU_S`] more CPU-seconds (it
//! waited 10.5 s behind four such requests).
//!
//! CPU time is the test process's (`getrusage`), the server being
//! in-process; the tests of this file run one at a time.

use std::sync::Mutex;
use std::time::{Duration, Instant};

use axum::http::StatusCode;
use serde_json::{Value, json};
use tetherplan::api::openapi::openapi;

mod common;
use common::{app, send};

/// CPU-seconds the most expensive accepted request may use.
const SHARE_CPU_S: f64 = 4.0;
/// Wall seconds it may take: half the default solve timeout (the machine
/// may be shared: the CPU time is the measure, this only says it ends).
const SHARE_WALL_S: f64 = 15.0;
/// CPU-seconds the process may spend while a cheap request waits behind
/// the most expensive ones: the priced work admitted at once
/// (`tetherplan::price::IN_FLIGHT_CPU_S`, 4) and one more. CPU, not wall
/// time, so that other load on the machine does not change the verdict;
/// before the prices, four 10 000-sample requests spent 45 CPU-s.
const CHEAP_WAIT_CPU_S: f64 = 5.0;

static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

fn cpu_s() -> f64 {
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: fills the struct.
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) };
    let t = |v: libc::timeval| v.tv_sec as f64 + v.tv_usec as f64 * 1e-6;
    t(u.ru_utime) + t(u.ru_stime)
}

fn example(path: &str) -> Value {
    let doc = serde_json::to_value(openapi()).unwrap();
    doc["paths"][path]["post"]["requestBody"]["content"]["application/json"]["example"].clone()
}

fn peaks(samples: usize, exposure_s: f64, dt: f64, segments: usize, length_m: f64) -> Value {
    let mut b = example("/api/v1/dynamics/peaks");
    b["samples"] = json!(samples);
    b["exposure_s"] = json!(exposure_s);
    b["tether_length_m"] = json!(length_m);
    b["numerics"] = json!({"segments": segments, "time_step_s": dt});
    b
}

/// One shape of request: its route and the body at a count.
struct Shape {
    name: &'static str,
    path: &'static str,
    top: usize,
    body: Box<dyn Fn(usize) -> Value>,
}

fn shapes() -> Vec<Shape> {
    vec![
        Shape {
            name: "peaks: many samples of 2 steps × 2 segments",
            path: "/api/v1/dynamics/peaks",
            top: 10_000,
            body: Box::new(|n| peaks(n, 0.2, 0.1, 2, 500.0)),
        },
        Shape {
            name: "peaks: samples with a 2 km tether's turbulence field",
            path: "/api/v1/dynamics/peaks",
            top: 10_000,
            body: Box::new(|n| peaks(n, 0.2, 0.1, 2, 2000.0)),
        },
        Shape {
            name: "peaks: many steps",
            path: "/api/v1/dynamics/peaks",
            top: 100_000,
            body: Box::new(|n| peaks(4, n as f64 * 0.01, 0.01, 2, 500.0)),
        },
        Shape {
            name: "peaks: many segments",
            path: "/api/v1/dynamics/peaks",
            top: 1000,
            body: Box::new(|n| peaks(4, 2.0, 0.01, n, 500.0)),
        },
        Shape {
            name: "dynamics: one run with a 20 km tether in a light wind",
            path: "/api/v1/dynamics",
            top: 20_000,
            body: Box::new(|n| {
                let mut b = example("/api/v1/dynamics");
                b["tether_length_m"] = json!(n as f64);
                b["duration_s"] = json!(1.0);
                b["numerics"] = json!({"segments": 10, "time_step_s": 0.1});
                b["wind"]["flow"] = json!({"kind": "uniform", "speed_m_s": 2.0});
                b["wind"]["time_history"] = json!({"kind": "turbulence", "model": "von_karman",
                    "turbulence_intensity_nondim": 0.15, "length_scale_m": 340.0, "seed": 1});
                b
            }),
        },
        Shape {
            name: "envelope: 5 000 points × many integration steps",
            path: "/api/v1/envelope",
            top: 100_000,
            body: Box::new(|n| {
                let mut b = example("/api/v1/envelope");
                b["wind_speeds_m_s"] = json!({"min": 0.0, "max": 30.0, "count": 100});
                b["tether_lengths_m"] = json!({"min": 100.0, "max": 3000.0, "count": 50});
                b["integration_steps"] = json!(n);
                b
            }),
        },
        Shape {
            name: "envelope bands: many integration steps",
            path: "/api/v1/envelope/bands",
            top: 100_000,
            body: Box::new(|n| {
                let mut b = example("/api/v1/envelope/bands");
                b["integration_steps"] = json!(n);
                b
            }),
        },
        Shape {
            name: "envelope: quasi-static GE on 20 elements, many winds",
            path: "/api/v1/envelope",
            top: 100,
            body: Box::new(|n| {
                let mut b = example("/api/v1/envelope");
                b["stability"] = json!({"method": "quasi_static_ge", "elements": 20});
                b["wind_speeds_m_s"] = json!({"min": 0.0, "max": 30.0, "count": n});
                b["tether_lengths_m"] = json!({"min": 100.0, "max": 3000.0, "count": 5});
                b
            }),
        },
    ]
}

/// Steps the count down from the top by factors of 1.5 until the server
/// answers; returns the count, the answer's status, CPU and wall seconds.
async fn most_expensive_accepted(app: &axum::Router, shape: &Shape) -> (usize, StatusCode, f64, f64) {
    let mut n = shape.top;
    loop {
        let body = (shape.body)(n);
        let (c0, t0) = (cpu_s(), Instant::now());
        let (status, answer) = send(app, "POST", shape.path, Some(&body)).await;
        let (cpu, wall) = (cpu_s() - c0, t0.elapsed().as_secs_f64());
        if status == StatusCode::UNPROCESSABLE_ENTITY && answer["error"]["code"] == "too_large" {
            assert!(wall < 1.0, "{}: a refusal took {wall:.1} s", shape.name);
            assert!(n > 1, "{}: even a count of 1 is refused: {answer}", shape.name);
            n = (n as f64 / 1.5) as usize;
            continue;
        }
        assert_eq!(status, StatusCode::OK, "{} at {n}: {answer}", shape.name);
        return (n, status, cpu, wall);
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_most_expensive_accepted_request_of_each_shape_stays_within_its_share() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let (app, _queue) = app();
    let mut report = Vec::new();
    for shape in shapes() {
        let (n, _, cpu, wall) = most_expensive_accepted(&app, &shape).await;
        eprintln!("{}: count {n} accepted, {cpu:.2} CPU-s, {wall:.2} s", shape.name);
        report.push((shape.name, n, cpu, wall));
    }
    for (name, n, cpu, wall) in report {
        assert!(
            cpu <= SHARE_CPU_S && wall <= SHARE_WALL_S,
            "{name}: at count {n} accepted synchronously and took {cpu:.2} CPU-s, {wall:.2} s \
             (at most {SHARE_CPU_S} CPU-s and {SHARE_WALL_S} s)"
        );
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn priced_work_does_not_starve_a_cheap_request() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let (app, _queue) = app();
    let shape = &shapes()[0];
    // The most expensive accepted many-sample request (found cheaply: the
    // refusals cost nothing; the accepted one runs once here).
    let (n, ..) = most_expensive_accepted(&app, shape).await;
    let heavy = (shape.body)(n);
    let cheap = example("/api/v1/stability");
    let (status, _) = send(&app, "POST", "/api/v1/stability", Some(&cheap)).await;
    assert_eq!(status, StatusCode::OK);
    let mut tasks = Vec::new();
    for _ in 0..4 {
        let (app, body) = (app.clone(), heavy.clone());
        tasks.push(tokio::spawn(async move {
            send(&app, "POST", "/api/v1/dynamics/peaks", Some(&body)).await.0
        }));
    }
    tokio::time::sleep(Duration::from_millis(200)).await;
    let (t0, c0) = (Instant::now(), cpu_s());
    let (status, answer) = send(&app, "POST", "/api/v1/stability", Some(&cheap)).await;
    let (waited, burnt) = (t0.elapsed().as_secs_f64(), cpu_s() - c0);
    let mut statuses = Vec::new();
    for t in tasks {
        statuses.push(t.await.unwrap().as_u16());
    }
    eprintln!(
        "4 × {n} samples at once ({statuses:?}); /stability answered in {waited:.2} s, \
         {burnt:.2} CPU-s spent meanwhile"
    );
    assert_eq!(status, StatusCode::OK, "{answer}");
    assert!(
        burnt <= CHEAP_WAIT_CPU_S,
        "a cheap /stability waited while {burnt:.1} CPU-s of priced work ran ({waited:.1} s; answers {statuses:?})"
    );
    assert!(
        statuses.iter().all(|s| *s == 200 || *s == 503),
        "{statuses:?}"
    );
}
