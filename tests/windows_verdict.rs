//! The windows' ensemble members are judged by `plan_verdict`, which skips
//! what `/plan` only reports: its `go`, durations and altitude must be
//! `/plan`'s bit for bit, in calm air, in uniform, power-law and log-law
//! winds, with gusts, with haul-down forecasts inside, across and past
//! their limits, and for a target out of reach. An ensemble is priced
//! accordingly: a plan per distinct wind of the first member, half a plan
//! per other member's distinct wind.

use serde_json::{Value, json};
use tetherplan::contract::analysis::Analysis;
use tetherplan::contract::plan::{PlanRequest, PlanResponse, PlanVerdict, plan, plan_verdict};
use tetherplan::contract::run::NoProgress;
use tetherplan::contract::windows::{WindowsRequest, prepare};

fn request(wind: Option<Value>, haul_down: Option<Value>) -> PlanRequest {
    let mut b = json!({
        "cable": {"mass_per_length_kg_m": 0.078, "diameter_m": 0.006, "breaking_strength_n": 20000.0},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0, "drag_coefficient_nondim": 0.3,
                     "reference_area_m2": 20.0},
        "winch": {"max_rate_m_s": 10.0, "max_acceleration_m_s2": 1.0},
        "target_elevation_m": 300.0
    });
    if let Some(w) = wind {
        b["wind"] = w;
    }
    if let Some(h) = haul_down {
        b["haul_down"] = h;
    }
    serde_json::from_value(b).unwrap()
}

fn power_law(a: f64, gust: Option<f64>) -> Value {
    let mut w = json!({"flow": {"kind": "power_law", "coefficient_m_s": a, "exponent_nondim": 0.15,
                                "reference_height_m": 10.0}});
    if let Some(g) = gust {
        w["gust"] = json!({"gust_m_s": g});
    }
    w
}

/// A haul-down forecast of `(time, wind, gust)` points; the gusts are
/// given only with a gust limit.
fn haul_down(points: &[(f64, f64, f64)], limit: f64, gust_limit: Option<f64>) -> Value {
    let forecast: Vec<Value> = points
        .iter()
        .map(|&(t, u, g)| match gust_limit {
            Some(_) => json!({"time_s": t, "wind_speed_m_s": u, "gust_m_s": g}),
            None => json!({"time_s": t, "wind_speed_m_s": u}),
        })
        .collect();
    let mut h = json!({"forecast": forecast, "max_operating_wind_m_s": limit});
    if let Some(g) = gust_limit {
        h["max_gust_m_s"] = json!(g);
    }
    h
}

/// `/plan`'s answer seen as a verdict.
fn as_verdict(p: &PlanResponse) -> PlanVerdict {
    PlanVerdict {
        go: p.go,
        duration_s: p.duration_s,
        haul_down_s: p.haul_down.as_ref().map(|h| h.retrieval_duration_s),
        max_altitude_m: p
            .wind
            .as_ref()
            .map_or(p.limits.lift_limit_m, |w| w.reachable_altitude_m),
    }
}

/// The verdict equals `/plan`'s; `shortcut`: a haul-down already past its
/// limit decided it, so no durations are given (and `/plan` is no-go).
fn assert_same(name: &str, r: &PlanRequest, shortcut: bool) -> PlanVerdict {
    let full = plan(r, &NoProgress).unwrap();
    let v = plan_verdict(r, &NoProgress).unwrap();
    let expected = as_verdict(&full);
    if shortcut {
        assert!(!full.go, "{name}: {}", full.reason);
        assert!(full.reason.contains("no-go"), "{name}: {}", full.reason);
        assert_eq!(
            v,
            PlanVerdict {
                go: false,
                duration_s: None,
                haul_down_s: None,
                max_altitude_m: expected.max_altitude_m,
            },
            "{name}"
        );
    } else {
        assert_eq!(v, expected, "{name}: {}", full.reason);
    }
    v
}

#[test]
fn calm_and_steady_winds_without_a_forecast() {
    let calm = assert_same("calm", &request(None, None), false);
    assert!(calm.go && calm.duration_s.unwrap() > 0.0 && calm.haul_down_s.is_none());
    let uniform = json!({"flow": {"kind": "uniform", "speed_m_s": 6.0}});
    let u = assert_same("uniform 6 m/s", &request(Some(uniform), None), false);
    assert!(u.go && u.max_altitude_m < calm.max_altitude_m);
    let log = json!({"flow": {"kind": "log_law", "speed_m_s": 5.0, "reference_height_m": 10.0,
                              "roughness_length_m": 0.03}});
    assert_same("log law", &request(Some(log), None), false);
    let g = assert_same(
        "power law and gust",
        &request(Some(power_law(4.0, Some(6.4))), None),
        false,
    );
    assert!(g.go, "{g:?}");
}

#[test]
fn haul_down_forecasts_inside_across_and_past_their_limits() {
    // At the target (300 m) the power law of 4 m/s at 10 m blows 6.7 m/s.
    let w = || Some(power_law(4.0, Some(6.4)));
    let inside = assert_same(
        "inside",
        &request(w(), Some(haul_down(&[(0.0, 6.7, 10.7)], 12.0, Some(20.0)))),
        false,
    );
    assert!(inside.go && inside.haul_down_s.unwrap() > 0.0);
    // The wind passes 12 m/s at 1 800 s: go, with a deadline.
    let later = assert_same(
        "later",
        &request(
            w(),
            Some(haul_down(
                &[(0.0, 6.7, 10.7), (3600.0, 17.3, 27.7)],
                12.0,
                Some(20.0),
            )),
        ),
        false,
    );
    assert!(later.go);
    // Passing 12 m/s 30 s from now leaves no time to deploy and haul down.
    let soon = assert_same(
        "soon",
        &request(
            w(),
            Some(haul_down(
                &[(0.0, 11.9, 11.9), (30.0, 13.0, 13.0)],
                12.0,
                None,
            )),
        ),
        false,
    );
    assert!(!soon.go && soon.duration_s.is_some());
    // Past the mean limit now, and past the gust limit only.
    assert_same(
        "mean past",
        &request(w(), Some(haul_down(&[(0.0, 12.5, 12.5)], 12.0, None))),
        true,
    );
    assert_same(
        "gust past",
        &request(w(), Some(haul_down(&[(0.0, 6.7, 21.0)], 12.0, Some(20.0)))),
        true,
    );
}

#[test]
fn a_target_out_of_reach_is_no_go_in_both() {
    let v = assert_same("gale", &request(Some(power_law(14.0, None)), None), false);
    assert!(
        !v.go && v.duration_s.is_none() && v.max_altitude_m < 300.0,
        "{v:?}"
    );
    // Out of reach and past the haul-down limit: no-go either way.
    assert_same(
        "gale past the limit",
        &request(
            Some(power_law(14.0, None)),
            Some(haul_down(&[(0.0, 23.0, 23.0)], 12.0, None)),
        ),
        true,
    );
}

/// An ensemble is priced a plan per distinct wind of the first member
/// (whose hours the answer reports in full) and half a plan per other
/// distinct wind (a member's verdict).
#[test]
fn an_ensemble_is_priced_in_plans_and_verdicts() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/forecasts/open_meteo_hourly.json"
    ))
    .unwrap();
    let mut data: Value = serde_json::from_str(&text).unwrap();
    let hourly = data["hourly"].as_object().unwrap().clone();
    let units = data["hourly_units"].as_object().unwrap().clone();
    // Member 1 equals the control; member 2 blows 10 % harder every hour.
    for (m, factor) in [(1, 1.0), (2, 1.1)] {
        for (k, v) in &hourly {
            if k == "time" {
                continue;
            }
            let key = format!("{k}_member{m:02}");
            let scaled: Vec<Value> = v
                .as_array()
                .unwrap()
                .iter()
                .map(|x| json!(x.as_f64().unwrap() * factor))
                .collect();
            data["hourly"][&key] = Value::Array(scaled);
            data["hourly_units"][&key] = units[k].clone();
        }
    }
    let req: WindowsRequest = serde_json::from_value(json!({
        "cable": {"mass_per_length_kg_m": 0.078, "diameter_m": 0.006, "breaking_strength_n": 20000.0},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0, "drag_coefficient_nondim": 0.3,
                     "reference_area_m2": 20.0},
        "winch": {"max_rate_m_s": 10.0, "max_acceleration_m_s2": 1.0},
        "target_elevation_m": 300.0,
        "operation_s": 3600.0,
        "forecast": {"format": "open_meteo", "data": data}
    }))
    .unwrap();
    let prepared = prepare(&req).unwrap();
    let full = prepared.full_plan_count();
    let verdicts = prepared.plan_count() - full;
    // The control's distinct winds; member 2's calm hours are the control's too.
    assert!(
        full >= 1 && verdicts >= 1 && verdicts <= full,
        "{full} {verdicts}"
    );
    let price = req.price().unwrap();
    let expected = (full as f64 + 0.5 * verdicts as f64) * 0.4;
    assert!(
        (price.cpu_s - expected).abs() < 1e-12,
        "{} {expected}",
        price.cpu_s
    );
    assert!(
        price
            .counts
            .contains(&format!("{verdicts} members' verdicts")),
        "{}",
        price.counts
    );
}
