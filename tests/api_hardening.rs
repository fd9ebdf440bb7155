//! Hardening, full stack: the real `tetherplan` binary on a free loopback
//! port, spoken to over raw TCP as a hostile client would.
//!
//! * abandoned solves stop and free their slot (timeout and disconnect);
//! * an unfinished request head is dropped within the header timeout;
//! * 1,500 idle connections do not take the server off the air;
//! * Host allow-list, CSP and nosniff on every response;
//! * the page is built in: `serve` from a temporary directory serves `/`;
//! * no colour codes in logs that are not a terminal;
//! * the CLI exits 0 when its reader goes away.

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::{Value, json};

mod common;
use common::http::{Reply, connect, exchange, spawn_listening};

struct Server {
    child: Child,
    addr: SocketAddr,
    dir: PathBuf,
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tetherplan-hard-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

impl Server {
    /// Starts the server in a fresh temporary directory (its working
    /// directory: no `static/` there), with `envs`.
    fn start(name: &str, envs: &[(&str, &str)]) -> Self {
        Self::start_with(name, envs, Stdio::inherit())
    }

    fn start_with(name: &str, envs: &[(&str, &str)], stderr: Stdio) -> Self {
        let dir = temp_dir(name);
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_tetherplan"));
        cmd.args(["serve", "--addr", "127.0.0.1:0"])
            .current_dir(&dir)
            .env_remove("TETHERPLAN_STATIC_DIR")
            .env_remove("TETHERPLAN_API_TOKENS")
            .env("RUST_LOG", "warn")
            .stderr(stderr);
        for (k, v) in envs {
            cmd.env(k, v);
        }
        let (child, addr) = spawn_listening(&mut cmd);
        Self { child, addr, dir }
    }

    fn connect(&self) -> TcpStream {
        connect(self.addr, Duration::from_secs(60))
    }

    fn send(&self, method: &str, path: &str, host: &str, body: Option<&Value>) -> Reply {
        let body = body
            .map(|b| serde_json::to_vec(b).unwrap())
            .unwrap_or_default();
        let content_type = (!body.is_empty()).then_some("application/json");
        exchange(self.connect(), method, path, host, content_type, &body)
    }

    fn get(&self, path: &str) -> Reply {
        self.send("GET", path, &self.addr.to_string(), None)
    }

    fn post(&self, path: &str, body: &Value) -> Reply {
        self.send("POST", path, &self.addr.to_string(), Some(body))
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

fn system(elements: usize) -> Value {
    json!({
        "cable": {"mass_per_length_kg_m": 0.078},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
        "initial_length_m": 1.0,
        "model": {"kind": "linear_string", "elements": elements}
    })
}

fn with(mut base: Value, extra: Value) -> Value {
    for (k, v) in extra.as_object().unwrap() {
        base[k] = v.clone();
    }
    base
}

fn critical_body() -> Value {
    with(
        system(50),
        json!({"profile": {"kind": "constant_rate", "rate_m_s": 10.0}}),
    )
}

/// The hang input: 250 bytes that kept a core busy for minutes.
fn hang_body() -> Value {
    json!({
        "cable": {"mass_per_length_kg_m": 9.615858988256474e+262},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
        "state": {"length_m": 100.0, "rate_m_s": 5.0, "acceleration_m_s2": 0.0}
    })
}

/// A legitimately slow, in-range request: a long transient run of a
/// fine linear-string model (minutes of CPU if nobody stops it).
fn slow_body() -> Value {
    with(
        with(system(2000), json!({"initial_length_m": 100.0})),
        // about 1 CPU-s: priced under the 2 CPU-s budget (issue 34), so it
        // is admitted and runs past a short solve timeout
        json!({"profile": {"kind": "constant_rate", "rate_m_s": 1.0}, "duration_s": 1800.0,
               "samples": 20}),
    )
}

#[test]
fn the_hang_input_twice_then_an_ordinary_answer_within_a_second() {
    let server = Server::start("hang", &[("TETHERPLAN_SOLVE_TIMEOUT_S", "1")]);
    let addr = server.addr;
    let callers: Vec<_> = (0..2)
        .map(|_| {
            std::thread::spawn(move || {
                let s = Server::post_raw(addr, "/api/v1/stability", &hang_body());
                s.status
            })
        })
        .collect();
    for c in callers {
        let status = c.join().unwrap();
        // 504 (stopped at the timeout) or 422 (refused by a range check).
        assert!(
            status == 504 || status == 422 || status == 200,
            "hang input answered {status}"
        );
    }
    let start = Instant::now();
    let r = server.post("/api/v1/critical", &critical_body());
    let took = start.elapsed();
    assert_eq!(r.status, 200, "{}", r.body);
    assert!(took < Duration::from_secs(1), "/critical took {took:?}");
}

impl Server {
    fn post_raw(addr: SocketAddr, path: &str, body: &Value) -> Reply {
        let s = connect(addr, Duration::from_secs(60));
        let body = serde_json::to_vec(body).unwrap();
        exchange(
            s,
            "POST",
            path,
            &addr.to_string(),
            Some("application/json"),
            &body,
        )
    }
}

/// Polls `/critical` until it answers 200; the time it took.
fn time_until_critical_answers(server: &Server, limit: Duration) -> Duration {
    let start = Instant::now();
    loop {
        let r = server.post("/api/v1/critical", &critical_body());
        if r.status == 200 {
            return start.elapsed();
        }
        assert_eq!(r.status, 503, "{}", r.body);
        assert!(
            start.elapsed() < limit,
            "the solve slot was not freed within {limit:?}"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn a_slow_solve_stops_at_its_timeout_and_frees_its_slot() {
    let server = Server::start(
        "slow-timeout",
        &[
            ("TETHERPLAN_SOLVE_TIMEOUT_S", "0.2"),
            ("TETHERPLAN_MAX_IN_FLIGHT", "1"),
        ],
    );
    let start = Instant::now();
    let r = server.post("/api/v1/simulate", &slow_body());
    assert_eq!(r.status, 504, "{}", r.body);
    assert!(start.elapsed() < Duration::from_secs(3));
    let freed = time_until_critical_answers(&server, Duration::from_secs(2));
    eprintln!("slot freed {freed:?} after the 504");
}

#[test]
fn a_slow_solve_stops_when_its_caller_goes_away() {
    let server = Server::start(
        "slow-gone",
        &[
            ("TETHERPLAN_SOLVE_TIMEOUT_S", "120"),
            ("TETHERPLAN_MAX_IN_FLIGHT", "1"),
        ],
    );
    let mut s = server.connect();
    let body = serde_json::to_vec(&slow_body()).unwrap();
    let head = format!(
        "POST /api/v1/simulate HTTP/1.1\r\nHost: {}\r\nContent-Type: application/json\r\nContent-Length: {}\r\n\r\n",
        server.addr,
        body.len()
    );
    s.write_all(head.as_bytes()).unwrap();
    s.write_all(&body).unwrap();
    std::thread::sleep(Duration::from_millis(200));
    // the solve holds the only slot
    assert_eq!(
        server.post("/api/v1/critical", &critical_body()).status,
        503
    );
    drop(s);
    let freed = time_until_critical_answers(&server, Duration::from_secs(3));
    eprintln!("slot freed {freed:?} after the caller hung up");
}

#[test]
fn an_unfinished_request_head_is_dropped_within_the_header_timeout() {
    let server = Server::start("header", &[]);
    let mut s = server.connect();
    s.write_all(b"GET /healthz HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Slow: ")
        .unwrap();
    let start = Instant::now();
    let mut buf = [0u8; 256];
    // EOF (or a reset) once the server gives up on the head
    loop {
        match s.read(&mut buf) {
            Ok(0) | Err(_) => break,
            Ok(_) => {}
        }
        assert!(start.elapsed() < Duration::from_secs(15));
    }
    let took = start.elapsed();
    eprintln!("unfinished head dropped after {took:?}");
    assert!(took < Duration::from_secs(10), "took {took:?}");
    assert!(
        took >= Duration::from_secs(4),
        "took {took:?}: before the 5 s default"
    );
}

#[test]
fn fifteen_hundred_idle_connections_and_healthz_still_answers() {
    // Cap 1 000: the oldest idle connections are closed to make room.
    let server = Server::start("idle", &[("TETHERPLAN_MAX_CONNECTIONS", "1000")]);
    let mut idle = Vec::with_capacity(1500);
    for _ in 0..1500 {
        let s = TcpStream::connect(server.addr).unwrap();
        idle.push(s);
    }
    let start = Instant::now();
    let r = server.get("/healthz");
    let took = start.elapsed();
    assert_eq!(r.status, 200, "{}", r.body);
    assert!(took < Duration::from_secs(2), "/healthz took {took:?}");
    // A synchronous solve answers too.
    assert_eq!(
        server.post("/api/v1/critical", &critical_body()).status,
        200
    );
    // The oldest idle connections were closed (EOF), the newest are open.
    let mut closed = 0;
    for s in idle.iter_mut().take(100) {
        s.set_read_timeout(Some(Duration::from_millis(200)))
            .unwrap();
        if matches!(s.read(&mut [0u8; 1]), Ok(0) | Err(_)) {
            closed += 1;
        }
    }
    eprintln!("1500 idle connections: /healthz in {took:?}; {closed}/100 oldest closed");
    assert!(closed >= 90, "{closed}");
}

#[test]
fn default_cap_holds_fifteen_hundred_idle_connections() {
    let server = Server::start("idle-default", &[]);
    let idle: Vec<TcpStream> = (0..1500)
        .map(|_| TcpStream::connect(server.addr).unwrap())
        .collect();
    let r = server.get("/healthz");
    assert_eq!(r.status, 200);
    drop(idle);
}

#[test]
fn security_headers_and_host_allow_list() {
    let server = Server::start("hosts", &[("TETHERPLAN_ALLOWED_HOSTS", "plan.example.org")]);
    for path in [
        "/",
        "/healthz",
        "/openapi.json",
        "/api/v1/jobs/none",
        "/no-such-file",
    ] {
        let r = server.get(path);
        assert_eq!(
            r.header("x-content-type-options"),
            Some("nosniff"),
            "{path}"
        );
        let csp = r.header("content-security-policy").unwrap_or("");
        assert!(csp.contains("default-src 'self'"), "{path}: {csp:?}");
    }
    let port = server.addr.port();
    for host in [
        format!("localhost:{port}"),
        format!("127.0.0.1:{port}"),
        "plan.example.org".into(),
    ] {
        assert_eq!(
            server.send("GET", "/healthz", &host, None).status,
            200,
            "{host}"
        );
    }
    let r = server.send("GET", "/healthz", "rebind.attacker.example", None);
    assert_eq!(r.status, 421, "{}", r.body);
    assert!(r.body.contains("host_not_allowed"), "{}", r.body);
    assert_eq!(r.header("x-content-type-options"), Some("nosniff"));
}

#[test]
fn serve_from_a_temporary_directory_serves_the_built_in_page() {
    let server = Server::start("anywhere", &[]);
    assert!(!server.dir.join("static").exists());
    let r = server.get("/");
    assert_eq!(r.status, 200);
    assert!(r.header("content-type").unwrap().starts_with("text/html"));
    assert!(
        r.body.contains("<script src=\"app.js\"></script>"),
        "{}",
        r.body
    );
    let js = server.get("/app.js");
    assert_eq!(js.status, 200);
    assert!(
        js.header("content-type")
            .unwrap()
            .starts_with("text/javascript")
    );
    let on_disk = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("static/app.js"),
    )
    .unwrap();
    assert_eq!(js.body, on_disk);
    assert_eq!(server.get("/vendor/uPlot.iife.min.js").status, 200);
    assert_eq!(server.get("/nothing-here.js").status, 404);
}

#[test]
fn logs_that_are_not_a_terminal_carry_no_colour_codes() {
    let mut server = Server::start_with("colour", &[("RUST_LOG", "info")], Stdio::piped());
    let _ = server.get("/healthz");
    let _ = server.child.kill();
    let mut log = String::new();
    server
        .child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut log)
        .unwrap();
    assert!(log.contains("listening"), "{log}");
    assert!(!log.contains('\u{1b}'), "ANSI escape in {log:?}");
}

#[test]
fn the_cli_exits_cleanly_when_its_reader_goes_away() {
    let request = with(
        system(50),
        json!({"rates_m_s": {"min": 1.0, "max": 120.0, "count": 2000}}),
    );
    let mut child = Command::new(env!("CARGO_BIN_EXE_tetherplan"))
        .arg("chart")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // `| head -c 0`: the reader is gone before the answer is written.
    drop(child.stdout.take());
    child
        .stdin
        .take()
        .unwrap()
        .write_all(&serde_json::to_vec(&request).unwrap())
        .unwrap();
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "stderr: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");

    // and through a shell pipeline, as a user types it
    let dir = temp_dir("pipe");
    std::fs::write(dir.join("req.json"), serde_json::to_vec(&request).unwrap()).unwrap();
    let status = Command::new("bash")
        .arg("-c")
        .arg(format!(
            "set -o pipefail; '{}' chart --input '{}' | head -1 >/dev/null",
            env!("CARGO_BIN_EXE_tetherplan"),
            dir.join("req.json").display()
        ))
        .status()
        .unwrap();
    assert_eq!(status.code(), Some(0));
    let _ = std::fs::remove_dir_all(&dir);
}
