//! Time integration: Newmark average acceleration (β = 1/4, γ = 1/2) by
//! default, or the dissipative generalized-α / HHT-α members of the same
//! family ([`Scheme`]), with Newton–Raphson on the residual of the
//! semi-discrete equations
//!
//! ```text
//! R(q, q̇, q̈, t) = M q̈ + C q̇ + K q + F_int(q) − F_body + T_aerostat(q, q̇, q̈) = 0
//! ```
//!
//! (thesis ch. 6.5, Fig. 6.1). The length `L(t)` comes from a deployment
//! profile; end loads may be held, ramped or pulsed; linear damping may be
//! switched on at a time. Newton stops when `‖R‖ ≤ atol + rtol·s`, with `s`
//! the largest of the norms of the inertia, internal, body and aerostat
//! terms, or when the Newton correction reaches the roundoff level of the
//! unknowns; failure to converge is a [`NewtonFailure`], not a panic.

use super::GeModel;
use super::banded::Band;
use super::diagnostics::{self, Energy};
use super::element::{self, HALF_BAND, TipLoad};
use super::stability;
use crate::numerics::aero::Aerodynamics;
use crate::numerics::params::Kinematics;
use crate::numerics::profile::Profile;
use crate::numerics::qep::Spectrum;

/// Largest number of time steps a run may take.
pub const MAX_STEPS: usize = 2_000_000;

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

fn norm(x: &[f64]) -> f64 {
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
fn residual_with(
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

fn system_matrices_with(
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
fn newton_correction(tangent: Band, residual: &[f64], q: &mut [f64]) -> Option<Vec<f64>> {
    let lu = tangent.factor()?;
    let mut dq: Vec<f64> = residual.iter().map(|x| -x).collect();
    lu.solve_in_place(&mut dq);
    for (qi, di) in q.iter_mut().zip(&dq) {
        *qi += di;
    }
    Some(dq)
}

fn at_roundoff(dq: &[f64], q: &[f64], length: f64) -> bool {
    let big = q.iter().fold(length, |m, x| m.max(x.abs()));
    dq.iter().all(|d| d.abs() <= 1e-13 * big)
}

/// Newmark parameters of the average-acceleration rule (the default).
pub const BETA: f64 = 0.25;
pub const GAMMA: f64 = 0.5;

/// The time-stepping scheme of the Newton–Newmark march.
///
/// Every scheme here is a member of the Chung–Hulbert generalized-α family
/// (J. Chung, G. M. Hulbert, J. Appl. Mech. 60 (1993) 371–375): the
/// residual is balanced at the intermediate instant `t_{n+1−α_f}`,
///
/// ```text
/// R(q_{n+1−α_f}, q̇_{n+1−α_f}, q̈_{n+1−α_m}, t_{n+1−α_f}) = 0,
/// x_{n+1−α} = (1 − α) x_{n+1} + α x_n,
/// q_{n+1} = q_n + Δt q̇_n + Δt² ((½ − β) q̈_n + β q̈_{n+1}),
/// q̇_{n+1} = q̇_n + Δt ((1 − γ) q̈_n + γ q̈_{n+1}).
/// ```
///
/// All are second-order accurate and unconditionally stable on linear
/// problems; they differ in the spectral radius `ρ∞` of the amplification
/// matrix as `ωΔt → ∞`: the fraction of an unresolved mode's amplitude
/// that survives one step. `ρ∞ = 1` dissipates nothing (trapezoidal);
/// `ρ∞ = 0` annihilates unresolved modes in one step. At low frequency
/// the dissipation is of third order in `ωΔt`, so resolved modes keep
/// their amplitude to second order (tested in `tests/verification_ge_integrators.rs`).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum Scheme {
    /// Newmark average acceleration (β = ¼, γ = ½, α_m = α_f = 0): energy
    /// conserving on linear problems, no dissipation (`ρ∞ = 1`).
    #[default]
    AverageAcceleration,
    /// Chung–Hulbert generalized-α with spectral radius `rho_infinity ∈ [0, 1]`:
    /// `α_m = (2ρ∞ − 1)/(ρ∞ + 1)`, `α_f = ρ∞/(ρ∞ + 1)`,
    /// `γ = ½ − α_m + α_f`, `β = ¼ (1 − α_m + α_f)²`.
    GeneralizedAlpha { rho_infinity: f64 },
    /// Hilber–Hughes–Taylor α (α_m = 0) with spectral radius
    /// `rho_infinity ∈ [½, 1]`: `α_f = (1 − ρ∞)/(1 + ρ∞)`,
    /// `γ = ½ + α_f`, `β = ¼ (1 + α_f)²`.
    HhtAlpha { rho_infinity: f64 },
}

/// The four coefficients of a [`Scheme`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SchemeCoefficients {
    pub alpha_m: f64,
    pub alpha_f: f64,
    pub beta: f64,
    pub gamma: f64,
}

impl Scheme {
    /// The dissipating scheme the critical-time search uses by default:
    /// generalized-α with `ρ∞ = 0` (asymptotic annihilation: a mode far
    /// above the step's resolution is gone after one step; `α_f = 0`, so
    /// the residual is balanced at `t_{n+1}`, the instant whose state the
    /// local QEP is solved about). Measured (Table 7.1, 20 elements,
    /// Δt = 0.02 s, `tests/verification_ge_search.rs`): with `ρ∞ = 0.5` a
    /// massless aerostat pushed with F0 = 400 N at 12 m/s shows a false
    /// onset at 1.04 s, just after the push is released (true t* 112.4 s);
    /// with `ρ∞ = 0.25` it needs a step cut; with `ρ∞ = 0` neither.
    pub const DISSIPATIVE_DEFAULT: Scheme = Scheme::GeneralizedAlpha { rho_infinity: 0.0 };

    pub fn coefficients(&self) -> SchemeCoefficients {
        match *self {
            Self::AverageAcceleration => SchemeCoefficients {
                alpha_m: 0.0,
                alpha_f: 0.0,
                beta: BETA,
                gamma: GAMMA,
            },
            Self::GeneralizedAlpha { rho_infinity: r } => {
                let alpha_m = (2.0 * r - 1.0) / (r + 1.0);
                let alpha_f = r / (r + 1.0);
                let d = 1.0 - alpha_m + alpha_f;
                SchemeCoefficients {
                    alpha_m,
                    alpha_f,
                    beta: 0.25 * d * d,
                    gamma: 0.5 - alpha_m + alpha_f,
                }
            }
            Self::HhtAlpha { rho_infinity: r } => {
                let alpha_f = (1.0 - r) / (1.0 + r);
                SchemeCoefficients {
                    alpha_m: 0.0,
                    alpha_f,
                    beta: 0.25 * (1.0 + alpha_f) * (1.0 + alpha_f),
                    gamma: 0.5 + alpha_f,
                }
            }
        }
    }

    /// Spectral radius at `ωΔt → ∞` (the stated dissipation).
    pub fn rho_infinity(&self) -> f64 {
        match *self {
            Self::AverageAcceleration => 1.0,
            Self::GeneralizedAlpha { rho_infinity } | Self::HhtAlpha { rho_infinity } => {
                rho_infinity
            }
        }
    }

    /// Checks `ρ∞` against the scheme's range (`field` names it).
    pub fn validate(&self, field: &str) -> Result<(), crate::numerics::params::InvalidInput> {
        let (lo, r) = match *self {
            Self::AverageAcceleration => return Ok(()),
            Self::GeneralizedAlpha { rho_infinity } => (0.0, rho_infinity),
            Self::HhtAlpha { rho_infinity } => (0.5, rho_infinity),
        };
        if !(lo..=1.0).contains(&r) {
            return Err(crate::numerics::params::InvalidInput::new(
                field,
                format!("must be between {lo} and 1, got {r}"),
            ));
        }
        Ok(())
    }
}

/// Advances one state by Newton-corrected steps of a [`Scheme`].
pub struct Integrator<'a> {
    pub model: &'a GeModel,
    pub drive: &'a Drive,
    pub state: State,
    pub time_step_s: f64,
    pub newton: NewtonConfig,
    pub scheme: Scheme,
}

/// A step taken with cuts: Newton iterations and how many times a failed
/// step was halved and retried.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CutStep {
    pub iterations: usize,
    pub cuts: usize,
}

impl<'a> Integrator<'a> {
    /// Average acceleration (the default [`Scheme`]).
    pub fn new(
        model: &'a GeModel,
        drive: &'a Drive,
        state: State,
        time_step_s: f64,
        newton: NewtonConfig,
    ) -> Self {
        Self {
            model,
            drive,
            state,
            time_step_s,
            newton,
            scheme: Scheme::default(),
        }
    }

    pub fn with_scheme(mut self, scheme: Scheme) -> Self {
        self.scheme = scheme;
        self
    }

    /// One step of `time_step_s`; when Newton fails, the step is retried
    /// as two halves, each of which may be halved again, at most
    /// `max_cuts` levels deep (the smallest step is `Δt / 2^max_cuts`).
    /// The state after success is at `t + Δt`, so the caller's step grid
    /// is kept. On failure the state is left where the last successful
    /// sub-step put it.
    pub fn step_with_cuts(&mut self, max_cuts: u32) -> Result<CutStep, NewtonFailure> {
        let dt = self.time_step_s;
        let t_end = self.state.time_s + dt;
        let out = self.advance(dt, max_cuts);
        self.time_step_s = dt;
        if out.is_ok() {
            self.state.time_s = t_end;
        }
        out
    }

    fn advance(&mut self, dt: f64, cuts_left: u32) -> Result<CutStep, NewtonFailure> {
        self.time_step_s = dt;
        match self.step() {
            Ok(iterations) => Ok(CutStep {
                iterations,
                cuts: 0,
            }),
            Err(f) if cuts_left == 0 => Err(f),
            Err(_) => {
                let first = self.advance(0.5 * dt, cuts_left - 1)?;
                let second = self.advance(0.5 * dt, cuts_left - 1)?;
                Ok(CutStep {
                    iterations: first.iterations + second.iterations,
                    cuts: 1 + first.cuts + second.cuts,
                })
            }
        }
    }

    /// One step; returns the number of Newton iterations (linear solves).
    /// The state is replaced only when Newton converges.
    pub fn step(&mut self) -> Result<usize, NewtonFailure> {
        let model = self.model;
        let n = model.dofs();
        let dt = self.time_step_s;
        let SchemeCoefficients {
            alpha_m,
            alpha_f,
            beta,
            gamma,
        } = self.scheme.coefficients();
        let t1 = self.state.time_s + dt;
        // the instant at which the residual is balanced
        let ta = t1 - alpha_f * dt;
        let kin = self.drive.length.kinematics(ta);
        let load = self.drive.tip_load(model, ta);
        let base = self.drive.base.acceleration_m_s2(ta);
        let mu = self.drive.damping.at(ta);
        let lin = element::linear_operators(model, kin, mu);
        let (qn, vn, an) = (&self.state.q, &self.state.v, &self.state.a);
        let alpha_a = 1.0 / (beta * dt * dt);
        let alpha_v = gamma / (beta * dt);
        // d(q, q̇, q̈ at the balance instant)/dq_{n+1}
        let (c_q, c_v, c_a) = (
            1.0 - alpha_f,
            (1.0 - alpha_f) * alpha_v,
            (1.0 - alpha_m) * alpha_a,
        );
        let mut q: Vec<f64> = (0..n)
            .map(|i| qn[i] + dt * vn[i] + 0.5 * dt * dt * an[i])
            .collect();
        let mut a = vec![0.0; n];
        let mut v = vec![0.0; n];
        let (mut qa, mut va, mut aa) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let update = |q: &[f64], a: &mut [f64], v: &mut [f64]| {
            for i in 0..n {
                a[i] = alpha_a * (q[i] - qn[i] - dt * vn[i]) - (0.5 / beta - 1.0) * an[i];
                v[i] = vn[i] + dt * ((1.0 - gamma) * an[i] + gamma * a[i]);
            }
        };
        let mut iterations = 0;
        let mut tangent = Band::zeros(n, HALF_BAND, HALF_BAND);
        loop {
            update(&q, &mut a, &mut v);
            if alpha_f == 0.0 && alpha_m == 0.0 {
                qa.copy_from_slice(&q);
                va.copy_from_slice(&v);
                aa.copy_from_slice(&a);
            } else {
                for i in 0..n {
                    qa[i] = (1.0 - alpha_f) * q[i] + alpha_f * qn[i];
                    va[i] = (1.0 - alpha_f) * v[i] + alpha_f * vn[i];
                    aa[i] = (1.0 - alpha_m) * a[i] + alpha_m * an[i];
                }
            }
            let aero = self.drive.aero_tip(model, ta, &qa, &va);
            let r = residual_with(model, &lin, kin, load, base, aero, &qa, &va, &aa);
            let rn = norm(&r.total);
            if rn <= self.newton.absolute_tolerance_n + self.newton.relative_tolerance * r.scale {
                break;
            }
            if iterations >= self.newton.max_iterations || !rn.is_finite() {
                return Err(NewtonFailure {
                    time_s: t1,
                    iterations,
                    residual_norm: rn,
                });
            }
            // S = c_q (K + K_int + K_tip) + c_v C + c_a M
            tangent.fill_zero();
            tangent.add_scaled(c_q, &lin.stiffness);
            tangent.add_scaled(c_v, &lin.damping);
            tangent.add_scaled(c_a, &lin.mass);
            let mut scratch = vec![0.0; n];
            if c_q == 1.0 {
                element::internal_forces(
                    model,
                    kin.length_m,
                    &qa,
                    &mut scratch,
                    Some(&mut tangent),
                    None,
                );
            } else {
                let mut k_int = Band::zeros(n, HALF_BAND, HALF_BAND);
                element::internal_forces(
                    model,
                    kin.length_m,
                    &qa,
                    &mut scratch,
                    Some(&mut k_int),
                    None,
                );
                tangent.add_scaled(c_q, &k_int);
            }
            let top = model.elements;
            let tip = element::tip_terms(
                model,
                kin,
                element::node(&qa, top),
                element::node(&va, top),
                element::node(&aa, top),
                load,
            );
            for i in 0..3 {
                for j in 0..3 {
                    let value =
                        c_q * tip.stiffness[i][j] + c_v * tip.damping[i][j] + c_a * tip.mass[i][j];
                    tangent.add(GeModel::dof(top, i), GeModel::dof(top, j), value);
                }
            }
            let y = GeModel::dof(top, 1);
            tangent.add(y, y, c_v * aero.damping_n_s_m + c_a * aero.added_mass_kg);
            let dq = newton_correction(tangent.clone(), &r.total, &mut q).ok_or(NewtonFailure {
                time_s: t1,
                iterations,
                residual_norm: rn,
            })?;
            iterations += 1;
            if at_roundoff(&dq, &q, kin.length_m) {
                update(&q, &mut a, &mut v);
                break;
            }
        }
        self.state = State {
            time_s: t1,
            q,
            v,
            a,
        };
        Ok(iterations)
    }
}

/// Settings of a transient run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RunConfig {
    pub time_step_s: f64,
    pub duration_s: f64,
    pub newton: NewtonConfig,
    /// Record a sample every this many steps (≥ 1); the last step is always recorded.
    pub record_every: usize,
    /// Solve the local QEP every this many steps (0: never).
    pub eigen_every: usize,
}

/// One recorded instant.
#[derive(Clone, Debug, PartialEq)]
pub struct Sample {
    pub time_s: f64,
    pub kinematics: Kinematics,
    /// Top of the cable (m): along the guide and across it.
    pub tip: [f64; 2],
    pub tip_rotation_rad: f64,
    /// The aerostat's mass point (m).
    pub aerostat: [f64; 2],
    pub energy: Energy,
    /// Angular momentum about the root (6.27) (N m s).
    pub angular_momentum_n_m_s: f64,
    /// Support reaction at the root on the cable: force (N), moment (N m).
    pub root_force_n: [f64; 2],
    pub root_moment_n_m: f64,
    /// Newton iterations of the step that produced this sample.
    pub newton_iterations: usize,
}

/// How a run ended.
#[derive(Clone, Debug, PartialEq)]
pub enum RunOutcome {
    Completed,
    NewtonFailed { step: usize, failure: NewtonFailure },
    Cancelled { step: usize, time_s: f64 },
}

/// The local QEP along the run.
#[derive(Clone, Debug)]
pub struct SpectrumSample {
    pub time_s: f64,
    pub length_m: f64,
    pub spectrum: Spectrum,
}

#[derive(Clone, Debug)]
pub struct RunResult {
    pub samples: Vec<Sample>,
    pub spectra: Vec<SpectrumSample>,
    pub outcome: RunOutcome,
    pub steps: usize,
    pub newton_iterations_total: usize,
    pub newton_iterations_max: usize,
    pub final_state: State,
    /// QEP solves that failed (eigenvalue iteration did not converge).
    pub spectrum_failures: usize,
}

impl RunResult {
    pub fn mean_newton_iterations(&self) -> f64 {
        if self.steps == 0 {
            0.0
        } else {
            self.newton_iterations_total as f64 / self.steps as f64
        }
    }
}

/// Diagnostics of a state.
pub fn sample(model: &GeModel, drive: &Drive, state: &State, newton_iterations: usize) -> Sample {
    let t = state.time_s;
    let kin = drive.length.kinematics(t);
    let mu = drive.damping.at(t);
    let top = model.elements;
    let (qt, vt) = (element::node(&state.q, top), element::node(&state.v, top));
    let (aerostat, _) = element::tip_point(model, kin, qt, vt);
    let reaction = diagnostics::root_reaction(model, kin, mu, &state.q, &state.v, &state.a);
    Sample {
        time_s: t,
        kinematics: kin,
        tip: [kin.length_m + qt[0], qt[1]],
        tip_rotation_rad: qt[2],
        aerostat,
        energy: diagnostics::energy(model, kin, &state.q, &state.v),
        angular_momentum_n_m_s: diagnostics::angular_momentum(model, kin, &state.q, &state.v),
        root_force_n: [reaction[0], reaction[1]],
        root_moment_n_m: reaction[2],
        newton_iterations,
    }
}

/// Runs from `initial` for `config.duration_s`. `observer(done, total)` is
/// called every few steps; returning `false` cancels.
pub fn run(
    model: &GeModel,
    drive: &Drive,
    initial: State,
    config: RunConfig,
    observer: &mut dyn FnMut(usize, usize) -> bool,
) -> RunResult {
    let steps_total = (config.duration_s / config.time_step_s).round() as usize;
    let every = config.record_every.max(1);
    let mut samples = vec![sample(model, drive, &initial, 0)];
    let mut spectra = Vec::new();
    let mut spectrum_failures = 0;
    let mut record_spectrum = |state: &State, spectra: &mut Vec<SpectrumSample>| {
        let kin = drive.length.kinematics(state.time_s);
        match stability::drive_spectrum(model, drive, state) {
            Ok(spectrum) => spectra.push(SpectrumSample {
                time_s: state.time_s,
                length_m: kin.length_m,
                spectrum,
            }),
            Err(_) => spectrum_failures += 1,
        }
    };
    if config.eigen_every > 0 {
        record_spectrum(&initial, &mut spectra);
    }
    let mut integrator = Integrator::new(model, drive, initial, config.time_step_s, config.newton);
    let (mut total, mut max) = (0, 0);
    let mut outcome = RunOutcome::Completed;
    // At most 64 steps between two polls: a cancelled run stops promptly.
    let report_every = (steps_total / 200).clamp(1, 64);
    let mut steps = 0;
    for step in 1..=steps_total {
        if step % report_every == 0 && !observer(step, steps_total) {
            outcome = RunOutcome::Cancelled {
                step,
                time_s: integrator.state.time_s,
            };
            break;
        }
        match integrator.step() {
            Ok(it) => {
                steps = step;
                total += it;
                max = max.max(it);
                if step % every == 0 || step == steps_total {
                    samples.push(sample(model, drive, &integrator.state, it));
                }
                if config.eigen_every > 0 && step % config.eigen_every == 0 {
                    record_spectrum(&integrator.state, &mut spectra);
                }
            }
            Err(failure) => {
                outcome = RunOutcome::NewtonFailed { step, failure };
                break;
            }
        }
    }
    observer(steps, steps_total);
    RunResult {
        samples,
        spectra,
        outcome,
        steps,
        newton_iterations_total: total,
        newton_iterations_max: max,
        final_state: integrator.state,
        spectrum_failures,
    }
}
