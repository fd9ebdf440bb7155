//! Tension in the `simulate` answer (issue 12, item 1) against the closed
//! form of the vertical heavy string: at the aerostat `F − m a`, at the
//! winch `F − m a − ρA (g + a) L`, effective winch tension minus `ρA L̇²`
//! (SPEC §6), evaluated here independently from the profile's own L(t).

use serde_json::{Value, json};
use tetherplan::contract;
use tetherplan::contract::run::NoProgress;

const F: f64 = 1000.0;
const M: f64 = 10.0;
const RHO_A: f64 = 7800.0 * 1e-5;
const G: f64 = 9.81;

fn body(profile: Value, breaking_strength_n: Option<f64>) -> Value {
    let mut cable = json!({"density_kg_m3": 7800.0, "area_m2": 1e-5});
    if let Some(b) = breaking_strength_n {
        cable["breaking_strength_n"] = json!(b);
    }
    json!({
        "cable": cable,
        "aerostat": {"net_buoyancy_n": F, "mass_kg": M},
        "initial_length_m": 100.0,
        "gravity_m_s2": G,
        "model": {"kind": "linear_string", "elements": 20},
        "profile": profile,
        "duration_s": 20.0,
        "samples": 21,
        "initial": {"kind": "shape", "tip_deflection_m": 0.1}
    })
}

fn simulate(v: &Value) -> Value {
    let req: contract::transient::SimulateRequest =
        contract::parse(&serde_json::to_vec(v).unwrap()).unwrap();
    serde_json::to_value(contract::transient::simulate(&req, &NoProgress).unwrap()).unwrap()
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

#[test]
fn constant_acceleration_tensions_follow_the_closed_form() {
    let a = 0.5;
    let out = simulate(&body(
        json!({"kind": "constant_acceleration", "acceleration_m_s2": a}),
        Some(5000.0),
    ));
    let times = floats(&out["time_s"]);
    let tension = &out["tension"];
    let winch = floats(&tension["winch_tension_n"]);
    let top = floats(&tension["top_tension_n"]);
    let effective = floats(&tension["effective_winch_tension_n"]);
    assert_eq!(winch.len(), times.len());
    assert!(times.len() >= 2);
    let mut max_winch: f64 = 0.0;
    for (i, &t) in times.iter().enumerate() {
        let length = 100.0 + 0.5 * a * t * t;
        let rate = a * t;
        let top_exact = F - M * a;
        let winch_exact = top_exact - RHO_A * (G + a) * length;
        let tol = 1e-9 * F;
        assert!(
            (top[i] - top_exact).abs() < tol,
            "top at {t}: {} vs {top_exact}",
            top[i]
        );
        assert!(
            (winch[i] - winch_exact).abs() < tol,
            "winch at {t}: {} vs {winch_exact}",
            winch[i]
        );
        let eff_exact = winch_exact - RHO_A * rate * rate;
        assert!((effective[i] - eff_exact).abs() < tol, "effective at {t}");
        max_winch = max_winch.max(winch_exact.max(top_exact));
    }
    // The largest tension is at the aerostat (F − m a > winch), so the
    // safety factor is the rating over it.
    let sf = tension["safety_factor_nondim"].as_f64().unwrap();
    assert!((sf - 5000.0 / max_winch).abs() < 1e-9, "{sf}");
    assert_eq!(tension["slack"], json!(false));
    assert!(tension["first_slack_time_s"].is_null());
}

#[test]
fn a_heavy_tether_goes_slack_at_the_winch_and_says_when() {
    // Constant rate: a = 0, winch tension F − ρA g L(t) vanishes at
    // L = F/(ρA g) = 1306.9 m; start at 1200 m and pay out at 10 m/s, so the
    // first slack sample is the first output time with L > 1306.9 m.
    let mut b = body(json!({"kind": "constant_rate", "rate_m_s": 10.0}), None);
    b["initial_length_m"] = json!(1200.0);
    let out = simulate(&b);
    let tension = &out["tension"];
    assert!(tension["safety_factor_nondim"].is_null());
    let times = floats(&out["time_s"]);
    let l_slack = F / (RHO_A * G);
    let first = times.iter().copied().find(|&t| 1200.0 + 10.0 * t > l_slack);
    match first {
        Some(t) => {
            assert_eq!(tension["slack"], json!(true));
            assert_eq!(tension["first_slack_time_s"].as_f64().unwrap(), t);
            let min = tension["min_tension_n"].as_f64().unwrap();
            let t_last = *times.last().unwrap();
            let exact_min = F - RHO_A * G * (1200.0 + 10.0 * t_last);
            // The run may stop early past onset; the minimum is at the last
            // output time it reached.
            assert!(min <= F - RHO_A * G * (1200.0 + 10.0 * t) + 1e-9, "{min}");
            assert!(min >= exact_min - 1e-9, "{min} vs {exact_min}");
        }
        None => panic!("the run should pass the slack length"),
    }
}
