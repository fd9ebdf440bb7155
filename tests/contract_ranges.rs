//! The OpenAPI bounds of every range-checked numeric field equal its
//! validation range ([`tetherplan::numerics::params::ranges`]), and the
//! service enforces exactly that range.
//!
//! One table lists, per job kind, a small valid request, a field path in it
//! and the range the contract checks there. For each row the test
//! 1. walks `openapi/openapi.json` from the kind's request schema along the
//!    path (following `$ref`, `allOf`, and picking the `oneOf` branch the
//!    request matches) and asserts `minimum` / `maximum` equal the range,
//!    inclusive (no `exclusiveMinimum` / `exclusiveMaximum`);
//! 2. submits the request with the value just outside either bound as a job
//!    (validated, nothing run) and asserts a 422 naming the field and the
//!    range (`must be between <min> and <max>`);
//! 3. submits it with each bound itself and asserts no range refusal of
//!    that field (another check may still refuse the combination, e.g. an
//!    answer too large for a job: that names a different reason).
//!
//! A last test reads `src/contract/ranges.rs` and asserts every literal
//! field path it range-checks appears in the table.

use std::collections::BTreeSet;
use std::path::Path;
use std::sync::Arc;

use axum::Router;
use axum::body::Body;
use axum::http::{Request, StatusCode, header};
use http_body_util::BodyExt;
use serde_json::{Value, json};
use tetherplan::api::{self, AppState};
use tetherplan::config::Limits;
use tetherplan::jobs::JobQueue;
use tetherplan::jobs::store::JobStore;
use tetherplan::numerics::params::ranges::*;
use tetherplan::numerics::params::{Range, compact};
use tower::ServiceExt;

// ------------------------------------------------------------- requests

fn merge(mut base: Value, patch: Value) -> Value {
    fn go(a: &mut Value, b: Value) {
        match (a, b) {
            (Value::Object(a), Value::Object(b)) => {
                for (k, v) in b {
                    match a.get_mut(&k) {
                        Some(x) if x.is_object() && v.is_object() => go(x, v),
                        _ => {
                            a.insert(k, v);
                        }
                    }
                }
            }
            (a, b) => *a = b,
        }
    }
    go(&mut base, patch);
    base
}

fn string_system(elements: usize) -> Value {
    json!({
        "cable": {"mass_per_length_kg_m": 0.078},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
        "initial_length_m": 1.0,
        "gravity_m_s2": 9.81,
        "model": {"kind": "linear_string", "elements": elements}
    })
}

fn string_with(patch: Value) -> Value {
    merge(string_system(20), patch)
}

fn ge_system(extra_model: Value) -> Value {
    json!({
        "cable": {"mass_per_length_kg_m": 0.078},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0, "link_length_m": 0.0},
        "initial_length_m": 1.0,
        "gravity_m_s2": 9.81,
        "model": merge(json!({"kind": "geometrically_exact", "elements": 10,
            "bending_stiffness_n_m2": 1000.0, "inertia_ratio": 1.0}), extra_model)
    })
}

fn ge_simulate(patch: Value) -> Value {
    merge(
        merge(
            ge_system(json!({"stiffness_ratio": 1e5, "shear_stiffness_ratio": 1e5})),
            json!({"time_step_s": 0.000883, "duration_s": 0.0883,
                   "damping_per_s": 0.0, "damping_from_s": 0.0}),
        ),
        patch,
    )
}

fn ge_chart(patch: Value) -> Value {
    merge(
        merge(
            ge_system(json!({})),
            json!({"stiffness_ratios": [1e5], "net_buoyancies_n": [1000.0],
                   "rates_m_s": {"min": 100.0, "max": 110.0, "count": 2}}),
        ),
        patch,
    )
}

fn ge_base(patch: Value) -> Value {
    let scale = (0.078f64 / 1000.0).sqrt();
    merge(
        json!({
            "excitation": "base",
            "cable": {"mass_per_length_kg_m": 0.078},
            "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0, "link_length_m": 0.0},
            "initial_length_m": 1.0,
            "gravity_m_s2": 0.0,
            "model": {"kind": "geometrically_exact", "elements": 10, "bending_stiffness_n_m2": 1000.0,
                      "stiffness_ratio": 5.0, "inertia_ratio": 1.0},
            "amplitude_m": 1e-3,
            "frequencies_rad_s": {"min": 1.0 / scale, "max": 3.5 / scale, "count": 3},
            "reference_frequency_rad_s": 1.0 / scale,
            "duration_s": 20.0 * scale,
            "time_step_s": 0.05 * scale,
            "reduced_model_epsilon_nondim": 0.2,
            "profile": {"kind": "constant_rate", "rate_m_s": 0.005 / scale}
        }),
        patch,
    )
}

fn ge_critical(patch: Value) -> Value {
    merge(
        merge(
            ge_system(json!({"stiffness_ratio": 1e5})),
            json!({"profile": {"kind": "constant_rate", "rate_m_s": 40.0},
                   "numerics": {"time_step_s": 0.02, "horizon_s": 100.0, "growth_tolerance_1_s": 1e-6}}),
        ),
        patch,
    )
}

fn ge_stability(patch: Value) -> Value {
    merge(
        merge(
            ge_system(json!({"stiffness_ratio": 1e5})),
            json!({"state": {"length_m": 500.0, "rate_m_s": 10.0, "acceleration_m_s2": 0.0}}),
        ),
        patch,
    )
}

fn simulate(patch: Value) -> Value {
    merge(
        string_with(json!({"initial_length_m": 100.0,
            "profile": {"kind": "constant_rate", "rate_m_s": 1.0},
            "duration_s": 5.0, "samples": 20, "time_step_s": 0.01,
            "initial": {"kind": "rest"}})),
        patch,
    )
}

fn frequency_response(patch: Value) -> Value {
    merge(
        string_with(
            json!({"profile": {"kind": "constant_rate", "rate_m_s": 1.0},
            "duration_s": 10.0, "samples": 10, "time_step_s": 0.01,
            "aero": {"radius_m": 0.5, "air_density_kg_m3": 1.205, "gas_density_kg_m3": 0.17},
            "wind_amplitude_m_s": 10.0,
            "frequencies_rad_s": {"min": 1.0, "max": 4.0, "count": 3}}),
        ),
        patch,
    )
}

fn equilibrium(patch: Value) -> Value {
    merge(
        json!({
            "cable": {"diameter_m": 0.006, "mass_per_length_kg_m": 0.025,
                      "normal_drag_coefficient_nondim": 1.2, "axial_stiffness_n": 850000.0,
                      "breaking_strength_n": 30000.0},
            "aerostat": {"net_buoyancy_n": 2000.0, "mass_kg": 100.0, "drag_coefficient_nondim": 0.3,
                         "lift_coefficient_nondim": 0.0, "reference_area_m2": 20.0,
                         "radius_m": 2.0, "volume_m3": 30.0},
            "tether_length_m": 1000.0,
            "gravity_m_s2": 9.81,
            "required_safety_factor_nondim": 5.0,
            "payout_rate_m_s": 1.0,
            "integration_steps": 100,
            "shape_samples": 51,
            "wind": {"air_density_kg_m3": 1.225, "flow": {"kind": "uniform", "speed_m_s": 8.0}}
        }),
        patch,
    )
}

/// [`equilibrium`] in the wind `flow` (replacing the uniform one).
fn equilibrium_in(flow: Value) -> Value {
    let mut e = equilibrium(json!({}));
    e["wind"]["flow"] = flow;
    e
}

fn envelope(patch: Value) -> Value {
    merge(
        json!({
            "cable": {"diameter_m": 0.006, "mass_per_length_kg_m": 0.025},
            "aerostat": {"net_buoyancy_n": 2000.0, "mass_kg": 100.0, "drag_coefficient_nondim": 0.3,
                         "reference_area_m2": 20.0},
            "wind": {"air_density_kg_m3": 1.225,
                     "flow": {"kind": "power_law", "coefficient_m_s": 0.0, "exponent_nondim": 0.14, "reference_height_m": 10.0}},
            "wind_speeds_m_s": {"min": 0.0, "max": 30.0, "count": 3},
            "tether_lengths_m": {"min": 100.0, "max": 3000.0, "count": 3},
            "required_safety_factor_nondim": 5.0,
            "ceiling_m": 2500.0,
            "gravity_m_s2": 9.81,
            "payout_rate_m_s": 5.0,
            "integration_steps": 100
        }),
        patch,
    )
}

fn plan(patch: Value) -> Value {
    merge(
        json!({
            "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
            "initial_length_m": 1.0,
            "gravity_m_s2": 9.81,
            "target_elevation_m": 1200.0,
            "winch": {"max_rate_m_s": 40.0, "max_acceleration_m_s2": 2.0, "max_jerk_m_s3": 1.0},
            "lift_reserve_nondim": 0.05,
            "cable": {"mass_per_length_kg_m": 0.078, "breaking_strength_n": 20000.0},
            "required_safety_factor_nondim": 5.0,
            "samples": 50,
            "disturbance_tip_deflection_m": 1.0,
            "max_amplification_nondim": 10.0,
            "haul_down": {"forecast": [{"time_s": 0.0, "wind_speed_m_s": 5.0},
                                       {"time_s": 3600.0, "wind_speed_m_s": 15.0}],
                          "max_operating_wind_m_s": 12.0}
        }),
        patch,
    )
}

fn bands_request(patch: Value) -> Value {
    merge(
        json!({
            "cable": {"mass_per_length_kg_m": 0.078},
            "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
            "initial_length_m": 1.0,
            "gravity_m_s2": 9.81,
            "rates_m_s": {"min": 5.0, "max": 30.0, "count": 4},
            "target_elevation_m": 1200.0,
            "uncertainty": {"samples": 10, "seed": 7, "inputs": [
                {"field": "aerostat.net_buoyancy_n", "distribution": "normal", "mean": 1000.0, "std_dev": 50.0}
            ]}
        }),
        patch,
    )
}

fn profile(p: Value) -> Value {
    string_with(json!({ "profile": p }))
}

/// One row: job kind, request, field path, range (inclusive).
struct Case {
    kind: &'static str,
    request: Value,
    path: &'static str,
    range: Range,
    /// The minimum itself is refused (by a positivity check after the range).
    exclusive_min: bool,
    /// The bounds depend on the request (a multiple of `initial_length_m`):
    /// the schema cannot state them.
    in_schema: bool,
}

fn case(kind: &'static str, request: Value, path: &'static str, range: Range) -> Case {
    Case {
        kind,
        request,
        path,
        range,
        exclusive_min: false,
        in_schema: true,
    }
}

fn exclusive(mut c: Case) -> Case {
    c.exclusive_min = true;
    c
}

fn cases() -> Vec<Case> {
    let cr = json!({"kind": "constant_rate", "rate_m_s": 10.0, "target_length_m": 100.0});
    let ca = json!({"kind": "constant_acceleration", "acceleration_m_s2": 0.5, "target_length_m": 100.0});
    let tr = json!({"kind": "trapezoidal", "cruise_rate_m_s": 10.0, "ramp_up_s": 5.0,
                    "ramp_down_s": 5.0, "target_length_m": 1100.0});
    let pw = json!({"kind": "piecewise_linear_rate", "target_length_m": 100.0,
                    "points": [{"time_s": 0.0, "rate_m_s": 10.0}, {"time_s": 10.0, "rate_m_s": 5.0}]});
    let stab = string_with(
        json!({"state": {"length_m": 500.0, "rate_m_s": 10.0, "acceleration_m_s2": 0.0}}),
    );
    let with_density = |d: f64| {
        let mut v = stab.clone();
        v["cable"] = json!({"density_kg_m3": d, "area_m2": 1e-5});
        v
    };
    let flow = |f: Value| simulate(json!({"aero": {"flow": f, "radius_m": 0.5}}));
    let steady = |f: Value| {
        flow(json!({"kind": "perturbed", "base": f,
                                        "amplitude_nondim": 0.5, "wavenumber_1_m": 0.01}))
    };
    // The GE chart's wind: the §9 flow, the drag data on the aerostat.
    let ge_wind = |w: Value| {
        let mut wind = json!({"flow": {"kind": "uniform", "speed_m_s": 5.0},
            "force_model": {"kind": "drag"},
            "radius_m": 1.0, "air_density_kg_m3": 1.12, "amplitudes_nondim": [0.5],
            "wavenumber_1_m": 0.01});
        if let Some(p) = w.get("flow") {
            wind["flow"] = p.clone();
        }
        ge_chart(json!({ "wind": wind,
            "aerostat": {"drag_coefficient_nondim": 0.5, "reference_area_m2": 1.0} }))
    };
    // The tether kinds and the plan state most of their bounds as literals.
    let lit = |kind: &'static str, request: &Value, path: &'static str, min: f64, max: f64| {
        case(kind, request.clone(), path, Range::new(min, max, ""))
    };
    let eq = equilibrium(json!({}));
    let eq_power = equilibrium_in(json!({"kind": "power_law", "coefficient_m_s": 3.0,
                                          "exponent_nondim": 0.14}));
    let eq_table = equilibrium_in(json!({"kind": "tabulated", "points": [
        {"elevation_m": 0.0, "speed_m_s": 2.0}, {"elevation_m": 1000.0, "speed_m_s": 10.0}]}));
    let eq_log = equilibrium_in(json!({"kind": "log_law", "speed_m_s": 8.0,
                                        "reference_height_m": 10.0, "roughness_length_m": 0.03}));
    let env = envelope(json!({}));
    let mut env_log = env.clone();
    env_log["wind"]["flow"] = json!({"kind": "log_law", "speed_m_s": 0.0, "roughness_length_m": 0.03,
                                     "reference_height_m": 10.0});
    let pl = plan(json!({}));
    let eq_gust = equilibrium(
        json!({"wind": {"gust": {"turbulence_intensity_nondim": 0.1, "peak_factor_nondim": 3.0}}}),
    );
    let eq_gust_speed = equilibrium(json!({"wind": {"gust": {"gust_m_s": 12.0}}}));
    let env_floor = envelope(json!({"min_altitude_m": 100.0}));
    let pl_gust = plan(json!({"min_altitude_m": 100.0, "haul_down": {
        "forecast": [{"time_s": 0.0, "wind_speed_m_s": 0.0, "gust_m_s": 1.0},
                     {"time_s": 3600.0, "wind_speed_m_s": 15.0, "gust_m_s": 20.0}],
        "max_operating_wind_m_s": 12.0, "max_gust_m_s": 18.0}}));
    let bands = bands_request(json!({}));
    let plan_ge = json!({
        "cable": {"mass_per_length_kg_m": 0.078},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
        "target_elevation_m": 1000.0,
        "winch": {"max_rate_m_s": 40.0, "max_acceleration_m_s2": 2.0},
        "stability": {"method": "quasi_static_ge", "bending_stiffness_n_m2": 1000.0}
    });
    vec![
        // the plan's quasi-static GE stability
        case(
            "plan",
            plan_ge.clone(),
            "stability.bending_stiffness_n_m2",
            BENDING_STIFFNESS_N_M2,
        ),
        // system of the linear string
        case(
            "stability",
            stab.clone(),
            "cable.mass_per_length_kg_m",
            MASS_PER_LENGTH_KG_M,
        ),
        case(
            "stability",
            with_density(7800.0),
            "cable.density_kg_m3",
            DENSITY_KG_M3,
        ),
        case("stability", with_density(1000.0), "cable.area_m2", AREA_M2),
        case(
            "stability",
            stab.clone(),
            "aerostat.net_buoyancy_n",
            NET_BUOYANCY_N,
        ),
        case(
            "stability",
            stab.clone(),
            "aerostat.mass_kg",
            AEROSTAT_MASS_KG,
        ),
        case(
            "stability",
            stab.clone(),
            "initial_length_m",
            INITIAL_LENGTH_M,
        ),
        case("stability", stab.clone(), "gravity_m_s2", GRAVITY_M_S2),
        case("stability", stab.clone(), "state.length_m", LENGTH_M),
        case("stability", stab.clone(), "state.rate_m_s", RATE_M_S),
        case(
            "stability",
            stab.clone(),
            "state.acceleration_m_s2",
            ACCELERATION_M_S2,
        ),
        // profiles
        case(
            "critical",
            profile(cr.clone()),
            "profile.rate_m_s",
            RATE_M_S,
        ),
        case(
            "critical",
            profile(cr.clone()),
            "profile.target_length_m",
            LENGTH_M,
        ),
        case(
            "critical",
            profile(ca.clone()),
            "profile.acceleration_m_s2",
            ACCELERATION_M_S2,
        ),
        case(
            "critical",
            profile(ca.clone()),
            "profile.target_length_m",
            LENGTH_M,
        ),
        case(
            "critical",
            profile(tr.clone()),
            "profile.cruise_rate_m_s",
            RATE_M_S,
        ),
        case(
            "critical",
            profile(tr.clone()),
            "profile.ramp_up_s",
            DURATION_S,
        ),
        case(
            "critical",
            profile(tr.clone()),
            "profile.ramp_down_s",
            DURATION_S,
        ),
        case(
            "critical",
            profile(tr.clone()),
            "profile.target_length_m",
            LENGTH_M,
        ),
        case(
            "critical",
            profile(pw.clone()),
            "profile.points[1].time_s",
            TIME_S,
        ),
        case(
            "critical",
            profile(pw.clone()),
            "profile.points[0].rate_m_s",
            RATE_M_S,
        ),
        case(
            "critical",
            profile(pw.clone()),
            "profile.target_length_m",
            LENGTH_M,
        ),
        case(
            "safe_rate",
            string_with(json!({"target_elevation_m": 100.0})),
            "target_elevation_m",
            LENGTH_M,
        ),
        // equilibrium (the tether's own bounds, `contract::equilibrium`)
        exclusive(lit("equilibrium", &eq, "cable.diameter_m", 0.0, 1.0)),
        case(
            "equilibrium",
            eq.clone(),
            "cable.mass_per_length_kg_m",
            MASS_PER_LENGTH_KG_M,
        ),
        lit(
            "equilibrium",
            &eq,
            "cable.normal_drag_coefficient_nondim",
            0.0,
            10.0,
        ),
        exclusive(lit(
            "equilibrium",
            &eq,
            "cable.axial_stiffness_n",
            0.0,
            1e12,
        )),
        exclusive(lit(
            "equilibrium",
            &eq,
            "cable.breaking_strength_n",
            0.0,
            1e9,
        )),
        exclusive(lit("equilibrium", &eq, "aerostat.radius_m", 0.0, 100.0)),
        exclusive(lit("equilibrium", &eq, "aerostat.volume_m3", 0.0, 1e7)),
        case(
            "equilibrium",
            eq.clone(),
            "aerostat.mass_kg",
            AEROSTAT_MASS_KG,
        ),
        case(
            "equilibrium",
            eq.clone(),
            "aerostat.net_buoyancy_n",
            NET_BUOYANCY_N,
        ),
        lit(
            "equilibrium",
            &eq,
            "aerostat.drag_coefficient_nondim",
            0.0,
            10.0,
        ),
        lit(
            "equilibrium",
            &eq,
            "aerostat.lift_coefficient_nondim",
            -10.0,
            10.0,
        ),
        exclusive(lit(
            "equilibrium",
            &eq,
            "aerostat.reference_area_m2",
            0.0,
            1e5,
        )),
        exclusive(lit("equilibrium", &eq, "tether_length_m", 0.0, 1e5)),
        exclusive(lit("equilibrium", &eq, "gravity_m_s2", 0.0, 100.0)),
        lit(
            "equilibrium",
            &eq,
            "required_safety_factor_nondim",
            1.0,
            100.0,
        ),
        lit("equilibrium", &eq, "payout_rate_m_s", 0.0, 1000.0),
        lit("equilibrium", &eq, "integration_steps", 8.0, 100_000.0),
        lit("equilibrium", &eq, "shape_samples", 2.0, 10_001.0),
        exclusive(lit("equilibrium", &eq, "wind.air_density_kg_m3", 0.0, 5.0)),
        lit("equilibrium", &eq, "wind.flow.speed_m_s", -150.0, 150.0),
        lit(
            "equilibrium",
            &eq_power,
            "wind.flow.coefficient_m_s",
            -150.0,
            150.0,
        ),
        lit(
            "equilibrium",
            &eq_power,
            "wind.flow.exponent_nondim",
            0.0,
            2.0,
        ),
        lit(
            "equilibrium",
            &eq_table,
            "wind.flow.points[0].elevation_m",
            0.0,
            1e5,
        ),
        lit(
            "equilibrium",
            &eq_table,
            "wind.flow.points[1].speed_m_s",
            -150.0,
            150.0,
        ),
        lit("equilibrium", &eq_log, "wind.flow.speed_m_s", -150.0, 150.0),
        exclusive(lit(
            "equilibrium",
            &eq_log,
            "wind.flow.reference_height_m",
            0.0,
            1e4,
        )),
        lit(
            "equilibrium",
            &eq_log,
            "wind.flow.roughness_length_m",
            1e-6,
            10.0,
        ),
        // envelope (the tether's bounds, and the grids and limits)
        lit("envelope", &env, "wind_speeds_m_s.min", 0.0, 150.0),
        lit("envelope", &env, "wind_speeds_m_s.max", 0.0, 150.0),
        lit("envelope", &env, "wind_speeds_m_s.count", 1.0, 1000.0),
        exclusive(lit("envelope", &env, "tether_lengths_m.min", 0.0, 1e5)),
        exclusive(lit("envelope", &env, "tether_lengths_m.max", 0.0, 1e5)),
        lit("envelope", &env, "tether_lengths_m.count", 1.0, 1000.0),
        exclusive(lit("envelope", &env, "cable.diameter_m", 0.0, 1.0)),
        case(
            "envelope",
            env.clone(),
            "aerostat.net_buoyancy_n",
            NET_BUOYANCY_N,
        ),
        exclusive(lit("envelope", &env, "wind.air_density_kg_m3", 0.0, 5.0)),
        lit("envelope", &env, "wind.flow.exponent_nondim", 0.0, 2.0),
        exclusive(lit(
            "envelope",
            &env,
            "wind.flow.reference_height_m",
            0.0,
            1e4,
        )),
        lit(
            "envelope",
            &env_log,
            "wind.flow.roughness_length_m",
            1e-6,
            10.0,
        ),
        exclusive(lit("envelope", &env, "gravity_m_s2", 0.0, 100.0)),
        lit(
            "envelope",
            &env,
            "required_safety_factor_nondim",
            1.0,
            100.0,
        ),
        exclusive(lit("envelope", &env, "ceiling_m", 0.0, 1e5)),
        lit("envelope", &env, "payout_rate_m_s", 0.0, 1000.0),
        lit("envelope", &env, "integration_steps", 8.0, 100_000.0),
        // plan (the system's ranges, the plan's own bounds)
        case(
            "plan",
            pl.clone(),
            "cable.mass_per_length_kg_m",
            MASS_PER_LENGTH_KG_M,
        ),
        case(
            "plan",
            pl.clone(),
            "aerostat.net_buoyancy_n",
            NET_BUOYANCY_N,
        ),
        case("plan", pl.clone(), "aerostat.mass_kg", AEROSTAT_MASS_KG),
        case("plan", pl.clone(), "initial_length_m", INITIAL_LENGTH_M),
        case("plan", pl.clone(), "gravity_m_s2", GRAVITY_M_S2),
        lit("plan", &pl, "lift_reserve_nondim", 0.0, 0.9),
        lit("plan", &pl, "required_safety_factor_nondim", 1.0, 100.0),
        exclusive(lit("plan", &pl, "cable.breaking_strength_n", 0.0, 1e9)),
        lit("plan", &pl, "target_elevation_m", 1e-3, 1e6),
        exclusive(lit("plan", &pl, "winch.max_rate_m_s", 0.0, 1000.0)),
        exclusive(lit("plan", &pl, "winch.max_acceleration_m_s2", 0.0, 100.0)),
        exclusive(lit("plan", &pl, "winch.max_jerk_m_s3", 0.0, 1e4)),
        lit("plan", &pl, "samples", 2.0, 10_000.0),
        exclusive(lit("plan", &pl, "disturbance_tip_deflection_m", 0.0, 1e3)),
        exclusive(lit("plan", &pl, "max_amplification_nondim", 0.0, 1e6)),
        lit("plan", &pl, "haul_down.forecast[1].time_s", 0.0, 1e9),
        lit(
            "plan",
            &pl,
            "haul_down.forecast[0].wind_speed_m_s",
            0.0,
            200.0,
        ),
        exclusive(lit(
            "plan",
            &pl,
            "haul_down.max_operating_wind_m_s",
            0.0,
            200.0,
        )),
        // gusts (SPEC §10): the system's `wind.gust`, the floor, the forecast's gusts
        lit(
            "equilibrium",
            &eq_gust,
            "wind.gust.turbulence_intensity_nondim",
            0.0,
            1.0,
        ),
        lit(
            "equilibrium",
            &eq_gust,
            "wind.gust.peak_factor_nondim",
            0.0,
            10.0,
        ),
        lit(
            "equilibrium",
            &eq_gust_speed,
            "wind.gust.gust_m_s",
            0.0,
            150.0,
        ),
        lit("envelope", &env_floor, "min_altitude_m", 0.0, 1e5),
        lit("plan", &pl_gust, "min_altitude_m", 0.0, 1e6),
        exclusive(lit("plan", &pl_gust, "haul_down.max_gust_m_s", 0.0, 200.0)),
        lit(
            "plan",
            &pl_gust,
            "haul_down.forecast[0].gust_m_s",
            0.0,
            200.0,
        ),
        // bands (the system's ranges, the ensemble and the grid)
        case(
            "bands",
            bands.clone(),
            "cable.mass_per_length_kg_m",
            MASS_PER_LENGTH_KG_M,
        ),
        case(
            "bands",
            bands.clone(),
            "aerostat.net_buoyancy_n",
            NET_BUOYANCY_N,
        ),
        case("bands", bands.clone(), "aerostat.mass_kg", AEROSTAT_MASS_KG),
        case("bands", bands.clone(), "initial_length_m", INITIAL_LENGTH_M),
        case("bands", bands.clone(), "gravity_m_s2", GRAVITY_M_S2),
        lit("bands", &bands, "uncertainty.samples", 1.0, 100_000.0),
        lit("bands", &bands, "rates_m_s.count", 1.0, 1000.0),
        // chart
        case(
            "chart",
            string_with(json!({"rates_m_s": {"min": 1.0, "max": 120.0, "count": 5},
            "net_buoyancies_n": [1000.0]})),
            "rates_m_s.min",
            POSITIVE_RATE_M_S,
        ),
        case(
            "chart",
            string_with(json!({"rates_m_s": {"min": 1e-6, "max": 120.0, "count": 5},
            "net_buoyancies_n": [1000.0]})),
            "rates_m_s.max",
            POSITIVE_RATE_M_S,
        ),
        case(
            "chart",
            string_with(json!({"rates_m_s": {"min": 1.0, "max": 120.0, "count": 5},
            "net_buoyancies_n": [1000.0]})),
            "net_buoyancies_n[0]",
            NET_BUOYANCY_N,
        ),
        // simulate
        case("simulate", simulate(json!({})), "duration_s", DURATION_S),
        case("simulate", simulate(json!({})), "time_step_s", TIME_STEP_S),
        case(
            "simulate",
            simulate(
                json!({"initial": {"kind": "tip_force", "force_n": 200.0, "duration_s": 1.0}}),
            ),
            "initial.force_n",
            FORCE_N,
        ),
        case(
            "simulate",
            simulate(
                json!({"initial": {"kind": "tip_force", "force_n": 200.0, "duration_s": 1.0}}),
            ),
            "initial.duration_s",
            DURATION_S,
        ),
        case(
            "simulate",
            simulate(json!({"eigenvalues": {"interval_s": 1.0, "count": 2}})),
            "eigenvalues.interval_s",
            DURATION_S,
        ),
        case(
            "simulate",
            flow(json!({"kind": "uniform", "speed_m_s": 5.0})),
            "aero.flow.speed_m_s",
            WIND_SPEED_M_S,
        ),
        case(
            "simulate",
            flow(json!({"kind": "power_law", "coefficient_m_s": 0.1, "exponent_nondim": 0.3})),
            "aero.flow.coefficient_m_s",
            WIND_SPEED_M_S,
        ),
        case(
            "simulate",
            flow(json!({"kind": "power_law", "coefficient_m_s": 0.1, "exponent_nondim": 0.3})),
            "aero.flow.exponent_nondim",
            EXPONENT_NONDIM,
        ),
        case(
            "simulate",
            flow(
                json!({"kind": "sinusoidal", "amplitude_m_s": 10.0, "angular_frequency_rad_s": 2.0}),
            ),
            "aero.flow.amplitude_m_s",
            WIND_SPEED_M_S,
        ),
        case(
            "simulate",
            flow(
                json!({"kind": "sinusoidal", "amplitude_m_s": 10.0, "angular_frequency_rad_s": 2.0}),
            ),
            "aero.flow.angular_frequency_rad_s",
            FREQUENCY_RAD_S,
        ),
        case(
            "simulate",
            flow(
                json!({"kind": "tabulated", "points": [{"elevation_m": 0.0, "speed_m_s": 1.0},
            {"elevation_m": 100.0, "speed_m_s": 4.0}]}),
            ),
            "aero.flow.points[0].elevation_m",
            ELEVATION_M,
        ),
        case(
            "simulate",
            flow(
                json!({"kind": "tabulated", "points": [{"elevation_m": 0.0, "speed_m_s": 1.0},
            {"elevation_m": 1e5, "speed_m_s": 4.0}]}),
            ),
            "aero.flow.points[1].speed_m_s",
            WIND_SPEED_M_S,
        ),
        case(
            "simulate",
            steady(json!({"kind": "uniform", "speed_m_s": 5.0})),
            "aero.flow.amplitude_nondim",
            AMPLITUDE_NONDIM,
        ),
        case(
            "simulate",
            steady(json!({"kind": "uniform", "speed_m_s": 5.0})),
            "aero.flow.wavenumber_1_m",
            WAVENUMBER_1_M,
        ),
        case(
            "simulate",
            steady(json!({"kind": "uniform", "speed_m_s": 5.0})),
            "aero.flow.base.speed_m_s",
            WIND_SPEED_M_S,
        ),
        case(
            "simulate",
            steady(json!({"kind": "power_law", "coefficient_m_s": 0.1, "exponent_nondim": 0.3})),
            "aero.flow.base.exponent_nondim",
            EXPONENT_NONDIM,
        ),
        case(
            "simulate",
            simulate(
                json!({"aero": {"flow": {"kind": "uniform", "speed_m_s": 5.0}, "radius_m": 0.5,
            "model": {"kind": "drag", "drag_coefficient_nondim": 0.5, "reference_area_m2": 1.0}}}),
            ),
            "aero.model.drag_coefficient_nondim",
            DRAG_COEFFICIENT_NONDIM,
        ),
        case(
            "simulate",
            simulate(
                json!({"aero": {"flow": {"kind": "uniform", "speed_m_s": 5.0}, "radius_m": 0.5,
            "model": {"kind": "drag", "drag_coefficient_nondim": 0.5, "reference_area_m2": 1.0}}}),
            ),
            "aero.model.reference_area_m2",
            REFERENCE_AREA_M2,
        ),
        case(
            "simulate",
            flow(json!({"kind": "uniform", "speed_m_s": 5.0})),
            "aero.radius_m",
            RADIUS_M,
        ),
        case(
            "simulate",
            simulate(
                json!({"aero": {"flow": {"kind": "uniform", "speed_m_s": 5.0}, "radius_m": 0.5,
            "air_density_kg_m3": 1.2, "gas_density_kg_m3": 0.17}}),
            ),
            "aero.air_density_kg_m3",
            GAS_DENSITY_KG_M3,
        ),
        case(
            "simulate",
            simulate(
                json!({"aero": {"flow": {"kind": "uniform", "speed_m_s": 5.0}, "radius_m": 0.5,
            "air_density_kg_m3": 1.2, "gas_density_kg_m3": 0.17}}),
            ),
            "aero.gas_density_kg_m3",
            GAS_DENSITY_KG_M3,
        ),
        // the tip deflection of the initial state: within ± initial_length_m
        Case {
            in_schema: false,
            ..case(
                "simulate",
                simulate(json!({"initial": {"kind": "shape", "tip_deflection_m": 0.1}})),
                "initial.tip_deflection_m",
                Range::new(-100.0, 100.0, "m"),
            )
        },
        // frequency response
        case(
            "frequency_response",
            frequency_response(json!({})),
            "duration_s",
            DURATION_S,
        ),
        case(
            "frequency_response",
            frequency_response(json!({})),
            "time_step_s",
            TIME_STEP_S,
        ),
        case(
            "frequency_response",
            frequency_response(json!({})),
            "wind_amplitude_m_s",
            WIND_SPEED_M_S,
        ),
        case(
            "frequency_response",
            frequency_response(json!({})),
            "frequencies_rad_s.min",
            FREQUENCY_RAD_S,
        ),
        case(
            "frequency_response",
            frequency_response(json!({"frequencies_rad_s": {"min": 0.5}})),
            "frequencies_rad_s.max",
            FREQUENCY_RAD_S,
        ),
        case(
            "frequency_response",
            frequency_response(json!({})),
            "aero.radius_m",
            RADIUS_M,
        ),
        case(
            "frequency_response",
            frequency_response(json!({})),
            "aero.air_density_kg_m3",
            GAS_DENSITY_KG_M3,
        ),
        case(
            "frequency_response",
            frequency_response(json!({})),
            "aero.gas_density_kg_m3",
            GAS_DENSITY_KG_M3,
        ),
        // GE simulate
        case(
            "simulate",
            ge_simulate(json!({})),
            "aerostat.net_buoyancy_n",
            NET_BUOYANCY_N,
        ),
        case(
            "simulate",
            ge_simulate(json!({})),
            "aerostat.mass_kg",
            AEROSTAT_MASS_KG,
        ),
        case(
            "simulate",
            ge_simulate(json!({})),
            "aerostat.link_length_m",
            LINK_LENGTH_M,
        ),
        case(
            "simulate",
            ge_simulate(json!({})),
            "initial_length_m",
            INITIAL_LENGTH_M,
        ),
        case(
            "simulate",
            ge_simulate(json!({})),
            "gravity_m_s2",
            GE_GRAVITY_M_S2,
        ),
        case(
            "simulate",
            ge_simulate(json!({})),
            "model.bending_stiffness_n_m2",
            BENDING_STIFFNESS_N_M2,
        ),
        case(
            "simulate",
            ge_simulate(json!({})),
            "model.stiffness_ratio",
            STIFFNESS_RATIO,
        ),
        case(
            "simulate",
            ge_simulate(json!({})),
            "model.shear_stiffness_ratio",
            STIFFNESS_RATIO,
        ),
        case(
            "simulate",
            ge_simulate(json!({})),
            "model.inertia_ratio",
            INERTIA_RATIO,
        ),
        case(
            "simulate",
            ge_simulate(json!({})),
            "time_step_s",
            TIME_STEP_S,
        ),
        case("simulate", ge_simulate(json!({})), "duration_s", DURATION_S),
        case(
            "simulate",
            ge_simulate(json!({})),
            "damping_per_s",
            RATE_1_S,
        ),
        case("simulate", ge_simulate(json!({})), "damping_from_s", TIME_S),
        case(
            "simulate",
            ge_simulate(json!({"profile": cr.clone()})),
            "profile.rate_m_s",
            RATE_M_S,
        ),
        case(
            "simulate",
            ge_simulate(
                json!({"end_load": {"axial_force_n": 1.0, "transverse_force_n": 1.0,
            "moment_n_m": 0.0, "time": {"kind": "held", "ramp_s": 0.1, "hold_s": 0.5}}}),
            ),
            "end_load.axial_force_n",
            FORCE_N,
        ),
        case(
            "simulate",
            ge_simulate(
                json!({"end_load": {"axial_force_n": 1.0, "transverse_force_n": 1.0,
            "moment_n_m": 0.0, "time": {"kind": "held", "ramp_s": 0.1, "hold_s": 0.5}}}),
            ),
            "end_load.transverse_force_n",
            FORCE_N,
        ),
        case(
            "simulate",
            ge_simulate(
                json!({"end_load": {"axial_force_n": 1.0, "transverse_force_n": 1.0,
            "moment_n_m": 0.0, "time": {"kind": "held", "ramp_s": 0.1, "hold_s": 0.5}}}),
            ),
            "end_load.moment_n_m",
            MOMENT_N_M,
        ),
        case(
            "simulate",
            ge_simulate(json!({"end_load": {"axial_force_n": 1.0,
            "time": {"kind": "held", "ramp_s": 0.0, "hold_s": 0.5}}})),
            "end_load.time.hold_s",
            TIME_S,
        ),
        case(
            "simulate",
            ge_simulate(json!({"end_load": {"axial_force_n": 1.0,
            "time": {"kind": "held", "ramp_s": 0.0, "hold_s": 1e7}}})),
            "end_load.time.ramp_s",
            TIME_S,
        ),
        case(
            "simulate",
            ge_simulate(json!({"end_load": {"axial_force_n": 1.0,
            "time": {"kind": "triangle", "peak_s": 1.0, "end_s": 2.0}}})),
            "end_load.time.end_s",
            TIME_S,
        ),
        // the peak must be after the start
        exclusive(case(
            "simulate",
            ge_simulate(json!({"end_load": {"axial_force_n": 1.0,
            "time": {"kind": "triangle", "peak_s": 1.0, "end_s": 1e7}}})),
            "end_load.time.peak_s",
            TIME_S,
        )),
        // GE chart
        case("chart", ge_chart(json!({})), "gravity_m_s2", GRAVITY_M_S2),
        case(
            "chart",
            ge_chart(json!({})),
            "model.bending_stiffness_n_m2",
            BENDING_STIFFNESS_N_M2,
        ),
        case(
            "chart",
            ge_chart(json!({})),
            "model.inertia_ratio",
            INERTIA_RATIO,
        ),
        case(
            "chart",
            ge_chart(json!({})),
            "stiffness_ratios[0]",
            STIFFNESS_RATIO,
        ),
        case(
            "chart",
            ge_chart(json!({})),
            "net_buoyancies_n[0]",
            NET_BUOYANCY_N,
        ),
        case(
            "chart",
            ge_chart(json!({})),
            "rates_m_s.min",
            POSITIVE_RATE_M_S,
        ),
        case(
            "chart",
            ge_chart(json!({"perturbation": {"forces_n": [0.0], "ramp_s": 0.25, "hold_s": 1.0}})),
            "perturbation.forces_n[0]",
            FORCE_N,
        ),
        case(
            "chart",
            ge_chart(json!({"perturbation": {"forces_n": [0.0], "ramp_s": 0.0, "hold_s": 1.0}})),
            "perturbation.hold_s",
            TIME_S,
        ),
        case(
            "chart",
            ge_chart(json!({"perturbation": {"forces_n": [0.0], "ramp_s": 0.25, "hold_s": 1e7}})),
            "perturbation.ramp_s",
            TIME_S,
        ),
        case(
            "chart",
            ge_chart(
                json!({"numerics": {"time_step_s": 0.02, "horizon_s": 100.0, "growth_tolerance_1_s": 1e-6}}),
            ),
            "numerics.time_step_s",
            TIME_STEP_S,
        ),
        case(
            "chart",
            ge_chart(
                json!({"numerics": {"time_step_s": 0.02, "horizon_s": 100.0, "growth_tolerance_1_s": 1e-6}}),
            ),
            "numerics.horizon_s",
            DURATION_S,
        ),
        case(
            "chart",
            ge_chart(
                json!({"numerics": {"time_step_s": 0.02, "horizon_s": 100.0, "growth_tolerance_1_s": 1e-6}}),
            ),
            "numerics.growth_tolerance_1_s",
            RATE_1_S,
        ),
        lit(
            "chart",
            &ge_wind(json!({})),
            "wind.flow.speed_m_s",
            -150.0,
            150.0,
        ),
        lit(
            "chart",
            &ge_wind(
                json!({"flow": {"kind": "power_law", "coefficient_m_s": 0.1, "exponent_nondim": 0.3}}),
            ),
            "wind.flow.coefficient_m_s",
            -150.0,
            150.0,
        ),
        lit(
            "chart",
            &ge_wind(
                json!({"flow": {"kind": "power_law", "coefficient_m_s": 0.1, "exponent_nondim": 0.3}}),
            ),
            "wind.flow.exponent_nondim",
            0.0,
            2.0,
        ),
        lit(
            "chart",
            &ge_wind(
                json!({"flow": {"kind": "tabulated", "points": [{"elevation_m": 0.0, "speed_m_s": 1.0},
            {"elevation_m": 1e5, "speed_m_s": 4.0}]}}),
            ),
            "wind.flow.points[0].elevation_m",
            0.0,
            1e5,
        ),
        lit(
            "chart",
            &ge_wind(
                json!({"flow": {"kind": "tabulated", "points": [{"elevation_m": 0.0, "speed_m_s": 1.0},
            {"elevation_m": 1e5, "speed_m_s": 4.0}]}}),
            ),
            "wind.flow.points[1].speed_m_s",
            -150.0,
            150.0,
        ),
        case("chart", ge_wind(json!({})), "wind.radius_m", RADIUS_M),
        case(
            "chart",
            ge_wind(json!({})),
            "wind.air_density_kg_m3",
            GAS_DENSITY_KG_M3,
        ),
        case(
            "chart",
            ge_wind(json!({})),
            "wind.amplitudes_nondim[0]",
            AMPLITUDE_NONDIM,
        ),
        case(
            "chart",
            ge_wind(json!({})),
            "wind.wavenumber_1_m",
            WAVENUMBER_1_M,
        ),
        // GE base frequency response
        case(
            "frequency_response",
            ge_base(json!({})),
            "amplitude_m",
            BASE_AMPLITUDE_M,
        ),
        case(
            "frequency_response",
            ge_base(json!({})),
            "gravity_m_s2",
            GE_GRAVITY_M_S2,
        ),
        case(
            "frequency_response",
            ge_base(json!({})),
            "initial_length_m",
            INITIAL_LENGTH_M,
        ),
        // the GE grid of frequencies starts above zero
        exclusive(case(
            "frequency_response",
            ge_base(json!({})),
            "frequencies_rad_s.min",
            FREQUENCY_RAD_S,
        )),
        // and every value of it, its end too
        exclusive(case(
            "frequency_response",
            ge_base(json!({"frequencies_rad_s": {"min": 0.5}})),
            "frequencies_rad_s.max",
            FREQUENCY_RAD_S,
        )),
        case(
            "frequency_response",
            ge_base(json!({})),
            "reference_frequency_rad_s",
            FREQUENCY_RAD_S,
        ),
        case(
            "frequency_response",
            ge_base(json!({})),
            "duration_s",
            DURATION_S,
        ),
        case(
            "frequency_response",
            ge_base(json!({})),
            "time_step_s",
            TIME_STEP_S,
        ),
        case(
            "frequency_response",
            ge_base(json!({})),
            "reduced_model_epsilon_nondim",
            EPSILON_NONDIM,
        ),
        // GE critical and stability
        case(
            "critical",
            ge_critical(json!({})),
            "initial_length_m",
            INITIAL_LENGTH_M,
        ),
        case(
            "critical",
            ge_critical(json!({})),
            "gravity_m_s2",
            GE_GRAVITY_M_S2,
        ),
        case(
            "critical",
            ge_critical(json!({})),
            "model.stiffness_ratio",
            STIFFNESS_RATIO,
        ),
        case(
            "critical",
            ge_critical(json!({})),
            "profile.rate_m_s",
            RATE_M_S,
        ),
        case(
            "critical",
            ge_critical(json!({})),
            "numerics.time_step_s",
            TIME_STEP_S,
        ),
        case(
            "critical",
            ge_critical(json!({})),
            "numerics.horizon_s",
            DURATION_S,
        ),
        case(
            "stability",
            ge_stability(json!({})),
            "state.length_m",
            LENGTH_M,
        ),
        case(
            "stability",
            ge_stability(json!({})),
            "state.rate_m_s",
            RATE_M_S,
        ),
        case(
            "stability",
            ge_stability(json!({})),
            "state.acceleration_m_s2",
            ACCELERATION_M_S2,
        ),
        case(
            "stability",
            ge_stability(json!({})),
            "gravity_m_s2",
            GE_GRAVITY_M_S2,
        ),
    ]
}

// ------------------------------------------------------------- JSON paths

/// `a.b[2].c` as keys and indices.
enum Step {
    Key(String),
    Index(usize),
}

fn steps(path: &str) -> Vec<Step> {
    let mut out = Vec::new();
    for part in path.split('.') {
        let (name, rest) = part.split_once('[').unwrap_or((part, ""));
        out.push(Step::Key(name.to_string()));
        for i in rest.split(['[', ']']).filter(|s| !s.is_empty()) {
            out.push(Step::Index(i.parse().unwrap()));
        }
    }
    out
}

fn get<'a>(v: &'a Value, path: &str) -> &'a Value {
    steps(path).iter().fold(v, |v, s| match s {
        Step::Key(k) => &v[k.as_str()],
        Step::Index(i) => &v[*i],
    })
}

fn set(v: &mut Value, path: &str, x: f64) {
    let mut node = v;
    for s in steps(path) {
        node = match s {
            Step::Key(k) => &mut node[k.as_str()],
            Step::Index(i) => &mut node[i],
        };
    }
    *node = json!(x);
}

fn set_integer(v: &mut Value, path: &str, x: i64) {
    let mut node = v;
    for s in steps(path) {
        node = match s {
            Step::Key(k) => &mut node[k.as_str()],
            Step::Index(i) => &mut node[i],
        };
    }
    *node = json!(x);
}

// ------------------------------------------------------------- schema walk

struct Doc(Value);

impl Doc {
    fn deref<'a>(&'a self, s: &'a Value) -> &'a Value {
        match s.get("$ref").and_then(Value::as_str) {
            Some(r) => self.deref(self.0.pointer(r.trim_start_matches('#')).unwrap()),
            None => s,
        }
    }

    /// The object forms `s` may take for `value`: `allOf` parts merged,
    /// `oneOf` / `anyOf` branches the value matches.
    fn forms<'a>(&'a self, s: &'a Value, value: &Value) -> Vec<&'a Value> {
        let s = self.deref(s);
        let mut out = Vec::new();
        if let Some(parts) = s.get("allOf").and_then(Value::as_array) {
            for p in parts {
                out.extend(self.forms(p, value));
            }
        }
        for key in ["oneOf", "anyOf"] {
            if let Some(branches) = s.get(key).and_then(Value::as_array) {
                let matching: Vec<&Value> =
                    branches.iter().filter(|b| self.matches(b, value)).collect();
                assert!(!matching.is_empty(), "no branch of {s} matches {value}");
                out.extend(self.forms(matching[0], value));
            }
        }
        if s.get("properties").is_some() || s.get("items").is_some() || s.get("type").is_some() {
            out.push(s);
        }
        out
    }

    /// A loose structural match: type, required keys, no unknown keys,
    /// string enums, recursively.
    fn matches(&self, s: &Value, value: &Value) -> bool {
        let s = self.deref(s);
        if let Some(parts) = s.get("allOf").and_then(Value::as_array) {
            // an object matches the merge: check keys against the union
            let forms: Vec<&Value> = parts.iter().map(|p| self.deref(p)).collect();
            if !forms.iter().all(|f| self.matches_loose(f, value)) {
                return false;
            }
            if let Some(o) = value.as_object() {
                let known = |k: &String| forms.iter().any(|f| self.has_property(f, k));
                return o.keys().all(known);
            }
            return true;
        }
        for key in ["oneOf", "anyOf"] {
            if let Some(b) = s.get(key).and_then(Value::as_array) {
                return b.iter().any(|b| self.matches(b, value));
            }
        }
        if !self.matches_loose(s, value) {
            return false;
        }
        if let (Some(o), Some(props)) = (value.as_object(), s.get("properties")) {
            return o.keys().all(|k| props.get(k).is_some());
        }
        true
    }

    fn has_property(&self, s: &Value, k: &str) -> bool {
        let s = self.deref(s);
        if s.get("properties").and_then(|p| p.get(k)).is_some() {
            return true;
        }
        ["allOf", "oneOf", "anyOf"].iter().any(|key| {
            s.get(*key)
                .and_then(Value::as_array)
                .is_some_and(|b| b.iter().any(|b| self.has_property(b, k)))
        })
    }

    /// Type, enum, required and the properties present (without the
    /// unknown-key check).
    fn matches_loose(&self, s: &Value, value: &Value) -> bool {
        let s = self.deref(s);
        if s.get("oneOf").is_some() || s.get("anyOf").is_some() || s.get("allOf").is_some() {
            return self.matches(s, value);
        }
        if let Some(t) = s.get("type") {
            let types: Vec<&str> = match t {
                Value::String(t) => vec![t.as_str()],
                Value::Array(a) => a.iter().filter_map(Value::as_str).collect(),
                _ => vec![],
            };
            let ok = types.iter().any(|t| match *t {
                "null" => value.is_null(),
                "object" => value.is_object(),
                "array" => value.is_array(),
                "number" => value.is_number(),
                "integer" => value.is_u64() || value.is_i64(),
                "string" => value.is_string(),
                "boolean" => value.is_boolean(),
                _ => true,
            });
            if !ok {
                return false;
            }
        }
        if let Some(e) = s.get("enum").and_then(Value::as_array)
            && !e.contains(value)
        {
            return false;
        }
        if let Some(o) = value.as_object() {
            if let Some(req) = s.get("required").and_then(Value::as_array)
                && !req.iter().all(|k| o.contains_key(k.as_str().unwrap()))
            {
                return false;
            }
            if let Some(props) = s.get("properties").and_then(Value::as_object) {
                for (k, v) in o {
                    if let Some(p) = props.get(k)
                        && !self.matches(p, v)
                    {
                        return false;
                    }
                }
            }
        }
        true
    }

    /// The schemas that apply to the value at `path` of `request`.
    fn leaf<'a>(&'a self, root: &'a Value, request: &Value, path: &str) -> Vec<&'a Value> {
        let mut current = vec![root];
        let mut value = request;
        for step in steps(path) {
            let mut next = Vec::new();
            for s in &current {
                for f in self.forms(s, value) {
                    match &step {
                        Step::Key(k) => {
                            if let Some(p) = f.get("properties").and_then(|p| p.get(k.as_str())) {
                                next.push(p);
                            }
                        }
                        Step::Index(_) => {
                            if let Some(i) = f.get("items") {
                                next.push(i);
                            }
                        }
                    }
                }
            }
            value = match &step {
                Step::Key(k) => &value[k.as_str()],
                Step::Index(i) => &value[*i],
            };
            assert!(
                !next.is_empty(),
                "{path}: no schema for `{}`",
                match &step {
                    Step::Key(k) => k.clone(),
                    Step::Index(i) => i.to_string(),
                }
            );
            current = next;
        }
        current
            .into_iter()
            .flat_map(|s| self.forms(s, value))
            .filter(|f| f.get("type").is_some())
            .collect()
    }
}

fn doc() -> Doc {
    let text = std::fs::read_to_string("openapi/openapi.json").unwrap();
    Doc(serde_json::from_str(&text).unwrap())
}

/// The `request` schema of a job kind.
fn request_schema<'a>(doc: &'a Doc, kind: &str) -> &'a Value {
    let item = &doc.0["components"]["schemas"]["JobItem"]["oneOf"];
    item.as_array()
        .unwrap()
        .iter()
        .find(|b| b["properties"]["kind"]["enum"][0] == kind)
        .map(|b| &b["properties"]["request"])
        .unwrap_or_else(|| panic!("no job kind {kind}"))
}

#[test]
fn every_schema_bound_equals_its_validation_range() {
    let doc = doc();
    let mut failures = Vec::new();
    for c in cases() {
        if !c.in_schema {
            continue;
        }
        let root = request_schema(&doc, c.kind);
        let leaves = doc.leaf(root, &c.request, c.path);
        assert!(!leaves.is_empty(), "{} {}: no schema", c.kind, c.path);
        for s in leaves {
            let (min_key, other_key) = if c.exclusive_min {
                ("exclusiveMinimum", "minimum")
            } else {
                ("minimum", "exclusiveMinimum")
            };
            let min = s.get(min_key).and_then(Value::as_f64);
            let max = s.get("maximum").and_then(Value::as_f64);
            let exclusive = s.get(other_key).is_some() || s.get("exclusiveMaximum").is_some();
            if min != Some(c.range.min) || max != Some(c.range.max) || exclusive {
                failures.push(format!(
                    "{} {}: schema {min_key} {min:?}, maximum {max:?}{} but validation [{}, {}]",
                    c.kind,
                    c.path,
                    if exclusive {
                        " (and another bound)"
                    } else {
                        ""
                    },
                    c.range.min,
                    c.range.max
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

// ------------------------------------------------------------- service

fn app() -> Router {
    let queue = Arc::new(JobQueue::new(
        JobStore::open_in_memory().unwrap(),
        1,
        Limits::default(),
    ));
    api::router(AppState::new(queue), Path::new("static"))
}

async fn submit(app: &Router, kind: &str, request: &Value) -> (StatusCode, Value) {
    let body = json!({"kind": kind, "request": request});
    let req = Request::builder()
        .method("POST")
        .uri("/api/v1/jobs")
        .header(header::CONTENT_TYPE, "application/json")
        .body(Body::from(serde_json::to_vec(&body).unwrap()))
        .unwrap();
    let resp = app.clone().oneshot(req).await.unwrap();
    let status = resp.status();
    let bytes = resp.into_body().collect().await.unwrap().to_bytes();
    (
        status,
        serde_json::from_slice(&bytes).unwrap_or(Value::Null),
    )
}

/// Whether `message` states the range of `c` on the side of the refused
/// value: `must be between <min> and <max>` (the ranges of
/// `numerics::params`), or `must be at least|above <min> and at most <max>`
/// (the tether kinds), or on the high side `… at most <max>` and, for a
/// minimum of zero excluded, `must be greater than zero` on the low side;
/// bounds written compactly or in full.
fn states_bound(message: &str, c: &Case, low: bool) -> bool {
    let forms = |x: f64| [compact(x), x.to_string()];
    // `pat` followed by the end or a character that cannot continue a number.
    let has = |pat: &str| {
        message.match_indices(pat).any(|(i, _)| {
            !message[i + pat.len()..]
                .starts_with(|ch: char| ch.is_ascii_digit() || ch == '.' || ch == 'e')
        })
    };
    let (min, max) = (forms(c.range.min), forms(c.range.max));
    if min.iter().any(|a| {
        max.iter()
            .any(|b| has(&format!("must be between {a} and {b}")))
    }) {
        return true;
    }
    if low {
        min.iter()
            .any(|a| has(&format!("must be at least {a}")) || has(&format!("must be above {a}")))
            || (c.exclusive_min && c.range.min == 0.0 && has("must be greater than zero"))
    } else {
        max.iter().any(|b| has(&format!("at most {b}")))
    }
}

/// Just outside a bound: a relative step of 1e-6, or 1e-12 at zero.
fn outside(bound: f64, up: bool) -> f64 {
    let step = (bound.abs() * 1e-6).max(1e-12);
    if up { bound + step } else { bound - step }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn values_just_outside_a_range_are_refused_and_its_bounds_accepted() {
    let app = app();
    let mut failures = Vec::new();
    for c in cases() {
        let field = format!("request.{}", c.path);
        assert!(
            get(&c.request, c.path).is_number(),
            "{} {}: not in the request",
            c.kind,
            c.path
        );
        let (status, v) = submit(&app, c.kind, &c.request).await;
        if !status.is_success() {
            failures.push(format!("{} {}: base request refused: {v}", c.kind, c.path));
            continue;
        }
        let text = format!(
            "must be between {} and {}",
            compact(c.range.min),
            compact(c.range.max)
        );
        // Counts step by one and stay integers.
        let integer = get(&c.request, c.path).is_u64();
        let step = |bound: f64, up: bool| {
            if integer {
                bound + if up { 1.0 } else { -1.0 }
            } else {
                outside(bound, up)
            }
        };
        for (value, refused) in [
            (step(c.range.min, false), true),
            (step(c.range.max, true), true),
            (c.range.min, false),
            (c.range.max, false),
        ] {
            let mut r = c.request.clone();
            if integer {
                set_integer(&mut r, c.path, value as i64);
            } else {
                set(&mut r, c.path, value);
            }
            let (status, v) = submit(&app, c.kind, &r).await;
            let named = v["error"]["field"] == field.as_str();
            let low = value <= c.range.min;
            let ranged = v["error"]["message"]
                .as_str()
                .is_some_and(|m| states_bound(m, &c, low));
            if refused && !(status == StatusCode::UNPROCESSABLE_ENTITY && named && ranged) {
                failures.push(format!(
                    "{} {} = {value:e}: expected 422 naming {field} and `{text}`, got {status} {v}",
                    c.kind, c.path
                ));
            }
            if value == c.range.min && c.exclusive_min {
                if !(status == StatusCode::UNPROCESSABLE_ENTITY && named) {
                    failures.push(format!(
                        "{} {} = {value:e} (an exclusive minimum): expected 422 naming {field}, got {status} {v}",
                        c.kind, c.path
                    ));
                }
                continue;
            }
            if !refused && status == StatusCode::UNPROCESSABLE_ENTITY && named && ranged {
                failures.push(format!(
                    "{} {} = {value:e} (a bound) refused: {v}",
                    c.kind, c.path
                ));
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} failures: {failures:#?}",
        failures.len()
    );
}

/// Every literal field path range-checked in `src/contract/ranges.rs` is a
/// row of the table (so a new check cannot go untested).
#[test]
fn every_literal_range_check_is_in_the_table() {
    let src = std::fs::read_to_string("src/contract/ranges.rs").unwrap();
    let covered: BTreeSet<String> = cases()
        .iter()
        .map(|c| {
            let p = c.path.to_string();
            // `points[1].x` / `x[0]` rows cover the `points[{i}].x` / `x` checks
            let mut out = String::new();
            let mut skip = false;
            for ch in p.chars() {
                match ch {
                    '[' => skip = true,
                    ']' => skip = false,
                    _ if !skip => out.push(ch),
                    _ => {}
                }
            }
            out
        })
        .collect();
    let mut missing = Vec::new();
    for (i, _) in src.match_indices(".check(\"") {
        let rest = &src[i + 8..];
        let name = &rest[..rest.find('"').unwrap()];
        if !name.is_empty() && !covered.contains(name) {
            missing.push(name.to_string());
        }
    }
    // `opt(RANGE, "field", ...)` and `each(RANGE, "field", ...)`
    for prefix in ["opt(", "each("] {
        for (i, _) in src.match_indices(prefix) {
            let rest = &src[i..];
            let Some(q) = rest.find('"') else { continue };
            if rest[..q].contains(')') || rest[..q].contains('&') {
                continue;
            }
            let rest = &rest[q + 1..];
            let name = &rest[..rest.find('"').unwrap()];
            if !covered.contains(name) {
                missing.push(name.to_string());
            }
        }
    }
    missing.sort();
    missing.dedup();
    assert!(
        missing.is_empty(),
        "range checks without a row: {missing:?}"
    );
}
