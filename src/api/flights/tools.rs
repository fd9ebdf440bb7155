//! A flight's report and a simulated flight (issue 33):
//! `GET /api/v1/flights/{id}/report` (JSON, CSV or a printable HTML page
//! by `Accept`) and `POST /api/v1/flights/simulate` (a flight flown in the
//! dynamics model through a wind event: its telemetry log as JSON or in
//! the flight's CSV format by `Accept`; solved like the solve routes: on
//! the rayon pool, priced, within the solve timeout).

use axum::Extension;
use axum::extract::{Path, State};
use axum::http::{HeaderMap, StatusCode, header};
use axum::response::{IntoResponse, Response};

use crate::api::AppState;
use crate::api::auth::Caller;
use crate::api::error::{ApiError, JsonBody};
use crate::api::flights::handlers::flight_of;
use crate::api::flights::hub::now_ms;
use crate::api::jobs::{blocking, json_response};
use crate::api::solve::{Deadline, SolveCtx};
use crate::contract::error::ErrorBody;
use crate::contract::flight::report::{self, FlightReportOutput};
use crate::contract::flight::simulate::{self, SimulateFlightRequest, SimulatedFlightOutput};

/// What an `Accept` header asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wanted {
    Json,
    Csv,
    Html,
}

/// The first of JSON, CSV or HTML an `Accept` names (JSON when absent or
/// `*/*`); `None` when it names none of them (406).
pub fn wanted(headers: &HeaderMap, html: bool) -> Option<Wanted> {
    let accept: Vec<String> = headers
        .get_all(header::ACCEPT)
        .iter()
        .filter_map(|v| v.to_str().ok())
        .flat_map(|v| v.split(','))
        .map(|v| {
            v.split(';')
                .next()
                .unwrap_or("")
                .trim()
                .to_ascii_lowercase()
        })
        .filter(|v| !v.is_empty())
        .collect();
    if accept.is_empty() {
        return Some(Wanted::Json);
    }
    accept.iter().find_map(|a| match a.as_str() {
        "application/json" | "application/*" | "*/*" => Some(Wanted::Json),
        "text/csv" => Some(Wanted::Csv),
        "text/html" if html => Some(Wanted::Html),
        _ => None,
    })
}

fn not_acceptable(what: &str) -> ApiError {
    ApiError::new(
        StatusCode::NOT_ACCEPTABLE,
        "not_acceptable",
        Some("accept"),
        format!("this answer is {what}"),
    )
}

fn typed(content_type: &'static str, body: String) -> Response {
    (StatusCode::OK, [(header::CONTENT_TYPE, content_type)], body).into_response()
}

/// A flight's report.
#[utoipa::path(
    get, path = "/api/v1/flights/{id}/report", operation_id = "flight_report", tag = "flights",
    params(("id" = i64, Path, description = "Flight id")),
    responses(
        (status = 200, description = "The report: planned against measured length, the alarms with their raise, clear and \
            acknowledgement times, the peaks with their sample times, the duration and the samples received. `Accept: \
            application/json` (default), `text/csv` (one record a line: `summary`, `peak`, `alarm`, `track`; header \
            `record,name,value,unit,time_s,planned_value,cleared_at_s,acknowledged_at_s`) or `text/html` (a printable, \
            self-contained page)",
            content(
                (FlightReportOutput = "application/json"),
                (String = "text/csv"),
                (String = "text/html"),
            )),
        (status = 404, description = "No such flight for this token", body = ErrorBody),
        (status = 406, description = "`Accept` names none of JSON, CSV or HTML", body = ErrorBody),
        (status = 500, description = "Store failure", body = ErrorBody),
    )
)]
pub async fn flight_report(
    State(app): State<AppState>,
    Extension(caller): Extension<Caller>,
    Path(id): Path<String>,
    headers: HeaderMap,
) -> Result<Response, ApiError> {
    let want = wanted(&headers, true)
        .ok_or_else(|| not_acceptable("application/json, text/csv or text/html"))?;
    let f = flight_of(&app, &caller, &id).await?;
    let hub = app.flights.clone();
    let g = f.clone();
    let out = blocking(move || {
        // the answer and the samples under the flight's lock: one state
        let st = g.lock();
        let samples = hub.store.samples_by_time(g.id).map_err(ApiError::from)?;
        let flight = st.output(g.id, now_ms());
        let plan = st.model.plan.as_ref();
        let limits = &st.model.limits;
        Ok(report::report(
            &flight,
            plan,
            plan.map(|p| p.end_time_s()),
            (limits.wind_mean_window_s, limits.gust_average_s),
            &samples,
        ))
    })
    .await?;
    Ok(match want {
        Wanted::Json => json_response(StatusCode::OK, &out),
        Wanted::Csv => typed("text/csv; charset=utf-8", report::to_csv(&out)),
        Wanted::Html => typed("text/html; charset=utf-8", report::to_html(&out)),
    })
}

/// Fly a flight in the dynamics model through a wind event: its telemetry log.
#[utoipa::path(
    post, path = "/api/v1/flights/simulate", operation_id = "simulate_flight", tag = "flights",
    request_body(content = SimulateFlightRequest, description = "A flight as `POST /api/v1/flights` takes it, a wind event, a sample rate and a hold"),
    responses(
        (status = 200, description = "The log: `Accept: application/json` (default) the samples and the run, `text/csv` the \
            flight's CSV format (header `time_s,tether_length_m,winch_rate_m_s,winch_tension_n,wind_speed_m_s,wind_height_m,aerostat_altitude_m`), \
            as `POST /api/v1/flights/{id}/telemetry` takes it",
            content(
                (SimulatedFlightOutput = "application/json"),
                (String = "text/csv"),
            )),
        (status = 400, description = "Malformed JSON", body = ErrorBody),
        (status = 406, description = "`Accept` names neither JSON nor CSV", body = ErrorBody),
        (status = 413, description = "Body larger than the limit", body = ErrorBody),
        (status = 415, description = "Content type is not JSON", body = ErrorBody),
        (status = 422, description = "Invalid input (the field named: the flight's under `flight.`), an infeasible plan, or \
            too long a run for a synchronous answer (`too_large`)", body = ErrorBody),
        (status = 503, description = "Too many solves in flight", body = ErrorBody,
            headers(("Retry-After" = u32, description = "Seconds to wait before retrying"))),
        (status = 504, description = "No answer within the solve timeout", body = ErrorBody),
    )
)]
pub async fn simulate_flight(
    State(app): State<AppState>,
    headers: HeaderMap,
    JsonBody(body): JsonBody,
) -> Result<Response, ApiError> {
    let want =
        wanted(&headers, false).ok_or_else(|| not_acceptable("application/json or text/csv"))?;
    let response = app
        .solve(move |ctx: &SolveCtx| {
            let req = SimulateFlightRequest::parse(&body)?;
            let deadline = Deadline::after(ctx);
            let setup = req.setup(&deadline)?;
            let _admitted = ctx.charge(&setup.price(), "dynamics")?;
            let out = setup.run(&deadline)?;
            Ok(match want {
                Wanted::Csv => simulate::to_csv(&out.samples).into_bytes(),
                _ => crate::contract::finite::to_vec(&out)?,
            })
        })
        .await?;
    if want != Wanted::Csv {
        return Ok(response);
    }
    let (mut parts, body) = response.into_parts();
    parts.headers.insert(
        header::CONTENT_TYPE,
        header::HeaderValue::from_static("text/csv; charset=utf-8"),
    );
    Ok(Response::from_parts(parts, body))
}
