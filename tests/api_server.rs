//! Full-stack tests: the real `tetherplan` binary on a free port (port 0)
//! with a temporary database, spoken to over raw HTTP/1.1.

use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::{Value, json};
use tetherplan::contract;
use tetherplan::contract::dto::ChartRequest;
use tetherplan::contract::run::{self, NoProgress};
use tetherplan::numerics::parallel::Parallelism;

mod common;
use common::http::{Reply, connect, exchange, spawn_listening};

struct Server {
    child: Child,
    addr: SocketAddr,
}

impl Server {
    fn start(dir: &Path, envs: &[(&str, &str)]) -> Self {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_tetherplan"));
        cmd.args(["serve", "--addr", "127.0.0.1:0"])
            .arg("--db")
            .arg(dir.join("jobs.db"))
            .arg("--static-dir")
            .arg(dir.join("static"))
            .env("RUST_LOG", "warn")
            .stderr(Stdio::inherit());
        for (k, v) in envs {
            cmd.env(k, v);
        }
        let (child, addr) = spawn_listening(&mut cmd);
        Self { child, addr }
    }

    fn request(&self, method: &str, path: &str, content_type: Option<&str>, body: &[u8]) -> Reply {
        let s = connect(self.addr, Duration::from_secs(120));
        exchange(s, method, path, &self.addr.to_string(), content_type, body)
    }

    fn get(&self, path: &str) -> Reply {
        self.request("GET", path, None, b"")
    }

    fn post(&self, path: &str, body: &Value) -> Reply {
        self.request(
            "POST",
            path,
            Some("application/json"),
            &serde_json::to_vec(body).unwrap(),
        )
    }

    fn pid(&self) -> u32 {
        self.child.id()
    }

    /// SIGKILL: no chance to clean up.
    fn kill(mut self) {
        self.child.kill().unwrap();
        self.child.wait().unwrap();
    }

    /// SIGTERM, then wait for a clean exit.
    fn terminate(mut self) {
        let ok = Command::new("kill")
            .args(["-TERM", &self.pid().to_string()])
            .status()
            .unwrap()
            .success();
        assert!(ok, "kill -TERM failed");
        let start = Instant::now();
        loop {
            if let Some(status) = self.child.try_wait().unwrap() {
                assert!(
                    status.success(),
                    "the server exited with {status} after SIGTERM"
                );
                return;
            }
            assert!(
                start.elapsed() < Duration::from_secs(30),
                "the server did not stop after SIGTERM"
            );
            std::thread::sleep(Duration::from_millis(20));
        }
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tetherplan-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("static")).unwrap();
    std::fs::write(
        dir.join("static/index.html"),
        "<!doctype html><title>t</title><h1>tetherplan test page</h1>",
    )
    .unwrap();
    dir
}

fn system(elements: usize) -> Value {
    json!({
        "cable": {"density_kg_m3": 7800.0, "area_m2": 1e-5},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
        "model": {"elements": elements}
    })
}

fn critical_body() -> Value {
    let mut v = system(50);
    v["profile"] = json!({"kind": "constant_rate", "rate_m_s": 10.0});
    v
}

fn chart_body(count: usize, elements: usize) -> Value {
    let mut v = system(elements);
    v["rates_m_s"] = json!({"min": 1.0, "max": 120.0, "count": count});
    v
}

fn job(server: &Server, id: i64) -> Value {
    let r = server.get(&format!("/api/v1/jobs/{id}"));
    assert_eq!(r.status, 200, "{}", r.body);
    r.json()
}

/// Polls the job until `done(job)`.
fn wait_for(server: &Server, id: i64, what: &str, done: impl Fn(&Value) -> bool) -> Value {
    let start = Instant::now();
    loop {
        let v = job(server, id);
        if done(&v) {
            return v;
        }
        assert!(
            start.elapsed() < Duration::from_secs(300),
            "job {id} never {what}: {v}"
        );
        std::thread::sleep(Duration::from_millis(25));
    }
}

#[test]
fn the_server_answers_serves_pages_and_refuses_bad_input() {
    let dir = temp_dir("full-stack");
    let server = Server::start(
        &dir,
        &[
            ("TETHERPLAN_MAX_PENDING_JOBS", "1"),
            ("TETHERPLAN_MAX_BODY_BYTES", "65536"),
        ],
    );

    let r = server.get("/healthz");
    assert_eq!((r.status, r.json()["status"].as_str()), (200, Some("ok")));

    let r = server.get("/");
    assert_eq!(r.status, 200);
    assert!(r.body.contains("tetherplan test page"));

    let r = server.post("/api/v1/critical", &critical_body());
    assert_eq!(r.status, 200, "{}", r.body);
    let v = r.json();
    assert!(
        (v["max_elevation_m"].as_f64().unwrap() - 1310.0).abs() < 0.5,
        "{v}"
    );
    assert!(
        (v["closed_form_elevation_m"].as_f64().unwrap() - 1296.69).abs() < 0.01,
        "{v}"
    );

    let r = server.request(
        "POST",
        "/api/v1/critical",
        Some("application/json"),
        b"{\"cable\":",
    );
    assert_eq!(
        (r.status, r.json()["error"]["code"].as_str()),
        (400, Some("malformed_json"))
    );
    let mut bad = critical_body();
    bad["aerostat"]["net_buoyancy_n"] = json!(-3.0);
    let r = server.post("/api/v1/critical", &bad);
    assert_eq!(
        (r.status, r.json()["error"]["field"].as_str()),
        (422, Some("aerostat.net_buoyancy_n"))
    );
    let r = server.request(
        "POST",
        "/api/v1/charts",
        Some("application/json"),
        &vec![b' '; 100_000],
    );
    assert_eq!(
        (r.status, r.json()["error"]["code"].as_str()),
        (413, Some("payload_too_large"))
    );
    let r = server.request("POST", "/api/v1/charts", Some("text/csv"), b"1,2");
    assert_eq!(r.status, 415);

    let r = server.get("/openapi.json");
    assert_eq!(r.status, 200);
    assert!(r.json()["paths"]["/api/v1/jobs/{id}"].is_object());
    let r = server.get("/docs/");
    assert_eq!(r.status, 200);
    assert!(r.body.to_lowercase().contains("swagger"));

    // One pending job at most (TETHERPLAN_MAX_PENDING_JOBS=1).
    let big = json!({"kind": "chart", "request": chart_body(20_000, 2000)});
    let r = server.post("/api/v1/jobs", &big);
    assert_eq!(r.status, 202, "{}", r.body);
    let id = r.json()["id"].as_i64().unwrap();
    let r = server.post(
        "/api/v1/jobs",
        &json!({"kind": "critical", "request": critical_body()}),
    );
    assert_eq!(r.status, 429, "{}", r.body);
    assert_eq!(r.header("retry-after"), Some("5"));
    let r = server.request("DELETE", &format!("/api/v1/jobs/{id}"), None, b"");
    assert_eq!(
        (r.status, r.json()["status"].as_str()),
        (200, Some("cancelled"))
    );
    let r = server.post(
        "/api/v1/jobs",
        &json!({"kind": "critical", "request": critical_body()}),
    );
    assert_eq!(r.status, 202, "{}", r.body);
    let id = r.json()["id"].as_i64().unwrap();
    let v = wait_for(&server, id, "finished", |v| v["status"] == "done");
    assert!((v["result"]["max_elevation_m"].as_f64().unwrap() - 1310.0).abs() < 0.5);
    drop(server);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_job_survives_sigterm_and_sigkill_and_matches_the_synchronous_answer() {
    let dir = temp_dir("persistence");
    // 4000 points at 2000 elements: a few seconds on two cores.
    let body = chart_body(4000, 2000);
    let server = Server::start(&dir, &[]);
    let r = server.post("/api/v1/jobs", &json!({"kind": "chart", "request": body}));
    assert_eq!(r.status, 202, "{}", r.body);
    let id = r.json()["id"].as_i64().unwrap();
    let running = |v: &Value| v["status"] == "running" && v["progress"].as_f64().unwrap() > 0.0;
    wait_for(&server, id, "ran", running);

    // Graceful stop: the running job goes back to the queue.
    server.terminate();
    let server = Server::start(&dir, &[]);
    let v = job(&server, id);
    assert!(v["status"] == "queued" || v["status"] == "running", "{v}");
    wait_for(&server, id, "restarted", |v| {
        running(v) && v["attempts"] == 2
    });

    // Crash: SIGKILL mid-job; the restarted server runs it to the end.
    server.kill();
    let server = Server::start(&dir, &[]);
    let listed = server.get("/api/v1/jobs").json();
    assert_eq!(
        listed["jobs"][0]["id"], id,
        "the job is still listed: {listed}"
    );
    wait_for(&server, id, "finished", |v| v["status"] == "done");
    let r = server.get(&format!("/api/v1/jobs/{id}"));
    let v = r.json();
    assert_eq!(v["attempts"], 3);
    assert_eq!(v["progress"], 1.0);

    #[derive(serde::Deserialize)]
    struct Job<'a> {
        #[serde(borrow)]
        result: &'a serde_json::value::RawValue,
    }
    let result = serde_json::from_str::<Job>(&r.body)
        .unwrap()
        .result
        .get()
        .to_string();
    let req: ChartRequest = contract::parse(&serde_json::to_vec(&body).unwrap()).unwrap();
    let sync =
        serde_json::to_string(&run::chart(&req, Parallelism::Rayon, &NoProgress).unwrap()).unwrap();
    assert!(
        result == sync,
        "the job's chart differs from the synchronous one"
    );
    drop(server);
    let _ = std::fs::remove_dir_all(&dir);
}
