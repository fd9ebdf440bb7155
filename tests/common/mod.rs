//! The in-process harness the `api_*` test binaries share: the router over
//! an in-memory job store, driven with `tower::ServiceExt::oneshot`
//! (requests with an optional JSON body, answers as text or JSON), and
//! small JSON helpers. Each binary includes it with `mod common;`.

// Each test binary uses a subset of these helpers; the rest would warn as
// dead code in that binary although another one uses them.
#![allow(dead_code)]

pub mod flights;
pub mod http;
pub mod pg;

use std::path::Path;
use std::sync::Arc;

use axum::Router;
use axum::body::Body;
use axum::http::{HeaderMap, Request, StatusCode, header, request};
use http_body_util::BodyExt;
use serde_json::Value;
use tetherplan::api::{self, AppState};
use tetherplan::config::Limits;
use tetherplan::contract::dto::{ErrorBody, ErrorDetail};
use tetherplan::jobs::JobQueue;
use tetherplan::jobs::store::JobStore;
use tower::ServiceExt;

/// A job queue over an in-memory store whose pool has `threads` threads.
pub fn queue_with(threads: usize, limits: Limits) -> Arc<JobQueue> {
    Arc::new(JobQueue::new(
        JobStore::open_in_memory().unwrap(),
        threads,
        limits,
    ))
}

/// The router over [`queue_with`]`(threads, limits)`, and the queue (for
/// `try_execute_next`).
pub fn app_with(threads: usize, limits: Limits) -> (Router, Arc<JobQueue>) {
    let queue = queue_with(threads, limits);
    (
        api::router(AppState::new(queue.clone()), Path::new("static")),
        queue,
    )
}

/// [`app_with`] with two threads and the default limits.
pub fn app() -> (Router, Arc<JobQueue>) {
    app_with(2, Limits::default())
}

/// An answer: status, headers and body text.
pub struct Answer {
    pub status: StatusCode,
    pub headers: HeaderMap,
    pub text: String,
}

impl Answer {
    /// The body as JSON (a panic showing the text when it is not JSON).
    pub fn json(&self) -> Value {
        serde_json::from_str(&self.text).unwrap_or_else(|e| panic!("not JSON ({e}): {}", self.text))
    }

    /// The error body; asserts its shape (JSON, a message).
    pub fn error(&self) -> ErrorDetail {
        assert_eq!(
            self.headers[header::CONTENT_TYPE],
            "application/json",
            "{}",
            self.text
        );
        let body: ErrorBody = serde_json::from_str(&self.text)
            .unwrap_or_else(|e| panic!("not an error body ({e}): {}", self.text));
        assert!(!body.error.message.is_empty());
        body.error
    }

    /// The error code, or "" when there is none.
    pub fn code(&self) -> String {
        self.json()["error"]["code"]
            .as_str()
            .unwrap_or("")
            .to_string()
    }

    /// The error field, or "" when there is none.
    pub fn field(&self) -> String {
        self.json()["error"]["field"]
            .as_str()
            .unwrap_or("")
            .to_string()
    }
}

/// The request `req` with `body`, answered by `app`.
pub async fn request(app: &Router, req: request::Builder, body: Body) -> Answer {
    let resp = app.clone().oneshot(req.body(body).unwrap()).await.unwrap();
    let status = resp.status();
    let headers = resp.headers().clone();
    let bytes = resp.into_body().collect().await.unwrap().to_bytes();
    Answer {
        status,
        headers,
        text: String::from_utf8_lossy(&bytes).into_owned(),
    }
}

/// A request builder for `method uri` with `body` as JSON (and its content
/// type) when given.
pub fn json_request(method: &str, uri: &str, body: Option<&Value>) -> (request::Builder, Body) {
    let req = Request::builder().method(method).uri(uri);
    match body {
        Some(b) => (
            req.header(header::CONTENT_TYPE, "application/json"),
            Body::from(serde_json::to_vec(b).unwrap()),
        ),
        None => (req, Body::empty()),
    }
}

/// `method uri` with `body` as JSON (and its content type) when given;
/// the status and the answer's text.
pub async fn send_text(
    app: &Router,
    method: &str,
    uri: &str,
    body: Option<&Value>,
) -> (StatusCode, String) {
    let (req, body) = json_request(method, uri, body);
    let answer = request(app, req, body).await;
    (answer.status, answer.text)
}

/// [`send_text`] with the answer parsed as JSON (a panic showing the text
/// when it is not JSON).
pub async fn send(
    app: &Router,
    method: &str,
    uri: &str,
    body: Option<&Value>,
) -> (StatusCode, Value) {
    let (req, body) = json_request(method, uri, body);
    let answer = request(app, req, body).await;
    (answer.status, answer.json())
}

/// `POST uri` with `body`; the status and the answer's text.
pub async fn post_text(app: &Router, uri: &str, body: &Value) -> (StatusCode, String) {
    send_text(app, "POST", uri, Some(body)).await
}

/// `POST uri` with `body`; the status and the answer as JSON.
pub async fn post(app: &Router, uri: &str, body: &Value) -> (StatusCode, Value) {
    send(app, "POST", uri, Some(body)).await
}

/// `GET uri`; the answer as JSON.
pub async fn get(app: &Router, uri: &str) -> Value {
    send(app, "GET", uri, None).await.1
}

/// `base` with the top-level keys of `extra` set (added or replaced).
pub fn with(mut base: Value, extra: Value) -> Value {
    for (k, v) in extra.as_object().unwrap() {
        base[k] = v.clone();
    }
    base
}

/// The error code and field of an error body (a panic showing the text
/// when it is not one).
pub fn error(text: &str) -> (String, Option<String>) {
    let e: ErrorBody =
        serde_json::from_str(text).unwrap_or_else(|e| panic!("not an error body ({e}): {text}"));
    (e.error.code, e.error.field)
}

/// Every path (object keys and array indices) in `v` below `prefix`,
/// parents before children, into `out`.
pub fn paths(v: &Value, prefix: Vec<String>, out: &mut Vec<Vec<String>>) {
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                let mut p = prefix.clone();
                p.push(k.clone());
                out.push(p.clone());
                paths(x, p, out);
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                let mut p = prefix.clone();
                p.push(i.to_string());
                out.push(p.clone());
                paths(x, p, out);
            }
        }
        _ => {}
    }
}

/// Sets the value at `path` (one of [`paths`]) in `v` to `new`.
pub fn replace(v: &mut Value, path: &[String], new: Value) {
    let mut cur = v;
    for key in path {
        cur = match cur {
            Value::Object(m) => m.get_mut(key).unwrap(),
            Value::Array(a) => &mut a[key.parse::<usize>().unwrap()],
            _ => unreachable!(),
        };
    }
    *cur = new;
}

/// A copy of `v` with the value at `path` set to `new`.
pub fn replaced(v: &Value, path: &[String], new: Value) -> Value {
    let mut out = v.clone();
    replace(&mut out, path, new);
    out
}

/// The router over an in-memory store with API `tokens` (as
/// `TETHERPLAN_API_TOKENS=alpha,beta` configures it), and the queue.
pub fn app_with_tokens(tokens: &[&str]) -> (Router, Arc<JobQueue>) {
    let queue = queue_with(1, Limits::default());
    let tokens: Vec<String> = tokens.iter().map(|t| t.to_string()).collect();
    (
        api::router(
            AppState::new(queue.clone()).with_tokens(&tokens),
            Path::new("static"),
        ),
        queue,
    )
}

/// `method uri` as the holder of `token`, with `body` as JSON when given;
/// the status and the answer as text.
pub async fn send_as(
    app: &Router,
    token: &str,
    method: &str,
    uri: &str,
    body: Option<&Value>,
) -> (StatusCode, String) {
    let (req, body) = json_request(method, uri, body);
    let req = req.header(header::AUTHORIZATION, format!("Bearer {token}"));
    let answer = request(app, req, body).await;
    (answer.status, answer.text)
}
