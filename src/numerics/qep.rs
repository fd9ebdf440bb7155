//! Quadratic eigenvalue problem `λ² M + λ C + K = 0` (thesis (4.2)).
//!
//! The tridiagonal `M` is symmetric positive definite, so the problem is
//! linearised to the standard eigenproblem of the `2n × 2n` companion
//! matrix `[[0, I], [-M⁻¹K, -M⁻¹C]]` and solved by faer's real Schur
//! (Hessenberg QR) in sequential mode: parallelism belongs to the sweeps.
//!
//! Stability verdict: stable iff `max Re λ ≤ STABILITY_RTOL · max(1, ρ)`,
//! with `ρ` the spectral radius (roundoff of the companion eigenvalues is
//! of order `1e-16 ρ`; the tolerance leaves six decades of margin).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::evd::{self, ComputeEigenvectors};
use faer::{Mat, Par};

use crate::numerics::string::operators::SecondOrderSystem;

/// Relative tolerance on `Re λ` for the stability verdict.
pub const STABILITY_RTOL: f64 = 1e-9;

/// One eigenvalue.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Eigenvalue {
    pub re: f64,
    pub im: f64,
}

impl Eigenvalue {
    pub fn abs(&self) -> f64 {
        self.re.hypot(self.im)
    }
}

/// The spectrum of a quadratic eigenvalue problem.
#[derive(Clone, Debug)]
pub struct Spectrum {
    /// All `2n` eigenvalues, conjugate pairs included.
    pub eigenvalues: Vec<Eigenvalue>,
    pub max_real: f64,
    pub spectral_radius: f64,
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum QepError {
    #[error("the eigenvalue iteration did not converge")]
    NoConvergence,
    #[error("the system matrices contain non-finite values")]
    NonFinite,
    /// The caller stopped the work (its answer is no longer wanted).
    #[error("the search was cancelled")]
    Cancelled,
}

impl Spectrum {
    /// The spectrum of these eigenvalues, with its largest real part and radius.
    pub fn from_eigenvalues(eigenvalues: Vec<Eigenvalue>) -> Self {
        let max_real = eigenvalues
            .iter()
            .map(|e| e.re)
            .fold(f64::NEG_INFINITY, f64::max);
        let spectral_radius = eigenvalues.iter().map(Eigenvalue::abs).fold(0.0, f64::max);
        Self {
            eigenvalues,
            max_real,
            spectral_radius,
        }
    }

    pub fn tolerance(&self) -> f64 {
        STABILITY_RTOL * self.spectral_radius.max(1.0)
    }

    pub fn is_stable(&self) -> bool {
        self.max_real <= self.tolerance()
    }

    /// One eigenvalue per conjugate pair (`Im λ ≥ 0`), sorted by imaginary
    /// part, then by real part descending: the modes in frequency order.
    pub fn modes(&self) -> Vec<Eigenvalue> {
        let tiny = 1e-12 * self.spectral_radius.max(1.0);
        let mut modes: Vec<Eigenvalue> = self
            .eigenvalues
            .iter()
            .copied()
            .filter(|e| e.im >= -tiny)
            .collect();
        modes.sort_by(|a, b| {
            a.im.abs()
                .total_cmp(&b.im.abs())
                .then(b.re.total_cmp(&a.re))
        });
        modes
    }
}

/// Solves `λ² M + λ C + K = 0` for all `2n` eigenvalues.
pub fn solve(system: &SecondOrderSystem) -> Result<Spectrum, QepError> {
    let n = system.mass.dim();
    let finite = |t: &crate::numerics::tridiag::Tridiagonal| {
        t.diag
            .iter()
            .chain(&t.lower)
            .chain(&t.upper)
            .all(|v| v.is_finite())
    };
    if !(finite(&system.mass) && finite(&system.damping) && finite(&system.stiffness)) {
        return Err(QepError::NonFinite);
    }
    // Row-major [K | C] (n × 2n), then M⁻¹[K | C].
    let cols = 2 * n;
    let mut rhs = vec![0.0; n * cols];
    for i in 0..n {
        for j in i.saturating_sub(1)..(i + 2).min(n) {
            rhs[i * cols + j] = system.stiffness.get(i, j);
            rhs[i * cols + n + j] = system.damping.get(i, j);
        }
    }
    system.mass.solve_columns_in_place(&mut rhs, cols);
    if !rhs.iter().all(|v| v.is_finite()) {
        return Err(QepError::NonFinite);
    }
    let gamma = eigenvalue_scale(&rhs, n);
    let (k_scale, c_scale) = (1.0 / (gamma * gamma), 1.0 / gamma);
    let companion = Mat::<f64>::from_fn(cols, cols, |i, j| {
        if i < n {
            if j == i + n { 1.0 } else { 0.0 }
        } else if j < n {
            -rhs[(i - n) * cols + j] * k_scale
        } else {
            -rhs[(i - n) * cols + j] * c_scale
        }
    });
    let (re, im) = if cols <= SMALL_DIM {
        // faer when nalgebra's iteration hits its cap
        eigenvalues_small(&companion).or_else(|_| eigenvalues_real(&companion))?
    } else {
        eigenvalues_real(&companion)?
    };
    if !re.iter().chain(&im).all(|v| v.is_finite()) {
        return Err(QepError::NonFinite);
    }
    Ok(Spectrum::from_eigenvalues(
        re.into_iter()
            .zip(im)
            .map(|(re, im)| Eigenvalue {
                re: re * gamma,
                im: im * gamma,
            })
            .collect(),
    ))
}

/// Scale `γ` of the eigenvalues, `λ = γ μ`, so that the companion of
/// `μ² M + μ C/γ + K/γ² = 0` has entries of order one (Fan, Lin & Van
/// Dooren 2004). Systems of wildly scaled parameters (ρA = 1e262 kg/m
/// gives `|M⁻¹K| ~ 1e265`) otherwise overflow inside the Schur iteration,
/// which then never ends. A power of two (exact scaling), and 1 unless
/// the entries are beyond 2^±64, so ordinary systems are untouched.
fn eigenvalue_scale(minv_kc: &[f64], n: usize) -> f64 {
    let cols = 2 * n;
    let (mut kmax, mut cmax) = (0.0f64, 0.0f64);
    for row in minv_kc.chunks(cols.max(1)) {
        for (j, v) in row.iter().enumerate() {
            if j < n {
                kmax = kmax.max(v.abs());
            } else {
                cmax = cmax.max(v.abs());
            }
        }
    }
    let size = kmax.sqrt().max(cmax);
    if !(size > 0.0 && size.is_finite()) {
        return 1.0;
    }
    let exp = size.log2().round();
    if exp.abs() <= 64.0 { 1.0 } else { exp.exp2() }
}

/// Largest companion dimension solved by nalgebra's Schur decomposition:
/// at these sizes it is several times faster than faer's (whose kernels
/// are tuned for large matrices); above it, faer.
pub const SMALL_DIM: usize = 128;

/// Eigenvalues of a small real square matrix: nalgebra's real Schur form
/// (Francis double shift), with an iteration cap.
pub fn eigenvalues_small(a: &Mat<f64>) -> Result<(Vec<f64>, Vec<f64>), QepError> {
    let n = a.nrows();
    let m = nalgebra::DMatrix::<f64>::from_fn(n, n, |i, j| a[(i, j)]);
    let schur =
        nalgebra::Schur::try_new(m, f64::EPSILON, 100 * n.max(1)).ok_or(QepError::NoConvergence)?;
    let eig = schur.complex_eigenvalues();
    Ok((
        eig.iter().map(|z| z.re).collect(),
        eig.iter().map(|z| z.im).collect(),
    ))
}

/// Eigenvalues of a real square matrix, sequential faer.
pub fn eigenvalues_real(a: &Mat<f64>) -> Result<(Vec<f64>, Vec<f64>), QepError> {
    let n = a.nrows();
    let mut s_re = faer::diag::Diag::<f64>::zeros(n);
    let mut s_im = faer::diag::Diag::<f64>::zeros(n);
    let par = Par::Seq;
    let scratch = evd::evd_scratch::<f64>(
        n,
        ComputeEigenvectors::No,
        ComputeEigenvectors::No,
        par,
        Default::default(),
    );
    let mut buffer = MemBuffer::new(scratch);
    evd::evd_real(
        a.as_ref(),
        s_re.as_mut(),
        s_im.as_mut(),
        None,
        None,
        par,
        MemStack::new(&mut buffer),
        Default::default(),
    )
    .map_err(|_| QepError::NoConvergence)?;
    let re = s_re.column_vector().iter().copied().collect();
    let im = s_im.column_vector().iter().copied().collect();
    Ok((re, im))
}

#[cfg(test)]
mod tests {

    #[test]
    fn the_small_and_the_large_eigensolvers_agree() {
        // a companion of a graded-mesh string: nalgebra's Schur (used up to
        // SMALL_DIM) against faer's, eigenvalue by eigenvalue
        use crate::numerics::params::{AerostatSystem, Kinematics};
        use crate::numerics::string::StringModel;
        let sys = AerostatSystem::thesis();
        let ops = crate::numerics::string::converged::graded_operators(8);
        let model = StringModel::with_operators(sys, ops);
        let m = model.matrices(sys.to_nondim(Kinematics {
            length_m: 1100.0,
            rate_m_s: 30.0,
            acceleration_m_s2: 0.5,
        }));
        let n = m.mass.dim();
        let mut minv = vec![0.0; n * 2 * n];
        for i in 0..n {
            for j in i.saturating_sub(1)..(i + 2).min(n) {
                minv[i * 2 * n + j] = m.stiffness.get(i, j);
                minv[i * 2 * n + n + j] = m.damping.get(i, j);
            }
        }
        m.mass.solve_columns_in_place(&mut minv, 2 * n);
        let a = Mat::<f64>::from_fn(2 * n, 2 * n, |i, j| {
            if i < n {
                if j == i + n { 1.0 } else { 0.0 }
            } else {
                -minv[(i - n) * 2 * n + j]
            }
        });
        let sorted = |(re, im): (Vec<f64>, Vec<f64>)| {
            let mut v: Vec<(f64, f64)> = re.into_iter().zip(im).collect();
            v.sort_by(|x, y| (x.1, x.0).partial_cmp(&(y.1, y.0)).unwrap());
            v
        };
        let small = sorted(eigenvalues_small(&a).unwrap());
        let large = sorted(eigenvalues_real(&a).unwrap());
        let radius = large.iter().map(|z| z.0.hypot(z.1)).fold(0.0, f64::max);
        for (x, y) in small.iter().zip(&large) {
            assert!(
                (x.0 - y.0).abs() + (x.1 - y.1).abs() <= 1e-9 * radius,
                "{x:?} vs {y:?}"
            );
        }
    }

    use super::*;
    use crate::numerics::tridiag::Tridiagonal;

    fn diagonal(values: &[f64]) -> Tridiagonal {
        let mut t = Tridiagonal::zeros(values.len());
        t.diag.copy_from_slice(values);
        t
    }

    /// Uncoupled oscillators `λ² + c λ + k = 0`: closed-form roots, and the
    /// same roots times `s` when `C → sC`, `K → s²K`, for `s` up to 1e130
    /// (which used to overflow inside the Schur iteration and never end).
    #[test]
    fn badly_scaled_systems_keep_their_closed_form_roots() {
        let (c, k) = ([0.3, 2.0, 0.0], [4.0, 0.5, 9.0]);
        for s in [1.0, 1e-80, 1e40, 1e130] {
            let system = SecondOrderSystem {
                mass: diagonal(&[1.0, 1.0, 1.0]),
                damping: diagonal(&c.map(|v| v * s)),
                stiffness: diagonal(&k.map(|v| v * s * s)),
            };
            let start = std::time::Instant::now();
            let spectrum = solve(&system).unwrap();
            assert!(start.elapsed().as_secs_f64() < 1.0);
            let mut want: Vec<(f64, f64)> = Vec::new();
            for (c, k) in c.iter().zip(&k) {
                let disc = c * c - 4.0 * k;
                if disc < 0.0 {
                    let im = 0.5 * (-disc).sqrt();
                    want.extend([(-0.5 * c, im), (-0.5 * c, -im)]);
                } else {
                    let r = 0.5 * disc.sqrt();
                    want.extend([(-0.5 * c + r, 0.0), (-0.5 * c - r, 0.0)]);
                }
            }
            for (re, im) in want {
                let found = spectrum.eigenvalues.iter().any(|e| {
                    (e.re / s - re).abs() <= 1e-12 * 4.0 && (e.im / s - im).abs() <= 1e-12 * 4.0
                });
                assert!(
                    found,
                    "s = {s:e}: {re} + {im}i not in {:?}",
                    spectrum.eigenvalues
                );
            }
        }
    }
}
