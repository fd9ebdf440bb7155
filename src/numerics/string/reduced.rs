//! One-mode reduced-order model of the lengthening/shortening string and its
//! WKB asymptotics (SPEC §2, thesis ch. 3, (3.1)–(3.16)).
//!
//! The deflection is taken as `η(ζ, t̄) = W(ζ) q(t̄)` with `W = sin(πζ/2)`
//! and the weak form of (2.15)–(2.17) is projected on `W` with the same
//! integrands (and the same element quadrature) as the finite-element
//! operators, giving one equation `m q̈ + c q̇ + k q = 0` with
//!
//! ```text
//! m = ½(2m̃ + l)          c = ½ l̇
//! k = ½{½ l̈ + π²/(4l) − (π²/4) m̃ l̈/l − (½ + π²/12) l̇²/l − (π²/8 + ½)(1/F̃ + l̈)}
//! ```
//!
//! which is (3.2) with the `1/l` of the `l̇²` term restored (it is printed in
//! (3.3)). For slow deployment the WKB solution has the frequency
//! `ψ = √[(α/l + γ)/(2m̃ + l)]`, `α = π²/4`, `γ = −(π²/8 + ½)/F̃`, the
//! amplitude `A0 ∝ [ψ (2m̃ + l)]^{-1/2}` (3.12) and the mode energy
//! `Ẽ = ¼(α/l + γ) A0²` (3.16).

use std::f64::consts::PI;

use crate::numerics::mesh::UniformMesh;
use crate::numerics::newmark::{Newmark, NewmarkParameters, NewmarkState, StepError};
use crate::numerics::params::{AerostatSystem, NondimState};
use crate::numerics::profile::Profile;
use crate::numerics::string::operators::MatrixCoefficients;
use crate::numerics::tridiag::Tridiagonal;

/// The assumed mode `W(ζ) = sin(πζ/2)`.
pub fn assumed_mode(zeta: f64) -> f64 {
    (0.5 * PI * zeta).sin()
}

fn assumed_mode_slope(zeta: f64) -> f64 {
    0.5 * PI * (0.5 * PI * zeta).cos()
}

/// The five operators of the finite-element model projected on `W`
/// (scalars), and `W(1)²` for the tip mass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReducedOperators {
    /// `∫ W²` (exact: 1/2).
    pub mass: f64,
    /// `∫ (1−ζ) W W'` (exact: 1/4).
    pub conv: f64,
    /// `∫ W'²` (exact: π²/8).
    pub stiff_0: f64,
    /// `∫ (1−ζ) W'²` (exact: π²/16 + 1/4).
    pub stiff_1: f64,
    /// `∫ (1−ζ)² W'²` (exact: π²/24 + 1/4).
    pub stiff_2: f64,
    /// `W(1)²` (= 1).
    pub tip: f64,
}

impl ReducedOperators {
    /// Projects with the 3-point Gauss rule on `elements` uniform elements
    /// (the rule the finite-element operators use).
    pub fn project(elements: usize) -> Self {
        let mesh = UniformMesh::new(elements.max(1));
        let mut r = Self {
            mass: 0.0,
            conv: 0.0,
            stiff_0: 0.0,
            stiff_1: 0.0,
            stiff_2: 0.0,
            tip: assumed_mode(1.0).powi(2),
        };
        for e in 0..mesh.elements {
            for q in mesh.element_quadrature(e, 3) {
                let (w, dw, s) = (
                    assumed_mode(q.zeta),
                    assumed_mode_slope(q.zeta),
                    1.0 - q.zeta,
                );
                r.mass += q.weight * w * w;
                r.conv += q.weight * s * w * dw;
                r.stiff_0 += q.weight * dw * dw;
                r.stiff_1 += q.weight * s * dw * dw;
                r.stiff_2 += q.weight * s * s * dw * dw;
            }
        }
        r
    }

    /// The closed-form integrals.
    pub fn exact() -> Self {
        let p2 = PI * PI;
        Self {
            mass: 0.5,
            conv: 0.25,
            stiff_0: p2 / 8.0,
            stiff_1: p2 / 16.0 + 0.25,
            stiff_2: p2 / 24.0 + 0.25,
            tip: 1.0,
        }
    }

    /// `(m, c, k)` at a state, from the same coefficients as the FE matrices.
    pub fn assemble(&self, c: &MatrixCoefficients) -> (f64, f64, f64) {
        let m = c.mass_scale * self.mass + c.tip_mass * self.tip;
        let d = c.damping_scale * self.conv;
        let k = c.conv_stiffness * self.conv - c.quad_stiffness * self.stiff_2
            + c.tension_top * self.stiff_0
            + c.tension_slope * self.stiff_1;
        (m, d, k)
    }
}

/// The printed single-mode equation (3.2), `1/l` restored on `l̇²`:
/// `(m, c, k)`.
pub fn thesis_equation(s: NondimState, mass_ratio: f64, buoyancy_ratio: f64) -> (f64, f64, f64) {
    let (l, v, a, mt) = (s.length, s.rate, s.acceleration, mass_ratio);
    let p2 = PI * PI;
    let m = 0.5 * (2.0 * mt + l);
    let c = 0.5 * v;
    let k = 0.5
        * (0.5 * a + p2 / (4.0 * l)
            - p2 / 4.0 * mt * a / l
            - (0.5 + p2 / 12.0) * v * v / l
            - (p2 / 8.0 + 0.5) * (1.0 / buoyancy_ratio + a));
    (m, c, k)
}

/// The reduced model of one system.
#[derive(Clone, Copy, Debug)]
pub struct ReducedModel {
    pub system: AerostatSystem,
    pub operators: ReducedOperators,
}

impl ReducedModel {
    /// Projection with 200 elements (integrals to ~1e-11).
    pub fn new(system: AerostatSystem) -> Self {
        Self {
            system,
            operators: ReducedOperators::project(200),
        }
    }

    pub fn coefficients(&self, s: NondimState) -> MatrixCoefficients {
        crate::numerics::string::state_coefficients(&self.system, s)
    }

    /// `(m, c, k)` of the projected equation at a state.
    pub fn equation(&self, s: NondimState) -> (f64, f64, f64) {
        self.operators.assemble(&self.coefficients(s))
    }

    /// `α/l + γ` (twice the static stiffness).
    fn static_stiffness(&self, l: f64) -> f64 {
        PI * PI / 4.0 / l - (PI * PI / 8.0 + 0.5) / self.system.buoyancy_ratio()
    }

    /// `ψ(l)` (1/t̄): the WKB frequency; `None` when `α/l + γ ≤ 0`.
    pub fn frequency(&self, l: f64) -> Option<f64> {
        let k = self.static_stiffness(l);
        (k > 0.0).then(|| (k / (2.0 * self.system.mass_ratio() + l)).sqrt())
    }

    /// WKB amplitude at length `l`, scaled to `amplitude_0` at `l0` (3.12).
    pub fn wkb_amplitude(&self, l: f64, l0: f64, amplitude_0: f64) -> Option<f64> {
        let mt2 = 2.0 * self.system.mass_ratio();
        let (psi, psi0) = (self.frequency(l)?, self.frequency(l0)?);
        Some(amplitude_0 * ((psi0 * (mt2 + l0)) / (psi * (mt2 + l))).sqrt())
    }

    /// Leading-order mode energy `¼(α/l + γ) A²` (3.16), units of `F L0`.
    pub fn mode_energy(&self, l: f64, amplitude: f64) -> f64 {
        0.25 * self.static_stiffness(l) * amplitude * amplitude
    }

    /// Integrates `m q̈ + c q̇ + k q = 0` (average acceleration) along the
    /// profile from `q(0) = q0`, `q̇(0) = 0`; returns `q` after each of
    /// `steps` steps of `dt_s` (SI time), non-dimensional `q`.
    pub fn simulate(
        &self,
        profile: &Profile,
        q0: f64,
        dt_s: f64,
        steps: usize,
    ) -> Result<Vec<f64>, StepError> {
        let ts = self.system.time_scale_s();
        let dt = dt_s / ts;
        let one = |v: f64| Tridiagonal {
            lower: vec![],
            diag: vec![v],
            upper: vec![],
        };
        let at = |t_s: f64| {
            let (m, c, k) = self.equation(self.system.to_nondim(profile.kinematics(t_s)));
            (one(m), one(c), one(k))
        };
        let mut state = NewmarkState {
            time: 0.0,
            displacement: vec![q0],
            velocity: vec![0.0],
            acceleration: vec![0.0],
        };
        let mut nm = Newmark::new(1, NewmarkParameters::AVERAGE_ACCELERATION);
        let (m, c, k) = at(0.0);
        nm.initialise(&m, &c, &k, &[0.0], &mut state)?;
        let mut out = Vec::with_capacity(steps);
        for j in 1..=steps {
            let (m, c, k) = at(j as f64 * dt_s);
            nm.step(dt, &m, &c, &k, &[0.0], &mut state)?;
            out.push(state.displacement[0]);
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projection_matches_the_closed_form_integrals() {
        let p = ReducedOperators::project(200);
        let e = ReducedOperators::exact();
        for (a, b) in [
            (p.mass, e.mass),
            (p.conv, e.conv),
            (p.stiff_0, e.stiff_0),
            (p.stiff_1, e.stiff_1),
            (p.stiff_2, e.stiff_2),
            (p.tip, e.tip),
        ] {
            assert!((a - b).abs() < 1e-10, "{a} vs {b}");
        }
    }

    #[test]
    fn projected_equation_is_thesis_3_2() {
        let model = ReducedModel::new(AerostatSystem::thesis());
        for s in [
            NondimState {
                length: 1.0,
                rate: 0.0,
                acceleration: 0.0,
            },
            NondimState {
                length: 3.5,
                rate: 0.05,
                acceleration: 1e-4,
            },
            NondimState {
                length: 250.0,
                rate: -0.2,
                acceleration: -3e-3,
            },
        ] {
            let (m, c, k) = model.equation(s);
            let (m2, c2, k2) =
                thesis_equation(s, model.system.mass_ratio(), model.system.buoyancy_ratio());
            assert!((m - m2).abs() < 1e-9 * m2.abs().max(1.0));
            assert!((c - c2).abs() < 1e-10);
            assert!((k - k2).abs() < 1e-9 * k2.abs().max(1e-3), "{k} vs {k2}");
        }
    }
}
