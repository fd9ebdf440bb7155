//! The deployment plan (SPEC §7) against independent checks:
//! every schedule sample is stable by the FE QEP of the string with the
//! reserve buoyancy `(1 − r)F` at that state (not the criterion the plan
//! uses), within the winch limits and the tension rating; the duration
//! against the SPEC §7 bound (thesis data: 50.0 s); `feasible: false` past
//! the lift limit; retrieval growth against WKB; the haul-down deadline.

use serde_json::{Value, json};
use tetherplan::contract::plan::{PlanRequest, PlanResponse, plan};
use tetherplan::contract::run::NoProgress;
use tetherplan::numerics::params::{AerostatSystem, Kinematics};
use tetherplan::numerics::plan::schedule::{self, PlanOutcome};
use tetherplan::numerics::plan::{PlanProblem, Winch};
use tetherplan::numerics::string::StringModel;

fn run(body: Value) -> PlanResponse {
    let req: PlanRequest = serde_json::from_value(body).expect("a valid request");
    plan(&req, &NoProgress).expect("an answer")
}

struct Case {
    name: &'static str,
    body: Value,
    rho_a: f64,
    f: f64,
    m: f64,
    reserve: f64,
    max_rate: f64,
    max_acc: f64,
}

fn thesis_body(target: f64, reserve: f64) -> Value {
    json!({
        "cable": {"mass_per_length_kg_m": 0.078},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
        "initial_length_m": 1.0,
        "target_elevation_m": target,
        "winch": {"max_rate_m_s": 40.0, "max_acceleration_m_s2": 2.0},
        "lift_reserve_nondim": reserve,
        "samples": 61
    })
}

fn cases() -> Vec<Case> {
    vec![
        Case {
            name: "thesis data, 1200 m, 40 m/s, 2 m/s², r = 0.05",
            body: thesis_body(1200.0, 0.05),
            rho_a: 0.078,
            f: 1000.0,
            m: 10.0,
            reserve: 0.05,
            max_rate: 40.0,
            max_acc: 2.0,
        },
        Case {
            name: "heavy tether, slow winch",
            body: json!({
                "cable": {"mass_per_length_kg_m": 0.25, "breaking_strength_n": 20000.0},
                "aerostat": {"net_buoyancy_n": 3000.0, "mass_kg": 40.0},
                "initial_length_m": 5.0,
                "target_elevation_m": 1000.0,
                "winch": {"max_rate_m_s": 8.0, "max_acceleration_m_s2": 0.3},
                "lift_reserve_nondim": 0.1,
                "required_safety_factor_nondim": 5.0,
                "samples": 61
            }),
            rho_a: 0.25,
            f: 3000.0,
            m: 40.0,
            reserve: 0.1,
            max_rate: 8.0,
            max_acc: 0.3,
        },
        Case {
            // The static ceiling at 1200 m is 9.3 m/s; braking at up to
            // 6 m/s² > g/2 makes the bound follow that ceiling down, while
            // the plan may brake from above it (the braking raises the roller
            // tension by (m + ρA L)|L̈|): faster than the bound.
            name: "thesis data, tight reserve r = 0.075, 6 m/s² winch",
            body: {
                let mut b = thesis_body(1200.0, 0.075);
                b["winch"]["max_acceleration_m_s2"] = json!(6.0);
                b
            },
            rho_a: 0.078,
            f: 1000.0,
            m: 10.0,
            reserve: 0.075,
            max_rate: 40.0,
            max_acc: 6.0,
        },
    ]
}

/// Independent check: the FE QEP of the string with the reserve buoyancy.
fn qep_stable(c: &Case, l0: f64, elements: usize, k: Kinematics) -> (bool, f64) {
    let sys = AerostatSystem::new(c.rho_a, (1.0 - c.reserve) * c.f, c.m, l0, 9.81).unwrap();
    let model = StringModel::new(sys, elements).unwrap();
    let spectrum = model.spectrum(sys.to_nondim(k)).unwrap();
    (spectrum.is_stable(), spectrum.max_real)
}

#[test]
fn every_sample_is_qep_stable_within_the_limits_and_near_the_bound() {
    for c in cases() {
        let r = run(c.body.clone());
        assert!(r.feasible, "{}: {}", c.name, r.reason);
        let l0 = c.body["initial_length_m"].as_f64().unwrap();
        let allow = c.body["cable"]["breaking_strength_n"]
            .as_f64()
            .map(|b| b / c.body["required_safety_factor_nondim"].as_f64().unwrap());
        let mut tightest = (f64::INFINITY, Kinematics::default());
        for s in &r.schedule {
            let k = Kinematics {
                length_m: s.length_m,
                rate_m_s: s.rate_m_s,
                acceleration_m_s2: s.acceleration_m_s2,
            };
            let (stable, max_re) = qep_stable(&c, l0, 100, k);
            assert!(
                stable,
                "{}: t = {:.2} s, L = {:.1} m, v = {:.2}, a = {:.3}: max Re λ = {max_re:e}",
                c.name, s.time_s, s.length_m, s.rate_m_s, s.acceleration_m_s2
            );
            assert!(s.rate_m_s.abs() <= c.max_rate * (1.0 + 1e-9), "{}", c.name);
            assert!(
                s.acceleration_m_s2.abs() <= c.max_acc * (1.0 + 1e-9),
                "{}",
                c.name
            );
            if let Some(a) = allow {
                assert!(s.max_tension_n <= a * (1.0 + 1e-12), "{}", c.name);
            }
            assert!(s.effective_tension_margin_n >= 0.0, "{}", c.name);
            if s.effective_tension_margin_n < tightest.0 {
                tightest = (s.effective_tension_margin_n, k);
            }
        }
        // The tightest sample also at a fine mesh (the FE converges to the
        // continuum criterion from above: finer is stricter).
        let (stable, max_re) = qep_stable(&c, l0, 400, tightest.1);
        assert!(stable, "{}: tightest sample at n = 400: {max_re:e}", c.name);

        let bound = r.bound.as_ref().expect("a bound");
        let d = r.duration_s.unwrap();
        let excess = d / bound.duration_s - 1.0;
        assert!(
            excess.abs() <= 0.03 || (excess < 0.0 && bound.explanation.contains("faster")),
            "{}: plan {d} s against bound {} s ({})",
            c.name,
            bound.duration_s,
            bound.explanation
        );
        eprintln!(
            "{}: plan {d:.3} s, bound {:.3} s ({:+.2} %), constant rate {:.2} m/s in {:.2} s, saves {:.2} s; \
             min margin {:.3} m/s; transient peak {:.4} m, amplification {:.4}, WKB {:?}",
            c.name,
            bound.duration_s,
            100.0 * excess,
            r.constant_rate.as_ref().unwrap().rate_m_s,
            r.constant_rate.as_ref().unwrap().duration_s,
            r.constant_rate.as_ref().unwrap().time_saved_s,
            r.limits.min_stability_margin_m_s.unwrap(),
            r.transient_check.as_ref().unwrap().peak_tip_deflection_m,
            r.transient_check.as_ref().unwrap().amplification_nondim,
            r.oscillation.as_ref().unwrap().wkb_amplification_nondim,
        );
        let tc = r.transient_check.as_ref().unwrap();
        assert_eq!(tc.outcome, "completed", "{}", c.name);
        // Never slower than the constant-rate plan (up to the grid error of
        // the pass when the two coincide).
        assert!(r.constant_rate.as_ref().unwrap().time_saved_s >= -1e-4 * d);
    }
}

#[test]
fn thesis_plan_meets_the_spec_bound_of_50_s() {
    // 1199 m: 20 s at 2 m/s² to 40 m/s (400 m), 9.975 s cruise, 20 s braking.
    let r = run(thesis_body(1200.0, 0.05));
    let b = r.bound.unwrap();
    assert!((b.duration_s - 49.975).abs() < 1e-3, "{}", b.duration_s);
    let d = r.duration_s.unwrap();
    assert!((d - 49.975).abs() < 0.01, "{d}");
    assert_eq!(format!("{d:.1}"), "50.0");
    // The best constant rate is the static ceiling at 1200 m with the
    // reserve and the margin ε = 1e-3, √(0.999·950/0.078 − 9.81·1200) =
    // 19.88 m/s: 1199/v + v/a.
    let v = (0.999 * 950.0f64 / 0.078 - 9.81 * 1200.0).sqrt();
    let c = r.constant_rate.unwrap();
    assert!((c.rate_m_s / v - 1.0).abs() < 2e-3, "{} vs {v}", c.rate_m_s);
    assert!((c.duration_s - (1199.0 / c.rate_m_s + c.rate_m_s / 2.0)).abs() < 1e-9);
    assert!(c.time_saved_s > 19.0, "{}", c.time_saved_s);
    eprintln!(
        "thesis 1200 m: plan {d:.3} s, constant {:.3} m/s in {:.3} s, saves {:.3} s",
        c.rate_m_s, c.duration_s, c.time_saved_s
    );
    let phases: Vec<&str> = r.phases.iter().map(|p| p.limit.as_str()).collect();
    assert_eq!(
        phases,
        ["winch_acceleration", "winch_rate", "winch_braking"]
    );
}

#[test]
fn beyond_the_lift_limit_is_infeasible_and_names_it() {
    // 1290 m with 5 %: the static limit is 950/(0.078·9.81) = 1241.5 m.
    let r = run(thesis_body(1290.0, 0.05));
    assert!(!r.feasible && !r.go);
    assert_eq!(r.binding_limit.as_deref(), Some("static_lift_limit"));
    // 950/(0.078·9.81) = 1241.5 m, less the margin ε = 1e-3: 1240.3 m.
    assert!(r.reason.contains("1240.3 m"), "{}", r.reason);
    assert!(r.schedule.is_empty() && r.duration_s.is_none());
    // Without the reserve 1290 m is below F/(ρA g) = 1306.9 m: feasible.
    assert!(run(thesis_body(1290.0, 0.0)).feasible);
    // The heavy tether past its limit 2700/(0.25·9.81) = 1100.9 m.
    let mut body = cases()[1].body.clone();
    body["target_elevation_m"] = json!(1150.0);
    let r = run(body);
    assert_eq!(r.binding_limit.as_deref(), Some("static_lift_limit"));
}

#[test]
fn the_tension_rating_limits_braking() {
    // Allowable 1010 N: braking may add at most m|L̈| = 10 N at the
    // aerostat, so |L̈| ≤ 1 m/s² while braking.
    let mut body = thesis_body(1200.0, 0.05);
    body["cable"]["breaking_strength_n"] = json!(5050.0);
    body["required_safety_factor_nondim"] = json!(5.0);
    let r = run(body);
    assert!(r.feasible, "{}", r.reason);
    for s in &r.schedule {
        assert!(
            s.max_tension_n <= 1010.0 * (1.0 + 1e-12),
            "{}",
            s.max_tension_n
        );
        assert!(s.acceleration_m_s2 >= -1.0 - 1e-9);
    }
    assert!(r.phases.iter().any(|p| p.limit == "tension"));
    // Braking 40 → 0 at 1 m/s² takes 40 s instead of 20.
    let d = r.duration_s.unwrap();
    assert!(d > 59.0, "{d}");
    // Below the static tension: nothing works.
    let mut body = thesis_body(1200.0, 0.05);
    body["cable"]["breaking_strength_n"] = json!(4000.0);
    body["required_safety_factor_nondim"] = json!(5.0);
    assert_eq!(run(body).binding_limit.as_deref(), Some("tension_limit"));
}

#[test]
fn the_pass_converges_with_the_grid() {
    // First order in the segment size; the tight-reserve case rides the
    // stability ceiling.
    let p0 = PlanProblem::new(
        AerostatSystem::thesis(),
        1200.0,
        Winch::new(40.0, 6.0).unwrap(),
        0.075,
        None,
    )
    .unwrap();
    let dur = |n: usize| {
        let mut p = p0;
        p.grid_segments = n;
        match schedule::fastest(&p) {
            PlanOutcome::Feasible(s) => {
                assert!(s.worst_violation_n <= 1e-9, "{}", s.worst_violation_n);
                s.duration_s
            }
            PlanOutcome::Infeasible(b) => panic!("{b:?}"),
        }
    };
    let (a, b, c) = (dur(1000), dur(4000), dur(16000));
    eprintln!("tight reserve: {a:.5} {b:.5} {c:.5} s");
    assert!((a - c).abs() < 0.01 * c && (b - c).abs() < 0.003 * c);
    assert!((a - c).abs() >= (b - c).abs());
}

#[test]
fn slow_retrieval_amplification_matches_wkb() {
    // Thesis data hauled in from 600 m to 200 m at 0.5 m/s.
    let r = run(json!({
        "cable": {"mass_per_length_kg_m": 0.078},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
        "initial_length_m": 600.0,
        "target_elevation_m": 200.0,
        "winch": {"max_rate_m_s": 0.5, "max_acceleration_m_s2": 0.05},
        "lift_reserve_nondim": 0.05,
        "samples": 101
    }));
    assert!(r.feasible, "{}", r.reason);
    assert_eq!(r.direction, "retrieval");
    let osc = r.oscillation.unwrap();
    let wkb = osc.wkb_amplification_nondim.unwrap();
    let fe = osc.transient_amplification_nondim.unwrap();
    let wkb_fe = osc.wkb_fe_mode_amplification_nondim.unwrap();
    eprintln!(
        "retrieval 600 → 200 m: transient {fe:.4}, WKB {wkb:.4}, WKB with the FE mode {wkb_fe:.4}"
    );
    // The one-mode WKB (sin(πζ/2), thesis (3.12)) within 5 %; the rest is
    // the assumed shape: with the FE string's own first mode the invariant
    // matches the run to 0.5 % (the run is converged in rate and elements:
    // 0.8711 / 0.8707 / 0.8708 at 1 / 0.5 / 0.25 m/s, 0.8707 at 50–200 elements).
    assert!((fe / wkb - 1.0).abs() < 0.05, "transient {fe} vs WKB {wkb}");
    assert!(
        (fe / wkb_fe - 1.0).abs() < 0.005,
        "transient {fe} vs FE-mode WKB {wkb_fe}"
    );
    // Shortening: the mode energy grows (ψ rises as the cable shortens).
    assert!(osc.wkb_energy_amplification_nondim.unwrap() > 1.0);
    let ret = r.retrieval.unwrap();
    // Hauling in speeds up with L̈ = −0.05 m/s² at 600 m: (m + ρA L)·0.05.
    let rise = (10.0 + 0.078 * 600.0) * 0.05;
    assert!(
        (ret.tension_rise_n - rise).abs() < 0.01 * rise,
        "{} vs {rise}",
        ret.tension_rise_n
    );
    assert!(r.schedule.iter().all(|s| s.rate_m_s <= 1e-12));
}

#[test]
fn a_retrieval_amplification_limit_slows_the_winch_or_names_the_limit() {
    let base = json!({
        "cable": {"mass_per_length_kg_m": 0.078},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
        "initial_length_m": 600.0,
        "target_elevation_m": 200.0,
        "winch": {"max_rate_m_s": 20.0, "max_acceleration_m_s2": 1.0},
        "lift_reserve_nondim": 0.05,
        "samples": 51
    });
    let free = run(base.clone());
    let amp = free
        .oscillation
        .unwrap()
        .transient_amplification_nondim
        .unwrap();
    // A limit far below what any rate gives is named.
    let mut body = base.clone();
    body["max_amplification_nondim"] = json!(0.01);
    let r = run(body);
    assert_eq!(r.binding_limit.as_deref(), Some("amplification_limit"));
    // A limit above the free run's growth changes nothing.
    let mut body = base;
    body["max_amplification_nondim"] = json!(amp * 1.01);
    let r = run(body);
    let o = r.oscillation.unwrap();
    assert!(!o.slowed_for_amplification);
    assert!(o.transient_amplification_nondim.unwrap() <= amp * 1.01);
}

#[test]
fn the_deadline_moves_earlier_as_the_wind_rises_faster() {
    let mut last = f64::INFINITY;
    for slope in [0.001, 0.002, 0.004, 0.008] {
        // 5 m/s now, rising linearly; limit 12 m/s.
        let mut body = thesis_body(1200.0, 0.05);
        body["haul_down"] = json!({
            "forecast": [{"time_s": 0.0, "wind_speed_m_s": 5.0},
                         {"time_s": 10000.0, "wind_speed_m_s": 5.0 + slope * 10000.0}],
            "max_operating_wind_m_s": 12.0
        });
        let r = run(body);
        let h = r.haul_down.unwrap();
        let exceed = 7.0 / slope;
        assert!((h.wind_exceeds_limit_at_s.unwrap() - exceed).abs() < 1e-6);
        // The haul-down from 1200 m to 1 m takes as long as the way up
        // (the same limits; braking is unconstrained by stability when
        // hauling in at these rates).
        let start = h.latest_start_s.unwrap();
        assert!((start - (exceed - h.retrieval_duration_s)).abs() < 1e-9);
        assert!(start < last, "{start} after {last}");
        last = start;
        assert_eq!(h.go, start >= r.duration_s.unwrap(), "{}", h.reason);
    }
    // 875 s until 12 m/s at 0.008 m/s²: go; a gust front in 60 s: no-go.
    let mut body = thesis_body(1200.0, 0.05);
    body["haul_down"] = json!({
        "forecast": [{"time_s": 0.0, "wind_speed_m_s": 5.0}, {"time_s": 60.0, "wind_speed_m_s": 20.0}],
        "max_operating_wind_m_s": 12.0
    });
    let r = run(body);
    assert!(r.feasible && !r.go, "{}", r.reason);
    assert!(r.haul_down.unwrap().reason.starts_with("no-go"));
}

// ------------------------------------------------------------------ jerk

/// Largest `|Δa/Δt|` between consecutive samples (finite differences of
/// the schedule's acceleration; exact for a piecewise-linear `L̈`).
fn finite_difference_jerk(r: &PlanResponse) -> f64 {
    r.schedule
        .windows(2)
        .filter(|w| w[1].time_s > w[0].time_s + 1e-9)
        .map(|w| {
            ((w[1].acceleration_m_s2 - w[0].acceleration_m_s2) / (w[1].time_s - w[0].time_s)).abs()
        })
        .fold(0.0, f64::max)
}

#[test]
fn a_jerk_limited_trapezoid_is_the_seven_segment_s_curve() {
    // Thesis data to 1200 m, 40 m/s, 2 m/s²: the ceiling never binds, so the
    // jerk-limited minimum time is the classical 7-segment S-curve
    // T = D/v + v/a + a/j (v ≥ a²/j: both limits reached).
    for j in [0.5, 1.0, 4.0, 1e4] {
        let mut body = thesis_body(1200.0, 0.05);
        body["winch"]["max_jerk_m_s3"] = json!(j);
        body["samples"] = json!(4001);
        let r = run(body);
        assert!(r.feasible, "{}", r.reason);
        let d = r.duration_s.unwrap();
        let closed = 1199.0 / 40.0 + 40.0 / 2.0 + 2.0 / j;
        assert!((d - closed).abs() < 0.01, "j = {j}: {d} vs {closed}");
        let fd = finite_difference_jerk(&r);
        assert!(
            fd <= j * (1.0 + 1e-6),
            "j = {j}: finite-difference jerk {fd}"
        );
        let jerk = r.jerk.as_ref().unwrap();
        assert!(jerk.peak_jerk_m_s3 <= j * (1.0 + 1e-9));
        assert!((jerk.averaging_window_s - 2.0 / j).abs() < 1e-9);
        // Rest to rest, within the winch limits.
        assert_eq!(r.schedule.first().unwrap().rate_m_s, 0.0);
        assert_eq!(r.schedule.last().unwrap().rate_m_s, 0.0);
        assert!((r.schedule.last().unwrap().length_m - 1200.0).abs() < 1e-9);
        for s in &r.schedule {
            assert!(s.rate_m_s.abs() <= 40.0 * (1.0 + 1e-12));
            assert!(s.acceleration_m_s2.abs() <= 2.0 * (1.0 + 1e-12));
        }
        // The constant-rate comparison has S-curve ramps too.
        let c = r.constant_rate.unwrap();
        let v = c.rate_m_s;
        assert!((c.duration_s - (1199.0 / v + v / 2.0 + 2.0 / j)).abs() < 1e-9 || v < 4.0 / j);
        eprintln!("jerk {j}: plan {d:.4} s, 7-segment S-curve {closed:.4} s, FD jerk {fd:.4}");
    }
}

#[test]
fn jerk_limited_plans_are_qep_stable_within_every_limit() {
    // The tight-reserve case rides the stability ceiling: the averaged
    // schedule is tightened until every instant keeps the margin.
    for (c, j) in cases().into_iter().zip([0.5, 0.05, 2.0]) {
        let mut body = c.body.clone();
        body["winch"]["max_jerk_m_s3"] = json!(j);
        body["samples"] = json!(81);
        let r = run(body.clone());
        assert!(r.feasible, "{}: {}", c.name, r.reason);
        let l0 = body["initial_length_m"].as_f64().unwrap();
        let allow = body["cable"]["breaking_strength_n"]
            .as_f64()
            .map(|b| b / body["required_safety_factor_nondim"].as_f64().unwrap());
        for s in &r.schedule {
            let k = Kinematics {
                length_m: s.length_m,
                rate_m_s: s.rate_m_s,
                acceleration_m_s2: s.acceleration_m_s2,
            };
            let (stable, max_re) = qep_stable(&c, l0, 100, k);
            assert!(
                stable,
                "{}: t = {:.2} s: max Re λ = {max_re:e}",
                c.name, s.time_s
            );
            assert!(s.rate_m_s.abs() <= c.max_rate * (1.0 + 1e-9), "{}", c.name);
            assert!(
                s.acceleration_m_s2.abs() <= c.max_acc * (1.0 + 1e-9),
                "{}",
                c.name
            );
            assert!(s.effective_tension_margin_n >= 0.0, "{}", c.name);
            if let Some(a) = allow {
                assert!(s.max_tension_n <= a * (1.0 + 1e-9), "{}", c.name);
            }
        }
        // Jerk on a dense sampling.
        body["samples"] = json!(6001);
        let dense = run(body);
        let fd = finite_difference_jerk(&dense);
        assert!(fd <= j * (1.0 + 1e-6), "{}: FD jerk {fd} > {j}", c.name);
        let free = run(c.body.clone()).duration_s.unwrap();
        let d = r.duration_s.unwrap();
        assert!(d >= free - 1e-6, "{}: {d} < {free}", c.name);
        eprintln!(
            "{} with jerk {j}: {d:.3} s (without {free:.3} s), window {:.3} s, FD jerk {fd:.4}",
            c.name,
            r.jerk.as_ref().unwrap().averaging_window_s
        );
    }
}

// ------------------------------------------------------------------ wind

fn windy(target_altitude: f64, wind_m_s: f64) -> Value {
    let mut b = thesis_body(target_altitude, 0.05);
    b["wind"] = json!({"flow": {"kind": "uniform", "speed_m_s": wind_m_s}});
    b["cable"]["diameter_m"] = json!(0.006);
    b["aerostat"]["drag_coefficient_nondim"] = json!(0.47);
    b["aerostat"]["reference_area_m2"] = json!(3.0);
    b
}

/// Independent check of a wind sample: the tether equilibrium at that
/// length with the reserve buoyancy, solved here at a finer integration,
/// and the string criterion with the payout terms.
fn wind_margin(s: &tetherplan::contract::plan::dto::PlanSampleOutput, wind_m_s: f64) -> f64 {
    use tetherplan::numerics::tether::{
        Body, Cable, EquilibriumConfig, EquilibriumProblem, WindProfile,
    };
    let eq = EquilibriumProblem {
        cable: Cable {
            mass_per_length_kg_m: 0.078,
            diameter_m: 0.006,
            normal_drag_coefficient: 1.2,
            axial_stiffness_n: None,
            breaking_strength_n: None,
        },
        body: Body {
            net_buoyancy_n: 0.95 * 1000.0,
            drag_coefficient: 0.47,
            lift_coefficient: 0.0,
            reference_area_m2: 3.0,
        },
        wind: WindProfile::uniform(wind_m_s),
        air_density_kg_m3: 1.225,
        tether_length_m: s.length_m,
        gravity_m_s2: 9.81,
    }
    .solve(&EquilibriumConfig {
        steps: 400,
        max_iterations: 60,
        keep_shape: false,
    })
    .unwrap();
    assert!(!eq.slack);
    // Paying out, the aerostat's ascent drag bound: ½ρ C_D A (v² + 2 U v).
    let c_d = 0.5 * 1.225 * 0.47 * 3.0;
    let v = s.rate_m_s.max(0.0);
    eq.min_tension_n
        - (10.0 + 0.078 * s.length_m) * s.acceleration_m_s2
        - 0.078 * s.rate_m_s * s.rate_m_s
        - c_d * (v * v + 2.0 * wind_m_s * v)
}

#[test]
fn wind_lowers_the_reachable_altitude_and_lengthens_the_plan() {
    // Calm air through the wind path (U = 0) is the calm-air plan with the
    // aerostat's ascent drag: its rate ceiling is the closed form
    // √(((1 − r)(1 − ε)F − ρA g L − (m + ρA L)L̈)/(ρA + ½ρ C_D A)).
    let calm = run(thesis_body(1000.0, 0.05));
    let zero = run(windy(1000.0, 0.0));
    let (dc, dz) = (calm.duration_s.unwrap(), zero.duration_s.unwrap());
    assert!(
        dz > 1.1 * dc,
        "the ascent drag slows the plan: {dc} s vs {dz} s"
    );
    assert!((zero.wind.as_ref().unwrap().target_length_m.unwrap() - 1000.0).abs() < 1e-6);
    let c_d = 0.5 * 1.225 * 0.47 * 3.0;
    let mut on_ceiling = 0;
    for s in &zero.schedule {
        let budget = 0.95 * (1.0 - 1e-3) * 1000.0
            - 0.078 * 9.81 * s.length_m
            - (10.0 + 0.078 * s.length_m) * s.acceleration_m_s2;
        let ceiling = (budget / (0.078 + c_d)).sqrt();
        assert!(
            s.rate_m_s <= ceiling * (1.0 + 1e-3),
            "t = {:.2} s: {} m/s above the closed-form ceiling {ceiling} m/s",
            s.time_s,
            s.rate_m_s
        );
        // the reported ceiling has no margin ε
        let reported = ((budget + 0.95 * 1e-3 * 1000.0) / (0.078 + c_d)).sqrt();
        assert!(
            (s.rate_ceiling_m_s - reported).abs() < 1e-9 * reported,
            "t = {:.2} s: reported ceiling {} against {reported}",
            s.time_s,
            s.rate_ceiling_m_s
        );
        if s.rate_m_s >= ceiling * (1.0 - 1e-3) {
            on_ceiling += 1;
        }
    }
    assert!(
        on_ceiling > 10,
        "the plan rides the ceiling ({on_ceiling} samples)"
    );
    let mut last_duration = 0.0;
    let mut last_reach = f64::INFINITY;
    for u in [0.0, 2.0, 4.0, 6.0] {
        let r = run(windy(1000.0, u));
        let w = r.wind.as_ref().unwrap();
        assert!(w.stability_criterion.contains("string tension"));
        assert!(r.feasible, "U = {u}: {}", r.reason);
        let d = r.duration_s.unwrap();
        let l = w.target_length_m.unwrap();
        assert!(d > last_duration, "U = {u}: {d} after {last_duration}");
        assert!(w.reachable_altitude_m < last_reach, "U = {u}");
        // The plan ends at the target altitude.
        let end = r.schedule.last().unwrap();
        assert!(
            (end.altitude_m - 1000.0).abs() < 1e-3 * 1000.0,
            "{}",
            end.altitude_m
        );
        for s in &r.schedule {
            let m = wind_margin(s, u);
            assert!(
                m >= -1e-6 * 950.0,
                "U = {u}: t = {:.2} s: margin {m} N",
                s.time_s
            );
            assert!(s.rate_m_s.abs() <= 40.0 * (1.0 + 1e-12));
        }
        eprintln!(
            "U = {u} m/s: length {l:.1} m for 1000 m, plan {d:.3} s, reachable {:.1} m (lift limit {:.1} m)",
            w.reachable_altitude_m, w.lift_limit_m
        );
        last_duration = d;
        last_reach = w.reachable_altitude_m;
    }
    // Beyond reach: named.
    let r = run(windy(1000.0, 9.0));
    assert!(!r.feasible);
    assert_eq!(
        r.binding_limit.as_deref(),
        Some("wind_blowdown"),
        "{}",
        r.reason
    );
}

// ------------------------------------------------------- transient check

#[test]
fn the_transient_check_is_converged_in_its_table_and_its_step() {
    // The check drives the FE run with a rate table on the schedule's own
    // knots (exact for constant-acceleration pieces). Reference: a uniform
    // table of 2000 intervals and half the time step. Peak tip deflection
    // within 1 %.
    use tetherplan::numerics::plan::retrieval;
    use tetherplan::numerics::profile::Profile;
    use tetherplan::numerics::string::transient::{self, InitialState, Silent, TransientConfig};
    for (reserve, acc) in [(0.05, 2.0), (0.075, 6.0)] {
        let p = PlanProblem::new(
            AerostatSystem::thesis(),
            1200.0,
            Winch::new(40.0, acc).unwrap(),
            reserve,
            None,
        )
        .unwrap();
        let PlanOutcome::Feasible(s) = schedule::fastest(&p) else {
            panic!("feasible")
        };
        let model = StringModel::new(p.system, 50).unwrap();
        let check = retrieval::check_transient(&model, &s, 0.1, &Silent).unwrap();
        let k = 2000;
        let points: Vec<(f64, f64)> = (0..=k)
            .map(|j| {
                let t = s.duration_s * j as f64 / k as f64;
                (t, if j == k { 0.0 } else { s.at(t).rate_m_s })
            })
            .collect();
        let profile = Profile::piecewise_linear_rate(1.0, &points, None).unwrap();
        let config = TransientConfig {
            duration_s: s.duration_s,
            time_step_s: Some(0.5 * check.time_step_s),
            samples: 2000,
            initial: InitialState::Mode {
                mode: 1,
                tip_deflection_m: 0.1,
            },
            aero: None,
            eigen: None,
        };
        let run = transient::simulate(&model, &profile, &config, &Silent).unwrap();
        let peak = run
            .samples
            .iter()
            .map(|x| x.tip_envelope_m.max(x.tip_deflection_m.abs()))
            .fold(0.0, f64::max);
        let rel = check.peak_tip_deflection_m / peak - 1.0;
        eprintln!(
            "r = {reserve}, a = {acc}: check peak {:.5} m ({} steps), reference {peak:.5} m ({} steps): {:+.3} %",
            check.peak_tip_deflection_m,
            check.steps,
            run.steps,
            100.0 * rel
        );
        assert!(rel.abs() < 0.01, "{rel}");
    }
}
