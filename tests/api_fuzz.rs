//! Property test: random JSON thrown at every POST route, and valid
//! requests with one field replaced by a random value, never give a 5xx
//! and always give the one error body (or a real answer).

use std::time::Duration;

use axum::Router;
use axum::body::Body;
use axum::http::{Request, header};
use http_body_util::BodyExt;
use proptest::prelude::*;
use serde_json::{Value, json};
use tetherplan::config::Limits;
use tetherplan::contract::dto::ErrorBody;
use tower::ServiceExt;

mod common;
use common::{paths, replace};

fn app() -> Router {
    let limits = Limits {
        solve_timeout: Duration::from_secs(60),
        ..Limits::default()
    };
    common::app_with(1, limits).0
}

const ROUTES: [&str; 5] = [
    "/api/v1/stability",
    "/api/v1/critical",
    "/api/v1/safe-rate",
    "/api/v1/charts",
    "/api/v1/jobs",
];

/// Transient routes: random JSON only (a mutated valid body can ask for a
/// legitimately long run, which is the job queue's business, not a fuzz case).
const TRANSIENT_ROUTES: [&str; 2] = ["/api/v1/simulate", "/api/v1/frequency-response"];

fn valid(route: &str) -> Value {
    let mut v = json!({
        "cable": {"mass_per_length_kg_m": 0.078},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
        "model": {"elements": 20}
    });
    let extra = match route {
        "/api/v1/stability" => json!({"state": {"length_m": 500.0, "rate_m_s": 10.0}, "modes": 3}),
        "/api/v1/critical" => {
            json!({"profile": {"kind": "constant_rate", "rate_m_s": 10.0, "target_length_m": 2000.0}})
        }
        "/api/v1/safe-rate" => json!({"target_elevation_m": 1200.0}),
        "/api/v1/charts" => {
            json!({"rates_m_s": {"min": 1.0, "max": 100.0, "count": 20}, "net_buoyancies_n": [1000.0]})
        }
        _ => return json!({"kind": "critical", "request": valid("/api/v1/critical")}),
    };
    for (k, x) in extra.as_object().unwrap() {
        v[k] = x.clone();
    }
    v
}

fn json_value() -> impl Strategy<Value = Value> {
    let leaf = prop_oneof![
        Just(Value::Null),
        any::<bool>().prop_map(Value::from),
        any::<i64>().prop_map(Value::from),
        (-5i64..3000).prop_map(Value::from),
        any::<f64>()
            .prop_filter("finite", |f| f.is_finite())
            .prop_map(Value::from),
        (-1e4f64..1e4).prop_map(Value::from),
        ".{0,12}".prop_map(Value::from),
        prop_oneof![
            Just("constant_rate"),
            Just("constant_acceleration"),
            Just("chart"),
            Just("batch"),
            Just("linear_string")
        ]
        .prop_map(Value::from),
    ];
    leaf.prop_recursive(3, 24, 6, |inner| {
        prop_oneof![
            prop::collection::vec(inner.clone(), 0..6).prop_map(Value::Array),
            prop::collection::btree_map(
                prop_oneof![
                    Just("cable".to_string()),
                    Just("aerostat".to_string()),
                    Just("model".to_string()),
                    Just("kind".to_string()),
                    Just("request".to_string()),
                    Just("elements".to_string()),
                    "[a-z_]{1,10}",
                ],
                inner,
                0..5
            )
            .prop_map(|m| Value::Object(m.into_iter().collect())),
        ]
    })
}

fn check(
    rt: &tokio::runtime::Runtime,
    app: &Router,
    route: &str,
    body: Vec<u8>,
) -> Result<(), TestCaseError> {
    let shown = String::from_utf8_lossy(&body).into_owned();
    let (status, text) = rt.block_on(async {
        let req = Request::post(route)
            .header(header::CONTENT_TYPE, "application/json")
            .body(Body::from(body))
            .unwrap();
        let resp = app.clone().oneshot(req).await.unwrap();
        let status = resp.status();
        let bytes = resp.into_body().collect().await.unwrap().to_bytes();
        (status, String::from_utf8_lossy(&bytes).into_owned())
    });
    prop_assert!(status.as_u16() < 500, "{route} {shown} → {status} {text}");
    if status.is_success() {
        prop_assert!(
            serde_json::from_str::<Value>(&text).is_ok(),
            "{route}: not JSON: {text}"
        );
    } else {
        let e: Result<ErrorBody, _> = serde_json::from_str(&text);
        prop_assert!(
            e.is_ok(),
            "{route} {shown} → {status}: not the error body: {text}"
        );
        prop_assert!(!e.unwrap().error.message.is_empty());
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn random_json_never_gives_a_5xx(route in prop::sample::select(ROUTES.to_vec()), value in json_value()) {
        let rt = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
        check(&rt, &app(), route, serde_json::to_vec(&value).unwrap())?;
    }

    #[test]
    fn random_json_at_the_transient_routes_never_gives_a_5xx(
        route in prop::sample::select(TRANSIENT_ROUTES.to_vec()),
        value in json_value(),
    ) {
        let rt = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
        check(&rt, &app(), route, serde_json::to_vec(&value).unwrap())?;
    }

    #[test]
    fn a_valid_request_with_one_field_replaced_never_gives_a_5xx(
        route in prop::sample::select(ROUTES.to_vec()),
        pick in any::<prop::sample::Index>(),
        value in json_value(),
    ) {
        let mut body = valid(route);
        let mut all = vec![];
        paths(&body, vec![], &mut all);
        let path = pick.get(&all).clone();
        replace(&mut body, &path, value);
        let rt = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
        check(&rt, &app(), route, serde_json::to_vec(&body).unwrap())?;
    }

    #[test]
    fn random_bytes_never_give_a_5xx(route in prop::sample::select(ROUTES.to_vec()), bytes in prop::collection::vec(any::<u8>(), 0..64)) {
        let rt = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
        check(&rt, &app(), route, bytes)?;
    }
}

#[test]
fn the_valid_bodies_are_valid() {
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .unwrap();
    let app = app();
    for route in ROUTES {
        let status = rt.block_on(async {
            let req = Request::post(route)
                .header(header::CONTENT_TYPE, "application/json")
                .body(Body::from(serde_json::to_vec(&valid(route)).unwrap()))
                .unwrap();
            app.clone().oneshot(req).await.unwrap().status()
        });
        assert!(status.is_success(), "{route}: {status}");
    }
}
