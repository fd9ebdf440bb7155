//! The MQTT telemetry feed (issue 33, item 6): with `--mqtt-url`, the
//! server subscribes to `<prefix>/+/telemetry` on the broker, where `+` is
//! a flight's id, and stores each message's samples in that flight exactly
//! as `POST /api/v1/flights/{id}/telemetry` does (a JSON array or object,
//! CSV with a header, or NMEA `$--MWV` lines, told apart by their first
//! characters: [`Format::sniff`]).
//!
//! Nothing acknowledged is lost: the subscription is QoS 1 in a persistent
//! session (`clean_session = false`, the configured client id), and a
//! message is acknowledged only once its samples are committed to the
//! store. A server that dies before that gets the message again from the
//! broker, and the store keeps a sample's `time_s` once, so a redelivery
//! stores nothing twice. After every connection (the first, or a
//! reconnection once the broker restarts, which may have lost the session)
//! the server subscribes again: rumqttc does not.
//!
//! Who may publish to a flight's topic is the broker's business (its ACLs):
//! the broker is configured by whoever runs the server, never named by an
//! API client. A message the flight cannot take (no such flight, an ended
//! flight, a payload that is not a batch) is acknowledged and logged, so
//! that it is not redelivered forever; refused samples inside a good batch
//! are logged with their line and field.

use std::sync::Arc;
use std::time::Duration;

use rumqttc::{AsyncClient, Event, MqttOptions, Packet, Publish, QoS};
use tokio::sync::mpsc;

use crate::api::flights::hub::{FlightHub, now_ms};
use crate::config::MqttSettings;
use crate::contract::flight::telemetry::{Format, parse_batch};

/// Messages received and not yet stored, at most.
const QUEUE: usize = 256;

/// The topic filter of the feed.
pub fn topic_filter(prefix: &str) -> String {
    format!("{prefix}/+/telemetry")
}

/// The flight id a topic names (`<prefix>/<id>/telemetry`).
pub fn flight_of_topic(prefix: &str, topic: &str) -> Option<i64> {
    topic
        .strip_prefix(prefix)?
        .strip_prefix('/')?
        .strip_suffix("/telemetry")?
        .parse()
        .ok()
        .filter(|id: &i64| *id > 0)
}

/// Starts the feed on the runtime: one task keeps the connection (and
/// resubscribes after each), one stores the messages in arrival order and
/// acknowledges each after its commit.
pub fn spawn(hub: Arc<FlightHub>, settings: MqttSettings) {
    let mut options = MqttOptions::new(&settings.client_id, &settings.host, settings.port);
    options
        .set_keep_alive(Duration::from_secs(5))
        .set_clean_session(false)
        .set_manual_acks(true);
    let (client, mut events) = AsyncClient::new(options, QUEUE);
    let (tx, mut rx) = mpsc::channel::<Publish>(QUEUE);
    let filter = topic_filter(&settings.topic_prefix);
    let subscriber = client.clone();
    tracing::info!(
        broker = %format!("{}:{}", settings.host, settings.port),
        %filter,
        client_id = %settings.client_id,
        "MQTT telemetry feed"
    );
    tokio::spawn(async move {
        let mut down_since: Option<std::time::Instant> = None;
        loop {
            match events.poll().await {
                Ok(Event::Incoming(Packet::ConnAck(ack))) => {
                    tracing::info!(
                        session_present = ack.session_present,
                        "MQTT broker connected; subscribing"
                    );
                    down_since = None;
                    if let Err(e) = subscriber.try_subscribe(&filter, QoS::AtLeastOnce) {
                        tracing::warn!(error = %e, "MQTT subscribe could not be queued");
                    }
                }
                Ok(Event::Incoming(Packet::Publish(p))) => {
                    if tx.send(p).await.is_err() {
                        return;
                    }
                }
                Ok(_) => {}
                Err(e) => {
                    if down_since.is_none() {
                        tracing::warn!(error = %e, "MQTT broker unreachable; retrying every second");
                        down_since = Some(std::time::Instant::now());
                    }
                    tokio::time::sleep(Duration::from_secs(1)).await;
                }
            }
        }
    });
    let prefix = settings.topic_prefix;
    tokio::spawn(async move {
        while let Some(p) = rx.recv().await {
            let hub = hub.clone();
            let prefix = prefix.clone();
            let (topic, payload) = (p.topic.clone(), p.payload.clone());
            let stored =
                tokio::task::spawn_blocking(move || store(&hub, &prefix, &topic, &payload)).await;
            match stored {
                Ok(Ok(())) => {}
                Ok(Err(Retry(e))) => {
                    // The store failed: not acknowledged, so the broker
                    // sends it again after the next reconnection.
                    tracing::error!(topic = %p.topic, error = %e, "MQTT message not stored");
                    continue;
                }
                Err(e) => {
                    tracing::error!(topic = %p.topic, error = %e, "MQTT message handler failed");
                    continue;
                }
            }
            if let Err(e) = client.ack(&p).await {
                tracing::warn!(error = %e, "MQTT acknowledgement could not be queued");
            }
        }
    });
}

/// A failure worth a redelivery (the store's, not the message's).
struct Retry(String);

/// Stores one message's samples in its flight. `Ok` also when the message
/// is dropped (logged): only a store failure asks for it again.
fn store(hub: &FlightHub, prefix: &str, topic: &str, payload: &[u8]) -> Result<(), Retry> {
    let Some(id) = flight_of_topic(prefix, topic) else {
        tracing::warn!(%topic, "MQTT topic names no flight id; dropped");
        return Ok(());
    };
    let flight = match hub.get_any(id) {
        Ok(Some(f)) => f,
        Ok(None) => {
            tracing::warn!(%topic, "MQTT telemetry for no stored flight; dropped");
            return Ok(());
        }
        Err(e) => return Err(Retry(e.to_string())),
    };
    let (ended, arrival_time_s) = {
        let st = flight.lock();
        (st.ended_at.is_some(), st.flight_time_s(now_ms()))
    };
    if ended {
        tracing::warn!(%topic, "MQTT telemetry for an ended flight; dropped");
        return Ok(());
    }
    let format = Format::sniff(payload);
    let wrapped;
    let body: &[u8] = if format == Format::Json && payload.trim_ascii_start().starts_with(b"{") {
        wrapped = [b"[".as_slice(), payload, b"]"].concat();
        &wrapped
    } else {
        payload
    };
    let parsed = match parse_batch(format, body, arrival_time_s) {
        Ok(p) => p,
        Err(e) => {
            tracing::warn!(%topic, error = %e, "MQTT payload is not a telemetry batch; dropped");
            return Ok(());
        }
    };
    for r in parsed.rejected.iter().take(10) {
        tracing::warn!(%topic, line = r.line, field = %r.field, reason = %r.reason, "MQTT sample refused");
    }
    hub.ingest(&flight, &parsed.samples, now_ms())
        .map(|_| ())
        .map_err(|e| Retry(e.to_string()))
}
