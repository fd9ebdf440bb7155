//! The committed OpenAPI document is the one the code generates, and it
//! documents every route with its error statuses and unit-named fields.

use serde_json::Value;
use tetherplan::api::openapi::openapi_json;

const COMMITTED: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/openapi/openapi.json");

#[test]
fn committed_openapi_is_up_to_date() {
    let committed = std::fs::read_to_string(COMMITTED).unwrap_or_default();
    assert!(
        committed == openapi_json(),
        "openapi/openapi.json is stale: run `cargo run --release --bin gen_openapi` and commit it"
    );
}

fn doc() -> Value {
    serde_json::from_str(&openapi_json()).unwrap()
}

#[test]
fn every_route_is_documented_with_its_statuses() {
    let doc = doc();
    let expected: &[(&str, &str, &str, &[&str])] = &[
        (
            "post",
            "/api/v1/stability",
            "compute_stability",
            &[
                "200", "400", "401", "413", "415", "422", "500", "503", "504",
            ],
        ),
        (
            "post",
            "/api/v1/critical",
            "compute_critical",
            &[
                "200", "400", "401", "413", "415", "422", "500", "503", "504",
            ],
        ),
        (
            "post",
            "/api/v1/safe-rate",
            "compute_safe_rate",
            &[
                "200", "400", "401", "413", "415", "422", "500", "503", "504",
            ],
        ),
        (
            "post",
            "/api/v1/charts",
            "create_chart",
            &[
                "200", "400", "401", "413", "415", "422", "500", "503", "504",
            ],
        ),
        (
            "post",
            "/api/v1/simulate",
            "run_simulation",
            &[
                "200", "400", "401", "413", "415", "422", "500", "503", "504",
            ],
        ),
        (
            "post",
            "/api/v1/frequency-response",
            "compute_frequency_response",
            &[
                "200", "400", "401", "413", "415", "422", "500", "503", "504",
            ],
        ),
        (
            "post",
            "/api/v1/equilibrium",
            "compute_equilibrium",
            &[
                "200", "400", "401", "413", "415", "422", "500", "503", "504",
            ],
        ),
        (
            "post",
            "/api/v1/envelope",
            "compute_envelope",
            &[
                "200", "400", "401", "413", "415", "422", "500", "503", "504",
            ],
        ),
        (
            "post",
            "/api/v1/plan",
            "compute_plan",
            &[
                "200", "400", "401", "413", "415", "422", "500", "503", "504",
            ],
        ),
        (
            "post",
            "/api/v1/bands",
            "compute_bands",
            &[
                "200", "400", "401", "413", "415", "422", "500", "503", "504",
            ],
        ),
        (
            "post",
            "/api/v1/plan/bands",
            "compute_plan_bands",
            &[
                "200", "400", "401", "413", "415", "422", "500", "503", "504",
            ],
        ),
        (
            "post",
            "/api/v1/envelope/bands",
            "compute_envelope_bands",
            &[
                "200", "400", "401", "413", "415", "422", "500", "503", "504",
            ],
        ),
        (
            "post",
            "/api/v1/dynamics",
            "run_dynamics",
            &[
                "200", "400", "401", "413", "415", "422", "500", "503", "504",
            ],
        ),
        (
            "post",
            "/api/v1/dynamics/peaks",
            "run_dynamics_peaks",
            &[
                "200", "400", "401", "413", "415", "422", "500", "503", "504",
            ],
        ),
        (
            "post",
            "/api/v1/jobs",
            "create_job",
            &[
                "200", "202", "400", "401", "413", "415", "422", "429", "500",
            ],
        ),
        (
            "get",
            "/api/v1/jobs",
            "list_jobs",
            &["200", "400", "401", "500"],
        ),
        (
            "get",
            "/api/v1/jobs/{id}",
            "get_job",
            &["200", "401", "404", "500"],
        ),
        (
            "delete",
            "/api/v1/jobs/{id}",
            "delete_job",
            &["200", "401", "404", "409", "500"],
        ),
        (
            "put",
            "/api/v1/systems/{name}",
            "put_system",
            &[
                "200", "201", "400", "401", "413", "415", "422", "429", "500",
            ],
        ),
        (
            "get",
            "/api/v1/systems/{name}",
            "get_system",
            &["200", "401", "404", "422", "500"],
        ),
        (
            "delete",
            "/api/v1/systems/{name}",
            "delete_system",
            &["204", "401", "404", "422", "500"],
        ),
        (
            "get",
            "/api/v1/systems",
            "list_systems",
            &["200", "401", "500"],
        ),
        (
            "post",
            "/api/v1/flights",
            "create_flight",
            &[
                "201", "400", "401", "413", "415", "422", "500", "503", "504",
            ],
        ),
        (
            "post",
            "/api/v1/flights/simulate",
            "simulate_flight",
            &[
                "200", "400", "401", "406", "413", "415", "422", "503", "504",
            ],
        ),
        (
            "get",
            "/api/v1/flights/{id}/report",
            "flight_report",
            &["200", "401", "404", "406", "500"],
        ),
        (
            "get",
            "/api/v1/flights/{id}/plan",
            "flight_plan",
            &["200", "401", "404", "500"],
        ),
        (
            "get",
            "/api/v1/flights",
            "list_flights",
            &["200", "401", "500"],
        ),
        (
            "get",
            "/api/v1/flights/{id}",
            "get_flight",
            &["200", "401", "404", "500"],
        ),
        (
            "post",
            "/api/v1/flights/{id}/end",
            "end_flight",
            &["200", "401", "404", "500"],
        ),
        (
            "post",
            "/api/v1/flights/{id}/telemetry",
            "post_telemetry",
            &[
                "200", "400", "401", "404", "409", "413", "415", "422", "500",
            ],
        ),
        (
            "post",
            "/api/v1/flights/{id}/alarms/acknowledge",
            "acknowledge_alarms",
            &["200", "401", "404", "500"],
        ),
        (
            "get",
            "/api/v1/flights/{id}/replan",
            "replan_flight",
            &["200", "401", "404", "422", "500"],
        ),
        (
            "get",
            "/api/v1/flights/{id}/events",
            "flight_events",
            &["200", "401", "404"],
        ),
        (
            "post",
            "/api/v1/windows",
            "compute_windows",
            &[
                "200", "400", "401", "413", "415", "422", "500", "503", "504",
            ],
        ),
        ("get", "/api/v1/presets", "list_presets", &["200", "401"]),
        (
            "get",
            "/api/v1/forecast",
            "get_forecast",
            &["200", "401", "404", "502"],
        ),
        ("get", "/healthz", "get_health", &["200"]),
        ("get", "/openapi.json", "get_openapi", &["200"]),
    ];
    let paths = doc["paths"].as_object().unwrap();
    let operations: usize = paths.values().map(|p| p.as_object().unwrap().len()).sum();
    assert_eq!(
        operations,
        expected.len(),
        "undocumented or unexpected operations"
    );
    for (method, path, id, statuses) in expected {
        let op = &doc["paths"][path][method];
        assert_eq!(op["operationId"], *id, "{method} {path}");
        let mut got: Vec<&str> = op["responses"]
            .as_object()
            .unwrap()
            .keys()
            .map(String::as_str)
            .collect();
        got.sort();
        assert_eq!(&got, statuses, "{method} {path}");
        for status in statuses
            .iter()
            .filter(|s| s.starts_with('4') || s.starts_with('5'))
        {
            let schema = &op["responses"][status]["content"]["application/json"]["schema"]["$ref"];
            assert_eq!(
                schema, "#/components/schemas/ErrorBody",
                "{method} {path} {status}"
            );
        }
        for retry in ["429", "503"] {
            if statuses.contains(&retry) {
                assert!(
                    op["responses"][retry]["headers"]["Retry-After"].is_object(),
                    "{method} {path} {retry}"
                );
            }
        }
    }
}

/// Numeric fields of the contract end in their unit (SPEC §4).
#[test]
fn numeric_fields_name_their_unit() {
    const UNITS: &[&str] = &[
        "_m", "_s", "_m_s", "_m_s2", "_m_s3", "_n", "_kg", "_kg_m", "_kg_m3", "_m2", "_1_s", "_hz",
        "_nondim", "_db", "_deg", "_m3",
    ];
    // Counts, ids and fractions; RateGrid's bounds are described in m/s by its parent `rates_m_s`.
    const UNITLESS: &[&str] = &[
        // Launch windows (issue 32 names `probability_go`): shares of
        // ensemble members and their Wilson bounds, member and plan counts.
        "probability",
        "probability_go",
        "probability_go_low",
        "probability_go_high",
        "members",
        "plans_computed",
        "elements",
        "check_elements",
        "finest_elements",
        "modes",
        "count",
        "id",
        "attempts",
        "progress",
        "min",
        "max",
        // Percentile bands and distributions carry their parent's unit
        // (`max_elevation_m.p05`, the `field` an uncertain input names).
        "p05",
        "p50",
        "p95",
        "p05_error",
        "p50_error",
        "p95_error",
        "p05_low",
        "p05_high",
        "p50_low",
        "p50_high",
        "p95_low",
        "p95_high",
        "mean",
        "std_dev",
        "low",
        "high",
        "seed",
        // The dynamics' mesh (segments), its step halvings, a sample's index.
        "segments",
        "halvings",
        "sample",
        // A live flight's check (SPEC §13 names them; their unit is the
        // check's `unit` field), a batch's counts, a refused sample's line.
        "value",
        "caution_at",
        "stop_at",
        "accepted",
        "duplicates",
        "rejected",
        "line",
        "samples_received",
        "acknowledged",
        "seq",
        // A dynamics answer's converged figure (issue 31 item 2): its
        // unit is the one its key ends in (`converged.peak_tension_n`:
        // `value`, `error_estimate`, `safe_value` in N).
        "error_estimate",
        "safe_value",
    ];
    // Dimensionless by name: ratios (E*, γ̃ as the issues name them), step
    // and sample counts, Newton iteration counts, relative tolerances,
    // step cuts (halvings of a time step).
    const DIMENSIONLESS_SUFFIXES: &[&str] = &[
        "_ratio",
        "steps",
        "samples",
        "steps_per_run",
        "_failures",
        "_tolerance",
        "iterations",
        "iterations_mean",
        "iterations_max",
        "iterations_total",
        "_solves",
        "_cuts",
        // Counts of processes (`/healthz` live_workers).
        "_workers",
        // Counts of kept outputs (the dynamics' `sample_count`, `shape_count`).
        "_count",
    ];
    let doc = doc();
    let mut offenders = vec![];
    for (name, schema) in doc["components"]["schemas"].as_object().unwrap() {
        let Some(props) = schema["properties"].as_object() else {
            continue;
        };
        for (field, p) in props {
            let ty = p["type"].clone();
            let numeric = ty == "number"
                || ty == "integer"
                || ty
                    .as_array()
                    .is_some_and(|a| a.iter().any(|t| t == "number" || t == "integer"));
            if numeric
                && !UNITS.iter().any(|u| field.ends_with(u))
                && !UNITLESS.contains(&field.as_str())
                && !DIMENSIONLESS_SUFFIXES.iter().any(|u| field.ends_with(u))
            {
                offenders.push(format!("{name}.{field}"));
            }
        }
    }
    assert!(
        offenders.is_empty(),
        "numeric fields without a unit suffix: {offenders:?}"
    );
}
