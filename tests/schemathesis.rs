//! A short schemathesis pass over the live server: the release binary on a
//! free loopback port with a temporary database, fuzzed from its own
//! `/openapi.json`. It must find no 5xx (`not_a_server_error`) and no
//! answer outside the document (`response_schema_conformance`), and every
//! operation must answer at least one 2xx (issue 22): read from the run's
//! HAR report, each request matched to its operation by method and path
//! template. The server runs no jobs (`TETHERPLAN_JOB_THREADS=0`), so a
//! job the stateful phase submits is still queued when it follows the
//! link to `DELETE /api/v1/jobs/{id}` (a finished one answers 409); done
//! jobs are checked against the schema in `api_job_schema.rs`.
//!
//! schemathesis comes from a venv (`.ci/run` creates
//! `target/schemathesis-venv`; `TETHERPLAN_SCHEMATHESIS` names another
//! executable). Without it the test prints `skipped`, unless `CI` is set.
//! Bounded: a few examples per operation, one worker, killed after 4 min.

use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

mod common;
use common::http::{serve_recorded_forecast, spawn_listening};

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
    // The forecast source (`GET /api/v1/forecast`): the recorded
    // Open-Meteo file, served on loopback.
    let forecast_url = serve_recorded_forecast();
    let (mut server, addr) = spawn_listening(
        Command::new(env!("CARGO_BIN_EXE_tetherplan"))
            .args([
                "serve",
                "--addr",
                "127.0.0.1:0",
                "--forecast-url",
                &forecast_url,
                "--db",
            ])
            .arg(dir.join("jobs.db"))
            .current_dir(&dir)
            .env("RUST_LOG", "error")
            .env("TETHERPLAN_SOLVE_TIMEOUT_S", "10")
            .env("TETHERPLAN_JOB_THREADS", "0")
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
            "--report",
            "har",
        ])
        .arg("--report-har-path")
        .arg(dir.join("run.har"))
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
    let har = std::fs::read(dir.join("run.har")).ok();
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
    let har: serde_json::Value =
        serde_json::from_slice(&har.expect("schemathesis wrote its HAR report")).unwrap();
    let statuses = statuses_by_operation(&har);
    let mut without_2xx = Vec::new();
    for (op, seen) in &statuses {
        eprintln!("{op}: {seen:?}");
        // schemathesis loaded its schema from it (200), before the report began
        if op == "GET /openapi.json" {
            continue;
        }
        if !seen.keys().any(|s| (200..300).contains(s)) {
            without_2xx.push(op.clone());
        }
    }
    assert!(
        without_2xx.is_empty(),
        "no 2xx answer to {without_2xx:?} in {} requests",
        har["log"]["entries"].as_array().map_or(0, Vec::len)
    );
}

/// The answers' statuses (and how many of each) per operation of the
/// committed OpenAPI document (`METHOD /path/{template}`), every
/// operation listed.
fn statuses_by_operation(
    har: &serde_json::Value,
) -> std::collections::BTreeMap<String, std::collections::BTreeMap<u64, usize>> {
    let doc: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/openapi/openapi.json"))
            .unwrap(),
    )
    .unwrap();
    let mut ops = Vec::new();
    for (path, item) in doc["paths"].as_object().unwrap() {
        for method in item.as_object().unwrap().keys() {
            ops.push((method.to_uppercase(), path.clone()));
        }
    }
    let matches = |template: &str, path: &str| {
        let (t, p): (Vec<_>, Vec<_>) = (template.split('/').collect(), path.split('/').collect());
        t.len() == p.len()
            && t.iter()
                .zip(&p)
                .all(|(t, p)| t == p || (t.starts_with('{') && t.ends_with('}') && !p.is_empty()))
    };
    let mut out: std::collections::BTreeMap<String, std::collections::BTreeMap<u64, usize>> = ops
        .iter()
        .map(|(m, p)| (format!("{m} {p}"), Default::default()))
        .collect();
    for e in har["log"]["entries"].as_array().unwrap() {
        let method = e["request"]["method"].as_str().unwrap();
        let url = e["request"]["url"].as_str().unwrap();
        let path = url
            .split_once("://")
            .map_or(url, |(_, rest)| rest.find('/').map_or("/", |i| &rest[i..]));
        let path = path.split(['?', '#']).next().unwrap();
        // a request no operation matches (an empty path parameter) is left out
        let Some((m, t)) = ops.iter().find(|(m, t)| m == method && matches(t, path)) else {
            continue;
        };
        let op = format!("{m} {t}");
        let status = e["response"]["status"].as_u64().unwrap_or(0);
        *out.entry(op).or_default().entry(status).or_default() += 1;
    }
    out
}

fn tail(text: &str, lines: usize) -> String {
    let all: Vec<&str> = text.lines().collect();
    all[all.len().saturating_sub(lines)..].join("\n")
}
