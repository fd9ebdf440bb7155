//! What utoipa's derive cannot say, added to the generated OpenAPI
//! document ([`refine`]):
//!
//! * **One complete request example per POST route** (media-type
//!   `example`, what `/docs` "Try it out" sends). Each succeeds as is:
//!   `tests/api_examples.rs` posts every example of the document and
//!   asserts a 2xx.
//! * **The cable is one of three forms**: `mass_per_length_kg_m`, or
//!   `density_kg_m3` with `area_m2` (never both: the server refuses a mix),
//!   or a `preset` with its `diameter_m`: `CableInput` becomes a `oneOf` of
//!   its forms, each built from the derived property schemas (so their
//!   bounds stay the derive's); a stored system's cable may be partial
//!   (`PartialCableInput`: the same forms, or no mass field at all).
//! * **The synchronous limits** per route, in the operation description
//!   (see [`SYNC_LIMITS`]); the larger requests are valid job requests.

use serde_json::{Value, json};

/// The Table A1 system (steel cable, F = 1000 N, m = 10 kg, L0 = 1 m).
/// No example fixes `model.elements`: the stability answers (t*, h*, safe
/// rate, chart points) are then converged, and spectra and transient runs
/// use the default mesh.
fn system() -> Value {
    json!({
        "cable": {"mass_per_length_kg_m": 0.078},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
        "initial_length_m": 1.0,
        "gravity_m_s2": 9.81,
        "model": {"kind": "linear_string"}
    })
}

fn with(mut base: Value, extra: Value) -> Value {
    if let (Some(b), Some(e)) = (base.as_object_mut(), extra.as_object()) {
        for (k, v) in e {
            b.insert(k.clone(), v.clone());
        }
    }
    base
}

/// The request example of each POST route (path, body).
pub fn request_examples() -> Vec<(&'static str, Value)> {
    let critical = with(
        system(),
        json!({"profile": {"kind": "constant_rate", "rate_m_s": 10.0}}),
    );
    vec![
        (
            "/api/v1/stability",
            with(
                system(),
                json!({"state": {"length_m": 500.0, "rate_m_s": 10.0, "acceleration_m_s2": 0.0}, "modes": 4}),
            ),
        ),
        ("/api/v1/critical", critical.clone()),
        (
            "/api/v1/safe-rate",
            with(system(), json!({"target_elevation_m": 1200.0})),
        ),
        (
            "/api/v1/charts",
            with(
                system(),
                json!({"rates_m_s": {"min": 1.0, "max": 120.0, "count": 60},
                       "net_buoyancies_n": [1000.0, 1500.0]}),
            ),
        ),
        (
            "/api/v1/simulate",
            with(
                with(system(), json!({"initial_length_m": 100.0})),
                json!({"profile": {"kind": "constant_rate", "rate_m_s": 1.0}, "duration_s": 5.0,
                       "samples": 20, "initial": {"kind": "shape", "tip_deflection_m": 0.1}}),
            ),
        ),
        (
            "/api/v1/frequency-response",
            with(
                system(),
                json!({"profile": {"kind": "constant_rate", "rate_m_s": 1.0}, "duration_s": 10.0,
                       "samples": 10, "aero": {"radius_m": 0.5}, "wind_amplitude_m_s": 10.0,
                       "frequencies_rad_s": {"min": 1.0, "max": 4.0, "count": 4}}),
            ),
        ),
        (
            "/api/v1/jobs",
            json!({"kind": "critical", "request": critical}),
        ),
    ]
}

/// Synchronous limits stated on each route (the server's `too_large`
/// answers: `config::Limits`, `solve::MAX_SYNC_*`).
pub const SYNC_LIMITS: [(&str, &str); 4] = [
    (
        "/api/v1/stability",
        "Synchronous limit: `model.elements` ≤ 400 (larger: 422 `too_large`, submit a job).",
    ),
    (
        "/api/v1/charts",
        "Synchronous limits: linear string ≤ 20 000 points (rates × buoyancies) and ≤ 2 000 000 \
         points × elements; GE ≤ 8 points. Larger charts: 422 `too_large`, submit a `chart` job.",
    ),
    (
        "/api/v1/frequency-response",
        "Synchronous limit: `frequencies_rad_s.count` ≤ 16 (larger: 422 `too_large`, submit a \
         `frequency_response` job).",
    ),
    (
        "/api/v1/simulate",
        "Runs that do not finish within the solve timeout (30 s by default) answer 504; submit \
         them as `simulate` jobs.",
    ),
];

/// Synchronous limits that are bounds on one field, added to the route's
/// request schema as `allOf: [request, overlay]` (the request types are
/// shared with jobs, which take more).
fn sync_overlays() -> Vec<(&'static str, Value)> {
    vec![
        (
            "/api/v1/stability",
            json!({"type": "object", "properties": {"model": {"type": "object",
                "properties": {"elements": {"type": "integer", "maximum": 400}}}}}),
        ),
        (
            "/api/v1/frequency-response",
            json!({"type": "object", "properties": {"frequencies_rad_s": {"type": "object",
                "properties": {"count": {"type": "integer", "maximum": 16}}}}}),
        ),
    ]
}

/// Adds the examples, the cable's `oneOf` and the synchronous limits to
/// the generated document.
/// (utoipa reads the refined JSON back; were that ever to fail, the
/// unrefined document is served and `tests/api_examples.rs` fails.)
pub fn refine(doc: utoipa::openapi::OpenApi) -> utoipa::openapi::OpenApi {
    let Ok(mut v) = serde_json::to_value(&doc) else {
        return doc;
    };
    refine_value(&mut v);
    serde_json::from_value(v).unwrap_or(doc)
}

/// A request made of two parts (`allOf` of the system and its parameters,
/// each refusing unknown fields) becomes one object with both parts'
/// properties: as `allOf` the parts would forbid each other's keys.
fn merge_all_of(v: &mut Value) {
    let Some(schemas) = v
        .pointer("/components/schemas")
        .and_then(Value::as_object)
        .cloned()
    else {
        return;
    };
    for (name, schema) in &schemas {
        let Some(parts) = schema.get("allOf").and_then(Value::as_array) else {
            continue;
        };
        let mut properties = serde_json::Map::new();
        let mut required: Vec<Value> = Vec::new();
        let mut mergeable = true;
        for part in parts {
            let resolved = match part.get("$ref").and_then(Value::as_str) {
                Some(r) => r.rsplit('/').next().and_then(|n| schemas.get(n)).cloned(),
                None => Some(part.clone()),
            };
            let Some(obj) = resolved.filter(|o| o.get("properties").is_some()) else {
                mergeable = false;
                break;
            };
            if let Some(p) = obj.get("properties").and_then(Value::as_object) {
                properties.extend(p.clone());
            }
            if let Some(r) = obj.get("required").and_then(Value::as_array) {
                required.extend(r.iter().cloned());
            }
        }
        if !mergeable {
            continue;
        }
        let mut merged = serde_json::Map::new();
        merged.insert("type".into(), json!("object"));
        merged.insert("properties".into(), Value::Object(properties));
        if !required.is_empty() {
            merged.insert("required".into(), Value::Array(required));
        }
        merged.insert("additionalProperties".into(), json!(false));
        for key in ["description", "example", "title"] {
            if let Some(x) = schema.get(key) {
                merged.insert(key.into(), x.clone());
            }
        }
        if let Some(slot) = v.pointer_mut(&format!("/components/schemas/{name}")) {
            *slot = Value::Object(merged);
        }
    }
}

fn refine_value(v: &mut Value) {
    merge_all_of(v);
    for (path, example) in request_examples() {
        if let Some(media) = v
            .pointer_mut(&format!(
                "/paths/{}/post/requestBody/content/application~1json",
                path.replace('~', "~0").replace('/', "~1")
            ))
            .and_then(Value::as_object_mut)
        {
            media.insert("example".into(), example);
        }
    }
    // Routes without a hand-written example take their request schema's own.
    let schema_examples: Vec<(String, Value)> = v["paths"]
        .as_object()
        .into_iter()
        .flatten()
        .filter_map(|(path, ops)| {
            let media = ops.pointer("/post/requestBody/content/application~1json")?;
            if media.get("example").is_some() {
                return None;
            }
            let reference = media.pointer("/schema/$ref")?.as_str()?;
            let name = reference.rsplit('/').next()?;
            let example = v.pointer(&format!("/components/schemas/{name}/example"))?;
            Some((path.clone(), example.clone()))
        })
        .collect();
    for (path, example) in schema_examples {
        if let Some(media) = v
            .pointer_mut(&format!(
                "/paths/{}/post/requestBody/content/application~1json",
                path.replace('~', "~0").replace('/', "~1")
            ))
            .and_then(Value::as_object_mut)
        {
            media.insert("example".into(), example);
        }
    }
    for (path, overlay) in sync_overlays() {
        if let Some(media) = v
            .pointer_mut(&format!(
                "/paths/{}/post/requestBody/content/application~1json",
                path.replace('/', "~1")
            ))
            .and_then(Value::as_object_mut)
            && let Some(schema) = media.remove("schema")
        {
            media.insert("schema".into(), json!({"allOf": [schema, overlay]}));
        }
    }
    for (path, note) in SYNC_LIMITS {
        if let Some(op) = v
            .pointer_mut(&format!("/paths/{}/post", path.replace('/', "~1")))
            .and_then(Value::as_object_mut)
        {
            let d = op
                .get("description")
                .and_then(Value::as_str)
                .unwrap_or("")
                .to_string();
            if !d.contains(note) {
                let joined = if d.is_empty() {
                    note.to_string()
                } else {
                    format!("{d}\n\n{note}")
                };
                op.insert("description".into(), Value::String(joined));
            }
        }
    }
    if let Some(cable) = v.pointer_mut("/components/schemas/CableInput") {
        let partial = cable_one_of(cable);
        if let Some(schemas) = v
            .pointer_mut("/components/schemas")
            .and_then(Value::as_object_mut)
        {
            schemas.insert("PartialCableInput".into(), partial);
        }
        // A stored system may be partial: its cable is the partial one.
        if let Some(c) = v.pointer_mut("/components/schemas/SystemDescription/properties/cable") {
            *c = json!({"oneOf": [
                {"$ref": "#/components/schemas/PartialCableInput"},
                {"type": "null"}
            ]});
        }
    }
}

/// `CableInput` as `oneOf` its forms (mass per length, density and area,
/// preset with diameter — alone, with a mass per length, or with density
/// and area), from the derived properties; every other property is
/// optional in each form. Also `PartialCableInput`, the cable of a stored
/// system (SPEC §9: a request that names the system completes it): the
/// same forms, or none of the mass fields at all.
fn cable_one_of(cable: &mut Value) -> Value {
    let Some(props) = cable.get("properties").and_then(Value::as_object).cloned() else {
        return cable.clone();
    };
    // The derive marks the optional fields nullable; in each form the
    // fields it uses are required numbers.
    let number = |name: &str| -> Value {
        let mut p = props.get(name).cloned().unwrap_or_else(|| json!({}));
        if let Some(o) = p.as_object_mut() {
            o.insert("type".into(), json!("number"));
            o.insert("format".into(), json!("double"));
        }
        p
    };
    let forms = ["mass_per_length_kg_m", "density_kg_m3", "area_m2", "preset"];
    let common: serde_json::Map<String, Value> = props
        .iter()
        .filter(|(k, _)| !forms.contains(&k.as_str()))
        .map(|(k, v)| (k.clone(), v.clone()))
        .collect();
    let form = |title: &str, required: &[&str], own: Vec<(&str, Value)>| {
        let mut p = common.clone();
        // A mass field this form does not use may still be given as
        // `null`, which the server reads as absent (a preset may not).
        for k in ["mass_per_length_kg_m", "density_kg_m3", "area_m2"] {
            p.insert(k.to_string(), json!({"type": "null"}));
        }
        for (k, v) in own {
            p.insert(k.to_string(), v);
        }
        json!({
            "title": title,
            "type": "object",
            "required": required,
            "properties": p,
            "additionalProperties": false
        })
    };
    let description = cable
        .get("description")
        .cloned()
        .unwrap_or_else(|| json!("The cable."));
    // A preset is never null (the server refuses `"preset": null`).
    let mut preset = props.get("preset").cloned().unwrap_or_else(|| json!({}));
    if let Some(o) = preset.as_object_mut() {
        if let Some(Value::Array(one_of)) = o.get_mut("oneOf") {
            one_of.retain(|v| v.get("type") != Some(&json!("null")));
            if one_of.len() == 1 {
                let only = one_of.remove(0);
                o.remove("oneOf");
                if let Some(only) = only.as_object() {
                    o.extend(only.clone());
                }
            }
        }
    }
    let with_mass = vec![
        form(
            "mass per length",
            &["mass_per_length_kg_m"],
            vec![("mass_per_length_kg_m", number("mass_per_length_kg_m"))],
        ),
        form(
            "density and area",
            &["density_kg_m3", "area_m2"],
            vec![
                ("density_kg_m3", number("density_kg_m3")),
                ("area_m2", number("area_m2")),
            ],
        ),
        form(
            "preset with its diameter",
            &["preset", "diameter_m"],
            vec![
                ("preset", preset.clone()),
                ("diameter_m", number("diameter_m")),
                (
                    "mass_per_length_kg_m",
                    props
                        .get("mass_per_length_kg_m")
                        .cloned()
                        .unwrap_or_else(|| json!({})),
                ),
            ],
        ),
        form(
            "preset with its diameter, density and area",
            &["preset", "diameter_m", "density_kg_m3", "area_m2"],
            vec![
                ("preset", preset),
                ("diameter_m", number("diameter_m")),
                ("density_kg_m3", number("density_kg_m3")),
                ("area_m2", number("area_m2")),
            ],
        ),
    ];
    let mut partial_forms = vec![form("without its mass", &[], vec![])];
    partial_forms.extend(with_mass.iter().cloned());
    *cable = json!({"description": description, "oneOf": with_mass});
    json!({
        "description": "The cable of a stored system (`PUT /api/v1/systems/{name}`): any of \
            `CableInput`'s fields, its mass given in one of the same forms or not at all; a \
            request that names the system gives the rest.",
        "oneOf": partial_forms
    })
}

#[cfg(test)]
mod tests {

    #[test]
    fn every_post_route_gets_an_example_and_the_cable_two_forms() {
        let doc = serde_json::to_value(crate::api::openapi::openapi()).unwrap();
        let paths = doc["paths"].as_object().unwrap();
        let posts: Vec<&String> = paths
            .iter()
            .filter(|(_, ops)| ops.get("post").is_some())
            .map(|(p, _)| p)
            .collect();
        assert!(posts.len() >= 7, "{posts:?}");
        for p in posts {
            let ex = &paths[p]["post"]["requestBody"]["content"]["application/json"]["example"];
            assert!(ex.is_object(), "{p} has no request example");
        }
        let cable = &doc["components"]["schemas"]["CableInput"];
        assert_eq!(cable["oneOf"].as_array().unwrap().len(), 4, "{cable}");
        let partial = &doc["components"]["schemas"]["PartialCableInput"];
        assert_eq!(partial["oneOf"].as_array().unwrap().len(), 5, "{partial}");
    }
}
