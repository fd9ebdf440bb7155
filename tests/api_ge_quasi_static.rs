//! `POST /api/v1/critical` with `"method": "quasi_static"` (GE model,
//! constant rate): the fast quasi-static GE critical time beside the
//! marching answer, through the router (tower oneshot):
//!
//! * h* within 2 % of the marching answer for the same body (Table 7.1
//!   data, 20 elements, 40 m/s), `t* = (h* − L0)/v`, the method stated;
//! * refused (422 naming the field) for a profile other than a constant
//!   rate, with a perturbation, with time-stepping numerics, or an
//!   unknown method.

use axum::Router;
use axum::http::StatusCode;
use serde_json::{Value, json};

mod common;

fn app() -> Router {
    common::app().0
}

async fn post(app: &Router, body: &Value) -> (StatusCode, Value) {
    common::post(app, "/api/v1/critical", body).await
}

fn body(method: Option<&str>) -> Value {
    let mut b = json!({
        "cable": {"mass_per_length_kg_m": 0.078},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
        "initial_length_m": 1.0,
        "model": {"kind": "geometrically_exact", "elements": 20, "bending_stiffness_n_m2": 1000.0,
                  "stiffness_ratio": 1e5, "inertia_ratio": 1.0},
        "profile": {"kind": "constant_rate", "rate_m_s": 40.0}
    });
    if let Some(m) = method {
        b["method"] = json!(m);
    }
    b
}

#[tokio::test]
async fn quasi_static_matches_the_marching_answer() {
    let app = app();
    let (s1, marched) = post(&app, &body(None)).await;
    let (s2, qs) = post(&app, &body(Some("quasi_static"))).await;
    assert_eq!((s1, s2), (StatusCode::OK, StatusCode::OK), "{marched} {qs}");
    assert_eq!(marched["method"], "marching");
    assert_eq!(qs["method"], "quasi_static");
    assert_eq!(qs["onset"], "during");
    let (hm, hq) = (
        marched["max_elevation_m"].as_f64().unwrap(),
        qs["max_elevation_m"].as_f64().unwrap(),
    );
    println!("h* marching {hm:.2} m, quasi-static {hq:.2} m");
    assert!((hq / hm - 1.0).abs() < 0.02);
    let t = qs["critical_time_s"].as_f64().unwrap();
    assert!((t - (hq - 1.0) / 40.0).abs() < 1e-9);
    let br = qs["quasi_static_bracket_m"].as_array().unwrap();
    assert!(br[0].as_f64().unwrap() < hq && hq < br[1].as_f64().unwrap());
    assert_eq!(qs["steps"], 0);
}

#[tokio::test]
async fn quasi_static_refuses_what_it_cannot_answer() {
    let app = app();
    let mut accel = body(Some("quasi_static"));
    accel["profile"] = json!({"kind": "constant_acceleration", "acceleration_m_s2": 0.5});
    let mut pushed = body(Some("quasi_static"));
    pushed["perturbation"] = json!({"force_n": 400.0});
    let mut stepped = body(Some("quasi_static"));
    stepped["numerics"] = json!({"time_step_s": 0.01});
    for (b, field) in [
        (accel, "method"),
        (pushed, "perturbation"),
        (stepped, "numerics"),
    ] {
        let (s, v) = post(&app, &b).await;
        assert_eq!(s, StatusCode::UNPROCESSABLE_ENTITY, "{v}");
        assert!(v.to_string().contains(field), "{v}");
    }
    let (s, v) = post(&app, &body(Some("leapfrog"))).await;
    assert!(s.is_client_error(), "{v}");
    assert!(v.to_string().contains("method"), "{v}");
}
