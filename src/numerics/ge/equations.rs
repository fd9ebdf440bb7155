//! The semi-discrete equations of the sliding GE beam under a drive
//! (thesis ch. 6.5): the length history, end loads, damping, base motion
//! and air load on the aerostat ([`Drive`]), a state `(q, q̇, q̈)`, the
//! residual
//!
//! ```text
//! R(q, q̇, q̈, t) = M q̈ + C q̇ + K q + F_int(q) − F_body + T_aerostat(q, q̇, q̈) = 0
//! ```
//!
//! and its system matrices, the consistent initial acceleration and the
//! static Newton solve. Below both the time stepping ([`super::solver`])
//! and the local stability ([`super::stability`]), which only linearise
//! these equations.

use super::GeModel;
use super::banded::Band;
use super::element::{self, TipLoad};
use crate::numerics::aero::Aerodynamics;
use crate::numerics::params::Kinematics;
use crate::numerics::profile::Profile;

/// Cable length against time.
#[derive(Clone, Debug, PartialEq)]
pub enum LengthHistory {
    Constant(f64),
    Profile(Profile),
}

impl LengthHistory {
    pub fn kinematics(&self, t_s: f64) -> Kinematics {
        match self {
            Self::Constant(l) => Kinematics {
                length_m: *l,
                rate_m_s: 0.0,
                acceleration_m_s2: 0.0,
            },
            Self::Profile(p) => p.kinematics(t_s),
        }
    }
}

/// Time shape of the varying part of an end load.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LoadShape {
    /// Always on.
    Constant,
    /// Rises linearly over `ramp_s`, held until `hold_s`, then removed.
    Held { ramp_s: f64, hold_s: f64 },
    /// Rises linearly to its peak at `peak_s`, back to zero at `end_s`.
    Triangle { peak_s: f64, end_s: f64 },
}

impl LoadShape {
    pub fn factor(&self, t: f64) -> f64 {
        match *self {
            Self::Constant => 1.0,
            Self::Held { ramp_s, hold_s } => {
                if t > hold_s {
                    0.0
                } else if ramp_s > 0.0 && t < ramp_s {
                    (t / ramp_s).max(0.0)
                } else {
                    1.0
                }
            }
            Self::Triangle { peak_s, end_s } => {
                if t <= 0.0 || t >= end_s {
                    0.0
                } else if t <= peak_s {
                    t / peak_s
                } else {
                    (end_s - t) / (end_s - peak_s)
                }
            }
        }
    }
}

/// End loads on the aerostat: a steady part (net buoyancy) and a varying one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EndLoads {
    pub steady: TipLoad,
    pub varying: TipLoad,
    pub shape: LoadShape,
}

impl EndLoads {
    pub fn steady(load: TipLoad) -> Self {
        Self {
            steady: load,
            varying: TipLoad::default(),
            shape: LoadShape::Constant,
        }
    }

    pub fn at(&self, t: f64) -> TipLoad {
        let k = self.shape.factor(t);
        TipLoad {
            force_n: [
                self.steady.force_n[0] + k * self.varying.force_n[0],
                self.steady.force_n[1] + k * self.varying.force_n[1],
            ],
            moment_n_m: self.steady.moment_n_m + k * self.varying.moment_n_m,
        }
    }
}

/// Linear viscous damping `μ` (1/s, per unit mass), on from `from_s`.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Damping {
    pub per_s: f64,
    pub from_s: f64,
}

impl Damping {
    pub fn at(&self, t: f64) -> f64 {
        if t >= self.from_s { self.per_s } else { 0.0 }
    }
}

/// Transverse motion of the deployment platform, `r(t) = R0 sin(ω0 t)`
/// along `E2` (thesis ch. 8.2). The equations are written in the
/// platform-fixed frame, so the motion enters as the inertial load
/// `−A_ρ r̈` per unit length on the cable's transverse equation (the
/// `−γ̃ l² r̈` of (8.2) in SI) and `−m r̈` on the aerostat; the unknowns
/// `u2` are measured from the moving platform.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct BaseMotion {
    pub amplitude_m: f64,
    pub circular_frequency_rad_s: f64,
}

impl BaseMotion {
    pub fn displacement_m(&self, t: f64) -> f64 {
        self.amplitude_m * (self.circular_frequency_rad_s * t).sin()
    }

    pub fn acceleration_m_s2(&self, t: f64) -> f64 {
        let w = self.circular_frequency_rad_s;
        -self.amplitude_m * w * w * (w * t).sin()
    }
}

/// What drives a run: length history, end loads, damping, platform
/// motion and air flow on the aerostat.
#[derive(Clone, Debug, PartialEq)]
pub struct Drive {
    pub length: LengthHistory,
    pub loads: EndLoads,
    pub damping: Damping,
    pub base: BaseMotion,
    /// Horizontal air flow on the aerostat (thesis ch. 7.5, [`crate::numerics::aero`]):
    /// evaluated at the top of the cable, elevation `L + u1(1)`, against its
    /// sideways velocity `u̇2(1)`; the added mass `½ m_f` moves with `ü2(1)`.
    /// (With a rigid link the flow still acts at the cable's top node.)
    pub aero: Option<Aerodynamics>,
}

/// The aerostat's air load at one iterate, along `E2` on the top node.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AeroTip {
    /// Force at the iterate's velocity (N).
    pub force_n: f64,
    /// `−∂F/∂u̇2` (N s/m).
    pub damping_n_s_m: f64,
    /// Added mass on `ü2` (kg).
    pub added_mass_kg: f64,
}

impl Drive {
    /// The air load at time `t` for the cable state `(q, v)`.
    pub fn aero_tip(&self, model: &GeModel, t: f64, q: &[f64], v: &[f64]) -> AeroTip {
        let Some(aero) = &self.aero else {
            return AeroTip::default();
        };
        let top = model.elements;
        let (qt, vt) = (element::node(q, top), element::node(v, top));
        let z = self.length.kinematics(t).length_m + qt[0];
        let l = aero.tip_load(z, t, vt[1]);
        AeroTip {
            force_n: l.force_n - l.damping_n_s_m * vt[1],
            damping_n_s_m: l.damping_n_s_m,
            added_mass_kg: aero.added_mass_kg(),
        }
    }

    /// The load on the aerostat at `t`: the end loads plus the inertial
    /// load `−m r̈` of the platform motion.
    pub fn tip_load(&self, model: &GeModel, t: f64) -> TipLoad {
        let mut load = self.loads.at(t);
        load.force_n[1] -= model.tip.mass_kg * self.base.acceleration_m_s2(t);
        load
    }
}

/// Newton–Raphson settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonConfig {
    /// Relative residual tolerance (against the largest force term).
    pub relative_tolerance: f64,
    /// Absolute residual tolerance (N).
    pub absolute_tolerance_n: f64,
    /// Iteration cap per step.
    pub max_iterations: usize,
}

impl Default for NewtonConfig {
    fn default() -> Self {
        Self {
            relative_tolerance: 1e-9,
            absolute_tolerance_n: 1e-10,
            max_iterations: 30,
        }
    }
}

/// Newton did not converge.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonFailure {
    pub time_s: f64,
    pub iterations: usize,
    pub residual_norm: f64,
}

/// Unknowns at one instant.
#[derive(Clone, Debug, PartialEq)]
pub struct State {
    pub time_s: f64,
    pub q: Vec<f64>,
    pub v: Vec<f64>,
    pub a: Vec<f64>,
}

impl State {
    pub fn at_rest(model: &GeModel, time_s: f64) -> Self {
        let n = model.dofs();
        Self {
            time_s,
            q: vec![0.0; n],
            v: vec![0.0; n],
            a: vec![0.0; n],
        }
    }
}

/// The linearisation about a state of a run: [`system_matrices`] with the
/// drive's loads at the state's time, plus the air load's damping and
/// added mass.
pub fn drive_matrices(model: &GeModel, drive: &Drive, state: &State) -> SystemMatrices {
    let t = state.time_s;
    let mut sys = system_matrices(
        model,
        drive.length.kinematics(t),
        drive.tip_load(model, t),
        drive.damping.at(t),
        &state.q,
        &state.v,
        &state.a,
    );
    let aero = drive.aero_tip(model, t, &state.q, &state.v);
    let y = GeModel::dof(model.elements, 1);
    sys.mass.add(y, y, aero.added_mass_kg);
    sys.damping.add(y, y, aero.damping_n_s_m);
    sys
}

/// `M`, `C`, `K` of the linearised equations about `(q, q̇, q̈)`:
/// `∂R/∂q̈`, `∂R/∂q̇`, `∂R/∂q`, aerostat included.
pub struct SystemMatrices {
    pub mass: Band,
    pub damping: Band,
    pub stiffness: Band,
}

/// Residual pieces at a state, and their sum.
pub struct Residual {
    pub total: Vec<f64>,
    /// Largest norm among the inertia, internal, body and aerostat terms.
    pub scale: f64,
}

pub(crate) fn norm(x: &[f64]) -> f64 {
    x.iter().map(|v| v * v).sum::<f64>().sqrt()
}

/// The residual `R(q, q̇, q̈)` at `kin` under `load` with damping `mu`.
pub fn residual(
    model: &GeModel,
    kin: Kinematics,
    load: TipLoad,
    mu: f64,
    q: &[f64],
    v: &[f64],
    a: &[f64],
) -> Residual {
    let lin = element::linear_operators(model, kin, mu);
    residual_with(model, &lin, kin, load, 0.0, AeroTip::default(), q, v, a)
}

/// The residual with the platform acceleration `base_m_s2` (the cable's
/// share `A_ρ L ∫ N r̈` on the transverse rows; the aerostat's is in `load`)
/// and the air load `aero` on the top node.
#[allow(clippy::too_many_arguments)]
pub(crate) fn residual_with(
    model: &GeModel,
    lin: &element::LinearOperators,
    kin: Kinematics,
    load: TipLoad,
    base_m_s2: f64,
    aero: AeroTip,
    q: &[f64],
    v: &[f64],
    a: &[f64],
) -> Residual {
    let n = model.dofs();
    let mut inertia = vec![0.0; n];
    lin.mass.mul_add(a, &mut inertia);
    lin.damping.mul_add(v, &mut inertia);
    lin.stiffness.mul_add(q, &mut inertia);
    let mut internal = vec![0.0; n];
    element::internal_forces(model, kin.length_m, q, &mut internal, None, None);
    let mut body = vec![0.0; n];
    element::body_forces(model, kin, 1.0, &mut body, &mut [0.0; 3]);
    if base_m_s2 != 0.0 {
        let per_length = -model.section.mass_per_length_kg_m * kin.length_m * base_m_s2;
        for k in 1..=model.elements {
            // the node's share of its elements: h on a uniform mesh
            // (the top node: h/2)
            let share = if k == model.elements {
                0.5 * model.ops.len(k - 1)
            } else {
                0.5 * (model.ops.len(k - 1) + model.ops.len(k))
            };
            body[GeModel::dof(k, 1)] += per_length * share;
        }
    }
    let top = model.elements;
    let tip = element::tip_terms(
        model,
        kin,
        element::node(q, top),
        element::node(v, top),
        element::node(a, top),
        load,
    );
    let mut total: Vec<f64> = (0..n).map(|i| inertia[i] + internal[i] - body[i]).collect();
    for c in 0..3 {
        total[GeModel::dof(top, c)] += tip.residual[c];
    }
    let air = aero.added_mass_kg * a[GeModel::dof(top, 1)] - aero.force_n;
    total[GeModel::dof(top, 1)] += air;
    let scale = norm(&inertia)
        .max(norm(&internal))
        .max(norm(&body))
        .max(norm(&tip.residual))
        .max(air.abs());
    Residual { total, scale }
}

/// The linearisation about a state (for Newton and the local QEP).
pub fn system_matrices(
    model: &GeModel,
    kin: Kinematics,
    load: TipLoad,
    mu: f64,
    q: &[f64],
    v: &[f64],
    a: &[f64],
) -> SystemMatrices {
    let lin = element::linear_operators(model, kin, mu);
    system_matrices_with(model, lin, kin, load, q, v, a)
}

pub(crate) fn system_matrices_with(
    model: &GeModel,
    lin: element::LinearOperators,
    kin: Kinematics,
    load: TipLoad,
    q: &[f64],
    v: &[f64],
    a: &[f64],
) -> SystemMatrices {
    let element::LinearOperators {
        mut mass,
        mut damping,
        mut stiffness,
    } = lin;
    let mut scratch = vec![0.0; model.dofs()];
    element::internal_forces(
        model,
        kin.length_m,
        q,
        &mut scratch,
        Some(&mut stiffness),
        None,
    );
    let top = model.elements;
    let tip = element::tip_terms(
        model,
        kin,
        element::node(q, top),
        element::node(v, top),
        element::node(a, top),
        load,
    );
    for i in 0..3 {
        for j in 0..3 {
            let (r, c) = (GeModel::dof(top, i), GeModel::dof(top, j));
            mass.add(r, c, tip.mass[i][j]);
            damping.add(r, c, tip.damping[i][j]);
            stiffness.add(r, c, tip.stiffness[i][j]);
        }
    }
    SystemMatrices {
        mass,
        damping,
        stiffness,
    }
}

/// Consistent initial acceleration: solves `M q̈ = −R(q, q̇, 0)`.
pub fn initial_acceleration(
    model: &GeModel,
    drive: &Drive,
    time_s: f64,
    q: &[f64],
    v: &[f64],
) -> Option<Vec<f64>> {
    let kin = drive.length.kinematics(time_s);
    let load = drive.tip_load(model, time_s);
    let mu = drive.damping.at(time_s);
    let zero = vec![0.0; model.dofs()];
    let lin = element::linear_operators(model, kin, mu);
    let aero = drive.aero_tip(model, time_s, q, v);
    let r = residual_with(
        model,
        &lin,
        kin,
        load,
        drive.base.acceleration_m_s2(time_s),
        aero,
        q,
        v,
        &zero,
    );
    let mut m = system_matrices(model, kin, load, mu, q, v, &zero).mass;
    let top = GeModel::dof(model.elements, 1);
    m.add(top, top, aero.added_mass_kg);
    let lu = m.factor()?;
    let mut a: Vec<f64> = r.total.iter().map(|x| -x).collect();
    lu.solve_in_place(&mut a);
    Some(a)
}

/// Static equilibrium at `kin` under `load` and gravity, applied in
/// `load_steps` equal increments, each solved by Newton from the last.
pub fn static_solve(
    model: &GeModel,
    kin: Kinematics,
    load: TipLoad,
    load_steps: usize,
    newton: NewtonConfig,
) -> Result<Vec<f64>, NewtonFailure> {
    let n = model.dofs();
    let mut q = vec![0.0; n];
    let zero = vec![0.0; n];
    let steps = load_steps.max(1);
    let mut scaled_model = model.clone();
    for k in 1..=steps {
        let lam = k as f64 / steps as f64;
        scaled_model.gravity_m_s2 = model.gravity_m_s2 * lam;
        let l = TipLoad {
            force_n: [lam * load.force_n[0], lam * load.force_n[1]],
            moment_n_m: lam * load.moment_n_m,
        };
        let mut iterations = 0;
        loop {
            let r = residual(&scaled_model, kin, l, 0.0, &q, &zero, &zero);
            let rn = norm(&r.total);
            if rn <= newton.absolute_tolerance_n + newton.relative_tolerance * r.scale {
                break;
            }
            if iterations >= newton.max_iterations || !rn.is_finite() {
                return Err(NewtonFailure {
                    time_s: 0.0,
                    iterations,
                    residual_norm: rn,
                });
            }
            let s = system_matrices(&scaled_model, kin, l, 0.0, &q, &zero, &zero).stiffness;
            let dq = newton_correction(s, &r.total, &mut q).ok_or(NewtonFailure {
                time_s: 0.0,
                iterations,
                residual_norm: rn,
            })?;
            iterations += 1;
            if at_roundoff(&dq, &q, kin.length_m) {
                break;
            }
        }
    }
    Ok(q)
}

/// The Newton correction is at the roundoff level of the unknowns: the
/// residual cannot be reduced further (stiff cables: `EA·ε` per element).
/// One Newton update: solves `tangent · Δq = −residual`, adds `Δq` to `q`
/// and returns it; `None` when the tangent is singular.
pub(crate) fn newton_correction(
    tangent: Band,
    residual: &[f64],
    q: &mut [f64],
) -> Option<Vec<f64>> {
    let lu = tangent.factor()?;
    let mut dq: Vec<f64> = residual.iter().map(|x| -x).collect();
    lu.solve_in_place(&mut dq);
    for (qi, di) in q.iter_mut().zip(&dq) {
        *qi += di;
    }
    Some(dq)
}

pub(crate) fn at_roundoff(dq: &[f64], q: &[f64], length: f64) -> bool {
    let big = q.iter().fold(length, |m, x| m.max(x.abs()));
    dq.iter().all(|d| d.abs() <= 1e-13 * big)
}
