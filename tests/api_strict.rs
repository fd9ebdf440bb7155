//! Strict input over every route (issue 10 item 4), driven through the
//! router with `tower::ServiceExt::oneshot` and, for jobs, through the
//! submission parser and the job runner:
//!
//! - random finite values within the accepted ranges
//!   (`numerics::params::ranges`) give an answer or a typed 4xx, never a
//!   5xx, never a `null` where the response schema promises a number, and
//!   never a job that fails with `internal` (or panics);
//! - a random unknown key anywhere in a valid body is refused naming it
//!   with its full path;
//! - the examples of the issue, one test each.
//!
//! Cost knobs (elements, steps, chart points) are kept small so the whole
//! file runs in seconds in release; the physical magnitudes span the
//! ranges (log-uniform where the range spans decades).

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::time::Duration;

use axum::Router;
use proptest::prelude::*;
use serde_json::{Value, json};
use tetherplan::config::Limits;
use tetherplan::contract::RequestError;
use tetherplan::contract::dto::*;
use tetherplan::contract::ge_charts::{AnyChartResponse, AnyFrequencyResponseResponse};
use tetherplan::contract::run::NoProgress;
use tetherplan::contract::simulate::AnySimulateResponse;
use tetherplan::jobs::kinds::JobSubmission;
use tetherplan::numerics::params::{Range, ranges::*};

mod common;
use common::with;

fn app() -> Router {
    let limits = Limits {
        solve_timeout: Duration::from_secs(120),
        ..Limits::default()
    };
    common::app_with(1, limits).0
}

fn post(app: &Router, route: &str, body: &Value) -> (u16, String) {
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .unwrap();
    let (status, text) = rt.block_on(common::post_text(app, route, body));
    (status.as_u16(), text)
}

/// A small deterministic generator (xorshift64*) driven by proptest's seed.
struct Gen(u64);

impl Gen {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn coin(&mut self) -> bool {
        self.next() & 1 == 1
    }
    fn int(&mut self, lo: usize, hi: usize) -> usize {
        lo + (self.next() % (hi - lo + 1) as u64) as usize
    }
    /// Anywhere in the range: the ends, log-uniform over positive decades,
    /// or uniform.
    fn in_range(&mut self, r: Range) -> f64 {
        match self.int(0, 5) {
            0 => r.min,
            1 => r.max,
            2 | 3 if r.min > 0.0 => (r.min.ln() + self.unit() * (r.max.ln() - r.min.ln())).exp(),
            2 | 3 if r.max > 0.0 => {
                let lo = r.min.max(r.max * 1e-9).max(1e-12);
                let v = (lo.ln() + self.unit() * (r.max.ln() - lo.ln())).exp();
                if r.min < 0.0 && self.coin() {
                    -v.min(-r.min)
                } else {
                    v
                }
            }
            _ => r.min + self.unit() * (r.max - r.min),
        }
    }
    fn pick<'a>(&mut self, xs: &[&'a str]) -> &'a str {
        xs[self.int(0, xs.len() - 1)]
    }
}

fn cable(g: &mut Gen) -> Value {
    if g.coin() {
        json!({"mass_per_length_kg_m": g.in_range(MASS_PER_LENGTH_KG_M)})
    } else {
        // density × area must itself be a plausible mass per length
        let rho = g.in_range(DENSITY_KG_M3);
        let lo = (MASS_PER_LENGTH_KG_M.min / rho).max(AREA_M2.min);
        let hi = (MASS_PER_LENGTH_KG_M.max / rho).min(AREA_M2.max);
        let a = (lo.ln() + g.unit() * (hi.ln() - lo.ln())).exp();
        json!({"density_kg_m3": rho, "area_m2": a.clamp(lo, hi)})
    }
}

fn string_system(g: &mut Gen, max_elements: usize) -> Value {
    json!({
        "cable": cable(g),
        "aerostat": {"net_buoyancy_n": g.in_range(NET_BUOYANCY_N), "mass_kg": g.in_range(AEROSTAT_MASS_KG)},
        "initial_length_m": g.in_range(INITIAL_LENGTH_M),
        "gravity_m_s2": g.in_range(GRAVITY_M_S2),
        "model": {"kind": "linear_string", "elements": g.int(2, max_elements)}
    })
}

fn profile(g: &mut Gen) -> Value {
    let target = |g: &mut Gen| {
        if g.coin() {
            Value::Null
        } else {
            json!(g.in_range(LENGTH_M))
        }
    };
    let mut p = match g.int(0, 3) {
        0 => json!({"kind": "constant_rate", "rate_m_s": g.in_range(RATE_M_S)}),
        1 => {
            json!({"kind": "constant_acceleration", "acceleration_m_s2": g.in_range(ACCELERATION_M_S2)})
        }
        2 => json!({"kind": "trapezoidal", "cruise_rate_m_s": g.in_range(RATE_M_S),
                    "ramp_up_s": g.in_range(DURATION_S), "ramp_down_s": g.in_range(DURATION_S),
                    "target_length_m": g.in_range(LENGTH_M)}),
        _ => {
            let n = g.int(1, 4);
            let mut t = 0.0;
            let points: Vec<Value> = (0..n)
                .map(|i| {
                    if i > 0 {
                        t += g.in_range(Range::new(1e-3, 1e3, "s"));
                    }
                    json!({"time_s": t, "rate_m_s": g.in_range(RATE_M_S)})
                })
                .collect();
            json!({"kind": "piecewise_linear_rate", "points": points})
        }
    };
    if p["kind"] != "trapezoidal" {
        let t = target(g);
        if !t.is_null() {
            p["target_length_m"] = t;
        }
    }
    p
}

fn aero_body(g: &mut Gen) -> Value {
    let mut b = json!({"radius_m": g.in_range(RADIUS_M), "air_density_kg_m3": g.in_range(GAS_DENSITY_KG_M3)});
    if g.coin() {
        b["model"] =
            json!({"kind": "drag", "drag_coefficient_nondim": g.in_range(DRAG_COEFFICIENT_NONDIM)});
    }
    b
}

fn initial(g: &mut Gen, l0: f64) -> Value {
    let tip = Range::new(
        -TIP_DEFLECTION_LENGTHS * l0,
        TIP_DEFLECTION_LENGTHS * l0,
        "m",
    );
    match g.int(0, 3) {
        0 => json!({"kind": "rest"}),
        1 => json!({"kind": "shape", "tip_deflection_m": g.in_range(tip)}),
        2 => json!({"kind": "mode", "mode": g.int(1, 3), "tip_deflection_m": g.in_range(tip)}),
        _ => {
            json!({"kind": "tip_force", "force_n": g.in_range(FORCE_N), "duration_s": g.in_range(DURATION_S)})
        }
    }
}

fn ge_system(g: &mut Gen, elements: usize) -> Value {
    json!({
        "cable": cable(g),
        "aerostat": {"net_buoyancy_n": g.in_range(NET_BUOYANCY_N), "mass_kg": g.in_range(AEROSTAT_MASS_KG),
                     "link_length_m": if g.coin() { 0.0 } else { g.in_range(LINK_LENGTH_M) }},
        "initial_length_m": g.in_range(INITIAL_LENGTH_M),
        "gravity_m_s2": g.in_range(GE_GRAVITY_M_S2),
        "model": {"kind": "geometrically_exact", "elements": elements,
                  "bending_stiffness_n_m2": g.in_range(BENDING_STIFFNESS_N_M2),
                  "stiffness_ratio": g.in_range(STIFFNESS_RATIO),
                  "inertia_ratio": g.in_range(INERTIA_RATIO)}
    })
}

/// A request of `kind` with random values within the accepted ranges.
fn random_request(kind: &str, g: &mut Gen) -> Value {
    match kind {
        "stability" => with(
            string_system(g, 40),
            json!({"state": {"length_m": g.in_range(LENGTH_M), "rate_m_s": g.in_range(RATE_M_S),
                             "acceleration_m_s2": g.in_range(ACCELERATION_M_S2)}, "modes": g.int(1, 5)}),
        ),
        "critical" => with(string_system(g, 30), json!({"profile": profile(g)})),
        "safe_rate" => with(
            string_system(g, 30),
            json!({"target_elevation_m": g.in_range(LENGTH_M)}),
        ),
        "chart" => {
            let (a, b) = (g.in_range(POSITIVE_RATE_M_S), g.in_range(POSITIVE_RATE_M_S));
            with(
                string_system(g, 20),
                json!({"rates_m_s": {"min": a.min(b), "max": a.max(b), "count": g.int(1, 6)},
                       "net_buoyancies_n": [g.in_range(NET_BUOYANCY_N)]}),
            )
        }
        "simulate" => {
            let sys = string_system(g, 10);
            let l0 = sys["initial_length_m"].as_f64().unwrap();
            let mut r = with(
                sys,
                json!({"profile": profile(g), "duration_s": g.in_range(Range::new(1e-6, 5.0, "s")),
                       "samples": g.int(2, 50), "initial": initial(g, l0)}),
            );
            if g.coin() {
                r["time_step_s"] = json!(g.in_range(Range::new(1e-3, 1.0, "s")));
            }
            if g.coin() {
                let mut a = aero_body(g);
                a["flow"] = match g.int(0, 2) {
                    0 => json!({"kind": "uniform", "speed_m_s": g.in_range(WIND_SPEED_M_S)}),
                    1 => json!({"kind": "power_law", "coefficient_m_s": g.in_range(WIND_SPEED_M_S),
                                "exponent_nondim": g.in_range(EXPONENT_NONDIM)}),
                    _ => json!({"kind": "sinusoidal", "amplitude_m_s": g.in_range(WIND_SPEED_M_S),
                                "angular_frequency_rad_s": g.in_range(Range::new(0.0, 10.0, "rad/s"))}),
                };
                r["aero"] = a;
            }
            r
        }
        "simulate_ge" => {
            let dt = g.in_range(Range::new(1e-6, 1.0, "s"));
            let steps = g.int(1, 60) as f64;
            let mut r = with(
                {
                    let n = g.int(1, 4);
                    ge_system(g, n)
                },
                json!({"time_step_s": dt, "duration_s": dt * steps,
                       "initial": {"kind": g.pick(&["rest", "static_equilibrium"])},
                       "eigenvalues_every_steps": g.int(0, 30)}),
            );
            if g.coin() {
                r["profile"] = profile(g);
            }
            if g.coin() {
                r["end_load"] = json!({"transverse_force_n": g.in_range(FORCE_N),
                    "moment_n_m": g.in_range(MOMENT_N_M), "time": {"kind": "held", "ramp_s": 0.0, "hold_s": dt * steps / 2.0}});
            }
            r
        }
        "frequency_response" => {
            let sys = string_system(g, 8);
            let l0 = sys["initial_length_m"].as_f64().unwrap();
            let (a, b) = (
                g.in_range(Range::new(0.0, 10.0, "")),
                g.in_range(Range::new(0.0, 10.0, "")),
            );
            with(
                sys,
                json!({"profile": profile(g), "duration_s": g.in_range(Range::new(1e-6, 2.0, "s")),
                       "samples": g.int(2, 20), "initial": initial(g, l0), "aero": aero_body(g),
                       "wind_amplitude_m_s": g.in_range(WIND_SPEED_M_S),
                       "frequencies_rad_s": {"min": a.min(b), "max": a.max(b), "count": g.int(1, 3)}}),
            )
        }
        "chart_ge" => {
            let dt = g.in_range(Range::new(1e-4, 1.0, "s"));
            let (a, b) = (g.in_range(POSITIVE_RATE_M_S), g.in_range(POSITIVE_RATE_M_S));
            let n = g.int(1, 3);
            let mut sys = ge_system(g, n);
            sys["model"]
                .as_object_mut()
                .unwrap()
                .remove("stiffness_ratio");
            sys["aerostat"]["net_buoyancy_n"] = json!(g.in_range(NET_BUOYANCY_N));
            with(
                sys,
                json!({"stiffness_ratios": [g.in_range(STIFFNESS_RATIO)],
                       "rates_m_s": {"min": a.min(b), "max": a.max(b), "count": g.int(1, 2)},
                       "perturbation": {"forces_n": [g.in_range(FORCE_N)], "ramp_s": dt, "hold_s": 2.0 * dt},
                       "numerics": {"time_step_s": dt, "check_every_steps": g.int(1, 10), "horizon_s": dt * g.int(1, 40) as f64}}),
            )
        }
        "frequency_response_ge" => {
            let dt = g.in_range(Range::new(1e-5, 0.1, "s"));
            let (a, b) = (
                g.in_range(Range::new(1e-3, 1e4, "")),
                g.in_range(Range::new(1e-3, 1e4, "")),
            );
            with(
                {
                    let n = g.int(1, 3);
                    ge_system(g, n)
                },
                json!({"excitation": "base", "amplitude_m": g.in_range(BASE_AMPLITUDE_M),
                       "frequencies_rad_s": {"min": a.min(b), "max": a.max(b), "count": g.int(1, 2)},
                       "duration_s": dt * g.int(1, 30) as f64, "time_step_s": dt}),
            )
        }
        other => panic!("no generator for {other}"),
    }
}

const KINDS: [&str; 9] = [
    "stability",
    "critical",
    "safe_rate",
    "chart",
    "simulate",
    "simulate_ge",
    "frequency_response",
    "chart_ge",
    "frequency_response_ge",
];

fn route_of(kind: &str) -> (&'static str, &'static str) {
    match kind {
        "stability" => ("/api/v1/stability", "stability"),
        "critical" => ("/api/v1/critical", "critical"),
        "safe_rate" => ("/api/v1/safe-rate", "safe_rate"),
        "chart" | "chart_ge" => ("/api/v1/charts", "chart"),
        "simulate" | "simulate_ge" => ("/api/v1/simulate", "simulate"),
        _ => ("/api/v1/frequency-response", "frequency_response"),
    }
}

/// The answer parses as the typed response: a `null` in a field typed as a
/// number (a NaN or infinity serialised) fails here.
fn typed(job_kind: &str, text: &str) -> Result<(), String> {
    let r = match job_kind {
        "stability" => serde_json::from_str::<StabilityResponse>(text).map(drop),
        "critical" => serde_json::from_str::<CriticalResponse>(text).map(drop),
        "safe_rate" => serde_json::from_str::<SafeRateResponse>(text).map(drop),
        "chart" => serde_json::from_str::<AnyChartResponse>(text).map(drop),
        "simulate" => serde_json::from_str::<AnySimulateResponse>(text).map(drop),
        _ => serde_json::from_str::<AnyFrequencyResponseResponse>(text).map(drop),
    };
    r.map_err(|e| {
        let mut nulls = vec![];
        null_paths(
            &serde_json::from_str(text).unwrap_or(Value::Null),
            String::new(),
            &mut nulls,
        );
        format!("{e}; nulls at {:?}", &nulls[..nulls.len().min(8)])
    })
}

fn null_paths(v: &Value, at: String, out: &mut Vec<String>) {
    match v {
        Value::Null => out.push(at),
        Value::Object(m) => m
            .iter()
            .for_each(|(k, x)| null_paths(x, format!("{at}.{k}"), out)),
        Value::Array(a) => a
            .iter()
            .enumerate()
            .for_each(|(i, x)| null_paths(x, format!("{at}[{i}]"), out)),
        _ => {}
    }
}

/// Every object path of a JSON value (key paths; array indices as numbers).
fn object_paths(v: &Value, prefix: Vec<Value>, out: &mut Vec<Vec<Value>>) {
    match v {
        Value::Object(m) => {
            out.push(prefix.clone());
            for (k, x) in m {
                let mut p = prefix.clone();
                p.push(json!(k));
                object_paths(x, p, out);
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                let mut p = prefix.clone();
                p.push(json!(i));
                object_paths(x, p, out);
            }
        }
        _ => {}
    }
}

fn at_path<'a>(v: &'a mut Value, path: &[Value]) -> &'a mut Value {
    path.iter().fold(v, |cur, k| match k {
        Value::String(s) => &mut cur[s.as_str()],
        Value::Number(n) => &mut cur[n.as_u64().unwrap() as usize],
        _ => unreachable!(),
    })
}

/// `cable.area_m2`, `profile.points[1].time_s`: the error's path syntax.
fn dotted(path: &[Value], key: &str) -> String {
    let mut s = String::new();
    for k in path {
        match k {
            Value::String(x) => {
                if !s.is_empty() {
                    s.push('.');
                }
                s.push_str(x);
            }
            Value::Number(n) => s.push_str(&format!("[{n}]")),
            _ => unreachable!(),
        }
    }
    if s.is_empty() {
        key.to_string()
    } else {
        format!("{s}.{key}")
    }
}

proptest! {
    // `STRICT_CASES=2000` for a longer hunt.
    #![proptest_config(ProptestConfig {
        cases: std::env::var("STRICT_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(96),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    /// Values within the ranges: an answer or a 4xx naming a field, never a
    /// 5xx, never a `null` number; as a job, never `internal`.
    #[test]
    fn values_within_the_ranges_never_give_a_5xx_or_an_internal_job(
        kind in prop::sample::select(KINDS.to_vec()),
        seed in 1u64..,
        as_job in any::<bool>(),
    ) {
        let mut g = Gen(seed);
        let body = random_request(kind, &mut g);
        let (route, job_kind) = route_of(kind);
        if as_job {
            let submission = json!({"kind": job_kind, "request": body});
            let bytes = serde_json::to_vec(&submission).unwrap();
            let parsed = JobSubmission::parse(&bytes, &Limits::default());
            let Ok(job) = parsed else {
                let e = parsed.unwrap_err();
                prop_assert!(matches!(e, RequestError::Invalid(_)), "{body}: {e:?}");
                return Ok(());
            };
            let out = catch_unwind(AssertUnwindSafe(|| job.run(&NoProgress)));
            prop_assert!(out.is_ok(), "job panicked: {body}");
            match out.unwrap() {
                Ok(text) => {
                    let t = typed(job_kind, &text);
                    prop_assert!(t.is_ok(), "{body}: null number? {t:?} in {}", &text[..text.len().min(600)]);
                }
                Err(e) => {
                    let b = e.body();
                    prop_assert!(b.error.code != "internal", "{body}: internal job failure {b:?}");
                }
            }
        } else {
            let (status, text) = post(&app(), route, &body);
            prop_assert!(status < 500, "{route} {body} → {status} {text}");
            if status == 200 {
                let t = typed(job_kind, &text);
                prop_assert!(t.is_ok(), "{body}: null number? {t:?} in {}", &text[..text.len().min(600)]);
            } else {
                let e: ErrorBody = serde_json::from_str(&text).unwrap();
                prop_assert!(e.error.field.is_some() || e.error.code != "invalid_input", "{text}");
            }
        }
    }

    /// A random unknown key anywhere in a valid body is refused, naming it.
    #[test]
    fn an_unknown_key_anywhere_is_refused_naming_it(
        kind in prop::sample::select(KINDS.to_vec()),
        seed in 1u64..,
        key in "[a-z]{1,8}_x[a-z0-9]{0,3}",
        pick in any::<prop::sample::Index>(),
        as_job in any::<bool>(),
    ) {
        let mut g = Gen(seed);
        let mut body = random_request(kind, &mut g);
        let (route, job_kind) = route_of(kind);
        if as_job {
            body = json!({"kind": job_kind, "request": body});
        }
        let mut objects = vec![];
        object_paths(&body, vec![], &mut objects);
        let path = pick.get(&objects).clone();
        at_path(&mut body, &path)[key.as_str()] = json!(1.0);
        let expected = dotted(&path, &key);
        let (status, text) = post(&app(), if as_job { "/api/v1/jobs" } else { route }, &body);
        prop_assert_eq!(status, 422, "{} {} → {}", route, body, text);
        let e: ErrorBody = serde_json::from_str(&text).unwrap();
        prop_assert_eq!(e.error.field.as_deref(), Some(expected.as_str()), "{}", text);
        let needle = format!("unknown field `{key}`");
        prop_assert!(e.error.message.contains(&needle), "{}", text);
    }
}

fn error_of(route: &str, body: Value) -> ErrorDetail {
    let (status, text) = post(&app(), route, &body);
    assert_eq!(status, 422, "{route} {body} → {status} {text}");
    serde_json::from_str::<ErrorBody>(&text).unwrap().error
}

fn thesis() -> Value {
    json!({"cable": {"mass_per_length_kg_m": 0.078}, "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0}})
}

#[test]
fn a_gravity_typo_is_refused_naming_the_field_and_the_keys_it_could_be() {
    let body = with(
        thesis(),
        json!({"gravity": 3.71, "profile": {"kind": "constant_rate", "rate_m_s": 10.0}}),
    );
    let e = error_of("/api/v1/critical", body);
    assert_eq!(e.field.as_deref(), Some("gravity"));
    assert!(
        e.message.contains("unknown field `gravity`"),
        "{}",
        e.message
    );
    // the list names the system's keys and the request's own
    assert!(
        e.message.contains("`gravity_m_s2`") && e.message.contains("`profile`"),
        "{}",
        e.message
    );
}

#[test]
fn a_denormal_mass_per_length_is_refused_with_the_range() {
    let mut body = with(
        thesis(),
        json!({"profile": {"kind": "constant_rate", "rate_m_s": 10.0}}),
    );
    body["cable"]["mass_per_length_kg_m"] = json!(5e-324);
    let e = error_of("/api/v1/critical", body);
    assert_eq!(e.field.as_deref(), Some("cable.mass_per_length_kg_m"));
    assert!(
        e.message.contains("between 1e-5 and 100 kg/m"),
        "{}",
        e.message
    );
}

#[test]
fn huge_magnitudes_are_refused_with_the_range() {
    for (path, field) in [
        (
            &["aerostat", "net_buoyancy_n"][..],
            "aerostat.net_buoyancy_n",
        ),
        (&["aerostat", "mass_kg"][..], "aerostat.mass_kg"),
        (
            &["cable", "mass_per_length_kg_m"][..],
            "cable.mass_per_length_kg_m",
        ),
        (&["initial_length_m"][..], "initial_length_m"),
        (&["gravity_m_s2"][..], "gravity_m_s2"),
    ] {
        let mut body = with(thesis(), json!({"state": {"length_m": 500.0}}));
        body["initial_length_m"] = json!(1.0);
        body["gravity_m_s2"] = json!(9.81);
        let leaf = path
            .iter()
            .take(path.len() - 1)
            .fold(&mut body, |v, k| &mut v[*k]);
        leaf[path[path.len() - 1]] = json!(1e308);
        let e = error_of("/api/v1/stability", body);
        assert_eq!(e.field.as_deref(), Some(field));
        assert!(e.message.contains("must be between"), "{}", e.message);
    }
}

#[test]
fn an_absurd_state_is_refused_not_a_500() {
    let e = error_of(
        "/api/v1/stability",
        with(
            thesis(),
            json!({"state": {"length_m": 500.0, "rate_m_s": 1e160}}),
        ),
    );
    assert_eq!(e.field.as_deref(), Some("state.rate_m_s"));
    assert!(
        e.message.contains("between -1000 and 1000 m/s"),
        "{}",
        e.message
    );
    let e = error_of(
        "/api/v1/stability",
        with(thesis(), json!({"state": {"length_m": 1e-200}})),
    );
    assert_eq!(e.field.as_deref(), Some("state.length_m"));
    assert!(
        e.message.contains("between 0.001 and 1e5 m"),
        "{}",
        e.message
    );
    // the ends of the ranges answer
    for (length, rate) in [(1e-3, 1000.0), (1e5, -1000.0), (1e5, 1000.0), (1e-3, 0.0)] {
        let body = with(
            thesis(),
            json!({"state": {"length_m": length, "rate_m_s": rate}}),
        );
        let (status, text) = post(&app(), "/api/v1/stability", &body);
        assert_eq!(status, 200, "{body} → {text}");
        serde_json::from_str::<StabilityResponse>(&text).unwrap();
    }
}

#[test]
fn a_tiny_ge_base_time_step_is_blamed_on_the_time_step() {
    let body = json!({
        "excitation": "base",
        "cable": {"mass_per_length_kg_m": 0.078},
        "model": {"kind": "geometrically_exact", "elements": 4, "bending_stiffness_n_m2": 1000.0,
                  "stiffness_ratio": 1e5, "inertia_ratio": 1.0},
        "amplitude_m": 0.001,
        "frequencies_rad_s": {"min": 10.0, "max": 100.0, "count": 4},
        "duration_s": 0.5,
        "time_step_s": 1e-12
    });
    let e = error_of("/api/v1/frequency-response", body.clone());
    assert_eq!(e.field.as_deref(), Some("time_step_s"));
    assert!(
        e.message.contains("between 1e-9 and 1000 s"),
        "{}",
        e.message
    );
    // within the range but too many steps for one run: still the time step
    let mut body = body;
    body["time_step_s"] = json!(1e-8);
    let e = error_of("/api/v1/frequency-response", body);
    assert_eq!(e.field.as_deref(), Some("time_step_s"), "{}", e.message);
}

#[test]
fn wrong_types_are_told_in_plain_words() {
    let e = error_of(
        "/api/v1/stability",
        with(thesis(), json!({"state": {"length_m": "500"}})),
    );
    assert_eq!(e.field.as_deref(), Some("state.length_m"));
    assert!(e.message.contains("must be a number"), "{}", e.message);
    assert!(!e.message.contains("f64"), "{}", e.message);
    let e = error_of(
        "/api/v1/stability",
        with(
            thesis(),
            json!({"state": {"length_m": 500.0}, "modes": 2.5}),
        ),
    );
    assert_eq!(e.field.as_deref(), Some("modes"));
    assert!(
        e.message.contains("must be a whole number"),
        "{}",
        e.message
    );
    assert!(!e.message.contains("usize"), "{}", e.message);
    let e = error_of(
        "/api/v1/critical",
        with(
            thesis(),
            json!({"profile": {"kind": "constant_rate", "rate_m_s": 10.0}, "confirm_with_qep": "yes"}),
        ),
    );
    assert!(e.message.contains("must be true or false"), "{}", e.message);
}

#[test]
fn one_initial_state_field_for_both_models() {
    let ge = json!({
        "cable": {"mass_per_length_kg_m": 0.078}, "aerostat": {"net_buoyancy_n": 1000.0},
        "model": {"kind": "geometrically_exact", "elements": 4, "bending_stiffness_n_m2": 1000.0,
                  "stiffness_ratio": 1e5, "inertia_ratio": 1.0},
        "time_step_s": 0.001, "duration_s": 0.01, "initial": {"kind": "rest"}
    });
    let (status, text) = post(&app(), "/api/v1/simulate", &ge);
    assert_eq!(status, 200, "{text}");
    let string = with(
        thesis(),
        json!({"profile": {"kind": "constant_rate", "rate_m_s": 1.0}, "duration_s": 1.0, "initial": {"kind": "rest"}}),
    );
    let (status, text) = post(&app(), "/api/v1/simulate", &string);
    assert_eq!(status, 200, "{text}");
    // the old GE name is gone, and says so
    let mut old = ge;
    old.as_object_mut().unwrap().remove("initial");
    old["initial_state"] = json!("rest");
    let e = error_of("/api/v1/simulate", old);
    assert_eq!(e.field.as_deref(), Some("initial_state"));
    assert!(e.message.contains("`initial`"), "{}", e.message);
}

#[test]
fn a_job_envelope_refuses_unknown_keys() {
    let body = json!({"kind": "critical", "request": with(thesis(), json!({"profile": {"kind": "constant_rate", "rate_m_s": 10.0}})), "priority": 1});
    let e = error_of("/api/v1/jobs", body);
    assert_eq!(e.field.as_deref(), Some("priority"));
    let body = json!({"kind": "batch", "request": [{"kind": "critical", "extra": 1,
        "request": with(thesis(), json!({"profile": {"kind": "constant_rate", "rate_m_s": 10.0}}))}]});
    let e = error_of("/api/v1/jobs", body);
    assert_eq!(e.field.as_deref(), Some("request[0].extra"));
}

/// Item 5: a run past onset states the first unstable time (the profile's
/// t*) and stops at the stated cap instead of printing 1e60 m.
#[test]
fn a_transient_past_divergence_stops_at_the_stated_cap() {
    let body = with(
        thesis(),
        json!({"model": {"elements": 20},
               "profile": {"kind": "constant_rate", "rate_m_s": 10.0, "target_length_m": 3000.0},
               "duration_s": 400.0, "samples": 400,
               "initial": {"kind": "shape", "tip_deflection_m": 0.01}}),
    );
    let (status, text) = post(&app(), "/api/v1/simulate", &body);
    assert_eq!(status, 200, "{text}");
    let v: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(v["stopped_reason"], "magnitude_cap", "{}", v["explanation"]);
    assert_eq!(v["outcome"], "diverged");
    let t_star = v["first_unstable_time_s"].as_f64().unwrap();
    // /critical gives the same onset
    let (_, c) = post(
        &app(),
        "/api/v1/critical",
        &with(
            thesis(),
            json!({"model": {"elements": 20}, "profile": {"kind": "constant_rate", "rate_m_s": 10.0, "target_length_m": 3000.0}}),
        ),
    );
    let c: Value = serde_json::from_str(&c).unwrap();
    assert!((t_star - c["critical_time_s"].as_f64().unwrap()).abs() < 1e-6 * t_star);
    let stop = v["outcome_time_s"].as_f64().unwrap();
    assert!(stop > t_star, "stopped at {stop} s before onset {t_star} s");
    let cap = v["magnitude_cap_m"].as_f64().unwrap();
    let length_at_stop = v["length_m"]
        .as_array()
        .unwrap()
        .last()
        .unwrap()
        .as_f64()
        .unwrap();
    assert!(
        (cap - v["magnitude_cap_lengths_nondim"].as_f64().unwrap() * length_at_stop).abs()
            < 1e-9 * cap
    );
    // every printed deflection is finite and within a step's growth of the cap
    for y in v["tip_deflection_m"].as_array().unwrap() {
        let y = y.as_f64().expect("a number, not null");
        assert!(y.abs() <= 10.0 * cap, "{y} m against the cap {cap} m");
    }
    // before onset the run is small
    let times = v["time_s"].as_array().unwrap();
    let tips = v["tip_envelope_m"].as_array().unwrap();
    for (t, y) in times.iter().zip(tips) {
        if t.as_f64().unwrap() < 0.9 * t_star {
            assert!(y.as_f64().unwrap() < 1.0, "{y} m at {t} s before onset");
        }
    }
}
