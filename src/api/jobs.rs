//! `/api/v1/jobs`: submit, list, get and cancel batch jobs.

use axum::extract::{Path, Query, State};
use axum::http::{StatusCode, header};
use axum::response::{IntoResponse, Response};
use serde::{Deserialize, Serialize};
use serde_json::value::RawValue;
use utoipa::{IntoParams, ToSchema};

use crate::api::AppState;
use crate::api::error::{ApiError, JsonBody};
use crate::contract::dto::ErrorBody;
use crate::jobs::SubmitError;
use crate::jobs::kinds::JobSubmission;
use crate::jobs::store::{InsertError, JobRecord, JobStatus};

/// A job: status, progress, and its answer or error.
#[derive(Debug, Serialize, ToSchema)]
pub struct JobView {
    /// Job id (path of `GET /api/v1/jobs/{id}`).
    pub id: i64,
    /// `stability`, `critical`, `safe_rate`, `chart` or `batch`.
    pub kind: String,
    pub status: JobStatus,
    /// Fraction done, 0 to 1 (updated about every 0.2 s while running).
    #[schema(minimum = 0.0, maximum = 1.0)]
    pub progress: f64,
    /// Times the job was started (more than 1 after an interrupted run).
    pub attempts: u32,
    /// When it was submitted (UTC, RFC 3339).
    pub created_at: String,
    /// When it last started (UTC, RFC 3339).
    pub started_at: Option<String>,
    /// When it finished (UTC, RFC 3339).
    pub finished_at: Option<String>,
    /// The answer, when `done`: the body the synchronous route returns
    /// (`StabilityResponse`, `CriticalResponse`, `SafeRateResponse`,
    /// `ChartResponse`), or `BatchOutcome` for a batch. Absent in lists.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(schema_with = job_result_schema)]
    pub result: Option<Box<RawValue>>,
    /// Why it failed or that it was cancelled.
    pub error: Option<ErrorBody>,
}

fn job_result_schema() -> impl Into<utoipa::openapi::RefOr<utoipa::openapi::schema::Schema>> {
    use utoipa::openapi::schema::{OneOfBuilder, Ref};
    let mut one_of = OneOfBuilder::new();
    for name in [
        "StabilityResponse",
        "CriticalResponse",
        "SafeRateResponse",
        "ChartResponse",
        "BatchOutcome",
    ] {
        one_of = one_of.item(Ref::from_schema_name(name));
    }
    one_of.description(Some(
        "The answer, when `done`; absent otherwise and in lists.",
    ))
}

impl JobView {
    fn new(rec: JobRecord) -> Self {
        Self {
            id: rec.id,
            kind: rec.kind,
            status: rec.status,
            progress: rec.progress,
            attempts: rec.attempts,
            created_at: rec.created_at,
            started_at: rec.started_at,
            finished_at: rec.finished_at,
            result: rec.result.and_then(|r| RawValue::from_string(r).ok()),
            error: rec.error.and_then(|e| serde_json::from_str(&e).ok()),
        }
    }
}

/// Answer to a submission.
#[derive(Debug, Serialize, Deserialize, ToSchema)]
pub struct JobAccepted {
    pub id: i64,
    pub kind: String,
    pub status: JobStatus,
    /// Where to poll: `/api/v1/jobs/{id}`.
    pub location: String,
}

/// A page of jobs, newest first, without answers.
#[derive(Debug, Serialize, ToSchema)]
pub struct JobList {
    pub jobs: Vec<JobView>,
}

#[derive(Debug, Deserialize, IntoParams)]
#[into_params(parameter_in = Query)]
pub struct ListQuery {
    /// Only jobs with this status.
    pub status: Option<JobStatus>,
    /// At most this many jobs (default 100).
    #[param(minimum = 1, maximum = 1000)]
    pub limit: Option<usize>,
}

fn json_response(status: StatusCode, value: &impl Serialize) -> Response {
    (
        status,
        [(header::CONTENT_TYPE, "application/json")],
        serde_json::to_vec(value).expect("views serialise"),
    )
        .into_response()
}

async fn blocking<T: Send + 'static>(
    f: impl FnOnce() -> Result<T, ApiError> + Send + 'static,
) -> Result<T, ApiError> {
    tokio::task::spawn_blocking(f)
        .await
        .map_err(|e| ApiError::internal(format!("job store task failed: {e}")))?
}

fn parse_id(id: &str) -> Result<i64, ApiError> {
    id.parse::<i64>()
        .map_err(|_| ApiError::not_found(format!("no job with id `{id}`")))
}

/// Submit a batch job.
///
/// The request is validated now (422 naming the field, nothing stored);
/// the answer is computed in the background on the job pool. Poll
/// `GET /api/v1/jobs/{id}`. Jobs survive restarts and crashes: an
/// interrupted job runs again from the start.
#[utoipa::path(
    post, path = "/api/v1/jobs", operation_id = "create_job", tag = "jobs",
    request_body(content = JobSubmission, description = "One request with its kind, or a batch"),
    responses(
        (status = 202, description = "Accepted and queued", body = JobAccepted,
            headers(("Location" = String, description = "The job's URL"))),
        (status = 400, description = "Malformed JSON", body = ErrorBody),
        (status = 413, description = "Body larger than the limit", body = ErrorBody),
        (status = 415, description = "Content type is not JSON", body = ErrorBody),
        (status = 422, description = "Invalid request; `field` names the culprit", body = ErrorBody),
        (status = 429, description = "Queue full", body = ErrorBody,
            headers(("Retry-After" = u32, description = "Seconds to wait before retrying"))),
        (status = 500, description = "Job store failure", body = ErrorBody),
    )
)]
pub async fn create_job(
    State(app): State<AppState>,
    JsonBody(body): JsonBody,
) -> Result<Response, ApiError> {
    let queue = app.queue.clone();
    let (id, kind) = blocking(move || {
        queue.submit(&body).map_err(|e| match e {
            SubmitError::Request(r) => ApiError::from(r),
            SubmitError::Queue(InsertError::QueueFull { .. }) => ApiError::new(
                StatusCode::TOO_MANY_REQUESTS,
                "queue_full",
                None,
                e.to_string(),
            )
            .retry_after(5),
            SubmitError::Queue(InsertError::Store(s)) => ApiError::from(s),
        })
    })
    .await?;
    let location = format!("/api/v1/jobs/{id}");
    let mut resp = json_response(
        StatusCode::ACCEPTED,
        &JobAccepted {
            id,
            kind: kind.into(),
            status: JobStatus::Queued,
            location: location.clone(),
        },
    );
    resp.headers_mut()
        .insert(header::LOCATION, location.parse().expect("valid header"));
    Ok(resp)
}

/// List jobs, newest first (without their answers).
#[utoipa::path(
    get, path = "/api/v1/jobs", operation_id = "list_jobs", tag = "jobs",
    params(ListQuery),
    responses(
        (status = 200, description = "Jobs, newest first", body = JobList),
        (status = 400, description = "Bad query string", body = ErrorBody),
        (status = 500, description = "Job store failure", body = ErrorBody),
    )
)]
pub async fn list_jobs(
    State(app): State<AppState>,
    query: Result<Query<ListQuery>, axum::extract::rejection::QueryRejection>,
) -> Result<Response, ApiError> {
    let Query(q) = query.map_err(|e| {
        ApiError::new(
            StatusCode::BAD_REQUEST,
            "invalid_query",
            Some("query"),
            e.body_text(),
        )
    })?;
    let limit = q.limit.unwrap_or(100);
    if !(1..=1000).contains(&limit) {
        return Err(ApiError::new(
            StatusCode::BAD_REQUEST,
            "invalid_query",
            Some("limit"),
            format!("limit: must be between 1 and 1000, got {limit}"),
        ));
    }
    let queue = app.queue.clone();
    let jobs = blocking(move || Ok(queue.store.list(q.status, limit)?)).await?;
    Ok(json_response(
        StatusCode::OK,
        &JobList {
            jobs: jobs.into_iter().map(JobView::new).collect(),
        },
    ))
}

/// One job: status, progress, and its answer or error.
#[utoipa::path(
    get, path = "/api/v1/jobs/{id}", operation_id = "get_job", tag = "jobs",
    params(("id" = i64, Path, description = "Job id")),
    responses(
        (status = 200, description = "The job", body = JobView),
        (status = 404, description = "No such job", body = ErrorBody),
        (status = 500, description = "Job store failure", body = ErrorBody),
    )
)]
pub async fn get_job(
    State(app): State<AppState>,
    Path(id): Path<String>,
) -> Result<Response, ApiError> {
    let id = parse_id(&id)?;
    let queue = app.queue.clone();
    let rec = blocking(move || Ok(queue.store.get(id)?)).await?;
    let rec = rec.ok_or_else(|| ApiError::not_found(format!("no job with id {id}")))?;
    Ok(json_response(StatusCode::OK, &JobView::new(rec)))
}

/// Cancel a queued or running job (it stays listed, as `cancelled`).
#[utoipa::path(
    delete, path = "/api/v1/jobs/{id}", operation_id = "delete_job", tag = "jobs",
    params(("id" = i64, Path, description = "Job id")),
    responses(
        (status = 200, description = "Cancelled; the job as it is now", body = JobView),
        (status = 404, description = "No such job", body = ErrorBody),
        (status = 409, description = "The job had already finished", body = ErrorBody),
        (status = 500, description = "Job store failure", body = ErrorBody),
    )
)]
pub async fn delete_job(
    State(app): State<AppState>,
    Path(id): Path<String>,
) -> Result<Response, ApiError> {
    let id = parse_id(&id)?;
    let queue = app.queue.clone();
    let before = {
        let queue = queue.clone();
        blocking(move || Ok(queue.store.status(id)?)).await?
    };
    match before {
        None => Err(ApiError::not_found(format!("no job with id {id}"))),
        Some(s) if s.is_finished() => Err(ApiError::new(
            StatusCode::CONFLICT,
            "conflict",
            None,
            format!(
                "job {id} has already finished ({}); nothing to cancel",
                s.as_str()
            ),
        )),
        Some(_) => {
            let rec = blocking(move || Ok(queue.cancel(id)?)).await?;
            let rec = rec.ok_or_else(|| ApiError::not_found(format!("no job with id {id}")))?;
            Ok(json_response(StatusCode::OK, &JobView::new(rec)))
        }
    }
}
