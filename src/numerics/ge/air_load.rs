//! Steady-wind loads on the GE cable and its aerostat, and their
//! linearisation (issue 12 item 4; SPEC §6 loads on the GE model of §3).
//!
//! The guide axis `E1` is vertical (gravity along `−E1`), `E2` horizontal;
//! the wind `U(z)` blows along `+E2` at the elevation `z = ζL + u1` of a
//! point of the cable. The loads are those of the static tether of
//! [`crate::numerics::tether::equilibrium`]:
//!
//! * **tether normal drag**, per unstretched length,
//!   `f = (1 + ε) ½ρ C_n d |w_n| w_n`, `w_n = w − (w·t) t`, `t` the unit
//!   tangent of the centreline and `1 + ε = |r_X|` its stretch. With
//!   `a = r0_ζ = (L + u1_ζ, u2_ζ)`, `ℓ = |a|`, the relative wind `w` and
//!   `κ = a1 w2 − a2 w1` this is, exactly,
//!
//!   ```text
//!   f = (c/L) (|κ| κ / ℓ²) (−a2, a1),        c = ½ρ C_n d,
//!   ```
//!
//!   lumped as `L ∫ N f dζ` with two Gauss points per element;
//! * **aerostat drag and lift** on the top node: `(½ρ C_L A w², ½ρ C_D A |w| w)`
//!   along `(E1, E2)`, `w = U(z_top) − u̇2(top)` (the horizontal relative
//!   wind; the net buoyancy is the tip load of the caller).
//!
//! The relative wind is `w = (0, U(z)) − u̇` with `u̇` the mapped-frame
//! velocity: in the quasi-static state (`u̇ = 0`) the payout moves material
//! along the tether, which adds no normal drag. The linearisation about a
//! state gives the stiffness `−∂F/∂q` (the tangent's turning, the stretch
//! and the wind shear `U'(z)`) and the aerodynamic damping `−∂F/∂u̇`, which
//! enter `K` and `C` of the local QEP. In calm air every term vanishes.

use super::GeModel;
use super::banded::Band;
use super::element::node;
use crate::numerics::tether::wind::WindProfile;

/// Gauss points on the unit element as (fraction along, weight fraction).
const GAUSS2: [(f64, f64); 2] = [
    (0.5 - 0.288_675_134_594_812_9, 0.5),
    (0.5 + 0.288_675_134_594_812_9, 0.5),
];

/// Step of the central difference of `U(z)` for the shear (m).
const SHEAR_STEP_M: f64 = 1e-3;

/// The air and the aerodynamic properties of cable and aerostat.
#[derive(Clone, Debug, PartialEq)]
pub struct AirLoads {
    pub wind: WindProfile,
    pub air_density_kg_m3: f64,
    /// Tether diameter `d` (m).
    pub cable_diameter_m: f64,
    /// Tether normal drag coefficient `C_n`.
    pub cable_normal_drag_coefficient: f64,
    /// Aerostat `C_D A` (m²).
    pub aerostat_drag_area_m2: f64,
    /// Aerostat `C_L A` (m²).
    pub aerostat_lift_area_m2: f64,
}

/// Load vector and its derivatives (on the unknowns).
pub struct AirTerms {
    /// Generalised air force on the unknowns (N).
    pub force: Vec<f64>,
    /// `−∂F/∂q` (add to the stiffness).
    pub stiffness: Band,
    /// `−∂F/∂u̇` (add to the damping).
    pub damping: Band,
}

impl AirLoads {
    /// No air load at all.
    pub fn calm() -> Self {
        Self {
            wind: WindProfile::calm(),
            air_density_kg_m3: 0.0,
            cable_diameter_m: 0.0,
            cable_normal_drag_coefficient: 0.0,
            aerostat_drag_area_m2: 0.0,
            aerostat_lift_area_m2: 0.0,
        }
    }

    /// Whether every load is identically zero (no wind anywhere).
    pub fn is_calm(&self) -> bool {
        self.air_density_kg_m3 == 0.0
            || matches!(self.wind, WindProfile::Flow(crate::numerics::aero::SteadyFlow::Uniform { speed_m_s }) if speed_m_s == 0.0)
    }

    /// The same air with the dynamic pressure scaled by `factor` (continuation).
    pub fn scaled(&self, factor: f64) -> Self {
        Self {
            air_density_kg_m3: self.air_density_kg_m3 * factor,
            ..self.clone()
        }
    }

    /// `(U, U')` at elevation `z` (central difference for the shear).
    fn wind_and_shear(&self, z: f64) -> (f64, f64) {
        let u = self.wind.speed_m_s(z);
        if self.wind.is_uniform() {
            return (u, 0.0);
        }
        let d = SHEAR_STEP_M;
        let lo = (z - d).max(0.0);
        let hi = z + d;
        (
            u,
            (self.wind.speed_m_s(hi) - self.wind.speed_m_s(lo)) / (hi - lo),
        )
    }

    /// The air force at length `length_m` for the state `(q, u̇)`, and, if
    /// `linearise`, its stiffness and damping.
    pub fn terms(
        &self,
        model: &GeModel,
        length_m: f64,
        q: &[f64],
        v: &[f64],
        linearise: bool,
    ) -> AirTerms {
        self.terms_with(model, length_m, q, v, linearise, linearise)
    }

    /// [`AirLoads::terms`] with the stiffness but no damping (an empty
    /// band): what a Newton on the equilibrium needs. The force and the
    /// stiffness are those of `terms(…, true)` bit for bit.
    pub fn terms_without_damping(
        &self,
        model: &GeModel,
        length_m: f64,
        q: &[f64],
        v: &[f64],
    ) -> AirTerms {
        self.terms_with(model, length_m, q, v, true, false)
    }

    fn terms_with(
        &self,
        model: &GeModel,
        length_m: f64,
        q: &[f64],
        v: &[f64],
        linearise: bool,
        with_damping: bool,
    ) -> AirTerms {
        let n = model.dofs();
        let hb = super::element::HALF_BAND;
        let with_damping = linearise && with_damping;
        let mut out = AirTerms {
            force: vec![0.0; n],
            stiffness: Band::zeros(if linearise { n } else { 0 }, hb, hb),
            damping: Band::zeros(if with_damping { n } else { 0 }, hb, hb),
        };
        if self.is_calm() {
            return out;
        }
        let l = length_m;
        let c = 0.5
            * self.air_density_kg_m3
            * self.cable_normal_drag_coefficient
            * self.cable_diameter_m;
        if c > 0.0 {
            for e in 0..model.elements {
                let h = model.ops.len(e);
                let dn = [-1.0 / h, 1.0 / h];
                let (qa, qb) = (node(q, e), node(q, e + 1));
                let (va, vb) = (node(v, e), node(v, e + 1));
                // element force (u1, u2 of both nodes) and derivatives
                let mut fe = [[0.0; 2]; 2];
                let mut kq = [[[[0.0; 2]; 2]; 2]; 2]; // [a][j][b][i]: ∂F_aj/∂q_bi
                let mut kv = [[[[0.0; 2]; 2]; 2]; 2];
                for &(xi, wf) in &GAUSS2 {
                    let wgt = wf * h * l;
                    let nn = [1.0 - xi, xi];
                    let zeta = model.ops.point(e, xi);
                    let a = [
                        l + dn[0] * qa[0] + dn[1] * qb[0],
                        dn[0] * qa[1] + dn[1] * qb[1],
                    ];
                    let z = zeta * l + nn[0] * qa[0] + nn[1] * qb[0];
                    let vel = [nn[0] * va[0] + nn[1] * vb[0], nn[0] * va[1] + nn[1] * vb[1]];
                    let (u, du) = self.wind_and_shear(z);
                    let w = [-vel[0], u - vel[1]];
                    let l2 = a[0] * a[0] + a[1] * a[1];
                    if l2 <= 0.0 {
                        continue;
                    }
                    let kappa = a[0] * w[1] - a[1] * w[0];
                    let phi = kappa.abs() * kappa / l2;
                    let m = [-a[1], a[0]];
                    let s = c / l;
                    let f = [s * phi * m[0], s * phi * m[1]];
                    for ia in 0..2 {
                        for j in 0..2 {
                            fe[ia][j] += wgt * nn[ia] * f[j];
                        }
                    }
                    if !linearise {
                        continue;
                    }
                    let dphi_dk = 2.0 * kappa.abs() / l2;
                    let dphi_dl = [-2.0 * phi * a[0] / l2, -2.0 * phi * a[1] / l2];
                    let dk_da = [w[1], -w[0]];
                    let dk_dw = [-a[1], a[0]];
                    let dm_da = [[0.0, 1.0], [-1.0, 0.0]]; // ∂m/∂a_i
                    // ∂f_j/∂a_i, ∂f_j/∂w_i
                    let mut df_da = [[0.0; 2]; 2];
                    let mut df_dw = [[0.0; 2]; 2];
                    for j in 0..2 {
                        for i in 0..2 {
                            df_da[j][i] =
                                s * ((dphi_dk * dk_da[i] + dphi_dl[i]) * m[j] + phi * dm_da[i][j]);
                            df_dw[j][i] = s * dphi_dk * dk_dw[i] * m[j];
                        }
                    }
                    for ia in 0..2 {
                        for j in 0..2 {
                            for ib in 0..2 {
                                for i in 0..2 {
                                    // a_i = … + dN_b u_i^b; z = … + N_b u_1^b; w = (0,U(z)) − N_b v^b
                                    let mut dq = df_da[j][i] * dn[ib];
                                    if i == 0 {
                                        dq += df_dw[j][1] * du * nn[ib];
                                    }
                                    kq[ia][j][ib][i] += wgt * nn[ia] * dq;
                                    kv[ia][j][ib][i] -= wgt * nn[ia] * df_dw[j][i] * nn[ib];
                                }
                            }
                        }
                    }
                }
                for ia in 0..2 {
                    let ka = e + ia;
                    if ka == 0 {
                        continue;
                    }
                    for j in 0..2 {
                        out.force[GeModel::dof(ka, j)] += fe[ia][j];
                        if !linearise {
                            continue;
                        }
                        for ib in 0..2 {
                            let kb = e + ib;
                            if kb == 0 {
                                continue;
                            }
                            for i in 0..2 {
                                let (r, col) = (GeModel::dof(ka, j), GeModel::dof(kb, i));
                                out.stiffness.add(r, col, -kq[ia][j][ib][i]);
                                if with_damping {
                                    out.damping.add(r, col, -kv[ia][j][ib][i]);
                                }
                            }
                        }
                    }
                }
            }
        }
        // the aerostat, on the top node
        let top = model.elements;
        let (qt, vt) = (node(q, top), node(v, top));
        let (u, du) = self.wind_and_shear(l + qt[0]);
        let w = u - vt[1];
        let half_rho = 0.5 * self.air_density_kg_m3;
        let lift = half_rho * self.aerostat_lift_area_m2 * w * w;
        let drag = half_rho * self.aerostat_drag_area_m2 * w.abs() * w;
        let (i1, i2) = (GeModel::dof(top, 0), GeModel::dof(top, 1));
        out.force[i1] += lift;
        out.force[i2] += drag;
        if linearise {
            // ∂/∂w of (lift, drag)
            let dw = [
                2.0 * half_rho * self.aerostat_lift_area_m2 * w,
                2.0 * half_rho * self.aerostat_drag_area_m2 * w.abs(),
            ];
            for (j, row) in [i1, i2].into_iter().enumerate() {
                out.stiffness.add(row, i1, -dw[j] * du); // w depends on z_top = L + u1
                if with_damping {
                    out.damping.add(row, i2, dw[j]); // w = U − u̇2
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::ge::{Section, TipBody};

    fn air(shear: bool) -> AirLoads {
        AirLoads {
            wind: if shear {
                WindProfile::log_law(9.0, 10.0, 0.05, "wind").unwrap()
            } else {
                WindProfile::uniform(9.0)
            },
            air_density_kg_m3: 1.2,
            cable_diameter_m: 0.01,
            cable_normal_drag_coefficient: 1.2,
            aerostat_drag_area_m2: 6.0,
            aerostat_lift_area_m2: 1.5,
        }
    }

    /// The stiffness and damping are the derivatives of the force
    /// (central differences, relative error 1e-6).
    #[test]
    fn linearisation_matches_finite_differences() {
        let s = Section::new(1e6, 1e6, 10.0, 0.05, 0.01).unwrap();
        let model = GeModel::new(s, 5, TipBody::default(), 9.81).unwrap();
        let n = model.dofs();
        let q: Vec<f64> = (0..n)
            .map(|i| 3.0 * ((i * 7 % 5) as f64 - 2.0) / 5.0 + 0.5 * i as f64)
            .collect();
        let v: Vec<f64> = (0..n).map(|i| 0.3 * ((i * 3 % 4) as f64 - 1.5)).collect();
        for shear in [false, true] {
            let a = air(shear);
            let t = a.terms(&model, 200.0, &q, &v, true);
            let scale = t.force.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            for col in 0..n {
                for (which, step) in [(0, 1e-5), (1, 1e-6)] {
                    let (mut xp, mut xm) = if which == 0 {
                        (q.clone(), q.clone())
                    } else {
                        (v.clone(), v.clone())
                    };
                    xp[col] += step;
                    xm[col] -= step;
                    let (fp, fm) = if which == 0 {
                        (
                            a.terms(&model, 200.0, &xp, &v, false).force,
                            a.terms(&model, 200.0, &xm, &v, false).force,
                        )
                    } else {
                        (
                            a.terms(&model, 200.0, &q, &xp, false).force,
                            a.terms(&model, 200.0, &q, &xm, false).force,
                        )
                    };
                    for row in 0..n {
                        let fd = -(fp[row] - fm[row]) / (2.0 * step);
                        let an = if which == 0 {
                            t.stiffness.get(row, col)
                        } else {
                            t.damping.get(row, col)
                        };
                        assert!(
                            (fd - an).abs() <= 1e-6 * scale.max(1.0),
                            "shear {shear} {which} ({row},{col}): fd {fd} analytic {an}"
                        );
                    }
                }
            }
        }
    }
}
