//! The GE beam's mesh on `ζ ∈ [0, 1]` (uniform or graded) and the
//! constant element integrals `R_e = ∫ N Nᵀ`, `P_e = ∫ (1-ζ) N N_ζᵀ`,
//! `Q_e = ∫ (1-ζ)² N_ζ N_ζᵀ` of the linear (inertia) operators of
//! [`super::element`] (exact 2-point Gauss). Below both the model
//! ([`super::GeModel`] holds one) and the element operators that use it.

/// Gauss points on the unit element as (fraction along, weight fraction).
pub(crate) const GAUSS1: [(f64, f64); 1] = [(0.5, 1.0)];
pub(crate) const GAUSS2: [(f64, f64); 2] = [
    (0.5 - 0.288_675_134_594_812_9, 0.5),
    (0.5 + 0.288_675_134_594_812_9, 0.5),
];

/// The mesh on `ζ ∈ [0, 1]` and the constant element integrals `R_e`,
/// `P_e`, `Q_e` of it. Uniform meshes ([`Self::new`]) keep `h = 1/n` and
/// `ζ = (e + ξ) h` exactly as before graded meshes existed, so their
/// answers are unchanged bit for bit; graded ones ([`Self::graded`]) take
/// their node positions.
#[derive(Clone, Debug)]
pub struct InertiaOperators {
    /// Element length on `ζ` of a uniform mesh; `None` when graded.
    pub h: Option<f64>,
    /// Element lengths on `ζ`.
    pub lengths: Vec<f64>,
    /// `ζ` of each element's first node.
    pub starts: Vec<f64>,
    pub r: Vec<[[f64; 2]; 2]>,
    pub p: Vec<[[f64; 2]; 2]>,
    pub q: Vec<[[f64; 2]; 2]>,
}

impl InertiaOperators {
    /// A uniform mesh of `elements` elements.
    pub fn new(elements: usize) -> Self {
        let h = 1.0 / elements as f64;
        let starts = (0..elements).map(|e| e as f64 * h).collect();
        Self::build(Some(h), vec![h; elements], starts)
    }

    /// A mesh with nodes at `nodes` (`0 = ζ₀ < ζ₁ < … < ζ_n = 1`).
    pub fn graded(nodes: &[f64]) -> Self {
        let lengths = nodes.windows(2).map(|w| w[1] - w[0]).collect();
        let starts = nodes[..nodes.len() - 1].to_vec();
        Self::build(None, lengths, starts)
    }

    fn build(h: Option<f64>, lengths: Vec<f64>, starts: Vec<f64>) -> Self {
        let elements = lengths.len();
        let mut r = vec![[[0.0; 2]; 2]; elements];
        let mut p = vec![[[0.0; 2]; 2]; elements];
        let mut q = vec![[[0.0; 2]; 2]; elements];
        for e in 0..elements {
            let (za, h) = (starts[e], lengths[e]);
            let dn = [-1.0 / h, 1.0 / h];
            for &(xi, wf) in &GAUSS2 {
                let z = za + xi * h;
                let w = wf * h;
                let n = [1.0 - xi, xi];
                let s = 1.0 - z;
                for i in 0..2 {
                    for j in 0..2 {
                        r[e][i][j] += w * n[i] * n[j];
                        p[e][i][j] += w * s * n[i] * dn[j];
                        q[e][i][j] += w * s * s * dn[i] * dn[j];
                    }
                }
            }
        }
        Self {
            h,
            lengths,
            starts,
            r,
            p,
            q,
        }
    }

    /// Length of element `e` on `ζ`.
    #[inline]
    pub fn len(&self, e: usize) -> f64 {
        self.lengths[e]
    }

    /// `ζ` of the point at fraction `xi` along element `e`.
    #[inline]
    pub fn point(&self, e: usize, xi: f64) -> f64 {
        match self.h {
            Some(h) => (e as f64 + xi) * h,
            None => self.starts[e] + xi * self.lengths[e],
        }
    }

    /// `ζ` of node `k`.
    pub fn node_position(&self, k: usize) -> f64 {
        match self.h {
            Some(h) => k as f64 * h,
            None if k < self.starts.len() => self.starts[k],
            None => 1.0,
        }
    }
}
