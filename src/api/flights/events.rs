//! `GET /api/v1/flights/{id}/events`: the flight as Server-Sent Events.
//!
//! - `event: samples`, `id: N`: samples stored since the last one sent,
//!   in arrival order (`{"samples": [{"seq", "time_s", …}]}`, at most
//!   2000 an event); `N` is the last one's arrival number, so a client
//!   that reconnects with `Last-Event-ID: N` (browsers do it by themselves)
//!   is sent exactly what it missed, and one without it everything;
//! - `event: state` (no id): the flight as `GET /api/v1/flights/{id}`
//!   answers it, after every change and every second (so silence shows as
//!   `unavailable` by the server's clock).
//!
//! The stream is fed by a task that reads the store after each change of
//! the flight (a broadcast that only says "changed": a slow client
//! cannot make the store lose anything, it reads from where it was).
//!
//! A client that does not accept `text/event-stream` (no `Accept` naming
//! it, as browsers' `EventSource` always sends) gets what is stored and
//! one `state` event, and the stream ends: a snapshot in the same form,
//! for tools that read a response to its end.

use std::convert::Infallible;
use std::time::Duration;

use axum::Extension;
use axum::extract::{Path, State};
use axum::http::HeaderMap;
use axum::response::sse::{Event, KeepAlive, Sse};
use futures_util::Stream;
use serde::Serialize;
use tokio::sync::broadcast::error::RecvError;

use crate::api::AppState;
use crate::api::auth::Caller;
use crate::api::error::ApiError;
use crate::api::flights::handlers::flight_of;
use crate::api::flights::hub::now_ms;
use crate::contract::error::ErrorBody;
use crate::contract::flight::telemetry::TelemetrySampleInput;

/// Samples per event.
const EVENT_SAMPLES: usize = 2000;
/// A state event at least this often.
const STATE_EVERY: Duration = Duration::from_millis(1000);

#[derive(Serialize)]
struct SampleEvent {
    seq: i64,
    #[serde(flatten)]
    sample: TelemetrySampleInput,
}

#[derive(Serialize)]
struct SamplesEvent {
    samples: Vec<SampleEvent>,
}

/// The flight's samples and state as Server-Sent Events, replaying after `Last-Event-ID`.
#[utoipa::path(
    get, path = "/api/v1/flights/{id}/events", operation_id = "flight_events", tag = "flights",
    params(
        ("id" = i64, Path, description = "Flight id"),
        ("Last-Event-ID" = Option<i64>, Header, description = "The last `samples` event's id received: only later samples are sent"),
    ),
    responses(
        (status = 200, description = "`text/event-stream`: `samples` events (id: the last sample's arrival number) and `state` events (the flight, every change and every second)", content_type = "text/event-stream"),
        (status = 404, description = "No such flight for this token", body = ErrorBody),
    )
)]
pub async fn flight_events(
    State(app): State<AppState>,
    Extension(caller): Extension<Caller>,
    Path(id): Path<String>,
    headers: HeaderMap,
) -> Result<Sse<impl Stream<Item = Result<Event, Infallible>>>, ApiError> {
    let flight = flight_of(&app, &caller, &id).await?;
    let after: i64 = headers
        .get("last-event-id")
        .and_then(|v| v.to_str().ok())
        .and_then(|v| v.trim().parse().ok())
        .filter(|n: &i64| *n >= 0)
        .unwrap_or(0);
    let follow = headers
        .get_all(axum::http::header::ACCEPT)
        .iter()
        .filter_map(|v| v.to_str().ok())
        .any(|v| v.to_ascii_lowercase().contains("text/event-stream"));
    let mut changed = flight.changed.subscribe();
    let (tx, rx) = tokio::sync::mpsc::channel::<Event>(8);
    let hub = app.flights.clone();
    tokio::spawn(async move {
        let mut sent = after;
        let mut tick = tokio::time::interval(STATE_EVERY);
        loop {
            loop {
                let store = hub.store.clone();
                let id = flight.id;
                let rows = tokio::task::spawn_blocking(move || {
                    store.samples_after(id, sent, EVENT_SAMPLES)
                })
                .await;
                let Ok(Ok(rows)) = rows else { return };
                let Some(&(last, _)) = rows.last() else { break };
                let full = rows.len() == EVENT_SAMPLES;
                let body = SamplesEvent {
                    samples: rows
                        .into_iter()
                        .map(|(seq, s)| SampleEvent {
                            seq,
                            sample: TelemetrySampleInput {
                                time_s: s.time_s,
                                tether_length_m: s.tether_length_m,
                                winch_rate_m_s: s.winch_rate_m_s,
                                winch_tension_n: s.winch_tension_n,
                                wind_speed_m_s: s.wind_speed_m_s,
                                wind_height_m: s.wind_height_m,
                                aerostat_altitude_m: s.aerostat_altitude_m,
                            },
                        })
                        .collect(),
                };
                sent = last;
                let Ok(ev) = Event::default()
                    .event("samples")
                    .id(last.to_string())
                    .json_data(&body)
                else {
                    return;
                };
                if tx.send(ev).await.is_err() {
                    return;
                }
                if !full {
                    break;
                }
            }
            let state = flight.lock().output(flight.id, now_ms());
            let Ok(ev) = Event::default().event("state").json_data(&state) else {
                return;
            };
            if tx.send(ev).await.is_err() || !follow {
                return;
            }
            tokio::select! {
                r = changed.recv() => if let Err(RecvError::Closed) = r { return },
                _ = tick.tick() => {}
            }
        }
    });
    let stream = futures_util::stream::unfold(rx, |mut rx| async move {
        rx.recv().await.map(|e| (Ok::<_, Infallible>(e), rx))
    });
    Ok(Sse::new(stream).keep_alive(KeepAlive::default()))
}
