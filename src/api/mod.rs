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

pub mod assets;
pub mod auth;
pub mod auth_doc;
pub mod bands;
pub mod body;
pub mod dynamics;
pub mod error;
pub mod flights;
pub mod guard;
pub mod jobs;
pub mod memory;
pub mod openapi;
pub mod server;
pub mod solve;
pub mod spec;
pub mod systems;
pub mod tether;
pub mod windows;

use std::path::Path;
use std::sync::Arc;

use axum::Router;
use axum::extract::DefaultBodyLimit;
use axum::http::{StatusCode, Uri, header};
use axum::response::{IntoResponse, Response};
use axum::routing::{any, get, post};
use serde::Serialize;
use tokio::sync::Semaphore;
use tower_http::trace::TraceLayer;
use utoipa::ToSchema;
use utoipa_swagger_ui::SwaggerUi;

use crate::config::{Config, Limits};
use crate::jobs::JobQueue;
use error::ApiError;

/// Shared state of the handlers.
#[derive(Clone)]
pub struct AppState {
    pub queue: Arc<JobQueue>,
    pub limits: Limits,
    solves: Arc<Semaphore>,
    /// Priced synchronous work running now (`crate::price`).
    priced: Arc<crate::price::InFlight>,
    /// API tokens (none: open).
    pub tokens: Arc<auth::Tokens>,
    /// Live flights (in memory until [`Self::with_flights`]).
    pub flights: Arc<flights::hub::FlightHub>,
}

impl AppState {
    pub fn new(queue: Arc<JobQueue>) -> Self {
        let limits = queue.limits().clone();
        let solves = Arc::new(Semaphore::new(limits.max_in_flight));
        Self {
            queue,
            limits,
            solves,
            priced: Arc::new(crate::price::InFlight::default()),
            tokens: Arc::new(auth::Tokens::default()),
            flights: Arc::new(flights::hub::FlightHub::in_memory()),
        }
    }

    /// The same, keeping its flights in `hub`.
    pub fn with_flights(mut self, hub: flights::hub::FlightHub) -> Self {
        self.flights = Arc::new(hub);
        self
    }

    /// The same, requiring one of `tokens` on every `/api` route.
    pub fn with_tokens(mut self, tokens: &[String]) -> Self {
        self.tokens = Arc::new(auth::Tokens::new(tokens));
        self
    }
}

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

/// The application: every route, the body limit, request tracing; the
/// page from `static_dir`.
pub fn router(state: AppState, static_dir: &Path) -> Router {
    app(state, Some(static_dir))
}

/// The application with the page from `static_dir`, or (`None`) the copy
/// built into the binary ([`assets`]). Every response carries the
/// security headers ([`guard::security_headers`]).
pub fn app(state: AppState, static_dir: Option<&Path>) -> Router {
    let body_limit = state.limits.max_body_bytes;
    let tokens = state.tokens.clone();
    let routes = Router::new()
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
        .route("/api/v1/equilibrium", post(tether::compute_equilibrium))
        .route("/api/v1/envelope", post(tether::compute_envelope))
        .route("/api/v1/plan", post(solve::compute_plan))
        .route("/api/v1/bands", post(solve::compute_bands))
        .route("/api/v1/plan/bands", post(bands::compute_plan_bands))
        .route(
            "/api/v1/envelope/bands",
            post(bands::compute_envelope_bands),
        )
        .route("/api/v1/dynamics", post(dynamics::run_dynamics))
        .route("/api/v1/dynamics/peaks", post(dynamics::run_dynamics_peaks))
        .route("/api/v1/windows", post(windows::compute_windows))
        .route("/api/v1/systems", get(systems::list_systems))
        .route(
            "/api/v1/systems/{name}",
            axum::routing::put(systems::put_system)
                .get(systems::get_system)
                .delete(systems::delete_system),
        )
        .route("/api/v1/presets", get(systems::list_presets))
        .route("/api/v1/jobs", post(jobs::create_job).get(jobs::list_jobs))
        .route(
            "/api/v1/jobs/{id}",
            get(jobs::get_job).delete(jobs::delete_job),
        )
        .merge(flights::routes())
        .route("/api", any(api_not_found))
        .route("/api/{*rest}", any(api_not_found))
        .method_not_allowed_fallback(method_not_allowed)
        .layer(axum::middleware::from_fn_with_state(
            tokens,
            auth::require_token,
        ))
        .with_state(state)
        .merge(SwaggerUi::new("/docs").url("/openapi.json", openapi::openapi()));
    let routes = match static_dir {
        Some(dir) => routes.fallback_service(guard::confined_static_dir(dir)),
        None => routes.fallback(assets::serve_embedded),
    };
    routes
        .layer(DefaultBodyLimit::max(body_limit))
        .layer(axum::middleware::map_response(guard::security_headers))
        .layer(TraceLayer::new_for_http())
}

/// Opens the job store, starts the worker and serves until SIGINT/SIGTERM;
/// then stops accepting, lets requests in flight finish, and puts the
/// running job back in the queue.
pub async fn serve(config: Config) -> Result<(), Box<dyn std::error::Error>> {
    let store = config
        .store
        .open()
        .map_err(|e| format!("cannot open job database {}: {e}", config.store.describe()))?;
    let queue = Arc::new(JobQueue::with_store(
        store,
        config.job_threads,
        config.limits.clone(),
    ));
    // TETHERPLAN_JOB_THREADS=0: jobs are left to `tetherplan worker` processes.
    let worker = (config.job_threads > 0).then(|| queue.spawn_worker());
    let flights = flights::hub::FlightHub::open(&config.store)
        .map_err(|e| format!("cannot open the flights of {}: {e}", config.store.describe()))?;
    let state = AppState::new(queue.clone())
        .with_tokens(&config.api_tokens)
        .with_flights(flights);
    let listener = tokio::net::TcpListener::bind(config.addr)
        .await
        .map_err(|e| format!("cannot listen on {}: {e}", config.addr))?;
    let addr = listener.local_addr()?;
    let hosts = guard::HostAllowList::new(addr, config.allowed_hosts.as_deref());
    let app = app(state, config.static_dir.as_deref())
        .layer(tower_http::timeout::RequestBodyTimeoutLayer::new(
            config.connections.body_timeout,
        ))
        .layer(axum::middleware::from_fn_with_state(
            hosts.clone(),
            guard::HostAllowList::check,
        ))
        // (again outside the Host check, so its 421 carries them too)
        .layer(axum::middleware::map_response(guard::security_headers));
    let fd_limit = server::raise_fd_limit();
    let cap = server::connection_cap(config.connections.max_connections, fd_limit);
    let static_dir = config
        .static_dir
        .as_ref()
        .map_or("(built in)".to_string(), |d| d.display().to_string());
    tracing::info!(%addr, db = %config.store.describe(), %static_dir, "listening");
    tracing::info!(
        max_connections = cap,
        fd_limit = fd_limit.unwrap_or(0),
        header_timeout_s = config.connections.header_timeout.as_secs_f64(),
        body_timeout_s = config.connections.body_timeout.as_secs_f64(),
        allowed_hosts = %hosts.describe(),
        "connection limits"
    );
    warn_if_exposed(addr);
    // A line for scripts and tests (port 0 picks a free port).
    {
        use std::io::Write;
        let mut out = std::io::stdout().lock();
        let _ = writeln!(out, "tetherplan listening on http://{addr}").and_then(|()| out.flush());
    }
    server::run(
        listener,
        app,
        config.connections.clone(),
        cap,
        shutdown_signal(),
    )
    .await;
    tracing::info!("shutting down: stopping the job worker");
    queue.shutdown();
    let joined = tokio::task::spawn_blocking(move || worker.is_none_or(|w| w.join().is_ok()));
    if tokio::time::timeout(std::time::Duration::from_secs(10), joined)
        .await
        .is_err()
    {
        tracing::warn!(
            "the job worker did not stop within 10 s; its job will run again at the next start"
        );
    }
    let requeued = queue.store.release_all()?;
    tracing::info!(requeued, "stopped");
    Ok(())
}

/// A loud warning when the service listens beyond loopback without
/// `TETHERPLAN_API_TOKENS` (anyone who can reach it may use it).
fn warn_if_exposed(addr: std::net::SocketAddr) {
    let tokens = std::env::var("TETHERPLAN_API_TOKENS")
        .map(|t| t.split(',').any(|s| !s.trim().is_empty()))
        .unwrap_or(false);
    if !addr.ip().is_loopback() && !tokens {
        let msg = format!(
            "SECURITY WARNING: listening on {addr}, beyond loopback, WITHOUT authentication: \
             anyone who can reach this address can run solves and read, submit and cancel every job. \
             Set TETHERPLAN_API_TOKENS=token1,token2 or bind to 127.0.0.1."
        );
        tracing::warn!("{msg}");
        eprintln!("{msg}");
    }
}

/// Resolves at SIGINT or SIGTERM.
pub async fn shutdown_signal() {
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
