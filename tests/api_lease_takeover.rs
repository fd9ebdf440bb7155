//! Two real `tetherplan serve` processes on one SQLite file, 2 s leases:
//! the one running a job is killed with SIGKILL mid-run; the other takes
//! the job over once the lease has expired (not before), runs it once to
//! the end, and its answer is the synchronous one.

use std::net::SocketAddr;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::{Value, json};
use tetherplan::contract;
use tetherplan::contract::dto::ChartRequest;
use tetherplan::contract::run::{self, NoProgress};
use tetherplan::numerics::parallel::Parallelism;

mod common;
use common::http::{connect, exchange, spawn_listening};

struct Server {
    child: Child,
    addr: SocketAddr,
}

impl Server {
    fn start(dir: &Path) -> Self {
        let (child, addr) = spawn_listening(
            Command::new(env!("CARGO_BIN_EXE_tetherplan"))
                .args(["serve", "--addr", "127.0.0.1:0"])
                .arg("--db")
                .arg(dir.join("jobs.db"))
                .arg("--static-dir")
                .arg(dir)
                .env("RUST_LOG", "warn")
                .env("TETHERPLAN_JOB_LEASE_S", "2")
                .env("TETHERPLAN_JOB_THREADS", "1")
                .stderr(Stdio::inherit()),
        );
        Self { child, addr }
    }

    fn request(&self, method: &str, path: &str, body: Option<&Value>) -> (u16, Value) {
        let body = body
            .map(|b| serde_json::to_vec(b).unwrap())
            .unwrap_or_default();
        let s = connect(self.addr, Duration::from_secs(60));
        let r = exchange(
            s,
            method,
            path,
            &self.addr.to_string(),
            Some("application/json"),
            &body,
        );
        (
            r.status,
            serde_json::from_str(&r.body).unwrap_or(Value::Null),
        )
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The job row as the database has it: status, attempts, lease owner.
fn row(db: &Path, id: i64) -> (String, u32, Option<String>) {
    let conn = rusqlite::Connection::open(db).unwrap();
    conn.busy_timeout(Duration::from_secs(5)).unwrap();
    conn.query_row(
        "SELECT status, attempts, lease_owner FROM jobs WHERE id = ?1",
        [id],
        |r| Ok((r.get(0)?, r.get(1)?, r.get(2)?)),
    )
    .unwrap()
}

fn pid_of(worker: &str) -> u32 {
    worker.rsplit('/').nth(1).unwrap().parse().unwrap()
}

#[test]
fn a_killed_servers_job_is_taken_over_after_its_lease_and_run_once() {
    let dir = std::env::temp_dir().join(format!("tetherplan-takeover-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let db = dir.join("jobs.db");
    let mut servers = vec![Some(Server::start(&dir)), Some(Server::start(&dir))];
    // Several seconds of work on one thread.
    let request = json!({
        "cable": {"density_kg_m3": 7800.0, "area_m2": 1e-5},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
        "model": {"elements": 1000},
        "rates_m_s": {"min": 1.0, "max": 120.0, "count": 6000}
    });
    let (status, v) = servers[0].as_ref().unwrap().request(
        "POST",
        "/api/v1/jobs",
        Some(&json!({"kind": "chart", "request": request})),
    );
    assert_eq!(status, 202, "{v}");
    let id = v["id"].as_i64().unwrap();
    // Wait until one of them runs it with progress.
    let start = Instant::now();
    let holder = loop {
        let (_, v) =
            servers[1]
                .as_ref()
                .unwrap()
                .request("GET", &format!("/api/v1/jobs/{id}"), None);
        let (status, attempts, owner) = row(&db, id);
        if status == "running" && v["progress"].as_f64().unwrap_or(0.0) > 0.0 {
            assert_eq!(attempts, 1);
            break owner.unwrap();
        }
        assert!(start.elapsed() < Duration::from_secs(120), "never ran: {v}");
        std::thread::sleep(Duration::from_millis(50));
    };
    let victim = servers
        .iter()
        .position(|s| s.as_ref().unwrap().child.id() == pid_of(&holder))
        .expect("the holder is one of the two servers");
    let survivor = 1 - victim;
    let mut dead = servers[victim].take().unwrap();
    dead.child.kill().unwrap();
    dead.child.wait().unwrap();
    let killed_at = Instant::now();
    // The survivor takes it over once the lease (2 s, renewed every 0.67 s) runs out.
    let taken = loop {
        let (status, attempts, owner) = row(&db, id);
        if owner.as_deref() != Some(holder.as_str()) {
            assert_eq!(status, "running");
            assert_eq!(attempts, 2);
            break (killed_at.elapsed(), owner.unwrap());
        }
        assert_eq!(status, "running", "nobody else may finish it");
        assert!(
            killed_at.elapsed() < Duration::from_secs(30),
            "not taken over within 30 s"
        );
        std::thread::sleep(Duration::from_millis(20));
    };
    let survivor_server = servers[survivor].as_ref().unwrap();
    assert_eq!(pid_of(&taken.1), survivor_server.child.id());
    eprintln!(
        "lease takeover {:.2} s after SIGKILL (lease 2 s)",
        taken.0.as_secs_f64()
    );
    assert!(
        taken.0 >= Duration::from_millis(600),
        "taken over before the lease could have expired: {:?}",
        taken.0
    );
    assert!(taken.0 < Duration::from_secs(6), "{:?}", taken.0);
    // It finishes once, with the synchronous answer.
    let start = Instant::now();
    let v = loop {
        let (_, v) = survivor_server.request("GET", &format!("/api/v1/jobs/{id}"), None);
        if v["status"] != "running" {
            break v;
        }
        assert!(start.elapsed() < Duration::from_secs(300), "{v}");
        std::thread::sleep(Duration::from_millis(100));
    };
    assert_eq!(v["status"], "done", "{v}");
    assert_eq!(v["attempts"], 2);
    let (status, attempts, owner) = row(&db, id);
    assert_eq!((status.as_str(), attempts), ("done", 2));
    assert_eq!(owner.as_deref(), Some(taken.1.as_str()));
    let req: ChartRequest = contract::parse(&serde_json::to_vec(&request).unwrap()).unwrap();
    let sync = run::chart(&req, Parallelism::Rayon, &NoProgress).unwrap();
    assert_eq!(v["result"], serde_json::to_value(&sync).unwrap());
    drop(servers);
    let _ = std::fs::remove_dir_all(&dir);
}
