//! The published schema and the server agree (issue 34, items 4–6):
//!
//! * stored systems, which may be partial (`{"cable": {}}`), are answered
//!   in a shape the published `SystemView` allows, and every system body
//!   the server stores is one the published `SystemDescription` allows
//!   (and those it refuses, the schema refuses too);
//! * names that read as paths (`.`, `..`, `.x`, `a..b`, `a.`) are refused
//!   as stored names and as `"system"` in bodies, and the published
//!   pattern is exactly the server's rule;
//! * the validation gaps: `cable.preset: null`, `/dynamics` with both
//!   `shape_count` and `shape_times_s`, `/envelope` with a flow speed it
//!   used to ignore unchecked.
//!
//! Schemas are checked with the `jsonschema` crate (JSON Schema 2020-12,
//! as OpenAPI 3.1 uses).

use axum::http::StatusCode;
use serde_json::{Value, json};
use tetherplan::api::openapi::openapi;
use tetherplan::contract::system::resolve::{MAX_NAME_LEN, check_name};

mod common;
use common::{app, send, with};

fn doc() -> Value {
    serde_json::to_value(openapi()).unwrap()
}

fn validator(name: &str) -> jsonschema::Validator {
    let mut doc = doc();
    doc["$ref"] = json!(format!("#/components/schemas/{name}"));
    doc["$schema"] = json!("https://json-schema.org/draft/2020-12/schema");
    jsonschema::draft202012::new(&doc).expect("the document's schemas compile")
}

fn errors(v: &jsonschema::Validator, instance: &Value) -> Vec<String> {
    v.iter_errors(instance)
        .take(5)
        .map(|e| format!("{} at {}", e, e.instance_path()))
        .collect()
}

fn example(path: &str) -> Value {
    doc()["paths"][path]["post"]["requestBody"]["content"]["application/json"]["example"].clone()
}

/// Partial systems are stored and answered as the schema says; the bodies
/// the server refuses are the ones the schema refuses.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn stored_systems_replay_against_their_published_schema() {
    let (app, _queue) = app();
    let view = validator("SystemView");
    let body_schema = validator("SystemDescription");
    let list = validator("SystemList");
    let accepted = [
        json!({"cable": {}}),
        json!({"cable": {"diameter_m": 0.006, "breaking_strength_n": 30000.0}}),
        json!({"cable": {"preset": "steel", "diameter_m": 0.01}}),
        json!({"cable": {"preset": "dyneema", "diameter_m": 0.006, "mass_per_length_kg_m": 0.03}}),
        json!({"cable": {"preset": "steel", "diameter_m": 0.004, "density_kg_m3": 7800.0, "area_m2": 1e-5}}),
        json!({"cable": {"density_kg_m3": 7800.0, "area_m2": 1e-5}}),
        json!({"cable": {"mass_per_length_kg_m": 0.078}}),
        json!({"cable": {"mass_per_length_kg_m": null, "diameter_m": 0.006}}),
        json!({"cable": {"mass_per_length_kg_m": 0.078, "density_kg_m3": null}}),
        json!({"cable": {"preset": "steel", "diameter_m": 0.01, "mass_per_length_kg_m": null}}),
        json!({"aerostat": {}}),
        json!({"aerostat": {"mass_kg": 10.0}}),
        json!({}),
        doc()["components"]["schemas"]["SystemDescription"]["example"].clone(),
    ];
    for (i, body) in accepted.iter().enumerate() {
        let uri = format!("/api/v1/systems/s{i}");
        let (status, answer) = send(&app, "PUT", &uri, Some(body)).await;
        assert_eq!(status, StatusCode::CREATED, "{body}: {answer}");
        assert_eq!(errors(&view, &answer), Vec::<String>::new(), "PUT {body} answered {answer}");
        assert_eq!(
            errors(&body_schema, body),
            Vec::<String>::new(),
            "the server stores {body}, which the published request schema refuses"
        );
        let (status, answer) = send(&app, "GET", &uri, None).await;
        assert_eq!(status, StatusCode::OK);
        assert_eq!(errors(&view, &answer), Vec::<String>::new(), "GET {uri} answered {answer}");
    }
    let (_, listed) = send(&app, "GET", "/api/v1/systems", None).await;
    assert_eq!(errors(&list, &listed), Vec::<String>::new());
    let refused = [
        (json!({"cable": {"density_kg_m3": 7800.0}}), "cable.area_m2"),
        (json!({"cable": {"area_m2": 1e-5}}), "cable.density_kg_m3"),
        (
            json!({"cable": {"mass_per_length_kg_m": 0.078, "area_m2": 1e-5}}),
            "cable.mass_per_length_kg_m",
        ),
        (json!({"cable": {"preset": "steel"}}), "cable.diameter_m"),
        (
            json!({"cable": {"preset": null, "mass_per_length_kg_m": 0.078}}),
            "cable.preset",
        ),
    ];
    for (body, field) in refused {
        let (status, answer) = send(&app, "PUT", "/api/v1/systems/r", Some(&body)).await;
        assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{body}: {answer}");
        assert_eq!(answer["error"]["field"], field, "{body}: {answer}");
        assert!(
            !errors(&body_schema, &body).is_empty(),
            "the server refuses {body} but the published schema allows it"
        );
    }
}

const PATH_LIKE: [&str; 8] = [".", "..", "...", ".hidden", "a..b", "a.", "../x", "a/b"];
const GOOD: [&str; 5] = ["a", "a.b", "site-1_tether", "0", "v1.2.3"];

/// `.`, `..` and every other name that reads as a path are refused, as a
/// stored name (percent-encoded in the URL too) and as `"system"` in a body.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn names_that_read_as_paths_are_refused() {
    let (app, _queue) = app();
    let body = json!({"cable": {"mass_per_length_kg_m": 0.078}});
    for name in GOOD {
        let (status, answer) =
            send(&app, "PUT", &format!("/api/v1/systems/{name}"), Some(&body)).await;
        assert_eq!(status, StatusCode::CREATED, "{name}: {answer}");
    }
    for name in PATH_LIKE {
        let encoded: String = name
            .bytes()
            .map(|b| format!("%{b:02X}"))
            .collect();
        for uri in [
            format!("/api/v1/systems/{encoded}"),
            format!("/api/v1/systems/{name}"),
        ] {
            if uri.matches('/').count() > 4 {
                continue; // a second path segment is another route (404)
            }
            let (status, answer) = send(&app, "PUT", &uri, Some(&body)).await;
            assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "PUT {uri}: {answer}");
            assert_eq!(answer["error"]["field"], "name", "{uri}: {answer}");
            assert!(
                answer["error"]["message"].as_str().unwrap().contains("name"),
                "{answer}"
            );
        }
        let request = with(example("/api/v1/equilibrium"), json!({"system": name}));
        let (status, answer) = send(&app, "POST", "/api/v1/equilibrium", Some(&request)).await;
        assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "system {name}: {answer}");
        assert_eq!(answer["error"]["field"], "system", "{name}: {answer}");
    }
}

/// The published name pattern (with its length bounds) accepts exactly
/// the names the server accepts.
#[test]
fn the_published_name_rule_is_the_servers() {
    let d = doc();
    let param = d["paths"]["/api/v1/systems/{name}"]["put"]["parameters"][0]["schema"].clone();
    assert!(param["pattern"].is_string(), "no pattern: {param}");
    assert_eq!(param["maxLength"], MAX_NAME_LEN, "{param}");
    let schema = jsonschema::draft202012::new(&param).unwrap();
    let long_ok = "a".repeat(MAX_NAME_LEN);
    let long_bad = "a".repeat(MAX_NAME_LEN + 1);
    let mut names: Vec<&str> = PATH_LIKE.iter().chain(GOOD.iter()).copied().collect();
    names.extend(["", "-a", "_a", "a-", "a_", "a b", "é", "a.-b", long_ok.as_str(), long_bad.as_str()]);
    for name in names {
        assert_eq!(
            schema.is_valid(&json!(name)),
            check_name("name", name).is_ok(),
            "schema and server disagree on {name:?}"
        );
    }
}

/// `"preset": null` is refused where the schema requires a value (a cable
/// preset is never null), naming the field.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_null_preset_is_refused() {
    let (app, _queue) = app();
    let mut request = example("/api/v1/equilibrium");
    request["cable"] = json!({"preset": null, "mass_per_length_kg_m": 0.078, "diameter_m": 0.006});
    let (status, answer) = send(&app, "POST", "/api/v1/equilibrium", Some(&request)).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{answer}");
    assert_eq!(answer["error"]["field"], "cable.preset", "{answer}");
    assert!(
        answer["error"]["message"].as_str().unwrap().contains("null"),
        "{answer}"
    );
    let schema = validator("CableInput");
    assert!(!errors(&schema, &request["cable"]).is_empty());
}

/// `shape_count` beside `shape_times_s` contradicts it (even `[]` beside
/// 1001, the count the schema refuses): refused naming `shape_count`.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn dynamics_refuses_a_shape_count_beside_shape_times() {
    let (app, _queue) = app();
    for (count, times) in [(1001, json!([])), (5, json!([1.0])), (0, json!([]))] {
        let request = with(
            example("/api/v1/dynamics"),
            json!({"shape_count": count, "shape_times_s": times, "duration_s": 2.0}),
        );
        let (status, answer) = send(&app, "POST", "/api/v1/dynamics", Some(&request)).await;
        assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{count} {times}: {answer}");
        assert_eq!(answer["error"]["field"], "shape_count", "{answer}");
        // As a job too (nothing stored).
        let job = json!({"kind": "dynamics", "request": request});
        let (status, answer) = send(&app, "POST", "/api/v1/jobs", Some(&job)).await;
        assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{answer}");
    }
}

/// `/envelope` with a wind grid used to take any `wind.flow.speed_m_s`
/// (−151, 1e300) and ignore it: it is checked as when it is used.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn envelope_checks_the_flow_speed_beside_a_grid() {
    let (app, _queue) = app();
    let base = example("/api/v1/envelope");
    assert!(base.get("wind_speeds_m_s").is_some(), "{base}");
    for speed in [-151.0, -1.0, 151.0, 1e300] {
        let mut request = base.clone();
        request["wind"]["flow"]["speed_m_s"] = json!(speed);
        let (status, answer) = send(&app, "POST", "/api/v1/envelope", Some(&request)).await;
        assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{speed}: {answer}");
        assert_eq!(answer["error"]["field"], "wind.flow.speed_m_s", "{answer}");
    }
    let mut request = base.clone();
    request["wind"]["flow"] = json!({"kind": "power_law", "coefficient_m_s": -3.0, "exponent_nondim": 0.14});
    let (status, answer) = send(&app, "POST", "/api/v1/envelope", Some(&request)).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{answer}");
    assert_eq!(answer["error"]["field"], "wind.flow.coefficient_m_s", "{answer}");
}
