//! The JSON contract shared by the CLI, the HTTP API and the job queue:
//! request/response types ([`dto`]), parsing with field paths in errors,
//! conversion to the numerical core, and one function per request kind
//! ([`run`]). Everything here is synchronous and CPU-bound.

pub mod dto;
pub mod run;
pub mod transient;

pub use run::{Progress, RequestError};

/// Parses a JSON body; errors name the offending field path.
pub fn parse<T: serde::de::DeserializeOwned>(body: &[u8]) -> Result<T, RequestError> {
    let mut de = serde_json::Deserializer::from_slice(body);
    let value: T = serde_path_to_error::deserialize(&mut de).map_err(|e| {
        let path = e.path().to_string();
        let inner = e.into_inner();
        let field = if path == "." || path.is_empty() { "body".to_string() } else { path };
        RequestError::Invalid(crate::numerics::params::InvalidInput::new(field, inner.to_string()))
    })?;
    de.end().map_err(|e| RequestError::Invalid(crate::numerics::params::InvalidInput::new("body", e.to_string())))?;
    Ok(value)
}
