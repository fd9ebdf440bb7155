//! A short schemathesis pass over the live server: the release binary on a
//! free loopback port with a temporary database, fuzzed from its own
//! `/openapi.json`. It must find no 5xx (`not_a_server_error`) and no
//! answer outside the document (`response_schema_conformance`).
//!
//! schemathesis comes from a venv (`.ci/run` creates
//! `target/schemathesis-venv`; `TETHERPLAN_SCHEMATHESIS` names another
//! executable). Without it the test prints `skipped`, unless `CI` is set.
//! Bounded: a few examples per operation, one worker, killed after 4 min.

use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

mod common;
use common::http::spawn_listening;

fn schemathesis() -> Option<PathBuf> {
    if let Ok(p) = std::env::var("TETHERPLAN_SCHEMATHESIS") {
        return Some(PathBuf::from(p));
    }
    let venv =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/schemathesis-venv/bin/schemathesis");
    venv.exists().then_some(venv)
}

#[test]
fn schemathesis_finds_no_server_error_and_no_schema_violation() {
    let Some(st) = schemathesis() else {
        assert!(
            std::env::var_os("CI").is_none(),
            "CI is set but schemathesis is missing: run .ci/run (it creates target/schemathesis-venv)"
        );
        eprintln!(
            "skipped: no schemathesis (python3 -m venv target/schemathesis-venv && target/schemathesis-venv/bin/pip install schemathesis)"
        );
        return;
    };
    let dir = std::env::temp_dir().join(format!("tetherplan-st-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let (mut server, addr) = spawn_listening(
        Command::new(env!("CARGO_BIN_EXE_tetherplan"))
            .args(["serve", "--addr", "127.0.0.1:0", "--db"])
            .arg(dir.join("jobs.db"))
            .current_dir(&dir)
            .env("RUST_LOG", "error")
            .env("TETHERPLAN_SOLVE_TIMEOUT_S", "10")
            .env_remove("TETHERPLAN_API_TOKENS")
            .stderr(Stdio::inherit()),
    );
    let base = format!("http://{addr}");
    let start = Instant::now();
    let mut run = Command::new(&st)
        .arg("run")
        .arg(format!("{base}/openapi.json"))
        .args([
            "--checks",
            "not_a_server_error,response_schema_conformance",
            "--phases",
            "examples,fuzzing,stateful",
            "--max-examples",
            "5",
            "--workers",
            "1",
            "--request-timeout",
            "30",
            "--no-color",
            "--seed",
            "1",
        ])
        .current_dir(&dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("schemathesis runs");
    let limit = Duration::from_secs(240);
    let status = loop {
        if let Some(s) = run.try_wait().unwrap() {
            break Some(s);
        }
        if start.elapsed() > limit {
            let _ = run.kill();
            break None;
        }
        std::thread::sleep(Duration::from_millis(200));
    };
    let out = run.wait_with_output().unwrap();
    let _ = server.kill();
    let _ = server.wait();
    let _ = std::fs::remove_dir_all(&dir);
    let text = format!(
        "{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    eprintln!(
        "schemathesis took {:?}:\n{}",
        start.elapsed(),
        tail(&text, 60)
    );
    let status = status.unwrap_or_else(|| panic!("schemathesis did not finish within {limit:?}"));
    assert!(status.success(), "schemathesis found failures:\n{text}");
}

fn tail(text: &str, lines: usize) -> String {
    let all: Vec<&str> = text.lines().collect();
    all[all.len().saturating_sub(lines)..].join("\n")
}
