//! `tetherplan feed` (issue 33): a recorded log replayed against a running
//! server's `POST /api/v1/flights/{id}/telemetry`, in batches
//! ([`crate::contract::flight::feed`]), paced by the log's `time_s`
//! divided by the speed (none: as fast as the server answers).
//!
//! HTTP/1.1 over plain TCP with hyper's client (no TLS: a local or
//! tunnelled server), a fresh connection per batch. A batch whose
//! connection fails, or that is answered 503 or 5xx, is sent again (at
//! most [`ATTEMPTS`] times, waiting longer each time): the server keys
//! samples by `time_s`, so a batch stored before the failure is only
//! counted as duplicates. A 4xx ends the feed with the server's error.

use std::time::{Duration, Instant};

use axum::body::Bytes;
use http_body_util::{BodyExt, Full};
use hyper::Request;
use hyper_util::rt::TokioIo;

use crate::contract::flight::dto::TelemetryOutput;
use crate::contract::flight::feed::{Batch, Log};

/// Tries of one batch.
pub const ATTEMPTS: usize = 8;
/// Lines of a batch at full speed.
pub const MAX_BATCH_LINES: usize = 2000;

/// Where to feed.
#[derive(Clone, Debug)]
pub struct Target {
    /// `host:port`.
    pub authority: String,
    /// The path prefix of the server's URL (usually empty).
    pub base_path: String,
    pub token: Option<String>,
    pub flight: i64,
}

impl Target {
    /// From a `http://host:port[/prefix]` URL.
    pub fn new(url: &str, token: Option<String>, flight: i64) -> Result<Self, String> {
        let rest = url.strip_prefix("http://").ok_or_else(|| {
            format!("--server must be an http:// URL (no TLS in the feed), got `{url}`")
        })?;
        let (authority, path) = match rest.find('/') {
            Some(i) => (&rest[..i], rest[i..].trim_end_matches('/')),
            None => (rest, ""),
        };
        if authority.is_empty() {
            return Err(format!("--server names no host: `{url}`"));
        }
        let authority = if authority.contains(':') {
            authority.to_string()
        } else {
            format!("{authority}:80")
        };
        Ok(Self {
            authority,
            base_path: path.to_string(),
            token,
            flight,
        })
    }
}

/// A refused sample, its line in the file.
#[derive(Clone, Debug, PartialEq)]
pub struct Refused {
    pub line: Option<usize>,
    pub field: String,
    pub reason: String,
}

/// What a feed did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Summary {
    pub batches: usize,
    pub accepted: usize,
    pub duplicates: usize,
    pub refused: Vec<Refused>,
    /// Batches sent again after a failure.
    pub retries: usize,
    pub state: Option<String>,
}

/// Why a feed stopped.
#[derive(Debug)]
pub enum FeedError {
    /// The server answered 4xx: its status and body.
    Refused { status: u16, body: String },
    /// No answer after every attempt.
    Unreachable(String),
}

async fn send_once(target: &Target, ct: &str, body: &str) -> Result<(u16, String), String> {
    let stream = tokio::net::TcpStream::connect(&target.authority)
        .await
        .map_err(|e| format!("cannot connect to {}: {e}", target.authority))?;
    let (mut sender, conn) = hyper::client::conn::http1::handshake(TokioIo::new(stream))
        .await
        .map_err(|e| format!("HTTP handshake: {e}"))?;
    let driver = tokio::spawn(conn);
    let mut req = Request::post(format!(
        "{}/api/v1/flights/{}/telemetry",
        target.base_path, target.flight
    ))
    .header(hyper::header::HOST, &target.authority)
    .header(hyper::header::CONTENT_TYPE, ct);
    if let Some(t) = &target.token {
        req = req.header(hyper::header::AUTHORIZATION, format!("Bearer {t}"));
    }
    let req = req
        .body(Full::new(Bytes::from(body.to_string())))
        .map_err(|e| format!("request: {e}"))?;
    let res = sender
        .send_request(req)
        .await
        .map_err(|e| format!("sending: {e}"))?;
    let status = res.status().as_u16();
    let bytes = res
        .into_body()
        .collect()
        .await
        .map_err(|e| format!("reading the answer: {e}"))?
        .to_bytes();
    driver.abort();
    Ok((status, String::from_utf8_lossy(&bytes).into_owned()))
}

/// Sends one batch, again on a connection failure or a 5xx.
async fn send(
    target: &Target,
    ct: &str,
    batch: &Batch,
    retries: &mut usize,
) -> Result<TelemetryOutput, FeedError> {
    let mut wait = Duration::from_millis(200);
    let mut last = String::new();
    for attempt in 0..ATTEMPTS {
        if attempt > 0 {
            *retries += 1;
            tokio::time::sleep(wait).await;
            wait = (wait * 2).min(Duration::from_secs(5));
        }
        match send_once(target, ct, &batch.body).await {
            Ok((200, body)) => {
                return serde_json::from_str(&body).map_err(|e| FeedError::Refused {
                    status: 200,
                    body: format!("an answer that is not the telemetry answer ({e}): {body}"),
                });
            }
            Ok((status, body)) if (400..500).contains(&status) => {
                return Err(FeedError::Refused { status, body });
            }
            Ok((status, body)) => last = format!("HTTP {status}: {body}"),
            Err(e) => last = e,
        }
    }
    Err(FeedError::Unreachable(format!(
        "no answer after {ATTEMPTS} tries: {last}"
    )))
}

/// Feeds `log`. `speed`: sample seconds per wall second (`None`: as fast
/// as possible); `on_batch(lines_sent)` after each batch.
pub async fn feed(
    target: &Target,
    log: &Log,
    speed: Option<f64>,
    mut on_batch: impl FnMut(usize),
) -> Result<Summary, FeedError> {
    let batches = match speed {
        None => log.batches(MAX_BATCH_LINES, None),
        Some(_) => log.batches(MAX_BATCH_LINES, Some(1.0)),
    };
    let t0 = log.lines.iter().find_map(|l| l.time_s).unwrap_or(0.0);
    let started = Instant::now();
    let mut summary = Summary::default();
    let mut sent = 0;
    for batch in &batches {
        if let (Some(speed), Some(due)) = (speed, batch.due_s) {
            let at = Duration::from_secs_f64(((due - t0) / speed).max(0.0));
            let now = started.elapsed();
            if at > now {
                tokio::time::sleep(at - now).await;
            }
        }
        let answer = send(target, log.content_type(), batch, &mut summary.retries).await?;
        summary.batches += 1;
        summary.accepted += answer.accepted;
        summary.duplicates += answer.duplicates;
        summary
            .refused
            .extend(answer.errors.into_iter().map(|e| Refused {
                line: batch.file_line(log.format, e.line),
                field: e.field,
                reason: e.reason,
            }));
        summary.state = Some(answer.state);
        sent += batch.lines.len();
        on_batch(sent);
    }
    Ok(summary)
}
