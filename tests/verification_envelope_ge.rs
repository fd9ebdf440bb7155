//! The operating envelope judged by the quasi-static GE stability (issue 12):
//! a tether of Table 7.1's line (ρA = 0.078 kg/m, d = 3.6 mm, C_n = 1.2,
//! inextensible), an aerostat of F = 1000 N, m = 10 kg, C_D A = 0.9 m²,
//! a nearly flexible tether (EI = 10 N m²), payout rate 30 m/s, uniform wind.
//!
//! * calm air: the stability boundary of the grid brackets the per-wind QS
//!   GE `critical_length` (same model), which is within 3 % of the string's
//!   `h* = (F/ρA − v²)/g` (mesh convergence printed at 10/20/40 elements);
//! * the envelope's GE cells (through the JSON contract) are the single-point
//!   `wind_stability` answers;
//! * in wind: `critical_length` against a dense scan of `wind_stability`
//!   over the length, `critical_rate` against a scan over the rate;
//! * the maximum safe altitude against wind speed (printed and checked
//!   against the scan at each wind).

use serde_json::{Value, json};
use tetherplan::contract::envelope::dto::{EnvelopeRequest, EnvelopeResponse};
use tetherplan::contract::envelope::envelope;
use tetherplan::contract::run::NoProgress;
use tetherplan::numerics::parallel::Parallelism;
use tetherplan::numerics::tether::envelope_ge::{GeStabilitySpec, cell_stability, ge_system};

const RATE: f64 = 30.0;

fn request(winds: (f64, f64, usize), lengths: (f64, f64, usize), elements: usize) -> Value {
    json!({
        "cable": {"mass_per_length_kg_m": 0.078, "diameter_m": 0.0036,
                  "normal_drag_coefficient_nondim": 1.2},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0, "drag_coefficient_nondim": 0.3,
                     "reference_area_m2": 3.0},
        "wind": {"flow": {"kind": "uniform", "speed_m_s": 0.0}, "air_density_kg_m3": 1.225},
        "wind_speeds_m_s": {"min": winds.0, "max": winds.1, "count": winds.2},
        "tether_lengths_m": {"min": lengths.0, "max": lengths.1, "count": lengths.2},
        "required_safety_factor_nondim": 1.0,
        "payout_rate_m_s": RATE,
        "stability": {"method": "quasi_static_ge", "bending_stiffness_n_m2": 10.0,
                      "elements": elements, "critical_rate_length_m": 1150.0}
    })
}

fn solve(v: &Value) -> (EnvelopeRequest, EnvelopeResponse) {
    let req: EnvelopeRequest = serde_json::from_value(v.clone()).unwrap();
    let out = envelope(&req, Parallelism::Rayon, &NoProgress).unwrap();
    (req, out)
}

fn string_h(v: f64) -> f64 {
    (1000.0 / 0.078 - v * v) / 9.81
}

/// Calm air: every cell below the first unstable one is stable and every
/// one above unstable (a single boundary), the per-wind QS GE critical
/// length lies between the last stable and the first unstable grid length
/// (26.5 m apart), and it is near the string's h*
/// (measured: +6.0 % at 10, +3.0 % at 20, +1.9 % at 40 elements: the
/// error falls by 2.6 from 10 to 20 and 1.6 from 20 to 40 elements, about
/// first order in the element length as the string's own FE onset; the
/// bending offset ∝ (EI/ρA g)^{1/3} ≈ 2.4 m is 0.2 % here). Asserted: below
/// 3.5 % at 20 and 2 % at 40 elements, each doubling cutting it by ≥ 1/3.
#[test]
fn calm_boundary_is_the_critical_length_and_near_the_string() {
    let h = string_h(RATE);
    let mut boundary = Vec::new();
    for elements in [10usize, 20, 40] {
        let (_, out) = solve(&request((0.0, 0.0, 1), (100.0, 1400.0, 50), elements));
        let ge = out.quasi_static_ge.as_ref().unwrap();
        let w = &ge.per_wind[0];
        assert_eq!(w.critical_length_outcome, "during");
        let l_crit = w.critical_length_m.unwrap();
        let first = out
            .points
            .iter()
            .position(|p| p.stable == Some(false))
            .expect("an unstable cell");
        assert!(first > 0);
        for (j, p) in out.points.iter().enumerate() {
            assert_eq!(p.stable, Some(j < first), "cell {j}");
            // past F/(ρA g) = 1306.9 m the tether is slack: judged by the static limit
            let limit = if j < first {
                None
            } else if p.slack {
                Some("slack")
            } else {
                Some("stability")
            };
            assert_eq!(p.binding_limit.as_deref(), limit, "cell {j}");
            assert_eq!(p.max_growth_rate_1_s.is_some(), !p.slack, "cell {j}");
        }
        assert!(!out.points[first].slack);
        let (lo, hi) = (
            out.points[first - 1].tether_length_m,
            out.points[first].tether_length_m,
        );
        println!(
            "{elements} elements: grid boundary ({lo:.1}, {hi:.1}] m, QS GE critical length {l_crit:.2} m \
             (altitude {:.2} m), string h* {h:.2} m ({:+.2} %)",
            w.critical_altitude_m.unwrap(),
            100.0 * (l_crit / h - 1.0)
        );
        assert!(lo <= l_crit && l_crit <= hi, "{lo} {l_crit} {hi}");
        // calm air: straight tether, altitude = length (inextensible: strain ≤ 1e-5)
        assert!((w.critical_altitude_m.unwrap() / l_crit - 1.0).abs() < 2e-5);
        boundary.push(l_crit);
    }
    let err: Vec<f64> = boundary.iter().map(|b| b / h - 1.0).collect();
    assert!(err[1] > 0.0 && err[1] < 0.035, "{err:?}");
    assert!(err[2] > 0.0 && err[2] < 0.02, "{err:?}");
    assert!(err[2] < 0.65 * err[1] && err[1] < 0.65 * err[0], "{err:?}");
}

/// Every GE cell of the envelope (JSON contract) is the single-point
/// `wind_stability` answer: (a) started, as the envelope does, from the
/// shorter neighbour's equilibrium, chained here by the test itself: the
/// same growth rate to 1e-12 1/s; (b) started from scratch (straight calm
/// equilibrium, then the wind load continued): the same verdict and growth
/// rate within 0.1 of the spectrum's tolerance (≈ 4e-5 1/s: the two Newton
/// solves stop at the same tolerance from different starts; measured up to
/// 6.5e-6 1/s) wherever that start finds the tensioned equilibrium.
/// In strong wind on long tethers (10 m/s at 1150 m, 15 m/s at 1000 m) the
/// scratch start lands on a compressed branch (root axial force −187 N and
/// −359 N, growth 1.9 and 2.0 1/s): that is why the envelope continues
/// along the length; those cells are counted and printed, and the envelope's
/// GE shape is checked against the string equilibrium instead (tip altitude
/// within 5 % of the static shooting's: the 20-element shape error).
#[test]
fn envelope_cells_are_single_point_answers() {
    let v = request((0.0, 15.0, 4), (100.0, 1300.0, 9), 20);
    let (req, out) = solve(&v);
    let (problem, _, spec) = req.ge_problem().unwrap();
    let spec: GeStabilitySpec = spec.unwrap();
    let (mut checked, mut compressed) = (0, 0);
    let nl = problem.tether_lengths_m.len();
    for (i, &u) in problem.wind_speeds_m_s.iter().enumerate() {
        let sys = ge_system(&problem, &spec, u).unwrap();
        let mut start: Option<Vec<f64>> = None;
        for p in &out.points[i * nl..(i + 1) * nl] {
            assert_eq!(p.wind_speed_m_s, u);
            if p.slack {
                assert_eq!(p.stable, Some(false));
                assert!(p.max_growth_rate_1_s.is_none());
                continue;
            }
            let g = p.max_growth_rate_1_s.unwrap();
            let chained = cell_stability(&sys, p.tether_length_m, RATE, start.as_deref()).unwrap();
            // The solid section's slow spectrum inverts K, which magnifies
            // the Newton tolerance's differences between two solves of one
            // state (measured against a fresh start: 5.6e-7 1/s of 1.3e-2
            // at 5 m/s, 1150 m; 6.9e-6 of 1.55e-2 at 10 m/s, 1000 m).
            assert!(
                (g - chained.spectrum.max_real).abs() < 1e-4 * g.abs() + 1e-9,
                "{g} vs {}",
                chained.spectrum.max_real
            );
            assert_eq!(p.stable, Some(chained.spectrum.is_stable()));
            assert!(chained.root_axial_force_n > 0.0);
            assert!(
                (chained.tip_altitude_m / p.aerostat_altitude_m - 1.0).abs() < 0.05,
                "GE {} vs string {}",
                chained.tip_altitude_m,
                p.aerostat_altitude_m
            );
            start = Some(chained.state.q.clone());
            let fresh = cell_stability(&sys, p.tether_length_m, RATE, None).unwrap();
            println!(
                "{u} m/s {} m: envelope {g:.4e} 1/s (GE altitude {:.2} m, string {:.2} m); scratch {:.4e} 1/s, root force {:.1} N",
                p.tether_length_m,
                chained.tip_altitude_m,
                p.aerostat_altitude_m,
                fresh.spectrum.max_real,
                fresh.root_axial_force_n
            );
            if fresh.root_axial_force_n <= 0.0 {
                compressed += 1;
                continue;
            }
            assert_eq!(p.stable, Some(fresh.spectrum.is_stable()));
            assert!(
                (g - fresh.spectrum.max_real).abs()
                    < (0.1 * fresh.spectrum.tolerance()).max(1e-3 * g.abs()),
                "{u} m/s {} m: {g} vs {}",
                p.tether_length_m,
                fresh.spectrum.max_real
            );
            checked += 1;
        }
    }
    println!(
        "{checked} cells equal the scratch answers; {compressed} scratch starts on the compressed branch"
    );
    assert!(checked >= 30 && compressed <= 3, "{checked} {compressed}");
}

/// In wind (uniform 0–20 m/s): each wind's QS GE `critical_length` against
/// a dense scan of `wind_stability` along the length (120 points from the
/// shortest grid length to the top of the search, each started from the
/// previous one), and `critical_rate` at 1150 m against a scan of 120 rates (started on
/// the tensioned branch continued along the length at the payout rate):
/// the onset lies within one scan step above the last stable scan point
/// and below the first unstable one (the scan's verdict is the spectrum
/// tolerance; the search's onset is the divergence root or the bisected
/// QEP verdict, relative width 1e-4). "never" means every scan point is
/// stable. The maximum safe altitude per wind is printed: see the test's
/// output for its trend (the assertion is only that it is reported and
/// below the length).
#[test]
fn critical_length_and_rate_in_wind_match_scans() {
    let v = request((0.0, 20.0, 5), (100.0, 1150.0, 8), 20);
    let (req, out) = solve(&v);
    let (problem, _, spec) = req.ge_problem().unwrap();
    let spec = spec.unwrap();
    let ge = out.quasi_static_ge.as_ref().unwrap();
    for w in &ge.per_wind {
        let u = w.wind_speed_m_s;
        let sys = ge_system(&problem, &spec, u).unwrap();
        // length scan
        let n = 120;
        let (lo, hi) = (100.0, w.length_search_max_m);
        let mut start: Option<Vec<f64>> = None;
        let mut last_stable = None;
        let mut first_unstable = None;
        for k in 0..=n {
            let l = lo + (hi - lo) * k as f64 / n as f64;
            let stable = match cell_stability(&sys, l, RATE, start.as_deref()) {
                Ok(s) => {
                    let st = s.spectrum.is_stable();
                    start = Some(s.state.q);
                    st
                }
                Err(_) => false,
            };
            if stable {
                last_stable = Some(l);
            } else {
                first_unstable = Some(l);
                break;
            }
        }
        let step = (hi - lo) / n as f64;
        println!(
            "{u} m/s: critical length {:?} m ({}), altitude {:?} m, downwind {:?} m; scan: last stable {last_stable:?}, first unstable {first_unstable:?}",
            w.critical_length_m,
            w.critical_length_outcome,
            w.critical_altitude_m,
            w.critical_downwind_m
        );
        match w.critical_length_outcome.as_str() {
            "during" => {
                let l = w.critical_length_m.unwrap();
                let (a, b) = (last_stable.unwrap(), first_unstable.unwrap());
                assert!(a - step <= l && l <= b + step, "{a} {l} {b}");
                let alt = w.critical_altitude_m.unwrap();
                assert!(alt > 0.0 && alt <= l * (1.0 + 1e-4), "{alt} {l}");
            }
            "never" => {
                assert!(first_unstable.is_none(), "{first_unstable:?}");
                println!(
                    "    stable up to {:?} m altitude",
                    w.stable_up_to_altitude_m
                );
                assert!(w.stable_up_to_altitude_m.unwrap() <= hi);
            }
            other => panic!("{u} m/s: {other}"),
        }
        // rate scan at 1150 m, from the tensioned branch continued along the length
        let cap = w.rate_search_max_m_s;
        let mut start: Option<Vec<f64>> = None;
        for k in 0..=23 {
            let l = 100.0 + 1050.0 * k as f64 / 23.0;
            start = Some(
                cell_stability(&sys, l, RATE, start.as_deref())
                    .unwrap()
                    .state
                    .q,
            );
        }
        let (mut last_stable, mut first_unstable) = (None, None);
        for k in 0..=n {
            let r = 1e-3 * cap + (cap - 1e-3 * cap) * k as f64 / n as f64;
            // Unstable also where det K < 0 on the continued branch: just
            // past a divergence root the QEP's real eigenvalue grows more
            // slowly than the tolerance, and further on the Newton may
            // follow the stable buckled branch instead (with the solid
            // section the rate search's 43 m/s at 1150 m in 5 m/s wind,
            // about √(T_guide/ρA) of the string, was "stable" to the QEP
            // alone up to 318 m/s).
            let stable = match cell_stability(&sys, 1150.0, r, start.as_deref()) {
                Ok(s) => {
                    let kin = tetherplan::numerics::params::Kinematics {
                        length_m: 1150.0,
                        rate_m_s: r,
                        acceleration_m_s2: 0.0,
                    };
                    let det = tetherplan::numerics::ge::quasi_static::stiffness_determinant_sign(
                        &sys.model,
                        kin,
                        sys.tip_load,
                        &sys.air,
                        &s.state.q,
                    );
                    // and a branch with compression at the guide is the
                    // buckled one, past the tensioned branch's onset
                    let st = s.spectrum.is_stable() && det > 0 && s.root_axial_force_n > 0.0;
                    start = Some(s.state.q);
                    st
                }
                Err(_) => false,
            };
            if stable {
                last_stable = Some(r);
            } else {
                first_unstable = Some(r);
                break;
            }
        }
        let step = (cap - 1e-3 * cap) / n as f64;
        println!(
            "    critical rate at 1150 m {:?} m/s ({}, search to {cap:.2} m/s); scan: last stable {last_stable:?}, first unstable {first_unstable:?}",
            w.critical_rate_m_s, w.critical_rate_outcome
        );
        // The string criterion at the guide, from the envelope's own
        // static equilibrium at 1150 m: v = √(T_min/ρA).
        let t_min = out
            .points
            .iter()
            .find(|p| p.wind_speed_m_s == u && (p.tether_length_m - 1150.0).abs() < 1e-9)
            .map(|p| p.min_tension_n)
            .unwrap();
        let v_string = (t_min / 0.078).sqrt();
        println!("    string critical rate at 1150 m: {v_string:.2} m/s");
        match w.critical_rate_outcome.as_str() {
            // In wind the scan along the rate, each Newton started from the
            // previous rate, leaves the tensioned branch at its bifurcation
            // and follows a stable buckled one (measured: "stable" up to
            // the cap of 318 m/s at 5 m/s wind, det K > 0, with the string
            // criterion at 44 m/s); there the 20-element search is held to
            // the string's rate: within +25 % (the FE error from above,
            // +12 % in calm air) and -10 %.
            "during" if u > 0.0 => {
                let r = w.critical_rate_m_s.unwrap();
                assert!(
                    r > 0.9 * v_string && r < 1.25 * v_string,
                    "{r} vs {v_string}"
                );
            }
            "during" => {
                let r = w.critical_rate_m_s.unwrap();
                let (a, b) = (last_stable.unwrap(), first_unstable.unwrap());
                assert!(a - step <= r && r <= b + step, "{a} {r} {b}");
                assert!(r > v_string && r < 1.25 * v_string, "{r} vs {v_string}");
            }
            "never" => assert!(first_unstable.is_none(), "{first_unstable:?}"),
            "immediate" => assert_eq!(last_stable, None),
            other => panic!("{u} m/s: {other}"),
        }
    }
}

/// Issue 21: without `stability.elements` (and without
/// `bending_stiffness_n_m2`, which then defaults from the tether: the
/// full-slip bound of a 12-strand braid of 3.6 mm with the aramid modulus,
/// no EA given) each wind's critical length and rate are converged and
/// given on the safe side with their error estimates. Calm air: the safe
/// critical length is within 0.2 % of the string's `(F/ρA − v²)/g` (EI is
/// tiny); the estimate meets the closed form of `airy_onset` (the string
/// plus the bending lift, 0.7 m here) within its error and the safe value
/// lies below that closed form (on graded meshes the levels resolve the
/// bending layer, so the safe side is no longer below the string); the grid's cells
/// past it are unstable and those below stable; the answer states the
/// tolerance and the solid section's rotary inertia ρA d²/16.
#[test]
fn converged_without_elements() {
    let mut v = request((0.0, 0.0, 1), (100.0, 1400.0, 14), 20);
    let st = v["stability"].as_object_mut().unwrap();
    st.remove("elements");
    st.remove("bending_stiffness_n_m2");
    let (_, out) = solve(&v);
    let ge = out.quasi_static_ge.as_ref().unwrap();
    assert!(ge.converged);
    assert_eq!(ge.relative_tolerance_nondim, Some(1e-3));
    let ei_default = 25e9 * std::f64::consts::PI * 0.0036f64.powi(4) / 64.0 / 12.0;
    assert!(
        (ge.bending_stiffness_n_m2 / ei_default - 1.0).abs() < 0.5,
        "{}",
        ge.bending_stiffness_n_m2
    );
    assert!((ge.rotary_inertia_kg_m - 0.078 * 0.0036 * 0.0036 / 16.0).abs() < 1e-15);
    let w = &ge.per_wind[0];
    let (l, est, err) = (
        w.critical_length_m.unwrap(),
        w.critical_length_estimate_m.unwrap(),
        w.critical_length_error_m.unwrap(),
    );
    println!(
        "calm, converged: critical length {l:.3} m = {est:.3} − {err:.3} m ({:?}), string {:.3} m; \
         rate at 1150 m {:?} ± {:?} m/s; finest mesh {:?}",
        w.critical_length_converged,
        string_h(RATE),
        w.critical_rate_m_s,
        w.critical_rate_error_m_s,
        ge.finest_elements
    );
    assert!((l - (est - err)).abs() <= 1e-9 * l);
    let airy = tetherplan::numerics::ge::airy_onset::AiryOnset {
        net_buoyancy_n: 1000.0,
        mass_per_length_kg_m: 0.078,
        gravity_m_s2: 9.81,
        bending_stiffness_n_m2: ge.bending_stiffness_n_m2,
        rotary_inertia_kg_m: ge.rotary_inertia_kg_m,
    }
    .critical_length_m(RATE)
    .unwrap();
    println!("closed form {airy:.3} m");
    assert!(l <= airy, "safe {l} above the closed form {airy}");
    assert!((est - airy).abs() <= err, "{est} ± {err} vs {airy}");
    assert!((l / string_h(RATE) - 1.0).abs() < 2e-3);
    assert!(w.critical_rate_error_m_s.is_some());
    for p in &out.points {
        if p.tether_length_m < l {
            assert_eq!(p.stable, Some(true), "{} m", p.tether_length_m);
        } else {
            assert_eq!(p.stable, Some(false), "{} m", p.tether_length_m);
        }
    }
}
