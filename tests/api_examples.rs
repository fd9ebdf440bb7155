//! Every POST route's request example in the generated OpenAPI document
//! (what `/docs` "Try it out" sends) succeeds as is: 2xx, and a job
//! example's job finishes.

use std::path::Path;
use std::sync::Arc;

use axum::body::Body;
use axum::http::{Request, header};
use http_body_util::BodyExt;
use serde_json::Value;
use tetherplan::api::{self, AppState};
use tetherplan::config::Limits;
use tetherplan::jobs::store::JobStore;
use tetherplan::jobs::{JobQueue, try_execute_next};
use tower::ServiceExt;

#[tokio::test]
async fn every_openapi_request_example_succeeds_as_is() {
    let queue = Arc::new(JobQueue::new(
        JobStore::open_in_memory().unwrap(),
        2,
        Limits::default(),
    ));
    let app = api::router(AppState::new(queue.clone()), Path::new("static"));
    let doc = serde_json::to_value(api::openapi::openapi()).unwrap();
    let mut posted = 0;
    // A flight's routes name the flight the creation's example made
    // (`{id}`); ending it comes last; routes without a body post none.
    let mut paths: Vec<(&String, &Value)> = doc["paths"].as_object().unwrap().iter().collect();
    paths.sort_by_key(|(p, _)| p.ends_with("/end"));
    let mut flight: Option<i64> = None;
    for (path, ops) in paths {
        let Some(op) = ops.get("post") else { continue };
        let uri = match flight {
            Some(id) => path.replace("{id}", &id.to_string()),
            None => path.clone(),
        };
        let req = Request::builder().method("POST").uri(uri.as_str());
        let req = if op.get("requestBody").is_none() {
            req.body(Body::empty()).unwrap()
        } else {
            let media = &op["requestBody"]["content"]["application/json"];
            let example = media
                .get("example")
                .unwrap_or_else(|| panic!("POST {path} has no request example"));
            req.header(header::CONTENT_TYPE, "application/json")
                .body(Body::from(serde_json::to_vec(example).unwrap()))
                .unwrap()
        };
        let resp = app.clone().oneshot(req).await.unwrap();
        let status = resp.status();
        let bytes = resp.into_body().collect().await.unwrap().to_bytes();
        assert!(
            status.is_success(),
            "POST {path} with its example: {status} {}",
            String::from_utf8_lossy(&bytes)
        );
        let body: Value = serde_json::from_slice(&bytes).unwrap();
        if path == "/api/v1/flights" {
            flight = body["id"].as_i64();
        }
        if path.ends_with("/jobs") {
            // the job it queued runs to completion
            let id = body["id"].as_i64().unwrap_or_else(|| panic!("{body}"));
            tokio::task::spawn_blocking({
                let queue = queue.clone();
                move || while try_execute_next(&queue).unwrap().is_some() {}
            })
            .await
            .unwrap();
            let req = Request::builder()
                .uri(format!("/api/v1/jobs/{id}"))
                .body(Body::empty())
                .unwrap();
            let resp = app.clone().oneshot(req).await.unwrap();
            let bytes = resp.into_body().collect().await.unwrap().to_bytes();
            let job: Value = serde_json::from_slice(&bytes).unwrap();
            assert_eq!(job["status"], "done", "{job}");
        }
        posted += 1;
    }
    assert!(posted >= 7, "only {posted} POST routes");
}
