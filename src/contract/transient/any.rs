//! One `simulate` entry point for both cable models: the body's
//! `model.kind` picks the linear string (`linear_string`, the default) or
//! the geometrically exact beam (`geometrically_exact`).

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::contract::ge::{GeSimulateRequest, GeSimulateResponse, simulate_ge};
use crate::contract::transient::{SimulateRequest, SimulateResponse, simulate};
use crate::contract::{Progress, RequestError, parse};

/// A transient run of either model.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(untagged)]
pub enum AnySimulateRequest {
    /// `model.kind = "geometrically_exact"`.
    GeometricallyExact(GeSimulateRequest),
    /// `model.kind = "linear_string"` (or absent).
    LinearString(SimulateRequest),
}

/// The answer of [`AnySimulateRequest`].
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(untagged)]
pub enum AnySimulateResponse {
    GeometricallyExact(GeSimulateResponse),
    LinearString(SimulateResponse),
}

/// Parses a simulate body, choosing the model by `model.kind`.
pub fn parse_simulate(body: &[u8]) -> Result<AnySimulateRequest, RequestError> {
    let value: serde_json::Value =
        serde_json::from_slice(body).map_err(|e| RequestError::Malformed(e.to_string()))?;
    if value.pointer("/model/kind").and_then(|k| k.as_str()) == Some("geometrically_exact") {
        let req: GeSimulateRequest = crate::contract::parse_ge(body, "the GE transient run")?;
        req.check_ranges()?;
        Ok(AnySimulateRequest::GeometricallyExact(req))
    } else {
        parse(body).map(AnySimulateRequest::LinearString)
    }
}

/// Runs a transient simulation of either model.
pub fn simulate_any(
    req: &AnySimulateRequest,
    progress: &dyn Progress,
) -> Result<AnySimulateResponse, RequestError> {
    match req {
        AnySimulateRequest::GeometricallyExact(r) => {
            simulate_ge(r, progress).map(AnySimulateResponse::GeometricallyExact)
        }
        AnySimulateRequest::LinearString(r) => {
            simulate(r, progress).map(AnySimulateResponse::LinearString)
        }
    }
}
