//! Verification of the GE deployment charts, base excitation and the
//! two-DOF reduced model (issue 6; thesis ch. 7–8, SPEC §3).
//!
//! Every test states its reference (thesis figure or claim, the string
//! model, a closed form) and its tolerance. Numerical settings are
//! coarse but converged: 20 elements, Δt = 0.02 s with the QEP every 25
//! steps for the charts (the refinement test shows `t*` moves by < 0.2 %
//! when either is refined), Δt̄ = 0.05 for the frequency sweeps (Newmark
//! period error < 0.3 % at ω̄ = 3.5).

use std::f64::consts::PI;
use std::sync::atomic::{AtomicUsize, Ordering};

use tetherplan::numerics::ge::base::{
    BaseExcitationProblem, FrequencyResponse, ResponsePoint, frequency_response, resonance_peaks,
};
use tetherplan::numerics::ge::chart::{
    GeChartRequest, GeChartSeries, GeChartSystem, deployment_chart,
};
use tetherplan::numerics::ge::critical::{
    CriticalConfig, CriticalProblem, GeOnset, StartState, TipPerturbation, critical_time,
};
use tetherplan::numerics::ge::element::TipLoad;
use tetherplan::numerics::ge::extensible::ExtensibleString;
use tetherplan::numerics::ge::reduced::{self as ge_reduced, ReducedFrequencies};
use tetherplan::numerics::ge::solver::{LengthHistory, NewtonConfig};
use tetherplan::numerics::ge::{GeModel, Section, TipBody};
use tetherplan::numerics::parallel::Parallelism;
use tetherplan::numerics::params::AerostatSystem;
use tetherplan::numerics::profile::Profile;
use tetherplan::numerics::string::StringModel;
use tetherplan::numerics::string::critical::{Onset, constant_rate_lengthening};

fn never() -> bool {
    false
}

fn table_7_1(stiffness_ratio: f64) -> GeModel {
    GeChartSystem::table_7_1().model(stiffness_ratio).unwrap()
}

fn t_star(rate: f64, stiffness_ratio: f64, f0: f64, config: &CriticalConfig) -> GeOnset {
    let problem = CriticalProblem {
        profile: Profile::constant_rate(1.0, rate, None).unwrap(),
        net_buoyancy_n: 1000.0,
        perturbation: (f0 > 0.0).then(|| TipPerturbation::held(f0)),
        aero: None,
        start: StartState::AtRest,
    };
    critical_time(&table_7_1(stiffness_ratio), &problem, config, &never)
        .unwrap()
        .onset
}

fn during(onset: GeOnset) -> (f64, f64) {
    match onset {
        GeOnset::During { time_s, length_m } => (time_s, length_m),
        other => panic!("expected an onset during the deployment, got {other:?}"),
    }
}

fn chart(request: &GeChartRequest) -> Vec<GeChartSeries> {
    deployment_chart(request, Parallelism::Rayon, &|_, _| {}, &never).unwrap()
}

// ---------------------------------------------------------------- ch. 7.3

/// Thesis ch. 7.3 (Fig. 7.1): doubling the rate 12 → 24 m/s "almost
/// halves" t*. Continuum string: t*(24)/t*(12) = (h*(24)/24)/(h*(12)/12)
/// = 0.483. Tolerance: the ratio within [0.45, 0.52].
#[test]
fn doubling_the_rate_about_halves_the_critical_time() {
    let config = CriticalConfig::default();
    let (t12, h12) = during(t_star(12.0, 1e5, 0.0, &config));
    let (t24, h24) = during(t_star(24.0, 1e5, 0.0, &config));
    let sys = AerostatSystem::thesis();
    let string_ratio =
        (sys.closed_form_elevation_m(24.0) / 24.0) / (sys.closed_form_elevation_m(12.0) / 12.0);
    println!(
        "t*(12) = {t12:.3} s (h* {h12:.1} m), t*(24) = {t24:.3} s (h* {h24:.1} m): ratio {:.4} (string continuum {string_ratio:.4})",
        t24 / t12
    );
    assert!((0.45..=0.52).contains(&(t24 / t12)), "ratio {}", t24 / t12);
    assert!(((t24 / t12) / string_ratio - 1.0).abs() < 0.02);
}

/// Thesis ch. 7.3: deploying faster than the wave speed is unstable at
/// once; the thesis finds the GE threshold near 117 m/s, above the string's
/// √(F/ρA) = 113.2 m/s because bending stiffens the 1 m initial cable
/// (EI/L0² = 1000 N, as large as F). Checked: 118 and 120 m/s unstable at
/// t = 0; 117 m/s stable at t = 0 but unstable within 1 s; 100 m/s lasts
/// several seconds (string continuum: 2.9 s).
#[test]
fn rate_above_the_wave_speed_is_unstable_at_once() {
    let config = CriticalConfig::default();
    for rate in [118.0, 120.0, 150.0] {
        let onset = t_star(rate, 1e5, 0.0, &config);
        println!("{rate} m/s: {onset:?}");
        assert!(matches!(onset, GeOnset::Immediate { max_real_1_s } if max_real_1_s > 1.0));
    }
    let (t117, _) = during(t_star(117.0, 1e5, 0.0, &config));
    let (t100, h100) = during(t_star(100.0, 1e5, 0.0, &config));
    println!("117 m/s: t* = {t117:.3} s; 100 m/s: t* = {t100:.3} s, h* = {h100:.1} m");
    assert!(t117 < 1.0);
    assert!(t100 > 2.0 && t100 < 5.0);
}

/// Thesis ch. 7.4 (Fig. 7.3): for E* = 1e5 the unperturbed GE chart is
/// the linear string's. Reference: the string FE chart at the same 20
/// elements. Tolerance 5 % in h* over 5–60 m/s. Bending makes the GE h*
/// a little higher: near the root the cable is under compression once the
/// effective tension there goes negative, and a clamped heavy column of
/// weight ρA g per metre carries a compressed length up to
/// ℓ = (7.837 EI/(ρA g))^(1/3) = 21.7 m (Greenhill) — the GE excess must
/// lie between 0.5 ℓ and 2 ℓ at every rate.
#[test]
fn stiff_ge_chart_matches_the_string_chart() {
    let rates = vec![5.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0];
    let ge = chart(&GeChartRequest::table_7_1(rates.clone(), vec![1e5]));
    let string = StringModel::new(AerostatSystem::thesis(), 20).unwrap();
    let column = f64::cbrt(7.837 * 1000.0 / (0.078 * 9.81));
    println!("heavy-column length ℓ = {column:.1} m");
    for p in &ge[0].points {
        let h_ge = p.max_elevation_m.unwrap();
        let Onset::During {
            length_m: h_str, ..
        } = constant_rate_lengthening(&string, p.rate_m_s, None).onset
        else {
            panic!()
        };
        let excess = h_ge - h_str;
        println!(
            "{:5.1} m/s: GE h* {h_ge:8.1} m, string (20 el) {h_str:8.1} m ({:+.2} %, {excess:+.1} m), continuum {:.1} m",
            p.rate_m_s,
            100.0 * (h_ge / h_str - 1.0),
            p.string_closed_form_m
        );
        assert!((h_ge / h_str - 1.0).abs() < 0.05);
        // EA = 1e8 N: the extensible bound is the string's within 1e-4
        assert!(
            (p.extensible_closed_form_m / p.string_closed_form_m - 1.0).abs() < 1e-4,
            "{} vs {}",
            p.extensible_closed_form_m,
            p.string_closed_form_m
        );
        assert!(
            excess > 0.5 * column && excess < 2.0 * column,
            "excess {excess} m"
        );
    }
}

/// Thesis ch. 7.4: t* "does not change for E* ≥ 1e5". Here it does not
/// change for E* ≥ 100 either: the chart's E* = 100, 1e3 series are within
/// 1 % of E* = 1e5 at 12, 40 and 80 m/s (EA ≥ 1e5 N stretches the cable by
/// less than 1 %).
#[test]
fn stiff_cables_share_one_chart() {
    let series = chart(&GeChartRequest::table_7_1(
        vec![12.0, 40.0, 80.0],
        vec![100.0, 1e3, 1e5],
    ));
    let t = |s: usize, r: usize| series[s].points[r].critical_time_s.unwrap();
    for (s, one) in series.iter().enumerate().take(2) {
        for r in 0..3 {
            println!(
                "E* = {}: t* = {:.3} s against {:.3} s at E* = 1e5",
                one.stiffness_ratio,
                t(s, r),
                t(2, r)
            );
            assert!((t(s, r) / t(2, r) - 1.0).abs() < 0.01);
        }
    }
}

/// Extensible cables (E* = 1, 10 at EI = 1000 N m², i.e. EA = 1, 10 kN)
/// against the quasi-static string limit of
/// [`tetherplan::numerics::ge::extensible`]: the shift in h* from E* = 1e5,
/// ΔL* = L*(β) − L*(0) with β = μv²/EA, started in steady payout (no start
/// transient). Tolerance: within 10 % of the closed-form shift at 12 and
/// 40 m/s (measured 0.2–7 %); past the crossover rate (≈ 65 m/s for
/// E* = 1, where the closed form turns negative) the shift changes sign as
/// the closed form says: E* = 1 goes unstable earlier at 70, 80 and 90 m/s.
///
/// Departure from the thesis (Fig. 7.3, "an extensible GE cable becomes
/// unstable earlier"): that holds only above the crossover. Below it the
/// decelerating, un-stretching cable weighs less on the guide and a more
/// extensible cable pays out a *longer* length first — the closed form and
/// the GE model agree on this.
#[test]
fn extensible_cable_follows_the_quasi_static_limit() {
    let run = |rate: f64, stiffness_ratio: f64| {
        let problem = CriticalProblem {
            profile: Profile::constant_rate(1.0, rate, None).unwrap(),
            net_buoyancy_n: 1000.0,
            perturbation: None,
            aero: None,
            start: StartState::SteadyPayout,
        };
        let model = table_7_1(stiffness_ratio);
        let r = critical_time(&model, &problem, &CriticalConfig::default(), &never).unwrap();
        during(r.onset).1
    };
    let closed = |rate: f64, stiffness_ratio: f64| {
        ExtensibleString {
            net_buoyancy_n: 1000.0,
            aerostat_mass_kg: 10.0,
            mass_per_length_kg_m: 0.078,
            axial_stiffness_n: stiffness_ratio * 1000.0,
            gravity_m_s2: 9.81,
        }
        .critical_length_m(rate)
        .unwrap()
    };
    for rate in [12.0, 40.0] {
        let stiff = run(rate, 1e5);
        let mut last = stiff;
        for es in [10.0, 1.0] {
            let shift = run(rate, es) - stiff;
            let expected = closed(rate, es) - closed(rate, 1e5);
            println!(
                "{rate} m/s, E* = {es}: h* shift {shift:+.2} m, closed form {expected:+.2} m ({:+.1} %)",
                100.0 * (shift / expected - 1.0)
            );
            assert!(expected > 0.0);
            assert!((shift / expected - 1.0).abs() < 0.10);
            // monotone: the more extensible, the longer (below the crossover)
            assert!(stiff + shift > last);
            last = stiff + shift;
        }
    }
    for rate in [70.0, 80.0, 90.0] {
        let (soft, stiff) = (run(rate, 1.0), run(rate, 1e5));
        println!("{rate} m/s: h* {soft:.1} m at E* = 1 against {stiff:.1} m at E* = 1e5");
        assert!(soft < stiff - 40.0);
    }
}

/// The onset does not move when the step or the QEP interval is refined
/// (Table 7.1, 12 m/s, 20 elements): Δt ∈ {0.04, 0.02, 0.01} s, checks
/// every 5–100 steps; all within 0.2 % of the default (Δt = 0.02 s, every
/// 25 steps). (Perturbed runs need a finer step: see the F0 test.)
#[test]
fn critical_time_is_converged_in_step_and_check_interval() {
    let base = CriticalConfig::default();
    let (t0, _) = during(t_star(12.0, 1e5, 0.0, &base));
    for (dt, every) in [(0.04, 5), (0.02, 5), (0.01, 100), (0.01, 25)] {
        let config = CriticalConfig {
            time_step_s: dt,
            check_every: every,
            ..base
        };
        let (t, _) = during(t_star(12.0, 1e5, 0.0, &config));
        println!(
            "Δt = {dt} s, QEP every {every} steps: t* = {t:.4} s ({:+.3} % vs default {t0:.4})",
            100.0 * (t / t0 - 1.0)
        );
        assert!((t / t0 - 1.0).abs() < 0.002);
    }
}

/// Thesis Fig. 7.4: a larger initial tip perturbation F0 (0, 200, 400 N,
/// here ramped over 0.25 s, held to 1 s, released) lowers t* above
/// ~20 m/s and leaves it alone below. The perturbed march needs a finer
/// step than the unperturbed one (it excites the short cable's fast
/// modes), so each claim is checked where it is converged:
/// * 70 m/s, Δt = 2.5 and 1.25 ms (they agree within 0.5 %): F0 = 400 N
///   lowers t* by more than 1 % (measured 1.3 %), F0 = 200 N lowers it by
///   less (0–0.3 %, within the step scatter); larger F0 never raises t*.
/// * 10 m/s, Δt = 10 ms: F0 ≤ 400 N moves t* by less than 0.5 % (the
///   oscillation has decayed long before t* ≈ 135 s).
///
/// Departure (reported): at 50 and 90 m/s the perturbed t* still moves by
/// 1–4 % between Δt = 2.5 and 1.25 ms, either side of the unperturbed
/// value, so no "lowers" claim is made there.
///
/// Scheme: this claim holds with average acceleration (no numerical
/// dissipation), which the test therefore sets. With the search's default
/// dissipative scheme (generalized-α, ρ∞ = 0, issue 10) the push's
/// unresolved axial content is removed and F0 = 200 / 400 N *raise* t* at
/// 70 m/s by 0.08 / 0.31 % (12.646 → 12.656 / 12.685 s, the same at both
/// steps): the 1.3 % lowering seen without dissipation comes from modes
/// the step does not resolve (departure from Fig. 7.4, reported).
#[test]
fn tip_perturbation_lowers_the_critical_time_at_higher_rates() {
    let run = |rate: f64, dt: f64| {
        let mut request = GeChartRequest::table_7_1(vec![rate], vec![1e5]);
        request.perturbation_forces_n = vec![0.0, 200.0, 400.0];
        request.config.scheme = tetherplan::numerics::ge::solver::Scheme::AverageAcceleration;
        request.config.time_step_s = dt;
        request.config.check_every = 50;
        let series = chart(&request);
        let t: Vec<f64> = series
            .iter()
            .map(|s| s.points[0].critical_time_s.unwrap())
            .collect();
        println!(
            "{rate:5.1} m/s, Δt {dt} s: t* = {:.3} / {:.3} / {:.3} s for F0 = 0 / 200 / 400 N ({:+.2} %, {:+.2} %)",
            t[0],
            t[1],
            t[2],
            100.0 * (t[1] / t[0] - 1.0),
            100.0 * (t[2] / t[0] - 1.0)
        );
        t
    };
    let fast = run(70.0, 0.0025);
    let finer = run(70.0, 0.00125);
    for k in 0..3 {
        assert!((fast[k] / finer[k] - 1.0).abs() < 0.005, "not converged");
    }
    for t in [&fast, &finer] {
        assert!(t[2] < t[0] * 0.99);
        assert!(t[1] <= t[0] * 1.005 && t[2] <= t[1]);
    }
    let slow = run(10.0, 0.01);
    for k in 1..3 {
        assert!((slow[k] / slow[0] - 1.0).abs() < 0.005);
    }
}

/// Parallel and serial sweeps give the same chart, bit for bit, and the
/// progress callback ends at the total, counted in thousandths of points.
#[test]
fn ge_chart_parallel_equals_serial() {
    use tetherplan::numerics::ge::chart::PROGRESS_UNITS_PER_POINT;
    let mut request = GeChartRequest::table_7_1(vec![60.0, 90.0, 110.0], vec![1e3, 1e5]);
    request.net_buoyancies_n = vec![1000.0, 1500.0];
    let last = AtomicUsize::new(0);
    let progress = |done: usize, total: usize| {
        assert_eq!(total, 12 * PROGRESS_UNITS_PER_POINT);
        assert!(done <= total);
        last.fetch_max(done, Ordering::Relaxed);
    };
    let serial = deployment_chart(&request, Parallelism::Serial, &progress, &never).unwrap();
    assert_eq!(
        last.swap(0, Ordering::Relaxed),
        12 * PROGRESS_UNITS_PER_POINT
    );
    let parallel = deployment_chart(&request, Parallelism::Rayon, &progress, &never).unwrap();
    assert_eq!(last.load(Ordering::Relaxed), 12 * PROGRESS_UNITS_PER_POINT);
    assert_eq!(serial, parallel);
    assert_eq!(serial.len(), 4);
    // more buoyancy, higher h*
    assert!(
        serial[1].points[0].max_elevation_m.unwrap()
            > serial[0].points[0].max_elevation_m.unwrap() * 1.2
    );
    // invalid input names the field
    request.stiffness_ratios = vec![1e5, -1.0];
    let e = deployment_chart(&request, Parallelism::Serial, &|_, _| {}, &never).unwrap_err();
    assert_eq!(e.field, "stiffness_ratios[1]");
}

// ---------------------------------------------------------------- ch. 8

/// The bare cantilever of ch. 8 (L0 = 1 m, EI = 1000 N m², ρA = 0.078
/// kg/m, γ̃ = 1, no aerostat, no gravity), 20 elements.
fn cantilever(stiffness_ratio: f64) -> (GeModel, f64) {
    let section = Section::from_ratios(1000.0, stiffness_ratio, 1.0, 0.078, 1.0).unwrap();
    let scale = section.time_scale_s(1.0);
    (
        GeModel::new(section, 20, TipBody::default(), 0.0).unwrap(),
        scale,
    )
}

/// Sweep over non-dimensional frequencies, duration t̄ = 100, Δt̄ = 0.05.
fn sweep(stiffness_ratio: f64, rate_nondim: f64, omegas: &[f64]) -> (FrequencyResponse, f64) {
    let (model, scale) = cantilever(stiffness_ratio);
    let length = if rate_nondim == 0.0 {
        LengthHistory::Constant(1.0)
    } else {
        LengthHistory::Profile(Profile::constant_rate(1.0, rate_nondim / scale, None).unwrap())
    };
    let problem = BaseExcitationProblem {
        model,
        length,
        steady_tip_load: TipLoad::default(),
        amplitude_m: 1e-3,
        frequencies_rad_s: omegas.iter().map(|w| w / scale).collect(),
        reference_frequency_rad_s: 0.01 / scale,
        duration_s: 100.0 * scale,
        time_step_s: 0.05 * scale,
        newton: NewtonConfig::default(),
    };
    let r = frequency_response(&problem, Parallelism::Rayon, &|_, _| {}, &never).unwrap();
    assert!(r.reference.completed && r.points.iter().all(|p| p.completed));
    (r, scale)
}

fn grid(lo: f64, hi: f64, step: f64) -> Vec<f64> {
    let n = ((hi - lo) / step).round() as usize;
    (0..=n).map(|i| lo + step * i as f64).collect()
}

fn nondim(points: &[ResponsePoint], scale: f64, i: usize) -> f64 {
    points[i].frequency_rad_s * scale
}

/// Thesis (8.8), Fig. 8.3: at ε = 0 the two frequencies are 0 and the
/// single EB-like one (π/2)√E*; they turn complex near ε ≈ 0.6 for E* = 5
/// (closed form of the discriminant: ε = 0.604); tolerance 0.01.
#[test]
fn reduced_model_frequencies_against_epsilon() {
    for es in [1.0, 5.0, 20.0] {
        let ReducedFrequencies::Real { first, second } =
            ge_reduced::natural_frequencies(es, 0.0, 1.0, 0.0)
        else {
            panic!()
        };
        assert!(first.abs() < 1e-12);
        assert!((second - 0.5 * PI * f64::sqrt(es)).abs() < 1e-12);
    }
    let onset = ge_reduced::complex_onset_epsilon(5.0, 2.0).unwrap();
    println!("E* = 5: frequencies complex from ε = {onset:.4}");
    assert!((onset - 0.6).abs() < 0.01);
    // below the onset the split grows with ε; above it they are complex
    let mut last = 0.0;
    for eps in [0.05, 0.2, 0.4, 0.58] {
        let ReducedFrequencies::Real { first, .. } =
            ge_reduced::natural_frequencies(5.0, eps, 1.0, 0.0)
        else {
            panic!("real below the onset")
        };
        assert!(first > last);
        last = first;
    }
    assert!(matches!(
        ge_reduced::natural_frequencies(5.0, 0.62, 1.0, 0.0),
        ReducedFrequencies::Complex { .. }
    ));
}

/// Thesis Fig. 8.5: the computed second resonance of the constant-length
/// cantilever under base excitation is compared with the model's
/// (π/2)√E* (ε = 0); the thesis finds agreement for E* ≤ 5.2. The peak is
/// found on a 0.1 grid from ω̄ = 0.3 and refined on a 0.01 grid around it.
/// Here: E* = 5 (the thesis's choice) within 5 % (measured −0.6 %); E* = 8
/// outside 5 % (the approximation has failed, as in the thesis). Departure
/// (reported): at E* = 1 the computed second transverse resonance is 20 %
/// *above* (π/2)√E*. What sits exactly at (π/2)√E* for every E* is the
/// axial bar mode (EA = GA, so the bar and shear-beam frequencies
/// coincide), which transverse shaking does not excite; the local QEP
/// spectrum shows it (checked to 0.5 %).
#[test]
fn constant_length_second_resonance_matches_the_reduced_model() {
    for (es, within) in [(1.0, false), (5.0, true), (8.0, false)] {
        let model = 0.5 * PI * f64::sqrt(es);
        let (coarse, scale) = sweep(es, 0.0, &grid(0.3, 1.25 * model, 0.1));
        let peaks = resonance_peaks(&coarse.points);
        assert!(peaks.len() >= 2, "E* = {es}: peaks {peaks:?}");
        let second = nondim(&coarse.points, scale, peaks[1]);
        let (fine, _) = sweep(es, 0.0, &grid(second - 0.1, second + 0.1, 0.01));
        let best = (0..fine.points.len())
            .max_by(|&a, &b| fine.points[a].gain_db.total_cmp(&fine.points[b].gain_db))
            .unwrap();
        let computed = nondim(&fine.points, scale, best);
        let first = nondim(&coarse.points, scale, peaks[0]);
        println!(
            "E* = {es}: first resonance ω̄ ≈ {first:.2}, second {computed:.3} ({:.1} dB); model (π/2)√E* = {model:.3} ({:+.2} %)",
            fine.points[best].gain_db,
            100.0 * (computed / model - 1.0)
        );
        assert_eq!((computed / model - 1.0).abs() < 0.05, within, "E* = {es}");
        // the axial mode at (π/2)√E*
        let (m, _) = cantilever(es);
        let spectrum = tetherplan::numerics::ge::stability::local_spectrum(
            &m,
            tetherplan::numerics::params::Kinematics {
                length_m: 1.0,
                rate_m_s: 0.0,
                acceleration_m_s2: 0.0,
            },
            TipLoad::default(),
            0.0,
            &tetherplan::numerics::ge::solver::State::at_rest(&m, 0.0),
        )
        .unwrap();
        assert!(
            spectrum
                .modes()
                .iter()
                .any(|e| (e.im * scale / model - 1.0).abs() < 0.005)
        );
    }
}

/// Thesis Fig. 8.6(a, b): base excitation of the cantilever (E* = 5)
/// lengthening at ṽ = 0.005 for t̄ = 100 (l: 1 → 1.5). The reduced model
/// (8.9) at ε = 0.2 (where (8.8) matches the constant-length response,
/// Fig. 8.4) predicts the bands swept by its two frequencies; the computed
/// resonance bands — the intervals around the response's peaks where the
/// gain is at least 15 dB (a 5.6-fold amplification; between resonances
/// of the constant-length cable it is 5–10 dB) — contain them. The first
/// band is also more than twice as wide as the constant-length cable's
/// first peak (band broadening).
#[test]
fn lengthening_resonance_bands_contain_the_reduced_model_bands() {
    let bands = ge_reduced::resonance_bands(5.0, 0.2, 0.005, 100.0).unwrap();
    println!(
        "model bands: [{:.3}, {:.3}], [{:.3}, {:.3}]",
        bands[0].low, bands[0].high, bands[1].low, bands[1].high
    );
    let omegas = grid(0.5, 4.0, 0.05);
    let (lengthening, scale) = sweep(5.0, 0.005, &omegas);
    let (still, _) = sweep(5.0, 0.0, &omegas);
    let threshold = 15.0;
    let above = |r: &FrequencyResponse| -> Vec<(f64, f64)> {
        // maximal runs of grid points at or above the threshold, widened to
        // the interpolated crossings
        let p = &r.points;
        let mut runs = Vec::new();
        let mut i = 0;
        while i < p.len() {
            if p[i].gain_db < threshold {
                i += 1;
                continue;
            }
            let start = i;
            while i + 1 < p.len() && p[i + 1].gain_db >= threshold {
                i += 1;
            }
            let cross = |a: usize, b: usize| {
                let (ga, gb) = (p[a].gain_db, p[b].gain_db);
                let (wa, wb) = (nondim(p, scale, a), nondim(p, scale, b));
                wa + (threshold - ga) / (gb - ga) * (wb - wa)
            };
            let lo = if start > 0 {
                cross(start - 1, start)
            } else {
                nondim(p, scale, 0)
            };
            let hi = if i + 1 < p.len() {
                cross(i, i + 1)
            } else {
                nondim(p, scale, i)
            };
            runs.push((lo, hi));
            i += 1;
        }
        runs
    };
    let computed = above(&lengthening);
    let fixed = above(&still);
    println!(
        "computed bands (≥ {threshold} dB), lengthening: {computed:.3?}; constant length: {fixed:.3?}"
    );
    for band in bands {
        assert!(
            computed
                .iter()
                .any(|&(lo, hi)| lo <= band.low && band.high <= hi),
            "model band [{:.3}, {:.3}] not inside a computed band",
            band.low,
            band.high
        );
    }
    // the first band is more than twice as wide as the fixed cable's peak
    let first_width = |runs: &[(f64, f64)]| runs[0].1 - runs[0].0;
    assert!(first_width(&computed) > 2.0 * first_width(&fixed));
}

/// Thesis Fig. 8.7(a, b): the same cantilever shortening at ṽ = −0.005 for
/// t̄ = 100 (l: 1 → 0.5). The model's bands now sweep upward, from the
/// initial frequencies [1.406 → 2.234] and [3.443 → 4.863]; the computed
/// bands (≥ 15 dB, as above) contain them to within 2 % of each band edge
/// (measured: the lower edge of the first band is 1 % high).
#[test]
fn shortening_resonance_bands_contain_the_reduced_model_bands() {
    let bands = ge_reduced::resonance_bands(5.0, 0.2, -0.005, 100.0).unwrap();
    let (response, scale) = sweep(5.0, -0.005, &grid(0.5, 5.5, 0.05));
    let computed = bands_above(&response, scale, 15.0);
    println!(
        "shortening: model bands [{:.3}, {:.3}], [{:.3}, {:.3}]; computed (≥ 15 dB) {computed:.3?}",
        bands[0].low, bands[0].high, bands[1].low, bands[1].high
    );
    assert!(bands[0].high > bands[0].low * 1.5, "sweeps upward");
    for band in bands {
        assert!(
            computed
                .iter()
                .any(|&(lo, hi)| lo <= band.low * 1.02 && band.high * 0.98 <= hi),
            "model band [{:.3}, {:.3}] not inside a computed band",
            band.low,
            band.high
        );
    }
}

/// Intervals of the response where the gain is at least `threshold` dB,
/// ends interpolated between grid points (non-dimensional frequencies).
fn bands_above(r: &FrequencyResponse, scale: f64, threshold: f64) -> Vec<(f64, f64)> {
    let p = &r.points;
    let w = |i: usize| nondim(p, scale, i);
    let cross = |a: usize, b: usize| {
        let (ga, gb) = (p[a].gain_db, p[b].gain_db);
        w(a) + (threshold - ga) / (gb - ga) * (w(b) - w(a))
    };
    let mut runs = Vec::new();
    let mut i = 0;
    while i < p.len() {
        if p[i].gain_db < threshold {
            i += 1;
            continue;
        }
        let start = i;
        while i + 1 < p.len() && p[i + 1].gain_db >= threshold {
            i += 1;
        }
        let lo = if start > 0 {
            cross(start - 1, start)
        } else {
            w(0)
        };
        let hi = if i + 1 < p.len() {
            cross(i, i + 1)
        } else {
            w(i)
        };
        runs.push((lo, hi));
        i += 1;
    }
    runs
}

/// The platform-frame load is the right size: shaken slowly (ω̄ = 0.05,
/// 3.5 % of the first resonance 1.44), the stiff bare cantilever
/// (E* = 1e5, R0 = 1 m) bends quasi-statically under the uniform load
/// q = A_ρ R0 ω², so its largest tip deflection relative to the platform is
/// the Timoshenko static value q L⁴/(8 EI) + q L²/(2 GA), plus at most the
/// start-up free vibration of relative size ω/ω1 ≈ 3.5 %: within
/// [−1 %, +5 %] of it.
#[test]
fn base_load_matches_the_quasi_static_deflection() {
    use tetherplan::numerics::ge::solver::{
        BaseMotion, Damping, Drive, EndLoads, Integrator, State,
    };
    let (model, scale) = cantilever(1e5);
    let omega = 0.05 / scale;
    let drive = Drive {
        length: LengthHistory::Constant(1.0),
        loads: EndLoads::steady(TipLoad::default()),
        damping: Damping::default(),
        base: BaseMotion {
            amplitude_m: 1.0,
            circular_frequency_rad_s: omega,
        },
        aero: None,
    };
    let mut it = Integrator::new(
        &model,
        &drive,
        State::at_rest(&model, 0.0),
        0.05 * scale,
        NewtonConfig::default(),
    );
    let top = GeModel::dof(model.elements, 1);
    let mut max = 0.0f64;
    for _ in 0..2000 {
        it.step().unwrap();
        max = max.max(it.state.q[top].abs());
    }
    let q = 0.078 * omega * omega;
    let statics = q / (8.0 * 1000.0) + q / (2.0 * 1e5 * 1000.0);
    println!(
        "ω = {omega:.3} rad/s: max relative tip deflection {max:.4e} m, static {statics:.4e} m ({:+.2} %)",
        100.0 * (max / statics - 1.0)
    );
    assert!(max / statics > 0.99 && max / statics < 1.05);
}

/// Thesis Figs 8.6(a), 8.7(a): both frequencies of (8.9) fall while the
/// cable lengthens and rise while it shortens; a faster rate over the same
/// t̄ widens the bands (Fig. 8.6(c)). And the frozen model's frequencies
/// follow the GE cantilever's own: at l = 1 the first two GE frequencies
/// (local QEP, 20 elements) are within 5 % of the model's at ε = 0.2.
#[test]
fn reduced_model_frequency_evolution() {
    let at = |l: f64, v: f64| match ge_reduced::natural_frequencies(5.0, 0.2, l, v) {
        ReducedFrequencies::Real { first, second } => (first, second),
        c => panic!("{c:?}"),
    };
    let evolution = ge_reduced::frequency_evolution(5.0, 0.2, 0.005, 100.0, 10);
    assert_eq!(evolution.len(), 11);
    assert!((evolution[10].length - 1.5).abs() < 1e-12);
    let mut prev = at(1.0, 0.005);
    for s in &evolution[1..] {
        let ReducedFrequencies::Real { first, second } = s.frequencies else {
            panic!()
        };
        assert!(first < prev.0 && second < prev.1);
        prev = (first, second);
    }
    let mut prev = at(1.0, -0.005);
    for k in 1..=10 {
        let now = at(1.0 - 0.05 * k as f64, -0.005);
        assert!(now.0 > prev.0 && now.1 > prev.1);
        prev = now;
    }
    let slow = ge_reduced::resonance_bands(5.0, 0.2, 0.005, 100.0).unwrap();
    let fast = ge_reduced::resonance_bands(5.0, 0.2, 0.05, 100.0).unwrap();
    for k in 0..2 {
        println!(
            "band {k}: ṽ = 0.005 width {:.3}, ṽ = 0.05 width {:.3}",
            slow[k].high - slow[k].low,
            fast[k].high - fast[k].low
        );
        assert!(fast[k].high - fast[k].low > 1.5 * (slow[k].high - slow[k].low));
    }
    let (model, scale) = cantilever(5.0);
    let state = tetherplan::numerics::ge::solver::State::at_rest(&model, 0.0);
    let kin = tetherplan::numerics::params::Kinematics {
        length_m: 1.0,
        rate_m_s: 0.0,
        acceleration_m_s2: 0.0,
    };
    let spectrum = tetherplan::numerics::ge::stability::local_spectrum(
        &model,
        kin,
        TipLoad::default(),
        0.0,
        &state,
    )
    .unwrap();
    let ge: Vec<f64> = spectrum
        .modes()
        .iter()
        .filter(|e| e.im > 1e-6)
        .take(2)
        .map(|e| e.im * scale)
        .collect();
    let reduced = at(1.0, 0.0);
    println!(
        "l = 1: GE ω̄ = {:.3}, {:.3}; reduced (ε = 0.2) {:.3}, {:.3}",
        ge[0], ge[1], reduced.0, reduced.1
    );
    assert!((ge[0] / reduced.0 - 1.0).abs() < 0.05);
    assert!((ge[1] / reduced.1 - 1.0).abs() < 0.05);
}

/// Frequency sweeps: parallel equals serial; progress counts every run
/// (the reference included); invalid input names the field.
#[test]
fn frequency_response_parallel_equals_serial() {
    let (model, scale) = cantilever(5.0);
    let mut problem = BaseExcitationProblem {
        model,
        length: LengthHistory::Constant(1.0),
        steady_tip_load: TipLoad::default(),
        amplitude_m: 1e-3,
        frequencies_rad_s: [1.0, 2.0, 3.5].iter().map(|w| w / scale).collect(),
        reference_frequency_rad_s: 0.01 / scale,
        duration_s: 20.0 * scale,
        time_step_s: 0.05 * scale,
        newton: NewtonConfig::default(),
    };
    let count = AtomicUsize::new(0);
    let progress = |_: usize, total: usize| {
        assert_eq!(total, 4);
        count.fetch_add(1, Ordering::Relaxed);
    };
    let a = frequency_response(&problem, Parallelism::Serial, &progress, &never).unwrap();
    let b = frequency_response(&problem, Parallelism::Rayon, &progress, &never).unwrap();
    assert_eq!(a, b);
    assert_eq!(count.load(Ordering::Relaxed), 8);
    assert_eq!(a.reference.gain_db, 0.0);
    problem.frequencies_rad_s[1] = -2.0;
    let e = frequency_response(&problem, Parallelism::Serial, &|_, _| {}, &never).unwrap_err();
    assert_eq!(e.field, "frequencies_rad_s[1]");
}

// ---------------------------------------------------------------- ch. 7.5 wind

/// Thesis ch. 7.5 (Fig. 7.6): a steady air flow on the aerostat keeps a
/// lengthening cable stable longer. With the illustrative tabulated
/// profile (0 → 8 m/s over 600 m; not the thesis's data) and quadratic
/// drag (C_D = 0.5 on a 1 m sphere, ρ_air = 1.12 kg/m³), t* at 20 m/s rises
/// by more than 2 % over still air (measured +3.8 %: the sideways pull adds
/// to the cable tension). With the thesis's inviscid force model the
/// steady flow's load is only m_f u u_z ≈ 0.5 N, and t* moves by < 0.5 %.
/// Fig. 7.7 (larger A0 of (7.4), earlier instability) is *not* reproduced:
/// A0 = 0.5 and 1 move t* by less than 2 %, either way (reported).
#[test]
fn steady_wind_delays_the_instability() {
    use tetherplan::numerics::aero::ForceModel;
    use tetherplan::numerics::ge::chart::GeChartWind;
    let mut request = GeChartRequest::table_7_1(vec![20.0], vec![1e5]);
    let still = chart(&request)[0].points[0].critical_time_s.unwrap();
    let mut wind = GeChartWind::illustrative(vec![0.0, 0.5, 1.0]);
    request.wind = Some(wind.clone());
    let inviscid: Vec<f64> = chart(&request)
        .iter()
        .map(|s| s.points[0].critical_time_s.unwrap())
        .collect();
    wind.force_model = ForceModel::Drag {
        drag_coefficient: 0.5,
        reference_area_m2: wind.body.frontal_area_m2(),
    };
    request.wind = Some(wind);
    let series = chart(&request);
    assert_eq!(series.len(), 3);
    assert_eq!(series[2].wind_amplitude, Some(1.0));
    let drag: Vec<f64> = series
        .iter()
        .map(|s| s.points[0].critical_time_s.unwrap())
        .collect();
    println!(
        "20 m/s: still air t* = {still:.3} s; inviscid model A0 = 0/0.5/1: {inviscid:.3?}; drag: {drag:.3?}"
    );
    assert!(drag[0] > still * 1.02);
    assert!((inviscid[0] / still - 1.0).abs() < 0.005);
    for k in 1..3 {
        assert!((drag[k] / drag[0] - 1.0).abs() < 0.02);
    }
}

/// Progress is reported within a point, as its march advances (simulated
/// time over the horizon), not only when it finishes: a one-point chart
/// reports increasing values below one point before it ends.
#[test]
fn ge_chart_progress_advances_within_a_point() {
    use std::sync::Mutex;
    use tetherplan::numerics::ge::chart::PROGRESS_UNITS_PER_POINT;
    let request = GeChartRequest::table_7_1(vec![60.0], vec![1e5]);
    let seen = Mutex::new(Vec::new());
    let progress = |done: usize, total: usize| {
        assert_eq!(total, PROGRESS_UNITS_PER_POINT);
        seen.lock().unwrap().push(done);
    };
    deployment_chart(&request, Parallelism::Serial, &progress, &never).unwrap();
    let seen = seen.into_inner().unwrap();
    let within: Vec<usize> = seen
        .iter()
        .copied()
        .filter(|&d| d > 0 && d < PROGRESS_UNITS_PER_POINT)
        .collect();
    assert!(within.len() >= 3, "progress within the point: {seen:?}");
    assert!(seen.windows(2).all(|w| w[0] < w[1]), "increasing: {seen:?}");
    assert_eq!(*seen.last().unwrap(), PROGRESS_UNITS_PER_POINT);
}
