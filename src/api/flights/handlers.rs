//! The flight routes (issue 33): create, list, read, end, telemetry in,
//! acknowledge, re-plan. Every route names the caller's token: another
//! token's flight is 404.

use axum::Extension;
use axum::body::Bytes;
use axum::extract::{Path, State};
use axum::http::{HeaderMap, StatusCode, header};
use axum::response::Response;

use crate::api::AppState;
use crate::api::auth::Caller;
use crate::api::error::{ApiError, JsonBody};
use crate::api::flights::hub::{LiveFlight, now_ms};
use crate::api::jobs::{blocking, json_response};
use crate::api::solve::{Deadline, SolveCtx};
use crate::contract::error::ErrorBody;
use crate::contract::flight::dto::*;
use crate::contract::flight::model::{PreparedFlight, prepare_with};
use crate::contract::flight::replan::{ReplanOutput, replan};
use crate::contract::flight::telemetry::{Format, TelemetrySampleInput, parse_batch};
use crate::jobs::flights::{MAX_FLIGHTS_PER_OWNER, NewFlight};
use std::sync::{Arc, Mutex};

/// Most refused samples listed in an answer.
const MAX_LISTED_ERRORS: usize = 100;

pub(super) fn owner(caller: &Caller) -> String {
    caller.owner.clone().unwrap_or_default()
}

pub(super) fn parse_id(id: &str) -> Result<i64, ApiError> {
    id.parse::<i64>()
        .map_err(|_| ApiError::not_found(format!("no flight with id `{id}`")))
}

/// The live flight `id` of the caller, or 404.
pub(super) async fn flight_of(
    app: &AppState,
    caller: &Caller,
    id: &str,
) -> Result<std::sync::Arc<LiveFlight>, ApiError> {
    let id = parse_id(id)?;
    let hub = app.flights.clone();
    let owner = owner(caller);
    blocking(move || hub.get(id, &owner).map_err(ApiError::from))
        .await?
        .ok_or_else(|| ApiError::not_found(format!("no flight with id `{id}`")))
}

/// Start a flight: commit its plan.
#[utoipa::path(
    post, path = "/api/v1/flights", operation_id = "create_flight", tag = "flights",
    request_body(content = CreateFlightRequest, description = "A plan request (SPEC §7, §9) with the flight's `name` and optional `limits`"),
    responses(
        (status = 201, description = "Stored with its committed plan", body = FlightCreatedOutput),
        (status = 400, description = "Malformed JSON", body = ErrorBody),
        (status = 413, description = "Body larger than the limit", body = ErrorBody),
        (status = 415, description = "Content type is not JSON", body = ErrorBody),
        (status = 422, description = "Invalid request, an infeasible plan (no schedule to fly) or 1000 flights kept by this token", body = ErrorBody),
        (status = 500, description = "Store failure", body = ErrorBody),
        (status = 503, description = "Too many solves in flight", body = ErrorBody,
            headers(("Retry-After" = u32, description = "Seconds to wait before retrying"))),
        (status = 504, description = "The plan was not solved within the solve timeout", body = ErrorBody),
    )
)]
pub async fn create_flight(
    State(app): State<AppState>,
    Extension(caller): Extension<Caller>,
    JsonBody(body): JsonBody,
) -> Result<Response, ApiError> {
    let prepared = solve_prepare(&app, body).await?;
    let hub = app.flights.clone();
    let owner = owner(&caller);
    let request = text(&prepared.request);
    let plan = text(&prepared.plan);
    let limits = text(&prepared.limits);
    let ceiling = text(&prepared.table);
    let name = prepared.name.clone();
    let id = blocking(move || {
        let f = NewFlight {
            name: &name,
            request: &request,
            plan: &plan,
            limits: &limits,
            ceiling: &ceiling,
        };
        hub.store.create_flight(&owner, &f).map_err(ApiError::from)
    })
    .await?
    .ok_or_else(|| {
        ApiError::new(
            StatusCode::UNPROCESSABLE_ENTITY,
            "invalid_input",
            None,
            format!("this token keeps {MAX_FLIGHTS_PER_OWNER} flights already"),
        )
    })?;
    Ok(json_response(
        StatusCode::CREATED,
        &FlightCreatedOutput {
            id,
            plan: prepared.plan,
            state: "unavailable".into(),
            limits: prepared.limits,
        },
    ))
}

/// Commits a flight's plan as the solve routes solve: on the rayon pool,
/// within the server's solve timeout (504 `timeout` past it, the solve
/// stopped), at most `max_in_flight` at once (503).
async fn solve_prepare(app: &AppState, body: Bytes) -> Result<PreparedFlight, ApiError> {
    let slot = Arc::new(Mutex::new(None));
    let out = slot.clone();
    app.solve(move |ctx: &SolveCtx| {
        let prepared = prepare_with(&body, &Deadline::after(ctx))?;
        *out.lock().expect("not poisoned") = Some(prepared);
        Ok(Vec::new())
    })
    .await?;
    let prepared = slot.lock().expect("not poisoned").take();
    prepared.ok_or_else(|| ApiError::internal("the flight's plan was solved but not kept"))
}

/// JSON text of a stored part.
fn text<T: serde::Serialize>(v: &T) -> String {
    serde_json::to_string(v).expect("flight parts serialise")
}

/// The token's flights, newest first.
#[utoipa::path(
    get, path = "/api/v1/flights", operation_id = "list_flights", tag = "flights",
    responses(
        (status = 200, description = "The flights", body = FlightListOutput),
        (status = 500, description = "Store failure", body = ErrorBody),
    )
)]
pub async fn list_flights(
    State(app): State<AppState>,
    Extension(caller): Extension<Caller>,
) -> Result<Response, ApiError> {
    let hub = app.flights.clone();
    let owner = owner(&caller);
    let rows = blocking(move || hub.store.list_flights(&owner).map_err(ApiError::from)).await?;
    let flights = rows
        .into_iter()
        .map(|r| FlightEntryOutput {
            id: r.id,
            name: r.name,
            created_at: r.created_at,
            ended_at: r.ended_at,
        })
        .collect();
    Ok(json_response(StatusCode::OK, &FlightListOutput { flights }))
}

/// The flight's committed plan, as its creation answered it.
#[utoipa::path(
    get, path = "/api/v1/flights/{id}/plan", operation_id = "flight_plan", tag = "flights",
    params(("id" = i64, Path, description = "Flight id")),
    responses(
        (status = 200, description = "The committed plan", body = crate::contract::plan::PlanResponse),
        (status = 404, description = "No such flight for this token", body = ErrorBody),
        (status = 500, description = "Store failure", body = ErrorBody),
    )
)]
pub async fn flight_plan(
    State(app): State<AppState>,
    Extension(caller): Extension<Caller>,
    Path(id): Path<String>,
) -> Result<Response, ApiError> {
    let id = parse_id(&id)?;
    let hub = app.flights.clone();
    let owner = owner(&caller);
    let row = blocking(move || hub.store.get_flight(id, &owner).map_err(ApiError::from))
        .await?
        .ok_or_else(|| ApiError::not_found(format!("no flight with id `{id}`")))?;
    let mut resp = Response::new(axum::body::Body::from(row.plan));
    resp.headers_mut().insert(
        header::CONTENT_TYPE,
        header::HeaderValue::from_static("application/json"),
    );
    Ok(resp)
}

/// A flight: its state, checks and alarms.
#[utoipa::path(
    get, path = "/api/v1/flights/{id}", operation_id = "get_flight", tag = "flights",
    params(("id" = i64, Path, description = "Flight id")),
    responses(
        (status = 200, description = "The flight and its monitor", body = FlightOutput),
        (status = 404, description = "No such flight for this token", body = ErrorBody),
        (status = 500, description = "Store failure", body = ErrorBody),
    )
)]
pub async fn get_flight(
    State(app): State<AppState>,
    Extension(caller): Extension<Caller>,
    Path(id): Path<String>,
) -> Result<Response, ApiError> {
    let f = flight_of(&app, &caller, &id).await?;
    let out = f.lock().output(f.id, now_ms());
    Ok(json_response(StatusCode::OK, &out))
}

/// End a flight (its telemetry is refused from then on).
#[utoipa::path(
    post, path = "/api/v1/flights/{id}/end", operation_id = "end_flight", tag = "flights",
    params(("id" = i64, Path, description = "Flight id")),
    responses(
        (status = 200, description = "Ended", body = FlightOutput),
        (status = 404, description = "No such flight for this token", body = ErrorBody),
        (status = 500, description = "Store failure", body = ErrorBody),
    )
)]
pub async fn end_flight(
    State(app): State<AppState>,
    Extension(caller): Extension<Caller>,
    Path(id): Path<String>,
) -> Result<Response, ApiError> {
    let f = flight_of(&app, &caller, &id).await?;
    let hub = app.flights.clone();
    let g = f.clone();
    blocking(move || hub.end(&g).map_err(ApiError::from)).await?;
    let out = f.lock().output(f.id, now_ms());
    Ok(json_response(StatusCode::OK, &out))
}

/// Telemetry in: a batch of samples.
#[utoipa::path(
    post, path = "/api/v1/flights/{id}/telemetry", operation_id = "post_telemetry", tag = "flights",
    params(("id" = i64, Path, description = "Flight id")),
    request_body(description = "`application/json`: an array of samples; `text/csv`: a header of the sample's field \
        names then one sample a line; `text/plain`: NMEA 0183 `$--MWV` lines, each `time_s,$WIMWV,…` or alone (taken at \
        the arrival time)",
        content(
            (Vec<TelemetrySampleInput> = "application/json", example = json!([
                {"time_s": 0.0, "tether_length_m": 1.0, "winch_rate_m_s": 0.0, "winch_tension_n": 990.0, "wind_speed_m_s": 4.0},
                {"time_s": 0.1, "tether_length_m": 1.0, "winch_rate_m_s": 0.05, "winch_tension_n": 989.0, "wind_speed_m_s": 4.2}
            ])),
            (String = "text/csv", example = "time_s,tether_length_m,winch_tension_n,wind_speed_m_s\n0.2,1.01,989,4.1\n"),
            (String = "text/plain", example = "0.3,$WIMWV,270.0,R,8.0,N,A*2E\n"),
        )),
    responses(
        (status = 200, description = "Stored: counts of accepted, duplicate and refused samples, and the state after", body = TelemetryOutput),
        (status = 400, description = "Malformed JSON", body = ErrorBody),
        (status = 404, description = "No such flight for this token", body = ErrorBody),
        (status = 409, description = "The flight has ended", body = ErrorBody),
        (status = 413, description = "Body larger than the limit", body = ErrorBody),
        (status = 415, description = "Content type is not JSON, CSV or plain text", body = ErrorBody),
        (status = 422, description = "Not a batch (not a JSON array, an unknown CSV column, no time_s column)", body = ErrorBody),
        (status = 500, description = "Store failure", body = ErrorBody),
    )
)]
pub async fn post_telemetry(
    State(app): State<AppState>,
    Extension(caller): Extension<Caller>,
    Path(id): Path<String>,
    headers: HeaderMap,
    body: Bytes,
) -> Result<Response, ApiError> {
    let ct = headers
        .get(header::CONTENT_TYPE)
        .and_then(|v| v.to_str().ok())
        .unwrap_or("");
    let format = Format::from_content_type(ct).ok_or_else(|| {
        ApiError::new(
            StatusCode::UNSUPPORTED_MEDIA_TYPE,
            "unsupported_media_type",
            Some("content-type"),
            format!("telemetry is application/json, text/csv or text/plain (NMEA), got `{ct}`"),
        )
    })?;
    let f = flight_of(&app, &caller, &id).await?;
    let (ended, arrival_time_s) = {
        let st = f.lock();
        (st.ended_at.is_some(), st.flight_time_s(now_ms()))
    };
    if ended {
        return Err(ApiError::new(
            StatusCode::CONFLICT,
            "flight_ended",
            None,
            "this flight has ended: its telemetry is closed",
        ));
    }
    let hub = app.flights.clone();
    let g = f.clone();
    let (parsed, stored) = blocking(move || {
        if format == Format::Json {
            crate::contract::json_keys::reject_duplicate_keys(&body)?;
        }
        let parsed = parse_batch(format, &body, arrival_time_s)?;
        let stored = hub.ingest(&g, &parsed.samples, now_ms())?;
        Ok((parsed, stored))
    })
    .await?;
    let st = f.lock();
    let out = st.output(f.id, now_ms());
    let answer = TelemetryOutput {
        accepted: stored.accepted,
        duplicates: stored.duplicates,
        rejected: parsed.rejected.len(),
        errors: parsed
            .rejected
            .into_iter()
            .take(MAX_LISTED_ERRORS)
            .collect(),
        state: out.state,
        last_sample_time_s: out.last_sample_time_s,
        samples_received: out.samples_received,
    };
    Ok(json_response(StatusCode::OK, &answer))
}

/// Acknowledge the alarms: a latched stop whose value is back clears.
#[utoipa::path(
    post, path = "/api/v1/flights/{id}/alarms/acknowledge", operation_id = "acknowledge_alarms", tag = "flights",
    params(("id" = i64, Path, description = "Flight id")),
    responses(
        (status = 200, description = "Acknowledged (at the latest sample's time)", body = AcknowledgeOutput),
        (status = 404, description = "No such flight for this token", body = ErrorBody),
        (status = 500, description = "Store failure", body = ErrorBody),
    )
)]
pub async fn acknowledge_alarms(
    State(app): State<AppState>,
    Extension(caller): Extension<Caller>,
    Path(id): Path<String>,
) -> Result<Response, ApiError> {
    let f = flight_of(&app, &caller, &id).await?;
    let hub = app.flights.clone();
    let g = f.clone();
    let acknowledged = blocking(move || hub.acknowledge(&g).map_err(ApiError::from)).await?;
    let state = f.lock().output(f.id, now_ms()).state;
    Ok(json_response(
        StatusCode::OK,
        &AcknowledgeOutput {
            acknowledged,
            state,
        },
    ))
}

/// Re-plan from now: from the current length in the measured wind, or the haul-down when that is NO-GO.
#[utoipa::path(
    get, path = "/api/v1/flights/{id}/replan", operation_id = "replan_flight", tag = "flights",
    params(("id" = i64, Path, description = "Flight id")),
    responses(
        (status = 200, description = "The plan from now", body = ReplanOutput),
        (status = 404, description = "No such flight for this token", body = ErrorBody),
        (status = 422, description = "No length measured yet, or a plan the measured wind cannot be judged in (the field named)", body = ErrorBody),
        (status = 500, description = "Store failure", body = ErrorBody),
    )
)]
pub async fn replan_flight(
    State(app): State<AppState>,
    Extension(caller): Extension<Caller>,
    Path(id): Path<String>,
) -> Result<Response, ApiError> {
    let f = flight_of(&app, &caller, &id).await?;
    let (request, length, wind, height) = {
        let st = f.lock();
        (
            st.request.clone(),
            st.monitor.length_m(),
            st.monitor.wind_m_s(),
            st.limits.anemometer_height_m,
        )
    };
    let Some(length) = length else {
        return Err(ApiError::new(
            StatusCode::UNPROCESSABLE_ENTITY,
            "invalid_input",
            Some("tether_length_m"),
            "no tether length measured yet: send telemetry with tether_length_m first",
        ));
    };
    let out =
        blocking(move || replan(&request, length, wind, height).map_err(ApiError::from)).await?;
    Ok(json_response(StatusCode::OK, &out))
}
