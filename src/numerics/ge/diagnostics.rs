//! Diagnostics of a state: energy (6.22)–(6.24), angular momentum about the
//! root (6.27) and the support reaction at the root.
//!
//! Velocities are material: a point at `ζ` moves with
//! `ṙ0 = (L̇ + Du1/Dt, Du2/Dt)`, `Dθ/Dt`, where `D/Dt = ∂_t + (1−ζ)(L̇/L)∂_ζ`.
//! The integrals are exact for the element interpolation (2-point Gauss),
//! the strain energy uses the internal-force rule.

use super::GeModel;
use super::element::{self, node};
use crate::numerics::params::Kinematics;

/// Energy of a state (J).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Energy {
    /// Kinetic energy (6.22) of cable and aerostat, sliding included.
    pub kinetic_j: f64,
    /// Strain energy (6.24).
    pub strain_j: f64,
    /// Kinetic energy relative to the rigid sliding `L̇ E1`, plus strain
    /// energy: the energy of the oscillation.
    pub oscillation_j: f64,
}

impl Energy {
    pub fn total_j(&self) -> f64 {
        self.kinetic_j + self.strain_j
    }
}

const G2: [(f64, f64); 2] = [
    (0.5 - 0.288_675_134_594_812_9, 0.5),
    (0.5 + 0.288_675_134_594_812_9, 0.5),
];

/// Calls `f(weight·L, ζ, r0, ṙ0, Dθ/Dt)` at the exact quadrature points.
fn for_points(
    model: &GeModel,
    kin: Kinematics,
    q: &[f64],
    v: &[f64],
    mut f: impl FnMut(f64, [f64; 2], [f64; 2], f64),
) {
    let (l, ld) = (kin.length_m, kin.rate_m_s);
    for e in 0..model.elements {
        let h = model.ops.len(e);
        let (qa, qb, va, vb) = (node(q, e), node(q, e + 1), node(v, e), node(v, e + 1));
        for &(xi, wf) in &G2 {
            let z = model.ops.point(e, xi);
            let c = (1.0 - z) * ld / l;
            let mut d = [0.0; 3];
            let mut u = [0.0; 3];
            for k in 0..3 {
                let slope = (qb[k] - qa[k]) / h;
                u[k] = (1.0 - xi) * qa[k] + xi * qb[k];
                d[k] = (1.0 - xi) * va[k] + xi * vb[k] + c * slope;
            }
            f(wf * h * l, [z * l + u[0], u[1]], [ld + d[0], d[1]], d[2]);
        }
    }
}

pub fn energy(model: &GeModel, kin: Kinematics, q: &[f64], v: &[f64]) -> Energy {
    let s = &model.section;
    let (mut kinetic, mut relative) = (0.0, 0.0);
    for_points(model, kin, q, v, |w, _r, rd, thd| {
        let rot = s.rotary_inertia_kg_m * thd * thd;
        kinetic += 0.5 * w * (s.mass_per_length_kg_m * (rd[0] * rd[0] + rd[1] * rd[1]) + rot);
        let d1 = rd[0] - kin.rate_m_s;
        relative += 0.5 * w * (s.mass_per_length_kg_m * (d1 * d1 + rd[1] * rd[1]) + rot);
    });
    let top = model.elements;
    let (_, xd) = element::tip_point(model, kin, node(q, top), node(v, top));
    let m = model.tip.mass_kg;
    kinetic += 0.5 * m * (xd[0] * xd[0] + xd[1] * xd[1]);
    relative += 0.5 * m * ((xd[0] - kin.rate_m_s).powi(2) + xd[1] * xd[1]);
    let strain = element::strain_energy(model, kin.length_m, q);
    Energy {
        kinetic_j: kinetic,
        strain_j: strain,
        oscillation_j: relative + strain,
    }
}

/// Angular momentum about the root (6.27), aerostat included (N m s).
pub fn angular_momentum(model: &GeModel, kin: Kinematics, q: &[f64], v: &[f64]) -> f64 {
    let s = &model.section;
    let mut h = 0.0;
    for_points(model, kin, q, v, |w, r, rd, thd| {
        h += w
            * (s.rotary_inertia_kg_m * thd
                + s.mass_per_length_kg_m * (r[0] * rd[1] - r[1] * rd[0]));
    });
    let top = model.elements;
    let (x, xd) = element::tip_point(model, kin, node(q, top), node(v, top));
    h + model.tip.mass_kg * (x[0] * xd[1] - x[1] * xd[0])
}

/// Support reaction on the cable at the clamped root: `(F1, F2, M)` — the
/// rows of the root node of inertia + internal − body forces.
pub fn root_reaction(
    model: &GeModel,
    kin: Kinematics,
    mu: f64,
    q: &[f64],
    v: &[f64],
    a: &[f64],
) -> [f64; 3] {
    let mut root = element::root_linear(model, kin, mu, q, v, a);
    let mut scratch = vec![0.0; model.dofs()];
    element::internal_forces(model, kin.length_m, q, &mut scratch, None, Some(&mut root));
    let mut body = [0.0; 3];
    element::body_forces(model, kin, 1.0, &mut scratch, &mut body);
    [root[0] - body[0], root[1] - body[1], root[2] - body[2]]
}
