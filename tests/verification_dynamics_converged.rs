//! Converged figures of the dynamic tether (SPEC §5, §11; issue 31 item
//! 2): the peak and minimum winch tension, the peak tension anywhere and
//! the lowest aerostat altitude, each with an error estimate and its safe
//! side, on the 1000 m tether of SPEC §10 (0.078 kg/m, 5 mm, C_n 1.2,
//! EA 1e7 N, no internal damping; F 1000 N, 10 kg, C_D 0.3 on 20 m²).
//!
//! * (a) by default, every figure's error estimate bounds its actual
//!   error against a run at half the chosen step (turbulence; an 8 m/s
//!   haul-in with a winch that stops over 5 s); where the figures do not
//!   converge by the finest default step (an abrupt stop: the tether goes
//!   slack and snaps) the default refuses naming `numerics`;
//! * (b) the observed order of the peak winch tension: about 2 in
//!   turbulence, none in the snap after an abrupt stop (the changes do not
//!   decrease as the step is halved);
//! * (c) a request that fixes the numerics gets the estimate and
//!   `tolerance_enforced: false`;
//! * (d) why a refusal is right: the undamped snap's peak converges in
//!   the segments at an order of about 0.5; and winch ramps, which ring
//!   the axial waves: damped, the default ladder halves on to the step
//!   that resolves them; undamped, it refuses naming them.
//!
//! Figures measured on this tree are printed and in each test's doc.

use serde_json::{Value, json};
use tetherplan::contract::RequestError;
use tetherplan::contract::dynamics::{dynamics, parse_dynamics};
use tetherplan::contract::run::NoProgress;
use tetherplan::numerics::dynamics::converged::{Figures, NAMES, observed_order};
use tetherplan::numerics::dynamics::{self, DynamicsConfig};

/// The §10 tether in `wind` m/s with `extra` fields.
fn request(wind: f64, extra: Value) -> Value {
    let mut v = json!({
        "cable": {"mass_per_length_kg_m": 0.078, "diameter_m": 0.005,
                  "normal_drag_coefficient_nondim": 1.2, "axial_stiffness_n": 1.0e7},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0, "drag_coefficient_nondim": 0.3,
                     "reference_area_m2": 20.0},
        "wind": {"flow": {"kind": "uniform", "speed_m_s": wind}},
        "sample_count": 101,
        "shape_count": 0
    });
    for (k, x) in extra.as_object().unwrap() {
        v[k] = x.clone();
    }
    v
}

fn answer(v: &Value) -> Result<Value, RequestError> {
    let req = parse_dynamics(v.to_string().as_bytes())?;
    Ok(serde_json::to_value(dynamics(&req, &NoProgress)?).unwrap())
}

/// The figures of the request's problem run directly at `h` s on `segments`.
fn figures_at(v: &Value, h: f64, segments: usize) -> Figures {
    let req = parse_dynamics(v.to_string().as_bytes()).unwrap();
    let prepared = req.prepare().unwrap();
    let cfg = DynamicsConfig {
        time_step_s: h,
        segments,
        ..prepared.config.clone()
    };
    Figures::of(&dynamics::simulate(&prepared.problem, &cfg).unwrap())
}

/// (a): the default answer's estimates bound the error against the run
/// at half its step; the safe values are on the safe side.
fn check_default_bounds(name: &str, v: &Value) -> Value {
    let a = answer(v).unwrap();
    let c = &a["converged"];
    let h = c["time_step_s"].as_f64().unwrap();
    let n = c["segments"].as_u64().unwrap() as usize;
    assert_eq!(c["tolerance_enforced"], json!(true));
    assert_eq!(c["tolerance_met"], json!(true));
    let half = figures_at(v, 0.5 * h, n);
    for (i, key) in NAMES.iter().enumerate() {
        let f = &c[key];
        let value = f["value"].as_f64().unwrap();
        let err = f["error_estimate"].as_f64().unwrap();
        let safe = f["safe_value"].as_f64().unwrap();
        let actual = (value - half.values[i]).abs();
        println!(
            "{name}: {key} = {value:.3} ± {err:.3} (safe {safe:.3}) at {h} s, {n} segments; at {} s: {:.3} (|Δ| {actual:.3})",
            0.5 * h,
            half.values[i]
        );
        assert!(actual <= err, "{name} {key}: |Δ| {actual} > estimate {err}");
        let sign = if key.starts_with("peak") { 1.0 } else { -1.0 };
        assert!((safe - (value + sign * err)).abs() <= 1e-9 * value.abs().max(1.0));
    }
    println!("{name}: refinements {}", c["refinements"]);
    a
}

/// One hour is the bench's; two minutes here (von Kármán, I 0.15,
/// L_u 150 m, 8 m/s, seed 7). Measured: the ladder stops at 0.1 s (the
/// figures change by < 0.1 % of the tension scale from 0.2 s).
#[test]
fn turbulence_default_figures_bound_their_error() {
    let v = request(
        8.0,
        json!({
            "tether_length_m": 1000.0,
            "duration_s": 120.0,
            "wind": {"flow": {"kind": "uniform", "speed_m_s": 8.0},
                     "time_history": {"kind": "turbulence", "model": "von_karman",
                                      "turbulence_intensity_nondim": 0.15, "length_scale_m": 150.0,
                                      "seed": 7}}
        }),
    );
    let a = check_default_bounds("turbulence", &v);
    // The safety factor is taken from the safe side of the peak tension.
    assert!(a["explanation"].as_str().unwrap().contains("converged"));
}

/// An 8 m/s haul-in that stops over 5 s (1000 → 800 m at 2 m/s, ramps of
/// 5 s): the winch's finite deceleration keeps the tether taut.
#[test]
fn haul_in_in_wind_with_a_winch_that_stops_over_seconds() {
    let v = request(
        8.0,
        json!({
            "initial_length_m": 1000.0,
            "profile": {"kind": "trapezoidal", "cruise_rate_m_s": -2.0, "ramp_up_s": 5.0,
                        "ramp_down_s": 5.0, "target_length_m": 800.0},
            "duration_s": 130.0
        }),
    );
    check_default_bounds("haul-in 8 m/s, 5 s stop", &v);
}

/// The case: paid out 200 → 1000 m at 2 m/s in calm air, the
/// winch stopping abruptly at 400 s, run to 460 s; and an 8 m/s haul-in
/// 1000 → 800 m at 2 m/s stopping abruptly. The stop leaves the tether
/// slack and it snaps taut; the peaks change by more than 1 % at every
/// halving (calm, 50 segments, peak winch tension: 2341.5, 2274.8,
/// 2414.6, 2414.6, 3058.5, 3187.0, 3087.2, 3703.2, 3856.0 N at 0.1 s down
/// to 0.39 ms): the default refuses naming `numerics` and the reason
/// gives the runs' figures.
#[test]
fn an_abrupt_stop_is_refused_by_default_naming_numerics() {
    for v in [
        request(
            0.0,
            json!({"initial_length_m": 200.0,
                   "profile": {"kind": "constant_rate", "rate_m_s": 2.0, "target_length_m": 1000.0},
                   "duration_s": 460.0}),
        ),
        request(
            8.0,
            json!({"initial_length_m": 1000.0,
                   "profile": {"kind": "constant_rate", "rate_m_s": -2.0, "target_length_m": 800.0},
                   "duration_s": 130.0}),
        ),
    ] {
        match answer(&v) {
            Err(RequestError::Invalid(e)) => {
                println!("{}: {}", e.field, e.reason);
                assert_eq!(e.field, "numerics");
                assert!(e.reason.contains("peak_winch_tension_n"), "{}", e.reason);
                // The cause found in the run, and the physical remedy.
                assert!(e.reason.contains("went slack"), "{}", e.reason);
                assert!(e.reason.contains("ramp_down_s"), "{}", e.reason);
                assert!(e.reason.contains("internal_damping_n_s"), "{}", e.reason);
            }
            other => panic!("expected a refusal naming numerics, got {other:?}"),
        }
    }
}

/// Why the snap of an instantaneous stop is refused and not answered at
/// more segments: undamped, the calm stop's snap peak at 0.1 s is 5062.0,
/// 5526.3, 5843.9 N on 25, 50, 100 segments (measured; 6055.9 N on 200):
/// the changes fall by only 1.46× per halving of the segment length, an
/// order of about 0.55, so 1 % of the peak would need thousands of
/// segments. Asserted: the peak rises with the segments and the observed
/// order lies between 0.3 and 0.9 (below first order).
#[test]
fn an_undamped_snap_converges_only_slowly_in_the_segments() {
    let v = request(
        0.0,
        json!({"initial_length_m": 200.0,
               "profile": {"kind": "constant_rate", "rate_m_s": 2.0, "target_length_m": 1000.0},
               "duration_s": 460.0}),
    );
    let peaks: Vec<f64> = [25, 50, 100]
        .iter()
        .map(|&n| figures_at(&v, 0.1, n).values[0])
        .collect();
    println!("snap peak on 25, 50, 100 segments: {peaks:.1?} N");
    assert!(peaks[0] < peaks[1] && peaks[1] < peaks[2], "{peaks:?}");
    let order = observed_order(peaks[0], peaks[1], peaks[2], 1e-9).expect("changes decrease");
    println!("observed order in the segment length: {order:.2}");
    assert!((0.3..0.9).contains(&order), "{order}");
    // Not within 1 % of its scale between 50 and 100 segments.
    assert!((peaks[2] - peaks[1]) > 0.01 * peaks[2]);
}

/// Closed form: damped, an instantaneous stop strains the winch's
/// segment at `ΔV/l` at once, so the winch tension jumps by the damper's
/// `c ΔV / l` over its static value `F − ρA g L` (calm, 1000 m: 234.8 N).
/// With c = 1e5 N s and ΔV = 2 m/s: 10 234.8 N on 50 segments (l = 20 m),
/// 20 234.8 N on 100: the peak doubles with the segments, so it has no
/// converged value (measured at 0.05 s: 10 220.3 and 20 220.6 N).
/// Asserted: the peak within 1 % of the closed form on 50 and 100
/// segments, at the stop.
#[test]
fn a_damped_instantaneous_stop_takes_the_damper_force_of_one_segment() {
    let mut v = request(
        0.0,
        json!({"initial_length_m": 200.0,
               "profile": {"kind": "constant_rate", "rate_m_s": 2.0, "target_length_m": 1000.0},
               "duration_s": 402.0}),
    );
    v["internal_damping_n_s"] = json!(1e5);
    let rest = 1000.0 - 0.078 * 9.80665 * 1000.0;
    for n in [50, 100] {
        let f = figures_at(&v, 0.05, n);
        let closed = rest + 1e5 * 2.0 / (1000.0 / n as f64);
        println!(
            "{n} segments: peak winch tension {:.1} N at {:.3} s; closed form {closed:.1} N",
            f.values[0], f.times_s[0]
        );
        assert!(
            (f.values[0] - closed).abs() <= 0.01 * closed,
            "{n}: {}",
            f.values[0]
        );
        assert!((f.times_s[0] - 400.0).abs() < 0.01, "{}", f.times_s[0]);
    }
}

/// A winch that starts and stops over 2 s (1 m/s², the §10 tether paid
/// out 200 → 400 m at 2 m/s in calm air): no slack, but the changes of
/// acceleration ring the tether's axial waves (first period 4L/c =
/// 0.0707 s at 200 m), which the default steps do not resolve (measured,
/// peak winch tension at 0.2, 0.1, 0.05 s: 1194.4, 963.8, 992.8 N).
/// Undamped, the default refuses naming the waves, the step they need (a
/// 32nd of the period, 0.00221 s) and the damping: undamped they ring on
/// (paid out to 1000 m, at fixed steps from 0.00625 to 0.0016 s the peak
/// is 969.6, 971.5, 972.3 N but the minimum winch tension 26.3, 25.8,
/// 22.5 N: the last change three times the estimate of the one before).
/// With `internal_damping_n_s` 1e4 the default ladder halves on to
/// 0.0015625 s (peak winch tension 1227.4, 955.0, 959.7, 883.0, 925.1,
/// 931.1, 932.4, 932.5 N from 0.2 s), answering 932.54 ± 0.13 N (932.58 at
/// half the step); a 1 s stop in 8 m/s (1000 → 800 m), to 0.00625 s:
/// 702.18 ± 5.54 N (701.18 at half the step; 927.0, 723.0, 682.3, 696.9,
/// 706.7 N from 0.2 s).
/// Asserted: the refusal and its words; the damped defaults converge
/// below 0.05 s with estimates that bound the error against half the step.
#[test]
fn winch_ramps_converge_by_default_when_damped_and_are_refused_naming_the_waves_when_not() {
    let calm = |damping: f64| {
        request(
            0.0,
            json!({"initial_length_m": 200.0,
                   "profile": {"kind": "trapezoidal", "cruise_rate_m_s": 2.0, "ramp_up_s": 2.0,
                               "ramp_down_s": 2.0, "target_length_m": 400.0},
                   "duration_s": 130.0, "internal_damping_n_s": damping}),
        )
    };
    let c = (1.0e7f64 / 0.078).sqrt();
    let step = 4.0 * 200.0 / c / 32.0;
    match answer(&calm(0.0)) {
        Err(RequestError::Invalid(e)) => {
            println!("{}: {}", e.field, e.reason);
            assert_eq!(e.field, "numerics");
            assert!(e.reason.contains("axial waves"), "{}", e.reason);
            assert!(!e.reason.contains("went slack"), "{}", e.reason);
            assert!(
                e.reason.contains(&format!("{step:.5} s")),
                "{step}: {}",
                e.reason
            );
            assert!(e.reason.contains("internal_damping_n_s"), "{}", e.reason);
        }
        other => panic!("expected a refusal naming numerics, got {other:?}"),
    }
    let a = check_default_bounds("2 s ramps, damped", &calm(1e4));
    let h = a["converged"]["time_step_s"].as_f64().unwrap();
    assert!(h < 0.05 && h >= step / 2.0, "{h}");
    let windy = request(
        8.0,
        json!({"initial_length_m": 1000.0,
               "profile": {"kind": "trapezoidal", "cruise_rate_m_s": -2.0, "ramp_up_s": 1.0,
                           "ramp_down_s": 1.0, "target_length_m": 800.0},
               "duration_s": 130.0, "internal_damping_n_s": 1e4}),
    );
    let a = check_default_bounds("1 s ramps in 8 m/s, damped", &windy);
    assert!(a["converged"]["time_step_s"].as_f64().unwrap() < 0.05);
}

/// (b) Observed orders. Turbulence (two minutes as above) at 0.2, 0.1,
/// 0.05, 0.025, 0.0125, 0.00625 s, measured: the peak winch tension
/// 447.53, 441.86, 445.69, 446.96, 448.10, 448.88 N (orders of successive
/// triples 0.56, 1.60, 0.16, 0.54: no asymptotic order, the changes stay
/// at 0.1–0.5 % of the 1058 N tension scale), the lowest altitude
/// 805.8045, 805.7960, 805.7969, 805.7981, 805.7979, 805.7979 m (orders
/// 3.23, –, 2.28, 7.9). The snap after the calm abrupt stop (50 segments,
/// the request's defaults) at 0.05, 0.025, 0.0125, 0.00625 s: the peak
/// falls in the window after the stop where the step is refined to a
/// sixteenth of a segment's axial period whatever `h`, and the extremes
/// are taken at every sub-step's end, with the acceleration re-solved
/// (`M a = P`) where the refinement starts. Measured: 5526.25 N at every
/// `h` (before, on the outer steps only and with the coarse step's
/// algorithmic acceleration carried in: 3979.0, 4902.9, 5497.3, 5497.3 N;
/// the sub-steps without the re-solve: 5544, 5544, 7353, 6156 N).
/// Asserted: the four agree within 0.01 %.
#[test]
fn observed_order_of_the_peak_winch_tension() {
    let turb = request(
        8.0,
        json!({
            "tether_length_m": 1000.0,
            "duration_s": 120.0,
            "numerics": {"segments": 50, "time_step_s": 0.05},
            "wind": {"flow": {"kind": "uniform", "speed_m_s": 8.0},
                     "time_history": {"kind": "turbulence", "model": "von_karman",
                                      "turbulence_intensity_nondim": 0.15, "length_scale_m": 150.0,
                                      "seed": 7}}
        }),
    );
    let all: Vec<Figures> = [0.2, 0.1, 0.05, 0.025, 0.0125, 0.00625]
        .iter()
        .map(|&h| figures_at(&turb, h, 50))
        .collect();
    for i in 0..4 {
        let q: Vec<f64> = all.iter().map(|f| f.values[i]).collect();
        let o: Vec<Option<f64>> = (0..q.len() - 2)
            .map(|k| observed_order(q[k], q[k + 1], q[k + 2], 1e-9 * q[k + 2].abs()))
            .collect();
        println!("turbulence {}: {q:?}: orders {o:?}", NAMES[i]);
    }
    // The altitude converges at an order near 2 (0.2, 0.1, 0.05 s).
    let z: Vec<f64> = all.iter().map(|f| f.values[3]).collect();
    let p = observed_order(z[0], z[1], z[2], 1e-9 * z[2]).expect("an order");
    assert!((1.5..=4.0).contains(&p), "{p}");
    // The peak winch tension shows no order (the undamped axial modes
    // ring at the percent level) but stays within 1 % of the tension
    // scale of the finest run at every step.
    let scale = all[5].scales()[0];
    for f in &all {
        assert!((f.values[0] - all[5].values[0]).abs() <= 0.01 * scale);
    }
    let snap = request(
        0.0,
        json!({"initial_length_m": 200.0,
               "profile": {"kind": "constant_rate", "rate_m_s": 2.0, "target_length_m": 1000.0},
               "duration_s": 460.0,
               "numerics": {"segments": 50, "time_step_s": 0.025}}),
    );
    let q: Vec<f64> = [0.05, 0.025, 0.0125, 0.00625]
        .iter()
        .map(|&h| figures_at(&snap, h, 50).values[0])
        .collect();
    let orders: Vec<Option<f64>> = (0..2)
        .map(|k| observed_order(q[k], q[k + 1], q[k + 2], 1e-9 * q[k + 2]))
        .collect();
    println!("snap peak winch tension {q:?}: observed orders {orders:?}");
    // The refined window decides it: the outer step does not.
    let worst = q
        .windows(2)
        .map(|w| (w[1] - w[0]).abs() / w[1])
        .fold(0.0, f64::max);
    assert!(worst < 1e-4, "{worst}");
}

/// (c) A request that fixes the numerics gets its run with the estimate
/// from the runs at twice the step and half the segments, and says the
/// tolerance was not enforced (the calm abrupt stop at 0.05 s: not met).
#[test]
fn fixed_numerics_get_the_estimate_and_no_enforced_tolerance() {
    let v = request(
        0.0,
        json!({"initial_length_m": 200.0,
               "profile": {"kind": "constant_rate", "rate_m_s": 2.0, "target_length_m": 1000.0},
               "duration_s": 460.0,
               "numerics": {"segments": 50, "time_step_s": 0.05}}),
    );
    let a = answer(&v).unwrap();
    let c = &a["converged"];
    println!("{c:#}");
    assert_eq!(c["tolerance_enforced"], json!(false));
    assert_eq!(c["time_step_s"], json!(0.05));
    assert_eq!(c["segments"], json!(50));
    let runs = c["refinements"].as_array().unwrap();
    assert_eq!(runs.len(), 3);
    let coarse = &runs[0];
    let fine = &runs[1];
    let half = &runs[2];
    assert_eq!(coarse["time_step_s"], json!(0.1));
    assert_eq!(half["segments"], json!(25));
    for key in NAMES {
        let f = &c[key];
        let expected = (fine[key].as_f64().unwrap() - coarse[key].as_f64().unwrap()).abs()
            + (fine[key].as_f64().unwrap() - half[key].as_f64().unwrap()).abs();
        assert!(
            (f["error_estimate"].as_f64().unwrap() - expected).abs() <= 1e-9 * expected.max(1.0)
        );
        assert_eq!(f["value"], a[key]);
    }
    assert_eq!(c["tolerance_met"], json!(false));
    assert!(a["explanation"].as_str().unwrap().contains("not enforced"));
}
