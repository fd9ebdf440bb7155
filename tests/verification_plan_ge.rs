//! The plan with quasi-static GE stability (`stability.method =
//! quasi_static_ge`, issue 13) against independent checks:
//!
//! * calm air, a flexible tether (EI = 1 N m²): each row of the plan's
//!   critical-rate table against `qs_critical::critical_rate` on the same
//!   GE tether (the inertia-only search, exact in calm air at a constant
//!   rate by Kelvin–Tait–Chetaev), and against the string's closed form
//!   `v* = √((1 − r)F/ρA − gL)` (SPEC §7) within the mesh/bending offset;
//! * in a log-law wind (the bench request): every schedule sample is
//!   stable by a `wind_stability` QEP and an inertia count of the stiffness
//!   computed here, and the duration against the string-criterion plan;
//! * past the QS GE maximum safe length: `feasible: false`,
//!   `quasi_static_ge_limit`;
//! * `stability.method = string` is the default, answer for answer.

use serde_json::{Value, json};
use tetherplan::contract::plan::{PlanRequest, PlanResponse, plan, validate_plan};
use tetherplan::contract::run::NoProgress;
use tetherplan::numerics::ge::qs_critical::{QsOnset, QsSearchConfig, critical_rate};
use tetherplan::numerics::ge::quasi_static::{
    QsConfig, stiffness_negative_count, wind_equilibrium, wind_stability,
};
use tetherplan::numerics::ge::stability::StateMotion;
use tetherplan::numerics::ge::tether_system::{GeTetherOptions, GeTetherSystem, ge_tether_system};
use tetherplan::numerics::params::Kinematics;
use tetherplan::numerics::tether::{Body, Cable, EquilibriumProblem, WindProfile};

fn run(body: &Value) -> PlanResponse {
    let req: PlanRequest = serde_json::from_value(body.clone()).expect("a valid request");
    plan(&req, &NoProgress).expect("an answer")
}

const RHO_A: f64 = 0.078;
const RESERVE_F: f64 = 950.0;

fn calm_body(target: f64, ei: f64, elements: usize) -> Value {
    json!({
        "cable": {"mass_per_length_kg_m": RHO_A, "breaking_strength_n": 20000.0, "diameter_m": 0.006},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0, "drag_coefficient_nondim": 0.47,
                     "reference_area_m2": 3.0},
        "initial_length_m": 1.0,
        "target_elevation_m": target,
        "winch": {"max_rate_m_s": 100.0, "max_acceleration_m_s2": 5.0},
        "lift_reserve_nondim": 0.05,
        "samples": 41,
        "stability": {"method": "quasi_static_ge", "bending_stiffness_n_m2": ei,
                      "elements": elements, "table_samples": 12}
    })
}

fn wind_body(target: f64) -> Value {
    json!({
        "cable": {"mass_per_length_kg_m": RHO_A, "breaking_strength_n": 20000.0, "diameter_m": 0.006},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0, "drag_coefficient_nondim": 0.47,
                     "reference_area_m2": 3.0},
        "initial_length_m": 1.0,
        "target_elevation_m": target,
        "winch": {"max_rate_m_s": 40.0, "max_acceleration_m_s2": 2.0, "max_jerk_m_s3": 1.0},
        "lift_reserve_nondim": 0.05,
        "required_safety_factor_nondim": 5.0,
        "samples": 41,
        "wind": {"flow": {"kind": "log_law", "reference_speed_m_s": 3.0, "roughness_length_m": 0.03}},
        "stability": {"method": "quasi_static_ge", "bending_stiffness_n_m2": 1000.0,
                      "elements": 40, "check_elements": 16, "table_samples": 12, "check_samples": 41}
    })
}

/// The GE tether of a request, built here from its data with the reserve buoyancy.
fn ge_of(
    wind: WindProfile,
    diameter: f64,
    drag: f64,
    ei: f64,
    elements: usize,
    l_ref: f64,
) -> GeTetherSystem {
    let problem = EquilibriumProblem {
        cable: Cable {
            mass_per_length_kg_m: RHO_A,
            diameter_m: diameter,
            normal_drag_coefficient: if drag > 0.0 { 1.2 } else { 0.0 },
            axial_stiffness_n: None,
            breaking_strength_n: None,
        },
        body: Body {
            net_buoyancy_n: RESERVE_F,
            drag_coefficient: drag,
            lift_coefficient: 0.0,
            reference_area_m2: if drag > 0.0 { 3.0 } else { 1.0 },
        },
        wind,
        air_density_kg_m3: 1.225,
        tether_length_m: l_ref,
        gravity_m_s2: 9.81,
    };
    ge_tether_system(
        &problem,
        &GeTetherOptions {
            bending_stiffness_n_m2: ei,
            aerostat_mass_kg: 10.0,
            elements,
        },
    )
    .unwrap()
}

/// Calm air, EI = 1 N m², 80 elements. Each table row (below the cap)
/// against the inertia-only `critical_rate` on an independently built GE
/// tether (the plan's search bisects 16 times an interval of v_cap/12 =
/// 11 m/s: within 2e-3 m/s; the reference bisects to 1e-12), the plan's
/// ceiling there is `√(v*² − ε(1 − r)F/ρA)` to 1e-9, and the GE critical
/// length at that rate, `(v_GE² − v_string²)/g` beyond the string's, is
/// positive (the FE limit converges from above) and below 3 % of the
/// string's lift limit (measured at 80 elements: 2.5 % at 115 m, 1.6 % at 456 m;
/// at 456 m 1.9 % with 40, 0.9 % with 160 elements: mesh convergence plus the small bending
/// offset). The maximum safe length is within 1 % of the string's
/// `(1 − r)F/(ρA g)` (measured 1252.0 m against 1241.5 m).
#[test]
fn calm_ge_table_matches_the_critical_rate_and_the_string() {
    let a = run(&calm_body(1200.0, 1.0, 80));
    let ge = a.ge_stability.as_ref().expect("the GE block");
    let string_limit = RESERVE_F / (RHO_A * 9.81);
    let d = (4.0 * RHO_A / (std::f64::consts::PI * 1000.0)).sqrt();
    let top = ge.table.last().unwrap().length_m;
    let sys = ge_of(
        WindProfile::calm(),
        d,
        0.0,
        1.0,
        80,
        (1.25 * string_limit).max(top),
    );
    let config = QsSearchConfig {
        confirm_with_qep: false,
        scan_points: 32,
        ..QsSearchConfig::default()
    };
    println!(
        "max safe length {:.2} m, string {string_limit:.2} m; interpolation error {:.2} N ({:.2} m)",
        ge.max_safe_length_m, ge.interpolation_error_n, ge.interpolation_error_length_m
    );
    assert!((ge.max_safe_length_m / string_limit - 1.0).abs() < 0.01);
    let eps = 1e-3 * RESERVE_F / RHO_A;
    let mut compared = 0;
    // Below 100 m the tether is within a few bending lengths of the guide
    // and the GE differs from the string by design (only the table is
    // compared there).
    for row in ge
        .table
        .iter()
        .filter(|r| !r.capped && !r.unstable && r.critical_rate_m_s > 0.0)
    {
        let l = row.length_m;
        let reference = critical_rate(
            &sys.model,
            RESERVE_F,
            &sys.air,
            l,
            ge.rate_cap_m_s,
            StateMotion::AtRest,
            &config,
            &|| false,
        )
        .unwrap();
        let QsOnset::During { at } = reference.onset else {
            panic!("{l} m: {:?}", reference.onset)
        };
        let v = row.critical_rate_m_s;
        let string = (RESERVE_F / RHO_A - 9.81 * l).sqrt();
        let offset_m = (v * v - string * string) / 9.81;
        println!(
            "{l:8.2} m: plan table {v:.4} m/s, critical_rate {at:.4} m/s, string {string:.4} m/s, \
             GE critical length +{offset_m:.2} m"
        );
        assert!((v - at).abs() < 2e-3 + 1e-6 * at, "{l}: {v} vs {at}");
        assert!(v <= at + 1e-9, "the table takes the stable end");
        if l >= 100.0 {
            assert!(
                offset_m > 0.0 && offset_m < 0.03 * string_limit,
                "{l}: {offset_m}"
            );
        }
        let ceiling = (v * v - eps).sqrt();
        assert!((row.plan_rate_ceiling_m_s / ceiling - 1.0).abs() < 1e-9);
        compared += 1;
    }
    assert!(compared >= 9, "{compared} rows compared");
}

/// The same flexible tether with a 100 m/s winch, so that the stability
/// ceiling binds: the GE plan's duration against the string plan's. The
/// GE ceiling is higher by the mesh/bending offset (above) and lowered
/// between rows by the lower-neighbour rule (at most
/// `interpolation_error_n`); measured within 1 %, asserted within 3 %.
#[test]
fn calm_ge_duration_against_the_string_plan() {
    let ge = run(&calm_body(1100.0, 1.0, 80));
    let mut body = calm_body(1100.0, 1.0, 80);
    body.as_object_mut().unwrap().remove("stability");
    let string = run(&body);
    let (dg, ds) = (ge.duration_s.unwrap(), string.duration_s.unwrap());
    let g = ge.ge_stability.as_ref().unwrap();
    println!(
        "GE {dg:.3} s, string {ds:.3} s ({:+.2} %); interpolation error {:.2} N; checked {} samples, {} unstable",
        100.0 * (dg / ds - 1.0),
        g.interpolation_error_n,
        g.check.as_ref().unwrap().checked_samples,
        g.check.as_ref().unwrap().unstable_samples
    );
    assert!(ge.feasible && string.feasible);
    assert!((dg / ds - 1.0).abs() < 0.03);
    println!(
        "phases GE {:?}, string {:?}",
        ge.phases
            .iter()
            .map(|p| p.limit.as_str())
            .collect::<Vec<_>>(),
        string
            .phases
            .iter()
            .map(|p| p.limit.as_str())
            .collect::<Vec<_>>()
    );
    assert!(string.phases.iter().any(|p| p.limit == "stability"));
    assert_eq!(g.check.as_ref().unwrap().unstable_samples, 0);
}

/// The bench request (log-law wind 3 m/s at 10 m, jerk limit, rating):
/// every schedule sample (41 evenly spaced plus the phase boundaries) is
/// stable with the reserve by a QEP solved here (`wind_stability` on 16
/// elements: no complex eigenvalue above the roundoff tolerance; real ones
/// are the roundoff splitting of slow pairs, see `judge`) and by the
/// inertia of the stiffness on 40 elements (no negative eigenvalue: no
/// divergence); the plan's own check agrees. The aerostat's ascent drag
/// makes the stability ceiling bind. There the GE criterion with
/// EI = 1000 N m² (bending lifts its onset) allows a little more than the
/// string's: measured GE 65.5 s against string 66.6 s. Before the
/// ascent drag was counted, the ceiling did not bind and both were equal.
#[test]
fn wind_ge_plan_every_sample_is_stable() {
    let body = wind_body(1000.0);
    let a = run(&body);
    assert!(a.feasible, "{}", a.reason);
    let g = a.ge_stability.as_ref().unwrap();
    let chk = g.check.as_ref().unwrap();
    assert_eq!(chk.unstable_samples, 0);
    let wind = WindProfile::log_law(3.0, 10.0, 0.03, "wind").unwrap();
    let fine = ge_of(
        wind.clone(),
        0.006,
        0.47,
        1000.0,
        40,
        RESERVE_F / (RHO_A * 9.81),
    );
    let coarse = ge_of(wind, 0.006, 0.47, 1000.0, 16, RESERVE_F / (RHO_A * 9.81));
    let mut worst = f64::NEG_INFINITY;
    for s in &a.schedule {
        let kin = Kinematics {
            length_m: s.length_m,
            rate_m_s: s.rate_m_s,
            acceleration_m_s2: s.acceleration_m_s2,
        };
        let w = wind_stability(
            &coarse.model,
            kin,
            coarse.tip_load,
            &coarse.air,
            StateMotion::AtRest,
            &QsConfig::default(),
            None,
        )
        .unwrap();
        let growth = w
            .spectrum
            .eigenvalues
            .iter()
            .filter(|e| e.im != 0.0)
            .map(|e| e.re)
            .fold(f64::NEG_INFINITY, f64::max);
        assert!(growth <= w.spectrum.tolerance(), "t {}: {growth}", s.time_s);
        worst = worst.max(growth);
        let eq = wind_equilibrium(
            &fine.model,
            kin,
            fine.tip_load,
            &fine.air,
            &QsConfig::default(),
            None,
        )
        .unwrap();
        assert_eq!(
            stiffness_negative_count(&fine.model, kin, fine.tip_load, &fine.air, &eq.q),
            Some(0),
            "t {}",
            s.time_s
        );
    }
    let mut string_body = body.clone();
    string_body.as_object_mut().unwrap().remove("stability");
    let string = run(&string_body);
    let (dg, ds) = (a.duration_s.unwrap(), string.duration_s.unwrap());
    println!(
        "{} samples, worst complex growth {worst:.3e} 1/s; plan check worst {:?}; GE {dg:.3} s, string {ds:.3} s; \
         max safe length {:.1} m",
        a.schedule.len(),
        chk.worst_max_real_1_s,
        g.max_safe_length_m
    );
    assert!(
        (dg - ds).abs() <= 0.05 * ds,
        "GE {dg} s against string {ds} s"
    );
}

/// Past the QS GE maximum safe length (calm and wind): infeasible, the
/// GE limit named, and the limit reported is the table's last row within
/// the lower-neighbour interpolation error (its bisection is on the
/// interpolated table) and the margin ε.
#[test]
fn beyond_the_ge_max_safe_length_is_infeasible() {
    for body in [calm_body(1300.0, 1.0, 40), wind_body(1300.0)] {
        let a = run(&body);
        assert!(!a.feasible);
        assert_eq!(
            a.binding_limit.as_deref(),
            Some("quasi_static_ge_limit"),
            "{}",
            a.reason
        );
        let g = a.ge_stability.as_ref().unwrap();
        println!(
            "{}; table max safe length {:.2} m",
            a.reason, g.max_safe_length_m
        );
        assert!(a.limits.lift_limit_m < 1300.0);
        assert!(a.limits.lift_limit_m <= g.max_safe_length_m);
        let slack = g.interpolation_error_length_m + 1e-3 * RESERVE_F / (RHO_A * 9.81) + 1e-6;
        println!(
            "lift limit {:.2} m, table {:.2} m, allowed gap {slack:.2} m",
            a.limits.lift_limit_m, g.max_safe_length_m
        );
        assert!(a.limits.lift_limit_m >= g.max_safe_length_m - slack);
    }
}

/// `stability.method = string` (and the GE fields ignored) is the default.
#[test]
fn string_method_is_the_default_answer() {
    let mut with = wind_body(1000.0);
    with["stability"] = json!({"method": "string"});
    let mut without = wind_body(1000.0);
    without.as_object_mut().unwrap().remove("stability");
    let (a, b) = (run(&with), run(&without));
    assert_eq!(a.duration_s, b.duration_s);
    assert_eq!(a.schedule, b.schedule);
    assert!(a.ge_stability.is_none());
}

/// Field paths and ranges of the GE options.
#[test]
fn ge_options_are_validated() {
    for (patch, field) in [
        (json!({"elements": 3}), "stability.elements"),
        (json!({"elements": 2001}), "stability.elements"),
        (json!({"check_elements": 101}), "stability.check_elements"),
        (json!({"table_samples": 2}), "stability.table_samples"),
        (json!({"check_samples": 1}), "stability.check_samples"),
        (
            json!({"bending_stiffness_n_m2": 0.0}),
            "stability.bending_stiffness_n_m2",
        ),
    ] {
        let mut body = calm_body(1000.0, 1.0, 40);
        for (k, v) in patch.as_object().unwrap() {
            body["stability"][k] = v.clone();
        }
        let req: PlanRequest = serde_json::from_value(body).unwrap();
        let e = validate_plan(&req).unwrap_err().to_string();
        assert!(e.contains(field), "{e}");
    }
}

/// The table's stated interpolation error is over the lengths where the
/// interpolated `S` can limit a schedule (issue 21: "the plan's table
/// error is bounded on the safe side"; it used to read 283 m of length,
/// all of it from the first interval, 1–114 m, where the bending offset
/// D = S − S₀ falls from about 200 N to 7 N at rates above 100 m/s).
/// Recomputed here from the answer's rows: `D_k = ρA v_k² − S₀(L_k)`,
/// an interval can bind when `S₀(L) + min D < (m + ρA L) a_max + ρA
/// v_max² + ε(1 − r)F` at its longer end (the plan also takes off a
/// curvature margin, which only adds intervals and error). The stated
/// bound covers every such jump, is below the bound over all lengths,
/// and is below 1 m of length on the converged calm table; a finer table
/// (48 rows) gives the same schedule.
#[test]
fn calm_interpolation_error_is_stated_where_it_can_bind() {
    let body = |rows: usize| {
        let mut b = calm_body(1000.0, 1.0, 20);
        b["winch"] = json!({"max_rate_m_s": 40.0, "max_acceleration_m_s2": 2.0});
        b["stability"] = json!({"method": "quasi_static_ge", "table_samples": rows});
        b
    };
    let a = run(&body(12));
    let g = a.ge_stability.as_ref().unwrap();
    assert!(g.converged);
    let s0 = |l: f64| RESERVE_F - RHO_A * 9.81 * l;
    let rows: Vec<_> = g
        .table
        .iter()
        .filter(|r| !r.capped && !r.unstable)
        .collect();
    let d: Vec<f64> = rows
        .iter()
        .map(|r| RHO_A * r.critical_rate_m_s.powi(2) - s0(r.length_m))
        .collect();
    let (mut binding, mut all) = (0.0f64, 0.0f64);
    for k in 0..rows.len() - 1 {
        let jump = (d[k + 1] - d[k]).abs();
        all = all.max(jump);
        let l = rows[k + 1].length_m;
        let demand = (10.0 + RHO_A * l) * 2.0 + RHO_A * 40.0f64.powi(2) + 1e-3 * RESERVE_F;
        if s0(l) + d[k].min(d[k + 1]) < demand {
            binding = binding.max(jump);
        }
    }
    println!(
        "stated {:.3} N ({:.3} m), recomputed binding jumps {binding:.3} N; all lengths {:.1} N (recomputed {all:.1} N)",
        g.interpolation_error_n,
        g.interpolation_error_length_m,
        g.interpolation_error_all_lengths_n
    );
    assert!(all > 100.0, "the first interval's bending offset: {all}");
    assert!(g.interpolation_error_n >= binding - 1e-9);
    assert!(g.interpolation_error_all_lengths_n >= all - 1e-9);
    assert!(g.interpolation_error_n <= g.interpolation_error_all_lengths_n);
    assert!(
        g.interpolation_error_length_m < 1.0,
        "{}",
        g.interpolation_error_length_m
    );
    let fine = run(&body(48));
    assert_eq!(fine.duration_s, a.duration_s);
}
