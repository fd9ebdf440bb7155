//! Local stability of the GE cable in a steady wind, from a quasi-static
//! analysis (issue 12 item 4): the blown-down equilibrium at a deployment
//! state `(L, L̇, L̈)`, then the local QEP (7.3) about it with the payout's
//! rate terms and the linearised air loads of [`super::air_load`].
//!
//! **Equilibrium.** `R(q, 0, 0) − F_air(q, 0) = 0` in the mapped frame
//! (the sliding terms of `L̇`, `L̈` included, as in
//! [`super::stability::state_stability`]): first the straight calm-air
//! equilibrium by [`super::solver::static_solve`] (the very same call as
//! `state_stability`), then Newton under the air loads, continued in the
//! dynamic pressure from 0 to 1 with an adaptive increment (halved when
//! Newton fails, grown by 1.5 when it converges; at most
//! [`MAX_CONTINUATION_STEPS`] increments). A caller that has a nearby
//! equilibrium (the previous length of a search) passes it as `start`
//! and Newton tries the full load from there first.
//!
//! **Cost** (issue 21). Each Newton iteration takes the residual and the
//! tangent from one pass over the elements (the sliding operators and
//! body forces once per call, the air stiffness without its damping
//! band), the same arithmetic as [`solver::residual`] and
//! [`solver::system_matrices`] bit for bit (tested). Measured on the
//! converged plan in wind (`benches/plan.rs`): 21.7 → 12.8 G
//! instructions with the slice band LU, identical answers.
//!
//! **QEP.** `M = ∂R/∂q̈`, `C = ∂R/∂q̇ − ∂F_air/∂u̇` (the aerodynamic damping),
//! `K = ∂R/∂q − ∂F_air/∂q`, about the state with the velocity of `motion`
//! and the consistent acceleration `M q̈ = −(R(q, q̇, 0) − F_air)`.
//!
//! In calm air every air term is zero and is skipped, so the answer is
//! bit for bit that of `state_stability` (tested).

use super::GeModel;
use super::air_load::AirLoads;
use super::banded::Band;
use super::element::{self, TipLoad, node};
use super::solver::{self, NewtonConfig, NewtonFailure, State, SystemMatrices};
use super::stability::{GeStateFailure, StateMotion, spectrum_of};
use crate::numerics::params::Kinematics;
use crate::numerics::qep::{QepError, Spectrum};

/// Most load increments of the wind continuation.
pub const MAX_CONTINUATION_STEPS: usize = 200;

/// Settings of one quasi-static state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QsConfig {
    pub newton: NewtonConfig,
    /// Increments of gravity and buoyancy in the straight solve (as `state_stability`).
    pub load_steps: usize,
}

impl Default for QsConfig {
    fn default() -> Self {
        Self {
            newton: NewtonConfig::default(),
            load_steps: 2,
        }
    }
}

/// The blown-down equilibrium.
#[derive(Clone, Debug)]
pub struct WindEquilibrium {
    pub q: Vec<f64>,
    /// Wind increments taken (0 in calm air or from a converged `start`).
    pub continuation_steps: usize,
    pub newton_iterations: usize,
}

/// Local stability at one state in wind.
#[derive(Clone, Debug)]
pub struct WindStateStability {
    pub state: State,
    pub spectrum: Spectrum,
    /// Axial force in the element at the guide (N).
    pub root_axial_force_n: f64,
    /// Top of the cable: height above the guide and downwind offset (m).
    pub tip_altitude_m: f64,
    pub tip_downwind_m: f64,
    pub continuation_steps: usize,
    pub newton_iterations: usize,
}

fn norm(x: &[f64]) -> f64 {
    x.iter().map(|v| v * v).sum::<f64>().sqrt()
}

fn at_roundoff(dq: &[f64], q: &[f64], length: f64) -> bool {
    let big = q.iter().fold(length, |m, x| m.max(x.abs()));
    dq.iter().all(|d| d.abs() <= 1e-13 * big)
}

/// Newton on `R(q, 0, 0) − F_air(q, 0) = 0` from `q`; the iterations taken.
///
/// Each iteration evaluates the residual and, when it is not converged,
/// the tangent from the same pass over the elements: the sliding
/// operators and the body forces (functions of the kinematics alone) are
/// built once per call, and the internal forces once per iteration with
/// their tangent. The arithmetic is that of [`solver::residual`] and
/// [`solver::system_matrices`] term by term, so the iterates are those of
/// the separate calls bit for bit (tested against them).
fn newton(
    model: &GeModel,
    kin: Kinematics,
    load: TipLoad,
    air: &AirLoads,
    q: &mut [f64],
    config: NewtonConfig,
    limit: Option<StepLimit>,
) -> Result<usize, NewtonFailure> {
    let n = q.len();
    let zero = vec![0.0; n];
    let lin = element::linear_operators(model, kin, 0.0);
    let mut body = vec![0.0; n];
    element::body_forces(model, kin, 1.0, &mut body, &mut [0.0; 3]);
    let body_norm = norm(&body);
    let top = model.elements;
    let mut inertia = vec![0.0; n];
    let mut internal = vec![0.0; n];
    let mut iterations = 0;
    loop {
        // R(q, 0, 0): the sliding stiffness times q (its mass and damping
        // act on zero rates), the internal forces with their tangent, the
        // body forces and the aerostat.
        inertia.iter_mut().for_each(|x| *x = 0.0);
        lin.stiffness.mul_add(q, &mut inertia);
        internal.iter_mut().for_each(|x| *x = 0.0);
        let mut s = lin.stiffness.clone();
        element::internal_forces(model, kin.length_m, q, &mut internal, Some(&mut s), None);
        let tip = element::tip_terms(
            model,
            kin,
            node(q, top),
            node(&zero, top),
            node(&zero, top),
            load,
        );
        let mut total: Vec<f64> = (0..n).map(|i| inertia[i] + internal[i] - body[i]).collect();
        for c in 0..3 {
            total[GeModel::dof(top, c)] += tip.residual[c];
        }
        // the air term of `residual` with no aerostat air load: `0·a − 0`
        let tip_air = 0.0 * zero[GeModel::dof(top, 1)] - 0.0;
        total[GeModel::dof(top, 1)] += tip_air;
        let r_scale = norm(&inertia)
            .max(norm(&internal))
            .max(body_norm)
            .max(norm(&tip.residual))
            .max(tip_air.abs());
        let a = air.terms_without_damping(model, kin.length_m, q, &zero);
        let total: Vec<f64> = (0..n).map(|i| total[i] - a.force[i]).collect();
        let rn = norm(&total);
        let scale = r_scale.max(norm(&a.force));
        if rn <= config.absolute_tolerance_n + config.relative_tolerance * scale {
            return Ok(iterations);
        }
        let fail = NewtonFailure {
            time_s: 0.0,
            iterations,
            residual_norm: rn,
        };
        if iterations >= config.max_iterations || !rn.is_finite() {
            return Err(fail);
        }
        for i in 0..3 {
            for j in 0..3 {
                s.add(
                    GeModel::dof(top, i),
                    GeModel::dof(top, j),
                    tip.stiffness[i][j],
                );
            }
        }
        s.add_scaled(1.0, &a.stiffness);
        let lu = s.factor().ok_or(fail)?;
        let mut dq: Vec<f64> = total.iter().map(|x| -x).collect();
        lu.solve_in_place(&mut dq);
        if let Some(lim) = limit {
            // scale the step so that no rotation turns more than
            // `rotation_rad` and no node moves more than `displacement_m`
            let mut f: f64 = 1.0;
            for (i, d) in dq.iter().enumerate() {
                let cap = if i % 3 == 2 {
                    lim.rotation_rad
                } else {
                    lim.displacement_m
                };
                if d.abs() > cap {
                    f = f.min(cap / d.abs());
                }
            }
            if f < 1.0 {
                dq.iter_mut().for_each(|d| *d *= f);
            }
        }
        for (qi, di) in q.iter_mut().zip(&dq) {
            *qi += di;
        }
        iterations += 1;
        if dq.iter().any(|d| !d.is_finite()) {
            return Err(fail);
        }
        if at_roundoff(&dq, q, kin.length_m) {
            return Ok(iterations);
        }
    }
}

/// Largest Newton step of [`newton_from`]: the step is scaled down so that
/// no rotation changes by more than `rotation_rad` and no displacement by
/// more than `displacement_m` (a Newton that stays near its start).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepLimit {
    pub rotation_rad: f64,
    pub displacement_m: f64,
}

/// Newton alone on the equilibrium at `kin` from `q` (no continuation),
/// its steps limited by `limit`: the iterations taken; `q` is the
/// equilibrium on success.
pub fn newton_from(
    model: &GeModel,
    kin: Kinematics,
    load: TipLoad,
    air: &AirLoads,
    config: &QsConfig,
    q: &mut [f64],
    limit: Option<StepLimit>,
) -> Result<usize, NewtonFailure> {
    let newton_config = match limit {
        // a limited step converges more slowly from far
        Some(_) => NewtonConfig {
            max_iterations: config.newton.max_iterations.max(60),
            ..config.newton
        },
        None => config.newton,
    };
    newton(model, kin, load, air, q, newton_config, limit)
}

/// The blown-down equilibrium at `kin` under the tip `load`, gravity and `air`.
pub fn wind_equilibrium(
    model: &GeModel,
    kin: Kinematics,
    load: TipLoad,
    air: &AirLoads,
    config: &QsConfig,
    start: Option<&[f64]>,
) -> Result<WindEquilibrium, NewtonFailure> {
    if let Some(s) = start
        && s.len() == model.dofs()
    {
        let mut q = s.to_vec();
        if let Ok(it) = newton(model, kin, load, air, &mut q, config.newton, None) {
            return Ok(WindEquilibrium {
                q,
                continuation_steps: 0,
                newton_iterations: it,
            });
        }
    }
    let mut q = solver::static_solve(model, kin, load, config.load_steps, config.newton)?;
    if air.is_calm() {
        return Ok(WindEquilibrium {
            q,
            continuation_steps: 0,
            newton_iterations: 0,
        });
    }
    let (mut done, mut step) = (0.0f64, 1.0f64);
    let (mut steps, mut iterations) = (0usize, 0usize);
    let mut last_failure = None;
    while done < 1.0 {
        if steps >= MAX_CONTINUATION_STEPS || step < 1e-6 {
            return Err(last_failure.unwrap_or(NewtonFailure {
                time_s: 0.0,
                iterations,
                residual_norm: f64::NAN,
            }));
        }
        steps += 1;
        let target = (done + step).min(1.0);
        let mut trial = q.clone();
        match newton(
            model,
            kin,
            load,
            &air.scaled(target),
            &mut trial,
            config.newton,
            None,
        ) {
            Ok(it) => {
                iterations += it;
                q = trial;
                done = target;
                step *= 1.5;
            }
            Err(f) => {
                iterations += f.iterations;
                last_failure = Some(f);
                step *= 0.5;
            }
        }
    }
    Ok(WindEquilibrium {
        q,
        continuation_steps: steps,
        newton_iterations: iterations,
    })
}

/// `M`, `C`, `K` about a state, air terms included.
pub fn wind_matrices(
    model: &GeModel,
    kin: Kinematics,
    load: TipLoad,
    air: &AirLoads,
    state: &State,
) -> SystemMatrices {
    let mut sys = solver::system_matrices(model, kin, load, 0.0, &state.q, &state.v, &state.a);
    if !air.is_calm() {
        let a = air.terms(model, kin.length_m, &state.q, &state.v, true);
        sys.stiffness.add_scaled(1.0, &a.stiffness);
        sys.damping.add_scaled(1.0, &a.damping);
    }
    sys
}

/// The quasi-static state at an equilibrium `q`: the velocity of `motion`
/// and the consistent acceleration.
pub fn state_at(
    model: &GeModel,
    kin: Kinematics,
    load: TipLoad,
    air: &AirLoads,
    motion: StateMotion,
    q: Vec<f64>,
) -> Result<State, QepError> {
    let v = match motion {
        StateMotion::AtRest => vec![0.0; q.len()],
        StateMotion::SteadyPayout => super::start::steady_payout_velocity(model, kin, &q),
    };
    let zero = vec![0.0; q.len()];
    let r = solver::residual(model, kin, load, 0.0, &q, &v, &zero);
    let m = solver::system_matrices(model, kin, load, 0.0, &q, &v, &zero).mass;
    let lu = m.factor().ok_or(QepError::NonFinite)?;
    let mut a: Vec<f64> = r.total.iter().map(|x| -x).collect();
    if !air.is_calm() {
        let f = air.terms(model, kin.length_m, &q, &v, false).force;
        for (ai, fi) in a.iter_mut().zip(&f) {
            *ai += fi;
        }
    }
    lu.solve_in_place(&mut a);
    Ok(State {
        time_s: 0.0,
        q,
        v,
        a,
    })
}

/// Local stability of the GE cable at a deployment state in a steady
/// wind: the blown-down equilibrium, then the QEP about it. With
/// [`AirLoads::calm`] this is [`super::stability::state_stability`].
pub fn wind_stability(
    model: &GeModel,
    kin: Kinematics,
    load: TipLoad,
    air: &AirLoads,
    motion: StateMotion,
    config: &QsConfig,
    start: Option<&[f64]>,
) -> Result<WindStateStability, GeStateFailure> {
    let eq = wind_equilibrium(model, kin, load, air, config, start)
        .map_err(GeStateFailure::Equilibrium)?;
    let state = state_at(model, kin, load, air, motion, eq.q).map_err(GeStateFailure::Spectrum)?;
    let spectrum = spectrum_of(model, wind_matrices(model, kin, load, air, &state))
        .map_err(GeStateFailure::Spectrum)?;
    let top = node(&state.q, model.elements);
    Ok(WindStateStability {
        root_axial_force_n: super::critical::root_axial_force_n(model, kin.length_m, &state.q),
        tip_altitude_m: kin.length_m + top[0],
        tip_downwind_m: top[1],
        spectrum,
        state,
        continuation_steps: eq.continuation_steps,
        newton_iterations: eq.newton_iterations,
    })
}

/// `K` of the state at rest at the equilibrium `q` (the air stiffness
/// included in wind).
pub fn static_stiffness(
    model: &GeModel,
    kin: Kinematics,
    load: TipLoad,
    air: &AirLoads,
    q: &[f64],
) -> Band {
    let zero = vec![0.0; q.len()];
    let mut k = solver::system_matrices(model, kin, load, 0.0, q, &zero, &zero).stiffness;
    if !air.is_calm() {
        k.add_scaled(
            1.0,
            &air.terms(model, kin.length_m, q, &zero, true).stiffness,
        );
    }
    k
}

/// Sign of `det K` of the quasi-static state (`K` with the air stiffness):
/// `+1`, `−1`, or 0 when singular. A real eigenvalue of the QEP crosses
/// zero exactly where it changes sign (divergence).
pub fn stiffness_determinant_sign(
    model: &GeModel,
    kin: Kinematics,
    load: TipLoad,
    air: &AirLoads,
    q: &[f64],
) -> i8 {
    band_determinant_sign(&static_stiffness(model, kin, load, air, q))
}

/// Number of negative eigenvalues of the symmetric part of `K` (with the
/// air stiffness) at the equilibrium `q` (Sylvester's law of inertia on a
/// band `LDLᵀ`). In calm air at a constant rate `K` is symmetric and this is
/// its inertia; a zero or non-finite pivot gives `None`.
pub fn stiffness_negative_count(
    model: &GeModel,
    kin: Kinematics,
    load: TipLoad,
    air: &AirLoads,
    q: &[f64],
) -> Option<usize> {
    symmetric_negative_count(&static_stiffness(model, kin, load, air, q))
}

/// As [`stiffness_negative_count`], with `ln |det|` of the symmetric part.
pub fn stiffness_inertia(
    model: &GeModel,
    kin: Kinematics,
    load: TipLoad,
    air: &AirLoads,
    q: &[f64],
) -> Option<(usize, f64)> {
    symmetric_inertia(&static_stiffness(model, kin, load, air, q))
}

/// Negative pivots of `LDLᵀ` of `(A + Aᵀ)/2` for a band `A` (no pivoting).
pub fn symmetric_negative_count(a: &Band) -> Option<usize> {
    symmetric_inertia(a).map(|x| x.0)
}

/// Negative pivots of `LDLᵀ` of `(A + Aᵀ)/2` and `ln |det|` (the sum of
/// `ln |d_i|`): the determinant is `(−1)^count · exp(ln |det|)`.
pub fn symmetric_inertia(a: &Band) -> Option<(usize, f64)> {
    let n = a.n;
    let mut log_det = 0.0;
    let b = a.kl.min(a.ku);
    // l[i][k] for k in i-b..i stored at offset (k + b − i); d[i]
    let mut l = vec![0.0; n * (b + 1)];
    let mut d = vec![0.0; n];
    let sym = |i: usize, j: usize| 0.5 * (a.get(i, j) + a.get(j, i));
    let mut negative = 0;
    for i in 0..n {
        let lo = i.saturating_sub(b);
        for j in lo..i {
            // l_ij d_j = a_ij − Σ_{k<j} l_ik l_jk d_k
            let mut s = sym(i, j);
            for k in lo.max(j.saturating_sub(b))..j {
                s -= l[i * (b + 1) + (k + b - i)] * l[j * (b + 1) + (k + b - j)] * d[k];
            }
            l[i * (b + 1) + (j + b - i)] = s / d[j];
        }
        let mut s = sym(i, i);
        for k in lo..i {
            let lik = l[i * (b + 1) + (k + b - i)];
            s -= lik * lik * d[k];
        }
        if !s.is_finite() || s == 0.0 {
            return None;
        }
        d[i] = s;
        log_det += s.abs().ln();
        if s < 0.0 {
            negative += 1;
        }
    }
    Some((negative, log_det))
}

/// Sign of the determinant of a band matrix (LU with partial pivoting on a copy).
pub fn band_determinant_sign(a: &Band) -> i8 {
    band_determinant(a).map_or(0, |d| d.0)
}

/// The divergence indicator of the quasi-static state: in calm air the
/// inertia of `K` (symmetric) and `ln |det K|`; in wind the parity of
/// `det K` itself (`K` with the air stiffness, not symmetric: a real
/// eigenvalue of the QEP crosses zero exactly where `det K` changes sign;
/// the inertia of its symmetric part changes elsewhere) as a count of 0
/// (positive) or 1 (negative), and `ln |det K|`.
pub fn divergence_indicator(
    model: &GeModel,
    kin: Kinematics,
    load: TipLoad,
    air: &AirLoads,
    q: &[f64],
) -> Option<(usize, f64)> {
    if air.is_calm() {
        return stiffness_inertia(model, kin, load, air, q);
    }
    band_determinant(&static_stiffness(model, kin, load, air, q))
        .map(|(sign, ld)| (usize::from(sign < 0), ld))
}

/// Sign and `ln |det|` of a band matrix (LU with partial pivoting on a
/// copy); `None` when singular or not finite.
pub fn band_determinant(a: &Band) -> Option<(i8, f64)> {
    let mut log_det = 0.0;
    let n = a.n;
    let (kl, ku) = (a.kl, a.ku);
    let w = 2 * kl + ku + 1;
    // row i holds columns i − kl ..= i + kl + ku at offset j + kl − i
    let mut d = vec![0.0; n * w];
    for i in 0..n {
        for j in i.saturating_sub(kl)..=(i + ku).min(n.saturating_sub(1)) {
            d[i * w + (j + kl - i)] = a.get(i, j);
        }
    }
    let idx = |i: usize, j: usize| i * w + (j + kl - i);
    let mut sign = 1i8;
    for k in 0..n {
        let last_row = (k + kl).min(n - 1);
        let mut p = k;
        let mut best = d[idx(k, k)].abs();
        for r in k + 1..=last_row {
            let v = d[idx(r, k)].abs();
            if v > best {
                best = v;
                p = r;
            }
        }
        if !best.is_finite() || best == 0.0 {
            return None;
        }
        let last_col = (k + kl + ku).min(n - 1);
        if p != k {
            sign = -sign;
            for j in k..=last_col {
                d.swap(idx(k, j), idx(p, j));
            }
        }
        let pivot = d[idx(k, k)];
        log_det += pivot.abs().ln();
        if pivot < 0.0 {
            sign = -sign;
        }
        for r in k + 1..=last_row {
            let l = d[idx(r, k)] / pivot;
            if l != 0.0 {
                for j in k + 1..=last_col {
                    d[idx(r, j)] -= l * d[idx(k, j)];
                }
            }
        }
    }
    Some((sign, log_det))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::ge::qs_wind::continuum_start;
    use crate::numerics::ge::{Section, TipBody};
    use crate::numerics::tether::WindProfile;

    /// The Newton of the separate calls ([`solver::residual`], then
    /// [`solver::system_matrices`] for the tangent), as it was before the
    /// fused pass: the independent reference of [`newton`].
    fn reference_newton(
        model: &GeModel,
        kin: Kinematics,
        load: TipLoad,
        air: &AirLoads,
        q: &mut [f64],
        config: NewtonConfig,
        limit: Option<StepLimit>,
    ) -> Result<usize, NewtonFailure> {
        let n = q.len();
        let zero = vec![0.0; n];
        let mut iterations = 0;
        loop {
            let r = solver::residual(model, kin, load, 0.0, q, &zero, &zero);
            let a = air.terms(model, kin.length_m, q, &zero, true);
            let total: Vec<f64> = (0..n).map(|i| r.total[i] - a.force[i]).collect();
            let rn = norm(&total);
            let scale = r.scale.max(norm(&a.force));
            if rn <= config.absolute_tolerance_n + config.relative_tolerance * scale {
                return Ok(iterations);
            }
            let fail = NewtonFailure {
                time_s: 0.0,
                iterations,
                residual_norm: rn,
            };
            if iterations >= config.max_iterations || !rn.is_finite() {
                return Err(fail);
            }
            let mut s = solver::system_matrices(model, kin, load, 0.0, q, &zero, &zero).stiffness;
            s.add_scaled(1.0, &a.stiffness);
            let lu = s.factor().ok_or(fail)?;
            let mut dq: Vec<f64> = total.iter().map(|x| -x).collect();
            lu.solve_in_place(&mut dq);
            if let Some(lim) = limit {
                let mut f: f64 = 1.0;
                for (i, d) in dq.iter().enumerate() {
                    let cap = if i % 3 == 2 {
                        lim.rotation_rad
                    } else {
                        lim.displacement_m
                    };
                    if d.abs() > cap {
                        f = f.min(cap / d.abs());
                    }
                }
                if f < 1.0 {
                    dq.iter_mut().for_each(|d| *d *= f);
                }
            }
            for (qi, di) in q.iter_mut().zip(&dq) {
                *qi += di;
            }
            iterations += 1;
            if dq.iter().any(|d| !d.is_finite()) {
                return Err(fail);
            }
            if at_roundoff(&dq, q, kin.length_m) {
                return Ok(iterations);
            }
        }
    }

    /// The fused Newton iterates exactly as the separate residual and
    /// tangent calls: the same equilibrium bit for bit and the same
    /// iteration count, in wind (log law, the thesis tether blown down)
    /// from the continuum start with limited steps, at rest and paying
    /// out at a rate near the divergence (where the limited Newton walks
    /// and may fail: the failure must match too), and in calm air from
    /// the straight tether.
    #[test]
    fn fused_newton_iterates_as_the_separate_calls() {
        let (rho_a, d) = (0.078, 0.005);
        let s = Section::new(1e6, 1e6, 1.0, rho_a, rho_a * d * d / 16.0).unwrap();
        let tip = TipBody {
            mass_kg: 10.0,
            link_length_m: 0.0,
        };
        let load = TipLoad {
            force_n: [1000.0, 0.0],
            moment_n_m: 0.0,
        };
        let air = AirLoads {
            wind: WindProfile::log_law(8.0, 10.0, 0.03, "wind").unwrap(),
            air_density_kg_m3: 1.225,
            cable_diameter_m: d,
            cable_normal_drag_coefficient: 1.2,
            aerostat_drag_area_m2: 0.9,
            aerostat_lift_area_m2: 0.0,
        };
        let limit = StepLimit {
            rotation_rad: 0.25,
            displacement_m: 0.02 * 800.0,
        };
        let config = NewtonConfig {
            max_iterations: 60,
            ..NewtonConfig::default()
        };
        let mut checked = 0;
        for elements in [20, 40] {
            let m = GeModel::new(s, elements, tip, 9.81).unwrap();
            let (start, _) = continuum_start(&m, &air, 1000.0, 800.0).unwrap();
            for rate in [0.0, 10.0, 60.0, 95.0] {
                let kin = Kinematics {
                    length_m: 800.0,
                    rate_m_s: rate,
                    acceleration_m_s2: 0.0,
                };
                for lim in [Some(limit), None] {
                    let (mut a, mut b) = (start.clone(), start.clone());
                    let fa = newton(&m, kin, load, &air, &mut a, config, lim);
                    let fb = reference_newton(&m, kin, load, &air, &mut b, config, lim);
                    assert_eq!(fa, fb, "{elements} elements, {rate} m/s, {lim:?}");
                    let same = a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits());
                    assert!(same, "{elements} elements, {rate} m/s: states differ");
                    checked += usize::from(fa.is_ok());
                }
            }
            // calm air, from the unstretched straight tether
            let kin = Kinematics {
                length_m: 800.0,
                rate_m_s: 0.0,
                acceleration_m_s2: 0.0,
            };
            let calm = AirLoads::calm();
            let (mut a, mut b) = (vec![0.0; m.dofs()], vec![0.0; m.dofs()]);
            let fa = newton(&m, kin, load, &calm, &mut a, config, None);
            let fb = reference_newton(&m, kin, load, &calm, &mut b, config, None);
            assert_eq!(fa, fb);
            assert!(a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()));
            assert!(fa.is_ok_and(|it| it >= 1), "{fa:?}");
        }
        assert!(checked >= 8, "only {checked} converged cases compared");
    }
}
