//! Scale-out figures over PostgreSQL (plain harness; skipped with a message
//! when PostgreSQL is unreachable):
//!
//! 1. a GE chart job (80 points, 10 elements, 10 chunks) run by 1 and by 2
//!    `tetherplan worker` processes (one rayon thread each) behind an
//!    API-only `tetherplan serve`: wall time from submission to `done`,
//!    median of `TETHERPLAN_BENCH_RUNS` (3) runs each, and the speed-up;
//!    and a `dynamics_peaks` job (40 seeds of 900 s of von Kármán turbulence
//!    on the §10 1000 m tether at 10 m/s, I = 0.15, chunked by sample) the
//!    same way (issue 31: 2 workers ≥ 1.8× as fast as one);
//! 2. the overhead of one chunk: claim + finish of an empty chunk through
//!    the store (median over 200), PostgreSQL and SQLite.
//!
//! `cargo bench --bench distributed` (PostgreSQL at `TETHERPLAN_TEST_PG_URL`,
//! default `postgres://postgres:postgres@127.0.0.1:5432/postgres`; `.ci/run`
//! starts it). On a shared machine the medians move with the load.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::{Value, json};
use tetherplan::jobs::store::{ClaimPolicy, JobBackend, Lease};

fn admin_url() -> String {
    std::env::var("TETHERPLAN_TEST_PG_URL")
        .unwrap_or_else(|_| "postgres://postgres:postgres@127.0.0.1:5432/postgres".into())
}

struct Db {
    admin: String,
    name: String,
    url: String,
}

impl Db {
    fn create(tag: &str) -> Option<Self> {
        let admin = admin_url();
        let mut c = match postgres::Client::connect(&admin, postgres::NoTls) {
            Ok(c) => c,
            Err(e) => {
                eprintln!("distributed bench skipped: PostgreSQL unreachable at {admin}: {e}");
                return None;
            }
        };
        let name = format!("tetherplan_bench_{tag}_{}", std::process::id());
        c.batch_execute(&format!("DROP DATABASE IF EXISTS {name} WITH (FORCE)"))
            .unwrap();
        c.batch_execute(&format!("CREATE DATABASE {name}")).unwrap();
        let url = format!("{}/{name}", admin.rsplit_once('/').unwrap().0);
        Some(Self { admin, name, url })
    }
}

impl Drop for Db {
    fn drop(&mut self) {
        if let Ok(mut c) = postgres::Client::connect(&self.admin, postgres::NoTls) {
            let _ = c.batch_execute(&format!(
                "DROP DATABASE IF EXISTS {} WITH (FORCE)",
                self.name
            ));
        }
    }
}

struct Proc(Child, String);

impl Proc {
    fn spawn(args: &[&str], url: &str, prefix: &str) -> Self {
        let mut child = Command::new(env!("CARGO_BIN_EXE_tetherplan"))
            .args(args)
            .args(["--database-url", url])
            .env("RUST_LOG", "warn")
            .env(
                "TETHERPLAN_JOB_THREADS",
                if args[0] == "serve" { "0" } else { "1" },
            )
            .env("RAYON_NUM_THREADS", "1")
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .unwrap();
        let mut line = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut line)
            .unwrap();
        let rest = line.trim().strip_prefix(prefix).unwrap().to_string();
        Self(child, rest)
    }
}

impl Drop for Proc {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn request(addr: SocketAddr, method: &str, path: &str, body: Option<&Value>) -> Value {
    let body = body
        .map(|b| serde_json::to_vec(b).unwrap())
        .unwrap_or_default();
    let mut s = TcpStream::connect(addr).unwrap();
    let head = format!(
        "{method} {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\nContent-Type: application/json\r\nContent-Length: {}\r\n\r\n",
        body.len()
    );
    s.write_all(head.as_bytes()).unwrap();
    s.write_all(&body).unwrap();
    let mut raw = Vec::new();
    s.read_to_end(&mut raw).unwrap();
    let split = raw.windows(4).position(|w| w == b"\r\n\r\n").unwrap();
    let head = String::from_utf8_lossy(&raw[..split]).to_ascii_lowercase();
    let mut body = raw[split + 4..].to_vec();
    if head.contains("transfer-encoding: chunked") {
        body = dechunk(&body);
    }
    serde_json::from_slice(&body).unwrap_or(Value::Null)
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

fn chart_job() -> Value {
    json!({"kind": "chart", "request": {
        "cable": {"density_kg_m3": 7800.0, "area_m2": 1e-5},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
        "initial_length_m": 1.0,
        "model": {"kind": "geometrically_exact", "elements": 10, "bending_stiffness_n_m2": 1000.0, "inertia_ratio": 1.0},
        "stiffness_ratios": [1e4, 1e5],
        "rates_m_s": {"min": 70.0, "max": 110.0, "count": 40},
        "numerics": {"horizon_s": 20.0}
    }})
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// A `dynamics_peaks` job: 40 one-run samples of 900 s (the gust-check
/// system of `docs/gust_check.md`), chunked by sample.
fn peaks_job() -> Value {
    json!({"kind": "dynamics_peaks", "request": {
        "cable": {"mass_per_length_kg_m": 0.078, "diameter_m": 0.005,
                  "normal_drag_coefficient_nondim": 1.2, "axial_stiffness_n": 1.0e7},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0,
                     "drag_coefficient_nondim": 0.3, "reference_area_m2": 20.0},
        "wind": {"flow": {"kind": "uniform", "speed_m_s": 10.0},
                 "time_history": {"kind": "turbulence", "model": "von_karman",
                                  "turbulence_intensity_nondim": 0.15,
                                  "length_scale_m": 340.0, "seed": 1}},
        "tether_length_m": 1000.0,
        "exposure_s": 900.0,
        "samples": 40
    }})
}

/// Seconds from submission to `done` with `workers` worker processes.
fn job_time(workers: usize, runs: usize, job: &Value) -> Option<Vec<f64>> {
    let mut times = Vec::new();
    for run in 0..runs {
        let db = Db::create(&format!("w{workers}_{run}"))?;
        let api = Proc::spawn(
            &["serve", "--addr", "127.0.0.1:0"],
            &db.url,
            "tetherplan listening on http://",
        );
        let addr: SocketAddr = api.1.parse().unwrap();
        let _ws: Vec<Proc> = (0..workers)
            .map(|_| Proc::spawn(&["worker"], &db.url, "tetherplan worker "))
            .collect();
        std::thread::sleep(Duration::from_millis(300));
        let start = Instant::now();
        let v = request(addr, "POST", "/api/v1/jobs", Some(job));
        let id = v["id"].as_i64().unwrap();
        loop {
            let v = request(addr, "GET", &format!("/api/v1/jobs/{id}"), None);
            match v["status"].as_str() {
                Some("done") => break,
                Some("queued" | "running") => std::thread::sleep(Duration::from_millis(20)),
                _ => panic!("{v}"),
            }
        }
        times.push(start.elapsed().as_secs_f64());
    }
    Some(times)
}

/// Milliseconds per claim + finish of an empty chunk.
fn claim_overhead(store: &dyn JobBackend, chunks: usize) -> f64 {
    let policy = ClaimPolicy {
        lease: Duration::from_secs(30),
        max_attempts: 3,
        exhausted_error: "{}",
    };
    let new = tetherplan::jobs::store::NewJob {
        kind: "critical",
        request: "{}",
        owner: None,
        idempotency_key: None,
        request_hash: "",
        max_pending: 10,
        max_pending_per_owner: 10,
        priority: 1,
        reserve_bytes: 0,
        max_stored_bytes: u64::MAX,
    };
    let id = match store.insert(&new).unwrap() {
        tetherplan::jobs::store::Inserted::New(id) => id,
        other => panic!("{other:?}"),
    };
    let job = store.claim(&policy).unwrap().unwrap();
    assert_eq!(job.id, id);
    let lease: Lease = job.lease;
    assert!(store.create_chunks(&lease, chunks).unwrap());
    let mut per = Vec::new();
    for _ in 0..chunks {
        let t = Instant::now();
        let c = store.claim_chunk(None, &policy).unwrap().unwrap();
        assert!(store.finish_chunk(&c.lease, "[]").unwrap());
        per.push(t.elapsed().as_secs_f64() * 1e3);
    }
    median(per)
}

fn main() {
    if std::env::args().any(|a| a == "--list") {
        return;
    }
    let runs: usize = std::env::var("TETHERPLAN_BENCH_RUNS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(3);
    let Some(db) = Db::create("claims") else {
        return;
    };
    let pg = tetherplan::jobs::postgres::PgStore::open(&db.url).unwrap();
    println!(
        "chunk claim + finish, PostgreSQL: median {:.2} ms (200 chunks)",
        claim_overhead(&pg, 200)
    );
    let dir = std::env::temp_dir().join(format!("tetherplan-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let sqlite = tetherplan::jobs::store::JobStore::open(&dir.join("jobs.db")).unwrap();
    println!(
        "chunk claim + finish, SQLite: median {:.2} ms (200 chunks)",
        claim_overhead(&sqlite, 200)
    );
    let _ = std::fs::remove_dir_all(&dir);
    for (name, job) in [
        ("GE chart job", chart_job()),
        ("dynamics_peaks job", peaks_job()),
    ] {
        let Some(one) = job_time(1, runs, &job) else {
            return;
        };
        let Some(two) = job_time(2, runs, &job) else {
            return;
        };
        let (m1, m2) = (median(one.clone()), median(two.clone()));
        println!("{name}, 1 worker: median {m1:.2} s of {one:?}");
        println!("{name}, 2 workers: median {m2:.2} s of {two:?}");
        println!(
            "{name}: speed-up 2 vs 1 workers: {:.2}x (machine shared: medians move with its load)",
            m1 / m2
        );
    }
}
