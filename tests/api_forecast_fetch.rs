//! `GET /api/v1/forecast` (issue 32, item 3: "when the server is given a
//! forecast source by configuration, fetch one; off by default"): the
//! source is a real HTTP server on loopback (a thread here) answering the
//! recorded Open-Meteo file, a METAR text, an error status or garbage.
//!
//! - Off by default: 404 `not_configured`, saying how to turn it on.
//! - The fetched forecast is the file's JSON object, exactly (so a
//!   windows request made from it is the file's request), with its member
//!   and period counts.
//! - A METAR source gives the text; its one period.
//! - A source answering 503, non-JSON, JSON that is no forecast, or
//!   nothing at all (closed port): 502 `forecast_unavailable` saying why.

use std::net::TcpListener;
use std::path::Path;

use axum::http::StatusCode;
use serde_json::Value;
use tetherplan::api::{self, AppState};
use tetherplan::config::{ForecastSource, Limits};
use tetherplan::contract::windows::dto::ForecastFormat;

mod common;

/// A source answering `status` with `body`; its URL.
fn source(status: u16, body: Vec<u8>) -> String {
    let addr = common::http::serve_fixed(status, body);
    format!("http://{addr}/v1/forecast?latitude=52.52&longitude=13.41")
}

fn app(source: Option<(String, ForecastFormat)>) -> axum::Router {
    let queue = common::queue_with(1, Limits::default());
    let state = AppState::new(queue)
        .with_forecast_source(source.map(|(url, format)| ForecastSource { url, format }));
    api::router(state, Path::new("static"))
}

fn recorded() -> Vec<u8> {
    std::fs::read(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/forecasts/open_meteo_hourly.json"
    ))
    .unwrap()
}

#[tokio::test]
async fn off_by_default_it_says_how_to_turn_it_on() {
    let (status, text) = common::send_text(&app(None), "GET", "/api/v1/forecast", None).await;
    assert_eq!(status, StatusCode::NOT_FOUND);
    let (code, _) = common::error(&text);
    assert_eq!(code, "not_configured");
    assert!(text.contains("--forecast-url"), "{text}");
}

#[tokio::test]
async fn the_fetched_open_meteo_forecast_is_the_file_exactly() {
    let url = source(200, recorded());
    let router = app(Some((url.clone(), ForecastFormat::OpenMeteo)));
    let fetched = common::get(&router, "/api/v1/forecast").await;
    let file: Value = serde_json::from_slice(&recorded()).unwrap();
    assert_eq!(fetched["forecast"]["format"], "open_meteo", "{fetched}");
    assert_eq!(fetched["forecast"]["data"], file);
    assert_eq!(fetched["source_url"], url);
    assert_eq!(fetched["member_count"], 1);
    let hours = file["hourly"]["time"].as_array().unwrap().len();
    assert_eq!(fetched["period_count"], hours);
    assert!(fetched["fetched_at_unix_s"].as_f64().unwrap() > 1.7e9);
}

#[tokio::test]
async fn a_metar_source_gives_its_text() {
    let metar = "METAR EDDB 031050Z 27015G25KT 9999 FEW030 05/01 Q1012";
    let router = app(Some((
        source(200, metar.as_bytes().to_vec()),
        ForecastFormat::Metar,
    )));
    let fetched = common::get(&router, "/api/v1/forecast").await;
    assert_eq!(fetched["forecast"]["data"], metar, "{fetched}");
    assert_eq!(fetched["period_count"], 1);
}

#[tokio::test]
async fn a_source_that_fails_answers_502_saying_why() {
    let closed = {
        let l = TcpListener::bind("127.0.0.1:0").unwrap();
        let a = l.local_addr().unwrap();
        drop(l);
        format!("http://{a}/")
    };
    for (url, why) in [
        (source(503, b"{}".to_vec()), "HTTP 503"),
        (source(200, b"<html>busy</html>".to_vec()), "no JSON"),
        (
            source(200, br#"{"hourly": {"time": []}}"#.to_vec()),
            "not a readable Open-Meteo forecast",
        ),
        (closed, "could not be reached"),
    ] {
        let router = app(Some((url.clone(), ForecastFormat::OpenMeteo)));
        let (status, text) = common::send_text(&router, "GET", "/api/v1/forecast", None).await;
        assert_eq!(status, StatusCode::BAD_GATEWAY, "{url}: {text}");
        let (code, _) = common::error(&text);
        assert_eq!(code, "forecast_unavailable");
        assert!(text.contains(why), "{url}: expected `{why}` in {text}");
    }
}
