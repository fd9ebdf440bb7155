//! The constant finite-element operators of the linear string (SPEC §1,
//! thesis app. A) and their assembly into `M, C, K` at a state.
//!
//! With 2-node elements on the mapped coordinate and node 0 (the roller)
//! removed, every matrix of the model is a combination of five constant
//! tridiagonal operators (rows: test function, columns: trial function):
//!
//! ```text
//! mass      = ∫ N Nᵀ            conv      = ∫ (1-ζ) N N'ᵀ
//! stiff_0   = ∫ N' N'ᵀ          stiff_1   = ∫ (1-ζ) N' N'ᵀ     stiff_2 = ∫ (1-ζ)² N' N'ᵀ
//! ```
//!
//! All integrands are polynomials of degree ≤ 2 on an element; the 3-point
//! Gauss rule integrates them exactly (consistent mass).

use crate::numerics::mesh::Mesh;
use crate::numerics::tridiag::Tridiagonal;

/// The five constant operators for one mesh.
#[derive(Clone, Debug)]
pub struct StringOperators {
    pub mesh: Mesh,
    pub mass: Tridiagonal,
    pub conv: Tridiagonal,
    pub stiff_0: Tridiagonal,
    pub stiff_1: Tridiagonal,
    pub stiff_2: Tridiagonal,
}

/// Coefficients that turn the operators into `M, C, K`:
///
/// ```text
/// M = mass_scale·mass + tip_mass·e_n e_nᵀ
/// C = damping_scale·conv
/// K = conv_stiffness·conv − quad_stiffness·stiff_2 + tension_top·stiff_0 + tension_slope·stiff_1
/// ```
///
/// so the tension profile is `T(ζ) = tension_top + tension_slope·(1-ζ)`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MatrixCoefficients {
    pub mass_scale: f64,
    pub tip_mass: f64,
    pub damping_scale: f64,
    pub conv_stiffness: f64,
    pub quad_stiffness: f64,
    pub tension_top: f64,
    pub tension_slope: f64,
}

/// The second-order system `M q̈ + C q̇ + K q = f`.
#[derive(Clone, Debug)]
pub struct SecondOrderSystem {
    pub mass: Tridiagonal,
    pub damping: Tridiagonal,
    pub stiffness: Tridiagonal,
}

impl StringOperators {
    /// Operators on a uniform mesh of `elements` elements.
    pub fn new(elements: usize) -> Self {
        Self::on_mesh(Mesh::uniform(elements))
    }

    /// Operators on any mesh (e.g. graded toward the roller).
    pub fn on_mesh(mesh: Mesh) -> Self {
        let elements = mesh.elements();
        let n = elements; // unknowns: nodes 1..=n
        let mut ops = Self {
            mesh: mesh.clone(),
            mass: Tridiagonal::zeros(n),
            conv: Tridiagonal::zeros(n),
            stiff_0: Tridiagonal::zeros(n),
            stiff_1: Tridiagonal::zeros(n),
            stiff_2: Tridiagonal::zeros(n),
        };
        for e in 0..elements {
            let dofs = [e.checked_sub(1), Some(e)]; // node e -> dof e-1; node 0 is fixed
            for q in mesh.element_quadrature(e, 3) {
                let s = 1.0 - q.zeta;
                for (a, row) in dofs.iter().enumerate() {
                    let Some(row) = *row else { continue };
                    for (b, col) in dofs.iter().enumerate() {
                        let Some(col) = *col else { continue };
                        let w = q.weight;
                        ops.mass.add(row, col, w * q.shape[a] * q.shape[b]);
                        ops.conv.add(row, col, w * s * q.shape[a] * q.slope[b]);
                        let dd = w * q.slope[a] * q.slope[b];
                        ops.stiff_0.add(row, col, dd);
                        ops.stiff_1.add(row, col, s * dd);
                        ops.stiff_2.add(row, col, s * s * dd);
                    }
                }
            }
        }
        ops
    }

    /// Number of unknowns (nodes 1..=n).
    pub fn dim(&self) -> usize {
        self.mesh.elements()
    }

    pub fn assemble(&self, c: &MatrixCoefficients) -> SecondOrderSystem {
        let mut mass = Tridiagonal::combination(&[(c.mass_scale, &self.mass)]);
        let last = self.dim() - 1;
        mass.diag[last] += c.tip_mass;
        let damping = Tridiagonal::combination(&[(c.damping_scale, &self.conv)]);
        let stiffness = Tridiagonal::combination(&[
            (c.conv_stiffness, &self.conv),
            (-c.quad_stiffness, &self.stiff_2),
            (c.tension_top, &self.stiff_0),
            (c.tension_slope, &self.stiff_1),
        ]);
        SecondOrderSystem {
            mass,
            damping,
            stiffness,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn operators_integrate_known_totals() {
        let ops = StringOperators::new(8);
        // Σ_ij mass_ij over all nodes but the fixed one = ∫ (Σ N)(Σ N) minus the node-0 share.
        // Test instead with the linear field q_k = ζ_k (exact in the FE space):
        let h = 1.0 / 8.0;
        let q: Vec<f64> = (1..=8).map(|k| k as f64 * h).collect();
        // ∫ ζ² = 1/3, ∫ 1·1 = 1, ∫ (1-ζ) = 1/2, ∫ (1-ζ)² = 1/3
        assert!((ops.mass.quadratic_form(&q) - 1.0 / 3.0).abs() < 1e-13);
        assert!((ops.stiff_0.quadratic_form(&q) - 1.0).abs() < 1e-13);
        assert!((ops.stiff_1.quadratic_form(&q) - 0.5).abs() < 1e-13);
        assert!((ops.stiff_2.quadratic_form(&q) - 1.0 / 3.0).abs() < 1e-13);
        // qᵀ conv q = ∫ (1-ζ) ζ · 1 = 1/6
        assert!((ops.conv.quadratic_form(&q) - 1.0 / 6.0).abs() < 1e-13);
    }

    #[test]
    fn symmetric_part_of_conv_is_half_the_mass() {
        // (conv + convᵀ) = ∫ (1-ζ) d(N Nᵀ)/dζ = ∫ N Nᵀ after integration by parts
        let ops = StringOperators::new(13);
        let sym = Tridiagonal::combination(&[(1.0, &ops.conv), (1.0, &ops.conv.transpose())]);
        for (a, b) in sym.diag.iter().zip(&ops.mass.diag) {
            assert!((a - b).abs() < 1e-14);
        }
        for (a, b) in sym.lower.iter().zip(&ops.mass.lower) {
            assert!((a - b).abs() < 1e-14);
        }
    }
}
