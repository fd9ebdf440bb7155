//! The state a GE march starts from ([`StartState`]: at rest, or already
//! paying out steadily with the velocity of [`steady_payout_velocity`]) and
//! the guide's axial force of a state ([`root_axial_force_n`]). Below both
//! the critical-time march ([`super::critical`]) and the stability of a
//! queried state ([`super::stability`]).

use super::GeModel;
use crate::numerics::params::Kinematics;

/// The cable's state at `t = 0`. Both start straight in the static
/// equilibrium under the buoyancy (stretched by `N/EA`); they differ in
/// velocity, which matters only for an extensible cable.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum StartState {
    /// The whole cable moves at the reel-out rate `L̇` when the winch
    /// starts (zero velocity in the mapped frame). A stretched cable
    /// should move at `L̇ (1 + ε_root)`, so this start sets off an axial
    /// transient of relative size `ε` (nil for the stiff cables of the
    /// charts, `E* ≥ 100`).
    #[default]
    AtRest,
    /// Already paying out steadily: every point moves along the cable at
    /// the speed the guide feeds it out, `L̇ (1 + ε_root)`, which is the
    /// quasi-static deployment of [`super::extensible`] (no start
    /// transient). Used to check the extensible cable against that limit.
    SteadyPayout,
}

/// Mapped-frame velocity `U̇` that gives every point the physical axial
/// velocity `L̇ (1 + ε_root)`. A point at `ζ` moves at
/// `L̇ + u̇1 + (1 − ζ) L̇ u1_ζ / L` (the convected frame), so
/// `u̇1 = L̇ (ε_root − (1 − ζ) ε(ζ))` with `ε = u1_ζ / L` (nodal slopes by
/// central differences); `u̇2 = θ̇ = 0`.
pub(crate) fn steady_payout_velocity(model: &GeModel, kin: Kinematics, q: &[f64]) -> Vec<f64> {
    let n = model.elements;
    let h = 1.0 / n as f64;
    let u1 = |k: usize| if k == 0 { 0.0 } else { q[GeModel::dof(k, 0)] };
    let strain = |k: usize| {
        let (lo, hi) = (k.saturating_sub(1), (k + 1).min(n));
        (u1(hi) - u1(lo)) / ((hi - lo) as f64 * h * kin.length_m)
    };
    let root = u1(1) / (h * kin.length_m);
    let mut v = vec![0.0; q.len()];
    for k in 1..=n {
        let zeta = k as f64 * h;
        v[GeModel::dof(k, 0)] = kin.rate_m_s * (root - (1.0 - zeta) * strain(k));
    }
    v
}

/// Axial force `EA Γ1` of the first element, at its middle (reference
/// position `ζ = h/2`), where the reduced rule evaluates it:
/// `Γ1 = (cos θ (L + u1_ζ) + sin θ u2_ζ)/L − 1`.
pub fn root_axial_force_n(model: &GeModel, length_m: f64, q: &[f64]) -> f64 {
    let h = model.ops.len(0);
    let (u1, u2, th) = (
        q[GeModel::dof(1, 0)],
        q[GeModel::dof(1, 1)],
        0.5 * q[GeModel::dof(1, 2)],
    );
    let gamma = (th.cos() * (length_m + u1 / h) + th.sin() * u2 / h) / length_m - 1.0;
    model.section.axial_stiffness_n * gamma
}
