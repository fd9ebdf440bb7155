//! Square band matrices with `kl` sub- and `ku` super-diagonals, and their
//! LU factorisation with partial pivoting (the `gbtrf` scheme: pivoting
//! widens the upper band to `kl + ku`, for which storage is reserved).
//! The GE tangent of 2-node elements has `kl = ku = 5`.
//!
//! One implementation over real and complex entries ([`BandScalar`]):
//! [`Band`] holds `f64` (tangents, mass and damping matrices), and
//! `BandMatrix<Complex<f64>>` the local QEP's `T(λ)` (`ComplexBand` of
//! `qs_flutter`).

use std::fmt::Debug;
use std::ops::{AddAssign, Div, Mul, SubAssign};

use faer::Mat;
use nalgebra::Complex;

/// The entries of a band matrix: `f64` or `Complex<f64>`, with the few
/// operations the product and the LU need.
pub trait BandScalar:
    Copy + Debug + PartialEq + Mul<Output = Self> + Div<Output = Self> + AddAssign + SubAssign
{
    const ZERO: Self;
    /// `|x|`, by which the pivot of a column is chosen.
    fn modulus(self) -> f64;
    /// The multiplier `self / pivot` of a row below the pivot.
    fn over_pivot(self, pivot: Self) -> Self;
}

impl BandScalar for f64 {
    const ZERO: Self = 0.0;
    #[inline]
    fn modulus(self) -> f64 {
        self.abs()
    }
    #[inline]
    fn over_pivot(self, pivot: Self) -> Self {
        self / pivot
    }
}

impl BandScalar for Complex<f64> {
    const ZERO: Self = Complex::new(0.0, 0.0);
    #[inline]
    fn modulus(self) -> f64 {
        self.norm()
    }
    /// Times the pivot's reciprocal (as the complex LU always formed its
    /// multipliers, so its answers are unchanged to the last bit).
    #[inline]
    fn over_pivot(self, pivot: Self) -> Self {
        self * (1.0 / pivot)
    }
}

/// Band matrix, row-major: row `i` stores columns `i − kl ..= i + kl + ku`.
#[derive(Clone, Debug, PartialEq)]
pub struct BandMatrix<T> {
    pub n: usize,
    pub kl: usize,
    pub ku: usize,
    data: Vec<T>,
}

/// A real band matrix.
pub type Band = BandMatrix<f64>;

impl<T: BandScalar> BandMatrix<T> {
    pub fn zeros(n: usize, kl: usize, ku: usize) -> Self {
        Self {
            n,
            kl,
            ku,
            data: vec![T::ZERO; n * (2 * kl + ku + 1)],
        }
    }

    fn width(&self) -> usize {
        2 * self.kl + self.ku + 1
    }

    #[inline]
    fn idx(&self, i: usize, j: usize) -> usize {
        debug_assert!(
            j + self.kl >= i && j <= i + self.kl + self.ku,
            "({i}, {j}) outside the band"
        );
        i * self.width() + (j + self.kl - i)
    }

    pub fn in_band(&self, i: usize, j: usize) -> bool {
        i < self.n && j < self.n && j + self.kl >= i && j <= i + self.ku
    }

    pub fn get(&self, i: usize, j: usize) -> T {
        if self.in_band(i, j) {
            self.data[self.idx(i, j)]
        } else {
            T::ZERO
        }
    }

    /// Sets the entry `(i, j)` of the band.
    #[inline]
    pub fn set(&mut self, i: usize, j: usize, v: T) {
        assert!(self.in_band(i, j), "({i}, {j}) outside the band");
        let k = self.idx(i, j);
        self.data[k] = v;
    }

    #[inline]
    pub fn add(&mut self, i: usize, j: usize, v: T) {
        assert!(self.in_band(i, j), "({i}, {j}) outside the band");
        let k = self.idx(i, j);
        self.data[k] += v;
    }

    pub fn fill_zero(&mut self) {
        self.data.iter_mut().for_each(|v| *v = T::ZERO);
    }

    /// `self += s · other` (same shape).
    pub fn add_scaled(&mut self, s: T, other: &Self) {
        assert_eq!((self.n, self.kl, self.ku), (other.n, other.kl, other.ku));
        for (a, b) in self.data.iter_mut().zip(&other.data) {
            *a += s * *b;
        }
    }

    /// `y += self · x` (each row summed in column order over its slice).
    pub fn mul_add(&self, x: &[T], y: &mut [T]) {
        let w = self.width();
        for i in 0..self.n {
            let lo = i.saturating_sub(self.kl);
            let hi = (i + self.ku).min(self.n - 1);
            let start = i * w + (lo + self.kl - i);
            let row = &self.data[start..start + (hi - lo) + 1];
            let mut s = T::ZERO;
            for (&a, &xj) in row.iter().zip(&x[lo..=hi]) {
                s += a * xj;
            }
            y[i] += s;
        }
    }

    /// LU with partial pivoting, in place. Returns `None` if a pivot is zero
    /// or not finite. The row updates run over contiguous slices of the
    /// row-major storage (the same operations in the same order as the
    /// element-by-element form, tested against it).
    pub fn factor(mut self) -> Option<BandLu<T>> {
        let n = self.n;
        let (kl, ku) = (self.kl, self.ku);
        let w = self.width();
        let mut pivots = vec![0usize; n];
        for k in 0..n {
            let last_row = (k + kl).min(n - 1);
            let mut p = k;
            let mut best = self.data[self.idx(k, k)].modulus();
            for r in k + 1..=last_row {
                let v = self.data[self.idx(r, k)].modulus();
                if v > best {
                    best = v;
                    p = r;
                }
            }
            if !best.is_finite() || best <= 0.0 {
                return None;
            }
            pivots[k] = p;
            let last_col = (k + kl + ku).min(n - 1);
            // row i's columns k..=last_col start at i·w + (k + kl − i)
            let span = last_col - k + 1;
            if p != k {
                let (a, b) = (k * w + kl, p * w + (k + kl - p));
                let (head, tail) = self.data.split_at_mut(b);
                head[a..a + span].swap_with_slice(&mut tail[..span]);
            }
            let pivot = self.data[k * w + kl];
            let (upper, lower) = self.data.split_at_mut((k + 1) * w);
            let row_k = &upper[k * w + kl + 1..k * w + kl + span];
            for r in k + 1..=last_row {
                let off = (r - k - 1) * w + (k + kl - r);
                let row_r = &mut lower[off..off + span];
                let l = row_r[0].over_pivot(pivot);
                row_r[0] = l;
                if l != T::ZERO {
                    for (x, &kj) in row_r[1..].iter_mut().zip(row_k) {
                        *x -= l * kj;
                    }
                }
            }
        }
        Some(BandLu { a: self, pivots })
    }

    /// The element-by-element form of [`Band::factor`] (its reference).
    #[cfg(test)]
    fn factor_reference(mut self) -> Option<BandLu<T>> {
        let n = self.n;
        let (kl, ku) = (self.kl, self.ku);
        let mut pivots = vec![0usize; n];
        for k in 0..n {
            let last_row = (k + kl).min(n - 1);
            let mut p = k;
            let mut best = self.data[self.idx(k, k)].modulus();
            for r in k + 1..=last_row {
                let v = self.data[self.idx(r, k)].modulus();
                if v > best {
                    best = v;
                    p = r;
                }
            }
            if !best.is_finite() || best <= 0.0 {
                return None;
            }
            pivots[k] = p;
            let last_col = (k + kl + ku).min(n - 1);
            if p != k {
                for j in k..=last_col {
                    let (a, b) = (self.idx(k, j), self.idx(p, j));
                    self.data.swap(a, b);
                }
            }
            let pivot = self.data[self.idx(k, k)];
            for r in k + 1..=last_row {
                let rk = self.idx(r, k);
                let l = self.data[rk].over_pivot(pivot);
                self.data[rk] = l;
                if l != T::ZERO {
                    for j in k + 1..=last_col {
                        let kj = self.data[self.idx(k, j)];
                        let rj = self.idx(r, j);
                        self.data[rj] -= l * kj;
                    }
                }
            }
        }
        Some(BandLu { a: self, pivots })
    }
}

impl Band {
    pub fn to_dense(&self) -> Mat<f64> {
        Mat::from_fn(self.n, self.n, |i, j| self.get(i, j))
    }
}

/// The factors of a [`BandMatrix`].
#[derive(Clone, Debug)]
pub struct BandLu<T = f64> {
    a: BandMatrix<T>,
    pivots: Vec<usize>,
}

impl<T: BandScalar> BandLu<T> {
    /// Solves `A x = b` in place.
    pub fn solve_in_place(&self, b: &mut [T]) {
        let a = &self.a;
        let n = a.n;
        for k in 0..n {
            let p = self.pivots[k];
            if p != k {
                b.swap(k, p);
            }
            let bk = b[k];
            if bk != T::ZERO {
                for r in k + 1..=(k + a.kl).min(n - 1) {
                    b[r] -= a.data[a.idx(r, k)] * bk;
                }
            }
        }
        let w = a.width();
        for i in (0..n).rev() {
            let last = (i + a.kl + a.ku).min(n - 1);
            let row = &a.data[i * w + a.kl..i * w + a.kl + (last - i) + 1];
            let mut s = b[i];
            for (&aij, &bj) in row[1..].iter().zip(&b[i + 1..=last]) {
                s -= aij * bj;
            }
            b[i] = s / row[0];
        }
    }
}

#[cfg(test)]
impl<T: BandScalar> BandLu<T> {
    /// The element-by-element form of [`BandLu::solve_in_place`].
    fn solve_reference(&self, b: &mut [T]) {
        let a = &self.a;
        let n = a.n;
        for k in 0..n {
            let p = self.pivots[k];
            if p != k {
                b.swap(k, p);
            }
            let bk = b[k];
            if bk != T::ZERO {
                for r in k + 1..=(k + a.kl).min(n - 1) {
                    b[r] -= a.data[a.idx(r, k)] * bk;
                }
            }
        }
        for i in (0..n).rev() {
            let mut s = b[i];
            for j in i + 1..=(i + a.kl + a.ku).min(n - 1) {
                s -= a.data[a.idx(i, j)] * b[j];
            }
            b[i] = s / a.data[a.idx(i, i)];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn band_lu_matches_dense_solve_with_pivoting() {
        let n = 23;
        let (kl, ku) = (5, 5);
        let mut a = Band::zeros(n, kl, ku);
        let mut seed = 7u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        for i in 0..n {
            for j in i.saturating_sub(kl)..=(i + ku).min(n - 1) {
                a.add(i, j, rnd());
            }
        }
        let x: Vec<f64> = (0..n).map(|i| (i as f64).sin()).collect();
        let mut b = vec![0.0; n];
        a.mul_add(&x, &mut b);
        let lu = a.clone().factor().unwrap();
        lu.solve_in_place(&mut b);
        for i in 0..n {
            assert!((b[i] - x[i]).abs() < 1e-9, "{i}: {} vs {}", b[i], x[i]);
        }
    }

    /// The slice forms of the factorisation and the product are the
    /// element-by-element ones bit for bit (factors, pivots, solution and
    /// product), on random bands with
    /// row swaps, of several sizes and band widths.
    #[test]
    fn factor_is_the_element_by_element_form() {
        let mut seed = 11u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        let mut swaps = 0;
        for (n, kl, ku) in [
            (1, 5, 5),
            (7, 5, 5),
            (60, 5, 5),
            (243, 5, 5),
            (30, 2, 3),
            (9, 3, 1),
        ] {
            let mut a = Band::zeros(n, kl, ku);
            for i in 0..n {
                for j in i.saturating_sub(kl)..=(i + ku).min(n - 1) {
                    a.add(i, j, rnd());
                }
            }
            let a_copy = a.clone();
            let (fast, slow) = (a.clone().factor().unwrap(), a.factor_reference().unwrap());
            assert_eq!(fast.pivots, slow.pivots);
            swaps += fast
                .pivots
                .iter()
                .enumerate()
                .filter(|(k, p)| *k != **p)
                .count();
            let bits = |b: &Band| b.data.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&fast.a), bits(&slow.a), "{n} × {n}, kl {kl}, ku {ku}");
            let rhs: Vec<f64> = (0..n).map(|_| rnd()).collect();
            // the product against the element-by-element sum
            let mut prod = vec![0.5; n];
            a_copy.mul_add(&rhs, &mut prod);
            for (i, p) in prod.iter().enumerate() {
                let mut s = 0.0;
                for j in i.saturating_sub(kl)..=(i + ku).min(n - 1) {
                    s += a_copy.get(i, j) * rhs[j];
                }
                assert_eq!(p.to_bits(), (0.5 + s).to_bits(), "row {i}");
            }
            let (mut x, mut y) = (rhs.clone(), rhs);
            fast.solve_in_place(&mut x);
            slow.solve_reference(&mut y);
            assert!(x.iter().zip(&y).all(|(u, v)| u.to_bits() == v.to_bits()));
        }
        assert!(swaps > 50, "{swaps} row swaps");
    }

    /// A random complex band (entries in the unit square about 0).
    fn complex_band(n: usize, kl: usize, ku: usize, seed: &mut u64) -> BandMatrix<Complex<f64>> {
        let mut rnd = || {
            *seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((*seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        let mut a = BandMatrix::zeros(n, kl, ku);
        for i in 0..n {
            for j in i.saturating_sub(kl)..=(i + ku).min(n - 1) {
                a.add(i, j, Complex::new(rnd(), rnd()));
            }
        }
        a
    }

    /// The complex band LU solves a random complex band system (with row
    /// swaps) as nalgebra's dense LU does, to 1e-10 relative.
    #[test]
    fn complex_band_lu_matches_a_dense_solve() {
        use nalgebra::{DMatrix, DVector};
        let mut seed = 23u64;
        let mut swaps = 0;
        for (n, kl, ku) in [(1, 5, 5), (12, 5, 5), (61, 5, 5), (40, 2, 4), (17, 3, 1)] {
            let a = complex_band(n, kl, ku, &mut seed);
            let b: Vec<Complex<f64>> = (0..n)
                .map(|i| Complex::new((i as f64).sin(), (3.0 * i as f64).cos()))
                .collect();
            let dense = DMatrix::from_fn(n, n, |i, j| a.get(i, j));
            let expected = dense
                .lu()
                .solve(&DVector::from_column_slice(&b))
                .expect("dense LU");
            let lu = a.factor().unwrap();
            swaps += lu
                .pivots
                .iter()
                .enumerate()
                .filter(|(k, p)| *k != **p)
                .count();
            let mut x = b;
            lu.solve_in_place(&mut x);
            let error = x
                .iter()
                .zip(expected.iter())
                .map(|(u, v)| (u - v).norm_sqr())
                .sum::<f64>()
                .sqrt();
            assert!(
                error <= 1e-10 * expected.norm(),
                "{n} × {n}, kl {kl}, ku {ku}: error {error:e} of {:e}",
                expected.norm()
            );
        }
        assert!(swaps > 20, "{swaps} row swaps");
    }

    /// The complex factorisation and solve through the slice forms are the
    /// element-by-element ones bit for bit (the complex LU's former code).
    #[test]
    fn complex_factor_is_the_element_by_element_form() {
        let mut seed = 5u64;
        let bits = |v: &[Complex<f64>]| {
            v.iter()
                .map(|z| (z.re.to_bits(), z.im.to_bits()))
                .collect::<Vec<_>>()
        };
        for (n, kl, ku) in [(7, 5, 5), (93, 5, 5), (30, 2, 3)] {
            let a = complex_band(n, kl, ku, &mut seed);
            let (fast, slow) = (a.clone().factor().unwrap(), a.factor_reference().unwrap());
            assert_eq!(fast.pivots, slow.pivots);
            assert_eq!(
                bits(&fast.a.data),
                bits(&slow.a.data),
                "{n} × {n}, kl {kl}, ku {ku}"
            );
            let rhs: Vec<Complex<f64>> = (0..n)
                .map(|i| Complex::new((i as f64).cos(), 0.5 - (i as f64).sin()))
                .collect();
            let (mut x, mut y) = (rhs.clone(), rhs);
            fast.solve_in_place(&mut x);
            slow.solve_reference(&mut y);
            assert_eq!(bits(&x), bits(&y));
        }
    }
}
