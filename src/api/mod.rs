//! The HTTP service (SPEC §4): a thin axum layer over [`crate::contract`]
//! and [`crate::jobs`].
//!
//! * `POST /api/v1/{stability,critical,safe-rate,charts}`: synchronous
//!   answers, computed on the rayon pool ([`solve`]);
//! * `/api/v1/jobs[/{id}]`: persisted batch jobs ([`jobs`]);
//! * `GET /healthz`, `GET /openapi.json`, `GET /docs` (Swagger UI, vendored);
//! * `GET /` and everything else: files from the static directory.
//!
//! Every error is the one body of [`error::ApiError`].

pub mod error;
pub mod jobs;
pub mod openapi;
pub mod solve;

use std::path::Path;
use std::sync::Arc;

use axum::Router;
use axum::extract::DefaultBodyLimit;
use axum::http::{StatusCode, Uri, header};
use axum::response::{IntoResponse, Response};
use axum::routing::{any, get, post};
use serde::Serialize;
use tokio::sync::Semaphore;
use tower_http::services::ServeDir;
use tower_http::trace::TraceLayer;
use utoipa::ToSchema;
use utoipa_swagger_ui::SwaggerUi;

use crate::config::{Config, Limits};
use crate::jobs::JobQueue;
use crate::jobs::store::JobStore;
use error::ApiError;

/// Shared state of the handlers.
#[derive(Clone)]
pub struct AppState {
    pub queue: Arc<JobQueue>,
    pub limits: Limits,
    solves: Arc<Semaphore>,
}

impl AppState {
    pub fn new(queue: Arc<JobQueue>) -> Self {
        let limits = queue.limits().clone();
        let solves = Arc::new(Semaphore::new(limits.max_in_flight));
        Self {
            queue,
            limits,
            solves,
        }
    }
}

/// Liveness.
#[derive(Debug, Serialize, ToSchema)]
pub struct Health {
    /// Always `ok` when the server answers.
    pub status: String,
    /// Version of the server.
    pub version: String,
}

/// Liveness: answers without touching the solver or the database.
#[utoipa::path(
    get, path = "/healthz", operation_id = "get_health", tag = "meta",
    responses((status = 200, description = "The server is up", body = Health))
)]
pub async fn get_health() -> Response {
    let body = Health {
        status: "ok".into(),
        version: env!("CARGO_PKG_VERSION").into(),
    };
    (
        [(header::CONTENT_TYPE, "application/json")],
        serde_json::to_vec(&body).expect("serialises"),
    )
        .into_response()
}

async fn api_not_found(uri: Uri) -> ApiError {
    ApiError::not_found(format!("no route {}", uri.path()))
}

async fn method_not_allowed() -> ApiError {
    ApiError::new(
        StatusCode::METHOD_NOT_ALLOWED,
        "method_not_allowed",
        None,
        "this method is not allowed on this path",
    )
}

/// The application: every route, the body limit, request tracing.
pub fn router(state: AppState, static_dir: &Path) -> Router {
    let body_limit = state.limits.max_body_bytes;
    Router::new()
        .route("/healthz", get(get_health))
        .route("/api/v1/stability", post(solve::compute_stability))
        .route("/api/v1/critical", post(solve::compute_critical))
        .route("/api/v1/safe-rate", post(solve::compute_safe_rate))
        .route("/api/v1/charts", post(solve::create_chart))
        .route("/api/v1/simulate", post(solve::run_simulation))
        .route(
            "/api/v1/frequency-response",
            post(solve::compute_frequency_response),
        )
        .route("/api/v1/bands", post(solve::compute_bands))
        .route("/api/v1/jobs", post(jobs::create_job).get(jobs::list_jobs))
        .route(
            "/api/v1/jobs/{id}",
            get(jobs::get_job).delete(jobs::delete_job),
        )
        .route("/api", any(api_not_found))
        .route("/api/{*rest}", any(api_not_found))
        .method_not_allowed_fallback(method_not_allowed)
        .with_state(state)
        .merge(SwaggerUi::new("/docs").url("/openapi.json", openapi::openapi()))
        .fallback_service(ServeDir::new(static_dir))
        .layer(DefaultBodyLimit::max(body_limit))
        .layer(TraceLayer::new_for_http())
}

/// Opens the job store, starts the worker and serves until SIGINT/SIGTERM;
/// then stops accepting, lets requests in flight finish, and puts the
/// running job back in the queue.
pub async fn serve(config: Config) -> Result<(), Box<dyn std::error::Error>> {
    let store = JobStore::open(&config.db)
        .map_err(|e| format!("cannot open job database {}: {e}", config.db.display()))?;
    let queue = Arc::new(JobQueue::new(
        store,
        config.job_threads,
        config.limits.clone(),
    ));
    let worker = queue.spawn_worker();
    let app = router(AppState::new(queue.clone()), &config.static_dir);
    let listener = tokio::net::TcpListener::bind(config.addr)
        .await
        .map_err(|e| format!("cannot listen on {}: {e}", config.addr))?;
    let addr = listener.local_addr()?;
    tracing::info!(%addr, db = %config.db.display(), static_dir = %config.static_dir.display(), "listening");
    // A line for scripts and tests (port 0 picks a free port).
    println!("tetherplan listening on http://{addr}");
    axum::serve(listener, app)
        .with_graceful_shutdown(shutdown_signal())
        .await?;
    tracing::info!("shutting down: stopping the job worker");
    queue.shutdown();
    let joined = tokio::task::spawn_blocking(move || worker.join().is_ok());
    if tokio::time::timeout(std::time::Duration::from_secs(10), joined)
        .await
        .is_err()
    {
        tracing::warn!(
            "the job worker did not stop within 10 s; its job will run again at the next start"
        );
    }
    let requeued = queue.store.requeue_running()?;
    tracing::info!(requeued, "stopped");
    Ok(())
}

async fn shutdown_signal() {
    let ctrl_c = async {
        let _ = tokio::signal::ctrl_c().await;
    };
    #[cfg(unix)]
    let terminate = async {
        match tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate()) {
            Ok(mut s) => {
                s.recv().await;
            }
            Err(_) => std::future::pending::<()>().await,
        }
    };
    #[cfg(not(unix))]
    let terminate = std::future::pending::<()>();
    tokio::select! {
        _ = ctrl_c => tracing::info!("SIGINT received"),
        _ = terminate => tracing::info!("SIGTERM received"),
    }
}
