//! The chunked kinds beyond GE charts and chart bands — string charts,
//! `plan_bands`, `envelope_bands` — and the cancellation of running
//! chunks, on SQLite.
//!
//! * For several chunk sizes, the answer put together from the chunks is
//!   the single-process answer, byte for byte (seeds, percentiles,
//!   rejected draws included).
//! * Through the queue: the job is split, every chunk is done once, the
//!   stored answer is the single-process one, and the job's `progress`
//!   moves in whole chunks (every value read while it runs is k / chunks).
//! * A cancelled job's running chunks, in two worker "processes" (queues
//!   on one database, cancelled from a third, so that only the database
//!   tells them), stop within a bound far below both their own length and
//!   the lease renewal interval; no further chunk is claimed; the job ends
//!   `cancelled`.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, mpsc};

use std::time::{Duration, Instant};

use serde_json::{Value, json};
use tetherplan::config::Limits;
use tetherplan::contract::run::NoProgress;
use tetherplan::jobs::chunks::{CANCEL_POLL, ChunkPlan};
use tetherplan::jobs::kinds::JobSubmission;
use tetherplan::jobs::store::{JobStatus, JobStore};
use tetherplan::jobs::{JobQueue, work_once};

fn string_chart() -> Value {
    json!({"kind": "chart", "request": {
        "cable": {"mass_per_length_kg_m": 0.078},
        "aerostat": {"net_buoyancy_n": 1000.0},
        "model": {"elements": 400},
        "rates_m_s": {"min": 1.0, "max": 120.0, "count": 1500},
        "net_buoyancies_n": [800.0, 1000.0, 1300.0]
    }})
}

fn converged_string_chart() -> Value {
    json!({"kind": "chart", "request": {
        "cable": {"mass_per_length_kg_m": 0.078},
        "aerostat": {"net_buoyancy_n": 1000.0},
        "rates_m_s": {"min": 1.0, "max": 120.0, "count": 37},
        "net_buoyancies_n": [800.0, 1300.0]
    }})
}

/// Net buoyancy wide enough that about 0.6 % of the draws are negative
/// (rejected and counted), so the assembly must carry rejections too.
fn plan_bands(samples: usize) -> Value {
    json!({"kind": "plan_bands", "request": {
        "cable": {"mass_per_length_kg_m": 0.078, "breaking_strength_n": 5200.0},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
        "initial_length_m": 1.0,
        "target_elevation_m": 1200.0,
        "winch": {"max_rate_m_s": 40.0, "max_acceleration_m_s2": 2.0},
        "lift_reserve_nondim": 0.05,
        "required_safety_factor_nondim": 5.0,
        "samples": 2001,
        "uncertainty": {"samples": samples, "seed": 11, "inputs": [
            {"field": "aerostat.net_buoyancy_n", "distribution": "normal", "mean": 1000.0, "std_dev": 400.0},
            {"field": "cable.mass_per_length_kg_m", "distribution": "normal", "mean": 0.078, "std_dev": 0.002},
            {"field": "cable.breaking_strength_n", "distribution": "lognormal", "mean": 5200.0, "std_dev": 500.0}
        ]}
    }})
}

fn envelope_bands(samples: usize) -> Value {
    json!({"kind": "envelope_bands", "request": {
        "cable": {"preset": "dyneema", "diameter_m": 0.006},
        "aerostat": {"net_buoyancy_n": 2000.0, "mass_kg": 100.0, "drag_coefficient_nondim": 0.3,
                     "reference_area_m2": 20.0},
        "wind": {"flow": {"kind": "power_law", "coefficient_m_s": 0.0, "exponent_nondim": 0.14, "reference_height_m": 10.0},
                 "air_density_kg_m3": 1.225},
        "wind_speeds_m_s": {"min": 0.0, "max": 30.0, "count": 7},
        "tether_lengths_m": {"min": 100.0, "max": 3000.0, "count": 6},
        "required_safety_factor_nondim": 5.0,
        "payout_rate_m_s": 5.0,
        "uncertainty": {"samples": samples, "seed": 7, "inputs": [
            {"field": "aerostat.net_buoyancy_n", "distribution": "normal", "mean": 2000.0, "std_dev": 850.0},
            {"field": "aerostat.drag_coefficient_nondim", "distribution": "uniform", "low": 0.25, "high": 0.4}
        ]}
    }})
}

/// The answer with its wall-clock field (`plan.compute_time_s` of a plan
/// bands answer: the time the nominal plan took, different at every run,
/// chunked or not) zeroed; everything else byte for byte.
fn without_wall_clock(answer: &str) -> String {
    const KEY: &str = "\"compute_time_s\":";
    let mut out = String::with_capacity(answer.len());
    let mut rest = answer;
    while let Some(at) = rest.find(KEY) {
        let (head, tail) = rest.split_at(at + KEY.len());
        out.push_str(head);
        out.push('0');
        let end = tail.find([',', '}']).unwrap_or(tail.len());
        rest = &tail[end..];
    }
    out.push_str(rest);
    out
}

fn submission(v: &Value) -> JobSubmission {
    JobSubmission::parse(&serde_json::to_vec(v).unwrap(), &Limits::default()).unwrap()
}

/// Runs every chunk of `plan` in turn and assembles them.
fn chunked(sub: &JobSubmission, plan: ChunkPlan) -> String {
    let parts: Vec<String> = (0..plan.count())
        .map(|c| sub.run_chunk(plan.range(c), &NoProgress).unwrap())
        .collect();
    sub.assemble(plan, &parts).unwrap()
}

/// For chunks of 1 item, a few items, a prime number of items and all
/// items, the assembled answer is the single-process one, byte for byte.
fn assembled_equals_single(v: &Value, items: usize) -> String {
    let sub = submission(v);
    let planned = sub.chunk_plan().expect("the kind is chunked");
    assert_eq!(planned.items, items);
    let single = sub.run(&NoProgress).unwrap();
    for per_chunk in [1, 3, 7, items / 2 + 1, items] {
        if per_chunk == 1 && items > 400 {
            continue; // one item per chunk is covered by the smaller cases
        }
        let plan = ChunkPlan { items, per_chunk };
        assert_eq!(
            without_wall_clock(&chunked(&sub, plan)),
            without_wall_clock(&single),
            "{} chunks of {per_chunk}",
            plan.count()
        );
    }
    single
}

#[test]
fn chunked_string_charts_are_the_single_process_chart() {
    let single = assembled_equals_single(&string_chart(), 1500);
    let v: Value = serde_json::from_str(&single).unwrap();
    assert_eq!(v["series"].as_array().unwrap().len(), 3);
    assert_eq!(v["series"][2]["points"].as_array().unwrap().len(), 1500);
    // And the synchronous route's function.
    let req: tetherplan::contract::dto::ChartRequest =
        tetherplan::contract::parse(&serde_json::to_vec(&string_chart()["request"]).unwrap())
            .unwrap();
    let sync = tetherplan::contract::run::chart(
        &req,
        tetherplan::numerics::parallel::Parallelism::Rayon,
        &NoProgress,
    )
    .unwrap();
    assert_eq!(single, serde_json::to_string(&sync).unwrap());
    assembled_equals_single(&converged_string_chart(), 37);
}

#[test]
fn chunked_plan_bands_are_the_single_process_plan_bands() {
    let single = assembled_equals_single(&plan_bands(300), 300);
    let v: Value = serde_json::from_str(&single).unwrap();
    let rejected = v["rejected_samples"][0]["count"].as_u64().unwrap_or(0);
    assert!(
        rejected > 0,
        "some draws are rejected: {}",
        v["rejected_samples"]
    );
    assert_eq!(v["valid_samples"].as_u64().unwrap() + rejected, 300);
    assert!(v["instants"].as_array().unwrap().len() > 2000);
}

#[test]
fn chunked_envelope_bands_are_the_single_process_envelope_bands() {
    let single = assembled_equals_single(&envelope_bands(200), 200);
    let v: Value = serde_json::from_str(&single).unwrap();
    let rejected = v["rejected_samples"][0]["count"].as_u64().unwrap_or(0);
    assert!(
        rejected > 0,
        "some draws are rejected: {}",
        v["rejected_samples"]
    );
    assert_eq!(v["cells"].as_array().unwrap().len(), 42);
}

/// The operating envelope (string criterion) over 9 winds × 8 lengths,
/// with a ceiling and a tension limit so that the per-length limits differ.
fn string_envelope() -> Value {
    json!({"kind": "envelope", "request": {
        "cable": {"preset": "dyneema", "diameter_m": 0.006},
        "aerostat": {"net_buoyancy_n": 2000.0, "mass_kg": 100.0, "drag_coefficient_nondim": 0.3,
                     "reference_area_m2": 20.0},
        "wind": {"flow": {"kind": "power_law", "coefficient_m_s": 0.0, "exponent_nondim": 0.14, "reference_height_m": 10.0},
                 "air_density_kg_m3": 1.225},
        "wind_speeds_m_s": {"min": 0.0, "max": 40.0, "count": 9},
        "tether_lengths_m": {"min": 100.0, "max": 3000.0, "count": 8},
        "required_safety_factor_nondim": 5.0,
        "ceiling_m": 2500.0,
        "payout_rate_m_s": 5.0
    }})
}

/// The envelope judged by the quasi-static GE (Table 7.1 cable, as
/// tests/verification_envelope_ge.rs), 3 winds × 4 lengths across the
/// calm-air onset near 1252 m.
fn ge_envelope() -> Value {
    json!({"kind": "envelope", "request": {
        "cable": {"mass_per_length_kg_m": 0.078, "diameter_m": 0.0036,
                  "normal_drag_coefficient_nondim": 1.2},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0, "drag_coefficient_nondim": 0.3,
                     "reference_area_m2": 3.0},
        "wind": {"flow": {"kind": "uniform", "speed_m_s": 0.0}, "air_density_kg_m3": 1.225},
        "wind_speeds_m_s": {"min": 0.0, "max": 10.0, "count": 3},
        "tether_lengths_m": {"min": 1150.0, "max": 1300.0, "count": 4},
        "required_safety_factor_nondim": 1.0,
        "payout_rate_m_s": 30.0,
        "stability": {"method": "quasi_static_ge", "bending_stiffness_n_m2": 10.0,
                      "elements": 10, "critical_rate_length_m": 1150.0}
    }})
}

#[test]
fn chunked_envelopes_are_the_single_process_envelope() {
    let single = assembled_equals_single(&string_envelope(), 9);
    let v: Value = serde_json::from_str(&single).unwrap();
    assert_eq!(v["points"].as_array().unwrap().len(), 72);
    // The per-length limits need every row: some lengths are limited by a
    // wind in the grid, others are inside up to the strongest wind or
    // outside at calm air.
    let limits = v["max_wind_per_length"].as_array().unwrap();
    let winds: Vec<Option<f64>> = limits
        .iter()
        .map(|l| l["max_wind_speed_m_s"].as_f64())
        .collect();
    assert!(
        winds.iter().any(|w| w.is_some_and(|w| w > 0.0 && w < 40.0)),
        "{winds:?}"
    );
    assert!(limits.iter().any(|l| l["binding_limit"].is_string()));

    let single = assembled_equals_single(&ge_envelope(), 3);
    let v: Value = serde_json::from_str(&single).unwrap();
    assert_eq!(
        v["quasi_static_ge"]["per_wind"].as_array().unwrap().len(),
        3
    );
    // In calm air the 10-element onset (1288.6 m) lies inside the grid:
    // the calm row has stable and unstable cells.
    let calm: Vec<bool> = v["points"].as_array().unwrap()[..4]
        .iter()
        .map(|p| p["stable"].as_bool().unwrap())
        .collect();
    assert_eq!(calm, [true, true, true, false], "{calm:?}");
}

struct Db {
    dir: std::path::PathBuf,
}

impl Db {
    fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!(
            "tetherplan-chunk-kinds-{name}-{}",
            std::process::id()
        ));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Self { dir }
    }
    fn queue(&self, limits: Limits) -> JobQueue {
        let store = JobStore::open(&self.dir.join("jobs.db")).unwrap();
        JobQueue::new(store, 1, limits)
    }
    /// (index, status, attempts) of every chunk of `job`.
    fn chunk_rows(&self, job: i64) -> Vec<(i64, String, i64)> {
        let conn = rusqlite::Connection::open(self.dir.join("jobs.db")).unwrap();
        let mut stmt = conn
            .prepare("SELECT idx, status, attempts FROM job_chunks WHERE job_id = ?1 ORDER BY idx")
            .unwrap();
        stmt.query_map([job], |r| Ok((r.get(0)?, r.get(1)?, r.get(2)?)))
            .unwrap()
            .collect::<Result<_, _>>()
            .unwrap()
    }
}

impl Drop for Db {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// Runs `v` as a job (one worker thread) while this thread reads its
/// progress; checks the split, every chunk done once, progress in whole
/// chunks, and returns the stored answer.
fn run_as_job(name: &str, v: &Value) -> String {
    let db = Db::new(name);
    let mut queue = db.queue(Limits::default());
    queue.progress_interval = Duration::ZERO;
    let queue = Arc::new(queue);
    let (id, _) = queue.submit(&serde_json::to_vec(v).unwrap()).unwrap();
    let worker = {
        let queue = queue.clone();
        std::thread::spawn(move || {
            let mut steps = 0;
            while work_once(&queue).unwrap() {
                steps += 1;
                assert!(steps < 10_000);
            }
        })
    };
    let reader = db.queue(Limits::default());
    let mut seen = Vec::new();
    while !worker.is_finished() {
        let p = reader.store.get(id).unwrap().unwrap().progress;
        if seen.last() != Some(&p) {
            seen.push(p);
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    worker.join().unwrap();
    let rec = queue.store.get(id).unwrap().unwrap();
    assert_eq!(rec.status, JobStatus::Done, "{:?}", rec.error);
    assert_eq!(rec.progress, 1.0);
    let rows = db.chunk_rows(id);
    let n = rows.len();
    assert!(n >= 4, "{name}: split into {n} chunks");
    assert_eq!(
        rows.iter().map(|r| r.0).collect::<Vec<_>>(),
        (0..n as i64).collect::<Vec<_>>()
    );
    assert!(rows.iter().all(|r| r.1 == "done" && r.2 == 1), "{rows:?}");
    let partial: Vec<f64> = seen
        .iter()
        .copied()
        .filter(|p| *p > 0.0 && *p < 1.0)
        .collect();
    assert!(
        !partial.is_empty(),
        "{name}: progress read mid-run: {seen:?}"
    );
    for p in &partial {
        let k = p * n as f64;
        assert!(
            (k - k.round()).abs() < 1e-9,
            "{name}: progress {p} is not a whole number of the {n} chunks ({seen:?})"
        );
    }
    eprintln!("{name}: {n} chunks, progress read {seen:?}");
    rec.result.unwrap()
}

#[test]
fn new_kinds_run_as_chunked_jobs_with_progress_in_chunks() {
    for (name, v) in [
        ("string_chart", string_chart()),
        ("plan_bands", plan_bands(3000)),
        ("envelope_bands", envelope_bands(600)),
    ] {
        let stored = run_as_job(name, &v);
        let single = submission(&v).run(&NoProgress).unwrap();
        assert_eq!(
            without_wall_clock(&stored),
            without_wall_clock(&single),
            "{name}"
        );
    }
}

/// A bands job with chunks of about 3 s (2 000 elements, 4 rates).
fn long_bands() -> Value {
    json!({"kind": "bands", "request": {
        "cable": {"mass_per_length_kg_m": 0.078},
        "aerostat": {"net_buoyancy_n": 1000.0},
        "model": {"elements": 2000},
        "rates_m_s": [5.0, 10.0, 15.0, 20.0, 25.0, 30.0, 35.0, 40.0],
        "target_elevation_m": 100.0,
        "uncertainty": {"samples": 20000, "seed": 3, "inputs": [
            {"field": "aerostat.net_buoyancy_n", "distribution": "normal", "mean": 1000.0, "std_dev": 50.0}
        ]}
    }})
}

#[test]
fn cancelling_a_job_stops_its_running_chunks_promptly() {
    let db = Db::new("cancel");
    cancel_scenario(&|limits| db.queue(limits.clone()), &|id| db.chunk_rows(id));
}

/// PostgreSQL (`TETHERPLAN_TEST_PG_URL`, default
/// `postgres://postgres:postgres@127.0.0.1:5432/postgres`): the same, on a
/// database of its own; skipped (with the reason printed) when PostgreSQL
/// is unreachable, unless `CI` is set.
#[test]
fn cancelling_a_job_stops_its_running_chunks_promptly_on_postgres() {
    let admin_url = std::env::var("TETHERPLAN_TEST_PG_URL")
        .unwrap_or_else(|_| "postgres://postgres:postgres@127.0.0.1:5432/postgres".into());
    let mut admin = match postgres::Client::connect(&admin_url, postgres::NoTls) {
        Ok(c) => c,
        Err(e) => {
            assert!(
                std::env::var_os("CI").is_none(),
                "PostgreSQL unreachable at {admin_url} with CI set: {e}"
            );
            eprintln!("SKIPPED: PostgreSQL unreachable at {admin_url} ({e})");
            return;
        }
    };
    let name = format!("tetherplan_test_cancel_{}", std::process::id());
    admin
        .batch_execute(&format!("DROP DATABASE IF EXISTS {name} WITH (FORCE)"))
        .unwrap();
    admin
        .batch_execute(&format!("CREATE DATABASE {name}"))
        .unwrap();
    let url = format!("{}/{name}", admin_url.rsplit_once('/').unwrap().0);
    let outcome = std::panic::catch_unwind(|| {
        let rows = |id: i64| -> Vec<(i64, String, i64)> {
            let mut c = postgres::Client::connect(&url, postgres::NoTls).unwrap();
            c.query(
                "SELECT idx, status, attempts FROM job_chunks WHERE job_id = $1 ORDER BY idx",
                &[&id],
            )
            .unwrap()
            .iter()
            .map(|r| {
                (
                    r.get::<_, i32>(0) as i64,
                    r.get::<_, String>(1),
                    r.get::<_, i32>(2) as i64,
                )
            })
            .collect()
        };
        cancel_scenario(
            &|limits| {
                let store = tetherplan::jobs::postgres::PgStore::open(&url).unwrap();
                JobQueue::new(store, 1, limits.clone())
            },
            &rows,
        );
    });
    let _ = admin.batch_execute(&format!("DROP DATABASE IF EXISTS {name} WITH (FORCE)"));
    if let Err(e) = outcome {
        std::panic::resume_unwind(e);
    }
}

/// Two worker "processes" (queues of one thread) and an API (a third
/// queue) on one database: a long chunked job is cancelled while both
/// workers run one of its chunks.
fn cancel_scenario(
    queue: &dyn Fn(&Limits) -> JobQueue,
    chunk_rows: &dyn Fn(i64) -> Vec<(i64, String, i64)>,
) {
    // A long lease: renewals every 20 s would be far too late.
    let limits = Limits {
        job_lease: Duration::from_secs(60),
        ..Limits::default()
    };
    let renewal = limits.job_lease / 3;
    let v = long_bands();
    let sub = submission(&v);
    let plan = sub.chunk_plan().unwrap();
    assert!(plan.count() >= 4, "{plan:?}");
    // How long one chunk takes uncancelled, on this machine now (from a
    // quarter of it: its first samples; a tenth read noisily, 1.0–2.2 s).
    let quarter = plan.range(0).start..plan.range(0).start + plan.per_chunk / 4;
    let t = Instant::now();
    sub.run_chunk(quarter, &NoProgress).unwrap();
    let chunk_s = t.elapsed().as_secs_f64() * 4.0;

    let stop = AtomicBool::new(false);
    let (ended_tx, ended_rx) = mpsc::channel::<Instant>();
    std::thread::scope(|scope| {
        for _ in 0..2 {
            let q = queue(&limits);
            let (stop, ended) = (&stop, ended_tx.clone());
            scope.spawn(move || {
                while !stop.load(Ordering::Relaxed) {
                    let t = Instant::now();
                    if work_once(&q).unwrap() {
                        if t.elapsed() > Duration::from_millis(200) {
                            ended.send(Instant::now()).unwrap();
                        }
                    } else {
                        std::thread::sleep(Duration::from_millis(20));
                    }
                }
            });
        }
        // Stops the workers however this scope ends (a failed assertion too).
        struct StopOnDrop<'a>(&'a AtomicBool);
        impl Drop for StopOnDrop<'_> {
            fn drop(&mut self) {
                self.0.store(true, Ordering::Relaxed);
            }
        }
        let _stop = StopOnDrop(&stop);
        let api = queue(&limits);
        let (id, _) = api.submit(&serde_json::to_vec(&v).unwrap()).unwrap();
        // Wait until both workers run a chunk (the coordinator one of its own).
        let start = Instant::now();
        loop {
            let rows = chunk_rows(id);
            if rows.iter().filter(|r| r.1 == "running").count() == 2 {
                break;
            }
            assert!(start.elapsed() < Duration::from_secs(30), "{rows:?}");
            std::thread::sleep(Duration::from_millis(5));
        }
        std::thread::sleep(Duration::from_millis(300));
        let before = chunk_rows(id);
        let cancelled_at = Instant::now();
        let rec = api.cancel(id, None).unwrap().unwrap();
        assert_eq!(rec.status, JobStatus::Cancelled);
        // Both workers' steps end: the coordinator (its chunk, then itself)
        // and the other worker's chunk.
        let mut latencies = Vec::new();
        for _ in 0..2 {
            let ended = ended_rx.recv_timeout(Duration::from_secs(60)).unwrap();
            latencies.push(ended.saturating_duration_since(cancelled_at));
        }
        // Let the workers look for work a while longer.
        std::thread::sleep(Duration::from_millis(500));
        stop.store(true, Ordering::Relaxed);
        let slowest = latencies.iter().max().unwrap().as_secs_f64();
        eprintln!(
            "{}: cancel → running chunks stopped in {latencies:?}; a chunk takes about              {chunk_s:.1} s, renewal every {renewal:?}, status read every {CANCEL_POLL:?}",
            api.store.store_kind()
        );
        // Bound: a status poll, the coordinator's 50 ms loop and a progress
        // write, with margin; well under the renewal interval and under what
        // was left of the running chunks.
        // The bound is also at most half a chunk (measured above: about
        // 2–3 s on a quiet machine, 5–13 s loaded), so a chunk that ran to
        // its end could not pass; stops measured 0.05–0.21 s.
        let bound = (0.5 * chunk_s).min(1.5);
        assert!(
            bound >= 0.5,
            "a chunk ({chunk_s:.1} s) is long enough for the bound to tell"
        );
        assert!(
            slowest < bound,
            "the running chunks stopped {slowest:.2} s after the cancel (bound {bound:.2} s)"
        );
        assert!(bound < renewal.as_secs_f64() / 10.0);
        let after = chunk_rows(id);
        assert_eq!(
            api.store.get(id).unwrap().unwrap().status,
            JobStatus::Cancelled
        );
        assert!(after.iter().all(|r| r.1 != "done"), "{after:?}");
        for (b, a) in before.iter().zip(&after) {
            assert_eq!(
                b.2, a.2,
                "no chunk claimed after the cancel: {before:?} → {after:?}"
            );
        }
        assert_eq!(after.iter().filter(|r| r.2 > 0).count(), 2, "{after:?}");
    });
}
