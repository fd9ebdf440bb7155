//! `GET /api/v1/forecast`: today's forecast, fetched on request from the
//! source the server is configured with (`--forecast-url`, off by default:
//! the server may have no network), and answered as the `forecast` object
//! a windows or plan request takes, after it has been read once (so the
//! page can hand it on as it is).
//!
//! The fetch (crate `ureq`, TLS by rustls) has 15 s in all and reads at
//! most 8 MiB. Failures answer 502 `forecast_unavailable` saying why in
//! plain words (unreachable, an HTTP status, not JSON, not a readable
//! forecast); an unconfigured server answers 404 `not_configured`.

use std::time::Duration;

use axum::extract::State;
use axum::http::StatusCode;
use axum::response::Response;
use serde::Serialize;
use utoipa::ToSchema;

use crate::api::AppState;
use crate::api::error::ApiError;
use crate::api::jobs::json_response;
use crate::config::ForecastSource;
use crate::contract::error::ErrorBody;
use crate::contract::windows::dto::ForecastInput;
use crate::contract::windows::source::forecast_from_source;

/// Most bytes read from the source.
const MAX_FORECAST_BYTES: u64 = 8 << 20;
/// The whole fetch, at most.
const FETCH_TIMEOUT: Duration = Duration::from_secs(15);

/// A fetched forecast.
#[derive(Debug, Serialize, ToSchema)]
pub struct FetchedForecastOutput {
    /// The forecast as `POST /api/v1/windows` and the plan's `haul_down.forecast` take it.
    pub forecast: ForecastInput,
    /// Where it was fetched (without credentials).
    pub source_url: String,
    /// When it was fetched (s since the Unix epoch).
    pub fetched_at_unix_s: f64,
    /// Forecast members (1 unless an ensemble).
    pub member_count: usize,
    /// Periods (hours, or report groups) of the first member.
    pub period_count: usize,
    /// What the parser assumed or left out.
    pub notes: Vec<String>,
}

/// `url` without a user or password.
fn without_credentials(url: &str) -> String {
    match (url.find("://"), url.find('@')) {
        (Some(s), Some(at)) if at > s && !url[s + 3..at].contains('/') => {
            format!("{}{}", &url[..s + 3], &url[at + 1..])
        }
        _ => url.to_string(),
    }
}

/// Fetches the source's bytes; `Err` says why not.
fn fetch(url: &str) -> Result<Vec<u8>, String> {
    let agent: ureq::Agent = ureq::Agent::config_builder()
        .timeout_global(Some(FETCH_TIMEOUT))
        .http_status_as_error(false)
        .build()
        .into();
    let mut answer = agent
        .get(url)
        .call()
        .map_err(|e| format!("the forecast source could not be reached: {e}"))?;
    let status = answer.status();
    if !status.is_success() {
        return Err(format!("the forecast source answered HTTP {status}"));
    }
    answer
        .body_mut()
        .with_config()
        .limit(MAX_FORECAST_BYTES)
        .read_to_vec()
        .map_err(|e| {
            format!(
                "the forecast source's answer could not be read (at most {} MiB): {e}",
                MAX_FORECAST_BYTES >> 20
            )
        })
}

fn unavailable(message: String) -> ApiError {
    ApiError::new(
        StatusCode::BAD_GATEWAY,
        "forecast_unavailable",
        None,
        message,
    )
}

/// Today's forecast from the configured source, as a request's `forecast`.
#[utoipa::path(
    get, path = "/api/v1/forecast", operation_id = "get_forecast", tag = "solve",
    responses(
        (status = 200, description = "Fetched and readable", body = FetchedForecastOutput),
        (status = 404, description = "The server has no forecast source (`--forecast-url`)", body = ErrorBody),
        (status = 502, description = "The source could not be reached, or answered something that is not a readable forecast", body = ErrorBody),
    )
)]
pub async fn get_forecast(State(app): State<AppState>) -> Result<Response, ApiError> {
    let Some(source) = app.forecast.clone() else {
        return Err(ApiError::new(
            StatusCode::NOT_FOUND,
            "not_configured",
            None,
            "this server has no forecast source: start it with --forecast-url \
             (TETHERPLAN_FORECAST_URL), or paste or drop a forecast file instead",
        ));
    };
    let out = tokio::task::spawn_blocking(move || answer(&source))
        .await
        .map_err(|e| unavailable(format!("the fetch failed: {e}")))?
        .map_err(unavailable)?;
    Ok(json_response(StatusCode::OK, &out))
}

fn answer(source: &ForecastSource) -> Result<FetchedForecastOutput, String> {
    let bytes = fetch(&source.url)?;
    let (forecast, parsed) = forecast_from_source(source.format, &bytes)?;
    Ok(FetchedForecastOutput {
        forecast,
        source_url: without_credentials(&source.url),
        fetched_at_unix_s: std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0.0, |d| d.as_secs_f64()),
        member_count: parsed.members.len(),
        period_count: parsed.members.first().map_or(0, |m| m.periods.len()),
        notes: parsed.notes,
    })
}

#[cfg(test)]
mod tests {
    use super::without_credentials;

    #[test]
    fn credentials_are_removed_and_nothing_else() {
        assert_eq!(
            without_credentials("https://u:p@example.org/v1?x=1"),
            "https://example.org/v1?x=1"
        );
        assert_eq!(
            without_credentials("https://example.org/a@b"),
            "https://example.org/a@b"
        );
    }
}
