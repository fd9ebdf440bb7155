//! The JSON contract shared by the CLI, the HTTP API and the job queue:
//! request/response types ([`dto`]), parsing with field paths in errors,
//! conversion to the numerical core, and one function per request kind
//! ([`run`]). Everything here is synchronous and CPU-bound.

pub mod dto;
pub mod envelope;
pub mod equilibrium;
pub mod ge;
pub mod ge_charts;
pub mod run;
pub mod simulate;
pub mod tension;
pub mod transient;

pub use run::{Progress, RequestError};

use crate::numerics::params::InvalidInput;

/// Parses a request body (system part and parameters); errors name the
/// offending field path.
pub fn parse<T: dto::SystemRequest>(body: &[u8]) -> Result<T, RequestError> {
    let value = json_object(body)?;
    let system = parse_value::<dto::SystemInput>(&value)?;
    let params = parse_value::<T::Params>(&value)?;
    Ok(T::from_parts(system, params))
}

/// Parses a body that has no flattened parts (one pass, field paths kept).
pub fn parse_plain<T: serde::de::DeserializeOwned>(body: &[u8]) -> Result<T, RequestError> {
    parse_value(&json_object(body)?)
}

/// The body as a JSON object (400 when it is not JSON, 422 when it is not an object).
fn json_object(body: &[u8]) -> Result<serde_json::Value, RequestError> {
    let value: serde_json::Value =
        serde_json::from_slice(body).map_err(|e| RequestError::Malformed(e.to_string()))?;
    if !value.is_object() {
        return Err(RequestError::Invalid(InvalidInput::new(
            "body",
            "must be a JSON object",
        )));
    }
    Ok(value)
}

/// Deserialises `T` from a JSON value with the error's field path.
pub fn parse_value<T: serde::de::DeserializeOwned>(
    value: &serde_json::Value,
) -> Result<T, RequestError> {
    serde_path_to_error::deserialize(value).map_err(|e| {
        let path = e.path().to_string();
        let message = e.into_inner().to_string();
        let prefix = if path == "." || path.is_empty() {
            String::new()
        } else {
            format!("{path}.")
        };
        // serde names a missing field only in its message: lift it into the path.
        let field = match message
            .strip_prefix("missing field `")
            .and_then(|rest| rest.split('`').next())
        {
            Some(name) => format!("{prefix}{name}"),
            None if prefix.is_empty() => "body".to_string(),
            None => path,
        };
        RequestError::Invalid(InvalidInput::new(field, message))
    })
}
