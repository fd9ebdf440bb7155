//! Verification of the transient response of the linear string (issue 4,
//! SPEC §2, thesis ch. 3.5, 4.3, 4.4) against the QEP, the WKB asymptotics
//! of the one-mode model, and the thesis's cases. Thesis data (Table A1)
//! throughout: ρA = 0.078 kg/m, F = 1000 N, m = 10 kg, L0 = 1 m,
//! c = 113.23 m/s, m̃ = 128.2, F̃ = 1306.9.

use std::f64::consts::PI;

use tetherplan::numerics::aero::{Aerodynamics, AerostatBody, AirFlow, ForceModel, SteadyFlow};
use tetherplan::numerics::parallel::Parallelism;
use tetherplan::numerics::params::{AerostatSystem, NondimState};
use tetherplan::numerics::profile::Profile;
use tetherplan::numerics::string::StringModel;
use tetherplan::numerics::string::critical::{Onset, SearchConfig, critical_time};
use tetherplan::numerics::string::frequency_response;
use tetherplan::numerics::string::reduced::ReducedModel;
use tetherplan::numerics::string::rest_modes::modal_energies;
use tetherplan::numerics::string::transient::{
    self, EigenTracking, InitialState, RunOutcome, Sample, Silent, TransientConfig, TransientRun,
};

fn thesis_model(elements: usize) -> StringModel {
    StringModel::new(AerostatSystem::thesis(), elements).unwrap()
}

fn config(
    duration_s: f64,
    time_step_s: Option<f64>,
    samples: usize,
    initial: InitialState,
) -> TransientConfig {
    TransientConfig {
        duration_s,
        time_step_s,
        samples,
        initial,
        aero: None,
        eigen: None,
    }
}

fn run(model: &StringModel, profile: &Profile, config: &TransientConfig) -> TransientRun {
    transient::simulate(model, profile, config, &Silent).unwrap()
}

/// Mean period (s) between upward zero crossings of the tip.
fn tip_period(samples: &[Sample]) -> f64 {
    let mut ups = vec![];
    for w in samples.windows(2) {
        let (a, b) = (w[0].tip_deflection_m, w[1].tip_deflection_m);
        if a < 0.0 && b >= 0.0 {
            ups.push(w[0].time_s + (w[1].time_s - w[0].time_s) * (-a) / (b - a));
        }
    }
    assert!(ups.len() >= 5, "too few oscillations: {}", ups.len());
    (ups[ups.len() - 1] - ups[0]) / (ups.len() - 1) as f64
}

fn thesis_body() -> AerostatBody {
    AerostatBody::new(0.5, 1.205, None).unwrap()
}

/// Newmark on a cable of fixed length (L = L0 = 1 m, n = 50), started in
/// its first or second mode: the tip period matches `2π / Im λ_k` of the
/// QEP within 0.5 % (measured: see the assertion messages; the trapezoidal
/// rule lags by `(ωΔt)²/12` ≈ 0.01 % at 200 steps per period).
#[test]
fn fixed_length_periods_match_the_qep() {
    let model = thesis_model(50);
    let profile = Profile::constant_rate(1.0, 0.0, None).unwrap();
    let sys = model.system;
    let spectrum = model
        .spectrum(NondimState {
            length: 1.0,
            rate: 0.0,
            acceleration: 0.0,
        })
        .unwrap();
    let modes = spectrum.modes();
    for mode in [1, 2] {
        let omega = sys.eigenvalue_to_si(modes[mode - 1].im);
        let period = 2.0 * PI / omega;
        let c = config(
            20.0 * period,
            Some(period / 200.0),
            4001,
            InitialState::Mode {
                mode,
                tip_deflection_m: 0.01,
            },
        );
        let r = run(&model, &profile, &c);
        assert_eq!(r.outcome, RunOutcome::Completed);
        let measured = tip_period(&r.samples);
        let error = measured / period - 1.0;
        println!(
            "mode {mode}: QEP period {period:.6} s, Newmark {measured:.6} s, error {:.4} %",
            100.0 * error
        );
        assert!(error.abs() < 0.005, "mode {mode}: period error {error}");
    }
}

/// Without loads and at fixed length the average-acceleration scheme keeps
/// the energy (3.14) constant: from `0.01 ζ⁴` (all modes excited), 20 000
/// steps, relative drift below 1e-9.
#[test]
fn fixed_length_energy_is_conserved() {
    let model = thesis_model(50);
    let profile = Profile::constant_rate(1.0, 0.0, None).unwrap();
    let c = config(
        10.0,
        Some(5e-4),
        201,
        InitialState::Shape {
            tip_deflection_m: 0.01,
        },
    );
    let r = run(&model, &profile, &c);
    let e0 = r.samples[0].energy_j;
    assert!(e0 > 0.0);
    let drift = r
        .samples
        .iter()
        .map(|s| (s.energy_j / e0 - 1.0).abs())
        .fold(0.0, f64::max);
    println!("energy {e0:.6e} J, max relative drift {drift:.2e}");
    assert!(drift < 1e-9, "drift {drift}");
}

/// Peaks of |tip| per window of `window_s`: (window centre time, length, peak).
fn windowed_peaks(samples: &[Sample], window_s: f64) -> Vec<(f64, f64, f64)> {
    let mut out = vec![];
    let mut start = samples[0].time_s;
    let mut peak: f64 = 0.0;
    let mut length_sum = 0.0;
    let mut count = 0.0;
    for s in samples {
        if s.time_s >= start + window_s {
            out.push((start + 0.5 * window_s, length_sum / count, peak));
            start += window_s;
            peak = 0.0;
            length_sum = 0.0;
            count = 0.0;
        }
        peak = peak.max(s.tip_envelope_m);
        length_sum += s.length_m;
        count += 1.0;
    }
    out
}

struct SlowCase {
    /// (time, length, FE peak, WKB amplitude) per window
    windows: Vec<(f64, f64, f64, f64)>,
    run: TransientRun,
}

/// Constant `ṽ = ±0.001` between l = 1 and l = 6 (t̄ = 5000, 44.2 s),
/// started in the first rest mode with 0.01 m at the tip.
fn slow_case(lengthening: bool) -> SlowCase {
    let model = thesis_model(50);
    let sys = model.system;
    let c = sys.wave_speed_m_s();
    let (l_start, rate) = if lengthening {
        (1.0, 0.001 * c)
    } else {
        (6.0, -0.001 * c)
    };
    let l_end = if lengthening { 6.0 } else { 1.0 };
    let profile = Profile::constant_rate(l_start, rate, Some(l_end)).unwrap();
    let duration = 5000.0 * sys.time_scale_s();
    let mut cfg = config(
        duration,
        None,
        20_000,
        InitialState::Mode {
            mode: 1,
            tip_deflection_m: 0.01,
        },
    );
    cfg.eigen = Some(EigenTracking {
        interval_s: duration / 50.0,
        count: 3,
    });
    let run = run(&model, &profile, &cfg);
    let reduced = ReducedModel::new(sys);
    let period0 = 2.0 * PI / sys.eigenvalue_to_si(reduced.frequency(l_start).unwrap());
    let peaks = windowed_peaks(&run.samples, 2.0 * period0);
    let a0 = peaks[0].2;
    let l0 = peaks[0].1;
    let windows = peaks
        .iter()
        .map(|&(t, l, p)| (t, l, p, reduced.wkb_amplitude(l, l0, a0).unwrap()))
        .collect();
    SlowCase { windows, run }
}

/// Figs 3.1–3.4: `ṽ = 0.001` lengthening l = 1 → 6 and shortening 6 → 1.
/// * The FE tip envelope (peak |y_tip| per two periods) follows the WKB
///   amplitude `A0 ∝ [ψ(2m̃ + l)]^{-1/2}` of the one-mode model within 3 %
///   (measured 0.9 % lengthening, 1.4 % shortening).
/// * The vibration energy falls while lengthening and rises while
///   shortening, window by window, and its end/start ratio equals the
///   WKB prediction `ψ(l_end)/ψ(l_start)` (energy/frequency is adiabatic)
///   within 3 % (measured 0.406 vs 0.404).
/// * The FE first frequency Im λ1 and ψ both fall as l grows; ψ lies above
///   Im λ1 by 10.6–11.0 % (the assumed mode sin(πζ/2) is stiffer than the
///   true, nearly linear, first mode of a cable with a heavy end mass):
///   asserted within 9–12 %.
#[test]
fn slow_lengthening_and_shortening_follow_wkb() {
    let sys = AerostatSystem::thesis();
    let reduced = ReducedModel::new(sys);
    let ts = sys.time_scale_s();
    for lengthening in [true, false] {
        let name = if lengthening {
            "lengthening"
        } else {
            "shortening"
        };
        let case = slow_case(lengthening);
        assert_eq!(case.run.outcome, RunOutcome::Completed);
        let worst = case
            .windows
            .iter()
            .map(|w| (w.2 / w.3 - 1.0).abs())
            .fold(0.0, f64::max);
        let (first, last) = (case.windows.first().unwrap(), case.windows.last().unwrap());
        println!(
            "{name}: FE peak {:.5} -> {:.5} m, WKB {:.5} -> {:.5} m, worst gap {:.2} %",
            first.2,
            last.2,
            first.3,
            last.3,
            100.0 * worst
        );
        assert!(
            worst < 0.03,
            "{name}: FE envelope departs from WKB by {worst}"
        );
        // the envelope really changes (by > 25 %), so the comparison means something
        assert!((last.2 / first.2 - 1.0).abs() > 0.25);

        // energy: window means, monotone, ratio = ψ ratio
        let samples = &case.run.samples;
        let per_window = samples.len() / 40;
        let means: Vec<f64> = samples
            .chunks(per_window)
            .filter(|c| c.len() == per_window)
            .map(|c| c.iter().map(|s| s.vibration_energy_j).sum::<f64>() / c.len() as f64)
            .collect();
        for w in means.windows(2) {
            if lengthening {
                assert!(w[1] < w[0], "{name}: energy rose {} -> {}", w[0], w[1]);
            } else {
                assert!(w[1] > w[0], "{name}: energy fell {} -> {}", w[0], w[1]);
            }
        }
        let (l0, l1) = (samples[0].length_m, samples.last().unwrap().length_m);
        let predicted = reduced.frequency(l1).unwrap() / reduced.frequency(l0).unwrap();
        let measured = means.last().unwrap() / means[0];
        let measured_ends =
            samples.last().unwrap().vibration_energy_j / samples[0].vibration_energy_j;
        println!(
            "{name}: energy ratio {measured_ends:.4} (window means {measured:.4}), WKB {predicted:.4}"
        );
        assert!(
            (measured_ends / predicted - 1.0).abs() < 0.03,
            "{name}: energy ratio {measured_ends} vs {predicted}"
        );

        // first frequency against ψ
        let mut previous: Option<(f64, f64)> = None;
        for ev in &case.run.eigen {
            let fe = ev.modes[0].im_1_s;
            let psi = reduced.frequency(ev.length_m).unwrap() / ts;
            let gap = psi / fe - 1.0;
            assert!(
                (0.09..0.12).contains(&gap),
                "{name}: ψ vs FE gap {gap} at L = {}",
                ev.length_m
            );
            if let Some((fe0, psi0)) = previous {
                if lengthening {
                    assert!(fe < fe0 && psi < psi0);
                } else {
                    assert!(fe > fe0 && psi > psi0);
                }
            }
            previous = Some((fe, psi));
        }
    }
}

fn thesis_wind(flow: AirFlow) -> Aerodynamics {
    Aerodynamics::new(flow, ForceModel::Thesis, thesis_body(), 10.0).unwrap()
}

/// Time (s) at which the first natural frequency Im λ1 of the lengthening
/// cable (1 m/s from 1 m, thesis data, with the tip added mass) falls to
/// `omega`, by bisection on the QEP, and the passage time scale
/// `τ_r = √(2π / |dω1/dt|)` there (the width of a swept resonance).
fn first_frequency_crossing(model: &StringModel, added_mass_kg: f64, omega: f64) -> (f64, f64) {
    let sys = model.system;
    let heavier = AerostatSystem::new(
        sys.mass_per_length_kg_m,
        sys.net_buoyancy_n,
        sys.aerostat_mass_kg + added_mass_kg,
        1.0,
        sys.gravity_m_s2,
    )
    .unwrap();
    let m = StringModel::with_operators(heavier, model.operators.clone());
    let w1 = |t: f64| {
        let s = heavier.to_nondim(tetherplan::numerics::params::Kinematics {
            length_m: 1.0 + t,
            rate_m_s: 1.0,
            acceleration_m_s2: 0.0,
        });
        heavier.eigenvalue_to_si(m.spectrum(s).unwrap().modes()[0].im)
    };
    let (mut lo, mut hi) = (0.0, 200.0);
    assert!(w1(lo) > omega && w1(hi) < omega);
    for _ in 0..50 {
        let mid = 0.5 * (lo + hi);
        if w1(mid) > omega { lo = mid } else { hi = mid }
    }
    let t = 0.5 * (lo + hi);
    let slope = (w1(t + 0.5) - w1(t - 0.5)) / 1.0;
    (t, (2.0 * PI / slope.abs()).sqrt())
}

/// Centre time of the first window whose tip peak reaches half the
/// largest peak of the run: when the resonance has built the response up.
fn half_rise_time(peaks: &[(f64, f64, f64)]) -> f64 {
    let max = peaks.iter().map(|p| p.2).fold(0.0, f64::max);
    peaks.iter().find(|p| p.2 >= 0.5 * max).unwrap().0
}

/// Fig 4.5: L0 = 1 m, 1 m/s, `u = 10 sin(2t)` m/s, sphere r = 0.5 m, air
/// 1.205 kg/m³ (thesis force model). The first natural frequency falls
/// through ω = 2 rad/s at t* = 21.7 s (QEP). The tip envelope reaches half
/// its largest value inside `[t* − τ_r/4, t* + 3τ_r/4]`, `τ_r = √(2π/|ω̇1|)`
/// = 11.6 s the width of a swept resonance (measured 25.0 s = t* + 0.29 τ_r),
/// the amplitude after the passage is more than 5× the amplitude before
/// t* − 10 s (measured 6.69 m vs 0.45 m), and the energy jumps > 10×.
/// The tracked eigenvalues along the run agree with the direct QEP t*.
#[test]
fn wind_resonance_when_the_first_frequency_passes_the_forcing() {
    let model = thesis_model(50);
    let profile = Profile::constant_rate(1.0, 1.0, None).unwrap();
    let omega = 2.0;
    let aero = thesis_wind(AirFlow::sinusoidal(10.0, omega).unwrap());
    let (t_star, width) = first_frequency_crossing(&model, aero.added_mass_kg(), omega);
    let mut cfg = config(60.0, None, 1200, InitialState::Rest);
    cfg.aero = Some(aero);
    cfg.eigen = Some(EigenTracking {
        interval_s: 0.5,
        count: 3,
    });
    let r = run(&model, &profile, &cfg);
    assert_eq!(r.outcome, RunOutcome::Completed);
    // the tracked first frequency crosses ω between the evaluations around t*
    let crossing = r
        .eigen
        .windows(2)
        .find(|w| w[0].modes[0].im_1_s > omega && w[1].modes[0].im_1_s <= omega)
        .unwrap();
    assert!(crossing[0].time_s <= t_star && t_star <= crossing[1].time_s + 1e-9);
    let peaks = windowed_peaks(&r.samples, 2.0);
    let growth = half_rise_time(&peaks);
    let before = peaks
        .iter()
        .filter(|p| p.0 < t_star - 10.0)
        .map(|p| p.2)
        .fold(0.0, f64::max);
    let after = peaks
        .iter()
        .filter(|p| p.0 > t_star + 5.0)
        .map(|p| p.2)
        .fold(0.0, f64::max);
    println!(
        "t* = {t_star:.2} s, τ_r = {width:.2} s, half rise at {growth:.2} s, peak before {before:.3} m, after {after:.3} m"
    );
    assert!(
        growth >= t_star - 0.25 * width && growth <= t_star + 0.75 * width,
        "growth at {growth} s, t* = {t_star} s"
    );
    assert!(after > 5.0 * before, "after {after} vs before {before}");
    // the energy jumps through the resonance (Fig 4.5c)
    let energy_at = |t: f64| {
        r.samples
            .iter()
            .find(|s| s.time_s >= t)
            .unwrap()
            .vibration_energy_j
    };
    assert!(energy_at(t_star + 6.0) > 10.0 * energy_at(t_star - 10.0));
}

/// Fig 4.5d: the frequency-response surface of the same case (1 m/s from
/// 1 m, `u = 10 sin(ω t)`, 60 s, n = 50, 16 frequencies 0.5–8 rad/s). For
/// ω = 1.5, 2, 2.5, 3 rad/s the envelope reaches half its peak inside
/// `[t* − τ_r/4, t* + 3τ_r/4]` of the QEP passage (measured t* + 0.24–0.38
/// τ_r); the largest amplitudes lie below 4 rad/s, more than twice those
/// from 4 rad/s up (measured 9.18 m vs 3.66 m, Fig 4.5d); parallel and serial
/// runs agree bit for bit; progress counts every run.
#[test]
fn frequency_response_surface() {
    use std::sync::atomic::{AtomicUsize, Ordering};
    struct Count(AtomicUsize, AtomicUsize);
    impl transient::Observer for Count {
        fn report(&self, done: usize, total: usize) {
            self.0.fetch_max(done, Ordering::Relaxed);
            self.1.store(total, Ordering::Relaxed);
        }
    }
    let model = thesis_model(50);
    let profile = Profile::constant_rate(1.0, 1.0, None).unwrap();
    let aero = thesis_wind(AirFlow::sinusoidal(10.0, 1.0).unwrap());
    let added = aero.added_mass_kg();
    let mut cfg = config(60.0, None, 600, InitialState::Rest);
    cfg.aero = Some(aero);
    let ws: Vec<f64> = (1..=16).map(|i| 0.5 * i as f64).collect();
    let count = Count(AtomicUsize::new(0), AtomicUsize::new(0));
    let par = frequency_response::frequency_response(
        &model,
        &profile,
        &cfg,
        10.0,
        &ws,
        Parallelism::Rayon,
        &count,
    )
    .unwrap();
    assert_eq!(
        (
            count.0.load(Ordering::Relaxed),
            count.1.load(Ordering::Relaxed)
        ),
        (16, 16)
    );
    let ser = frequency_response::frequency_response(
        &model,
        &profile,
        &cfg,
        10.0,
        &ws,
        Parallelism::Serial,
        &Silent,
    )
    .unwrap();
    assert_eq!(par, ser);
    assert_eq!(par.time_s.len(), 600);
    for (i, &w) in ws.iter().enumerate() {
        if !(1.5..=3.0).contains(&w) {
            continue;
        }
        let (t_star, width) = first_frequency_crossing(&model, added, w);
        // windowed peaks of 2 s from the 0.1 s envelope samples
        let peaks: Vec<(f64, f64, f64)> = par.envelope_m[i]
            .chunks(20)
            .enumerate()
            .map(|(k, c)| {
                (
                    par.time_s[k * 20] + 1.0,
                    0.0,
                    c.iter().cloned().fold(0.0, f64::max),
                )
            })
            .collect();
        let growth = half_rise_time(&peaks);
        println!(
            "ω = {w}: t* = {t_star:.2} s, τ_r = {width:.2} s, half rise at {growth:.2} s, peak {:.3} m",
            par.peak_m[i]
        );
        assert!(
            growth >= t_star - 0.25 * width && growth <= t_star + 0.75 * width,
            "ω = {w}: growth at {growth} s, t* = {t_star} s"
        );
    }
    let low = (0..ws.len())
        .filter(|&i| ws[i] < 4.0)
        .map(|i| par.peak_m[i])
        .fold(0.0, f64::max);
    let high = (0..ws.len())
        .filter(|&i| ws[i] >= 4.0)
        .map(|i| par.peak_m[i])
        .fold(0.0, f64::max);
    println!("largest peak below 4 rad/s {low:.3} m, from 4 rad/s {high:.3} m");
    assert!(low > 2.0 * high);
}

fn drag_wind(flow: AirFlow) -> Aerodynamics {
    let body = thesis_body();
    Aerodynamics::new(
        flow,
        ForceModel::Drag {
            drag_coefficient: 0.5,
            reference_area_m2: body.frontal_area_m2(),
        },
        body,
        10.0,
    )
    .unwrap()
}

/// Static tip deflection (m) of a cable of fixed length `length_m` under a
/// horizontal tip force `force_n`, from the discrete `K q = f`.
fn static_tip_deflection(model: &StringModel, length_m: f64, force_n: f64) -> f64 {
    let sys = model.system;
    let sys_matrices = model.matrices(NondimState {
        length: length_m / sys.initial_length_m,
        rate: 0.0,
        acceleration: 0.0,
    });
    let n = model.elements();
    let mut q = vec![0.0; n];
    q[n - 1] = force_n / sys.net_buoyancy_n;
    sys_matrices.stiffness.solve_columns_in_place(&mut q, 1);
    q[n - 1] * sys.initial_length_m
}

/// Blow-down: at a fixed length of 500 m in a uniform 5 m/s wind, the
/// `drag` model (C_D = 0.5, r = 0.5 m) pushes the aerostat down-wind; the
/// aerodynamic damping settles it on the static deflection
/// `P/(ρA g) ln(F/T(0))` of a heavy string (P the drag at rest), which the
/// FE `K⁻¹f` reproduces within 0.1 % and the run's final mean within 1 %.
/// The inviscid `thesis` model exerts no force in a uniform steady flow.
#[test]
fn steady_wind_blows_the_aerostat_down_under_drag() {
    let model = thesis_model(50);
    let sys = model.system;
    let length = 500.0;
    let profile = Profile::constant_rate(length, 0.0, None).unwrap();
    let flow = AirFlow::Steady(SteadyFlow::uniform(5.0).unwrap());
    let aero = drag_wind(flow.clone());
    let drag_n = aero.force_n(length, 0.0, 0.0);
    let bottom_tension = sys.net_buoyancy_n - sys.mass_per_length_kg_m * sys.gravity_m_s2 * length;
    let closed_form = drag_n / (sys.mass_per_length_kg_m * sys.gravity_m_s2)
        * (sys.net_buoyancy_n / bottom_tension).ln();
    let fe_static = static_tip_deflection(&model, length, drag_n);
    assert!(
        (fe_static / closed_form - 1.0).abs() < 1e-3,
        "{fe_static} vs {closed_form}"
    );
    let mut cfg = config(1500.0, Some(0.05), 3001, InitialState::Rest);
    cfg.aero = Some(aero);
    let r = run(&model, &profile, &cfg);
    let tail = &r.samples[2500..];
    let mean = tail.iter().map(|s| s.tip_deflection_m).sum::<f64>() / tail.len() as f64;
    println!(
        "drag {drag_n:.4} N, closed form {closed_form:.4} m, FE static {fe_static:.4} m, run mean {mean:.4} m"
    );
    assert!(
        (mean / fe_static - 1.0).abs() < 0.01,
        "mean {mean} vs static {fe_static}"
    );
    assert!(mean > 0.1, "blow-down is down-wind and sizeable");
    // thesis model: inviscid, uniform steady flow → no load, no motion
    let mut cfg = config(100.0, Some(0.05), 101, InitialState::Rest);
    cfg.aero = Some(thesis_wind(flow));
    let r = run(&model, &profile, &cfg);
    assert!(r.samples.iter().all(|s| s.tip_deflection_m == 0.0));
}

fn deployment(target_m: f64, duration_s: f64) -> (Profile, TransientRun) {
    let model = thesis_model(50);
    let profile = Profile::trapezoidal(1.0, 10.0, 5.0, 5.0, target_m).unwrap();
    let mut cfg = config(duration_s, None, 4000, InitialState::Rest);
    cfg.aero = Some(drag_wind(AirFlow::Steady(
        SteadyFlow::power_law(0.1, 1.0 / 3.0).unwrap(),
    )));
    cfg.eigen = Some(EigenTracking {
        interval_s: 1.0,
        count: 3,
    });
    let r = run(&model, &profile, &cfg);
    (profile, r)
}

/// Ch. 4.4, Fig 4.10: deployment at 10 m/s (5 s ramps) from 1 m in the
/// steady wind `u = 0.1 z^{1/3}` (drag model, C_D = 0.5, r = 0.5 m).
/// * To 2 km: the critical-time search on the trapezoidal profile gives
///   t* = 133.4 s at L = 1310 m (≈ 1 % above the closed-form 1296.7 m for
///   10 m/s; the thesis reads ≈ 140 s off its transient). The tip stays
///   within 2 m (blow-down plus oscillation) up to t*, then grows without
///   bound: past 100× its pre-t* peak after t* (measured 167 s) and the run
///   stops as diverged (192 s). The eigenvalues tracked every second are
///   stable before t* and unstable after it (until the blow-up).
/// * To 1.1 km: the search finds no onset; every tracked eigenvalue is
///   stable, and after the stop the tip stays within 1.5× the static
///   blow-down at 1.1 km (measured peak 0.72 m vs 0.61 m static).
#[test]
fn ramped_deployment_goes_unstable_past_the_critical_length_only() {
    let model = thesis_model(50);
    let (profile, r) = deployment(2000.0, 215.0);
    let ct = critical_time(&model, &profile, SearchConfig::default()).unwrap();
    assert!(ct.confirmed());
    let Onset::During {
        time_s: t_star,
        length_m,
    } = ct.onset
    else {
        panic!("expected an onset, got {:?}", ct.onset)
    };
    let closed = model.system.closed_form_elevation_m(10.0);
    println!(
        "2 km: t* = {t_star:.2} s at {length_m:.1} m (closed form {closed:.1} m); outcome {:?}",
        r.outcome
    );
    assert!(length_m > closed && length_m < 1.02 * closed);
    assert!((125.0..145.0).contains(&t_star));
    let before = r
        .samples
        .iter()
        .filter(|s| s.time_s <= t_star)
        .map(|s| s.tip_envelope_m)
        .fold(0.0, f64::max);
    assert!(before < 2.0, "pre-critical peak {before} m");
    // The tip passes 100× its pre-t* peak, or the run stops first because
    // a deflection near the roller (where the onset is) passed the
    // magnitude cap of MAGNITUDE_CAP_LENGTHS × the length.
    let blow_up_time_s = match r.samples.iter().find(|s| s.tip_envelope_m > 100.0 * before) {
        Some(s) => s.time_s,
        None => match r.outcome {
            RunOutcome::Diverged { time_s } if r.stopped_at_cap => time_s,
            other => panic!("the deflection must grow without bound, got {other:?}"),
        },
    };
    println!("pre-t* peak {before:.3} m; blow-up (100x tip or cap) at {blow_up_time_s:.1} s");
    assert!(blow_up_time_s > t_star);
    // Eigenvalues while the deflection is still within the linear model
    // (beyond, the drag linearised about ẏ ~ 1e5 m/s swamps the QEP).
    let tracked: Vec<_> = r
        .eigen
        .iter()
        .filter(|e| e.time_s < blow_up_time_s)
        .collect();
    assert!(tracked.iter().any(|e| e.time_s > t_star + 10.0));
    for ev in tracked {
        if ev.time_s < t_star - 0.5 {
            assert!(ev.stable, "unstable at {} s before t*", ev.time_s);
        } else if ev.time_s > t_star + 0.5 {
            assert!(!ev.stable, "stable at {} s after t*", ev.time_s);
        }
    }
    assert!(matches!(r.outcome, RunOutcome::Diverged { time_s } if time_s > t_star));

    let (profile, r) = deployment(1100.0, 140.0);
    let ct = critical_time(&model, &profile, SearchConfig::default()).unwrap();
    assert!(
        matches!(ct.onset, Onset::Never { .. }) && ct.confirmed(),
        "{:?}",
        ct.onset
    );
    assert_eq!(r.outcome, RunOutcome::Completed);
    assert!(r.eigen.iter().all(|e| e.stable));
    let stop = profile.stop_time_s().unwrap();
    let aero = drag_wind(AirFlow::Steady(
        SteadyFlow::power_law(0.1, 1.0 / 3.0).unwrap(),
    ));
    let static_m = static_tip_deflection(&model, 1100.0, aero.force_n(1100.0, 0.0, 0.0));
    let after = r
        .samples
        .iter()
        .filter(|s| s.time_s > stop)
        .map(|s| s.tip_envelope_m)
        .fold(0.0, f64::max);
    println!(
        "1.1 km: stop at {stop:.1} s, static blow-down {static_m:.3} m, post-stop peak {after:.3} m"
    );
    assert!(after < 1.5 * static_m && after > 0.5 * static_m);
}

/// Post-stop modal energies (J) of a 10 m/s deployment to 1.1 km with
/// ramps of `ramp_s`, in the steady wind `0.1 z^{1/3}` (inviscid thesis
/// model: no aerodynamic damping, so after the stop each mode keeps its
/// energy), measured 10 s after the stop about the static equilibrium.
fn post_stop_modal_energies(ramp_s: f64) -> Vec<f64> {
    let model = thesis_model(50);
    let sys = model.system;
    let profile = Profile::trapezoidal(1.0, 10.0, ramp_s, ramp_s, 1100.0).unwrap();
    let stop = profile.stop_time_s().unwrap();
    let mut cfg = config(stop + 10.0, None, 1000, InitialState::Rest);
    cfg.aero = Some(thesis_wind(AirFlow::Steady(
        SteadyFlow::power_law(0.1, 1.0 / 3.0).unwrap(),
    )));
    let r = run(&model, &profile, &cfg);
    assert_eq!(r.outcome, RunOutcome::Completed);
    let load = r.samples.last().unwrap().tip_force_n / sys.net_buoyancy_n;
    let l = 1100.0 / sys.initial_length_m;
    let e = modal_energies(
        &model,
        l,
        r.tip_mass_nondim,
        load,
        &r.final_state.displacement,
        &r.final_state.velocity,
    )
    .unwrap();
    e.iter()
        .map(|x| x.1 * sys.net_buoyancy_n * sys.initial_length_m)
        .collect()
}

/// Figs 4.8–4.9: deploying to 1.1 km at 10 m/s, sharp ramps (1 s) leave
/// most of the post-stop vibration energy in the higher modes (≥ 2), gradual
/// ramps (20 s) very little. Measured: higher-mode energy 3.18e-9 J (sharp)
/// vs 4.16e-11 J (gradual), ratio 0.013, asserted < 0.05; higher-mode share
/// 88 % vs 8 %, asserted > 50 % and < 20 %. Ramps of 5 and 10 s fall in
/// between, monotonically.
#[test]
fn gradual_ramps_excite_less_higher_mode_energy_than_sharp_ones() {
    let high = |e: &[f64]| e[1..].iter().sum::<f64>();
    let share = |e: &[f64]| high(e) / e.iter().sum::<f64>();
    let energies: Vec<Vec<f64>> = [1.0, 5.0, 10.0, 20.0]
        .iter()
        .map(|&r| post_stop_modal_energies(r))
        .collect();
    for (r, e) in [1.0, 5.0, 10.0, 20.0].iter().zip(&energies) {
        println!(
            "ramps {r} s: mode-1 energy {:.3e} J, higher modes {:.3e} J, share {:.1} %",
            e[0],
            high(e),
            100.0 * share(e)
        );
    }
    let (sharp, gradual) = (&energies[0], &energies[3]);
    assert!(high(gradual) < 0.05 * high(sharp));
    assert!(share(sharp) > 0.5 && share(gradual) < 0.2);
    for w in energies.windows(2) {
        assert!(high(&w[1]) < high(&w[0]));
    }
}

/// The critical-time search accepts the new profiles: on a trapezoid
/// (10 m/s, 5 s ramps, to 2 km) and on the same schedule as a rate table
/// it finds the same onset, confirmed by the QEP either side, within 0.5 %
/// of constant-rate lengthening's exact pencil answer shifted by the ramp
/// (the onset length is the constant-rate critical length: the cable is
/// cruising when it gets there).
#[test]
fn critical_time_accepts_trapezoidal_and_table_profiles() {
    let model = thesis_model(50);
    let trapezoid = Profile::trapezoidal(1.0, 10.0, 5.0, 5.0, 2000.0).unwrap();
    let stop = trapezoid.stop_time_s().unwrap();
    let table = Profile::piecewise_linear_rate(
        1.0,
        &[(0.0, 0.0), (5.0, 10.0), (stop - 5.0, 10.0), (stop, 0.0)],
        None,
    )
    .unwrap();
    let exact =
        tetherplan::numerics::string::critical::constant_rate_lengthening(&model, 10.0, None);
    let Onset::During {
        length_m: exact_length,
        ..
    } = exact.onset
    else {
        panic!()
    };
    for profile in [&trapezoid, &table] {
        let ct = critical_time(&model, profile, SearchConfig::default()).unwrap();
        assert!(ct.confirmed(), "{:?}", ct.probes);
        let Onset::During { time_s, length_m } = ct.onset else {
            panic!("{:?}", ct.onset)
        };
        println!(
            "t* = {time_s:.3} s at {length_m:.2} m (constant-rate pencil {exact_length:.2} m)"
        );
        assert!((length_m / exact_length - 1.0).abs() < 5e-3);
        assert!((time_s - (2.5 + (exact_length - 1.0) / 10.0)).abs() < 0.5);
    }
    // Shortening (negative cruise rate) is unstable as soon as it moves.
    let retrieval = Profile::trapezoidal(100.0, -2.0, 1.0, 1.0, 50.0).unwrap();
    let ct = critical_time(&model, &retrieval, SearchConfig::default()).unwrap();
    println!("retrieval: {:?} via {:?}", ct.onset, ct.method);
    assert!(ct.time_s().is_some_and(|t| t < 0.01), "{:?}", ct.onset);
}

/// The one-mode model itself (thesis ch. 3): its numerical solution at
/// `ṽ = 0.001` (l = 1 → 6, t̄ = 5000) has the WKB envelope within 1 %
/// at every half-cycle peak (measured 0.001 %), and its leading-order energy `¼(α/l + γ)A0²`
/// falls in proportion to ψ (the adiabatic invariant E/ψ is constant).
#[test]
fn one_mode_model_follows_its_wkb_solution() {
    let sys = AerostatSystem::thesis();
    let reduced = ReducedModel::new(sys);
    let c = sys.wave_speed_m_s();
    let profile = Profile::constant_rate(1.0, 0.001 * c, None).unwrap();
    let ts = sys.time_scale_s();
    let dt_s = 0.05 * ts; // t̄ step 0.05: ~1300 steps per period
    let steps = 100_000; // t̄ = 5000
    let q = reduced.simulate(&profile, 0.01, dt_s, steps).unwrap();
    // every local maximum of |q| (one per half cycle) against WKB there
    let mut worst: f64 = 0.0;
    let mut peaks = 0;
    for i in 1..q.len() - 1 {
        let (a, b, c) = (q[i - 1].abs(), q[i].abs(), q[i + 1].abs());
        if b > a && b >= c {
            let t_bar = (i + 1) as f64 * 0.05;
            let wkb = reduced
                .wkb_amplitude(1.0 + 0.001 * t_bar, 1.0, 0.01)
                .unwrap();
            worst = worst.max((b / wkb - 1.0).abs());
            peaks += 1;
        }
    }
    assert!(peaks > 50, "{peaks} peaks");
    println!(
        "one-mode model vs WKB: worst envelope gap {:.3} %",
        100.0 * worst
    );
    assert!(worst < 0.01);
    let e1 = reduced.mode_energy(1.0, 0.01);
    let a6 = reduced.wkb_amplitude(6.0, 1.0, 0.01).unwrap();
    let e6 = reduced.mode_energy(6.0, a6);
    let psi_ratio = reduced.frequency(6.0).unwrap() / reduced.frequency(1.0).unwrap();
    assert!(
        (e6 / e1 / psi_ratio - 1.0).abs() < 1e-2,
        "{} vs {psi_ratio}",
        e6 / e1
    );
}
