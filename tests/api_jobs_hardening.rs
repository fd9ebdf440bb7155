//! Jobs under a hostile or unlucky client: bounded answers, API tokens and
//! job ownership, idempotent submission, leases with fenced writes, the
//! attempt cap and the run-time limit. The router is driven with
//! `tower::ServiceExt::oneshot`; the queue is drained with the worker step.

use std::path::Path;
use std::sync::Arc;
use std::time::Duration;

use axum::Router;
use axum::http::{StatusCode, header};
use serde_json::{Value, json};
use tetherplan::api::auth::Tokens;
use tetherplan::api::{self, AppState};
use tetherplan::config::Limits;
use tetherplan::jobs::store::{ClaimPolicy, InsertError, JobBackend, JobStatus, JobStore, NewJob};
use tetherplan::jobs::{JobQueue, Submitter, try_execute_next};

mod common;
use common::Answer;

fn bearer(token: &str) -> String {
    format!("Bearer {token}")
}

fn system(elements: usize) -> Value {
    json!({
        "cable": {"mass_per_length_kg_m": 0.078},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
        "initial_length_m": 1.0,
        "model": {"kind": "linear_string", "elements": elements}
    })
}

fn chart_job(count: usize, elements: usize) -> Value {
    let mut r = system(elements);
    r["rates_m_s"] = json!({"min": 1.0, "max": 120.0, "count": count});
    json!({"kind": "chart", "request": r})
}

fn critical_job(rate: f64) -> Value {
    let mut r = system(50);
    r["profile"] = json!({"kind": "constant_rate", "rate_m_s": rate});
    json!({"kind": "critical", "request": r})
}

fn app_with(limits: Limits, tokens: &[&str]) -> (Router, Arc<JobQueue>) {
    let queue = common::queue_with(2, limits);
    let tokens: Vec<String> = tokens.iter().map(|t| t.to_string()).collect();
    let state = AppState::new(queue.clone()).with_tokens(&tokens);
    (api::router(state, Path::new("static")), queue)
}

async fn send(
    app: &Router,
    method: &str,
    uri: &str,
    headers: &[(&str, &str)],
    body: Option<&Value>,
) -> Answer {
    let (mut req, body) = common::json_request(method, uri, body);
    for (k, v) in headers {
        req = req.header(*k, *v);
    }
    common::request(app, req, body).await
}

// ---------------------------------------------------------------- bounded

/// The issue's hostile batch: 1000 charts of 10⁶ rates each, about 284 KB
/// of JSON asking for about 180 GB of answers, is refused at submission
/// with 422 naming the field; nothing is stored.
#[tokio::test]
async fn a_batch_of_a_thousand_million_point_charts_is_refused_at_submission() {
    let (app, queue) = app_with(Limits::default(), &[]);
    let item = chart_job(1_000_000, 50);
    let batch = json!({"kind": "batch", "request": vec![item.clone(); 1000]});
    let size = serde_json::to_vec(&batch).unwrap().len();
    assert!((200_000..400_000).contains(&size), "{size} bytes");
    let started = std::time::Instant::now();
    let a = send(&app, "POST", "/api/v1/jobs", &[], Some(&batch)).await;
    assert_eq!(a.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", a.text);
    assert_eq!(
        a.field(),
        "request[0].request.rates_m_s.count",
        "{}",
        a.text
    );
    assert!(a.text.contains("MB"), "{}", a.text);
    assert!(started.elapsed() < Duration::from_secs(10));
    // One such chart alone is refused as well…
    let a = send(&app, "POST", "/api/v1/jobs", &[], Some(&item)).await;
    assert_eq!(a.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", a.text);
    assert_eq!(a.field(), "request.rates_m_s.count");
    // …and a batch of charts that fit one by one but not together names the batch.
    let fits = chart_job(100_000, 50);
    let batch = json!({"kind": "batch", "request": vec![fits.clone(); 1000]});
    let a = send(&app, "POST", "/api/v1/jobs", &[], Some(&batch)).await;
    assert_eq!(a.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", a.text);
    assert_eq!(a.field(), "request", "{}", a.text);
    assert!(a.text.contains("GB"), "{}", a.text);
    assert!(queue.store.list(None, 10).unwrap().is_empty());
    // The same chart with fewer points is accepted.
    let a = send(&app, "POST", "/api/v1/jobs", &[], Some(&fits)).await;
    assert_eq!(a.status, StatusCode::ACCEPTED, "{}", a.text);
}

/// The estimate is an upper bound of the real answer, and not a loose one.
#[tokio::test]
async fn estimates_bound_the_real_answers() {
    use tetherplan::jobs::kinds::JobSubmission;
    let limits = Limits::default();
    for count in [2, 100, 5000] {
        let body = serde_json::to_vec(&chart_job(count, 20)).unwrap();
        let JobSubmission::One(item) = JobSubmission::parse(&body, &limits).unwrap() else {
            panic!()
        };
        let estimate = item.estimate().result_bytes;
        let real = JobSubmission::parse(&body, &limits)
            .unwrap()
            .run(&tetherplan::contract::run::NoProgress)
            .unwrap()
            .len() as u64;
        assert!(real <= estimate, "{count} rates: {real} > {estimate}");
        if count >= 100 {
            assert!(estimate < 3 * real, "{count} rates: {estimate} vs {real}");
        }
    }
}

/// The answer is served as stored: byte for byte the worker's JSON.
#[tokio::test]
async fn a_finished_job_serves_its_stored_answer_verbatim() {
    let (app, queue) = app_with(Limits::default(), &[]);
    let a = send(&app, "POST", "/api/v1/jobs", &[], Some(&chart_job(300, 20))).await;
    let id = a.json()["id"].as_i64().unwrap();
    assert_eq!(
        try_execute_next(&queue).unwrap().unwrap().status,
        JobStatus::Done
    );
    let stored = queue.store.get(id).unwrap().unwrap().result.unwrap();
    let a = send(&app, "GET", &format!("/api/v1/jobs/{id}"), &[], None).await;
    assert_eq!(a.status, StatusCode::OK);
    assert_eq!(a.headers[header::CONTENT_TYPE], "application/json");
    let prefix = r#","result":"#;
    let at = a.text.find(prefix).expect("a result");
    assert_eq!(&a.text[at + prefix.len()..a.text.len() - 1], stored);
    let v = a.json();
    assert_eq!(v["status"], "done");
    assert_eq!(
        v["result"]["series"][0]["points"].as_array().unwrap().len(),
        300
    );
}

/// A job that runs past the run-time limit fails with the reason.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_job_past_its_run_time_limit_fails_with_the_reason() {
    let limits = Limits {
        max_job_run_time: Duration::from_millis(300),
        ..Limits::default()
    };
    let (app, queue) = app_with(limits, &[]);
    // Several seconds of work at 1000 elements.
    let a = send(
        &app,
        "POST",
        "/api/v1/jobs",
        &[],
        Some(&chart_job(5000, 1000)),
    )
    .await;
    let id = a.json()["id"].as_i64().unwrap();
    let started = std::time::Instant::now();
    let q = queue.clone();
    let ran = tokio::task::spawn_blocking(move || try_execute_next(&q).unwrap().unwrap())
        .await
        .unwrap();
    assert_eq!(ran.status, JobStatus::Failed);
    assert!(
        started.elapsed() < Duration::from_secs(5),
        "{:?}",
        started.elapsed()
    );
    let v = send(&app, "GET", &format!("/api/v1/jobs/{id}"), &[], None)
        .await
        .json();
    assert_eq!(v["error"]["error"]["code"], "run_time_exceeded", "{v}");
    assert!(
        v["error"]["error"]["message"]
            .as_str()
            .unwrap()
            .contains("0.3 s")
    );
}

// ---------------------------------------------------------------- tokens

#[tokio::test]
async fn with_tokens_every_api_route_needs_one_and_jobs_belong_to_their_token() {
    let (app, queue) = app_with(Limits::default(), &["alpha-token", "beta-token"]);
    let alice = [("authorization", bearer("alpha-token"))];
    let alice: Vec<(&str, &str)> = alice.iter().map(|(k, v)| (*k, v.as_str())).collect();
    let bob_h = bearer("beta-token");
    let bob = [("authorization", bob_h.as_str())];

    // No token, a wrong one, a malformed header: 401 with the error body and a challenge.
    for headers in [
        vec![],
        vec![("authorization", "Bearer wrong")],
        vec![("authorization", "Basic YWxwaGEtdG9rZW4=")],
        vec![("authorization", "Bearer ")],
    ] {
        for (method, uri, body) in [
            ("POST", "/api/v1/jobs", Some(critical_job(10.0))),
            ("GET", "/api/v1/jobs", None),
            ("GET", "/api/v1/jobs/1", None),
            ("DELETE", "/api/v1/jobs/1", None),
            (
                "POST",
                "/api/v1/critical",
                Some(critical_job(10.0)["request"].clone()),
            ),
            ("GET", "/api/v1/nowhere", None),
        ] {
            let a = send(&app, method, uri, &headers, body.as_ref()).await;
            assert_eq!(
                a.status,
                StatusCode::UNAUTHORIZED,
                "{method} {uri} {headers:?}"
            );
            assert_eq!(a.code(), "unauthorized");
            let challenge = a.headers[header::WWW_AUTHENTICATE].to_str().unwrap();
            assert!(
                challenge.starts_with("Bearer realm=\"tetherplan\""),
                "{challenge}"
            );
        }
    }
    // Outside /api nothing is asked.
    assert_eq!(
        send(&app, "GET", "/healthz", &[], None).await.status,
        StatusCode::OK
    );
    assert_eq!(
        send(&app, "GET", "/openapi.json", &[], None).await.status,
        StatusCode::OK
    );
    // A synchronous route with a token answers.
    let a = send(
        &app,
        "POST",
        "/api/v1/critical",
        &alice,
        Some(&critical_job(10.0)["request"]),
    )
    .await;
    assert_eq!(a.status, StatusCode::OK, "{}", a.text);

    // Alice's job is hers: Bob gets 404 and does not see it listed or cancel it.
    let a = send(
        &app,
        "POST",
        "/api/v1/jobs",
        &alice,
        Some(&critical_job(10.0)),
    )
    .await;
    assert_eq!(a.status, StatusCode::ACCEPTED, "{}", a.text);
    let id = a.json()["id"].as_i64().unwrap();
    let uri = format!("/api/v1/jobs/{id}");
    assert_eq!(
        send(&app, "GET", &uri, &alice, None).await.status,
        StatusCode::OK
    );
    assert_eq!(
        send(&app, "GET", &uri, &bob, None).await.status,
        StatusCode::NOT_FOUND
    );
    assert_eq!(
        send(&app, "DELETE", &uri, &bob, None).await.status,
        StatusCode::NOT_FOUND
    );
    let listed = send(&app, "GET", "/api/v1/jobs", &bob, None).await.json();
    assert!(listed["jobs"].as_array().unwrap().is_empty(), "{listed}");
    let listed = send(&app, "GET", "/api/v1/jobs", &alice, None).await.json();
    assert_eq!(listed["jobs"][0]["id"], id);
    // The owner is stored as the token's hash, never the token.
    let stored_owner: Vec<String> = {
        let rec = queue.store.get(id).unwrap().unwrap();
        assert_eq!(rec.status, JobStatus::Queued);
        vec![Tokens::owner_id("alpha-token")]
    };
    assert_eq!(
        queue
            .store
            .get_owned(id, Some(&stored_owner[0]))
            .unwrap()
            .map(|r| r.id),
        Some(id)
    );
    // Bob's cancel did nothing; Alice's works.
    let a = send(&app, "DELETE", &uri, &alice, None).await;
    assert_eq!(a.status, StatusCode::OK);
    assert_eq!(a.json()["status"], "cancelled");
}

#[tokio::test]
async fn each_token_has_a_queue_quota() {
    let limits = Limits {
        max_pending_jobs_per_token: 2,
        ..Limits::default()
    };
    let (app, _queue) = app_with(limits, &["alpha-token", "beta-token"]);
    let a_h = bearer("alpha-token");
    let alice = [("authorization", a_h.as_str())];
    let b_h = bearer("beta-token");
    let bob = [("authorization", b_h.as_str())];
    for rate in [1.0, 2.0] {
        let a = send(
            &app,
            "POST",
            "/api/v1/jobs",
            &alice,
            Some(&critical_job(rate)),
        )
        .await;
        assert_eq!(a.status, StatusCode::ACCEPTED);
    }
    let a = send(
        &app,
        "POST",
        "/api/v1/jobs",
        &alice,
        Some(&critical_job(3.0)),
    )
    .await;
    assert_eq!(a.status, StatusCode::TOO_MANY_REQUESTS, "{}", a.text);
    assert_eq!(a.code(), "quota_full");
    assert!(a.headers.contains_key(header::RETRY_AFTER));
    // Bob's quota is his own.
    let a = send(&app, "POST", "/api/v1/jobs", &bob, Some(&critical_job(3.0))).await;
    assert_eq!(a.status, StatusCode::ACCEPTED);
}

// ---------------------------------------------------------------- exactly once

#[tokio::test]
async fn an_idempotency_key_returns_the_first_job() {
    let (app, queue) = app_with(Limits::default(), &["alpha-token", "beta-token"]);
    let a_h = bearer("alpha-token");
    let alice = [
        ("authorization", a_h.as_str()),
        ("idempotency-key", "order-17"),
    ];
    let b_h = bearer("beta-token");
    let bob = [
        ("authorization", b_h.as_str()),
        ("idempotency-key", "order-17"),
    ];
    let first = send(
        &app,
        "POST",
        "/api/v1/jobs",
        &alice,
        Some(&critical_job(10.0)),
    )
    .await;
    assert_eq!(first.status, StatusCode::ACCEPTED);
    let id = first.json()["id"].as_i64().unwrap();
    // The lost-202 retry: same key, same body → the same job, 200.
    let again = send(
        &app,
        "POST",
        "/api/v1/jobs",
        &alice,
        Some(&critical_job(10.0)),
    )
    .await;
    assert_eq!(again.status, StatusCode::OK, "{}", again.text);
    assert_eq!(again.json()["id"], id);
    assert_eq!(
        again.headers[header::LOCATION],
        format!("/api/v1/jobs/{id}")
    );
    // After it ran, a retry still returns it, with its status.
    try_execute_next(&queue).unwrap();
    let again = send(
        &app,
        "POST",
        "/api/v1/jobs",
        &alice,
        Some(&critical_job(10.0)),
    )
    .await;
    assert_eq!(
        (again.status, again.json()["status"].clone()),
        (StatusCode::OK, json!("done"))
    );
    // Same key, another body: 422 naming the header.
    let other = send(
        &app,
        "POST",
        "/api/v1/jobs",
        &alice,
        Some(&critical_job(11.0)),
    )
    .await;
    assert_eq!(
        other.status,
        StatusCode::UNPROCESSABLE_ENTITY,
        "{}",
        other.text
    );
    assert_eq!(other.code(), "idempotency_key_reused");
    assert_eq!(other.field(), "Idempotency-Key");
    assert!(other.text.contains(&format!("job {id}")), "{}", other.text);
    // Keys are per token: Bob's "order-17" is another job.
    let b = send(
        &app,
        "POST",
        "/api/v1/jobs",
        &bob,
        Some(&critical_job(11.0)),
    )
    .await;
    assert_eq!(b.status, StatusCode::ACCEPTED);
    assert_ne!(b.json()["id"], id);
    // A bad key is refused.
    let bad = [
        ("authorization", a_h.as_str()),
        ("idempotency-key", "with space"),
    ];
    let a = send(
        &app,
        "POST",
        "/api/v1/jobs",
        &bad,
        Some(&critical_job(10.0)),
    )
    .await;
    assert_eq!(a.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert_eq!(queue.store.list(None, 10).unwrap().len(), 2);
}

// ---------------------------------------------------------------- leases

fn temp_db(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("tetherplan-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir.join("jobs.db")
}

fn policy(lease_ms: u64, max_attempts: u32) -> ClaimPolicy<'static> {
    ClaimPolicy {
        lease: Duration::from_millis(lease_ms),
        max_attempts,
        exhausted_error: r#"{"error":{"code":"attempts_exhausted","field":null,"message":"x"}}"#,
    }
}

/// Two stores (two workers) on one file: a job is claimed by one only; the
/// other takes it over once the lease expires, and from then on the first
/// one's writes (progress, result, failure, renewal) change nothing.
#[test]
fn leases_fence_writes_and_expire_into_a_takeover() {
    let db = temp_db("lease-fence");
    let a = JobStore::open(&db).unwrap();
    let b = JobStore::open(&db).unwrap();
    assert_ne!(a.worker(), b.worker());
    let id = a.insert_simple("critical", "{}", 10).unwrap();
    let first = a.claim(&policy(300, 5)).unwrap().unwrap();
    assert_eq!((first.id, first.attempts), (id, 1));
    assert!(b.claim(&policy(300, 5)).unwrap().is_none(), "held by a");
    assert!(a.renew(&first.lease, Duration::from_millis(300)).unwrap());
    assert!(a.set_progress(&first.lease, 0.5).unwrap());
    std::thread::sleep(Duration::from_millis(400));
    let second = b.claim(&policy(10_000, 5)).unwrap().unwrap();
    assert_eq!((second.id, second.attempts), (id, 2));
    assert!(second.lease.epoch > first.lease.epoch);
    // The old holder is fenced off.
    assert!(!a.set_progress(&first.lease, 0.9).unwrap());
    assert!(!a.renew(&first.lease, Duration::from_secs(10)).unwrap());
    assert!(!a.finish_done(&first.lease, "{\"stale\":true}").unwrap());
    assert!(!a.finish_failed(&first.lease, "{}").unwrap());
    assert!(!a.release(&first.lease).unwrap());
    assert!(b.finish_done(&second.lease, "{\"ok\":true}").unwrap());
    let rec = a.get(id).unwrap().unwrap();
    assert_eq!(rec.status, JobStatus::Done);
    assert_eq!(rec.result.as_deref(), Some("{\"ok\":true}"));
    assert_eq!(rec.attempts, 2);
    assert_eq!(rec.worker.as_deref(), Some(b.worker().as_str()));
    // Cancelling fences the holder too.
    let id = a.insert_simple("critical", "{}", 10).unwrap();
    let c = a.claim(&policy(10_000, 5)).unwrap().unwrap();
    assert_eq!(c.id, id);
    b.cancel(id, None, "{}").unwrap();
    assert!(!a.renew(&c.lease, Duration::from_secs(1)).unwrap());
    assert!(!a.finish_done(&c.lease, "{}").unwrap());
    assert_eq!(a.status(id).unwrap(), Some(JobStatus::Cancelled));
}

/// A job whose process died at every attempt is failed, not run again.
#[test]
fn a_job_that_kills_its_process_stops_after_max_attempts() {
    let db = temp_db("attempts");
    let store = JobStore::open(&db).unwrap();
    let id = store.insert_simple("critical", "{}", 10).unwrap();
    for attempt in 1..=3 {
        let c = store.claim(&policy(50, 3)).unwrap().unwrap();
        assert_eq!((c.id, c.attempts), (id, attempt));
        // The process "dies": no renewal, the lease runs out.
        std::thread::sleep(Duration::from_millis(80));
    }
    assert!(store.claim(&policy(50, 3)).unwrap().is_none());
    let rec = store.get(id).unwrap().unwrap();
    assert_eq!(rec.status, JobStatus::Failed);
    assert_eq!(rec.attempts, 3);
    assert!(rec.error.unwrap().contains("attempts_exhausted"));
}

/// Through the queue: the reason names the number of starts.
#[test]
fn the_queue_fails_an_exhausted_job_with_a_reason() {
    let db = temp_db("attempts-queue");
    let limits = Limits {
        job_lease: Duration::from_millis(50),
        max_job_attempts: 2,
        ..Limits::default()
    };
    let store = JobStore::open(&db).unwrap();
    let body = serde_json::to_vec(&critical_job(10.0)).unwrap();
    let queue = JobQueue::new(store, 1, limits);
    let s = queue.submit_as(&body, &Submitter::default()).unwrap();
    // Two claims by "processes" that died.
    for _ in 0..2 {
        queue.store.claim(&policy(50, 2)).unwrap().unwrap();
        std::thread::sleep(Duration::from_millis(80));
    }
    let ran = try_execute_next(&queue).unwrap();
    assert!(ran.is_none(), "nothing left to run: {ran:?}");
    let rec = queue.store.get(s.id).unwrap().unwrap();
    assert_eq!(rec.status, JobStatus::Failed);
    let error: Value = serde_json::from_str(&rec.error.unwrap()).unwrap();
    assert_eq!(error["error"]["code"], "attempts_exhausted");
    assert!(
        error["error"]["message"]
            .as_str()
            .unwrap()
            .contains("started 2 times")
    );
}

/// A restarted process on the same host takes over its dead predecessor's
/// job at once, without waiting for the lease (here an hour) to expire.
#[test]
fn a_restart_takes_over_its_own_interrupted_job_at_once() {
    let db = temp_db("restart");
    let store = JobStore::open(&db).unwrap();
    let id = store.insert_simple("critical", "{}", 10).unwrap();
    store.claim(&policy(3_600_000, 5)).unwrap().unwrap();
    drop(store);
    // Same pid, new store: an earlier life of this process.
    let store = JobStore::open(&db).unwrap();
    let c = store.claim(&policy(3_600_000, 5)).unwrap().unwrap();
    assert_eq!((c.id, c.attempts), (id, 2));
}

/// The store refuses a reused key with another body, also when two
/// submissions race past the first check.
#[test]
fn the_store_keeps_one_job_per_key() {
    let store = JobStore::open_in_memory().unwrap();
    let job = |hash: &'static str| NewJob {
        kind: "critical",
        request: "{}",
        owner: Some("o"),
        idempotency_key: Some("k"),
        request_hash: hash,
        max_pending: 10,
        max_pending_per_owner: 10,
        priority: 0,
        reserve_bytes: 0,
        max_stored_bytes: u64::MAX,
    };
    let first = store.insert(&job("h1")).unwrap();
    let again = store.insert(&job("h1")).unwrap();
    assert!(matches!(
        again,
        tetherplan::jobs::store::Inserted::Existing { .. }
    ));
    assert!(matches!(
        store.insert(&job("h2")),
        Err(InsertError::KeyReused { .. })
    ));
    assert_eq!(store.list(None, 10).unwrap().len(), 1, "{first:?}");
}

// ---------------------------------------------------------------- store quota

/// Issue 22: each token's jobs (request plus estimated answer while
/// pending, then request plus answer) and named systems keep at most
/// `max_stored_bytes_per_token`; past it a submission or a system is 429
/// `store_quota_full` in plain words, with `Retry-After` until the token's
/// oldest finished job expires (when one has finished). Other tokens keep
/// their own room. On main every one of these submissions is accepted.
#[tokio::test]
async fn the_store_quota_is_per_token_and_answers_429() {
    use tetherplan::jobs::estimate::SMALL_ANSWER;
    let job = critical_job(10.0);
    let req = serde_json::to_vec(&job).unwrap().len() as u64;
    // a critical answer is estimated at SMALL_ANSWER (8 KiB): two jobs fit
    let quota = 2 * (req + SMALL_ANSWER) + SMALL_ANSWER / 2;
    let limits = Limits {
        max_stored_bytes_per_token: quota,
        job_retention: Duration::from_secs(600),
        ..Limits::default()
    };
    let (app, queue) = app_with(limits, &["alpha", "beta"]);
    let alpha = [("authorization", "Bearer alpha")];
    let beta = [("authorization", "Bearer beta")];
    for _ in 0..2 {
        let a = send(&app, "POST", "/api/v1/jobs", &alpha, Some(&job)).await;
        assert_eq!(a.status, StatusCode::ACCEPTED, "{}", a.text);
    }
    let refused = send(&app, "POST", "/api/v1/jobs", &alpha, Some(&job)).await;
    assert_eq!(
        refused.status,
        StatusCode::TOO_MANY_REQUESTS,
        "{}",
        refused.text
    );
    let e = refused.error();
    assert_eq!(e.code, "store_quota_full");
    assert!(
        e.message.contains(&format!("{quota} bytes kept per token"))
            && !e.message.contains("TETHERPLAN"),
        "{}",
        e.message
    );
    assert!(
        refused.headers.get(header::RETRY_AFTER).is_none(),
        "nothing finished yet: no time to name"
    );
    let b = send(&app, "POST", "/api/v1/jobs", &beta, Some(&job)).await;
    assert_eq!(b.status, StatusCode::ACCEPTED, "{}", b.text);

    // the first job finishes: its answer (far below its estimate) replaces the reserve
    let q = queue.clone();
    let ran = tokio::task::spawn_blocking(move || try_execute_next(&q).unwrap().unwrap())
        .await
        .unwrap();
    assert_eq!(ran.status, JobStatus::Done);
    let answer = send(
        &app,
        "GET",
        &format!("/api/v1/jobs/{}", ran.id),
        &alpha,
        None,
    )
    .await;
    let answer_len = serde_json::to_vec(&answer.json()["result"]).unwrap().len() as u64;
    assert!(
        req + answer_len < SMALL_ANSWER / 2,
        "{answer_len} bytes of answer"
    );
    let a = send(&app, "POST", "/api/v1/jobs", &alpha, Some(&job)).await;
    assert_eq!(a.status, StatusCode::ACCEPTED, "{}", a.text);
    let refused = send(&app, "POST", "/api/v1/jobs", &alpha, Some(&job)).await;
    assert_eq!(
        refused.status,
        StatusCode::TOO_MANY_REQUESTS,
        "{}",
        refused.text
    );
    let retry: u32 = refused.headers[header::RETRY_AFTER]
        .to_str()
        .unwrap()
        .parse()
        .unwrap();
    assert!(
        (590..=600).contains(&retry),
        "Retry-After {retry} (retention 600 s)"
    );
}

/// Named systems count against the same quota.
#[tokio::test]
async fn named_systems_count_against_the_store_quota() {
    let system =
        json!({"aerostat": {"net_buoyancy_n": 1000.0}, "cable": {"mass_per_length_kg_m": 0.078}});
    let size = serde_json::to_vec(&system).unwrap().len() as u64;
    let limits = Limits {
        max_stored_bytes_per_token: size + size / 2,
        ..Limits::default()
    };
    let (app, _) = app_with(limits, &["alpha", "beta"]);
    let alpha = [("authorization", "Bearer alpha")];
    let beta = [("authorization", "Bearer beta")];
    let put = send(&app, "PUT", "/api/v1/systems/rig", &alpha, Some(&system)).await;
    assert_eq!(put.status, StatusCode::CREATED, "{}", put.text);
    // replacing it takes no more room; a second one does not fit
    let put = send(&app, "PUT", "/api/v1/systems/rig", &alpha, Some(&system)).await;
    assert_eq!(put.status, StatusCode::OK, "{}", put.text);
    let put = send(&app, "PUT", "/api/v1/systems/rig-2", &alpha, Some(&system)).await;
    assert_eq!(put.status, StatusCode::TOO_MANY_REQUESTS, "{}", put.text);
    assert_eq!(put.error().code, "store_quota_full");
    let put = send(&app, "PUT", "/api/v1/systems/rig-2", &beta, Some(&system)).await;
    assert_eq!(put.status, StatusCode::CREATED, "{}", put.text);
}
