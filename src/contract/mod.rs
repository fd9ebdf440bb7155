//! The JSON contract shared by the CLI, the HTTP API and the job queue:
//! request/response types ([`dto`]), parsing with field paths in errors,
//! conversion to the numerical core, and one function per request kind
//! ([`run`]). Everything here is synchronous and CPU-bound.

pub mod bands;
pub mod chart_chunks;
pub mod dto;
pub mod dynamics;
pub mod envelope;
pub mod equilibrium;
pub mod finite;
pub mod ge;
pub mod ge_charts;
pub mod ge_critical;
pub mod ge_numerics;
pub mod ge_quasi_static;
pub mod json_keys;
pub mod plan;
pub mod ranges;
pub mod run;
pub mod simulate;
pub mod system;
pub mod tension;
pub mod transient;

pub use run::{Progress, RequestError};

use crate::numerics::params::InvalidInput;

/// Parses a request body (system part and parameters); errors name the
/// offending field path.
///
/// Both parts refuse unknown fields: the body's keys are split between
/// them ([`dto::SYSTEM_KEYS`] go to the system), and a key neither knows
/// is named with every key the request takes.
pub fn parse<T: dto::SystemRequest>(body: &[u8]) -> Result<T, RequestError> {
    let value = json_object(body)?;
    let (system_part, params_part): (serde_json::Map<_, _>, serde_json::Map<_, _>) = value
        .as_object()
        .expect("json_object gives an object")
        .clone()
        .into_iter()
        .partition(|(k, _)| dto::SYSTEM_KEYS.contains(&k.as_str()));
    let system = parse_value::<dto::SystemInput>(&serde_json::Value::Object(system_part))?;
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
    let system: Vec<String> = dto::SYSTEM_KEYS.iter().map(|k| format!("`{k}`")).collect();
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

/// A JSON value in plain words for an error message (`null`, `the number 2`, …).
pub fn describe_json(v: &serde_json::Value) -> String {
    use serde_json::Value;
    match v {
        Value::Null => "nothing (null)".into(),
        Value::Bool(b) => format!("{b}"),
        Value::Number(n) => format!("the number {n}"),
        Value::String(s) => format!("the text {:?}", s.chars().take(40).collect::<String>()),
        Value::Array(_) => "a list".into(),
        Value::Object(_) => "an object".into(),
    }
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
        // serde names a missing or unknown field only in its message: lift it into the path.
        let named = ["missing field `", "unknown field `"]
            .iter()
            .find_map(|p| message.strip_prefix(p))
            .and_then(|rest| rest.split('`').next());
        let unknown = message.starts_with("unknown field `");
        // A hand-written deserialiser names the part at fault: "in `key`: …".
        if let Some(rest) = message.strip_prefix("in `")
            && let Some((key, reason)) = rest.split_once("`: ")
        {
            let field = if path == "." || path.is_empty() {
                key.to_string()
            } else if key.starts_with('[') {
                format!("{path}{key}")
            } else {
                format!("{path}.{key}")
            };
            return RequestError::Invalid(InvalidInput::new(field, reason));
        }
        let field = match named {
            // serde_path_to_error already ends the path with an unknown key
            // of a plain struct (not inside a tagged enum).
            Some(name) if path == name || path.ends_with(&format!(".{name}")) => path,
            // inside a tagged enum the path stops at the enum: find the key below it
            Some(name) if unknown => {
                find_key(value, &path, name).unwrap_or_else(|| format!("{prefix}{name}"))
            }
            Some(name) => format!("{prefix}{name}"),
            None if prefix.is_empty() => "body".to_string(),
            None => path,
        };
        RequestError::Invalid(InvalidInput::new(field, plain_words(&message)))
    })
}

/// The full path of the first object holding `key` at or below `path`
/// (`profile.points[1]`) in `value`.
fn find_key(value: &serde_json::Value, path: &str, key: &str) -> Option<String> {
    let mut node = value;
    if !(path.is_empty() || path == ".") {
        for part in path.split('.') {
            let (name, indices) = match part.find('[') {
                Some(i) => (&part[..i], &part[i..]),
                None => (part, ""),
            };
            if !name.is_empty() {
                node = node.get(name)?;
            }
            for index in indices.split(['[', ']']).filter(|s| !s.is_empty()) {
                node = node.get(index.parse::<usize>().ok()?)?;
            }
        }
    }
    fn search(v: &serde_json::Value, at: String, key: &str) -> Option<String> {
        let join = |at: &str, k: &str| {
            if at.is_empty() {
                k.to_string()
            } else {
                format!("{at}.{k}")
            }
        };
        match v {
            serde_json::Value::Object(m) => {
                if m.contains_key(key) {
                    return Some(join(&at, key));
                }
                m.iter().find_map(|(k, x)| search(x, join(&at, k), key))
            }
            serde_json::Value::Array(a) => a
                .iter()
                .enumerate()
                .find_map(|(i, x)| search(x, format!("{at}[{i}]"), key)),
            _ => None,
        }
    }
    let at = if path == "." {
        String::new()
    } else {
        path.to_string()
    };
    search(node, at, key)
}

/// serde's messages in plain words: "must be a number, got string \"x\""
/// rather than "invalid type: string \"x\", expected f64".
pub fn plain_words(message: &str) -> String {
    if message.starts_with("missing field `") {
        return "is required".to_string();
    }
    if let Some(rest) = message.strip_prefix("unknown field `") {
        let (name, tail) = rest.split_once('`').unwrap_or((rest, ""));
        let tail = tail.trim_start_matches(", ");
        return match tail {
            "there are no fields" => format!("unknown field `{name}`; this object takes no fields"),
            t if t.starts_with("expected ") => format!("unknown field `{name}`; {t}"),
            _ => format!("unknown field `{name}`"),
        };
    }
    if let Some(rest) = message.strip_prefix("unknown variant `") {
        let (name, tail) = rest.split_once('`').unwrap_or((rest, ""));
        let tail = tail.trim_start_matches(", ");
        return format!("unknown kind `{name}`; {tail}");
    }
    let (got, expected) = match ["invalid type: ", "invalid value: ", "invalid length "]
        .iter()
        .find_map(|p| message.strip_prefix(p))
        .and_then(|rest| rest.rsplit_once(", expected "))
    {
        Some((got, expected)) => (got.to_string(), expected.to_string()),
        None => return message.to_string(),
    };
    let got = got
        .replace("floating point `", "")
        .replace("integer `", "")
        .replace('`', "");
    let need = match expected.as_str() {
        "f64" | "f32" => "must be a number".to_string(),
        "usize" | "u64" | "u32" | "u16" | "u8" => "must be a whole number (0 or more)".to_string(),
        "i64" | "i32" => "must be a whole number".to_string(),
        "a boolean" => "must be true or false".to_string(),
        "a string" => "must be a string".to_string(),
        "a sequence" => "must be a list".to_string(),
        e if e.starts_with("struct ") || e == "a map" || e.starts_with("internally tagged") => {
            "must be an object".to_string()
        }
        e if e.starts_with("unit variant") || e.starts_with("variant identifier") => {
            "must be one of the listed kinds".to_string()
        }
        e => format!("must be {e}"),
    };
    if got == "null" {
        // An empty input: say what belongs there.
        return format!("is empty: it {}", need.replacen("must be", "needs", 1));
    }
    format!("{need}, got {got}")
}
