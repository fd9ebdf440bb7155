//! Why a request was not answered ([`RequestError`]), the one error body
//! of the CLI and the API ([`ErrorBody`]), and the progress and
//! cancellation handle of long requests ([`Progress`]). Every kind of the
//! contract uses them; they use nothing of it.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::numerics::params::InvalidInput;
use crate::numerics::qep::QepError;

/// Why a request was not answered.
#[derive(Debug, thiserror::Error)]
pub enum RequestError {
    /// The body is not JSON (HTTP 400).
    #[error("malformed JSON: {0}")]
    Malformed(String),
    /// Bad input: the field and the reason (HTTP 422/400).
    #[error(transparent)]
    Invalid(#[from] InvalidInput),
    /// The numerics failed on valid input (HTTP 500; should not happen).
    #[error("numerical failure: {0}")]
    Numerical(QepError),
    /// The work was cancelled through its progress handle.
    #[error("cancelled")]
    Cancelled,
    /// Too large for a synchronous answer: the field and why (HTTP 422
    /// `too_large`; the request is a valid job).
    #[error("too large: {0}")]
    TooLarge(InvalidInput),
}

impl From<QepError> for RequestError {
    fn from(e: QepError) -> Self {
        match e {
            QepError::Cancelled => Self::Cancelled,
            e => Self::Numerical(e),
        }
    }
}

/// Progress reporting and cancellation for long requests.
pub trait Progress: Sync {
    /// `done` of `total` units finished.
    fn report(&self, done: usize, total: usize);
    /// Should the work stop?
    fn cancelled(&self) -> bool {
        false
    }
}

/// Progress that goes nowhere.
pub struct NoProgress;

impl Progress for NoProgress {
    fn report(&self, _: usize, _: usize) {}
}

impl RequestError {
    /// The error body the CLI prints and the API returns.
    pub fn body(&self) -> ErrorBody {
        match self {
            Self::Malformed(m) => ErrorBody::new(
                "malformed_json",
                Some("body".into()),
                format!("malformed JSON: {m}"),
            ),
            Self::Invalid(e) => ErrorBody::new(
                "invalid_input",
                Some(e.field.clone()),
                format!("{}: {}", e.field, e.reason),
            ),
            Self::Numerical(e) => ErrorBody::new("internal", None, e.to_string()),
            Self::Cancelled => ErrorBody::new("cancelled", None, "the work was cancelled"),
            Self::TooLarge(e) => ErrorBody::new(
                "too_large",
                Some(e.field.clone()),
                format!(
                    "{}: {}; submit it as a batch job instead: POST /api/v1/jobs",
                    e.field, e.reason
                ),
            ),
        }
    }
}

/// The one error body of the CLI and the API.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct ErrorBody {
    pub error: ErrorDetail,
}

#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct ErrorDetail {
    /// Machine-readable kind: `invalid_input`, `malformed_json`,
    /// `payload_too_large`, `queue_full`, `overloaded`, `not_found`,
    /// `cancelled`, `internal`.
    pub code: String,
    /// The offending field as a JSON path (`cable.mass_per_length_kg_m`), when one is to blame.
    pub field: Option<String>,
    /// What is wrong, in words.
    pub message: String,
}

impl ErrorBody {
    pub fn new(code: &str, field: Option<String>, message: impl Into<String>) -> Self {
        Self {
            error: ErrorDetail {
                code: code.into(),
                field,
                message: message.into(),
            },
        }
    }
}
