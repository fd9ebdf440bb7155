//! Live flights over HTTP (SPEC §13, issue 33): the routes
//! ([`handlers`], [`events`], the report and the simulated flight in
//! [`tools`]), the client that replays a log against them ([`feed`]), the
//! flights of a server ([`hub`]), the MQTT feed ([`mqtt`]) and their
//! part of the OpenAPI document ([`FlightsDoc`]). Wired into the router by
//! [`routes`] and into the document by merging [`FlightsDoc`].

pub mod events;
pub mod feed;
pub mod handlers;
pub mod hub;
pub mod mqtt;
pub mod tools;

use axum::Router;
use axum::routing::{get, post};
use utoipa::OpenApi;

use crate::api::AppState;

/// The flight routes.
pub fn routes() -> Router<AppState> {
    Router::new()
        .route(
            "/api/v1/flights",
            post(handlers::create_flight).get(handlers::list_flights),
        )
        .route("/api/v1/flights/simulate", post(tools::simulate_flight))
        .route("/api/v1/flights/{id}", get(handlers::get_flight))
        .route("/api/v1/flights/{id}/report", get(tools::flight_report))
        .route("/api/v1/flights/{id}/plan", get(handlers::flight_plan))
        .route("/api/v1/flights/{id}/end", post(handlers::end_flight))
        .route(
            "/api/v1/flights/{id}/telemetry",
            post(handlers::post_telemetry),
        )
        .route(
            "/api/v1/flights/{id}/alarms/acknowledge",
            post(handlers::acknowledge_alarms),
        )
        .route("/api/v1/flights/{id}/replan", get(handlers::replan_flight))
        .route("/api/v1/flights/{id}/events", get(events::flight_events))
}

#[derive(OpenApi)]
#[openapi(
    paths(
        handlers::create_flight,
        handlers::list_flights,
        handlers::get_flight,
        handlers::flight_plan,
        handlers::end_flight,
        handlers::post_telemetry,
        handlers::acknowledge_alarms,
        handlers::replan_flight,
        events::flight_events,
        tools::flight_report,
        tools::simulate_flight,
    ),
    tags((name = "flights", description = "Live flights: a committed plan against its telemetry, with alarms (SPEC §13)"))
)]
pub struct FlightsDoc;
