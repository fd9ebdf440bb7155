//! The one error body of the API (`{"error": {"code", "field", "message"}}`,
//! [`ErrorBody`]) as an axum response, and the JSON body extractor that
//! turns every transport-level rejection (wrong content type, oversize or
//! unreadable body) into it.
//!
//! Status codes: 400 malformed JSON, 404 unknown job or path, 405 wrong
//! method, 409 cancelling a finished job, 413 oversize body, 415 not
//! `application/json`, 422 invalid input (wrong type, missing field,
//! out-of-range value, too large for a synchronous answer: the field is
//! named), 429 job queue full, 503 too many solves in flight, 504 solve
//! took too long, 500 a bug.

use axum::body::Bytes;
use axum::extract::{FromRequest, Request};
use axum::http::{HeaderValue, StatusCode, header};
use axum::response::{IntoResponse, Response};

use crate::contract::RequestError;
use crate::contract::error::ErrorBody;
use crate::jobs::store::StoreError;

/// An error answer: status, the error body, and `Retry-After` when waiting helps.
#[derive(Debug)]
pub struct ApiError {
    pub status: StatusCode,
    pub body: ErrorBody,
    pub retry_after_s: Option<u32>,
}

impl ApiError {
    pub fn new(
        status: StatusCode,
        code: &str,
        field: Option<&str>,
        message: impl Into<String>,
    ) -> Self {
        Self {
            status,
            body: ErrorBody::new(code, field.map(str::to_string), message),
            retry_after_s: None,
        }
    }

    pub fn retry_after(mut self, seconds: u32) -> Self {
        self.retry_after_s = Some(seconds);
        self
    }

    pub fn not_found(message: impl Into<String>) -> Self {
        Self::new(StatusCode::NOT_FOUND, "not_found", None, message)
    }

    pub fn internal(message: impl Into<String>) -> Self {
        Self::new(StatusCode::INTERNAL_SERVER_ERROR, "internal", None, message)
    }

    /// Valid input too large to answer synchronously; names the field and points to jobs.
    pub fn too_large(field: &str, message: impl std::fmt::Display) -> Self {
        crate::contract::analysis::too_large(field, message).into()
    }
}

impl From<RequestError> for ApiError {
    fn from(e: RequestError) -> Self {
        let status = match e {
            RequestError::Malformed(_) => StatusCode::BAD_REQUEST,
            RequestError::Invalid(_) | RequestError::TooLarge(_) => {
                StatusCode::UNPROCESSABLE_ENTITY
            }
            RequestError::Numerical(_) => StatusCode::INTERNAL_SERVER_ERROR,
            RequestError::Cancelled => StatusCode::SERVICE_UNAVAILABLE,
        };
        if status == StatusCode::INTERNAL_SERVER_ERROR {
            tracing::error!(error = %e, "numerical failure on valid input");
        }
        Self {
            status,
            body: e.body(),
            retry_after_s: None,
        }
    }
}

impl From<StoreError> for ApiError {
    fn from(e: StoreError) -> Self {
        tracing::error!(error = %e, "job store failure");
        Self::internal(e.to_string())
    }
}

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        let body = serde_json::to_vec(&self.body).expect("error bodies serialise");
        let mut resp = (
            self.status,
            [(
                header::CONTENT_TYPE,
                HeaderValue::from_static("application/json"),
            )],
            body,
        )
            .into_response();
        if let Some(s) = self.retry_after_s {
            resp.headers_mut()
                .insert(header::RETRY_AFTER, HeaderValue::from(s));
        }
        resp
    }
}

/// A request body that claims to be JSON, read within the body limit.
/// Parsing (with field paths) is left to [`crate::contract::parse`].
pub struct JsonBody(pub Bytes);

fn is_json(content_type: &str) -> bool {
    let essence = content_type
        .split(';')
        .next()
        .unwrap_or("")
        .trim()
        .to_ascii_lowercase();
    essence == "application/json"
        || (essence.starts_with("application/") && essence.ends_with("+json"))
}

/// Did the connection layer stop the body for the global byte budget?
fn refused_for_budget(e: &(dyn std::error::Error + 'static)) -> bool {
    let mut next: Option<&(dyn std::error::Error + 'static)> = Some(e);
    while let Some(err) = next {
        if err.downcast_ref::<BodyRefusal>().is_some() {
            return true;
        }
        next = err.source();
    }
    false
}

impl<S: Send + Sync> FromRequest<S> for JsonBody {
    type Rejection = ApiError;

    async fn from_request(req: Request, state: &S) -> Result<Self, ApiError> {
        let content_type = req
            .headers()
            .get(header::CONTENT_TYPE)
            .and_then(|v| v.to_str().ok())
            .unwrap_or("");
        if !is_json(content_type) {
            return Err(ApiError::new(
                StatusCode::UNSUPPORTED_MEDIA_TYPE,
                "unsupported_media_type",
                Some("content-type"),
                format!(
                    "the body must be JSON with `Content-Type: application/json`, got {}",
                    if content_type.is_empty() {
                        "no content type".to_string()
                    } else {
                        format!("`{content_type}`")
                    }
                ),
            ));
        }
        // Gathered into one buffer as it arrives: the memory follows the
        // body's bytes, not its pieces (`api::body`).
        let req = req.map(|b| axum::body::Body::new(crate::api::body::Gathered::new(b)));
        let bytes = Bytes::from_request(req, state).await.map_err(|rejection| {
            if refused_for_budget(&rejection) {
                ApiError::new(
                    StatusCode::SERVICE_UNAVAILABLE,
                    "overloaded",
                    Some("body"),
                    BodyRefusal::Busy.to_string(),
                )
                .retry_after(1)
            } else if rejection.status() == StatusCode::PAYLOAD_TOO_LARGE {
                ApiError::new(
                    StatusCode::PAYLOAD_TOO_LARGE,
                    "payload_too_large",
                    Some("body"),
                    "the request body is larger than the server accepts (see --max-body-bytes)",
                )
            } else {
                ApiError::new(
                    StatusCode::BAD_REQUEST,
                    "malformed_json",
                    Some("body"),
                    rejection.body_text(),
                )
            }
        })?;
        crate::contract::json_keys::reject_duplicate_keys(&bytes)?;
        Ok(Self(bytes))
    }
}

/// Why the server stopped reading a body.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BodyRefusal {
    /// The bytes held over all connections reached the budget.
    Busy,
}

impl std::fmt::Display for BodyRefusal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Busy => f.write_str(
                "the server holds as many request bytes as it accepts at once; retry shortly",
            ),
        }
    }
}

impl std::error::Error for BodyRefusal {}

#[cfg(test)]
mod tests {
    use super::is_json;

    #[test]
    fn json_content_types() {
        assert!(is_json("application/json"));
        assert!(is_json("Application/JSON; charset=utf-8"));
        assert!(is_json("application/problem+json"));
        assert!(!is_json("text/plain"));
        assert!(!is_json(""));
    }
}
