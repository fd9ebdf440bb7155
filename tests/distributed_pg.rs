//! Scale-out over PostgreSQL: real `tetherplan serve` (API only,
//! `TETHERPLAN_JOB_THREADS=0`) and `tetherplan worker` processes (one
//! rayon thread each) on one database, 2 s leases.
//!
//! * A GE chart job, then a bands job, split into chunks, with the worker
//!   running a chunk SIGKILLed mid-run: the job finishes, its chunks are
//!   exactly `0..n`, each done once (the killed one by another worker,
//!   after its lease expired), and the answer is the single-process one,
//!   byte for byte (bands: also the SQLite job's answer for the same seed).
//! * Killing an API process loses nothing; two API processes share the
//!   database; a worker stopped by SIGTERM hands its chunk back and leaves
//!   the live workers; `/healthz` counts them.
//!
//! Each test uses a database of its own (created, then dropped). Without a
//! reachable PostgreSQL (`TETHERPLAN_TEST_PG_URL`, default
//! `postgres://postgres:postgres@127.0.0.1:5432/postgres`) the tests print
//! why and pass, unless `CI` is set: then they fail.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::{Value, json};
use tetherplan::contract::ge_charts::{self, GeChartRequest};
use tetherplan::contract::run::NoProgress;
use tetherplan::numerics::parallel::Parallelism;

mod common;
use common::pg::TestDb;

const LEASE_S: &str = "2";

/// A done job's answer as the database keeps it: its pages, in order.
const STORED_ANSWER: &str = "SELECT convert_from(string_agg(data, ''::BYTEA ORDER BY page), 'UTF8')
    FROM job_answers WHERE job_id = $1";

/// A child process killed (SIGKILL) when dropped.
struct Proc {
    child: Child,
    /// The API address, or the worker id.
    first_line: String,
}

impl Proc {
    fn api(url: &str) -> Self {
        let dir = std::env::temp_dir();
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_tetherplan"));
        cmd.args(["serve", "--addr", "127.0.0.1:0", "--database-url", url])
            .arg("--static-dir")
            .arg(dir)
            .env("TETHERPLAN_JOB_THREADS", "0");
        Self::spawn(cmd, "tetherplan listening on http://")
    }

    fn worker(url: &str) -> Self {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_tetherplan"));
        cmd.args(["worker", "--database-url", url])
            .env("TETHERPLAN_JOB_THREADS", "1")
            .env("RAYON_NUM_THREADS", "1");
        Self::spawn(cmd, "tetherplan worker ")
    }

    fn spawn(mut cmd: Command, prefix: &str) -> Self {
        let mut child = cmd
            .env("RUST_LOG", "warn")
            .env("TETHERPLAN_JOB_LEASE_S", LEASE_S)
            .env_remove("TETHERPLAN_DB")
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("the process starts");
        let mut line = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut line)
            .unwrap();
        let first_line = line
            .trim()
            .strip_prefix(prefix)
            .unwrap_or_else(|| panic!("unexpected first line {line:?}"))
            .to_string();
        Self { child, first_line }
    }

    fn addr(&self) -> SocketAddr {
        self.first_line.parse().unwrap()
    }

    fn pid(&self) -> u32 {
        self.child.id()
    }

    fn kill(mut self) {
        self.child.kill().unwrap();
        self.child.wait().unwrap();
    }

    /// SIGTERM, then the exit status (within `within`).
    fn terminate(mut self, within: Duration) -> std::process::ExitStatus {
        // SAFETY: kill(2) on the pid of our own child.
        unsafe { libc::kill(self.child.id() as libc::pid_t, libc::SIGTERM) };
        let start = Instant::now();
        loop {
            if let Some(status) = self.child.try_wait().unwrap() {
                return status;
            }
            assert!(
                start.elapsed() < within,
                "no exit within {within:?} of SIGTERM"
            );
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    fn request(&self, method: &str, path: &str, body: Option<&Value>) -> (u16, Value) {
        let (status, text) = self.request_text(method, path, body);
        (status, serde_json::from_str(&text).unwrap_or(Value::Null))
    }

    fn request_text(&self, method: &str, path: &str, body: Option<&Value>) -> (u16, String) {
        let addr = self.addr();
        let body = body
            .map(|b| serde_json::to_vec(b).unwrap())
            .unwrap_or_default();
        let mut s = TcpStream::connect(addr).unwrap();
        s.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
        let head = format!(
            "{method} {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\nContent-Type: application/json\r\nContent-Length: {}\r\n\r\n",
            body.len()
        );
        s.write_all(head.as_bytes()).unwrap();
        s.write_all(&body).unwrap();
        let mut raw = Vec::new();
        s.read_to_end(&mut raw).unwrap();
        let split = raw.windows(4).position(|w| w == b"\r\n\r\n").unwrap();
        let head = String::from_utf8_lossy(&raw[..split]).to_string();
        let status = head.split(' ').nth(1).unwrap().parse().unwrap();
        let mut body = raw[split + 4..].to_vec();
        if head
            .to_ascii_lowercase()
            .contains("transfer-encoding: chunked")
        {
            body = dechunk(&body);
        }
        (status, String::from_utf8(body).unwrap())
    }

    fn submit(&self, body: &Value) -> i64 {
        let (status, v) = self.request("POST", "/api/v1/jobs", Some(body));
        assert_eq!(status, 202, "{v}");
        v["id"].as_i64().unwrap()
    }

    /// Polls until the job is finished; its view.
    fn wait_finished(&self, id: i64, within: Duration) -> Value {
        let start = Instant::now();
        loop {
            let (_, v) = self.request("GET", &format!("/api/v1/jobs/{id}"), None);
            if matches!(v["status"].as_str(), Some("done" | "failed" | "cancelled")) {
                return v;
            }
            assert!(start.elapsed() < within, "job {id} not finished: {v}");
            std::thread::sleep(Duration::from_millis(100));
        }
    }
}

impl Drop for Proc {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn dechunk(mut b: &[u8]) -> Vec<u8> {
    let mut out = vec![];
    loop {
        let eol = b.windows(2).position(|w| w == b"\r\n").unwrap();
        let size =
            usize::from_str_radix(std::str::from_utf8(&b[..eol]).unwrap().trim(), 16).unwrap();
        if size == 0 {
            return out;
        }
        out.extend_from_slice(&b[eol + 2..eol + 2 + size]);
        b = &b[eol + 4 + size..];
    }
}

fn pid_of(worker: &str) -> u32 {
    worker.rsplit('/').nth(1).unwrap().parse().unwrap()
}

/// A chunk row: index, status, attempts, lease owner, finished by.
type ChunkRow = (i32, String, i32, Option<String>, Option<String>);

fn chunks(db: &mut postgres::Client, job: i64) -> Vec<ChunkRow> {
    db.query(
        "SELECT idx, status, attempts, lease_owner, finished_by FROM job_chunks
         WHERE job_id = $1 ORDER BY idx",
        &[&job],
    )
    .unwrap()
    .iter()
    .map(|r| (r.get(0), r.get(1), r.get(2), r.get(3), r.get(4)))
    .collect()
}

/// A small GE chart: 10 elements, fast rates (each point a fraction of a second).
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

/// Bands over a string chart, seeded.
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

/// Runs `job` (submitted via `api`, 3 workers on `db`), SIGKILLs the worker
/// of a running chunk once some chunk is done, and checks that every chunk
/// is done exactly once; returns the job's stored answer (JSON text).
///
/// A worker can finish its chunk between the poll that sees it running and
/// the kill. Then it holds nothing when it dies, so the kill proves nothing:
/// a fresh worker takes its place and another running chunk's worker is
/// killed, until a dead worker is seen holding a chunk.
fn run_with_a_killed_worker(db: &TestDb, job: &Value) -> String {
    let api = Proc::api(&db.url);
    let mut workers: Vec<Option<Proc>> = (0..3).map(|_| Some(Proc::worker(&db.url))).collect();
    let mut pg = db.client();
    let id = api.submit(job);
    let start = Instant::now();
    let (victim_id, orphans) = 'kill: loop {
        // Mid-run: a chunk done, another held by a live worker.
        let (victim_id, victim) = loop {
            let rows = chunks(&mut pg, id);
            let done = rows.iter().filter(|r| r.1 == "done").count();
            let held = rows.iter().filter(|r| r.1 == "running").find_map(|r| {
                let owner = r.3.clone()?;
                let index = workers
                    .iter()
                    .position(|w| w.as_ref().is_some_and(|w| w.pid() == pid_of(&owner)))?;
                Some((owner, index))
            });
            if done >= 1
                && done + 2 <= rows.len()
                && let Some(held) = held
            {
                break held;
            }
            assert!(
                start.elapsed() < Duration::from_secs(90),
                "never mid-run: {rows:?}"
            );
            std::thread::sleep(Duration::from_millis(20));
        };
        workers[victim].take().unwrap().kill();
        let orphans: Vec<i32> = chunks(&mut pg, id)
            .iter()
            .filter(|r| r.1 == "running" && r.3.as_deref() == Some(victim_id.as_str()))
            .map(|r| r.0)
            .collect();
        if !orphans.is_empty() {
            break 'kill (victim_id, orphans);
        }
        eprintln!("{victim_id} finished its chunk before the kill; killing another");
        workers.push(Some(Proc::worker(&db.url)));
    };
    let n = chunks(&mut pg, id).len();
    assert!(n >= 4, "the job is split into {n} chunks");
    let v = api.wait_finished(id, Duration::from_secs(120));
    assert_eq!(v["status"], "done", "{v}");
    assert_eq!(v["progress"], 1.0);
    let rows = chunks(&mut pg, id);
    let indices: Vec<i32> = rows.iter().map(|r| r.0).collect();
    assert_eq!(indices, (0..n as i32).collect::<Vec<_>>(), "none lost");
    assert!(
        rows.iter().all(|r| r.1 == "done"),
        "every chunk done once: {rows:?}"
    );
    for &chunk in &orphans {
        let killed = &rows[chunk as usize];
        assert!(
            killed.2 >= 2,
            "the killed chunk was claimed again: {killed:?}"
        );
        assert_ne!(
            killed.4.as_deref(),
            Some(victim_id.as_str()),
            "the dead worker wrote nothing"
        );
    }
    let victim_chunk = orphans[0];
    let retried = rows.iter().filter(|r| r.2 >= 2).count();
    eprintln!("{n} chunks, {retried} retried after SIGKILL of {victim_id} (chunk {victim_chunk})");
    // The one stored answer is the one the API serves.
    let (status, text) = api.request_text("GET", &format!("/api/v1/jobs/{id}"), None);
    assert_eq!(status, 200);
    let stored: String = pg.query_one(STORED_ANSWER, &[&id]).unwrap().get(0);
    assert!(text.contains(&stored));
    stored
}

#[test]
fn a_ge_chart_job_survives_a_killed_worker_and_equals_the_single_process_chart() {
    let Some(db) = TestDb::create("ge_chart") else {
        return;
    };
    let request = ge_chart_request();
    let stored = run_with_a_killed_worker(&db, &json!({"kind": "chart", "request": request}));
    let req: GeChartRequest = serde_json::from_value(request).unwrap();
    let single = ge_charts::ge_chart(&req, Parallelism::Rayon, &NoProgress).unwrap();
    assert_eq!(stored, serde_json::to_string(&single).unwrap());
}

#[test]
fn a_bands_job_survives_a_killed_worker_and_equals_the_sqlite_run() {
    let Some(db) = TestDb::create("bands") else {
        return;
    };
    let submission = json!({"kind": "bands", "request": bands_request()});
    let stored = run_with_a_killed_worker(&db, &submission);
    // The same submission as a job on SQLite, in this process.
    let dir = std::env::temp_dir().join(format!("tetherplan-bands-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let store = tetherplan::jobs::store::JobStore::open(&dir.join("jobs.db")).unwrap();
    let queue = tetherplan::jobs::JobQueue::new(store, 2, Default::default());
    let (id, _) = queue
        .submit(&serde_json::to_vec(&submission).unwrap())
        .unwrap();
    while tetherplan::jobs::work_once(&queue).unwrap() {}
    let rec = queue.store.get(id).unwrap().unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(rec.status, tetherplan::jobs::store::JobStatus::Done);
    assert_eq!(rec.result.as_deref(), Some(stored.as_str()));
    // And the synchronous answer.
    let req =
        tetherplan::contract::bands::parse_bands(&serde_json::to_vec(&bands_request()).unwrap())
            .unwrap();
    let single = tetherplan::contract::bands::bands(&req, Parallelism::Rayon, &NoProgress).unwrap();
    assert_eq!(stored, serde_json::to_string(&single).unwrap());
}

#[test]
fn killing_an_api_loses_nothing_and_two_apis_share_the_database() {
    let Some(db) = TestDb::create("apis") else {
        return;
    };
    let a = Proc::api(&db.url);
    let b = Proc::api(&db.url);
    let critical = json!({"kind": "critical", "request": {
        "cable": {"mass_per_length_kg_m": 0.078}, "aerostat": {"net_buoyancy_n": 1000.0},
        "profile": {"kind": "constant_rate", "rate_m_s": 10.0}}});
    let chart = json!({"kind": "chart", "request": ge_chart_request()});
    // No worker yet: everything stays queued while A is killed.
    let ids: Vec<i64> = vec![a.submit(&critical), a.submit(&chart), b.submit(&critical)];
    a.kill();
    let (_, health) = b.request("GET", "/healthz", None);
    assert_eq!(health["store"], "postgres", "{health}");
    assert_eq!(health["live_workers"], 0, "{health}");
    let (_, list) = b.request("GET", "/api/v1/jobs", None);
    let listed: Vec<i64> = list["jobs"]
        .as_array()
        .unwrap_or_else(|| panic!("{list}"))
        .iter()
        .map(|j| j["id"].as_i64().unwrap())
        .collect();
    for id in &ids {
        assert!(listed.contains(id), "job {id} survives: {list}");
    }
    let workers: Vec<Proc> = (0..2).map(|_| Proc::worker(&db.url)).collect();
    let start = Instant::now();
    loop {
        let (_, health) = b.request("GET", "/healthz", None);
        if health["live_workers"] == 2 {
            break;
        }
        assert!(start.elapsed() < Duration::from_secs(10), "{health}");
        std::thread::sleep(Duration::from_millis(100));
    }
    // A restarted API sees the same jobs as B.
    let a = Proc::api(&db.url);
    for id in &ids {
        let v = b.wait_finished(*id, Duration::from_secs(120));
        assert_eq!(v["status"], "done", "{v}");
        let (_, w) = a.request("GET", &format!("/api/v1/jobs/{id}"), None);
        assert_eq!(v["result"], w["result"]);
    }
    // A worker stopped by SIGTERM in the middle of a chunk hands it back
    // (or finishes it) and leaves the live workers.
    let id = a.submit(&chart);
    let mut pg = db.client();
    let start = Instant::now();
    while !chunks(&mut pg, id).iter().any(|r| r.1 == "running") {
        assert!(start.elapsed() < Duration::from_secs(60));
        std::thread::sleep(Duration::from_millis(20));
    }
    let mut workers = workers.into_iter();
    let first = workers.next().unwrap();
    let first_id = first.first_line.clone();
    let status = first.terminate(Duration::from_secs(25));
    assert!(status.success(), "{status:?}");
    let held: i64 = pg
        .query_one(
            "SELECT count(*) FROM job_chunks WHERE status = 'running' AND lease_owner = $1",
            &[&first_id],
        )
        .unwrap()
        .get(0);
    assert_eq!(held, 0, "a stopped worker holds no chunk");
    let (_, health) = a.request("GET", "/healthz", None);
    assert_eq!(health["live_workers"], 1, "{health}");
    let v = a.wait_finished(id, Duration::from_secs(120));
    assert_eq!(v["status"], "done", "{v}");
    let req: GeChartRequest = serde_json::from_value(ge_chart_request()).unwrap();
    let single = ge_charts::ge_chart(&req, Parallelism::Rayon, &NoProgress).unwrap();
    assert_eq!(v["result"], serde_json::to_value(&single).unwrap());
}

/// Envelope bands, seeded, with draws out of range (rejected and counted):
/// about 3 s of work on one core, split into chunks.
fn envelope_bands_request() -> Value {
    json!({
        "cable": {"preset": "dyneema", "diameter_m": 0.006},
        "aerostat": {"net_buoyancy_n": 2000.0, "mass_kg": 100.0, "drag_coefficient_nondim": 0.3,
                     "reference_area_m2": 20.0},
        "wind": {"flow": {"kind": "power_law", "coefficient_m_s": 0.0, "exponent_nondim": 0.14, "reference_height_m": 10.0},
                 "air_density_kg_m3": 1.225},
        "wind_speeds_m_s": {"min": 0.0, "max": 30.0, "count": 7},
        "tether_lengths_m": {"min": 100.0, "max": 3000.0, "count": 6},
        "required_safety_factor_nondim": 5.0,
        "payout_rate_m_s": 5.0,
        "uncertainty": {"samples": 600, "seed": 5, "inputs": [
            {"field": "aerostat.net_buoyancy_n", "distribution": "normal", "mean": 2000.0, "std_dev": 850.0},
            {"field": "aerostat.drag_coefficient_nondim", "distribution": "uniform", "low": 0.25, "high": 0.4}
        ]}
    })
}

/// The answer of `submission` as a job on SQLite, in this process.
fn sqlite_answer(submission: &Value) -> String {
    let dir = std::env::temp_dir().join(format!(
        "tetherplan-pg-vs-sqlite-{}-{}",
        std::process::id(),
        submission["kind"].as_str().unwrap()
    ));
    std::fs::create_dir_all(&dir).unwrap();
    let store = tetherplan::jobs::store::JobStore::open(&dir.join("jobs.db")).unwrap();
    let queue = tetherplan::jobs::JobQueue::new(store, 2, Default::default());
    let (id, _) = queue
        .submit(&serde_json::to_vec(submission).unwrap())
        .unwrap();
    while tetherplan::jobs::work_once(&queue).unwrap() {}
    let rec = queue.store.get(id).unwrap().unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(rec.status, tetherplan::jobs::store::JobStatus::Done);
    rec.result.unwrap()
}

#[test]
fn envelope_bands_on_two_workers_equal_the_sqlite_run() {
    let Some(db) = TestDb::create("uq_bands") else {
        return;
    };
    let api = Proc::api(&db.url);
    let workers: Vec<Proc> = (0..2).map(|_| Proc::worker(&db.url)).collect();
    let mut pg = db.client();
    // (plan_bands chunks carry every sample's traces, about 60 bytes a
    // sample × instant: tested chunked on SQLite, tests/chunks_kinds.rs.)
    for (kind, request) in [("envelope_bands", envelope_bands_request())] {
        let submission = json!({"kind": kind, "request": request});
        let id = api.submit(&submission);
        let v = api.wait_finished(id, Duration::from_secs(180));
        assert_eq!(v["status"], "done", "{v}");
        assert_eq!(v["progress"], 1.0);
        let rows = chunks(&mut pg, id);
        let n = rows.len();
        assert!(n >= 2, "{kind}: split into {n} chunks");
        assert_eq!(
            rows.iter().map(|r| r.0).collect::<Vec<_>>(),
            (0..n as i32).collect::<Vec<_>>()
        );
        assert!(rows.iter().all(|r| r.1 == "done" && r.2 == 1), "{rows:?}");
        let finishers: std::collections::BTreeSet<_> =
            rows.iter().filter_map(|r| r.4.clone()).collect();
        eprintln!("{kind}: {n} chunks done by {finishers:?}");
        let stored: String = pg.query_one(STORED_ANSWER, &[&id]).unwrap().get(0);
        assert_eq!(stored, sqlite_answer(&submission), "{kind}");
    }
    drop(workers);
}
