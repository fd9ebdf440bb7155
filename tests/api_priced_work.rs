//! Synchronous work priced by what it costs (issue 34, item 2): every
//! synchronous kind (the dynamics and envelope shapes in [`shapes`], the
//! others in [`kind_shapes`]; `TETHERPLAN_PRICED_SHAPES=word` runs only the
//! kinds' shapes whose name contains `word`).
//!
//! For every priced shape of request (many tiny dynamics samples, a large
//! turbulence field, many steps, many segments, envelopes with many
//! integration steps, GE envelopes on a fixed mesh) the count that sets
//! its cost is stepped down from the largest the schema allows, by
//! factors of 1.5, until the server accepts it (a refusal is `422
//! too_large`, answered before any work). That request, the most
//! expensive of its shape the server answers synchronously within a factor
//! 1.5, must use at most [`SHARE_CPU_S`] CPU-seconds (the 2 CPU-second
//! budget of `tetherplan::contract::price` with a factor 2 for the model) and answer
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
use common::{app, send, with};

/// CPU-seconds the most expensive accepted request may use.
const SHARE_CPU_S: f64 = 4.0;
/// Wall seconds it may take: half the default solve timeout (the machine
/// may be shared: the CPU time is the measure, this only says it ends).
const SHARE_WALL_S: f64 = 15.0;
/// CPU-seconds the process may spend while a cheap request waits behind
/// the most expensive ones: the priced work admitted at once
/// (`tetherplan::contract::price::IN_FLIGHT_CPU_S`, 4) and one more. CPU, not wall
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

/// The GE cable of the thesis' table (scaled steel wire, EI 1000 N m²).
fn ge(elements: usize) -> Value {
    json!({"kind": "geometrically_exact", "elements": elements, "bending_stiffness_n_m2": 1000.0,
           "stiffness_ratio": 1e5, "inertia_ratio": 1.0})
}

fn ge_system() -> Value {
    json!({"cable": {"density_kg_m3": 7800.0, "area_m2": 1e-5},
           "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0}, "initial_length_m": 1.0})
}

/// The thesis' base-excited GE cable (E* 5, scaled time), 16 frequencies,
/// `steps` steps of each run on `elements` elements.
fn base_excitation(elements: usize, steps: usize) -> Value {
    let scale = (0.078f64 / 1000.0).sqrt();
    json!({
        "excitation": "base",
        "cable": {"mass_per_length_kg_m": 0.078},
        "model": {"kind": "geometrically_exact", "elements": elements, "bending_stiffness_n_m2": 1000.0,
                  "stiffness_ratio": 5.0, "inertia_ratio": 1.0},
        "amplitude_m": 1e-3,
        "frequencies_rad_s": {"min": 1.0 / scale, "max": 3.5 / scale, "count": 16},
        "duration_s": steps as f64 * 0.05 * scale,
        "time_step_s": 0.05 * scale,
        "profile": {"kind": "constant_rate", "rate_m_s": 0.005 / scale}
    })
}

/// A CSV forecast of `hours` hours, each with its own wind (no two alike).
fn hourly_csv(hours: usize) -> String {
    let mut s = String::from("time,height_m,speed_m_s,gust_m_s\n");
    for h in 0..hours {
        let day = 1 + h / 24;
        let (month, day) = (1 + (day - 1) / 28 % 12, 1 + (day - 1) % 28);
        let speed = 2.0 + (h % 97) as f64 * 0.1;
        s.push_str(&format!(
            "2026-{month:02}-{day:02}T{:02}:00,10,{speed:.1},{:.1}\n",
            h % 24,
            speed * 1.4
        ));
    }
    s
}

/// The other kinds' shapes: transient runs and frequency responses of
/// both models, the GE stability, critical time and chart, string charts,
/// stability and critical times on fine meshes, bands, plan bands, plans,
/// launch windows and equilibria.
fn kind_shapes() -> Vec<Shape> {
    vec![
        Shape {
            name: "simulate: string, many elements",
            path: "/api/v1/simulate",
            top: 2000,
            body: Box::new(|n| {
                let mut b = example("/api/v1/simulate");
                b["model"] = json!({"kind": "linear_string", "elements": n});
                b["duration_s"] = json!(60.0);
                b
            }),
        },
        Shape {
            name: "simulate: string, a long run",
            path: "/api/v1/simulate",
            top: 500_000, // 4.4e6 steps of the automatic 0.113 s (the run's limit: 5e6)
            body: Box::new(|n| {
                let mut b = example("/api/v1/simulate");
                b["duration_s"] = json!(n as f64);
                b["profile"] = json!({"kind": "constant_rate", "rate_m_s": 0.0});
                b
            }),
        },
        Shape {
            name: "simulate: GE, many elements",
            path: "/api/v1/simulate",
            top: 2000,
            body: Box::new(|n| {
                with(
                    ge_system(),
                    json!({"model": ge(n), "time_step_s": 0.000883, "duration_s": 0.0883}),
                )
            }),
        },
        Shape {
            name: "simulate: GE, many steps",
            path: "/api/v1/simulate",
            top: 199_000, // the most steps whose every output fits the run's 200 000 samples
            body: Box::new(|n| {
                with(
                    ge_system(),
                    json!({"model": ge(10), "time_step_s": 0.000883, "duration_s": n as f64 * 0.000883}),
                )
            }),
        },
        Shape {
            name: "simulate: GE, eigenvalues every step, many elements",
            path: "/api/v1/simulate",
            top: 300, // eigenvalues need elements ≤ 300
            body: Box::new(|n| {
                with(
                    ge_system(),
                    json!({"model": ge(n), "time_step_s": 0.000883, "duration_s": 0.0883,
                           "eigenvalues_every_steps": 1}),
                )
            }),
        },
        Shape {
            name: "frequency response: string, 16 frequencies, a long run",
            path: "/api/v1/frequency-response",
            top: 40_000, // 4.0e6 steps of 0.00999 s a run (the run's limit: 5e6)
            body: Box::new(|n| {
                let mut b = example("/api/v1/frequency-response");
                b["frequencies_rad_s"] = json!({"min": 1.0, "max": 4.0, "count": 16});
                b["duration_s"] = json!(n as f64);
                b["profile"] = json!({"kind": "constant_rate", "rate_m_s": 0.0});
                b
            }),
        },
        Shape {
            name: "frequency response: string, 16 frequencies, many elements",
            path: "/api/v1/frequency-response",
            top: 2000,
            body: Box::new(|n| {
                let mut b = example("/api/v1/frequency-response");
                b["frequencies_rad_s"] = json!({"min": 1.0, "max": 4.0, "count": 16});
                b["model"] = json!({"kind": "linear_string", "elements": n});
                b
            }),
        },
        Shape {
            name: "frequency response: GE base excitation, 16 frequencies, many steps",
            path: "/api/v1/frequency-response",
            top: 2_000_000,
            body: Box::new(|n| base_excitation(10, n)),
        },
        Shape {
            name: "frequency response: GE base excitation, 16 frequencies, many elements",
            path: "/api/v1/frequency-response",
            top: 2000,
            body: Box::new(|n| base_excitation(n, 400)),
        },
        Shape {
            name: "safe rate: string, many elements",
            path: "/api/v1/safe-rate",
            top: 2000,
            body: Box::new(|n| {
                let mut b = example("/api/v1/safe-rate");
                b["model"] = json!({"kind": "linear_string", "elements": n});
                b
            }),
        },
        Shape {
            name: "stability: GE, many elements",
            path: "/api/v1/stability",
            top: 2000,
            body: Box::new(|n| {
                with(
                    ge_system(),
                    json!({"model": ge(n), "state": {"length_m": 500.0, "rate_m_s": 10.0}, "modes": 4}),
                )
            }),
        },
        Shape {
            name: "stability: string, many elements",
            path: "/api/v1/stability",
            top: 2000,
            body: Box::new(|n| {
                let mut b = example("/api/v1/stability");
                b["model"] = json!({"kind": "linear_string", "elements": n});
                b
            }),
        },
        Shape {
            name: "critical: GE, many elements",
            path: "/api/v1/critical",
            top: 2000,
            body: Box::new(|n| {
                with(
                    ge_system(),
                    json!({"model": ge(n), "profile": {"kind": "constant_rate", "rate_m_s": 100.0}}),
                )
            }),
        },
        Shape {
            name: "critical: string confirmed by the QEP, many elements",
            path: "/api/v1/critical",
            top: 2000,
            body: Box::new(|n| {
                let mut b = example("/api/v1/critical");
                b["model"] = json!({"kind": "linear_string", "elements": n});
                b["confirm_with_qep"] = json!(true);
                b
            }),
        },
        Shape {
            name: "chart: GE, 8 points, many elements",
            path: "/api/v1/charts",
            top: 200,
            body: Box::new(|n| {
                let mut m = ge(n);
                m.as_object_mut().unwrap().remove("stiffness_ratio");
                with(
                    ge_system(),
                    json!({"model": m, "stiffness_ratios": [1e5, 1e6],
                           "rates_m_s": {"min": 100.0, "max": 130.0, "count": 4}}),
                )
            }),
        },
        Shape {
            name: "chart: string, 1 000 points, many elements",
            path: "/api/v1/charts",
            top: 2000,
            body: Box::new(|n| {
                let mut b = example("/api/v1/charts");
                b["model"] = json!({"kind": "linear_string", "elements": n});
                b["rates_m_s"] = json!({"min": 1.0, "max": 120.0, "count": 500});
                b
            }),
        },
        Shape {
            name: "chart: string, converged, many points",
            path: "/api/v1/charts",
            top: 100_000,
            body: Box::new(|n| {
                let mut b = example("/api/v1/charts");
                b["rates_m_s"] = json!({"min": 1.0, "max": 120.0, "count": n});
                b["net_buoyancies_n"] = json!([1000.0]);
                b
            }),
        },
        Shape {
            name: "bands: many samples",
            path: "/api/v1/bands",
            top: 100_000,
            body: Box::new(|n| {
                let mut b = example("/api/v1/bands");
                b["uncertainty"]["samples"] = json!(n);
                b
            }),
        },
        Shape {
            name: "bands: 1 000 samples on many elements",
            path: "/api/v1/bands",
            top: 2000,
            body: Box::new(|n| {
                let mut b = example("/api/v1/bands");
                b["model"] = json!({"kind": "linear_string", "elements": n});
                b
            }),
        },
        Shape {
            name: "plan bands: many samples",
            path: "/api/v1/plan/bands",
            top: 100_000,
            body: Box::new(|n| {
                let mut b = example("/api/v1/plan/bands");
                b["uncertainty"]["samples"] = json!(n);
                b
            }),
        },
        Shape {
            name: "plan: many schedule samples",
            path: "/api/v1/plan",
            top: 10_000,
            body: Box::new(|n| {
                let mut b = example("/api/v1/plan");
                b["samples"] = json!(n);
                b
            }),
        },
        Shape {
            name: "windows: many distinct hours",
            path: "/api/v1/windows",
            top: 8_000, // 333 days of hours (the CSV's dates run over 12 months of 28 days)
            body: Box::new(|n| {
                let mut b = example("/api/v1/windows");
                b["forecast"] = json!({"format": "csv", "data": hourly_csv(n)});
                b
            }),
        },
        Shape {
            name: "equilibrium: many integration steps",
            path: "/api/v1/equilibrium",
            top: 100_000,
            body: Box::new(|n| {
                let mut b = example("/api/v1/equilibrium");
                b["integration_steps"] = json!(n);
                b["shape_samples"] = json!(10_001);
                b
            }),
        },
    ]
}

/// Steps the count down from the top by factors of 1.5 until the server
/// answers; returns the count, the answer's status and error (if any),
/// CPU and wall seconds.
async fn most_expensive_accepted(
    app: &axum::Router,
    shape: &Shape,
) -> (usize, StatusCode, String, f64, f64) {
    let mut n = shape.top;
    loop {
        let body = (shape.body)(n);
        let (c0, t0) = (cpu_s(), Instant::now());
        let (status, answer) = send(app, "POST", shape.path, Some(&body)).await;
        let (cpu, wall) = (cpu_s() - c0, t0.elapsed().as_secs_f64());
        if status == StatusCode::UNPROCESSABLE_ENTITY && answer["error"]["code"] == "too_large" {
            assert!(wall < 1.0, "{}: a refusal took {wall:.1} s", shape.name);
            assert!(
                n > 1,
                "{}: even a count of 1 is refused: {answer}",
                shape.name
            );
            n = (n as f64 / 1.5) as usize;
            continue;
        }
        let error = if status == StatusCode::OK {
            String::new()
        } else {
            answer["error"].to_string()
        };
        return (n, status, error, cpu, wall);
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_most_expensive_accepted_request_of_each_shape_stays_within_its_share() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let (app, _queue) = app();
    let mut report = Vec::new();
    for shape in shapes() {
        let (n, status, error, cpu, wall) = most_expensive_accepted(&app, &shape).await;
        eprintln!(
            "{}: count {n} answered {status} {error}, {cpu:.2} CPU-s, {wall:.2} s",
            shape.name
        );
        report.push((shape.name, n, status, error, cpu, wall));
    }
    for (name, n, status, error, cpu, wall) in report {
        assert_eq!(status, StatusCode::OK, "{name} at count {n}: {error}");
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
    let (n, status, error, ..) = most_expensive_accepted(&app, shape).await;
    assert_eq!(status, StatusCode::OK, "{error}");
    let heavy = (shape.body)(n);
    let cheap = example("/api/v1/stability");
    let (status, _) = send(&app, "POST", "/api/v1/stability", Some(&cheap)).await;
    assert_eq!(status, StatusCode::OK);
    let mut tasks = Vec::new();
    for _ in 0..4 {
        let (app, body) = (app.clone(), heavy.clone());
        tasks.push(tokio::spawn(async move {
            send(&app, "POST", "/api/v1/dynamics/peaks", Some(&body))
                .await
                .0
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

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_most_expensive_accepted_request_of_every_kind_stays_within_its_share() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let (app, _queue) = app();
    let only = std::env::var("TETHERPLAN_PRICED_SHAPES").ok();
    let mut report = Vec::new();
    for shape in kind_shapes() {
        if only.as_deref().is_some_and(|w| !shape.name.contains(w)) {
            continue;
        }
        let (n, status, error, cpu, wall) = most_expensive_accepted(&app, &shape).await;
        eprintln!(
            "{}: count {n} answered {status} {error}, {cpu:.2} CPU-s, {wall:.2} s",
            shape.name
        );
        report.push((shape.name, n, status, error, cpu, wall));
    }
    for (name, n, status, error, cpu, wall) in report {
        assert_eq!(status, StatusCode::OK, "{name} at count {n}: {error}");
        assert!(
            cpu <= SHARE_CPU_S && wall <= SHARE_WALL_S,
            "{name}: at count {n} accepted synchronously and took {cpu:.2} CPU-s, {wall:.2} s \
             (at most {SHARE_CPU_S} CPU-s and {SHARE_WALL_S} s)"
        );
    }
}
