//! The linear string at rest (`l̇ = l̈ = 0`, SPEC §1): the eigenvalues of
//! its symmetric pencil `(K, M)` by bisection on inertia, its mode shapes
//! by shifted inverse iteration, and a state's energy split over its modes.
//! The transient run picks its step and its initial modes from these.

use nalgebra::{DMatrix, DVector};

use crate::numerics::params::NondimState;
use crate::numerics::qep::QepError;
use crate::numerics::string::StringModel;
use crate::numerics::string::operators::SecondOrderSystem;
use crate::numerics::tridiag::Tridiagonal;

/// The `k`-th (1-based) eigenvalue `ω²` of the symmetric pencil `(K, M)` of
/// a cable at rest (`l̇ = l̈ = 0`), by bisection on the inertia of
/// `K − σM` (the number of negative pivots is the number of eigenvalues
/// below `σ`): `O(n)` per step, no dense solve.
pub fn rest_eigenvalue(sys: &SecondOrderSystem, k: usize) -> Option<f64> {
    let n = sys.mass.dim();
    if k == 0 || k > n {
        return None;
    }
    let below = |sigma: f64| {
        Tridiagonal::combination(&[(1.0, &sys.stiffness), (-sigma, &sys.mass)]).negative_pivots()
    };
    let (mut lo, mut hi) = (-1.0, 1.0);
    while below(lo) >= k {
        lo *= 2.0;
        if lo < -1e300 {
            return None;
        }
    }
    while below(hi) < k {
        hi *= 2.0;
        if hi > 1e300 {
            return None;
        }
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi || hi - lo <= 1e-15 * hi.abs().max(lo.abs()) {
            break;
        }
        if below(mid) >= k { hi = mid } else { lo = mid }
    }
    Some(0.5 * (lo + hi))
}

pub(crate) fn rest_system(
    model: &StringModel,
    length: f64,
    added_mass_nondim: f64,
) -> SecondOrderSystem {
    let mut c = model.coefficients(NondimState {
        length,
        rate: 0.0,
        acceleration: 0.0,
    });
    c.tip_mass += added_mass_nondim;
    model.operators.assemble(&c)
}

/// Mode `mode` (1-based, by frequency) of the cable at rest at length `l`
/// (`l̇ = l̈ = 0`, `K` symmetric), by shifted inverse iteration; normalised
/// to a unit tip deflection. Returns the shape and `ω` (1/t̄).
pub fn rest_mode_shape(
    model: &StringModel,
    length: f64,
    added_mass_nondim: f64,
    mode: usize,
) -> Result<(Vec<f64>, f64), QepError> {
    let sys = rest_system(model, length, added_mass_nondim);
    let eig = |k: usize| rest_eigenvalue(&sys, k);
    let w2 = eig(mode).ok_or(QepError::NoConvergence)?;
    // Shift just below the target, by a small fraction of the gap to its
    // neighbours, so inverse iteration converges to this mode alone.
    let gap = [mode.checked_sub(1).and_then(eig), eig(mode + 1)]
        .into_iter()
        .flatten()
        .map(|v| (v - w2).abs())
        .filter(|g| *g > 0.0)
        .fold(f64::INFINITY, f64::min);
    let shift = w2 - 1e-3 * gap.min(w2.abs().max(1e-300));
    let omega = w2.max(0.0).sqrt();
    let shifted = Tridiagonal::combination(&[(1.0, &sys.stiffness), (-shift, &sys.mass)]);
    let n = model.elements();
    let mut x = vec![1.0; n];
    let mut y = vec![0.0; n];
    for _ in 0..30 {
        sys.mass.mul_vec(&x, &mut y);
        shifted.solve_columns_in_place(&mut y, 1);
        let norm = y.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        if !(norm.is_finite() && norm > 0.0) {
            return Err(QepError::NonFinite);
        }
        for (xi, yi) in x.iter_mut().zip(&y) {
            *xi = yi / norm;
        }
    }
    let tip = x[n - 1];
    if tip == 0.0 {
        return Err(QepError::NonFinite);
    }
    Ok((x.iter().map(|v| v / tip).collect(), omega))
}

/// Energies of the modes of the cable at rest at length `length` (non-dim),
/// for a state `(q, q̇)` measured from the static equilibrium under the tip
/// load `tip_load` (non-dim, `F/F_net`): `(ω_k [1/t̄], E_k [F L0])`, by
/// frequency. They sum to `½q̇ᵀMq̇ + ½(q−q_s)ᵀK(q−q_s)` and are constant in
/// time once the length is fixed and the load steady and undamped.
/// `None` if `length ≤ 0` or the state has the wrong size.
pub fn modal_energies(
    model: &StringModel,
    length: f64,
    tip_mass_nondim: f64,
    tip_load: f64,
    q: &[f64],
    qd: &[f64],
) -> Option<Vec<(f64, f64)>> {
    let n = model.elements();
    if length.is_nan() || length <= 0.0 || q.len() != n || qd.len() != n {
        return None;
    }
    let s = NondimState {
        length,
        rate: 0.0,
        acceleration: 0.0,
    };
    let mut c = model.coefficients(s);
    c.tip_mass = tip_mass_nondim;
    let sys = model.operators.assemble(&c);
    let dense = |t: &Tridiagonal| DMatrix::from_fn(n, n, |i, j| t.get(i, j));
    let (m, k) = (dense(&sys.mass), dense(&sys.stiffness));
    // static equilibrium K q_s = f
    let mut qs = vec![0.0; n];
    qs[n - 1] = tip_load;
    sys.stiffness.solve_columns_in_place(&mut qs, 1);
    let l = nalgebra::Cholesky::new(m)?.l();
    let l_inv = l.clone().try_inverse()?;
    let a = &l_inv * &k * l_inv.transpose();
    let a = (&a + a.transpose()) * 0.5;
    let eig = nalgebra::SymmetricEigen::new(a);
    let dq = DVector::from_iterator(n, q.iter().zip(&qs).map(|(a, b)| a - b));
    let dv = DVector::from_column_slice(qd);
    let xi = eig.eigenvectors.transpose() * (l.transpose() * dq);
    let xid = eig.eigenvectors.transpose() * (l.transpose() * dv);
    let mut out: Vec<(f64, f64)> = (0..n)
        .map(|i| {
            let lam = eig.eigenvalues[i];
            (
                lam.max(0.0).sqrt(),
                0.5 * xid[i] * xid[i] + 0.5 * lam * xi[i] * xi[i],
            )
        })
        .collect();
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    Some(out)
}
