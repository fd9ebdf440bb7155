//! One eigenvalue of the GE cable's local QEP `T(λ) x = (λ² M + λ C + K) x
//! = 0` tracked along a parameter and across meshes (issue 21): the
//! critical eigenvalue of a flutter onset in wind, at O(n) per state.
//!
//! **Method.** Newton on the eigenpair (nonlinear inverse iteration,
//! Ruhe 1973): with `u` a fixed vector and `uᴴx = 1`,
//! `y = T(λ)⁻¹ T'(λ) x`, `λ ← λ − 1/(uᴴ y)`, `x ← y/(uᴴ y)`,
//! `T'(λ) = 2λM + C`. It converges quadratically to the simple eigenvalue
//! next to its start. `T(λ)` has the band of the tangent (`kl = ku = 5`)
//! and is factored by a complex band LU with partial pivoting
//! ([`ComplexBand`]), so one step costs O(n) where the dense companion
//! (`6n` square) costs O(n³). A coarser mesh's eigenvector is carried to a
//! finer one by linear interpolation of the nodal values (nested meshes).

use nalgebra::Complex;

use super::GeModel;
use super::banded::{BandLu, BandMatrix};
use super::solver::SystemMatrices;

/// A complex scalar.
pub type C64 = Complex<f64>;

/// Newton steps of one eigenpair refinement at most.
pub const MAX_EIGEN_STEPS: usize = 30;
/// Relative change of `λ` at which an eigenpair refinement stops.
pub const EIGEN_RTOL: f64 = 1e-13;
/// Relative change of `λ` below which a step that no longer halves the
/// last one ends the refinement (roundoff plateau).
pub const PLATEAU_RTOL: f64 = 1e-9;
/// Relative step at which a refinement that used all its steps is still
/// accepted.
pub const LOOSE_RTOL: f64 = 1e-7;

/// `T(λ)`: a square complex band matrix (storage and LU of
/// [`BandMatrix`], as the real tangents').
pub type ComplexBand = BandMatrix<C64>;

/// The factors of a [`ComplexBand`].
pub type ComplexBandLu = BandLu<C64>;

impl BandMatrix<C64> {
    /// `T(λ) = λ² M + λ C + K` of `sys`.
    pub fn qep(sys: &SystemMatrices, lambda: C64) -> Self {
        let k = &sys.stiffness;
        let (n, kl, ku) = (k.n, k.kl, k.ku);
        let mut t = Self::zeros(n, kl, ku);
        let l2 = lambda * lambda;
        for i in 0..n {
            for j in i.saturating_sub(kl)..=(i + ku).min(n - 1) {
                let v = l2 * sys.mass.get(i, j) + lambda * sys.damping.get(i, j) + k.get(i, j);
                t.set(i, j, v);
            }
        }
        t
    }
}

/// `(2λ M + C) x`.
fn derivative_times(sys: &SystemMatrices, lambda: C64, x: &[C64]) -> Vec<C64> {
    let n = x.len();
    let (re, im): (Vec<f64>, Vec<f64>) = x.iter().map(|z| (z.re, z.im)).unzip();
    let (mut mr, mut mi, mut cr, mut ci) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    sys.mass.mul_add(&re, &mut mr);
    sys.mass.mul_add(&im, &mut mi);
    sys.damping.mul_add(&re, &mut cr);
    sys.damping.mul_add(&im, &mut ci);
    (0..n)
        .map(|i| 2.0 * lambda * C64::new(mr[i], mi[i]) + C64::new(cr[i], ci[i]))
        .collect()
}

fn dot_conj(u: &[C64], x: &[C64]) -> C64 {
    u.iter().zip(x).map(|(a, b)| a.conj() * b).sum()
}

/// An eigenpair of the local QEP.
#[derive(Clone, Debug, PartialEq)]
pub struct EigenPair {
    pub lambda: C64,
    /// Normalised to unit 2-norm.
    pub vector: Vec<C64>,
}

/// The eigenpair of `sys` next to `(lambda0, x0)` by Newton (module docs);
/// `x0 = None`: started from two inverse iterations on a fixed vector.
/// `None` when a factorisation fails or the iteration does not settle.
pub fn refine_eigenpair(
    sys: &SystemMatrices,
    lambda0: C64,
    x0: Option<&[C64]>,
) -> Option<EigenPair> {
    refine_eigenpair_at_scale(sys, lambda0, x0, 0.0)
}

/// [`refine_eigenpair`] with the changes of `λ` measured against at
/// least `scale` (1/s): near a divergence root `λ → 0` and a relative
/// test alone never settles.
pub fn refine_eigenpair_at_scale(
    sys: &SystemMatrices,
    lambda0: C64,
    x0: Option<&[C64]>,
    scale: f64,
) -> Option<EigenPair> {
    let n = sys.stiffness.n;
    let mut lambda = lambda0;
    let mut x: Vec<C64> = match x0 {
        Some(x) if x.len() == n => x.to_vec(),
        _ => {
            let lu = ComplexBand::qep(sys, lambda).factor()?;
            let mut x: Vec<C64> = (0..n)
                .map(|i| C64::new(1.0 + (i as f64 * 0.7).sin(), (i as f64 * 1.3).cos()))
                .collect();
            for _ in 0..2 {
                lu.solve_in_place(&mut x);
                let s = x.iter().map(|z| z.norm_sqr()).sum::<f64>().sqrt();
                if !(s.is_finite() && s > 0.0) {
                    return None;
                }
                x.iter_mut().for_each(|z| *z /= s);
            }
            x
        }
    };
    let s = x.iter().map(|z| z.norm_sqr()).sum::<f64>().sqrt();
    if !(s.is_finite() && s > 0.0) {
        return None;
    }
    x.iter_mut().for_each(|z| *z /= s);
    let u = x.clone();
    let scale = lambda0.norm().max(scale).max(1e-300);
    let mut last = f64::INFINITY;
    for _ in 0..MAX_EIGEN_STEPS {
        let Some(lu) = ComplexBand::qep(sys, lambda).factor() else {
            // exactly on an eigenvalue: the pair is (λ, x)
            return Some(EigenPair { lambda, vector: x });
        };
        let mut y = derivative_times(sys, lambda, &x);
        lu.solve_in_place(&mut y);
        let d = dot_conj(&u, &y);
        if !(d.re.is_finite() && d.im.is_finite()) || d.norm() == 0.0 {
            return None;
        }
        let step = dot_conj(&u, &x) / d;
        lambda -= step;
        x = y.into_iter().map(|z| z / d).collect();
        let size = lambda.norm().max(scale);
        let h = step.norm();
        // settled: at the tolerance, or at a roundoff plateau (a
        // non-normal pencil's eigenvalue is only as exact as its
        // condition allows)
        if h <= EIGEN_RTOL * size || (h <= PLATEAU_RTOL * size && h >= 0.5 * last) {
            let s = x.iter().map(|z| z.norm_sqr()).sum::<f64>().sqrt();
            x.iter_mut().for_each(|z| *z /= s);
            return Some(EigenPair { lambda, vector: x });
        }
        last = h;
    }
    // not settled: accepted only when the last steps were already tiny
    (last <= LOOSE_RTOL * lambda.norm().max(scale)).then(|| {
        let s = x.iter().map(|z| z.norm_sqr()).sum::<f64>().sqrt();
        x.iter_mut().for_each(|z| *z /= s);
        EigenPair { lambda, vector: x }
    })
}

/// `‖T(λ) x‖ / (‖T(λ)‖-ish scale · ‖x‖)`: the relative residual of a pair.
pub fn residual(sys: &SystemMatrices, pair: &EigenPair) -> f64 {
    let t = ComplexBand::qep(sys, pair.lambda);
    let n = t.n;
    let mut r = 0.0f64;
    let mut scale = 0.0f64;
    for i in 0..n {
        let mut s = C64::new(0.0, 0.0);
        for j in i.saturating_sub(t.kl)..=(i + t.ku).min(n - 1) {
            let a = t.get(i, j);
            scale = scale.max(a.norm());
            s += a * pair.vector[j];
        }
        r = r.max(s.norm());
    }
    r / scale.max(1e-300)
}

/// A coarse mesh's nodal vector (three values per node, the root
/// excluded) linearly interpolated onto the mesh of twice the elements.
pub fn prolong_vector(x: &[C64], coarse_elements: usize) -> Vec<C64> {
    let at = |k: usize| -> [C64; 3] {
        if k == 0 {
            [C64::new(0.0, 0.0); 3]
        } else {
            let i = GeModel::dof(k, 0);
            [x[i], x[i + 1], x[i + 2]]
        }
    };
    let mut out = vec![C64::new(0.0, 0.0); 6 * coarse_elements];
    for k in 1..=2 * coarse_elements {
        let v = if k % 2 == 0 {
            at(k / 2)
        } else {
            let (a, b) = (at(k / 2), at(k / 2 + 1));
            [
                0.5 * (a[0] + b[0]),
                0.5 * (a[1] + b[1]),
                0.5 * (a[2] + b[2]),
            ]
        };
        out[GeModel::dof(k, 0)..GeModel::dof(k, 0) + 3].copy_from_slice(&v);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::ge::banded::Band;

    /// `T(λ) x = b` by the complex band LU against `T(λ)` applied to the
    /// solution (a random band system that needs pivoting).
    #[test]
    fn complex_band_lu_solves_a_pivoted_system() {
        let (n, kl, ku) = (31, 5, 5);
        let mut seed = 11u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        let mut band = || {
            let mut a = Band::zeros(n, kl, ku);
            for i in 0..n {
                for j in i.saturating_sub(kl)..=(i + ku).min(n - 1) {
                    a.add(i, j, rnd());
                }
            }
            a
        };
        let sys = SystemMatrices {
            mass: band(),
            damping: band(),
            stiffness: band(),
        };
        let lambda = C64::new(0.3, 1.7);
        let t = ComplexBand::qep(&sys, lambda);
        let x: Vec<C64> = (0..n)
            .map(|i| C64::new((i as f64).sin(), (2.0 * i as f64).cos()))
            .collect();
        let mut b = vec![C64::new(0.0, 0.0); n];
        for (i, bi) in b.iter_mut().enumerate() {
            for j in i.saturating_sub(kl)..=(i + ku).min(n - 1) {
                *bi += t.get(i, j) * x[j];
            }
        }
        t.factor().unwrap().solve_in_place(&mut b);
        for i in 0..n {
            assert!((b[i] - x[i]).norm() < 1e-10, "{i}: {} vs {}", b[i], x[i]);
        }
    }

    /// Uncoupled oscillators `λ² + cλ + k = 0`: Newton converges to the
    /// closed-form root next to its start.
    #[test]
    fn eigenpair_of_uncoupled_oscillators() {
        let n = 4;
        let diag = |v: [f64; 4]| {
            let mut a = Band::zeros(n, 1, 1);
            for (i, x) in v.iter().enumerate() {
                a.add(i, i, *x);
            }
            a
        };
        let (c, k) = ([0.3, -0.1, 2.0, 0.05], [4.0, 9.0, 0.5, 16.0]);
        let sys = SystemMatrices {
            mass: diag([1.0; 4]),
            damping: diag(c),
            stiffness: diag(k),
        };
        for i in [0, 1, 3] {
            let root = C64::new(-0.5 * c[i], (k[i] - 0.25 * c[i] * c[i]).sqrt());
            let p = refine_eigenpair(&sys, root * C64::new(1.02, 0.01), None).unwrap();
            assert!(
                (p.lambda - root).norm() < 1e-12,
                "{i}: {} vs {root}",
                p.lambda
            );
            assert!(p.vector[i].norm() > 1.0 - 1e-9);
        }
    }
}
