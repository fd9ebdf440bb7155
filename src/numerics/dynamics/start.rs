//! The start of a run: at rest in the static equilibrium of the steady
//! flow (see the module docs of [`super`]): the §6 shooting solution on the
//! mesh, relaxed by Newton's method to the equilibrium of the discrete
//! forces, with the payout velocity of the material if the length changes
//! at `t = 0`.

use super::blocks::{self, V2, ZERO, norm, scale};
use super::model::{self, Evaluation, Length, evaluate};
use super::problem::{DynamicsError, DynamicsProblem};
use super::state::State;
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
    // The guess: from the winch, each segment at its continuum strain
    // `T/EA`, pointing at the continuum's point `s_i`. Placing the nodes on
    // the curve itself leaves the chords of a curved, lightly loaded lower
    // tether shorter than their unstretched length (2.7 % at 20 m segments
    // where the 1000 m tether lies low in 8 m/s): slack, stiffness zero, and
    // Newton stuck with a force of 27 N left.
    let seg0 = len0.length_m / segments as f64;
    let mut pos: Vec<V2> = Vec::with_capacity(segments);
    let mut prev = [0.0f64; 2];
    for (a, b) in equilibrium.shape.iter().zip(&equilibrium.shape[1..]) {
        let target = [b.x_m, b.z_m];
        let d = blocks::sub(target, prev);
        let r = norm(d);
        let strain = 0.5 * (a.tension_n + b.tension_n).max(0.0) / p.axial_stiffness_n;
        let next = if r > 0.0 {
            blocks::add(prev, scale(seg0 * (1.0 + strain) / r, d))
        } else {
            target
        };
        pos.push(next);
        prev = next;
    }
    let vel = vec![[0.0; 2]; segments];
    let at_rest = Length {
        rate_m_s: 0.0,
        acceleration_m_s2: 0.0,
        ..len0
    };
    // The steady flow plus the wind change just before t = 0: a gust that
    // starts at t = 0 (a step at `time_s: 0`) acts on the run, not on its start.
    let du = problem.gust_change_m_s(-f64::MIN_POSITIVE);
    let flow = &problem.flow;
    let wind = |_x: f64, z: f64| flow.speed_m_s(z) + du;
    let mut ev = Evaluation::new(segments);
    let mut trial = Evaluation::new(segments);
    let scale_n = problem.aerostat.net_buoyancy_n;
    let mut residual = f64::INFINITY;
    let mut lower = vec![ZERO; segments];
    let mut diag = vec![ZERO; segments];
    let mut upper = vec![ZERO; segments];
    let mut rhs = vec![[0.0; 2]; segments];
    let mut moved = pos.clone();
    let seg = len0.length_m / segments as f64;
    // Roundoff floor: a position known to ε|R| gives a force error of about EA ε |R| / l.
    let floor = 1e-11 * scale_n + 64.0 * f64::EPSILON * p.axial_stiffness_n * segments as f64;
    let sum_sq = |ev: &Evaluation| {
        ev.force
            .iter()
            .map(|f| f[0] * f[0] + f[1] * f[1])
            .sum::<f64>()
    };
    evaluate(&p, at_rest, &pos, &vel, &wind, false, &mut ev);
    let mut stalled = false;
    let mut previous = f64::INFINITY;
    for it in 0..MAX_STATIC_ITERATIONS {
        residual = ev.force.iter().map(|f| norm(*f)).fold(0.0, f64::max);
        // Less than halving the force left is no longer Newton: stalled.
        stalled |= residual >= 0.5 * previous;
        previous = residual;
        if !residual.is_finite() {
            break;
        }
        // At the floor, or where no step lowers the force left any more
        // and it is below 1e-5 of the buoyancy (roundoff of short stiff
        // segments in a log law: 200 segments of 5 m stall at 1e-3 N).
        if residual <= floor || (stalled && residual <= 1e-5 * scale_n) {
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
        // K δ = −P with K = ∂P/∂R by differences (exact in every term:
        // drag on the tangent and on the shear included).
        difference_jacobian(
            &p, at_rest, &pos, &vel, &wind, &ev, &mut trial, &mut lower, &mut diag, &mut upper,
        );
        for k in 0..segments {
            rhs[k] = scale(-1.0, ev.force[k]);
        }
        if !model::solve_tridiagonal(&lower, &mut diag, &upper, &mut rhs) {
            // A singular difference Jacobian (at the roundoff floor): stalled.
            if residual <= 1e-5 * scale_n && !stalled {
                stalled = true;
                continue;
            }
            break;
        }
        // Damp large corrections (a tenth of a segment at most per pass),
        // then halve until the force imbalance falls.
        let big = rhs.iter().map(|d| norm(*d)).fold(0.0, f64::max);
        let mut factor = if big > 0.1 * seg {
            0.1 * seg / big
        } else {
            1.0
        };
        let before = sum_sq(&ev);
        stalled = true;
        for _ in 0..30 {
            for ((m, x), d) in moved.iter_mut().zip(&pos).zip(&rhs) {
                *m = [x[0] + factor * d[0], x[1] + factor * d[1]];
            }
            evaluate(&p, at_rest, &moved, &vel, &wind, false, &mut trial);
            let after = sum_sq(&trial);
            if after.is_finite() && after < before {
                stalled = false;
                break;
            }
            factor *= 0.5;
        }
        if !stalled {
            std::mem::swap(&mut pos, &mut moved);
            std::mem::swap(&mut ev, &mut trial);
        }
    }
    Err(DynamicsError::NoStaticEquilibrium {
        residual_n: residual,
    })
}

/// Most static Newton iterations.
const MAX_STATIC_ITERATIONS: usize = 200;

/// `∂P/∂R` of the static forces at `pos` (forces `ev`) by forward
/// differences, three colours × two directions: a node's position enters
/// the forces of its two neighbours and its own only (the tension of its
/// two segments, the drag tangents of its neighbours), so the Jacobian is
/// block-tridiagonal and nodes three apart are perturbed together.
#[allow(clippy::too_many_arguments)]
fn difference_jacobian(
    p: &model::Parameters,
    len: Length,
    pos: &[V2],
    vel: &[V2],
    wind: &dyn Fn(f64, f64) -> f64,
    ev: &Evaluation,
    trial: &mut Evaluation,
    lower: &mut [[[f64; 2]; 2]],
    diag: &mut [[[f64; 2]; 2]],
    upper: &mut [[[f64; 2]; 2]],
) {
    let n = pos.len();
    let seg = len.length_m / n as f64;
    let mut moved = pos.to_vec();
    let step: Vec<f64> = pos
        .iter()
        .map(|r| f64::EPSILON.sqrt() * (norm(*r) + seg))
        .collect();
    for colour in 0..3 {
        for d in 0..2 {
            moved.copy_from_slice(pos);
            for k in (colour..n).step_by(3) {
                moved[k][d] += step[k];
            }
            evaluate(p, len, &moved, vel, wind, false, trial);
            for r in 0..n {
                for (k, block) in [
                    (r.wrapping_sub(1), &mut lower[r]),
                    (r, &mut diag[r]),
                    (r + 1, &mut upper[r]),
                ] {
                    if k < n && k % 3 == colour {
                        let h = step[k];
                        block[0][d] = (trial.force[r][0] - ev.force[r][0]) / h;
                        block[1][d] = (trial.force[r][1] - ev.force[r][1]) / h;
                    }
                }
            }
        }
    }
}
