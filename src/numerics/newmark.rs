//! Newmark time stepping for `M(t) q̈ + C(t) q̇ + K(t) q = f(t)` with
//! tridiagonal, time-varying matrices (SPEC §2; thesis app. A).
//!
//! The average-acceleration member (`β = 1/4`, `γ = 1/2`, the trapezoidal
//! rule) is unconditionally stable and conserves `½ q̇ᵀMq̇ + ½ qᵀKq` exactly
//! for constant symmetric `M, K` without damping or load. Each step solves
//!
//! ```text
//! (M + γΔt C + βΔt² K)_{n+1} a_{n+1} = f_{n+1} − C_{n+1} ṽ − K_{n+1} ũ
//! ũ = u_n + Δt v_n + (½ − β) Δt² a_n,    ṽ = v_n + (1 − γ) Δt a_n
//! u_{n+1} = ũ + β Δt² a_{n+1},           v_{n+1} = ṽ + γ Δt a_{n+1}
//! ```
//!
//! with the matrices evaluated at `t_{n+1}`. The effective matrix is
//! tridiagonal: one Thomas solve, `O(n)` per step, no allocation.

use crate::numerics::tridiag::Tridiagonal;

/// Newmark parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewmarkParameters {
    pub beta: f64,
    pub gamma: f64,
}

impl NewmarkParameters {
    /// Average acceleration: `β = 1/4`, `γ = 1/2`.
    pub const AVERAGE_ACCELERATION: Self = Self {
        beta: 0.25,
        gamma: 0.5,
    };
}

impl Default for NewmarkParameters {
    fn default() -> Self {
        Self::AVERAGE_ACCELERATION
    }
}

/// Displacement, velocity and acceleration at one instant.
#[derive(Clone, Debug, PartialEq)]
pub struct NewmarkState {
    pub time: f64,
    pub displacement: Vec<f64>,
    pub velocity: Vec<f64>,
    pub acceleration: Vec<f64>,
}

impl NewmarkState {
    pub fn at_rest(n: usize, time: f64) -> Self {
        Self {
            time,
            displacement: vec![0.0; n],
            velocity: vec![0.0; n],
            acceleration: vec![0.0; n],
        }
    }

    pub fn is_finite(&self) -> bool {
        self.displacement
            .iter()
            .chain(&self.velocity)
            .chain(&self.acceleration)
            .all(|v| v.is_finite())
    }
}

/// A step could not be taken.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum StepError {
    /// The effective matrix has a zero (or non-finite) pivot at `time`.
    #[error("singular effective matrix at t = {time}")]
    SingularMatrix { time: f64 },
    /// The state became non-finite at `time`.
    #[error("non-finite state at t = {time}")]
    NonFinite { time: f64 },
}

/// The stepper with its work space (reused across steps).
#[derive(Clone, Debug)]
pub struct Newmark {
    pub parameters: NewmarkParameters,
    effective: Tridiagonal,
    rhs: Vec<f64>,
    work: Vec<f64>,
    predicted_u: Vec<f64>,
    predicted_v: Vec<f64>,
    pivots: Vec<f64>,
    ratios: Vec<f64>,
}

impl Newmark {
    pub fn new(n: usize, parameters: NewmarkParameters) -> Self {
        Self {
            parameters,
            effective: Tridiagonal::zeros(n),
            rhs: vec![0.0; n],
            work: vec![0.0; n],
            predicted_u: vec![0.0; n],
            predicted_v: vec![0.0; n],
            pivots: vec![0.0; n],
            ratios: vec![0.0; n],
        }
    }

    /// Sets `state.acceleration` from the equation of motion at its time:
    /// `M a = f − C v − K u`.
    pub fn initialise(
        &mut self,
        mass: &Tridiagonal,
        damping: &Tridiagonal,
        stiffness: &Tridiagonal,
        load: &[f64],
        state: &mut NewmarkState,
    ) -> Result<(), StepError> {
        damping.mul_vec(&state.velocity, &mut self.work);
        stiffness.mul_vec(&state.displacement, &mut self.rhs);
        for ((r, f), w) in self.rhs.iter_mut().zip(load).zip(&self.work) {
            *r = f - w - *r;
        }
        self.effective.clone_from(mass);
        solve_in_place(
            &self.effective,
            &mut self.rhs,
            &mut self.pivots,
            &mut self.ratios,
        )
        .map_err(|_| StepError::SingularMatrix { time: state.time })?;
        state.acceleration.copy_from_slice(&self.rhs);
        if !state.is_finite() {
            return Err(StepError::NonFinite { time: state.time });
        }
        Ok(())
    }

    /// Predicted velocity `ṽ = v_n + (1 − γ)Δt a_n` of the next step (the
    /// part known before the solve), e.g. to linearise a velocity-dependent
    /// load about it.
    pub fn predicted_velocity(&self, dt: f64, state: &NewmarkState, i: usize) -> f64 {
        state.velocity[i] + (1.0 - self.parameters.gamma) * dt * state.acceleration[i]
    }

    /// Advances `state` by `dt` with the matrices and load at the new time.
    pub fn step(
        &mut self,
        dt: f64,
        mass: &Tridiagonal,
        damping: &Tridiagonal,
        stiffness: &Tridiagonal,
        load: &[f64],
        state: &mut NewmarkState,
    ) -> Result<(), StepError> {
        let NewmarkParameters { beta, gamma } = self.parameters;
        let n = mass.dim();
        let time = state.time + dt;
        for i in 0..n {
            let (u, v, a) = (
                state.displacement[i],
                state.velocity[i],
                state.acceleration[i],
            );
            self.predicted_u[i] = u + dt * v + (0.5 - beta) * dt * dt * a;
            self.predicted_v[i] = v + (1.0 - gamma) * dt * a;
        }
        damping.mul_vec(&self.predicted_v, &mut self.work);
        stiffness.mul_vec(&self.predicted_u, &mut self.rhs);
        for ((r, f), w) in self.rhs.iter_mut().zip(load).zip(&self.work) {
            *r = f - w - *r;
        }
        let (cg, kb) = (gamma * dt, beta * dt * dt);
        combine_into(&mut self.effective, mass, (cg, damping), (kb, stiffness));
        solve_in_place(
            &self.effective,
            &mut self.rhs,
            &mut self.pivots,
            &mut self.ratios,
        )
        .map_err(|_| StepError::SingularMatrix { time })?;
        for i in 0..n {
            let a = self.rhs[i];
            state.acceleration[i] = a;
            state.displacement[i] = self.predicted_u[i] + kb * a;
            state.velocity[i] = self.predicted_v[i] + cg * a;
        }
        state.time = time;
        if !state.is_finite() {
            return Err(StepError::NonFinite { time });
        }
        Ok(())
    }
}

/// `out = m + c1·a + c2·b` (all tridiagonal of one size).
fn combine_into(
    out: &mut Tridiagonal,
    m: &Tridiagonal,
    (c1, a): (f64, &Tridiagonal),
    (c2, b): (f64, &Tridiagonal),
) {
    for i in 0..m.diag.len() {
        out.diag[i] = m.diag[i] + c1 * a.diag[i] + c2 * b.diag[i];
    }
    for i in 0..m.lower.len() {
        out.lower[i] = m.lower[i] + c1 * a.lower[i] + c2 * b.lower[i];
        out.upper[i] = m.upper[i] + c1 * a.upper[i] + c2 * b.upper[i];
    }
}

/// A zero or non-finite pivot in a tridiagonal solve.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SingularPivot;

/// Thomas solve of `A x = b` in place, with caller-provided scratch; fails
/// on a zero or non-finite pivot.
pub fn solve_in_place(
    a: &Tridiagonal,
    b: &mut [f64],
    pivots: &mut [f64],
    ratios: &mut [f64],
) -> Result<(), SingularPivot> {
    let n = a.dim();
    if n == 0 {
        return Ok(());
    }
    for i in 0..n {
        let mut p = a.diag[i];
        if i > 0 {
            p -= a.lower[i - 1] * ratios[i - 1];
        }
        if p == 0.0 || !p.is_finite() {
            return Err(SingularPivot);
        }
        pivots[i] = p;
        if i + 1 < n {
            ratios[i] = a.upper[i] / p;
        }
    }
    b[0] /= pivots[0];
    for i in 1..n {
        b[i] = (b[i] - a.lower[i - 1] * b[i - 1]) / pivots[i];
    }
    for i in (0..n - 1).rev() {
        b[i] -= ratios[i] * b[i + 1];
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One degree of freedom, `q̈ + ω² q = 0`: the trapezoidal rule keeps the
    /// energy and lags the phase by `(ωΔt)²/12` per radian.
    #[test]
    fn harmonic_oscillator_energy_and_period_elongation() {
        let omega: f64 = 2.0;
        let one = |v: f64| Tridiagonal {
            lower: vec![],
            diag: vec![v],
            upper: vec![],
        };
        let (m, c, k) = (one(1.0), one(0.0), one(omega * omega));
        let mut state = NewmarkState {
            time: 0.0,
            displacement: vec![1.0],
            velocity: vec![0.0],
            acceleration: vec![0.0],
        };
        let mut nm = Newmark::new(1, NewmarkParameters::AVERAGE_ACCELERATION);
        nm.initialise(&m, &c, &k, &[0.0], &mut state).unwrap();
        let dt = 0.05;
        let steps = 2000;
        let mut last_up = None;
        let mut crossings = vec![];
        for _ in 0..steps {
            let prev = state.displacement[0];
            nm.step(dt, &m, &c, &k, &[0.0], &mut state).unwrap();
            let e = 0.5 * state.velocity[0].powi(2)
                + 0.5 * omega * omega * state.displacement[0].powi(2);
            assert!((e - 2.0).abs() < 1e-12, "energy {e}");
            let now = state.displacement[0];
            if prev < 0.0 && now >= 0.0 {
                let t = state.time - dt * now / (now - prev);
                if let Some(t0) = last_up {
                    crossings.push(t - t0);
                }
                last_up = Some(t);
            }
        }
        let period = crossings.iter().sum::<f64>() / crossings.len() as f64;
        let exact = 2.0 * std::f64::consts::PI / omega;
        let elongation = (omega * dt).powi(2) / 12.0;
        assert!(
            ((period / exact - 1.0) - elongation).abs() < 0.1 * elongation,
            "period {period}"
        );
    }
}
