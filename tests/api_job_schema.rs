//! Every job kind's finished answer (every kind of the catalogue, each
//! model) matches the published `JobView` schema
//! of the generated OpenAPI document (validated with the `jsonschema`
//! crate, JSON Schema 2020-12 as OpenAPI 3.1 uses), and so do lists,
//! failures and cancellations. POST /jobs links to GET and DELETE /jobs/{id}.

use axum::http::StatusCode;
use serde_json::{Value, json};
use tetherplan::api::openapi::openapi;
use tetherplan::contract::catalogue::KINDS;
use tetherplan::jobs::store::JobStatus;
use tetherplan::jobs::try_execute_next;

mod common;
use common::{app, send as call, with};

fn string(elements: usize) -> Value {
    json!({
        "cable": {"density_kg_m3": 7800.0, "area_m2": 1e-5},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
        "initial_length_m": 1.0,
        "model": {"kind": "linear_string", "elements": elements}
    })
}

/// One small request of every kind of the catalogue and of each model;
/// the kinds without one written here run their route's published example.
fn requests() -> Vec<(&'static str, Value)> {
    let mut requests = written_requests();
    let doc = serde_json::to_value(openapi()).unwrap();
    for kind in KINDS {
        if requests.iter().any(|(k, _)| *k == kind.name) {
            continue;
        }
        let example = &doc["paths"][kind.path]["post"]["requestBody"]["content"]["application/json"]
            ["example"];
        assert!(
            example.is_object(),
            "no request for the kind {} ({}): its route publishes no example",
            kind.name,
            kind.path
        );
        requests.push((kind.name, example.clone()));
    }
    requests
}

/// Every kind of the catalogue has a request here: a new kind is checked
/// against the published `JobView` as soon as it is in the list.
#[test]
fn every_kind_of_the_catalogue_is_checked() {
    let kinds: Vec<&str> = requests().iter().map(|(k, _)| *k).collect();
    assert_eq!(KINDS.len(), 15, "the catalogue's kinds");
    for kind in KINDS {
        assert!(kinds.contains(&kind.name), "{} has no request", kind.name);
    }
    // JobView.result and BatchItemOutcome.result list the same answers
    let doc = serde_json::to_value(openapi()).unwrap();
    let refs = |schema: &str| -> Vec<String> {
        doc["components"]["schemas"][schema]["properties"]["result"]["oneOf"]
            .as_array()
            .unwrap_or_else(|| panic!("{schema}.result is a oneOf"))
            .iter()
            .map(|r| r["$ref"].as_str().unwrap().to_string())
            .collect()
    };
    let (job, item) = (refs("JobView"), refs("BatchItemOutcome"));
    assert_eq!(
        job[..job.len() - 1],
        item[..],
        "JobView.result vs BatchItemOutcome.result"
    );
    assert_eq!(job.last().unwrap(), "#/components/schemas/BatchOutcome");
    assert_eq!(item.len(), KINDS.len());
    for name in ["DynamicsResponse", "DynamicsPeaksResponse"] {
        assert!(
            job.contains(&format!("#/components/schemas/{name}")),
            "{job:?}"
        );
    }
}

/// The requests written for this test: small ones, and both models.
fn written_requests() -> Vec<(&'static str, Value)> {
    let scale = (0.078f64 / 1000.0).sqrt();
    vec![
        (
            "stability",
            with(string(20), json!({"state": {"length_m": 10.0}, "modes": 3})),
        ),
        (
            "critical",
            with(
                string(50),
                json!({"profile": {"kind": "constant_rate", "rate_m_s": 10.0}}),
            ),
        ),
        (
            "safe_rate",
            with(string(50), json!({"target_elevation_m": 100.0})),
        ),
        (
            "chart",
            with(
                string(20),
                json!({"rates_m_s": {"min": 1.0, "max": 120.0, "count": 5}, "net_buoyancies_n": [1000.0, 1500.0]}),
            ),
        ),
        (
            "chart",
            json!({
                "cable": {"density_kg_m3": 7800.0, "area_m2": 1e-5},
                "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
                "initial_length_m": 1.0,
                "model": {"kind": "geometrically_exact", "elements": 10, "bending_stiffness_n_m2": 1000.0, "inertia_ratio": 1.0},
                "stiffness_ratios": [1e5],
                "rates_m_s": {"min": 100.0, "max": 110.0, "count": 2}
            }),
        ),
        (
            "simulate",
            with(
                with(string(30), json!({"initial_length_m": 100.0})),
                json!({"profile": {"kind": "constant_rate", "rate_m_s": 1.0}, "duration_s": 5.0, "samples": 20,
                       "initial": {"kind": "shape", "tip_deflection_m": 0.1}, "reduced_model": true,
                       "eigenvalues": {"interval_s": 1.0, "count": 2}}),
            ),
        ),
        (
            "simulate",
            json!({"cable": {"density_kg_m3": 7800.0, "area_m2": 1e-5},
                   "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0}, "initial_length_m": 1.0,
                   "model": {"kind": "geometrically_exact", "elements": 10, "bending_stiffness_n_m2": 1000.0,
                             "stiffness_ratio": 1e5, "inertia_ratio": 1.0},
                   "time_step_s": 0.000883, "duration_s": 0.0883, "eigenvalues_every_steps": 50}),
        ),
        (
            "frequency_response",
            with(
                string(20),
                json!({"profile": {"kind": "constant_rate", "rate_m_s": 1.0}, "duration_s": 10.0, "samples": 10,
                       "aero": {"radius_m": 0.5}, "wind_amplitude_m_s": 10.0,
                       "frequencies_rad_s": {"min": 1.0, "max": 4.0, "count": 3}}),
            ),
        ),
        (
            "frequency_response",
            json!({
                "excitation": "base",
                "cable": {"mass_per_length_kg_m": 0.078},
                "model": {"kind": "geometrically_exact", "elements": 10, "bending_stiffness_n_m2": 1000.0,
                          "stiffness_ratio": 5.0, "inertia_ratio": 1.0},
                "amplitude_m": 1e-3,
                "frequencies_rad_s": {"min": 1.0 / scale, "max": 3.5 / scale, "count": 3},
                "duration_s": 20.0 * scale,
                "time_step_s": 0.05 * scale,
                "profile": {"kind": "constant_rate", "rate_m_s": 0.005 / scale}
            }),
        ),
    ]
}

/// A validator of `#/components/schemas/{name}` of the generated document.
fn validator(name: &str) -> jsonschema::Validator {
    let mut doc = serde_json::to_value(openapi()).unwrap();
    doc["$ref"] = json!(format!("#/components/schemas/{name}"));
    doc["$schema"] = json!("https://json-schema.org/draft/2020-12/schema");
    jsonschema::draft202012::new(&doc).expect("the document's schemas compile")
}

fn assert_valid(v: &jsonschema::Validator, what: &str, instance: &Value) {
    let errors: Vec<String> = v
        .iter_errors(instance)
        .take(5)
        .map(|e| format!("{} at {}", e, e.instance_path()))
        .collect();
    assert!(
        errors.is_empty(),
        "{what} does not match the schema: {errors:#?}"
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn every_finished_job_matches_the_published_job_view() {
    let (app, queue) = app();
    let job_view = validator("JobView");
    let accepted = validator("JobAccepted");
    let list = validator("JobList");
    let mut ids = Vec::new();
    for (kind, request) in requests() {
        let (status, v) = call(
            &app,
            "POST",
            "/api/v1/jobs",
            Some(&json!({"kind": kind, "request": request})),
        )
        .await;
        assert_eq!(status, StatusCode::ACCEPTED, "{kind}: {v}");
        assert_valid(&accepted, "JobAccepted", &v);
        ids.push((kind, v["id"].as_i64().unwrap()));
    }
    let batch: Vec<Value> = requests()
        .into_iter()
        .map(|(kind, request)| json!({"kind": kind, "request": request}))
        .collect();
    let (status, v) = call(
        &app,
        "POST",
        "/api/v1/jobs",
        Some(&json!({"kind": "batch", "request": batch})),
    )
    .await;
    assert_eq!(status, StatusCode::ACCEPTED, "{v}");
    ids.push(("batch", v["id"].as_i64().unwrap()));
    let q = queue.clone();
    tokio::task::spawn_blocking(move || while try_execute_next(&q).unwrap().is_some() {})
        .await
        .unwrap();
    for (kind, id) in &ids {
        let (status, v) = call(&app, "GET", &format!("/api/v1/jobs/{id}"), None).await;
        assert_eq!(status, StatusCode::OK);
        assert_eq!(v["status"], "done", "{kind}: {v}");
        assert!(v["result"].is_object(), "{kind}");
        assert_valid(&job_view, &format!("the finished {kind} job {id}"), &v);
    }
    // Every item of the batch answered.
    let (_, v) = call(
        &app,
        "GET",
        &format!("/api/v1/jobs/{}", ids.last().unwrap().1),
        None,
    )
    .await;
    for item in v["result"]["items"].as_array().unwrap() {
        assert!(item["result"].is_object(), "{item}");
    }
    // A failure and a cancellation match too, and so does the list.
    let bad = json!({"kind": "critical", "request": with(string(50), json!({"profile": {"kind": "constant_rate", "rate_m_s": 10.0}}))});
    let (_, v) = call(&app, "POST", "/api/v1/jobs", Some(&bad)).await;
    let (status, v) = call(&app, "DELETE", &format!("/api/v1/jobs/{}", v["id"]), None).await;
    assert_eq!(status, StatusCode::OK);
    assert_eq!(v["status"], "cancelled");
    assert_valid(&job_view, "a cancelled job", &v);
    let (_, v) = call(&app, "GET", "/api/v1/jobs", None).await;
    assert_valid(&list, "the job list", &v);
    assert_eq!(queue.store.status(ids[0].1).unwrap(), Some(JobStatus::Done));
}

/// A result of the wrong shape is refused by the schema: the test can fail.
#[test]
fn the_job_view_schema_refuses_a_foreign_result() {
    let job_view = validator("JobView");
    let v = json!({"id": 1, "kind": "chart", "status": "done", "progress": 1.0, "attempts": 1,
                   "created_at": "2026-01-01T00:00:00Z", "started_at": null, "finished_at": null,
                   "error": null, "result": {"series": "not a list"}});
    assert!(!job_view.is_valid(&v));
}

#[test]
fn creating_a_job_links_to_getting_and_deleting_it() {
    let doc = serde_json::to_value(openapi()).unwrap();
    for status in ["200", "202"] {
        let links = &doc["paths"]["/api/v1/jobs"]["post"]["responses"][status]["links"];
        assert_eq!(
            links["GetJob"]["operationId"], "get_job",
            "{status}: {links}"
        );
        assert_eq!(links["DeleteJob"]["operationId"], "delete_job");
        assert_eq!(links["GetJob"]["parameters"]["id"], "$response.body#/id");
    }
    let security = &doc["components"]["securitySchemes"]["bearer"];
    assert_eq!(security["scheme"], "bearer", "{security}");
    assert!(doc["paths"]["/api/v1/jobs/{id}"]["get"]["responses"]["401"].is_object());
}
