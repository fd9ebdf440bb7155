//! Element operators of the sliding GE beam (thesis (6.3)–(6.8),
//! (6.16)–(6.21) with the corrections of SPEC §3), assembled over the
//! unknowns (node 0 clamped) into band matrices, plus the root rows that
//! give the support reactions.
//!
//! Linear (inertia) part, per element and per component `c` with
//! `I_c ∈ {A_ρ, A_ρ, I_ρ}` (exact 2-point Gauss):
//!
//! ```text
//! M = L R                       R = ∫ N Nᵀ
//! C = 2 L̇ P + μ L R             P = ∫ (1-ζ) N N_ζᵀ
//! K = −(L̇²/L) Q + (L̈ + μ L̇) P    Q = ∫ (1-ζ)² N_ζ N_ζᵀ
//! ```
//!
//! `2L̇P` equals the thesis's skew convection operator plus the missing
//! `L̇ R` term of SPEC §3 (integration by parts, exact for these elements);
//! a unit test checks the identity. `μ` is linear viscous damping on the
//! material velocity relative to the guide, per unit mass (1/s).

use super::banded::Band;
pub use super::inertia::InertiaOperators;
use super::inertia::{GAUSS1, GAUSS2};
use super::{GeModel, StiffnessRule};
use crate::numerics::params::Kinematics;

/// Half bandwidth of the tangent: a node's dofs reach the neighbour's.
pub const HALF_BAND: usize = 5;

/// Nodal values `(u1, u2, θ)` of node `k` (zero at the clamped root).
#[inline]
pub fn node(x: &[f64], k: usize) -> [f64; 3] {
    if k == 0 {
        [0.0; 3]
    } else {
        [x[3 * k - 3], x[3 * k - 2], x[3 * k - 1]]
    }
}

/// The linear operators `M, C, K` of the cable (aerostat excluded) at one
/// instant.
pub struct LinearOperators {
    pub mass: Band,
    pub damping: Band,
    pub stiffness: Band,
}

/// Scalar 2×2 coefficient matrices of element `e`: `(M, C, K)`.
fn element_linear(model: &GeModel, e: usize, kin: Kinematics, damping: f64) -> [[[f64; 2]; 2]; 3] {
    let ops = &model.ops;
    let (l, ld, ldd) = (kin.length_m, kin.rate_m_s, kin.acceleration_m_s2);
    let mut out = [[[0.0; 2]; 2]; 3];
    for i in 0..2 {
        for j in 0..2 {
            out[0][i][j] = l * ops.r[e][i][j];
            out[1][i][j] = 2.0 * ld * ops.p[e][i][j] + damping * l * ops.r[e][i][j];
            out[2][i][j] = -(ld * ld / l) * ops.q[e][i][j] + (ldd + damping * ld) * ops.p[e][i][j];
        }
    }
    out
}

pub fn linear_operators(model: &GeModel, kin: Kinematics, damping: f64) -> LinearOperators {
    let n = model.dofs();
    let mut ops = LinearOperators {
        mass: Band::zeros(n, HALF_BAND, HALF_BAND),
        damping: Band::zeros(n, HALF_BAND, HALF_BAND),
        stiffness: Band::zeros(n, HALF_BAND, HALF_BAND),
    };
    let inertia = model.section.inertia();
    for e in 0..model.elements {
        let mats = element_linear(model, e, kin, damping);
        for a in 0..2 {
            let ka = e + a;
            if ka == 0 {
                continue;
            }
            for b in 0..2 {
                let kb = e + b;
                if kb == 0 {
                    continue;
                }
                for c in 0..3 {
                    let (row, col) = (GeModel::dof(ka, c), GeModel::dof(kb, c));
                    ops.mass.add(row, col, inertia[c] * mats[0][a][b]);
                    ops.damping.add(row, col, inertia[c] * mats[1][a][b]);
                    ops.stiffness.add(row, col, inertia[c] * mats[2][a][b]);
                }
            }
        }
    }
    ops
}

/// Rows of the clamped root node of `M a + C v + K q` (the linear part of
/// the support reaction).
pub fn root_linear(
    model: &GeModel,
    kin: Kinematics,
    damping: f64,
    q: &[f64],
    v: &[f64],
    a: &[f64],
) -> [f64; 3] {
    let mats = element_linear(model, 0, kin, damping);
    let inertia = model.section.inertia();
    let (q1, v1, a1) = (node(q, 1), node(v, 1), node(a, 1));
    let mut out = [0.0; 3];
    for c in 0..3 {
        out[c] =
            inertia[c] * (mats[0][0][1] * a1[c] + mats[1][0][1] * v1[c] + mats[2][0][1] * q1[c]);
    }
    out
}

/// Gauss points of the internal-force rule.
fn stiffness_points(rule: StiffnessRule) -> &'static [(f64, f64)] {
    match rule {
        StiffnessRule::Reduced => &GAUSS1,
        StiffnessRule::Full => &GAUSS2,
    }
}

/// Stress resultants at one point: `(f1, f2, m)`, the strains `(γ1, γ2, κ)`
/// in the section frame, and `r0_ζ`.
#[derive(Clone, Copy, Debug)]
pub struct PointState {
    pub f: [f64; 2],
    pub m: f64,
    pub gamma: [f64; 2],
    pub curvature: f64,
    pub r_zeta: [f64; 2],
    pub theta: f64,
}

#[inline]
fn point_state(
    model: &GeModel,
    length: f64,
    ua: [f64; 3],
    ub: [f64; 3],
    xi: f64,
    h: f64,
) -> PointState {
    let s = &model.section;
    let u1z = (ub[0] - ua[0]) / h;
    let u2z = (ub[1] - ua[1]) / h;
    let thz = (ub[2] - ua[2]) / h;
    let th = (1.0 - xi) * ua[2] + xi * ub[2];
    let r = [length + u1z, u2z];
    let (sn, cs) = th.sin_cos();
    let g1 = r[0] / length - cs;
    let g2 = r[1] / length - sn;
    let gam = [cs * g1 + sn * g2, -sn * g1 + cs * g2];
    let n1 = s.axial_stiffness_n * gam[0];
    let n2 = s.shear_stiffness_n * gam[1];
    let curvature = thz / length;
    PointState {
        f: [cs * n1 - sn * n2, sn * n1 + cs * n2],
        m: s.bending_stiffness_n_m2 * curvature,
        gamma: gam,
        curvature,
        r_zeta: r,
        theta: th,
    }
}

/// Internal force `∫ D(U)W·p` (6.21): adds to `f` (unknowns) and, if given,
/// to `root` (the clamped node's rows); adds the tangent (6.19)+(6.20) to
/// `tangent` if given.
pub fn internal_forces(
    model: &GeModel,
    length: f64,
    q: &[f64],
    f: &mut [f64],
    mut tangent: Option<&mut Band>,
    mut root: Option<&mut [f64; 3]>,
) {
    let sec = &model.section;
    let (ea, ga, ei) = (
        sec.axial_stiffness_n,
        sec.shear_stiffness_n,
        sec.bending_stiffness_n_m2,
    );
    let points = stiffness_points(model.rule);
    for e in 0..model.elements {
        let h = model.ops.len(e);
        let dn = [-1.0 / h, 1.0 / h];
        let ua = node(q, e);
        let ub = node(q, e + 1);
        let mut fe = [0.0; 6];
        let mut ke = [[0.0; 6]; 6];
        for &(xi, wf) in points {
            let w = wf * h;
            let nn = [1.0 - xi, xi];
            let p = point_state(model, length, ua, ub, xi, h);
            let [f1, f2] = p.f;
            let [r1, r2] = p.r_zeta;
            for a in 0..2 {
                fe[3 * a] += w * dn[a] * f1;
                fe[3 * a + 1] += w * dn[a] * f2;
                fe[3 * a + 2] += w * (nn[a] * (r2 * f1 - r1 * f2) + dn[a] * p.m);
            }
            if tangent.is_some() {
                let (sn, cs) = p.theta.sin_cos();
                let d11 = (ea * cs * cs + ga * sn * sn) / length;
                let d22 = (ea * sn * sn + ga * cs * cs) / length;
                let d12 = (ea - ga) * sn * cs / length;
                let dm = ei / length;
                // B_a = [[dN, 0, r2 N], [0, dN, −r1 N], [0, 0, dN]]
                let bmat = |a: usize| -> [[f64; 3]; 3] {
                    [
                        [dn[a], 0.0, r2 * nn[a]],
                        [0.0, dn[a], -r1 * nn[a]],
                        [0.0, 0.0, dn[a]],
                    ]
                };
                let dmat = [[d11, d12, 0.0], [d12, d22, 0.0], [0.0, 0.0, dm]];
                let g = [
                    [0.0, 0.0, -f2],
                    [0.0, 0.0, f1],
                    [-f2, f1, -(r1 * f1 + r2 * f2)],
                ];
                for a in 0..2 {
                    let ba = bmat(a);
                    let dbar_a = [dn[a], dn[a], nn[a]];
                    for b in 0..2 {
                        let bb = bmat(b);
                        let dbar_b = [dn[b], dn[b], nn[b]];
                        // D B_b
                        let mut db = [[0.0; 3]; 3];
                        for i in 0..3 {
                            for j in 0..3 {
                                db[i][j] = (0..3).map(|k| dmat[i][k] * bb[k][j]).sum();
                            }
                        }
                        for i in 0..3 {
                            for j in 0..3 {
                                let material: f64 = (0..3).map(|k| ba[k][i] * db[k][j]).sum();
                                let geometric = dbar_a[i] * g[i][j] * dbar_b[j];
                                ke[3 * a + i][3 * b + j] += w * (material + geometric);
                            }
                        }
                    }
                }
            }
        }
        for a in 0..2 {
            let k = e + a;
            if k == 0 {
                if let Some(root) = root.as_deref_mut() {
                    for c in 0..3 {
                        root[c] += fe[c];
                    }
                }
                continue;
            }
            for c in 0..3 {
                f[GeModel::dof(k, c)] += fe[3 * a + c];
            }
            if let Some(t) = tangent.as_deref_mut() {
                for b in 0..2 {
                    let kb = e + b;
                    if kb == 0 {
                        continue;
                    }
                    for c in 0..3 {
                        for d in 0..3 {
                            t.add(
                                GeModel::dof(k, c),
                                GeModel::dof(kb, d),
                                ke[3 * a + c][3 * b + d],
                            );
                        }
                    }
                }
            }
        }
    }
}

/// Strain energy (6.24), `½ ∫₀ᴸ (EA γ1² + GA γ2² + EI κ²) dX`, with the
/// rule of the internal forces (so they are its exact gradient).
pub fn strain_energy(model: &GeModel, length: f64, q: &[f64]) -> f64 {
    let s = &model.section;
    let mut total = 0.0;
    for e in 0..model.elements {
        let h = model.ops.len(e);
        let (ua, ub) = (node(q, e), node(q, e + 1));
        for &(xi, wf) in stiffness_points(model.rule) {
            let p = point_state(model, length, ua, ub, xi, h);
            total += wf
                * h
                * length
                * 0.5
                * (s.axial_stiffness_n * p.gamma[0].powi(2)
                    + s.shear_stiffness_n * p.gamma[1].powi(2)
                    + s.bending_stiffness_n_m2 * p.curvature * p.curvature);
        }
    }
    total
}

/// Stress resultants at the middle of every element: `(f1, f2, m)`.
pub fn element_resultants(model: &GeModel, length: f64, q: &[f64]) -> Vec<[f64; 3]> {
    (0..model.elements)
        .map(|e| {
            let h = model.ops.len(e);
            let p = point_state(model, length, node(q, e), node(q, e + 1), 0.5, h);
            [p.f[0], p.f[1], p.m]
        })
        .collect()
}

/// Distributed load of gravity and sliding inertia (6.7)–(6.8),
/// `L ∫ W·A_ρ(−g − L̈)E1`, scaled by `factor`: adds to `f` and `root`.
pub fn body_forces(
    model: &GeModel,
    kin: Kinematics,
    factor: f64,
    f: &mut [f64],
    root: &mut [f64; 3],
) {
    let per_half = factor
        * kin.length_m
        * model.section.mass_per_length_kg_m
        * (-model.gravity_m_s2 - kin.acceleration_m_s2)
        * 0.5;
    root[0] += per_half * model.ops.len(0);
    for e in 0..model.elements {
        let per_node = per_half * model.ops.len(e);
        for k in [e, e + 1] {
            if k > 0 {
                f[GeModel::dof(k, 0)] += per_node;
            }
        }
    }
}

/// An end load on the aerostat: force at the mass point (E1 up the
/// cable, E2 across) and a couple on the top section.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct TipLoad {
    pub force_n: [f64; 2],
    pub moment_n_m: f64,
}

/// The aerostat's generalised force on the top node and its derivatives.
#[derive(Clone, Copy, Debug, Default)]
pub struct TipTerms {
    /// Inertia minus applied load, `Jᵀ(m ẍ_a − P) − M e3`.
    pub residual: [f64; 3],
    pub mass: [[f64; 3]; 3],
    pub damping: [[f64; 3]; 3],
    pub stiffness: [[f64; 3]; 3],
}

/// The aerostat on its rigid link: `x_a = r0(1) + r_a t1(θ(1))`,
/// `ẍ_a = (L̈ + ü1 − r_a(θ̈ sθ + θ̇² cθ), ü2 + r_a(θ̈ cθ − θ̇² sθ))` (5.35)–(5.36).
pub fn tip_terms(
    model: &GeModel,
    kin: Kinematics,
    q: [f64; 3],
    v: [f64; 3],
    a: [f64; 3],
    load: TipLoad,
) -> TipTerms {
    let m = model.tip.mass_kg;
    let r = model.tip.link_length_m;
    let (sn, cs) = q[2].sin_cos();
    let (thd, thdd) = (v[2], a[2]);
    let acc1 = kin.acceleration_m_s2 + a[0] - r * (thdd * sn + thd * thd * cs);
    let acc2 = a[1] + r * (thdd * cs - thd * thd * sn);
    let a1 = m * acc1 - load.force_n[0];
    let a2 = m * acc2 - load.force_n[1];
    let residual = [a1, a2, r * (-sn * a1 + cs * a2) - load.moment_n_m];
    let mass = [
        [m, 0.0, -m * r * sn],
        [0.0, m, m * r * cs],
        [-m * r * sn, m * r * cs, m * r * r],
    ];
    let damping = [
        [0.0, 0.0, -2.0 * m * r * thd * cs],
        [0.0, 0.0, -2.0 * m * r * thd * sn],
        [0.0; 3],
    ];
    let da1 = -m * r * (thdd * cs - thd * thd * sn);
    let da2 = -m * r * (thdd * sn + thd * thd * cs);
    let dq3 = r * (-cs * a1 - sn * a2) - m * r * r * thd * thd;
    let stiffness = [[0.0, 0.0, da1], [0.0, 0.0, da2], [0.0, 0.0, dq3]];
    TipTerms {
        residual,
        mass,
        damping,
        stiffness,
    }
}

/// Position of the aerostat's mass point and its velocity.
pub fn tip_point(
    model: &GeModel,
    kin: Kinematics,
    q: [f64; 3],
    v: [f64; 3],
) -> ([f64; 2], [f64; 2]) {
    let r = model.tip.link_length_m;
    let (sn, cs) = q[2].sin_cos();
    let x = [kin.length_m + q[0] + r * cs, q[1] + r * sn];
    let xd = [kin.rate_m_s + v[0] - r * v[2] * sn, v[1] + r * v[2] * cs];
    (x, xd)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::ge::{Section, TipBody};

    #[test]
    fn convection_operator_is_the_corrected_thesis_form() {
        // 2P = ∫(1-ζ)(N N_ζᵀ − N_ζ Nᵀ) + ∫ N Nᵀ, assembled over the whole mesh.
        let n = 7;
        let ops = InertiaOperators::new(n);
        let h = ops.len(0);
        let mut worst: f64 = 0.0;
        // Assembled: wᵀ(2P)u == wᵀ(skew + R)u for all w, u.
        let nodes = n + 1;
        let mut two_p = vec![vec![0.0; nodes]; nodes];
        let mut rhs = vec![vec![0.0; nodes]; nodes];
        for e in 0..n {
            let za = e as f64 * h;
            for &(xi, wf) in &GAUSS2 {
                let z = za + xi * h;
                let nn = [1.0 - xi, xi];
                let dn = [-1.0 / h, 1.0 / h];
                for i in 0..2 {
                    for j in 0..2 {
                        two_p[e + i][e + j] += 2.0 * wf * h * (1.0 - z) * nn[i] * dn[j];
                        rhs[e + i][e + j] +=
                            wf * h * ((1.0 - z) * (nn[i] * dn[j] - dn[i] * nn[j]) + nn[i] * nn[j]);
                    }
                }
            }
        }
        // Equal except in the row of node 0 (boundary term W(0)(1-0)U_t(0)),
        // which is removed by the clamp.
        for i in 1..nodes {
            for j in 0..nodes {
                worst = worst.max((two_p[i][j] - rhs[i][j]).abs());
            }
        }
        assert!(worst < 1e-12, "{worst}");
        // and the operator stored per element is the same P
        let mut stored = vec![vec![0.0; nodes]; nodes];
        for e in 0..n {
            for i in 0..2 {
                for j in 0..2 {
                    stored[e + i][e + j] += 2.0 * ops.p[e][i][j];
                }
            }
        }
        for i in 0..nodes {
            for j in 0..nodes {
                assert!((stored[i][j] - two_p[i][j]).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn strain_energy_gradient_is_the_internal_force() {
        let s = Section::new(1e4, 5e3, 3.0, 1.0, 0.1).unwrap();
        let model = GeModel::new(s, 4, TipBody::default(), 0.0).unwrap();
        let q: Vec<f64> = (0..12).map(|i| 0.05 * ((i * 7 % 5) as f64 - 2.0)).collect();
        let mut f = vec![0.0; 12];
        internal_forces(&model, 2.0, &q, &mut f, None, None);
        for i in 0..12 {
            let d = 1e-6;
            let mut qp = q.clone();
            qp[i] += d;
            let mut qm = q.clone();
            qm[i] -= d;
            let g = (strain_energy(&model, 2.0, &qp) - strain_energy(&model, 2.0, &qm)) / (2.0 * d);
            assert!(
                (g - f[i]).abs() < 1e-5 * (1.0 + f[i].abs()),
                "{i}: {g} vs {}",
                f[i]
            );
        }
    }
}
