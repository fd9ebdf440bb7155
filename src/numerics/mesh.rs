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

/// A mesh of linear elements on `[0, 1]` with arbitrary node positions
/// `0 = ζ_0 < ζ_1 < … < ζ_n = 1`: uniform, or graded toward the roller
/// (`ζ = 0`) where the critical mode of the string concentrates.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    nodes: Vec<f64>,
}

impl Mesh {
    /// `elements` equal elements.
    pub fn uniform(elements: usize) -> Self {
        assert!(elements >= 1, "a mesh needs at least one element");
        let u = UniformMesh::new(elements);
        let mut nodes: Vec<f64> = (0..u.nodes()).map(|k| u.node_coordinate(k)).collect();
        nodes[elements] = 1.0;
        Self { nodes }
    }

    /// Graded toward `ζ = 0`: nodes at `0, first, 2·first, 4·first, …`
    /// (element sizes doubling from `first`) until an element would exceed
    /// `1/bulk_elements`; the rest of `[0, 1]` is cut into equal elements of
    /// at most that size. Halving `first` adds one node, at `first/2`, and
    /// keeps every other node: a refinement sequence is nested.
    pub fn graded(first: f64, bulk_elements: usize) -> Self {
        assert!(bulk_elements >= 1, "a mesh needs at least one element");
        let h_bulk = 1.0 / bulk_elements as f64;
        assert!(
            first > 0.0 && first <= h_bulk,
            "the first element must be in (0, 1/bulk_elements]"
        );
        let mut nodes = vec![0.0, first];
        let mut at = first;
        while at < h_bulk && 2.0 * at < 1.0 {
            at *= 2.0;
            nodes.push(at);
        }
        if at < 1.0 {
            let rest = 1.0 - at;
            let count = ((rest / h_bulk) - 1e-9).ceil().max(1.0) as usize;
            for k in 1..count {
                nodes.push(at + rest * k as f64 / count as f64);
            }
            nodes.push(1.0);
        }
        Self { nodes }
    }

    pub fn elements(&self) -> usize {
        self.nodes.len() - 1
    }

    pub fn nodes(&self) -> usize {
        self.nodes.len()
    }

    /// Node coordinate `ζ_k`.
    pub fn node_coordinate(&self, k: usize) -> f64 {
        self.nodes[k]
    }

    /// Size of element `e`.
    pub fn element_size(&self, e: usize) -> f64 {
        self.nodes[e + 1] - self.nodes[e]
    }

    /// Quadrature points of element `e` (see [`UniformMesh::element_quadrature`]).
    pub fn element_quadrature(
        &self,
        e: usize,
        points: usize,
    ) -> impl Iterator<Item = QuadraturePoint> + '_ {
        let (a, b) = (self.nodes[e], self.nodes[e + 1]);
        let h = b - a;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn graded_mesh_doubles_from_the_roller_and_is_nested() {
        let m = Mesh::graded(1e-3, 10);
        assert_eq!(m.node_coordinate(0), 0.0);
        assert_eq!(m.node_coordinate(m.elements()), 1.0);
        assert!((m.element_size(0) - 1e-3).abs() < 1e-15);
        assert!((m.element_size(1) - 1e-3).abs() < 1e-15);
        assert!((m.element_size(2) - 2e-3).abs() < 1e-15);
        for e in 0..m.elements() {
            assert!(m.element_size(e) > 0.0 && m.element_size(e) <= 0.1 + 1e-12);
        }
        // halving the first element adds exactly one node, at 5e-4
        let finer = Mesh::graded(5e-4, 10);
        assert_eq!(finer.elements(), m.elements() + 1);
        assert!((finer.node_coordinate(1) - 5e-4).abs() < 1e-15);
        for k in 1..m.nodes() {
            assert_eq!(finer.node_coordinate(k + 1), m.node_coordinate(k));
        }
        assert_eq!(Mesh::uniform(4).node_coordinate(3), 0.75);
    }
}
