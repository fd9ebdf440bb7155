//! The chunk engine on SQLite, in one process: a GE chart, a bands and a
//! batch job split into chunks give exactly the single-process answer
//! (same JSON text); progress counts chunks; short jobs pass chunked ones;
//! a cancelled job's pending chunks are never claimed.

use std::time::Duration;

use serde_json::{Value, json};
use tetherplan::config::Limits;
use tetherplan::contract::ge_charts::{self, GeChartRequest};
use tetherplan::contract::run::NoProgress;
use tetherplan::jobs::kinds::JobSubmission;
use tetherplan::jobs::store::{ClaimPolicy, JobStatus, JobStore};
use tetherplan::jobs::{JobQueue, work_once};
use tetherplan::numerics::parallel::Parallelism;

fn ge_chart_request() -> Value {
    json!({
        "cable": {"density_kg_m3": 7800.0, "area_m2": 1e-5},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
        "initial_length_m": 1.0,
        "model": {"kind": "geometrically_exact", "elements": 10, "bending_stiffness_n_m2": 1000.0, "inertia_ratio": 1.0},
        "stiffness_ratios": [1e4, 1e5],
        "rates_m_s": {"min": 70.0, "max": 110.0, "count": 40},
        "numerics": {"horizon_s": 20.0}
    })
}

fn bands_request() -> Value {
    json!({
        "cable": {"mass_per_length_kg_m": 0.078},
        "aerostat": {"net_buoyancy_n": 1000.0},
        "model": {"elements": 500},
        "rates_m_s": [5.0, 10.0, 20.0, 40.0],
        "target_elevation_m": 100.0,
        "uncertainty": {"samples": 1600, "seed": 7, "inputs": [
            {"field": "aerostat.net_buoyancy_n", "distribution": "normal", "mean": 1000.0, "std_dev": 50.0},
            {"field": "cable.mass_per_length_kg_m", "distribution": "uniform", "low": 0.07, "high": 0.09}
        ]}
    })
}

struct Db {
    dir: std::path::PathBuf,
}

impl Db {
    fn new(name: &str) -> Self {
        let dir =
            std::env::temp_dir().join(format!("tetherplan-chunks-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Self { dir }
    }
    fn queue(&self) -> JobQueue {
        let store = JobStore::open(&self.dir.join("jobs.db")).unwrap();
        JobQueue::new(store, 2, Limits::default())
    }
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

/// Submits and drains; the stored answer and the chunk rows.
fn run_job(db: &Db, submission: &Value) -> (String, Vec<(i64, String, i64)>) {
    let queue = db.queue();
    let (id, _) = queue
        .submit(&serde_json::to_vec(submission).unwrap())
        .unwrap();
    let mut steps = 0;
    while work_once(&queue).unwrap() {
        steps += 1;
        assert!(steps < 10_000);
    }
    let rec = queue.store.get(id).unwrap().unwrap();
    assert_eq!(rec.status, JobStatus::Done, "{:?}", rec.error);
    assert_eq!(rec.progress, 1.0);
    (rec.result.unwrap(), db.chunk_rows(id))
}

fn all_done_once(rows: &[(i64, String, i64)]) {
    let idx: Vec<i64> = rows.iter().map(|r| r.0).collect();
    assert_eq!(idx, (0..rows.len() as i64).collect::<Vec<_>>());
    assert!(rows.iter().all(|r| r.1 == "done" && r.2 == 1), "{rows:?}");
}

#[test]
fn a_chunked_ge_chart_is_the_single_process_chart() {
    let db = Db::new("ge");
    let (result, rows) = run_job(
        &db,
        &json!({"kind": "chart", "request": ge_chart_request()}),
    );
    assert!(rows.len() >= 4, "split into {} chunks", rows.len());
    all_done_once(&rows);
    let req: GeChartRequest = serde_json::from_value(ge_chart_request()).unwrap();
    let single = ge_charts::ge_chart(&req, Parallelism::Serial, &NoProgress).unwrap();
    assert_eq!(result, serde_json::to_string(&single).unwrap());
}

#[test]
fn chunked_bands_are_the_single_process_bands() {
    let db = Db::new("bands");
    let (result, rows) = run_job(&db, &json!({"kind": "bands", "request": bands_request()}));
    assert!(rows.len() >= 4, "split into {} chunks", rows.len());
    all_done_once(&rows);
    let req =
        tetherplan::contract::bands::parse_bands(&serde_json::to_vec(&bands_request()).unwrap())
            .unwrap();
    let single = tetherplan::contract::bands::bands(&req, Parallelism::Rayon, &NoProgress).unwrap();
    assert_eq!(result, serde_json::to_string(&single).unwrap());
}

#[test]
fn a_chunked_batch_is_the_single_process_batch() {
    let db = Db::new("batch");
    let item = |rate: f64| {
        json!({"kind": "critical", "request": {
            "cable": {"mass_per_length_kg_m": 0.078}, "aerostat": {"net_buoyancy_n": 1000.0},
            "profile": {"kind": "constant_rate", "rate_m_s": rate}}})
    };
    let mut items: Vec<Value> = (1..=20).map(|i| item(i as f64)).collect();
    items.push(json!({"kind": "chart", "request": ge_chart_request()}));
    let body = json!({"kind": "batch", "request": items});
    let bytes = serde_json::to_vec(&body).unwrap();
    let sub = JobSubmission::parse(&bytes, &Limits::default()).unwrap();
    let plan = sub.chunk_plan().unwrap();
    let (result, rows) = run_job(&db, &body);
    assert_eq!(rows.len().max(1), plan.count());
    let single = sub.run(&NoProgress).unwrap();
    assert_eq!(result, single);
}

#[test]
fn short_jobs_pass_chunked_ones_and_cancelled_chunks_are_not_claimed() {
    let db = Db::new("prio");
    let queue = db.queue();
    let long = json!({"kind": "chart", "request": ge_chart_request()});
    let short = json!({"kind": "critical", "request": {
        "cable": {"mass_per_length_kg_m": 0.078}, "aerostat": {"net_buoyancy_n": 1000.0},
        "profile": {"kind": "constant_rate", "rate_m_s": 10.0}}});
    let (long_id, _) = queue.submit(&serde_json::to_vec(&long).unwrap()).unwrap();
    let (short_id, _) = queue.submit(&serde_json::to_vec(&short).unwrap()).unwrap();
    let policy = ClaimPolicy {
        lease: Duration::from_secs(30),
        max_attempts: 3,
        exhausted_error: "{}",
    };
    let first = queue.store.claim(&policy).unwrap().unwrap();
    assert_eq!(first.id, short_id, "the short job is claimed first");
    assert!(queue.store.finish_done(&first.lease, "{}").unwrap());
    let second = queue.store.claim(&policy).unwrap().unwrap();
    assert_eq!(second.id, long_id);
    assert!(queue.store.create_chunks(&second.lease, 5).unwrap());
    let chunk = queue.store.claim_chunk(None, &policy).unwrap().unwrap();
    assert_eq!((chunk.lease.job_id, chunk.lease.index), (long_id, 0));
    // A second claim of chunk 0's lease epoch is refused after a takeover.
    assert!(
        queue
            .store
            .renew_chunk(&chunk.lease, Duration::from_secs(30))
            .unwrap()
    );
    queue.cancel(long_id, None).unwrap();
    assert!(
        queue.store.claim_chunk(None, &policy).unwrap().is_none(),
        "no chunk of a cancelled job is claimed"
    );
    assert!(
        !queue
            .store
            .renew_chunk(&chunk.lease, Duration::from_secs(30))
            .unwrap(),
        "the running chunk of a cancelled job loses its lease"
    );
    assert!(!queue.store.finish_chunk(&chunk.lease, "[]").unwrap());
    let state = queue.store.chunk_state(long_id).unwrap();
    assert_eq!((state.total, state.done), (5, 0));
}

#[test]
fn plans_cover_every_item_once() {
    use tetherplan::jobs::chunks::{CHUNK_TARGET_S, ChunkPlan, MIN_CHUNKS, MIN_SPLIT_JOB_S};
    for items in [1usize, 2, 7, 100, 4097, 10_000] {
        for cost in [1e-6, 0.01, 0.8, 5.0] {
            let plan = ChunkPlan::for_cost(items, cost);
            let mut next = 0;
            for c in 0..plan.count() {
                let r = plan.range(c);
                assert_eq!(r.start, next);
                assert!(!r.is_empty());
                next = r.end;
            }
            assert_eq!(next, items, "{items} items at {cost} s");
            if items as f64 * cost >= MIN_SPLIT_JOB_S {
                assert!(plan.per_chunk as f64 * cost <= CHUNK_TARGET_S.max(cost) + 1e-9);
                assert!(plan.count() >= MIN_CHUNKS.min(items), "{plan:?}");
            } else {
                assert_eq!(plan.count(), 1);
            }
        }
    }
}
