//! Wind in time for the dynamic tether (SPEC §11): the steady flow `U(z)`
//! of §6 plus a spatially uniform change `ΔU(t)` (step, ramp, `1 − cos`
//! gust, sinusoid) or a seeded turbulent field `u′(x, z, t)`.
//!
//! **Discrete gusts** (`t0` the start, `T` the duration, `A` the amplitude):
//! step `ΔU = A` for `t ≥ t0`; ramp `ΔU = A min(1, (t − t0)/T)` for `t ≥ t0`;
//! `1 − cos`: `ΔU = (A/2)(1 − cos(2π (t − t0)/T))` on `[t0, t0 + T]`, zero
//! outside (peak `A` at `t0 + T/2`); sinusoid `ΔU = A sin(2π t/T)`.
//!
//! **Turbulence** (longitudinal component only). At levels `z_k`
//! (`k = 0..K`, spacing `Δz`) the one-sided spectrum of `u′` is, with
//! `σ_k = I U(z_k)` and `n = f L_u/U(z_k)`,
//!
//! ```text
//! von Kármán:  S(f) = 4 σ² (L_u/U) / (1 + 70.8 n²)^(5/6)
//! Kaimal:      S(f) = 4 σ² (L_u/U) / (1 + 6 n)^(5/3)
//! ```
//!
//! (both integrate to `σ²`). Levels are correlated with the coherence of
//! Davenport, `coh(Δz, f) = exp(−C f Δz / Ū)` (`C =` [`DAVENPORT_DECAY`],
//! `Ū` the mean of the two levels' speeds). The synthesis is the spectral
//! method of Veers (1988) with a closed-form factor: on a chain of levels
//! the matrix `coh_kj = Π ρ_i` (`ρ_i = exp(−C f (z_i − z_{i−1})/Ū_i)`,
//! the product over the levels between `j` and `k`) is the covariance of
//! the Markov chain `g_0 = ξ_0`, `g_k = ρ_k g_{k−1} + √(1 − ρ_k²) ξ_k`, so
//! its Cholesky factor is applied in `O(K)` per frequency instead of
//! `O(K³)`; with a uniform mean speed it is Davenport's coherence exactly.
//! The Fourier coefficients `√(S_k Δf) g_k` of every frequency
//! `f_m = m/T_p` (`m = 1 … M/2 − 1`) give, by one inverse FFT per level,
//! a periodic series of `M` samples at `Δt_w`; `ξ` (complex standard
//! normal) comes from the counter-based stream of
//! [`crate::numerics::uncertainty::sampling::uniform01`] at
//! `(seed, m, 2k or 2k + 1)`, so the same seed gives the same field on any
//! machine and thread count (the FFT is a fixed sequence of IEEE operations).
//! The band `[1/T_p, 1/(2Δt_w)]` holds all but the spectrum's tails (the
//! measured variance is checked against it in the tests).
//!
//! **Between levels.** Read linearly between two levels alone, a point
//! mid-way would keep only `(1 + ρ)/2` of the power at frequencies whose
//! coherence `ρ` across the cell is small (the turbulence the tether
//! answers to, 0.03–0.3 Hz, lost a third of its energy that way). Each
//! cell `k` (levels `k`, `k + 1`) therefore carries a third series `η_k`,
//! independent of the levels, of spectrum `S̄ (1 − ρ_k)` (`S̄` at the
//! cell's mean speed), and a point at the fraction `φ` of the cell reads
//!
//! ```text
//! u′ = (1 − φ) u′_k + φ u′_{k+1} + √(2 φ (1 − φ)) η_k
//! ```
//!
//! whose spectrum is `S ((1 − φ)² + φ² + 2 φ (1 − φ) ρ + 2 φ (1 − φ)(1 − ρ)) = S`
//! at every frequency and height, continuous across the levels. The series
//! are linear between samples in time, which keeps `1 − (1 − cos 2πfΔt_w)/3`
//! of the power at `f`; the synthesised spectrum is raised by its inverse.
//!
//! **Frozen and carried downwind** (Taylor): `u′(x, z, t) = u′_z(t − x/U_c)`
//! with `U_c` the mean speed at the aerostat's initial altitude; the series
//! is periodic in `T_p ≥ duration + x_max/U_c`, linear in `t` and `z`
//! between samples and levels, constant above the top level.

use std::f64::consts::PI;

use crate::numerics::params::InvalidInput;
use crate::numerics::tether::wind::WindProfile;
use crate::numerics::uncertainty::sampling::{inverse_normal_cdf, uniform01};

/// Davenport's vertical decay constant `C` (Simiu & Scanlan, "Wind Effects
/// on Structures", 3rd ed., §2.3.6: 10 for the vertical separation).
pub const DAVENPORT_DECAY: f64 = 10.0;
/// Most samples of one turbulence series (per level).
pub const MAX_SERIES_SAMPLES: usize = 1 << 22;
/// Most levels of one field.
pub const MAX_LEVELS: usize = 256;

/// A spatially uniform change of the wind in time.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum GustHistory {
    /// The steady flow only.
    #[default]
    None,
    /// `ΔU = change` from `time_s` on.
    Step { time_s: f64, change_m_s: f64 },
    /// `ΔU` rises linearly to `change` over `[start, start + duration]`.
    Ramp {
        start_time_s: f64,
        duration_s: f64,
        change_m_s: f64,
    },
    /// `ΔU = (A/2)(1 − cos 2π(t − t0)/T)` on `[t0, t0 + T]`.
    OneMinusCosine {
        start_time_s: f64,
        duration_s: f64,
        amplitude_m_s: f64,
    },
    /// `ΔU = A sin(2π t / T)`.
    Sinusoid { amplitude_m_s: f64, period_s: f64 },
}

impl GustHistory {
    /// `ΔU(t)` (m/s).
    #[inline]
    pub fn change_m_s(&self, t: f64) -> f64 {
        match *self {
            Self::None => 0.0,
            Self::Step { time_s, change_m_s } => {
                if t >= time_s {
                    change_m_s
                } else {
                    0.0
                }
            }
            Self::Ramp {
                start_time_s,
                duration_s,
                change_m_s,
            } => {
                if t <= start_time_s {
                    0.0
                } else if duration_s <= 0.0 || t >= start_time_s + duration_s {
                    change_m_s
                } else {
                    change_m_s * (t - start_time_s) / duration_s
                }
            }
            Self::OneMinusCosine {
                start_time_s,
                duration_s,
                amplitude_m_s,
            } => {
                let tau = t - start_time_s;
                if tau <= 0.0 || tau >= duration_s {
                    0.0
                } else {
                    0.5 * amplitude_m_s * (1.0 - (2.0 * PI * tau / duration_s).cos())
                }
            }
            Self::Sinusoid {
                amplitude_m_s,
                period_s,
            } => amplitude_m_s * (2.0 * PI * t / period_s).sin(),
        }
    }

    /// The largest and smallest `ΔU` over `[0, until]` (m/s).
    pub fn range_m_s(&self, until_s: f64) -> (f64, f64) {
        match *self {
            Self::None => (0.0, 0.0),
            Self::Step { time_s, .. }
            | Self::Ramp {
                start_time_s: time_s,
                ..
            } => {
                if time_s < until_s {
                    let reached = self.change_m_s(until_s);
                    (reached.max(0.0), reached.min(0.0))
                } else {
                    (0.0, 0.0)
                }
            }
            Self::OneMinusCosine {
                start_time_s,
                duration_s,
                amplitude_m_s,
            } => {
                let peak_at = start_time_s + 0.5 * duration_s;
                let a = if until_s >= peak_at {
                    amplitude_m_s
                } else {
                    self.change_m_s(until_s)
                };
                (a.max(0.0), a.min(0.0))
            }
            Self::Sinusoid {
                amplitude_m_s,
                period_s,
            } => {
                let a = amplitude_m_s.abs();
                if until_s >= 0.75 * period_s {
                    (a, -a)
                } else {
                    // Sample finely: the exact extremes are at quarter periods.
                    let mut hi = 0.0f64;
                    let mut lo = 0.0f64;
                    for i in 0..=1000 {
                        let v = self.change_m_s(until_s * i as f64 / 1000.0);
                        hi = hi.max(v);
                        lo = lo.min(v);
                    }
                    (hi, lo)
                }
            }
        }
    }
}

/// The turbulence spectrum.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpectrumModel {
    VonKarman,
    Kaimal,
}

impl SpectrumModel {
    /// One-sided `S(f)` (m²/s² per Hz) for `σ`, `L_u`, mean speed `U`.
    #[inline]
    pub fn density(&self, f: f64, sigma: f64, length_scale_m: f64, speed_m_s: f64) -> f64 {
        let tl = length_scale_m / speed_m_s;
        let n = f * tl;
        match self {
            Self::VonKarman => 4.0 * sigma * sigma * tl / (1.0 + 70.8 * n * n).powf(5.0 / 6.0),
            Self::Kaimal => 4.0 * sigma * sigma * tl / (1.0 + 6.0 * n).powf(5.0 / 3.0),
        }
    }
}

/// Turbulence parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Turbulence {
    pub model: SpectrumModel,
    /// `I = σ_u / U` at every level.
    pub intensity: f64,
    /// `L_u` (m).
    pub length_scale_m: f64,
    pub seed: u64,
}

/// Where and how finely a field is synthesised.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FieldGrid {
    /// Time between samples `Δt_w` (s).
    pub time_step_s: f64,
    /// Period covered (s): rounded up to `2^k Δt_w`.
    pub period_s: f64,
    /// Highest level (m).
    pub top_m: f64,
    /// Number of levels (≥ 2), equally spaced from 0 to `top_m`.
    pub levels: usize,
    /// Taylor convection speed `U_c` (m/s, > 0).
    pub convection_m_s: f64,
}

/// A synthesised field: `u′` at `levels × samples`.
#[derive(Clone, Debug, PartialEq)]
pub struct TurbulenceField {
    dt: f64,
    dz: f64,
    samples: usize,
    levels: usize,
    convection_m_s: f64,
    /// `1/Δt_w`, `1/Δz`, `1/U_c`: sampling multiplies.
    inv_dt: f64,
    inv_dz: f64,
    inv_convection: f64,
    /// Level-major.
    data: Vec<f64>,
    /// The cells' independent series `η_k` (cell `k` between levels `k`
    /// and `k + 1`), cell-major.
    cells: Vec<f64>,
}

impl TurbulenceField {
    /// Synthesises the field for the mean flow `mean`.
    pub fn synthesise(
        t: &Turbulence,
        mean: &WindProfile,
        grid: &FieldGrid,
    ) -> Result<Self, InvalidInput> {
        let field = "wind.time_history";
        if !(t.intensity.is_finite() && t.intensity >= 0.0 && t.intensity <= 2.0) {
            return Err(InvalidInput::new(
                format!("{field}.turbulence_intensity_nondim"),
                format!("must be between 0 and 2, got {}", t.intensity),
            ));
        }
        if !(t.length_scale_m.is_finite() && t.length_scale_m > 0.0) {
            return Err(InvalidInput::new(
                format!("{field}.length_scale_m"),
                format!("must be greater than zero, got {}", t.length_scale_m),
            ));
        }
        if !(grid.convection_m_s.is_finite() && grid.convection_m_s > 0.0) {
            return Err(InvalidInput::new(
                "wind.flow",
                "turbulence is carried by the mean wind: the mean speed at the aerostat must be above zero",
            ));
        }
        let levels = grid.levels.clamp(2, MAX_LEVELS);
        let wanted = (grid.period_s / grid.time_step_s).ceil().max(4.0);
        if !(wanted.is_finite() && wanted <= MAX_SERIES_SAMPLES as f64) {
            return Err(InvalidInput::new(
                "duration_s",
                format!(
                    "the turbulence series would need {wanted:.0} samples, more than {MAX_SERIES_SAMPLES}"
                ),
            ));
        }
        let m = (wanted as usize).next_power_of_two();
        let period = m as f64 * grid.time_step_s;
        let df = 1.0 / period;
        let dz = grid.top_m.max(1e-3) / (levels - 1) as f64;
        let speeds: Vec<f64> = (0..levels)
            .map(|k| mean.speed_m_s(k as f64 * dz).abs())
            .collect();
        // Level by level, carrying the Markov chain of every frequency up.
        let normal = |stream: u64, dim: u64| inverse_normal_cdf(uniform01(t.seed, stream, dim));
        let half = 1.0 / 2f64.sqrt();
        let mut chain = vec![(0.0f64, 0.0f64); m / 2];
        let mut data = vec![0.0; levels * m];
        let mut cells = vec![0.0; (levels - 1) * m];
        let mut buf = vec![(0.0, 0.0); m];
        // Linear interpolation in time between samples `Δt_w` apart keeps
        // `1 − (1 − cos 2πfΔt_w)/3` of the power at `f` (averaged over
        // where in the interval the series is read): the synthesised
        // spectrum is raised by its inverse so the wind read is the model's.
        let emphasis = |f: f64| 1.0 / (1.0 - (1.0 - (2.0 * PI * f * grid.time_step_s).cos()) / 3.0);
        for k in 0..levels {
            let u = speeds[k];
            let ubar = if k > 0 {
                0.5 * (speeds[k] + speeds[k - 1])
            } else {
                0.0
            };
            buf.iter_mut().for_each(|c| *c = (0.0, 0.0));
            for j in 1..m / 2 {
                let f = j as f64 * df;
                let xr = normal(j as u64, 2 * k as u64) * half;
                let xi = normal(j as u64, 2 * k as u64 + 1) * half;
                let (gr, gi) = if k == 0 {
                    (xr, xi)
                } else {
                    let rho = if ubar > 0.0 {
                        (-DAVENPORT_DECAY * f * dz / ubar).exp()
                    } else {
                        0.0
                    };
                    let s = (1.0 - rho * rho).max(0.0).sqrt();
                    (rho * chain[j].0 + s * xr, rho * chain[j].1 + s * xi)
                };
                chain[j] = (gr, gi);
                let amp = if u > 1e-6 && t.intensity > 0.0 {
                    // a_m cos + b_m sin with a, b ~ N(0, S Δf): coefficient a − i b.
                    (2.0 * t.model.density(f, t.intensity * u, t.length_scale_m, u)
                        * df
                        * emphasis(f))
                    .sqrt()
                } else {
                    0.0
                };
                buf[j] = (amp * gr, -amp * gi);
            }
            fft_in_place(&mut buf, 1.0);
            for (d, c) in data[k * m..(k + 1) * m].iter_mut().zip(&buf) {
                *d = c.0;
            }
            if k == 0 {
                continue;
            }
            // The cell below level k: η with S̄ (1 − ρ), independent of the levels.
            let cell = k - 1;
            buf.iter_mut().for_each(|c| *c = (0.0, 0.0));
            if ubar > 1e-6 && t.intensity > 0.0 {
                for j in 1..m / 2 {
                    let f = j as f64 * df;
                    let rho = (-DAVENPORT_DECAY * f * dz / ubar).exp();
                    let xr = normal(j as u64, (2 * (MAX_LEVELS + cell)) as u64) * half;
                    let xi = normal(j as u64, (2 * (MAX_LEVELS + cell) + 1) as u64) * half;
                    let s = t
                        .model
                        .density(f, t.intensity * ubar, t.length_scale_m, ubar);
                    let amp = (2.0 * s * (1.0 - rho) * df * emphasis(f)).sqrt();
                    buf[j] = (amp * xr, -amp * xi);
                }
                fft_in_place(&mut buf, 1.0);
            }
            for (d, c) in cells[cell * m..(cell + 1) * m].iter_mut().zip(&buf) {
                *d = c.0;
            }
        }
        Ok(Self {
            dt: grid.time_step_s,
            dz,
            samples: m,
            levels,
            convection_m_s: grid.convection_m_s,
            inv_dt: 1.0 / grid.time_step_s,
            inv_dz: 1.0 / dz,
            inv_convection: 1.0 / grid.convection_m_s,
            data,
            cells,
        })
    }

    /// The period of the series (s).
    pub fn period_s(&self) -> f64 {
        self.samples as f64 * self.dt
    }

    /// The series at level `k` (for tests).
    pub fn level(&self, k: usize) -> &[f64] {
        &self.data[k * self.samples..(k + 1) * self.samples]
    }

    /// The series `η_k` of the cell between levels `k` and `k + 1` (for tests).
    pub fn cell(&self, k: usize) -> &[f64] {
        &self.cells[k * self.samples..(k + 1) * self.samples]
    }

    /// Level spacing (m).
    pub fn level_spacing_m(&self) -> f64 {
        self.dz
    }

    /// The Taylor convection speed `U_c` (m/s).
    pub fn convection_m_s(&self) -> f64 {
        self.convection_m_s
    }

    /// `u′(x, z, t)` (m/s): bilinear in `τ = t − x/U_c` and `z` (no libm
    /// call, no division: it is evaluated at every node in every Newton
    /// iteration).
    #[inline(always)]
    pub fn sample(&self, x: f64, z: f64, t: f64) -> f64 {
        let p = (t - x * self.inv_convection) * self.inv_dt;
        // ⌊p⌋ without a libm call; the period is a power of two, so the
        // wrap is a mask (two's complement gives the Euclidean remainder).
        let mut i = p as i64;
        if (i as f64) > p {
            i -= 1;
        }
        let frac = p - i as f64;
        let mask = self.samples - 1;
        let i0 = (i as usize) & mask;
        let i1 = (i0 + 1) & mask;
        let top = (self.levels - 1) as f64;
        let zk = (z.max(0.0) * self.inv_dz).min(top);
        let k0 = (zk as usize).min(self.levels - 2);
        let fz = zk - k0 as f64;
        let a = &self.data[k0 * self.samples..(k0 + 2) * self.samples];
        let (a0, a1) = (a[i0], a[i1]);
        let (b0, b1) = (a[self.samples + i0], a[self.samples + i1]);
        let va = a0 + frac * (a1 - a0);
        let vb = b0 + frac * (b1 - b0);
        let c = &self.cells[k0 * self.samples..(k0 + 1) * self.samples];
        let eta = c[i0] + frac * (c[i1] - c[i0]);
        va + fz * (vb - va) + (2.0 * fz * (1.0 - fz)).sqrt() * eta
    }
}

/// In-place iterative radix-2 FFT of `buf` (length a power of two):
/// `X_n = Σ_k x_k e^{sign·2πi k n / M}` (no normalisation).
pub fn fft_in_place(buf: &mut [(f64, f64)], sign: f64) {
    let n = buf.len();
    assert!(n.is_power_of_two());
    let bits = n.trailing_zeros();
    if bits == 0 {
        return;
    }
    for i in 0..n {
        let j = i.reverse_bits() >> (usize::BITS - bits);
        if j > i {
            buf.swap(i, j);
        }
    }
    let mut len = 2;
    while len <= n {
        let ang = sign * 2.0 * PI / len as f64;
        let half = len / 2;
        // Twiddles computed directly (no recurrence): the same values on every machine.
        let tw: Vec<(f64, f64)> = (0..half)
            .map(|k| {
                let a = ang * k as f64;
                (a.cos(), a.sin())
            })
            .collect();
        for start in (0..n).step_by(len) {
            for k in 0..half {
                let (wr, wi) = tw[k];
                let (br, bi) = buf[start + k + half];
                let (tr, ti) = (br * wr - bi * wi, br * wi + bi * wr);
                let (ar, ai) = buf[start + k];
                buf[start + k] = (ar + tr, ai + ti);
                buf[start + k + half] = (ar - tr, ai - ti);
            }
        }
        len *= 2;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fft_matches_the_direct_sum() {
        let x: Vec<(f64, f64)> = (0..16)
            .map(|i| ((i as f64 * 0.7).sin(), (i as f64 * 0.3).cos()))
            .collect();
        let mut y = x.clone();
        fft_in_place(&mut y, 1.0);
        for (n, yn) in y.iter().enumerate() {
            let (mut re, mut im) = (0.0, 0.0);
            for (k, xk) in x.iter().enumerate() {
                let a = 2.0 * PI * (k * n) as f64 / 16.0;
                re += xk.0 * a.cos() - xk.1 * a.sin();
                im += xk.0 * a.sin() + xk.1 * a.cos();
            }
            assert!((yn.0 - re).abs() < 1e-12 && (yn.1 - im).abs() < 1e-12);
        }
    }

    /// The sampling (floor and wrap without libm) is the bilinear
    /// interpolation of the stored series, periodic in `τ` also for
    /// negative `τ`, constant above the top level.
    #[test]
    fn field_sampling_interpolates_the_series() {
        let t = Turbulence {
            model: SpectrumModel::Kaimal,
            intensity: 0.1,
            length_scale_m: 100.0,
            seed: 3,
        };
        let grid = FieldGrid {
            time_step_s: 0.25,
            period_s: 60.0,
            top_m: 200.0,
            levels: 5,
            convection_m_s: 10.0,
        };
        let f = TurbulenceField::synthesise(&t, &WindProfile::uniform(10.0), &grid).unwrap();
        let (m, dz, dt) = (f.samples, f.level_spacing_m(), 0.25);
        let period = f.period_s();
        let direct = |x: f64, z: f64, t: f64| {
            let tau = (t - x / 10.0).rem_euclid(period) / dt;
            let i0 = tau.floor() as usize % m;
            let i1 = (i0 + 1) % m;
            let fr = tau - tau.floor();
            let zk = (z.max(0.0) / dz).min(4.0);
            let k0 = (zk.floor() as usize).min(3);
            let fz = zk - k0 as f64;
            let at = |k: usize| f.level(k)[i0] + fr * (f.level(k)[i1] - f.level(k)[i0]);
            let eta = f.cell(k0)[i0] + fr * (f.cell(k0)[i1] - f.cell(k0)[i0]);
            at(k0) + fz * (at(k0 + 1) - at(k0)) + (2.0 * fz * (1.0 - fz)).sqrt() * eta
        };
        for &(x, z, tt) in &[
            (0.0, 0.0, 0.0),
            (0.0, 50.0, 0.25),
            (37.0, 61.3, 12.34),
            (900.0, 130.0, 3.0),
            (-15.0, 199.0, 59.9),
            (0.0, 500.0, 7.7),
            (123.0, -4.0, -30.1),
        ] {
            let (a, b) = (f.sample(x, z, tt), direct(x, z, tt));
            assert!((a - b).abs() < 1e-12, "{x} {z} {tt}: {a} vs {b}");
        }
        assert_eq!(f.sample(0.0, 50.0, 0.5), f.level(1)[2]);
    }

    #[test]
    fn gusts_have_their_shapes() {
        let g = GustHistory::OneMinusCosine {
            start_time_s: 10.0,
            duration_s: 4.0,
            amplitude_m_s: 5.0,
        };
        assert_eq!(g.change_m_s(9.0), 0.0);
        assert!((g.change_m_s(12.0) - 5.0).abs() < 1e-12);
        assert_eq!(g.range_m_s(100.0), (5.0, 0.0));
        let r = GustHistory::Ramp {
            start_time_s: 1.0,
            duration_s: 2.0,
            change_m_s: 4.0,
        };
        assert!((r.change_m_s(2.0) - 2.0).abs() < 1e-12);
        assert_eq!(r.change_m_s(5.0), 4.0);
    }
}
