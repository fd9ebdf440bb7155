//! The tether routes and contract: `POST /api/v1/equilibrium`,
//! `POST /api/v1/envelope`, the envelope job, presets and strict input.

use axum::http::StatusCode;
use serde_json::{Value, json};
use tetherplan::contract::envelope::dto::EnvelopeRequest;
use tetherplan::contract::equilibrium::dto::{EquilibriumRequest, WindFlowInput};
use tetherplan::contract::run::NoProgress;
use tetherplan::contract::{self, envelope, equilibrium};
use tetherplan::jobs::store::JobStatus;
use tetherplan::jobs::try_execute_next;
use tetherplan::numerics::parallel::Parallelism;
use utoipa::PartialSchema;

mod common;
use common::{app, paths, replaced, send};

fn example<T: PartialSchema>() -> Value {
    serde_json::to_value(T::schema()).unwrap()["example"].clone()
}

fn parse_equilibrium(v: &Value) -> EquilibriumRequest {
    contract::parse_plain(&serde_json::to_vec(v).unwrap()).unwrap()
}

#[tokio::test]
async fn the_schema_examples_succeed_as_they_are() {
    let (app, _) = app();
    let (status, body) = send(
        &app,
        "POST",
        "/api/v1/equilibrium",
        Some(&example::<EquilibriumRequest>()),
    )
    .await;
    assert_eq!(status, StatusCode::OK, "{body}");
    for field in [
        "aerostat_altitude_m",
        "aerostat_downwind_m",
        "winch_tension_n",
        "top_tension_n",
        "safety_factor_nondim",
        "blowdown_angle_deg",
        "slack",
    ] {
        assert!(!body[field].is_null(), "{field}: {body}");
    }
    let shape = body["shape"].as_array().unwrap();
    assert_eq!(shape.len(), 51);
    for key in ["s_m", "x_m", "z_m", "tension_n"] {
        assert!(shape[10][key].is_number());
    }
    assert_eq!(shape[0]["z_m"], 0.0);
    assert_eq!(shape[50]["s_m"], 1000.0);
    // preset dyneema 6 mm: 0.0195 kg/m, 30 kN
    assert!(
        (body["cable"]["mass_per_length_kg_m"].as_f64().unwrap() - 690.0 * 2.827e-5).abs() < 1e-4
    );
    let (status, body) = send(
        &app,
        "POST",
        "/api/v1/envelope",
        Some(&example::<EnvelopeRequest>()),
    )
    .await;
    assert_eq!(status, StatusCode::OK, "{body}");
    assert_eq!(body["points"].as_array().unwrap().len(), 2000);
    assert_eq!(body["max_wind_per_length"].as_array().unwrap().len(), 50);
    assert_eq!(body["max_altitude_per_wind"].as_array().unwrap().len(), 40);
}

#[tokio::test]
async fn bad_input_names_its_field() {
    let (app, _) = app();
    let base = example::<EquilibriumRequest>();
    let cases: Vec<(Value, &str)> = vec![
        (
            {
                let mut b = base.clone();
                b["cable"]["colour"] = json!("red");
                b
            },
            "cable",
        ),
        (
            {
                let mut b = base.clone();
                b["cable"] = json!({"diameter_m": 0.006});
                b
            },
            "cable.mass_per_length_kg_m",
        ),
        (
            {
                let mut b = base.clone();
                b["tether_length_m"] = json!(-5.0);
                b
            },
            "tether_length_m",
        ),
        (
            {
                let mut b = base.clone();
                b["wind"]["flow"]["roughness_length_m"] = json!(50.0);
                b
            },
            "wind.flow.roughness_length_m",
        ),
        (
            {
                let mut b = base.clone();
                b["aerostat"] = json!({"net_buoyancy_n": 10.0, "preset": "sphere"});
                b
            },
            "aerostat.radius_m",
        ),
        (
            {
                let mut b = base.clone();
                b["required_safety_factor_nondim"] = json!(0.5);
                b
            },
            "required_safety_factor_nondim",
        ),
        (
            {
                let mut b = base.clone();
                b["integration_steps"] = json!(2);
                b
            },
            "integration_steps",
        ),
    ];
    for (body, field) in cases {
        let (status, err) = send(&app, "POST", "/api/v1/equilibrium", Some(&body)).await;
        assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{field}: {err}");
        let got = err["error"]["field"].as_str().unwrap_or_default();
        assert!(got.starts_with(field), "{field}: {err}");
    }
    let mut big = example::<EnvelopeRequest>();
    big["tether_lengths_m"]["count"] = json!(1000);
    let (status, err) = send(&app, "POST", "/api/v1/envelope", Some(&big)).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY);
    assert_eq!(err["error"]["code"], "too_large");
}

#[test]
fn explicit_fields_override_the_presets() {
    let mut v = example::<EquilibriumRequest>();
    v["cable"]["mass_per_length_kg_m"] = json!(0.05);
    v["cable"]["breaking_strength_n"] = json!(12345.0);
    v["aerostat"] = json!({"preset": "sphere", "radius_m": 3.0, "net_buoyancy_n": 2000.0, "drag_coefficient_nondim": 0.2});
    let out = equilibrium::equilibrium(&parse_equilibrium(&v)).unwrap();
    assert_eq!(out.cable.mass_per_length_kg_m, 0.05);
    assert_eq!(out.cable.breaking_strength_n, Some(12345.0));
    // EA still from the preset: 30 GPa × π (3 mm)²
    let ea = out.cable.axial_stiffness_n.unwrap();
    assert!((ea - 30e9 * std::f64::consts::PI * 9e-6).abs() < 1.0);
    assert_eq!(out.aerostat.drag_coefficient_nondim, 0.2);
    assert!((out.aerostat.reference_area_m2 - std::f64::consts::PI * 9.0).abs() < 1e-12);
    let sf = out.safety_factor_nondim.unwrap();
    assert!((sf - 12345.0 / out.max_tension_n).abs() < 1e-12);
    assert_eq!(out.meets_required_safety_factor, Some(sf >= 5.0));
}

#[test]
fn slack_is_an_answer() {
    let mut v = example::<EquilibriumRequest>();
    v["tether_length_m"] = json!(20000.0);
    let out = equilibrium::equilibrium(&parse_equilibrium(&v)).unwrap();
    assert!(out.slack);
    assert!(out.grounded_length_m > 0.0);
    assert_eq!(out.binding_limit.as_deref(), Some("slack"));
    assert!(out.explanation.contains("Slack"));
}

#[test]
fn envelope_points_equal_single_point_answers() {
    for shape in [
        json!({"kind": "uniform", "speed_m_s": 0.0}),
        json!({"kind": "power_law", "coefficient_m_s": 0.0, "exponent_nondim": 0.14, "reference_height_m": 10.0}),
        json!({"kind": "log_law", "speed_m_s": 0.0, "roughness_length_m": 0.03, "reference_height_m": 10.0}),
    ] {
        let mut v = example::<EnvelopeRequest>();
        v["wind"]["flow"] = shape.clone();
        v["wind_speeds_m_s"] = json!({"min": 0.0, "max": 30.0, "count": 7});
        v["tether_lengths_m"] = json!({"min": 200.0, "max": 6000.0, "count": 6});
        let req: EnvelopeRequest = contract::parse_plain(&serde_json::to_vec(&v).unwrap()).unwrap();
        let env = envelope::envelope(&req, Parallelism::Rayon, &NoProgress).unwrap();
        let serial = envelope::envelope(&req, Parallelism::Serial, &NoProgress).unwrap();
        assert_eq!(env, serial, "parallel == serial");
        let mut kinds = std::collections::BTreeSet::new();
        for p in &env.points {
            let u = p.wind_speed_m_s;
            let flow = match shape["kind"].as_str().unwrap() {
                "uniform" => json!({"kind": "uniform", "speed_m_s": u}),
                "power_law" => {
                    json!({"kind": "power_law", "coefficient_m_s": u / 10f64.powf(0.14), "exponent_nondim": 0.14})
                }
                _ => {
                    json!({"kind": "log_law", "reference_speed_m_s": u, "reference_height_m": 10.0, "roughness_length_m": 0.03})
                }
            };
            let single = json!({
                "cable": v["cable"], "aerostat": v["aerostat"], "tether_length_m": p.tether_length_m,
                "wind": {"flow": flow, "air_density_kg_m3": 1.225},
                "required_safety_factor_nondim": 5.0, "payout_rate_m_s": 5.0,
            });
            // JSON parsing may round a float by an ulp (serde_json without
            // float_roundtrip): set the numbers directly.
            let mut single = parse_equilibrium(&single);
            single.tether_length_m = p.tether_length_m;
            single.wind.flow = match single.wind.flow {
                WindFlowInput::Uniform { .. } => WindFlowInput::Uniform { speed_m_s: u },
                WindFlowInput::PowerLaw {
                    exponent_nondim, ..
                } => WindFlowInput::PowerLaw {
                    coefficient_m_s: u / 10f64.powf(0.14),
                    exponent_nondim,
                    reference_height_m: 1.0,
                },
                WindFlowInput::LogLaw {
                    reference_height_m,
                    roughness_length_m,
                    ..
                } => WindFlowInput::LogLaw {
                    speed_m_s: u,
                    reference_height_m,
                    roughness_length_m,
                },
                other => other,
            };
            let one = equilibrium::equilibrium(&single).unwrap();
            assert_eq!(
                p.aerostat_altitude_m, one.aerostat_altitude_m,
                "{shape} {u} {}",
                p.tether_length_m
            );
            assert_eq!(p.aerostat_downwind_m, one.aerostat_downwind_m);
            assert_eq!(p.winch_tension_n, one.winch_tension_n);
            assert_eq!(p.top_tension_n, one.top_tension_n);
            assert_eq!(p.safety_factor_nondim, one.safety_factor_nondim);
            assert_eq!(p.slack, one.slack);
            assert_eq!(p.stable, one.stable);
            // the ceiling is the envelope's own limit
            let ceiling = p.aerostat_altitude_m > 2500.0 && one.binding_limit.is_none();
            let want = if ceiling {
                Some("ceiling".to_string())
            } else {
                one.binding_limit.clone()
            };
            assert_eq!(p.binding_limit, want, "{u} m/s, {} m", p.tether_length_m);
            kinds.insert(p.binding_limit.clone());
        }
        assert!(
            kinds.len() >= 3,
            "the grid should cross several limits: {kinds:?}"
        );
        // largest operating wind per length: every lower wind is feasible, the next is not
        for (j, m) in env.max_wind_per_length.iter().enumerate() {
            let column: Vec<_> = (0..7).map(|i| &env.points[i * 6 + j]).collect();
            match m.max_wind_speed_m_s {
                None => assert!(!column[0].feasible),
                Some(w) => {
                    for p in &column {
                        if p.wind_speed_m_s <= w {
                            assert!(p.feasible);
                        }
                    }
                    if let Some(next) = column.iter().find(|p| p.wind_speed_m_s > w) {
                        assert_eq!(next.binding_limit, m.binding_limit);
                    }
                }
            }
        }
    }
}

#[tokio::test]
async fn envelope_runs_as_a_job_with_progress() {
    let (app, queue) = app();
    let mut req = example::<EnvelopeRequest>();
    req["tether_lengths_m"]["count"] = json!(200);
    let (status, body) = send(
        &app,
        "POST",
        "/api/v1/jobs",
        Some(&json!({"kind": "envelope", "request": req})),
    )
    .await;
    assert_eq!(status, StatusCode::ACCEPTED, "{body}");
    let id = body["id"].as_i64().unwrap();
    let q = queue.clone();
    tokio::task::spawn_blocking(move || try_execute_next(&q).unwrap())
        .await
        .unwrap()
        .expect("a job ran");
    let (status, job) = send(&app, "GET", &format!("/api/v1/jobs/{id}"), None).await;
    assert_eq!(status, StatusCode::OK);
    assert_eq!(
        job["status"],
        serde_json::to_value(JobStatus::Done).unwrap(),
        "{job}"
    );
    assert_eq!(job["result"]["points"].as_array().unwrap().len(), 40 * 200);
    assert_eq!(job["progress"], 1.0);
}

#[tokio::test]
async fn any_one_field_replaced_never_gives_a_5xx() {
    let (app, _) = app();
    let mut env = example::<EnvelopeRequest>();
    env["wind_speeds_m_s"]["count"] = json!(3);
    env["tether_lengths_m"]["count"] = json!(3);
    let mut tabulated = example::<EquilibriumRequest>();
    tabulated["wind"]["flow"] = json!({"kind": "tabulated", "points": [
        {"elevation_m": 0.0, "speed_m_s": 3.0}, {"elevation_m": 500.0, "speed_m_s": 12.0}]});
    let bad = [
        json!(null),
        json!(-1.0),
        json!(0.0),
        json!(1e-300),
        json!(1e300),
        json!(-1e300),
        json!("x"),
        json!([]),
        json!({}),
        json!(true),
    ];
    for (route, body) in [
        ("/api/v1/equilibrium", example::<EquilibriumRequest>()),
        ("/api/v1/equilibrium", tabulated),
        ("/api/v1/envelope", env),
    ] {
        let mut all = vec![];
        paths(&body, vec![], &mut all);
        for path in &all {
            for new in &bad {
                let b = replaced(&body, path, new.clone());
                let (status, answer) = send(&app, "POST", route, Some(&b)).await;
                assert!(
                    status.as_u16() < 500,
                    "{route} {path:?} = {new} → {status} {answer}"
                );
                if status.is_success() {
                    let text = answer.to_string();
                    assert!(!text.contains("NaN") && !text.contains("inf"), "{text}");
                } else {
                    assert!(answer["error"]["message"].is_string(), "{answer}");
                }
            }
        }
    }
}

#[test]
fn cli_answers_equilibrium_and_envelope() {
    use std::io::Write;
    use std::process::{Command, Stdio};
    let run = |cmd: &str, body: &Value| {
        let mut child = Command::new(env!("CARGO_BIN_EXE_tetherplan"))
            .arg(cmd)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        child
            .stdin
            .take()
            .unwrap()
            .write_all(body.to_string().as_bytes())
            .unwrap();
        let out = child.wait_with_output().unwrap();
        let v: Value = serde_json::from_slice(&out.stdout).unwrap();
        (out.status.code().unwrap(), v)
    };
    let req = example::<EquilibriumRequest>();
    let (code, v) = run("equilibrium", &req);
    assert_eq!(code, 0, "{v}");
    let direct = equilibrium::equilibrium(&parse_equilibrium(&req)).unwrap();
    assert_eq!(
        v["aerostat_altitude_m"].as_f64().unwrap(),
        direct.aerostat_altitude_m
    );
    let mut env = example::<EnvelopeRequest>();
    env["wind_speeds_m_s"]["count"] = json!(4);
    let (code, v) = run("envelope", &env);
    assert_eq!(code, 0, "{v}");
    assert_eq!(v["points"].as_array().unwrap().len(), 200);
    let (code, v) = run("equilibrium", &json!({"cable": {}}));
    assert_eq!(code, 2);
    assert!(v["error"]["field"].is_string());
}

#[test]
fn critical_and_chart_answers_carry_the_tensions() {
    use tetherplan::contract::dto::{ChartRequest, CriticalRequest};
    let system = json!({"cable": {"mass_per_length_kg_m": 0.078, "breaking_strength_n": 20000.0},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0}, "model": {"elements": 50}});
    let with = |extra: Value| {
        let mut v = system.clone();
        for (k, x) in extra.as_object().unwrap() {
            v[k] = x.clone();
        }
        serde_json::to_vec(&v).unwrap()
    };
    let (rho_a, f, m, g) = (0.078, 1000.0, 10.0, 9.81);
    let req: CriticalRequest = contract::parse(&with(
        json!({"profile": {"kind": "constant_rate", "rate_m_s": 10.0}}),
    ))
    .unwrap();
    let out = tetherplan::contract::run::critical(&req).unwrap();
    let t = out.tension_at_onset.expect("unstable at some length");
    let h = out.max_elevation_m.unwrap();
    assert_eq!(t.length_m, h);
    assert!((t.top_tension_n - f).abs() < 1e-9);
    assert!((t.winch_tension_n - (f - rho_a * g * h)).abs() < 1e-9);
    assert!((t.kinematic_tension_n - rho_a * 100.0).abs() < 1e-9);
    // the converged h* sits near the continuum limit: effective tension ≈ 0
    assert!(t.effective_winch_tension_n.abs() < 0.05 * f, "{t:?}");
    assert!((t.safety_factor_nondim.unwrap() - 20.0).abs() < 1e-12);
    let req: CriticalRequest = contract::parse(&with(
        json!({"profile": {"kind": "constant_acceleration", "acceleration_m_s2": 0.5}}),
    ))
    .unwrap();
    let out = tetherplan::contract::run::critical(&req).unwrap();
    let t = out.tension_at_onset.unwrap();
    assert!((t.top_tension_n - (f - m * 0.5)).abs() < 1e-9);
    assert!((t.winch_tension_n - (f - m * 0.5 - rho_a * (g + 0.5) * t.length_m)).abs() < 1e-9);
    let req: ChartRequest = contract::parse(&with(
        json!({"rates_m_s": {"min": 1.0, "max": 50.0, "count": 5}}),
    ))
    .unwrap();
    let out = tetherplan::contract::run::chart(&req, Parallelism::Serial, &NoProgress).unwrap();
    for p in &out.series[0].points {
        assert!((p.winch_tension_at_onset_n - (f - rho_a * g * p.max_elevation_m)).abs() < 1e-9);
        assert!((p.kinematic_tension_n - rho_a * p.rate_m_s * p.rate_m_s).abs() < 1e-12);
    }
    let bad: Result<CriticalRequest, _> = contract::parse(&serde_json::to_vec(&json!({
        "cable": {"mass_per_length_kg_m": 0.078, "breaking_strength_n": -1.0},
        "aerostat": {"net_buoyancy_n": 1000.0}, "profile": {"kind": "constant_rate", "rate_m_s": 10.0}})).unwrap());
    // Refused as the request is parsed (one validation for every route and jobs).
    let err = bad.unwrap_err();
    assert_eq!(
        err.body().error.field.as_deref(),
        Some("cable.breaking_strength_n")
    );
}
