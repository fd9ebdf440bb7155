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
pub mod body;
pub mod error;
pub mod flights;
pub mod forecast;
pub mod guard;
pub mod health;
pub mod jobs;
pub mod kinds;
pub mod memory;
pub mod openapi;
pub mod server;
pub mod solve;
pub mod spec;
pub mod state;
pub mod systems;

use std::path::Path;
use std::sync::Arc;

use axum::Router;
use axum::extract::DefaultBodyLimit;
use axum::http::{StatusCode, Uri};
use axum::routing::{any, get, post};
use tower_http::trace::TraceLayer;
use utoipa_swagger_ui::SwaggerUi;

use crate::config::Config;
use crate::jobs::JobQueue;
use crate::shutdown::shutdown_signal;
use error::ApiError;
pub use health::{Health, get_health};
pub use state::AppState;

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
    let routes = kinds::routes(Router::new().route("/healthz", get(get_health)))
        .route("/api/v1/systems", get(systems::list_systems))
        .route(
            "/api/v1/systems/{name}",
            axum::routing::put(systems::put_system)
                .get(systems::get_system)
                .delete(systems::delete_system),
        )
        .route("/api/v1/presets", get(systems::list_presets))
        .route("/api/v1/forecast", get(forecast::get_forecast))
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
    let mqtt = config.mqtt.settings()?;
    let forecast_source = config.forecast.settings()?;
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
    let flights = flights::hub::FlightHub::open(&config.store).map_err(|e| {
        format!(
            "cannot open the flights of {}: {e}",
            config.store.describe()
        )
    })?;
    let state = AppState::new(queue.clone())
        .with_tokens(&config.api_tokens)
        .with_flights(flights)
        .with_forecast_source(forecast_source);
    if let Some(settings) = mqtt {
        flights::mqtt::spawn(state.flights.clone(), settings);
    }
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
