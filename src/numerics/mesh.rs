//! One-dimensional meshes on the mapped coordinate `ζ ∈ [0, 1]`:
//! uniform 2-node linear elements, their shape functions and the
//! Gauss–Legendre rules the element integrals use.

/// Gauss–Legendre points and weights on `[-1, 1]`.
pub fn gauss_legendre(points: usize) -> &'static [(f64, f64)] {
    const G1: [(f64, f64); 1] = [(0.0, 2.0)];
    const G2: [(f64, f64); 2] = [
        (-0.577_350_269_189_625_8, 1.0),
        (0.577_350_269_189_625_8, 1.0),
    ];
    const G3: [(f64, f64); 3] = [
        (-0.774_596_669_241_483_4, 5.0 / 9.0),
        (0.0, 8.0 / 9.0),
        (0.774_596_669_241_483_4, 5.0 / 9.0),
    ];
    match points {
        1 => &G1,
        2 => &G2,
        3 => &G3,
        _ => panic!("gauss_legendre supports 1 to 3 points, not {points}"),
    }
}

/// A uniform mesh of `elements` linear elements on `[0, 1]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UniformMesh {
    pub elements: usize,
}

impl UniformMesh {
    pub fn new(elements: usize) -> Self {
        assert!(elements >= 1, "a mesh needs at least one element");
        Self { elements }
    }

    pub fn element_size(&self) -> f64 {
        1.0 / self.elements as f64
    }

    pub fn nodes(&self) -> usize {
        self.elements + 1
    }

    /// Node coordinates `ζ_k = k h`.
    pub fn node_coordinate(&self, k: usize) -> f64 {
        k as f64 * self.element_size()
    }

    /// Quadrature points of element `e` mapped to `ζ`, with their weights
    /// (already scaled by the Jacobian `h/2`), and the shape values
    /// `(N_a, N_b)` there.
    pub fn element_quadrature(
        &self,
        e: usize,
        points: usize,
    ) -> impl Iterator<Item = QuadraturePoint> + '_ {
        let h = self.element_size();
        let a = e as f64 * h;
        gauss_legendre(points).iter().map(move |&(xi, w)| {
            let zeta = a + 0.5 * h * (xi + 1.0);
            let nb = (zeta - a) / h;
            QuadraturePoint {
                zeta,
                weight: 0.5 * h * w,
                shape: [1.0 - nb, nb],
                slope: [-1.0 / h, 1.0 / h],
            }
        })
    }
}

/// One quadrature point of a linear element.
#[derive(Clone, Copy, Debug)]
pub struct QuadraturePoint {
    pub zeta: f64,
    pub weight: f64,
    /// Shape functions `N_a, N_b` at `zeta`.
    pub shape: [f64; 2],
    /// Their derivatives `dN/dζ`.
    pub slope: [f64; 2],
}
