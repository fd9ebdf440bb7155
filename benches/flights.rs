//! Live flights (issue 33 targets): ingest ≥ 50 000 samples/s into one
//! flight (SQLite file), the re-plan ≤ 100 ms, and an event on an
//! `/events` stream ≤ 100 ms after its sample is posted (p99) with 100
//! flights fed at 10 Hz each.
//!
//! - `flight_ingest_batch_1000_sqlite`: one 1000-sample batch stored and
//!   judged by the hub (`FlightHub::ingest`, a WAL SQLite file, the
//!   monitor with every check on); criterion reports samples/s.
//! - `flight_replan_800m_in_9_m_s`: `GET …/replan`'s work for the 1000 m
//!   reference flight at 800 m with 9 m/s measured (gusts 13 m/s).
//! - `flight_events_latency` (printed, not a criterion figure: it is a
//!   distribution under load): a server in this process on a loopback
//!   port, 100 flights each with an `/events` stream open, each fed one
//!   sample every 100 ms over its own keep-alive connection for
//!   `TETHERPLAN_BENCH_EVENTS_S` seconds (default 20); the latency of
//!   each sample from just before its POST to its arrival in the stream,
//!   p50/p99/max. `TETHERPLAN_BENCH_EVENTS_ONLY=1` runs only this.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use criterion::{Criterion, Throughput};
use serde_json::{Value, json};
use tetherplan::api::AppState;
use tetherplan::api::flights::hub::FlightHub;
use tetherplan::config::Limits;
use tetherplan::contract::flight::model::prepare;
use tetherplan::contract::flight::replan::replan;
use tetherplan::jobs::JobQueue;
use tetherplan::jobs::flights::{FlightStore, NewFlight};
use tetherplan::jobs::flights_sqlite::SqliteFlights;
use tetherplan::jobs::store::JobStore;
use tetherplan::numerics::monitor::Sample;
use tokio::io::{AsyncBufReadExt, AsyncReadExt, AsyncWriteExt, BufReader};
use tokio::net::TcpStream;

/// The 1000 m reference flight (SPEC §10's tether), every check on.
fn flight_body(name: &str) -> Value {
    json!({
        "name": name,
        "cable": {"mass_per_length_kg_m": 0.078, "diameter_m": 0.005,
                  "breaking_strength_n": 20000.0},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0, "drag_coefficient_nondim": 0.3,
                     "reference_area_m2": 20.0},
        "wind": {"flow": {"kind": "uniform", "speed_m_s": 6.0}},
        "initial_length_m": 1.0,
        "target_elevation_m": 800.0,
        "winch": {"max_rate_m_s": 3.0, "max_acceleration_m_s2": 0.5},
        "required_safety_factor_nondim": 3.0,
        "limits": {"max_operating_wind_m_s": 12.0, "max_gust_m_s": 18.0, "stale_after_s": 3600.0}
    })
}

fn sample(t: f64) -> Sample {
    Sample {
        time_s: t,
        tether_length_m: Some(1.0 + 2.0 * t.min(300.0)),
        winch_rate_m_s: Some(2.0),
        winch_tension_n: Some(1500.0 + 300.0 * (0.05 * t).sin()),
        wind_speed_m_s: Some(6.0 + 2.0 * (0.3 * t).sin()),
        wind_height_m: Some(10.0),
        aerostat_altitude_m: None,
    }
}

fn store_flight(store: &dyn FlightStore, name: &str) -> i64 {
    let p = prepare(flight_body(name).to_string().as_bytes()).expect("the flight commits");
    let f = NewFlight {
        name,
        request: &text(&p.request),
        plan: &text(&p.plan),
        limits: &text(&p.limits),
        ceiling: &text(&p.table),
    };
    store.create_flight("", &f).unwrap().unwrap()
}

/// JSON text of a committed part.
fn text<T: serde::Serialize>(v: &T) -> String {
    serde_json::to_string(v).unwrap()
}

fn criterion_benches(c: &mut Criterion) {
    let dir = std::env::temp_dir().join(format!("tetherplan-bench-flights-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let store = Arc::new(SqliteFlights::open(&dir.join("flights.db")).unwrap());
    let id = store_flight(store.as_ref(), "ingest");
    let hub = FlightHub::new(store);
    let flight = hub.get(id, "").unwrap().unwrap();
    let mut g = c.benchmark_group("flights");
    g.throughput(Throughput::Elements(1000));
    let mut k = 0u64;
    g.bench_function("flight_ingest_batch_1000_sqlite", |b| {
        b.iter(|| {
            let batch: Vec<Sample> = (0..1000)
                .map(|j| sample(0.1 * (k * 1000 + j) as f64))
                .collect();
            k += 1;
            let stored = hub.ingest(&flight, &batch, 0).unwrap();
            assert_eq!(stored.accepted, 1000);
        })
    });
    g.throughput(Throughput::Elements(1));
    let request = {
        let mut v = flight_body("replan");
        v.as_object_mut().unwrap().remove("name");
        v.as_object_mut().unwrap().remove("limits");
        v
    };
    g.bench_function("flight_replan_800m_in_9_m_s", |b| {
        b.iter(|| replan(&request, 800.0, Some((9.0, 13.0)), 10.0).unwrap())
    });
    g.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

/// Reads one HTTP/1.1 response (Content-Length bodies) from `r`.
async fn read_response(r: &mut BufReader<tokio::net::tcp::OwnedReadHalf>) -> u16 {
    let mut line = String::new();
    r.read_line(&mut line).await.unwrap();
    let status: u16 = line.split(' ').nth(1).unwrap().parse().unwrap();
    let mut len = 0usize;
    loop {
        line.clear();
        r.read_line(&mut line).await.unwrap();
        if line == "\r\n" {
            break;
        }
        if let Some(v) = line.to_ascii_lowercase().strip_prefix("content-length:") {
            len = v.trim().parse().unwrap();
        }
    }
    let mut body = vec![0; len];
    r.read_exact(&mut body).await.unwrap();
    status
}

/// Sent instants by (flight, time_s in tenths).
type Sent = Arc<Mutex<HashMap<(i64, i64), Instant>>>;

async fn feed(addr: std::net::SocketAddr, id: i64, until: Instant, sent: Sent) -> usize {
    let s = TcpStream::connect(addr).await.unwrap();
    s.set_nodelay(true).unwrap();
    let (rd, mut wr) = s.into_split();
    let mut rd = BufReader::new(rd);
    let mut tick = tokio::time::interval(Duration::from_millis(100));
    let mut k = 0i64;
    while Instant::now() < until {
        tick.tick().await;
        let body = json!([{"time_s": k as f64 / 10.0, "tether_length_m": 100.0,
                           "winch_tension_n": 1500.0, "wind_speed_m_s": 6.0}])
        .to_string();
        let req = format!(
            "POST /api/v1/flights/{id}/telemetry HTTP/1.1\r\nHost: {addr}\r\nContent-Type: application/json\r\nContent-Length: {}\r\n\r\n{body}",
            body.len()
        );
        sent.lock().unwrap().insert((id, k), Instant::now());
        wr.write_all(req.as_bytes()).await.unwrap();
        assert_eq!(read_response(&mut rd).await, 200);
        k += 1;
    }
    k as usize
}

/// Reads `/events` of flight `id`, recording each sample's latency.
async fn watch(addr: std::net::SocketAddr, id: i64, sent: Sent, lat: Arc<Mutex<Vec<f64>>>) {
    let s = TcpStream::connect(addr).await.unwrap();
    let (rd, mut wr) = s.into_split();
    let req = format!(
        "GET /api/v1/flights/{id}/events HTTP/1.1\r\nHost: {addr}\r\nAccept: text/event-stream\r\n\r\n"
    );
    wr.write_all(req.as_bytes()).await.unwrap();
    let mut rd = BufReader::new(rd);
    let mut line = String::new();
    loop {
        line.clear();
        if rd.read_line(&mut line).await.unwrap_or(0) == 0 {
            return;
        }
        // chunked framing lines are skipped: a data line is whole in a chunk
        let Some(data) = line.strip_prefix("data: ") else {
            continue;
        };
        let now = Instant::now();
        let Ok(v) = serde_json::from_str::<Value>(data.trim()) else {
            continue;
        };
        let Some(samples) = v["samples"].as_array() else {
            continue;
        };
        let sent = sent.lock().unwrap();
        let mut lat = lat.lock().unwrap();
        for s in samples {
            let k = (s["time_s"].as_f64().unwrap() * 10.0).round() as i64;
            if let Some(t0) = sent.get(&(id, k)) {
                lat.push((now - *t0).as_secs_f64() * 1000.0);
            }
        }
    }
}

fn events_latency() {
    let seconds: f64 = std::env::var("TETHERPLAN_BENCH_EVENTS_S")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(20.0);
    let flights = 100;
    let rt = tokio::runtime::Runtime::new().unwrap();
    rt.block_on(async move {
        let dir =
            std::env::temp_dir().join(format!("tetherplan-bench-events-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let store = Arc::new(SqliteFlights::open(&dir.join("flights.db")).unwrap());
        let ids: Vec<i64> = (0..flights)
            .map(|k| store_flight(store.as_ref(), &format!("f{k}")))
            .collect();
        let queue = Arc::new(JobQueue::new(
            JobStore::open_in_memory().unwrap(),
            0,
            Limits::default(),
        ));
        let state = AppState::new(queue).with_flights(FlightHub::new(store));
        let app = tetherplan::api::app(state, None);
        let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
        let addr = listener.local_addr().unwrap();
        tokio::spawn(async move { axum::serve(listener, app).await.unwrap() });
        let sent: Sent = Arc::default();
        let lat: Arc<Mutex<Vec<f64>>> = Arc::default();
        for &id in &ids {
            tokio::spawn(watch(addr, id, sent.clone(), lat.clone()));
        }
        tokio::time::sleep(Duration::from_millis(500)).await;
        let until = Instant::now() + Duration::from_secs_f64(seconds);
        let feeds: Vec<_> = ids
            .iter()
            .map(|&id| tokio::spawn(feed(addr, id, until, sent.clone())))
            .collect();
        let mut posted = 0;
        for f in feeds {
            posted += f.await.unwrap();
        }
        tokio::time::sleep(Duration::from_millis(1000)).await;
        let mut l = lat.lock().unwrap().clone();
        l.sort_by(f64::total_cmp);
        let q = |p: f64| l[((l.len() as f64 - 1.0) * p).round() as usize];
        println!(
            "flight_events_latency: {flights} flights at 10 Hz for {seconds} s: {posted} samples \
             posted, {} seen on the streams; latency p50 {:.1} ms, p99 {:.1} ms, max {:.1} ms",
            l.len(),
            q(0.5),
            q(0.99),
            l.last().copied().unwrap_or(f64::NAN)
        );
        let _ = std::fs::remove_dir_all(&dir);
    });
}

fn main() {
    if std::env::var("TETHERPLAN_BENCH_EVENTS_ONLY").as_deref() != Ok("1") {
        let mut c = Criterion::default().configure_from_args();
        criterion_benches(&mut c);
        c.final_summary();
    }
    // `cargo bench -- <filter>` or `cargo test --benches` (which passes --bench
    // only when benchmarking): the load run goes with the benchmarks.
    if std::env::args().any(|a| a == "--bench") {
        events_latency();
    }
}
