//! Tridiagonal matrices: the shape every linear-string operator has with
//! 2-node elements. Owns storage, linear combinations, products, the
//! Thomas solve and the pivot counts (Sylvester inertia) that the fast
//! stability searches rely on.

/// A square tridiagonal matrix. `lower[i] = A[i+1][i]`, `upper[i] = A[i][i+1]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Tridiagonal {
    pub lower: Vec<f64>,
    pub diag: Vec<f64>,
    pub upper: Vec<f64>,
}

impl Tridiagonal {
    pub fn zeros(n: usize) -> Self {
        Self {
            lower: vec![0.0; n.saturating_sub(1)],
            diag: vec![0.0; n],
            upper: vec![0.0; n.saturating_sub(1)],
        }
    }

    pub fn dim(&self) -> usize {
        self.diag.len()
    }

    /// Adds `value` at `(row, col)`; `|row - col| <= 1`.
    pub fn add(&mut self, row: usize, col: usize, value: f64) {
        if row == col {
            self.diag[row] += value;
        } else if row + 1 == col {
            self.upper[row] += value;
        } else if col + 1 == row {
            self.lower[col] += value;
        } else {
            panic!("({row}, {col}) is outside the tridiagonal band");
        }
    }

    pub fn get(&self, row: usize, col: usize) -> f64 {
        if row == col {
            self.diag[row]
        } else if row + 1 == col {
            self.upper[row]
        } else if col + 1 == row {
            self.lower[col]
        } else {
            0.0
        }
    }

    /// `sum_k coef_k * term_k`, all of the same dimension.
    pub fn combination(terms: &[(f64, &Tridiagonal)]) -> Self {
        let n = terms.first().map_or(0, |(_, t)| t.dim());
        let mut out = Self::zeros(n);
        for (coef, term) in terms {
            if *coef == 0.0 {
                continue;
            }
            for (o, v) in out.diag.iter_mut().zip(&term.diag) {
                *o += coef * v;
            }
            for (o, v) in out.lower.iter_mut().zip(&term.lower) {
                *o += coef * v;
            }
            for (o, v) in out.upper.iter_mut().zip(&term.upper) {
                *o += coef * v;
            }
        }
        out
    }

    pub fn transpose(&self) -> Self {
        Self {
            lower: self.upper.clone(),
            diag: self.diag.clone(),
            upper: self.lower.clone(),
        }
    }

    pub fn is_symmetric(&self, tol: f64) -> bool {
        self.lower
            .iter()
            .zip(&self.upper)
            .all(|(l, u)| (l - u).abs() <= tol * (1.0 + l.abs().max(u.abs())))
    }

    /// `y = A x`.
    pub fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        let n = self.dim();
        for i in 0..n {
            let mut s = self.diag[i] * x[i];
            if i > 0 {
                s += self.lower[i - 1] * x[i - 1];
            }
            if i + 1 < n {
                s += self.upper[i] * x[i + 1];
            }
            y[i] = s;
        }
    }

    /// `x^T A x`.
    pub fn quadratic_form(&self, x: &[f64]) -> f64 {
        let mut y = vec![0.0; x.len()];
        self.mul_vec(x, &mut y);
        x.iter().zip(&y).map(|(a, b)| a * b).sum()
    }

    /// Solves `A X = B` in place for the columns of the row-major dense
    /// `b` (`n` rows, `cols` columns) by the Thomas algorithm. Needs
    /// nonzero pivots, which holds for the symmetric positive definite
    /// mass matrices it is used on.
    pub fn solve_columns_in_place(&self, b: &mut [f64], cols: usize) {
        let n = self.dim();
        let mut c_prime = vec![0.0; n];
        let mut denom = vec![0.0; n];
        denom[0] = self.diag[0];
        for i in 0..n {
            if i > 0 {
                denom[i] = self.diag[i] - self.lower[i - 1] * c_prime[i - 1];
            }
            if i + 1 < n {
                c_prime[i] = self.upper[i] / denom[i];
            }
        }
        for j in 0..cols {
            // forward
            b[j] /= denom[0];
            for i in 1..n {
                let prev = b[(i - 1) * cols + j];
                b[i * cols + j] = (b[i * cols + j] - self.lower[i - 1] * prev) / denom[i];
            }
            // backward
            for i in (0..n.saturating_sub(1)).rev() {
                let next = b[(i + 1) * cols + j];
                b[i * cols + j] -= c_prime[i] * next;
            }
        }
    }

    /// Number of negative pivots of the LDL^T (or, when not symmetric,
    /// the LU without pivoting) factorisation. For a symmetric matrix it
    /// is the number of negative eigenvalues (Sylvester's law of inertia),
    /// so `0` means positive semidefinite up to the exact-zero pivot.
    pub fn negative_pivots(&self) -> usize {
        count_negative_pivots(
            self.dim(),
            |i| self.diag[i],
            |i| self.lower[i] * self.upper[i],
        )
    }
}

/// Negative-pivot count of a tridiagonal matrix given by its diagonal
/// `d(i)` and off-diagonal products `p(i) = A[i+1][i] * A[i][i+1]`.
/// Zero pivots are nudged to a tiny positive value, the usual Sturm-count
/// convention, so the count is that of the matrix shifted by `+0`.
#[inline]
pub fn count_negative_pivots(
    n: usize,
    d: impl Fn(usize) -> f64,
    p: impl Fn(usize) -> f64,
) -> usize {
    let mut count = 0;
    let mut pivot = 1.0;
    for i in 0..n {
        let mut u = d(i);
        if i > 0 {
            u -= p(i - 1) / pivot;
        }
        if u == 0.0 {
            u = f64::MIN_POSITIVE.sqrt();
        }
        if u < 0.0 {
            count += 1;
        }
        pivot = u;
    }
    count
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Tridiagonal {
        Tridiagonal {
            lower: vec![1.0, -2.0],
            diag: vec![4.0, 5.0, 6.0],
            upper: vec![0.5, 1.5],
        }
    }

    #[test]
    fn thomas_solve_inverts_the_product() {
        let a = sample();
        let x = [1.0, -2.0, 3.0];
        let mut y = [0.0; 3];
        a.mul_vec(&x, &mut y);
        let mut b = y.to_vec();
        a.solve_columns_in_place(&mut b, 1);
        for (got, want) in b.iter().zip(x) {
            assert!((got - want).abs() < 1e-12);
        }
    }

    #[test]
    fn pivot_count_is_the_inertia_of_a_symmetric_matrix() {
        // eigenvalues of the 1-D Laplacian shifted by s: 2 - 2cos(k pi/4) - s, k = 1..3
        let lap = |s: f64| Tridiagonal {
            lower: vec![-1.0; 2],
            diag: vec![2.0 - s; 3],
            upper: vec![-1.0; 2],
        };
        assert_eq!(lap(0.5).negative_pivots(), 0); // smallest eigenvalue 0.586
        assert_eq!(lap(1.0).negative_pivots(), 1);
        assert_eq!(lap(2.5).negative_pivots(), 2);
        assert_eq!(lap(3.5).negative_pivots(), 3); // largest 3.414
    }
}
