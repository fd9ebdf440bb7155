//! The turbulence the dynamic tether is blown by (SPEC §11, issue 31):
//! read at a fixed point, as the tether reads it (bilinear in time and
//! height, with the cell series of `numerics::dynamics::wind`), averaged
//! over 20 seeds, its one-sided spectrum follows the requested von Kármán
//! or Kaimal model within 10 % from 0.003 to 0.5 Hz (15 % at 0.001–0.003 Hz,
//! where 20 seeds leave a 6 % sampling error) and its σ_u/U is I within 3 %
//! (measured 0.975: the series' period and Nyquist frequency bound it); two levels are correlated with Davenport's coherence.
//! The point is mid-way between two levels (the worst place: read
//! linearly between the levels alone it kept 0.63–0.65 of the power at
//! 0.03–0.3 Hz). Figures measured on this tree are printed.

use std::f64::consts::PI;

use tetherplan::numerics::dynamics::wind::{
    DAVENPORT_DECAY, FieldGrid, SpectrumModel, Turbulence, TurbulenceField, fft_in_place,
};
use tetherplan::numerics::tether::wind::WindProfile;

const U: f64 = 10.0;
const I: f64 = 0.15;
const L_U: f64 = 340.0;
const SEEDS: u64 = 20;
/// The probe's reading interval (s): the API's default step.
const DT: f64 = 0.05;

/// A field as a one-hour run of the 1000 m tether synthesises it (the
/// defaults of `DynamicsConfig`: 0.2 s, levels 50 m apart up to 1200 m).
fn field(model: SpectrumModel, seed: u64) -> TurbulenceField {
    let t = Turbulence {
        model,
        intensity: I,
        length_scale_m: L_U,
        seed,
    };
    let grid = FieldGrid {
        time_step_s: 0.2,
        period_s: 3600.0 + 2.0 * 1200.0 / U + 10.0,
        top_m: 1200.0,
        levels: 25,
        convection_m_s: U,
    };
    TurbulenceField::synthesise(&t, &WindProfile::uniform(U), &grid).unwrap()
}

/// The readings at height `z` over one period, every [`DT`].
fn readings(f: &TurbulenceField, z: f64) -> Vec<f64> {
    let n = (f.period_s() / DT).round() as usize;
    (0..n).map(|i| f.sample(0.0, z, i as f64 * DT)).collect()
}

/// The one-sided periodogram of a periodic record (m²/s² per Hz) at `k/T`.
fn spectrum(x: &[f64]) -> Vec<(f64, (f64, f64))> {
    let n = x.len();
    assert!(n.is_power_of_two());
    let mut buf: Vec<(f64, f64)> = x.iter().map(|&v| (v, 0.0)).collect();
    fft_in_place(&mut buf, -1.0);
    let t = n as f64 * DT;
    (1..n / 2).map(|k| (k as f64 / t, buf[k])).collect()
}

fn check_model(model: SpectrumModel) {
    let z = 525.0; // mid-way between the levels at 500 and 550 m
    let bands = [
        (0.001, 0.003),
        (0.003, 0.01),
        (0.01, 0.03),
        (0.03, 0.1),
        (0.1, 0.3),
        (0.3, 0.5),
    ];
    let mut measured = vec![0.0; bands.len()];
    let mut expected = vec![0.0; bands.len()];
    let mut variance = 0.0;
    for seed in 0..SEEDS {
        let f = field(model, 1000 + seed);
        let x = readings(&f, z);
        let n = x.len() as f64;
        let mean = x.iter().sum::<f64>() / n;
        variance += x.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / n / SEEDS as f64;
        let t = n * DT;
        for (f_hz, c) in spectrum(&x) {
            // One-sided: 2 |X|² Δt² / T.
            let s = 2.0 * (c.0 * c.0 + c.1 * c.1) * DT * DT / t;
            for (b, &(lo, hi)) in bands.iter().enumerate() {
                if f_hz >= lo && f_hz < hi {
                    measured[b] += s;
                    expected[b] += model.density(f_hz, I * U, L_U, U);
                }
            }
        }
    }
    let sigma_ratio = variance.sqrt() / (I * U);
    println!(
        "{model:?}: σ_u/U = {:.4} (I = {I}): ratio {sigma_ratio:.4}",
        variance.sqrt() / U
    );
    // The band 0.001–0.003 Hz holds 13 periodogram bins per seed: 260 in
    // all, a sampling error of 1/√260 = 6 % (σ); it is held to 15 %
    // (measured 0.872 von Kármán, 0.873 Kaimal), every other band to 10 %
    // (measured 0.988–1.028; before the cell series 0.63–0.65 at 0.03–0.3 Hz).
    for (b, &(lo, hi)) in bands.iter().enumerate() {
        let r = measured[b] / expected[b];
        println!("  {lo}–{hi} Hz: measured / model = {r:.3}");
        let tol = if b == 0 { 0.15 } else { 0.10 };
        assert!((r - 1.0).abs() <= tol, "{model:?} {lo}–{hi} Hz: {r}");
    }
    assert!(
        (sigma_ratio - 1.0).abs() <= 0.03,
        "{model:?}: σ ratio {sigma_ratio}"
    );
}

#[test]
fn von_karman_spectrum_and_intensity_at_a_fixed_point() {
    check_model(SpectrumModel::VonKarman);
}

#[test]
fn kaimal_spectrum_and_intensity_at_a_fixed_point() {
    check_model(SpectrumModel::Kaimal);
}

/// The co-coherence of two levels 50 m apart (500 and 550 m) against
/// Davenport's `exp(−C f Δz/U)` (C = 10), averaged over 20 seeds in
/// bands: within 0.1 (measured in the output).
#[test]
fn levels_have_davenports_coherence() {
    let bands = [(0.002, 0.005), (0.005, 0.01), (0.01, 0.02), (0.02, 0.05)];
    let mut cross = vec![0.0; bands.len()];
    let mut auto_a = vec![0.0; bands.len()];
    let mut auto_b = vec![0.0; bands.len()];
    let mut model = vec![(0.0, 0usize); bands.len()];
    for seed in 0..SEEDS {
        let f = field(SpectrumModel::VonKarman, 2000 + seed);
        let a = spectrum(&readings(&f, 500.0));
        let b = spectrum(&readings(&f, 550.0));
        for ((fa, ca), (_, cb)) in a.iter().zip(&b) {
            for (k, &(lo, hi)) in bands.iter().enumerate() {
                if *fa >= lo && *fa < hi {
                    cross[k] += ca.0 * cb.0 + ca.1 * cb.1;
                    auto_a[k] += ca.0 * ca.0 + ca.1 * ca.1;
                    auto_b[k] += cb.0 * cb.0 + cb.1 * cb.1;
                    if seed == 0 {
                        model[k].0 += (-DAVENPORT_DECAY * fa * 50.0 / U).exp();
                        model[k].1 += 1;
                    }
                }
            }
        }
    }
    for (k, &(lo, hi)) in bands.iter().enumerate() {
        let coh = cross[k] / (auto_a[k] * auto_b[k]).sqrt();
        let want = model[k].0 / model[k].1 as f64;
        println!("  {lo}–{hi} Hz: co-coherence {coh:.3}, Davenport {want:.3}");
        assert!((coh - want).abs() <= 0.1, "{lo}–{hi} Hz: {coh} vs {want}");
    }
    let _ = PI;
}
