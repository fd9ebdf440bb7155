//! 2×2 blocks and the block-tridiagonal solve of the implicit step
//! (block Thomas elimination, `O(N)`; no pivoting across blocks: the
//! iteration matrix `(1−α_m) M − (1−α_f)(γ h ∂P/∂v + β h² ∂P/∂x)` is
//! dominated by its mass diagonal at the steps used).

/// A 2-vector `(x, z)`.
pub type V2 = [f64; 2];
/// A 2×2 matrix, rows first.
pub type B2 = [[f64; 2]; 2];

pub const ZERO: B2 = [[0.0; 2]; 2];

#[inline]
pub fn add(a: V2, b: V2) -> V2 {
    [a[0] + b[0], a[1] + b[1]]
}

#[inline]
pub fn sub(a: V2, b: V2) -> V2 {
    [a[0] - b[0], a[1] - b[1]]
}

#[inline]
pub fn scale(s: f64, a: V2) -> V2 {
    [s * a[0], s * a[1]]
}

#[inline]
pub fn dot(a: V2, b: V2) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

#[inline]
pub fn norm(a: V2) -> f64 {
    // √(x² + z²), not `hypot`: a libm call ten times the cost, and these
    // magnitudes (m, m/s, N) are far from overflow and underflow.
    (a[0] * a[0] + a[1] * a[1]).sqrt()
}

/// `s a bᵀ`.
#[inline]
pub fn outer(s: f64, a: V2, b: V2) -> B2 {
    [
        [s * a[0] * b[0], s * a[0] * b[1]],
        [s * a[1] * b[0], s * a[1] * b[1]],
    ]
}

#[inline]
pub fn add_to(m: &mut B2, s: f64, a: &B2) {
    for r in 0..2 {
        for c in 0..2 {
            m[r][c] += s * a[r][c];
        }
    }
}

#[inline]
pub fn add_identity(m: &mut B2, s: f64) {
    m[0][0] += s;
    m[1][1] += s;
}

#[inline]
pub fn mul_vec(m: &B2, v: V2) -> V2 {
    [
        m[0][0] * v[0] + m[0][1] * v[1],
        m[1][0] * v[0] + m[1][1] * v[1],
    ]
}

#[inline]
pub fn mul(a: &B2, b: &B2) -> B2 {
    [
        [
            a[0][0] * b[0][0] + a[0][1] * b[1][0],
            a[0][0] * b[0][1] + a[0][1] * b[1][1],
        ],
        [
            a[1][0] * b[0][0] + a[1][1] * b[1][0],
            a[1][0] * b[0][1] + a[1][1] * b[1][1],
        ],
    ]
}

/// The inverse, or `None` when singular.
#[inline]
pub fn inverse(m: &B2) -> Option<B2> {
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    if !(det.is_finite() && det != 0.0) {
        return None;
    }
    let inv = 1.0 / det;
    Some([
        [m[1][1] * inv, -m[0][1] * inv],
        [-m[1][0] * inv, m[0][0] * inv],
    ])
}

/// Solves `A x = rhs` in place for the block-tridiagonal `A` with
/// `lower[i]` coupling row `i` to unknown `i − 1` (`lower[0]` unused),
/// `diag[i]`, and `upper[i]` coupling row `i` to `i + 1` (the last unused).
/// `diag` is overwritten. `false` when a pivot block is singular.
pub fn solve_tridiagonal(lower: &[B2], diag: &mut [B2], upper: &[B2], rhs: &mut [V2]) -> bool {
    let n = diag.len();
    if n == 0 {
        return true;
    }
    // Forward: D_i ← D_i − L_i D_{i−1}⁻¹ U_{i−1}, r_i ← r_i − L_i D_{i−1}⁻¹ r_{i−1}.
    // The inverses of the pivots are kept in `diag` for the back pass.
    let Some(mut inv) = inverse(&diag[0]) else {
        return false;
    };
    diag[0] = inv;
    for i in 1..n {
        let w = mul(&lower[i], &inv);
        let wu = mul(&w, &upper[i - 1]);
        let mut d = diag[i];
        add_to(&mut d, -1.0, &wu);
        let wr = mul_vec(&w, rhs[i - 1]);
        rhs[i] = sub(rhs[i], wr);
        let Some(next) = inverse(&d) else {
            return false;
        };
        inv = next;
        diag[i] = inv;
    }
    rhs[n - 1] = mul_vec(&diag[n - 1], rhs[n - 1]);
    for i in (0..n - 1).rev() {
        let r = sub(rhs[i], mul_vec(&upper[i], rhs[i + 1]));
        rhs[i] = mul_vec(&diag[i], r);
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn block_thomas_matches_a_dense_product() {
        let n = 7;
        let mut lower = vec![ZERO; n];
        let mut diag = vec![ZERO; n];
        let mut upper = vec![ZERO; n];
        for i in 0..n {
            let f = i as f64;
            diag[i] = [[4.0 + f, 0.3], [-0.2, 5.0 - 0.1 * f]];
            lower[i] = [[0.5, 0.1 * f], [-0.3, 0.7]];
            upper[i] = [[-0.4, 0.2], [0.1, -0.6 + 0.05 * f]];
        }
        let x: Vec<V2> = (0..n).map(|i| [1.0 + i as f64, -0.5 * i as f64]).collect();
        let mut b = vec![[0.0; 2]; n];
        for i in 0..n {
            b[i] = mul_vec(&diag[i], x[i]);
            if i > 0 {
                b[i] = add(b[i], mul_vec(&lower[i], x[i - 1]));
            }
            if i + 1 < n {
                b[i] = add(b[i], mul_vec(&upper[i], x[i + 1]));
            }
        }
        assert!(solve_tridiagonal(&lower, &mut diag, &upper, &mut b));
        for i in 0..n {
            assert!((b[i][0] - x[i][0]).abs() < 1e-12 && (b[i][1] - x[i][1]).abs() < 1e-12);
        }
    }
}
