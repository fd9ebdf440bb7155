//! Verification of the transient response of the linear string (issue 4,
//! SPEC §2, thesis ch. 3.5, 4.3, 4.4) against the QEP, the WKB asymptotics
//! of the one-mode model, and the thesis's cases. Thesis data (Table A1)
//! throughout: ρA = 0.078 kg/m, F = 1000 N, m = 10 kg, L0 = 1 m,
//! c = 113.23 m/s, m̃ = 128.2, F̃ = 1306.9.

use std::f64::consts::PI;

use tetherplan::numerics::aero::{AerostatBody, Aerodynamics, AirFlow, ForceModel, SteadyFlow};
use tetherplan::numerics::chart::Parallelism;
use tetherplan::numerics::params::{AerostatSystem, NondimState};
use tetherplan::numerics::profile::Profile;
use tetherplan::numerics::reduced::ReducedModel;
use tetherplan::numerics::string::StringModel;
use tetherplan::numerics::string::critical::{Onset, SearchConfig, critical_time};
use tetherplan::numerics::string::transient::{
    self, EigenTracking, InitialState, RunOutcome, Sample, Silent, TransientConfig, TransientRun, modal_energies,
};

fn thesis_model(elements: usize) -> StringModel {
    StringModel::new(AerostatSystem::thesis(), elements).unwrap()
}

fn config(duration_s: f64, time_step_s: Option<f64>, samples: usize, initial: InitialState) -> TransientConfig {
    TransientConfig { duration_s, time_step_s, samples, initial, aero: None, eigen: None }
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
    let spectrum = model.spectrum(NondimState { length: 1.0, rate: 0.0, acceleration: 0.0 }).unwrap();
    let modes = spectrum.modes();
    for mode in [1, 2] {
        let omega = sys.eigenvalue_to_si(modes[mode - 1].im);
        let period = 2.0 * PI / omega;
        let c = config(20.0 * period, Some(period / 200.0), 4001, InitialState::Mode { mode, tip_deflection_m: 0.01 });
        let r = run(&model, &profile, &c);
        assert_eq!(r.outcome, RunOutcome::Completed);
        let measured = tip_period(&r.samples);
        let error = measured / period - 1.0;
        println!("mode {mode}: QEP period {period:.6} s, Newmark {measured:.6} s, error {:.4} %", 100.0 * error);
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
    let c = config(10.0, Some(5e-4), 201, InitialState::Shape { tip_deflection_m: 0.01 });
    let r = run(&model, &profile, &c);
    let e0 = r.samples[0].energy_j;
    assert!(e0 > 0.0);
    let drift = r.samples.iter().map(|s| (s.energy_j / e0 - 1.0).abs()).fold(0.0, f64::max);
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
    let (l_start, rate) = if lengthening { (1.0, 0.001 * c) } else { (6.0, -0.001 * c) };
    let l_end = if lengthening { 6.0 } else { 1.0 };
    let profile = Profile::constant_rate(l_start, rate, Some(l_end)).unwrap();
    let duration = 5000.0 * sys.time_scale_s();
    let mut cfg = config(duration, None, 20_000, InitialState::Mode { mode: 1, tip_deflection_m: 0.01 });
    cfg.eigen = Some(EigenTracking { interval_s: duration / 50.0, count: 3 });
    let run = run(&model, &profile, &cfg);
    let reduced = ReducedModel::new(sys);
    let period0 = 2.0 * PI / sys.eigenvalue_to_si(reduced.frequency(l_start).unwrap());
    let peaks = windowed_peaks(&run.samples, 2.0 * period0);
    let a0 = peaks[0].2;
    let l0 = peaks[0].1;
    let windows = peaks.iter().map(|&(t, l, p)| (t, l, p, reduced.wkb_amplitude(l, l0, a0).unwrap())).collect();
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
        let name = if lengthening { "lengthening" } else { "shortening" };
        let case = slow_case(lengthening);
        assert_eq!(case.run.outcome, RunOutcome::Completed);
        let worst = case.windows.iter().map(|w| (w.2 / w.3 - 1.0).abs()).fold(0.0, f64::max);
        let (first, last) = (case.windows.first().unwrap(), case.windows.last().unwrap());
        println!("{name}: FE peak {:.5} -> {:.5} m, WKB {:.5} -> {:.5} m, worst gap {:.2} %", first.2, last.2, first.3, last.3, 100.0 * worst);
        assert!(worst < 0.03, "{name}: FE envelope departs from WKB by {worst}");
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
        let measured_ends = samples.last().unwrap().vibration_energy_j / samples[0].vibration_energy_j;
        println!("{name}: energy ratio {measured_ends:.4} (window means {measured:.4}), WKB {predicted:.4}");
        assert!((measured_ends / predicted - 1.0).abs() < 0.03, "{name}: energy ratio {measured_ends} vs {predicted}");

        // first frequency against ψ
        let mut previous: Option<(f64, f64)> = None;
        for ev in &case.run.eigen {
            let fe = ev.modes[0].im_1_s;
            let psi = reduced.frequency(ev.length_m).unwrap() / ts;
            let gap = psi / fe - 1.0;
            assert!((0.09..0.12).contains(&gap), "{name}: ψ vs FE gap {gap} at L = {}", ev.length_m);
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
