//! Hostile clients against a live `tetherplan serve` (issue 22, items 1,
//! 2 and 8): slow request bodies, bodies that fill memory, answers never
//! read, oversized `Content-Length` with `Expect: 100-continue`, and the
//! Host edge cases. Every client count is bounded and every client stops
//! by itself; the server runs with a small cap and short deadlines.

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

mod common;
use common::http::{Reply, connect, exchange, probe_healthz, spawn_listening};

struct Server {
    child: Child,
    addr: SocketAddr,
    dir: PathBuf,
}

impl Server {
    fn start(name: &str, envs: &[(&str, &str)]) -> Self {
        Self::start_prepared(name, envs, |_| {})
    }

    /// [`Server::start`] after `prepare` has written into the server's
    /// directory (its database is `jobs.db` there).
    fn start_prepared(name: &str, envs: &[(&str, &str)], prepare: impl FnOnce(&Path)) -> Self {
        let dir = std::env::temp_dir().join(format!("tp-slow-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("static")).unwrap();
        prepare(&dir);
        std::fs::write(
            dir.join("static/index.html"),
            "<!doctype html><title>t</title>",
        )
        .unwrap();
        // 48 MiB: far more than the socket buffers hold
        std::fs::write(dir.join("static/big.bin"), vec![b'x'; 48 << 20]).unwrap();
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_tetherplan"));
        cmd.args(["serve", "--addr", "127.0.0.1:0"])
            .arg("--db")
            .arg(dir.join("jobs.db"))
            .arg("--static-dir")
            .arg(dir.join("static"))
            // TETHERPLAN_TEST_SERVER_LOG=tetherplan=debug shows the connection layer.
            .env(
                "RUST_LOG",
                std::env::var("TETHERPLAN_TEST_SERVER_LOG").unwrap_or("error".into()),
            )
            .env("TETHERPLAN_JOB_THREADS", "0")
            .stderr(Stdio::inherit());
        for (k, v) in envs {
            cmd.env(k, v);
        }
        let (child, addr) = spawn_listening(&mut cmd);
        Self { child, addr, dir }
    }

    /// Resident memory of the server (kB).
    fn rss_kb(&self) -> u64 {
        let status = std::fs::read_to_string(format!("/proc/{}/status", self.child.id())).unwrap();
        status
            .lines()
            .find_map(|l| l.strip_prefix("VmRSS:"))
            .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
            .unwrap()
    }

    /// `GET /healthz` over a fresh connection, each step within
    /// `timeout`; the error says what failed.
    fn healthy(&self, timeout: Duration) -> Result<(), String> {
        probe_healthz(self.addr, timeout)
    }

    /// Sends `head` (a request head, blank line included) and reads the
    /// whole reply.
    fn raw(&self, head: &str) -> Vec<u8> {
        let mut s = connect(self.addr, Duration::from_secs(10));
        s.write_all(head.as_bytes()).unwrap();
        let mut raw = Vec::new();
        let _ = s.read_to_end(&mut raw);
        raw
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// A client that sends a POST head announcing `length` bytes, then
/// `burst` bytes at once, then one byte every `every` up to `trickle`
/// bytes (then stops); returns when the server closes the connection (or
/// the trickle ends), with the time that took and the reply's first bytes.
fn slow_body(
    addr: SocketAddr,
    length: usize,
    burst: usize,
    every: Duration,
    trickle: usize,
) -> (Duration, Vec<u8>) {
    let start = Instant::now();
    let Ok(mut s) = TcpStream::connect(addr) else {
        return (start.elapsed(), Vec::new());
    };
    s.set_read_timeout(Some(Duration::from_millis(20))).unwrap();
    let head = format!(
        "POST /api/v1/critical HTTP/1.1\r\nHost: {addr}\r\nContent-Type: application/json\r\nContent-Length: {length}\r\n\r\n"
    );
    if s.write_all(head.as_bytes()).is_err() {
        return (start.elapsed(), Vec::new());
    }
    let mut reply = Vec::new();
    let mut buf = [0u8; 4096];
    let mut closed = |s: &mut TcpStream, reply: &mut Vec<u8>| loop {
        match s.read(&mut buf) {
            Ok(0) => return true,
            Ok(n) => reply.extend_from_slice(&buf[..n]),
            Err(e)
                if e.kind() == std::io::ErrorKind::WouldBlock
                    || e.kind() == std::io::ErrorKind::TimedOut =>
            {
                return false;
            }
            Err(_) => return true,
        }
    };
    if burst > 0 && s.write_all(&vec![b' '; burst]).is_err() {
        closed(&mut s, &mut reply);
        return (start.elapsed(), reply);
    }
    for _ in 0..trickle {
        let until = Instant::now() + every;
        while Instant::now() < until {
            if closed(&mut s, &mut reply) {
                return (start.elapsed(), reply);
            }
        }
        if s.write_all(b" ").is_err() {
            closed(&mut s, &mut reply);
            return (start.elapsed(), reply);
        }
    }
    (start.elapsed(), reply)
}

/// Item 1: 60 connections trickling a body byte every 500 ms against a cap
/// of 20 keep `/healthz` answering (each is dropped when a newer one needs
/// its place, and at the latest at the 3 s body deadline), and every slow
/// connection ends within the deadline.
#[test]
fn slow_bodies_do_not_hold_the_connection_cap() {
    let server = Server::start(
        "cap",
        &[
            ("TETHERPLAN_MAX_CONNECTIONS", "20"),
            ("TETHERPLAN_BODY_DEADLINE_S", "3"),
        ],
    );
    let addr = server.addr;
    let clients: Vec<_> = (0..60)
        .map(|_| {
            std::thread::spawn(move || {
                // at most 30 bytes over 15 s, then it stops by itself
                slow_body(addr, 1000, 0, Duration::from_millis(500), 30)
            })
        })
        .collect();
    std::thread::sleep(Duration::from_millis(500));
    let probes = 10;
    let mut failed = Vec::new();
    for i in 0..probes {
        if let Err(why) = server.healthy(Duration::from_secs(2)) {
            failed.push(format!("probe {i}: {why}"));
        }
        std::thread::sleep(Duration::from_millis(300));
    }
    let ok = probes - failed.len();
    let times: Vec<Duration> = clients.into_iter().map(|c| c.join().unwrap().0).collect();
    assert_eq!(
        ok, probes,
        "/healthz answered {ok} of {probes} probes; the others: {failed:?}"
    );
    let slowest = times.iter().max().unwrap();
    // deadline 3 s + the server's reaction (a phase change or a timer) + scheduling
    assert!(
        *slowest < Duration::from_secs(7),
        "a slow body was held {slowest:?} (body deadline 3 s)"
    );
    server.healthy(Duration::from_secs(2)).unwrap();
}

/// Item 2: 60 bodies of 1,000,000 bytes, each sent up to 900 kB at once
/// and then stalled, against a 8 MiB byte budget: most are refused (503)
/// as soon as the budget is spent, the resident memory grows by far less
/// than the 54 MB they carry, and all of them end by the body deadline.
#[test]
fn request_bodies_are_bounded_in_total() {
    let server = Server::start(
        "budget",
        &[
            ("TETHERPLAN_MAX_CONNECTIONS", "200"),
            ("TETHERPLAN_BODY_DEADLINE_S", "4"),
            ("TETHERPLAN_BODY_BUDGET_BYTES", "8388608"),
        ],
    );
    let addr = server.addr;
    let before = server.rss_kb();
    let clients: Vec<_> = (0..60)
        .map(|_| {
            std::thread::spawn(move || {
                slow_body(addr, 1_000_000, 900_000, Duration::from_millis(500), 12)
            })
        })
        .collect();
    // sample RSS while the bodies are held
    let mut peak = before;
    for _ in 0..20 {
        peak = peak.max(server.rss_kb());
        std::thread::sleep(Duration::from_millis(100));
    }
    let results: Vec<(Duration, Vec<u8>)> =
        clients.into_iter().map(|c| c.join().unwrap()).collect();
    let refused = results
        .iter()
        .filter(|(_, r)| r.starts_with(b"HTTP/1.1 503"))
        .count();
    let grown_mb = (peak.saturating_sub(before)) as f64 / 1024.0;
    eprintln!(
        "RSS {} kB before, peak {peak} kB (+{grown_mb:.1} MB) with 60 × 900 kB bodies; {refused} refused 503",
        before
    );
    // held: still connected after 3 s (the budget holds about 9 bodies
    // of 900 kB; the others are refused, or reset, at once)
    let held = results
        .iter()
        .filter(|(t, _)| *t > Duration::from_secs(3))
        .count();
    eprintln!("{held} of 60 held past 3 s");
    assert!(
        held <= 15,
        "{held} of 60 bodies held (budget 8 MiB: about 9 of 900 kB)"
    );
    assert!(
        grown_mb < 40.0,
        "RSS grew {grown_mb:.1} MB for 54 MB of bodies (budget 8 MiB)"
    );
    let slowest = results.iter().map(|(t, _)| *t).max().unwrap();
    assert!(slowest < Duration::from_secs(9), "held {slowest:?}");
    server.healthy(Duration::from_secs(2)).unwrap();
}

/// Item 2: an answer the client never reads is dropped at the write
/// deadline (2 s) instead of being held in memory.
#[test]
fn an_unread_answer_is_dropped_at_the_write_deadline() {
    let server = Server::start("write", &[("TETHERPLAN_WRITE_DEADLINE_S", "2")]);
    let mut s = connect(server.addr, Duration::from_secs(10));
    write!(
        s,
        "GET /big.bin HTTP/1.1\r\nHost: {}\r\nConnection: close\r\n\r\n",
        server.addr
    )
    .unwrap();
    std::thread::sleep(Duration::from_secs(4));
    let mut got = 0usize;
    let mut buf = vec![0u8; 1 << 16];
    let start = Instant::now();
    loop {
        match s.read(&mut buf) {
            Ok(0) | Err(_) => break,
            Ok(n) => got += n,
        }
        assert!(start.elapsed() < Duration::from_secs(10), "never closed");
    }
    assert!(
        got < 48 << 20,
        "the whole 48 MiB answer arrived ({got} bytes) after the write deadline"
    );
    server.healthy(Duration::from_secs(2)).unwrap();
}

/// Item 8: a too-large `Content-Length` is 413 from the head alone: no
/// `100 Continue` first, and at once even for 10 GB.
#[test]
fn oversize_bodies_are_refused_from_the_head() {
    let server = Server::start("expect", &[]);
    let head = format!(
        "POST /api/v1/critical HTTP/1.1\r\nHost: {}\r\nContent-Type: application/json\r\nContent-Length: 2097152\r\nExpect: 100-continue\r\n\r\n",
        server.addr
    );
    let raw = server.raw(&head);
    let text = String::from_utf8_lossy(&raw);
    assert!(text.starts_with("HTTP/1.1 413"), "{text}");
    assert!(!text.contains("100 Continue"), "{text}");
    let start = Instant::now();
    let head = format!(
        "POST /api/v1/critical HTTP/1.1\r\nHost: {}\r\nContent-Type: application/json\r\nContent-Length: 10000000000\r\n\r\n",
        server.addr
    );
    let raw = server.raw(&head);
    let reply = Reply::parse(&raw);
    assert_eq!(reply.status, 413, "{}", reply.body);
    assert_eq!(reply.json()["error"]["code"], "payload_too_large");
    assert!(
        start.elapsed() < Duration::from_secs(2),
        "{:?}",
        start.elapsed()
    );
}

/// Item 8: the Host allow-list against two Host headers and an
/// absolute-form target naming another host.
#[test]
fn host_edges_are_closed() {
    let server = Server::start("host", &[]);
    let a = server.addr;
    let status = |raw: Vec<u8>| Reply::parse(&raw).status;
    let two = format!(
        "GET /healthz HTTP/1.1\r\nHost: {a}\r\nHost: evil.example\r\nConnection: close\r\n\r\n"
    );
    assert_eq!(status(server.raw(&two)), 400);
    let absolute = format!(
        "GET http://evil.example/healthz HTTP/1.1\r\nHost: {a}\r\nConnection: close\r\n\r\n"
    );
    assert_eq!(status(server.raw(&absolute)), 421);
    for host in ["[::1]evil.com", "[::1].evil.com"] {
        let h = format!("GET /healthz HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n\r\n");
        assert_eq!(status(server.raw(&h)), 421, "{host}");
    }
    let own = format!("GET http://{a}/healthz HTTP/1.1\r\nHost: {a}\r\nConnection: close\r\n\r\n");
    assert_eq!(status(server.raw(&own)), 200);
}

/// Item 2, last clause: a job's answer is streamed from the store page by
/// page as the client reads, not built in memory per GET. 16 clients GET a
/// 24 MiB answer and never read: the server's resident memory grows by a
/// few pages per client, not by the 384 MiB the answers would take (main:
/// each GET held its whole answer until the write deadline), and every
/// client is dropped at the 4 s write deadline. A client that reads gets
/// the whole answer.
#[test]
fn unread_job_answers_are_streamed_not_held() {
    use tetherplan::jobs::store::{JobBackend, JobStore};
    const ANSWER_BYTES: usize = 24 << 20;
    const CLIENTS: usize = 16;
    let answer = format!("[{}0]", "1.25,".repeat(ANSWER_BYTES / 5));
    let server = Server::start_prepared(
        "answers",
        &[("TETHERPLAN_WRITE_DEADLINE_S", "4")],
        |dir: &Path| {
            let store = JobStore::open(&dir.join("jobs.db")).unwrap();
            let id = store.insert_simple("chart", "{}", 10).unwrap();
            assert_eq!(id, 1);
            let job = store.claim_next().unwrap().unwrap();
            assert!(store.finish_done(&job.lease, &answer).unwrap());
        },
    );
    let addr = server.addr;
    // one reader gets the whole answer, spliced into the view
    let reply = exchange(
        connect(addr, Duration::from_secs(30)),
        "GET",
        "/api/v1/jobs/1",
        &addr.to_string(),
        None,
        b"",
    );
    assert_eq!(reply.status, 200);
    let view: serde_json::Value = serde_json::from_str(&reply.body).unwrap();
    assert_eq!(view["status"], "done");
    assert_eq!(
        view["result"].as_array().map(Vec::len),
        Some(ANSWER_BYTES / 5 + 1)
    );
    drop(view);
    drop(reply);
    std::thread::sleep(Duration::from_millis(300));
    let before = server.rss_kb();
    let start = Instant::now();
    let clients: Vec<_> = (0..CLIENTS)
        .map(|_| {
            std::thread::spawn(move || {
                let mut s = connect(addr, Duration::from_secs(20));
                write!(s, "GET /api/v1/jobs/1 HTTP/1.1\r\nHost: {addr}\r\n\r\n").unwrap();
                // never read until the deadline is well past
                std::thread::sleep(Duration::from_secs(6));
                let mut got = 0usize;
                let mut buf = vec![0u8; 1 << 16];
                loop {
                    match s.read(&mut buf) {
                        Ok(0) | Err(_) => break,
                        Ok(n) => got += n,
                    }
                }
                (got, start.elapsed())
            })
        })
        .collect();
    let mut peak = before;
    for _ in 0..40 {
        peak = peak.max(server.rss_kb());
        std::thread::sleep(Duration::from_millis(100));
    }
    let results: Vec<(usize, Duration)> = clients.into_iter().map(|c| c.join().unwrap()).collect();
    let grown_mb = peak.saturating_sub(before) as f64 / 1024.0;
    let held_mb = (CLIENTS * ANSWER_BYTES) as f64 / (1 << 20) as f64;
    eprintln!(
        "RSS {before} kB before, peak {peak} kB (+{grown_mb:.1} MB) with {CLIENTS} unread GETs of a \
         {} MiB answer ({held_mb:.0} MiB if each were held); received {:?}",
        ANSWER_BYTES >> 20,
        results.iter().map(|r| r.0).collect::<Vec<_>>()
    );
    assert!(
        grown_mb < 48.0,
        "RSS grew {grown_mb:.1} MB for {CLIENTS} unread answers of {} MiB",
        ANSWER_BYTES >> 20
    );
    for (got, _) in &results {
        assert!(
            *got < ANSWER_BYTES,
            "a client that did not read got the whole answer ({got} bytes) after the deadline"
        );
    }
    // dropped at the deadline: the connection was closed when the client
    // first read (6 s), not held open to the end of the answer
    let slowest = results.iter().map(|r| r.1).max().unwrap();
    assert!(slowest < Duration::from_secs(12), "held {slowest:?}");
    server.healthy(Duration::from_secs(2)).unwrap();
}
