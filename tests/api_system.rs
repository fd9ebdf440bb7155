//! One system, described once (SPEC §9, issue 20): every route that takes
//! a system accepts the same full §9 body (cable with its diameter and
//! rating, aerostat with its drag data, the air, the winch, the safety
//! factor and lift reserve); the plan's old names are refused naming
//! their new place; a named system is stored, used with an override,
//! listed, deleted and invisible to another token, on the synchronous
//! routes and in jobs; a list and `{min, max, count}` give the same
//! envelope byte for byte; the presets are listed with their sources.

use axum::http::StatusCode;
use serde_json::{Value, json};

mod common;
use common::{post, post_text, send, send_as, with};

/// The full system, in calm air (zero wind everywhere).
fn system() -> Value {
    json!({
        "cable": {"mass_per_length_kg_m": 0.078, "diameter_m": 0.006,
                  "normal_drag_coefficient_nondim": 1.2, "breaking_strength_n": 30000.0},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0, "drag_coefficient_nondim": 0.3,
                     "reference_area_m2": 20.0, "lift_coefficient_nondim": 0.0,
                     "added_mass_coefficient_nondim": 0.5},
        "wind": {"air_density_kg_m3": 1.225, "flow": {"kind": "uniform", "speed_m_s": 0.0}},
        "winch": {"max_rate_m_s": 40.0, "max_acceleration_m_s2": 2.0},
        "initial_length_m": 1.0,
        "gravity_m_s2": 9.81,
        "required_safety_factor_nondim": 5.0,
        "lift_reserve_nondim": 0.05
    })
}

const GE_MODEL: &str = r#"{"kind": "geometrically_exact", "elements": 10, "bending_stiffness_n_m2": 1000.0,
    "stiffness_ratio": 1e5, "inertia_ratio": 1.0}"#;

/// One request per kind: the full system and the kind's own fields.
fn requests() -> Vec<(&'static str, Value)> {
    let u = json!({"samples": 8, "seed": 3, "inputs": [
        {"field": "aerostat.net_buoyancy_n", "distribution": "normal", "mean": 1000.0, "std_dev": 20.0}]});
    let ge: Value = serde_json::from_str(GE_MODEL).unwrap();
    vec![
        (
            "/api/v1/stability",
            json!({"state": {"length_m": 500.0, "rate_m_s": 10.0}, "modes": 3}),
        ),
        (
            "/api/v1/critical",
            json!({"profile": {"kind": "constant_rate", "rate_m_s": 10.0}}),
        ),
        ("/api/v1/safe-rate", json!({"target_elevation_m": 1200.0})),
        ("/api/v1/charts", json!({"rates_m_s": [5.0, 10.0, 20.0]})),
        (
            "/api/v1/simulate",
            json!({"profile": {"kind": "constant_rate", "rate_m_s": 1.0}, "duration_s": 2.0,
                   "samples": 10, "initial": {"kind": "shape", "tip_deflection_m": 0.1}}),
        ),
        (
            "/api/v1/frequency-response",
            json!({"profile": {"kind": "constant_rate", "rate_m_s": 1.0}, "duration_s": 2.0,
                   "samples": 5, "aero": {"radius_m": 0.5}, "wind_amplitude_m_s": 1.0,
                   "frequencies_rad_s": {"min": 1.0, "max": 2.0, "count": 2}}),
        ),
        ("/api/v1/equilibrium", json!({"tether_length_m": 1000.0})),
        (
            "/api/v1/envelope",
            json!({"tether_lengths_m": [200.0, 600.0, 1000.0]}),
        ),
        (
            "/api/v1/plan",
            json!({"target_elevation_m": 900.0, "samples": 21}),
        ),
        (
            "/api/v1/bands",
            json!({"rates_m_s": [10.0, 20.0], "uncertainty": u}),
        ),
        (
            "/api/v1/plan/bands",
            json!({"target_elevation_m": 900.0, "samples": 21, "uncertainty": u}),
        ),
        (
            "/api/v1/envelope/bands",
            json!({"tether_lengths_m": [200.0, 600.0], "uncertainty": u}),
        ),
        (
            "/api/v1/stability",
            json!({"model": ge, "state": {"length_m": 200.0, "rate_m_s": 5.0}, "modes": 2}),
        ),
    ]
}

#[tokio::test]
async fn every_route_that_takes_a_system_accepts_the_whole_system() {
    let (app, _) = common::app();
    for (path, own) in requests() {
        let body = with(system(), own);
        let (status, r) = post(&app, path, &body).await;
        assert_eq!(status, StatusCode::OK, "{path}: {r}");
    }
    // The same bodies as jobs, validated at submission by the same rules.
    let kinds = [
        ("stability", 0),
        ("critical", 1),
        ("safe_rate", 2),
        ("chart", 3),
        ("equilibrium", 6),
        ("envelope", 7),
        ("plan", 8),
    ];
    let reqs = requests();
    for (kind, i) in kinds {
        let body = json!({"kind": kind, "request": with(system(), reqs[i].1.clone())});
        let (status, r) = post(&app, "/api/v1/jobs", &body).await;
        assert_eq!(status, StatusCode::ACCEPTED, "{kind}: {r}");
    }
}

#[tokio::test]
async fn calm_air_analyses_refuse_a_wind_naming_the_flow() {
    let (app, _) = common::app();
    let windy = json!({"wind": {"flow": {"kind": "uniform", "speed_m_s": 6.0}}});
    for (path, own) in requests() {
        if matches!(
            path,
            "/api/v1/equilibrium"
                | "/api/v1/envelope"
                | "/api/v1/plan"
                | "/api/v1/plan/bands"
                | "/api/v1/envelope/bands"
        ) {
            continue;
        }
        let body = with(with(system(), own), windy.clone());
        let (status, r) = post(&app, path, &body).await;
        assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{path}: {r}");
        assert_eq!(r["error"]["field"], "wind.flow", "{path}: {r}");
        let m = r["error"]["message"].as_str().unwrap();
        assert!(m.contains("calm air"), "{path}: {m}");
    }
    // The bounds of the schema hold in every route: a breaking strength of 0.
    for (path, own) in requests() {
        let mut body = with(system(), own);
        body["cable"]["breaking_strength_n"] = json!(0.0);
        let (status, r) = post(&app, path, &body).await;
        assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{path}: {r}");
        assert_eq!(
            r["error"]["field"], "cable.breaking_strength_n",
            "{path}: {r}"
        );
    }
}

#[tokio::test]
async fn the_plans_old_names_are_refused_naming_the_new_place() {
    let (app, _) = common::app();
    let base = with(system(), json!({"target_elevation_m": 900.0}));
    for (old, new) in tetherplan::contract::system::MOVED {
        let mut body = base.clone();
        let (head, leaf) = old.split_once('.').unwrap();
        if body.get(head).is_none() {
            body[head] = json!({});
        }
        body[head][leaf] = if *old == "wind.shape" {
            json!({"kind": "uniform"})
        } else {
            json!(5.0)
        };
        let (status, r) = post(&app, "/api/v1/plan", &body).await;
        assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{old}: {r}");
        assert_eq!(r["error"]["field"], *old);
        assert_eq!(
            r["error"]["message"],
            format!("{old}: moved to {new}"),
            "{old}"
        );
        // A job is refused the same way at submission.
        let (status, r) = post(
            &app,
            "/api/v1/jobs",
            &json!({"kind": "plan", "request": body}),
        )
        .await;
        assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{old}: {r}");
        assert!(
            r["error"]["message"].as_str().unwrap().contains(new),
            "{old}: {r}"
        );
    }
    // The log law's `reference_speed_m_s` is still accepted for `speed_m_s`.
    let mut a = with(system(), json!({"tether_length_m": 800.0}));
    a["wind"]["flow"] = json!({"kind": "log_law", "speed_m_s": 6.0, "roughness_length_m": 0.03});
    let mut b = a.clone();
    b["wind"]["flow"] =
        json!({"kind": "log_law", "reference_speed_m_s": 6.0, "roughness_length_m": 0.03});
    let (sa, ta) = post_text(&app, "/api/v1/equilibrium", &a).await;
    let (sb, tb) = post_text(&app, "/api/v1/equilibrium", &b).await;
    assert_eq!((sa, sb), (StatusCode::OK, StatusCode::OK), "{ta} {tb}");
    assert_eq!(ta, tb);
}

#[tokio::test]
async fn the_ge_charts_wind_is_the_systems_flow_and_its_old_form_is_refused() {
    let (app, _) = common::app();
    let mut ge: Value = serde_json::from_str(GE_MODEL).unwrap();
    // the chart takes its stiffness ratios as a list
    ge.as_object_mut().unwrap().remove("stiffness_ratio");
    let chart = |wind: Value| {
        let mut body = with(
            system(),
            json!({"model": ge, "stiffness_ratios": [1e5], "net_buoyancies_n": [1000.0],
                   "rates_m_s": [40.0], "numerics": {"horizon_s": 20.0}}),
        );
        body["wind"] = wind;
        body
    };
    // The system's calm wind: the still-air chart.
    let (status, calm) = post(&app, "/api/v1/charts", &chart(system()["wind"].clone())).await;
    assert_eq!(status, StatusCode::OK, "{calm}");
    assert!(
        calm["series"][0]["wind_amplitude_nondim"].is_null(),
        "{calm}"
    );
    // A wind on `wind.flow`; a power law of exponent 0 is the same uniform wind.
    let flow = |f: Value| json!({"air_density_kg_m3": 1.12, "flow": f, "amplitudes_nondim": [0.0]});
    let (status, windy) = post(
        &app,
        "/api/v1/charts",
        &chart(flow(json!({"kind": "uniform", "speed_m_s": 5.0}))),
    )
    .await;
    assert_eq!(status, StatusCode::OK, "{windy}");
    assert_eq!(windy["series"][0]["wind_amplitude_nondim"], 0.0, "{windy}");
    let (status, power) = post(
        &app,
        "/api/v1/charts",
        &chart(flow(
            json!({"kind": "power_law", "coefficient_m_s": 5.0, "exponent_nondim": 0.0,
                           "reference_height_m": 10.0}),
        )),
    )
    .await;
    assert_eq!(status, StatusCode::OK, "{power}");
    assert_eq!(power["series"], windy["series"]);
    // The drag model takes the aerostat's coefficient: without one it is
    // refused naming the aerostat's field.
    let mut drag = chart(flow(json!({"kind": "uniform", "speed_m_s": 5.0})));
    drag["wind"]["force_model"] = json!({"kind": "drag"});
    let (status, a) = post(&app, "/api/v1/charts", &drag).await;
    assert_eq!(status, StatusCode::OK, "{a}");
    drag["aerostat"]
        .as_object_mut()
        .unwrap()
        .remove("drag_coefficient_nondim");
    let (status, b) = post(&app, "/api/v1/charts", &drag).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{b}");
    assert_eq!(
        b["error"]["field"], "aerostat.drag_coefficient_nondim",
        "{b}"
    );
    // The old shape is refused naming the new place (also as a job).
    for (old, wind, new) in [
        (
            "wind.profile",
            json!({"profile": {"kind": "uniform", "speed_m_s": 5.0}, "force_model": {"kind": "thesis"}}),
            "wind.flow",
        ),
        (
            "wind.force_model.drag_coefficient",
            json!({"flow": {"kind": "uniform", "speed_m_s": 5.0},
                   "force_model": {"kind": "drag", "drag_coefficient": 0.5}}),
            "aerostat.drag_coefficient_nondim",
        ),
        (
            "wind.force_model.reference_area_m2",
            json!({"flow": {"kind": "uniform", "speed_m_s": 5.0},
                   "force_model": {"kind": "drag", "reference_area_m2": 2.0}}),
            "aerostat.reference_area_m2",
        ),
    ] {
        let body = chart(wind);
        let (status, r) = post(&app, "/api/v1/charts", &body).await;
        assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{old}: {r}");
        assert_eq!(r["error"]["field"], old, "{r}");
        let m = r["error"]["message"].as_str().unwrap();
        assert!(m.contains(&format!("moved to {new}")), "{old}: {m}");
        let (status, r) = post(
            &app,
            "/api/v1/jobs",
            &json!({"kind": "chart", "request": body}),
        )
        .await;
        assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{old}: {r}");
        assert_eq!(r["error"]["field"], format!("request.{old}"), "{r}");
    }
}

fn json_of(text: &str) -> Value {
    serde_json::from_str(text).unwrap_or_else(|_| panic!("not JSON: {text}"))
}

#[tokio::test]
async fn a_named_system_is_stored_used_overridden_listed_and_deleted_per_token() {
    let (app, queue) = common::app_with_tokens(&["alpha", "beta"]);
    let stored = json!({
        "cable": {"mass_per_length_kg_m": 0.078, "diameter_m": 0.006},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0, "drag_coefficient_nondim": 0.3,
                     "reference_area_m2": 20.0},
        "winch": {"max_rate_m_s": 40.0, "max_acceleration_m_s2": 2.0}
    });
    let (status, text) =
        send_as(&app, "alpha", "PUT", "/api/v1/systems/rig-1", Some(&stored)).await;
    assert_eq!(status, StatusCode::CREATED, "{text}");
    assert_eq!(json_of(&text)["system"], stored);
    let (status, _) = send_as(&app, "alpha", "PUT", "/api/v1/systems/rig-1", Some(&stored)).await;
    assert_eq!(status, StatusCode::OK, "a second PUT replaces");

    // Used: the safe rate to 1200 m is the closed form's √(F/ρA − g h),
    // from above within the converged tolerance (SPEC §5: 32.381 m/s).
    let rate = |text: &str| json_of(text)["max_rate_m_s"].as_f64().unwrap();
    let req = json!({"system": "rig-1", "target_elevation_m": 1200.0});
    let (status, text) = send_as(&app, "alpha", "POST", "/api/v1/safe-rate", Some(&req)).await;
    assert_eq!(status, StatusCode::OK, "{text}");
    let closed = |f: f64| (f / 0.078 - 9.81 * 1200.0).sqrt();
    let v1 = rate(&text);
    assert!((v1 / closed(1000.0) - 1.0).abs() < 2e-3, "{v1}");
    // Overridden: 1500 N instead of 1000 N (the rest of the aerostat kept).
    let over = with(req.clone(), json!({"aerostat": {"net_buoyancy_n": 1500.0}}));
    let (status, text) = send_as(&app, "alpha", "POST", "/api/v1/safe-rate", Some(&over)).await;
    assert_eq!(status, StatusCode::OK, "{text}");
    let v2 = rate(&text);
    assert!(
        (v2 / closed(1500.0) - 1.0).abs() < 2e-3,
        "{v2} vs {}",
        closed(1500.0)
    );
    assert!(v2 > 2.5 * v1, "{v1} {v2}");
    // The answer's inputs echo the resolved system (the plan).
    let plan = json!({"system": "rig-1", "target_elevation_m": 900.0, "samples": 21,
                      "wind": {"flow": {"kind": "uniform", "speed_m_s": 6.0}}});
    let (status, text) = send_as(&app, "alpha", "POST", "/api/v1/plan", Some(&plan)).await;
    assert_eq!(status, StatusCode::OK, "{text}");
    let r = json_of(&text);
    assert_eq!(r["inputs"]["cable"]["diameter_m"], 0.006);
    assert_eq!(r["inputs"]["aerostat"]["drag_coefficient_nondim"], 0.3);
    assert_eq!(r["go"], true, "{}", r["reason"]);
    assert!(r["wind"]["target_length_m"].as_f64().unwrap() > 900.0);

    // A job is resolved at submission and answers what the route answers.
    let (status, text) = send_as(
        &app,
        "alpha",
        "POST",
        "/api/v1/jobs",
        Some(&json!({"kind": "safe_rate", "request": over})),
    )
    .await;
    assert_eq!(status, StatusCode::ACCEPTED, "{text}");
    let id = json_of(&text)["id"].as_i64().unwrap();
    let q = queue.clone();
    tokio::task::spawn_blocking(move || tetherplan::jobs::try_execute_next(&q).unwrap().unwrap())
        .await
        .unwrap();
    let (_, text) = send_as(&app, "alpha", "GET", &format!("/api/v1/jobs/{id}"), None).await;
    let job = json_of(&text);
    assert_eq!(job["status"], "done", "{job}");
    assert_eq!(job["result"]["max_rate_m_s"].as_f64().unwrap(), v2);

    // Listed for its token only.
    let (_, text) = send_as(&app, "alpha", "GET", "/api/v1/systems", None).await;
    let list = json_of(&text);
    assert_eq!(list["systems"].as_array().unwrap().len(), 1, "{list}");
    assert_eq!(list["systems"][0]["name"], "rig-1");
    assert!(list["systems"][0]["updated_at"].is_string());
    let (_, text) = send_as(&app, "beta", "GET", "/api/v1/systems", None).await;
    assert_eq!(json_of(&text)["systems"], json!([]));
    let (status, _) = send_as(&app, "beta", "GET", "/api/v1/systems/rig-1", None).await;
    assert_eq!(status, StatusCode::NOT_FOUND);
    let (status, text) = send_as(&app, "beta", "POST", "/api/v1/safe-rate", Some(&req)).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{text}");
    assert_eq!(json_of(&text)["error"]["field"], "system");
    let (status, _) = send_as(&app, "beta", "DELETE", "/api/v1/systems/rig-1", None).await;
    assert_eq!(status, StatusCode::NOT_FOUND);

    // Deleted: gone, and a request naming it is refused on `system`.
    let (status, _) = send_as(&app, "alpha", "DELETE", "/api/v1/systems/rig-1", None).await;
    assert_eq!(status, StatusCode::NO_CONTENT);
    let (status, _) = send_as(&app, "alpha", "GET", "/api/v1/systems/rig-1", None).await;
    assert_eq!(status, StatusCode::NOT_FOUND);
    let (status, text) = send_as(&app, "alpha", "POST", "/api/v1/safe-rate", Some(&req)).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{text}");
    let e = json_of(&text);
    assert_eq!(e["error"]["field"], "system");
    assert!(e["error"]["message"].as_str().unwrap().contains("rig-1"));
    let (status, text) = send_as(
        &app,
        "alpha",
        "POST",
        "/api/v1/jobs",
        Some(&json!({"kind": "safe_rate", "request": req})),
    )
    .await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{text}");
    assert_eq!(json_of(&text)["error"]["field"], "request.system");

    // A stored system is checked like a request's; names are checked.
    let bad = json!({"cable": {"breaking_strength_n": -1.0}});
    let (status, text) = send_as(&app, "alpha", "PUT", "/api/v1/systems/x", Some(&bad)).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{text}");
    assert_eq!(
        json_of(&text)["error"]["field"],
        "cable.breaking_strength_n"
    );
    let (status, text) =
        send_as(&app, "alpha", "PUT", "/api/v1/systems/a%20b", Some(&stored)).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{text}");
    assert_eq!(json_of(&text)["error"]["field"], "name");
}

#[tokio::test]
async fn at_most_100_systems_per_token() {
    let (app, _) = common::app_with_tokens(&["alpha", "beta"]);
    let s = json!({"aerostat": {"net_buoyancy_n": 1000.0}});
    for i in 0..100 {
        let (status, t) = send_as(
            &app,
            "alpha",
            "PUT",
            &format!("/api/v1/systems/s{i}"),
            Some(&s),
        )
        .await;
        assert_eq!(status, StatusCode::CREATED, "{i}: {t}");
    }
    let (status, t) = send_as(&app, "alpha", "PUT", "/api/v1/systems/s100", Some(&s)).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{t}");
    assert_eq!(json_of(&t)["error"]["code"], "too_many_systems");
    // Replacing one is not a new one; another token has its own 100.
    let (status, _) = send_as(&app, "alpha", "PUT", "/api/v1/systems/s7", Some(&s)).await;
    assert_eq!(status, StatusCode::OK);
    let (status, _) = send_as(&app, "beta", "PUT", "/api/v1/systems/s100", Some(&s)).await;
    assert_eq!(status, StatusCode::CREATED);
}

#[tokio::test]
async fn a_list_and_a_range_give_the_same_envelope_byte_for_byte() {
    let (app, _) = common::app();
    let mut base = with(
        system(),
        json!({"payout_rate_m_s": 5.0, "ceiling_m": 2500.0}),
    );
    base["wind"]["flow"] = json!({"kind": "log_law", "speed_m_s": 8.0, "roughness_length_m": 0.03});
    let ranges = with(
        base.clone(),
        json!({"wind_speeds_m_s": {"min": 0.0, "max": 20.0, "count": 5},
               "tether_lengths_m": {"min": 200.0, "max": 1800.0, "count": 5}}),
    );
    let lists = with(
        base.clone(),
        json!({"wind_speeds_m_s": [0.0, 5.0, 10.0, 15.0, 20.0],
               "tether_lengths_m": [200.0, 600.0, 1000.0, 1400.0, 1800.0]}),
    );
    let (s1, t1) = post_text(&app, "/api/v1/envelope", &ranges).await;
    let (s2, t2) = post_text(&app, "/api/v1/envelope", &lists).await;
    assert_eq!((s1, s2), (StatusCode::OK, StatusCode::OK), "{t1} {t2}");
    assert_eq!(t1, t2);
    let r = json_of(&t1);
    assert_eq!(r["points"].as_array().unwrap().len(), 25);
    // Without a wind grid: the flow's own speed, one row.
    let (s, t) = post_text(
        &app,
        "/api/v1/envelope",
        &with(base.clone(), json!({"tether_lengths_m": [200.0, 600.0]})),
    )
    .await;
    assert_eq!(s, StatusCode::OK, "{t}");
    assert_eq!(json_of(&t)["wind_speeds_m_s"], json!([8.0]));
    // The charts the same way.
    let charts = |rates: Value| with(system(), json!({"rates_m_s": rates}));
    let (s1, t1) = post_text(
        &app,
        "/api/v1/charts",
        &charts(json!({"min": 5.0, "max": 25.0, "count": 3})),
    )
    .await;
    let (s2, t2) = post_text(&app, "/api/v1/charts", &charts(json!([5.0, 15.0, 25.0]))).await;
    assert_eq!((s1, s2), (StatusCode::OK, StatusCode::OK), "{t1} {t2}");
    let strip = |t: &str| {
        let mut v = json_of(t);
        v.as_object_mut().unwrap().remove("compute_time_s");
        v.as_object_mut().unwrap().remove("inputs");
        v
    };
    assert_eq!(strip(&t1), strip(&t2));
    // A huge count lands on the lengths' count, a bad list value on its index.
    let (status, r) = post(
        &app,
        "/api/v1/envelope",
        &with(
            base.clone(),
            json!({"tether_lengths_m": {"min": 100.0, "max": 200.0, "count": 1e9}}),
        ),
    )
    .await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{r}");
    assert_eq!(r["error"]["field"], "tether_lengths_m.count", "{r}");
    let (status, r) = post(
        &app,
        "/api/v1/envelope",
        &with(
            base.clone(),
            json!({"tether_lengths_m": {"min": 100.0, "max": 200.0, "count": 1000000000}}),
        ),
    )
    .await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{r}");
    assert_eq!(r["error"]["field"], "tether_lengths_m.count", "{r}");
    let (status, r) = post(
        &app,
        "/api/v1/envelope",
        &with(base, json!({"tether_lengths_m": [100.0, -5.0]})),
    )
    .await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{r}");
    assert_eq!(r["error"]["field"], "tether_lengths_m[1]", "{r}");
}

#[tokio::test]
async fn errors_speak_plain_words() {
    let (app, _) = common::app();
    let mut body = with(system(), json!({"target_elevation_m": 1200.0}));
    body["cable"] = json!({});
    let (status, r) = post(&app, "/api/v1/safe-rate", &body).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{r}");
    assert_eq!(r["error"]["field"], "cable.mass_per_length_kg_m");
    assert_eq!(
        r["error"]["message"],
        "cable.mass_per_length_kg_m: give the mass per length (kg/m), or the density and the area, \
         or a preset with its diameter"
    );
    let mut body = with(system(), json!({"target_elevation_m": 1200.0}));
    body["target_elevation_m"] = Value::Null;
    let (_, r) = post(&app, "/api/v1/safe-rate", &body).await;
    let m = r["error"]["message"].as_str().unwrap();
    assert!(!m.contains("got null"), "{m}");
    assert!(m.contains("needs a number"), "{m}");
    // A grid that is neither a list nor a range says what it takes.
    let (_, r) = post(
        &app,
        "/api/v1/charts",
        &with(system(), json!({"rates_m_s": "fast"})),
    )
    .await;
    assert_eq!(r["error"]["field"], "rates_m_s", "{r}");
    assert!(
        r["error"]["message"]
            .as_str()
            .unwrap()
            .contains("list of numbers"),
        "{r}"
    );
}

#[tokio::test]
async fn the_presets_are_listed_with_their_sources_and_fill_the_system() {
    let (app, _) = common::app();
    let (status, p) = send(&app, "GET", "/api/v1/presets", None).await;
    assert_eq!(status, StatusCode::OK);
    let thesis = p["aerostat"]
        .as_array()
        .unwrap()
        .iter()
        .find(|a| a["name"] == "thesis_table_7_1")
        .expect("the thesis aerostat")
        .clone();
    assert_eq!(thesis["net_buoyancy_n"], 1000.0);
    assert_eq!(thesis["mass_kg"], 10.0);
    assert!(thesis["source"].as_str().unwrap().contains("Table 7.1"));
    assert!(
        p["cable"]
            .as_array()
            .unwrap()
            .iter()
            .any(|c| c["name"] == "dyneema")
    );
    // A named aerostat gives the same answer as its figures written out.
    let by_preset = json!({"cable": {"mass_per_length_kg_m": 0.078},
        "aerostat": {"preset": "thesis_table_7_1"}, "target_elevation_m": 1200.0});
    let written = json!({"cable": {"mass_per_length_kg_m": 0.078},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0}, "target_elevation_m": 1200.0});
    let (s1, a) = post(&app, "/api/v1/safe-rate", &by_preset).await;
    let (s2, b) = post(&app, "/api/v1/safe-rate", &written).await;
    assert_eq!((s1, s2), (StatusCode::OK, StatusCode::OK), "{a} {b}");
    assert!(a["max_rate_m_s"].as_f64().is_some(), "{a}");
    assert_eq!(a["max_rate_m_s"], b["max_rate_m_s"]);
    // In wind its drag data come from its 1 m sphere: C_D 0.47 on π m².
    let eq = json!({"cable": {"mass_per_length_kg_m": 0.078, "diameter_m": 0.006},
        "aerostat": {"preset": "thesis_table_7_1"}, "tether_length_m": 500.0,
        "wind": {"flow": {"kind": "uniform", "speed_m_s": 5.0}}});
    let (status, r) = post(&app, "/api/v1/equilibrium", &eq).await;
    assert_eq!(status, StatusCode::OK, "{r}");
    let drag = 0.5 * 1.225 * 0.47 * std::f64::consts::PI * 25.0;
    assert!(
        (r["aerostat_drag_n"].as_f64().unwrap() - drag).abs() < 1e-9 * drag,
        "{r}"
    );
}
