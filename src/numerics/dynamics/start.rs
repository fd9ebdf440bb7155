//! The start of a run: at rest in the static equilibrium of the steady
//! flow (see the module docs of [`super`]): the §6 shooting solution on the
//! mesh, relaxed by Newton's method to the equilibrium of the discrete
//! forces, with the payout velocity of the material if the length changes
//! at `t = 0`.

use super::blocks::{self, V2, ZERO, norm, scale};
use super::model::{self, Evaluation, Length, evaluate};
use super::problem::{DynamicsError, DynamicsProblem};
use super::run::State;
use crate::numerics::tether::equilibrium::{Equilibrium, EquilibriumConfig};

/// The outcome of a static solve.
#[derive(Clone, Debug, PartialEq)]
pub struct StaticStart {
    pub state: State,
    pub equilibrium: Equilibrium,
    pub iterations: usize,
    /// Largest nodal force imbalance left (N).
    pub residual_n: f64,
}

/// The static start at `t = 0`: the §6 shooting solution relaxed to the
/// discrete equilibrium in the steady flow (plus `ΔU(0)`, without turbulence).
pub fn static_start(
    problem: &DynamicsProblem,
    segments: usize,
) -> Result<StaticStart, DynamicsError> {
    problem.validate()?;
    let len0 = problem.length.at(0.0);
    let eq_problem = problem.static_problem(len0.length_m);
    let equilibrium = eq_problem.solve(&EquilibriumConfig {
        steps: segments,
        max_iterations: 60,
        keep_shape: true,
    })?;
    if equilibrium.slack {
        return Err(DynamicsError::SlackStart);
    }
    let p = problem.parameters(segments);
    let mut pos: Vec<V2> = equilibrium.shape[1..]
        .iter()
        .map(|s| [s.x_m, s.z_m])
        .collect();
    let vel = vec![[0.0; 2]; segments];
    let at_rest = Length {
        rate_m_s: 0.0,
        acceleration_m_s2: 0.0,
        ..len0
    };
    let du = problem.gust_change_m_s(0.0);
    let flow = &problem.flow;
    let wind = |_x: f64, z: f64| flow.speed_m_s(z) + du;
    let mut ev = Evaluation::new(segments);
    let scale_n = problem.aerostat.net_buoyancy_n;
    let mut residual = f64::INFINITY;
    let mut lower = vec![ZERO; segments];
    let mut diag = vec![ZERO; segments];
    let mut upper = vec![ZERO; segments];
    let mut rhs = vec![[0.0; 2]; segments];
    for it in 0..100 {
        evaluate(&p, at_rest, &pos, &vel, &wind, true, &mut ev);
        residual = ev.force.iter().map(|f| norm(*f)).fold(0.0, f64::max);
        // Roundoff floor: a position known to ε|R| gives a force error of about EA ε |R| / l.
        let floor = 1e-11 * scale_n + 64.0 * f64::EPSILON * p.axial_stiffness_n * segments as f64;
        if residual <= floor {
            // Paying out (or hauling in) at t = 0: the material moves along
            // the tether at L̇, so Ṙ_i = V_i − ζ̇_i R_ζ = ζ_i L̇ R_ζ / L.
            let mut vel = vel;
            if len0.rate_m_s != 0.0 {
                let node = |i: usize| if i == 0 { [0.0; 2] } else { pos[i - 1] };
                let dz = 1.0 / segments as f64;
                for i in 1..=segments {
                    let d = if i < segments {
                        scale(0.5 / dz, blocks::sub(node(i + 1), node(i - 1)))
                    } else {
                        scale(1.0 / dz, blocks::sub(node(i), node(i - 1)))
                    };
                    vel[i - 1] = scale(i as f64 * dz * len0.rate_m_s / len0.length_m, d);
                }
            }
            return Ok(StaticStart {
                state: State {
                    time_s: 0.0,
                    positions: pos,
                    velocities: vel,
                },
                equilibrium,
                iterations: it,
                residual_n: residual,
            });
        }
        // K δ = −P with K = ∂P/∂R.
        for k in 0..segments {
            lower[k] = ev.kx[0][k];
            diag[k] = ev.kx[1][k];
            upper[k] = ev.kx[2][k];
            rhs[k] = scale(-1.0, ev.force[k]);
        }
        if !model::solve_tridiagonal(&lower, &mut diag, &upper, &mut rhs) {
            break;
        }
        // Damp large corrections (a tenth of a segment at most per pass).
        let seg = len0.length_m / segments as f64;
        let big = rhs.iter().map(|d| norm(*d)).fold(0.0, f64::max);
        let factor = if big > 0.1 * seg {
            0.1 * seg / big
        } else {
            1.0
        };
        for (x, d) in pos.iter_mut().zip(&rhs) {
            x[0] += factor * d[0];
            x[1] += factor * d[1];
        }
    }
    Err(DynamicsError::NoStaticEquilibrium {
        residual_n: residual,
    })
}
