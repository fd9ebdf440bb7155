//! Parsing a request body: the JSON object, the old names refused naming
//! their new place, the system part and the parameters parsed separately
//! (unknown fields refused in both), and the range checks
//! ([`crate::contract::ranges`]) run right after.

use crate::contract::error::RequestError;
use crate::contract::json::parse_value;
use crate::contract::system;
use crate::contract::system::input;
use crate::numerics::params::InvalidInput;

/// Parses a request body (system part and parameters); errors name the
/// offending field path.
///
/// Both parts refuse unknown fields: the body's keys are split between
/// them ([`input::SYSTEM_KEYS`] go to the system), and a key neither knows
/// is named with every key the request takes.
pub fn parse<T: input::SystemRequest>(body: &[u8]) -> Result<T, RequestError> {
    let value = json_object(body)?;
    let (system_part, params_part): (serde_json::Map<_, _>, serde_json::Map<_, _>) = value
        .as_object()
        .expect("json_object gives an object")
        .clone()
        .into_iter()
        .partition(|(k, _)| input::SYSTEM_KEYS.contains(&k.as_str()));
    let system = parse_value::<input::SystemInput>(&serde_json::Value::Object(system_part))?;
    let params =
        parse_value::<T::Params>(&serde_json::Value::Object(params_part)).map_err(|e| match e {
            RequestError::Invalid(InvalidInput { field, reason })
                if !field.contains('.') && reason.starts_with("unknown field") =>
            {
                RequestError::Invalid(InvalidInput::new(field, with_system_keys(&reason)))
            }
            other => other,
        })?;
    let request = T::from_parts(system, params);
    request.check_ranges()?;
    Ok(request)
}

/// Adds the system keys to the "expected one of" list of a top-level
/// unknown-field message.
fn with_system_keys(reason: &str) -> String {
    let system: Vec<String> = input::SYSTEM_KEYS
        .iter()
        .map(|k| format!("`{k}`"))
        .collect();
    match reason.split_once("; expected ") {
        Some((head, tail)) => {
            let tail = tail.trim_start_matches("one of ").replace(" or ", ", ");
            format!("{head}; expected one of {}, {tail}", system.join(", "))
        }
        None => format!("{reason}; expected one of {}", system.join(", ")),
    }
}

/// Parses a geometrically exact body (one pass, field paths kept): the
/// whole system is accepted, its parts this calm-air analysis has no use
/// for checked and set aside ([`system::resolve::strip_calm_system`]).
pub fn parse_ge<T: serde::de::DeserializeOwned>(
    body: &[u8],
    analysis: &str,
) -> Result<T, RequestError> {
    let mut value = json_object(body)?;
    system::resolve::strip_calm_system(&mut value, analysis)?;
    parse_value(&value)
}

/// [`parse_ge`] for an analysis with its own use for the top-level key
/// `keep` (the GE chart's `wind`, which is not calm): that key stays in the
/// body and is parsed with it.
pub fn parse_ge_keeping<T: serde::de::DeserializeOwned>(
    body: &[u8],
    analysis: &str,
    keep: &str,
) -> Result<T, RequestError> {
    let mut value = json_object(body)?;
    let kept = value.as_object_mut().and_then(|o| o.remove(keep));
    system::resolve::strip_calm_system(&mut value, analysis)?;
    if let (Some(k), Some(o)) = (kept, value.as_object_mut()) {
        o.insert(keep.to_string(), k);
    }
    parse_value(&value)
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
    system::refuse_moved(&value)?;
    Ok(value)
}
