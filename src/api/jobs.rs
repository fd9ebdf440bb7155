//! `/api/v1/jobs`: submit, list, get and cancel batch jobs.
//!
//! Jobs belong to the token that submitted them ([`Caller`]): another
//! token gets 404 for them and does not see them listed. `Idempotency-Key`
//! makes a submission safe to repeat. A finished job's answer is sent as
//! the stored JSON text, spliced into the view without being parsed, and
//! streamed from the store one page at a time as the client reads it.

use axum::body::{Body, Bytes};
use axum::extract::{Extension, Path, Query, State};
use axum::http::{HeaderMap, StatusCode, header};
use axum::response::{IntoResponse, Response};
use serde::{Deserialize, Serialize};
use serde_json::value::RawValue;
use utoipa::{IntoParams, ToSchema};

use crate::api::AppState;
use crate::api::auth::Caller;
use crate::api::error::{ApiError, JsonBody};
use crate::contract::error::ErrorBody;
use crate::jobs::kinds::JobSubmission;
use crate::jobs::store::{InsertError, JobHead, JobRecord, JobStatus, StoreError};
use crate::jobs::{JobQueue, SubmitError, Submitter};
use std::sync::Arc;

/// A job: status, progress, and its answer or error.
#[derive(Debug, Serialize, ToSchema)]
pub struct JobView {
    /// Job id (path of `GET /api/v1/jobs/{id}`).
    pub id: i64,
    /// The kind of its request (one of `JobItem`'s `kind`s) or `batch`.
    pub kind: String,
    pub status: JobStatus,
    /// Fraction done, 0 to 1 (updated about every 0.2 s while running).
    #[schema(minimum = 0.0, maximum = 1.0)]
    pub progress: f64,
    /// Times the job was started (more than 1 after an interrupted run; a
    /// job whose process died at every one of `TETHERPLAN_JOB_MAX_ATTEMPTS`
    /// starts fails with `attempts_exhausted`). A chunked job's coordinator
    /// taken over while chunks remain is a start that does not count
    /// against that limit: each chunk counts its own starts.
    pub attempts: u32,
    /// When it was submitted (UTC, RFC 3339).
    pub created_at: String,
    /// When it last started (UTC, RFC 3339).
    pub started_at: Option<String>,
    /// When it finished (UTC, RFC 3339).
    pub finished_at: Option<String>,
    /// The answer, when `done`: the body the synchronous route of `kind`
    /// returns, or `BatchOutcome` for a batch. Absent in lists.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(schema_with = job_result_schema)]
    pub result: Option<Box<RawValue>>,
    /// Why it failed or that it was cancelled.
    pub error: Option<ErrorBody>,
}

/// The schemas a finished job's `result` may have: the answer of every
/// kind (the same list as a batch item's, [`crate::contract::catalogue`])
/// and a batch's outcome.
pub(crate) fn job_result_schema()
-> impl Into<utoipa::openapi::RefOr<utoipa::openapi::schema::Schema>> {
    use utoipa::openapi::schema::{OneOfBuilder, Ref};
    let mut one_of = OneOfBuilder::new();
    for name in crate::contract::catalogue::response_schemas() {
        one_of = one_of.item(Ref::from_schema_name(name));
    }
    one_of = one_of.item(Ref::from_schema_name("BatchOutcome"));
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

    /// The view as a response body. The stored answer (JSON text, possibly
    /// tens of MB) is spliced in as it is, not parsed: it is read from the
    /// store one page ([`crate::jobs::store::ANSWER_PAGE_BYTES`]) at a time, each when the
    /// connection asks for more, so a client that does not read holds at
    /// most a page or two in memory (hyper's write buffer), not the answer.
    fn into_body(head: JobHead, queue: Arc<JobQueue>) -> Body {
        let id = head.record.id;
        let mut start = serde_json::to_vec(&Self::new(head.record)).expect("views serialise");
        let Some(pages) = head.answer_pages else {
            return Body::from(start);
        };
        start.pop(); // the closing brace
        start.extend_from_slice(br#","result":"#);
        if pages == 0 {
            start.extend_from_slice(b"null}");
            return Body::from(start);
        }
        let first = futures_util::stream::iter([Ok::<_, StoreError>(Bytes::from(start))]);
        let answer = futures_util::stream::unfold(0usize, move |page| {
            let queue = queue.clone();
            async move {
                if page == pages {
                    return None;
                }
                let read = tokio::task::spawn_blocking(move || queue.store.answer_page(id, page))
                    .await
                    .map_err(|e| StoreError(format!("reading the answer of job {id}: {e}")))
                    .and_then(|r| r)
                    .and_then(|p| {
                        p.map(Bytes::from).ok_or_else(|| {
                            StoreError(format!("page {page} of the answer of job {id} is gone"))
                        })
                    });
                if let Err(e) = &read {
                    // the connection is cut: the client sees a truncated body
                    tracing::warn!(job = id, error = %e, "answer stream stopped");
                }
                Some((read, page + 1))
            }
        });
        let end = futures_util::stream::iter([Ok(Bytes::from_static(b"}"))]);
        use futures_util::StreamExt;
        Body::from_stream(first.chain(answer).chain(end))
    }
}

/// Answer to a submission (202 new, 200 an earlier one with the same
/// `Idempotency-Key`).
#[derive(Debug, Serialize, Deserialize, ToSchema)]
pub struct JobAccepted {
    pub id: i64,
    pub kind: String,
    /// `queued` for a new job; the current status for a repeated key.
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

/// 429 `store_quota_full` with `message`, and `Retry-After` until the
/// owner's oldest finished job expires (room is freed then), when one has
/// finished `oldest_finished_s` ago.
pub(crate) fn store_quota_full(
    message: String,
    oldest_finished_s: Option<f64>,
    retention_s: f64,
) -> ApiError {
    let err = ApiError::new(
        StatusCode::TOO_MANY_REQUESTS,
        "store_quota_full",
        None,
        message,
    );
    match oldest_finished_s {
        Some(age) => {
            err.retry_after((retention_s - age).ceil().clamp(1.0, f64::from(u32::MAX)) as u32)
        }
        None => err,
    }
}

pub(crate) fn json_response(status: StatusCode, value: &impl Serialize) -> Response {
    (
        status,
        [(header::CONTENT_TYPE, "application/json")],
        serde_json::to_vec(value).expect("views serialise"),
    )
        .into_response()
}

pub(crate) async fn blocking<T: Send + 'static>(
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

/// The `Idempotency-Key` header: 1 to 255 visible ASCII characters.
pub const IDEMPOTENCY_KEY: &str = "idempotency-key";

fn idempotency_key(headers: &HeaderMap) -> Result<Option<String>, ApiError> {
    let Some(v) = headers.get(IDEMPOTENCY_KEY) else {
        return Ok(None);
    };
    let bad = || {
        ApiError::new(
            StatusCode::UNPROCESSABLE_ENTITY,
            "invalid_input",
            Some("Idempotency-Key"),
            "Idempotency-Key: must be 1 to 255 visible ASCII characters",
        )
    };
    let key = v.to_str().map_err(|_| bad())?.trim();
    if key.is_empty() || key.len() > 255 || !key.bytes().all(|b| b.is_ascii_graphic()) {
        return Err(bad());
    }
    Ok(Some(key.to_string()))
}

/// Submit a batch job.
///
/// The request is validated now (422 naming the field, nothing stored),
/// including an estimate of its answer's size against the job limit; the
/// answer is computed in the background on the job pool. Poll
/// `GET /api/v1/jobs/{id}`. Jobs survive restarts and crashes: an
/// interrupted job runs again from the start. With `Idempotency-Key`, a
/// repeated submission (same token, same key, same body) returns the
/// first job with 200 instead of creating another; the same key with
/// another body is 422.
#[utoipa::path(
    post, path = "/api/v1/jobs", operation_id = "create_job", tag = "jobs",
    request_body(content = JobSubmission, description = "One request with its kind, or a batch"),
    params(
        ("Idempotency-Key" = Option<String>, Header,
            description = "Client-chosen key (1 to 255 visible ASCII characters): a repeated key returns the first job"),
    ),
    responses(
        (status = 200, description = "Seen before: the job first submitted with this Idempotency-Key", body = JobAccepted,
            headers(("Location" = String, description = "The job's URL")),
            links(
                ("GetJob" = (operation_id = "get_job", parameters(("id" = "$response.body#/id")),
                    description = "The job: status, progress, answer")),
                ("DeleteJob" = (operation_id = "delete_job", parameters(("id" = "$response.body#/id")),
                    description = "Cancel the job")),
            )),
        (status = 202, description = "Accepted and queued", body = JobAccepted,
            headers(("Location" = String, description = "The job's URL")),
            links(
                ("GetJob" = (operation_id = "get_job", parameters(("id" = "$response.body#/id")),
                    description = "The job: status, progress, answer")),
                ("DeleteJob" = (operation_id = "delete_job", parameters(("id" = "$response.body#/id")),
                    description = "Cancel the job")),
            )),
        (status = 400, description = "Malformed JSON", body = ErrorBody),
        (status = 413, description = "Body larger than the limit", body = ErrorBody),
        (status = 415, description = "Content type is not JSON", body = ErrorBody),
        (status = 422, description = "Invalid request, answer too large for a job, or an Idempotency-Key reused with another body; `field` names the culprit", body = ErrorBody),
        (status = 429, description = "Queue full (`queue_full`), this token's quota of pending jobs reached (`quota_full`), or its store quota (`store_quota_full`): the bytes its jobs (requests, answers, the estimated answers of pending jobs) and named systems keep, at most `TETHERPLAN_TOKEN_MAX_STORED_BYTES` (1 GiB by default); room is freed when finished jobs expire or named systems are deleted", body = ErrorBody,
            headers(("Retry-After" = u32, description = "Seconds to wait before retrying (store quota: until this token's oldest finished job expires; absent when none has finished)"))),
        (status = 500, description = "Job store failure", body = ErrorBody),
    )
)]
pub async fn create_job(
    State(app): State<AppState>,
    Extension(caller): Extension<Caller>,
    headers: HeaderMap,
    JsonBody(body): JsonBody,
) -> Result<Response, ApiError> {
    let who = Submitter {
        owner: caller.owner,
        idempotency_key: idempotency_key(&headers)?,
    };
    let queue = app.queue.clone();
    let retention_s = queue.limits().job_retention.as_secs_f64();
    let submitted = blocking(move || {
        queue.submit_as(&body, &who).map_err(|e| match e {
            SubmitError::Request(r) => ApiError::from(r),
            SubmitError::Queue(InsertError::QueueFull { .. }) => ApiError::new(
                StatusCode::TOO_MANY_REQUESTS,
                "queue_full",
                None,
                e.to_string(),
            )
            .retry_after(5),
            SubmitError::Queue(InsertError::QuotaFull { .. }) => ApiError::new(
                StatusCode::TOO_MANY_REQUESTS,
                "quota_full",
                None,
                e.to_string(),
            )
            .retry_after(5),
            SubmitError::Queue(InsertError::StoreFull {
                oldest_finished_s, ..
            }) => store_quota_full(e.to_string(), oldest_finished_s, retention_s),
            SubmitError::Queue(InsertError::KeyReused { .. }) => ApiError::new(
                StatusCode::UNPROCESSABLE_ENTITY,
                "idempotency_key_reused",
                Some("Idempotency-Key"),
                e.to_string(),
            ),
            SubmitError::Queue(InsertError::Store(s)) => ApiError::from(s),
        })
    })
    .await?;
    let location = format!("/api/v1/jobs/{}", submitted.id);
    let status = if submitted.created {
        StatusCode::ACCEPTED
    } else {
        StatusCode::OK
    };
    let mut resp = json_response(
        status,
        &JobAccepted {
            id: submitted.id,
            kind: submitted.kind,
            status: submitted.status,
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
    Extension(caller): Extension<Caller>,
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
    let jobs = blocking(move || {
        Ok(queue
            .store
            .list_owned(caller.owner.as_deref(), q.status, limit)?)
    })
    .await?;
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
    Extension(caller): Extension<Caller>,
    Path(id): Path<String>,
) -> Result<Response, ApiError> {
    let id = parse_id(&id)?;
    let queue = app.queue.clone();
    let head = {
        let queue = queue.clone();
        blocking(move || Ok(queue.store.get_head(id, caller.owner.as_deref())?)).await?
    };
    let head = head.ok_or_else(|| ApiError::not_found(format!("no job with id {id}")))?;
    Ok((
        StatusCode::OK,
        [(header::CONTENT_TYPE, "application/json")],
        JobView::into_body(head, queue),
    )
        .into_response())
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
    Extension(caller): Extension<Caller>,
    Path(id): Path<String>,
) -> Result<Response, ApiError> {
    let id = parse_id(&id)?;
    let queue = app.queue.clone();
    let owner = caller.owner;
    let before = {
        let queue = queue.clone();
        let owner = owner.clone();
        blocking(move || Ok(queue.store.status_owned(id, owner.as_deref())?)).await?
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
            let rec = blocking(move || Ok(queue.cancel(id, owner.as_deref())?)).await?;
            let rec = rec.ok_or_else(|| ApiError::not_found(format!("no job with id {id}")))?;
            Ok(json_response(StatusCode::OK, &JobView::new(rec)))
        }
    }
}
