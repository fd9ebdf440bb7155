//! A request before it is parsed: the stored named system it names
//! (`"system": "name"`) merged under it (objects merged key by key, the
//! request's fields win, a `null` removes the stored field), and the old
//! names of the plan refused naming their new place.

use serde_json::Value;

use crate::contract::RequestError;
use crate::numerics::params::InvalidInput;

/// The moved names: (old path, new path).
pub const MOVED: &[(&str, &str)] = &[
    ("wind.cable_diameter_m", "cable.diameter_m"),
    (
        "wind.cable_normal_drag_coefficient_nondim",
        "cable.normal_drag_coefficient_nondim",
    ),
    (
        "wind.aerostat_drag_coefficient_nondim",
        "aerostat.drag_coefficient_nondim",
    ),
    (
        "wind.aerostat_reference_area_m2",
        "aerostat.reference_area_m2",
    ),
    (
        "wind.aerostat_lift_coefficient_nondim",
        "aerostat.lift_coefficient_nondim",
    ),
    ("wind.shape", "wind.flow"),
    ("tether.breaking_strength_n", "cable.breaking_strength_n"),
    (
        "tether.safety_factor_nondim",
        "required_safety_factor_nondim",
    ),
];

fn get<'a>(v: &'a Value, path: &str) -> Option<&'a Value> {
    path.split('.').try_fold(v, |node, key| node.get(key))
}

/// Refuses the old names of the system (the plan's `wind.cable_*`,
/// `wind.aerostat_*`, `tether.*`), naming where each moved.
pub fn refuse_moved(v: &Value) -> Result<(), InvalidInput> {
    for (old, new) in MOVED {
        if get(v, old).is_some() {
            return Err(InvalidInput::new(*old, format!("moved to {new}")));
        }
    }
    if v.get("tether").is_some() {
        return Err(InvalidInput::new(
            "tether",
            "moved: the breaking strength is cable.breaking_strength_n and the safety factor \
             required_safety_factor_nondim",
        ));
    }
    Ok(())
}

/// Longest name of a stored system.
pub const MAX_NAME_LEN: usize = 64;

/// The pattern of a system's name (with at most [`MAX_NAME_LEN`]
/// characters): letters, digits, `-` and `_`, with single dots between
/// them; it starts with a letter or digit and ends without a dot, so no
/// name reads as a path (`.`, `..`, `.hidden`, `a..b`, `a/b`).
pub const NAME_PATTERN: &str = r"^[A-Za-z0-9](\.?[A-Za-z0-9_-])*$";

/// Checks a system's name against [`NAME_PATTERN`] and [`MAX_NAME_LEN`].
pub fn check_name(field: &str, name: &str) -> Result<(), InvalidInput> {
    let shown = || format!("{:?}", name.chars().take(80).collect::<String>());
    let chars_ok = name
        .chars()
        .all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.'));
    let why = if name.is_empty() || name.len() > MAX_NAME_LEN || !chars_ok {
        format!(
            "a system's name is 1 to {MAX_NAME_LEN} letters, digits, '-', '_' or '.', got {}",
            shown()
        )
    } else if !name.starts_with(|c: char| c.is_ascii_alphanumeric()) {
        format!(
            "a system's name starts with a letter or digit (a name such as `.`, `..` or `.x` reads as a path), got {}",
            shown()
        )
    } else if name.contains("..") || name.ends_with('.') {
        format!(
            "a system's name has single dots between other characters, never two in a row or one at the end (it would read as a path), got {}",
            shown()
        )
    } else {
        return Ok(());
    };
    Err(InvalidInput::new(field, why))
}

/// Deep merge: `over` onto `base` (objects key by key, `null` removes, anything else replaces).
pub fn merge(base: &mut Value, over: &Value) {
    match (base, over) {
        (Value::Object(b), Value::Object(o)) => {
            for (k, v) in o {
                if v.is_null() {
                    b.remove(k);
                } else if let Some(slot) = b.get_mut(k) {
                    merge(slot, v);
                } else {
                    b.insert(k.clone(), v.clone());
                }
            }
        }
        (b, o) => *b = o.clone(),
    }
}

/// Resolves `"system": "name"` in the request object `value` with
/// `lookup` (the stored system's JSON, or None when there is none);
/// `field` names the `system` key in errors. Returns whether the request
/// changed. The moved names are refused in the result.
pub fn resolve_request<E: From<RequestError>>(
    value: &mut Value,
    field: &str,
    lookup: &mut dyn FnMut(&str) -> Result<Option<Value>, E>,
) -> Result<bool, E> {
    let Some(obj) = value.as_object_mut() else {
        return Ok(false);
    };
    let Some(name) = obj.remove("system") else {
        return Ok(false);
    };
    let name = match name {
        Value::String(s) => s,
        other => {
            return Err(RequestError::Invalid(InvalidInput::new(
                field,
                format!(
                    "must be the name of a stored system, got {}",
                    crate::contract::describe_json(&other)
                ),
            ))
            .into());
        }
    };
    check_name(field, &name).map_err(|e| E::from(e.into()))?;
    let Some(mut stored) = lookup(&name)? else {
        return Err(RequestError::Invalid(InvalidInput::new(
            field,
            format!("no system named `{name}` is stored for this token"),
        ))
        .into());
    };
    merge(&mut stored, value);
    *value = stored;
    Ok(true)
}

/// Resolves the body of a synchronous request: unchanged bytes when it
/// names no system.
pub fn resolve_body<E: From<RequestError>>(
    body: &[u8],
    lookup: &mut dyn FnMut(&str) -> Result<Option<Value>, E>,
) -> Result<Option<Vec<u8>>, E> {
    // Fast path: a body without the key is left as it is.
    if !body.windows(8).any(|w| w == b"\"system\"") {
        return Ok(None);
    }
    let Ok(mut value) = serde_json::from_slice::<Value>(body) else {
        return Ok(None); // the parser reports it
    };
    if resolve_request(&mut value, "system", lookup)? {
        Ok(Some(serde_json::to_vec(&value).expect("JSON serialises")))
    } else {
        Ok(None)
    }
}

/// Resolves the requests of a job submission (`{"kind", "request"}`, or a
/// batch of them): unchanged bytes when none names a system.
pub fn resolve_job_body<E: From<RequestError>>(
    body: &[u8],
    lookup: &mut dyn FnMut(&str) -> Result<Option<Value>, E>,
) -> Result<Option<Vec<u8>>, E> {
    if !body.windows(8).any(|w| w == b"\"system\"") {
        return Ok(None);
    }
    let Ok(mut value) = serde_json::from_slice::<Value>(body) else {
        return Ok(None);
    };
    let mut changed = false;
    if value.get("kind").and_then(Value::as_str) == Some("batch") {
        if let Some(list) = value.get_mut("request").and_then(Value::as_array_mut) {
            for (i, item) in list.iter_mut().enumerate() {
                if let Some(r) = item.get_mut("request") {
                    changed |= resolve_request(r, &format!("request[{i}].request.system"), lookup)?;
                }
            }
        }
    } else if let Some(r) = value.get_mut("request") {
        changed = resolve_request(r, "request.system", lookup)?;
    }
    Ok(changed.then(|| serde_json::to_vec(&value).expect("JSON serialises")))
}

/// The system parts a calm-air body without its own place for them
/// accepts (the geometrically exact bodies): checked, then set aside.
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct CalmExtras {
    #[serde(default)]
    wind: Option<super::WindInput>,
    #[serde(default)]
    winch: Option<super::WinchInput>,
    #[serde(default)]
    required_safety_factor_nondim: Option<f64>,
    #[serde(default)]
    lift_reserve_nondim: Option<f64>,
}

/// Takes the system's `wind` (when it is the §9 one, with `flow`),
/// `winch`, `required_safety_factor_nondim` and `lift_reserve_nondim` out
/// of a body whose analysis is in calm air and has no place for them:
/// each is checked, and a non-zero wind is refused naming `wind.flow`.
pub fn strip_calm_system(value: &mut Value, analysis: &str) -> Result<(), RequestError> {
    let Some(obj) = value.as_object_mut() else {
        return Ok(());
    };
    let mut extras = serde_json::Map::new();
    if obj.get("wind").is_some_and(|w| w.get("flow").is_some()) {
        extras.insert("wind".into(), obj.remove("wind").expect("present"));
    }
    for k in [
        "winch",
        "required_safety_factor_nondim",
        "lift_reserve_nondim",
    ] {
        if let Some(v) = obj.remove(k) {
            extras.insert(k.into(), v);
        }
    }
    if extras.is_empty() {
        return Ok(());
    }
    let e: CalmExtras = crate::contract::parse_value(&Value::Object(extras))?;
    if let Some(w) = &e.wind {
        w.check()?;
    }
    super::WindInput::require_calm(e.wind.as_ref(), analysis)?;
    if let Some(w) = &e.winch {
        w.check("winch")?;
    }
    if let Some(f) = e.required_safety_factor_nondim {
        super::validate::required_safety_factor(f)?;
    }
    if let Some(r) = e.lift_reserve_nondim {
        super::validate::lift_reserve(r)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn moved_names_are_refused_naming_the_new_place() {
        let e = refuse_moved(&json!({"wind": {"cable_diameter_m": 0.006}})).unwrap_err();
        assert_eq!(e.field, "wind.cable_diameter_m");
        assert_eq!(e.reason, "moved to cable.diameter_m");
        let e = refuse_moved(&json!({"tether": {"safety_factor_nondim": 5}})).unwrap_err();
        assert_eq!(e.reason, "moved to required_safety_factor_nondim");
        assert!(refuse_moved(&json!({"wind": {"flow": {}}})).is_ok());
    }

    #[test]
    fn a_named_system_is_merged_under_the_request() {
        let stored = json!({"cable": {"mass_per_length_kg_m": 0.078, "diameter_m": 0.006},
                            "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0}});
        let mut req = json!({"system": "a", "aerostat": {"net_buoyancy_n": 1500.0}, "cable": {"diameter_m": null}});
        let mut lookup = |n: &str| -> Result<Option<Value>, RequestError> {
            Ok((n == "a").then(|| stored.clone()))
        };
        assert!(resolve_request(&mut req, "system", &mut lookup).unwrap());
        assert_eq!(
            req,
            json!({"cable": {"mass_per_length_kg_m": 0.078},
                   "aerostat": {"net_buoyancy_n": 1500.0, "mass_kg": 10.0}})
        );
        let mut unknown = json!({"system": "b"});
        let e = resolve_request(&mut unknown, "system", &mut lookup).unwrap_err();
        assert!(
            matches!(e, RequestError::Invalid(ref i) if i.field == "system"),
            "{e}"
        );
    }
}
