//! `GET /healthz`: liveness, the job store and its live workers.

use axum::http::header;
use axum::response::{IntoResponse, Response};
use serde::Serialize;
use utoipa::ToSchema;

use crate::api::AppState;

/// Liveness.
#[derive(Debug, Serialize, ToSchema)]
pub struct Health {
    /// Always `ok` when the server answers.
    pub status: String,
    /// Version of the server.
    pub version: String,
    /// The job store: `sqlite` or `postgres`.
    pub store: String,
    /// Job workers (API processes with job threads and `tetherplan worker`
    /// processes) whose heartbeat is recent; absent when the store did not
    /// answer within a second.
    #[schema(minimum = 0)]
    pub live_workers: Option<usize>,
    /// Whether `GET /api/v1/forecast` fetches a forecast (the server was
    /// given `--forecast-url`).
    pub forecast_source: bool,
}

/// Liveness, the job store and its live workers (the solver is not touched;
/// the store is asked at most one second).
#[utoipa::path(
    get, path = "/healthz", operation_id = "get_health", tag = "meta",
    responses((status = 200, description = "The server is up", body = Health))
)]
pub async fn get_health(axum::extract::State(app): axum::extract::State<AppState>) -> Response {
    let queue = app.queue.clone();
    let live = tokio::task::spawn_blocking(move || {
        queue.store.live_workers(crate::jobs::PRESENCE_TIMEOUT).ok()
    });
    let live_workers = tokio::time::timeout(std::time::Duration::from_secs(1), live)
        .await
        .ok()
        .and_then(Result::ok)
        .flatten();
    let body = Health {
        status: "ok".into(),
        version: env!("CARGO_PKG_VERSION").into(),
        store: app.queue.store.store_kind().into(),
        live_workers,
        forecast_source: app.forecast.is_some(),
    };
    (
        [(header::CONTENT_TYPE, "application/json")],
        serde_json::to_vec(&body).expect("serialises"),
    )
        .into_response()
}
