//! Tether dynamics in the time domain (SPEC §11): a lumped-mass tether in
//! the vertical plane downwind, its unstretched length following a
//! deployment profile, the aerostat a point mass, in a wind that changes
//! in time ([`wind`]).
//!
//! * `problem`: what a run is asked and its checks;
//! * [`model`]: the moving-mesh lumped-mass equations (why no node is
//!   inserted at the winch, the forces, the Jacobian);
//! * [`blocks`]: 2×2 blocks and the block-tridiagonal solve;
//! * [`wind`]: discrete gusts, the sinusoid, seeded turbulence;
//! * `start`: the static start; `integrator`: the step; `outputs`:
//!   samples, shapes, slack, extremes; `run`: the loop;
//! * [`converged`]: the figures an operator acts on, compared between
//!   steps: their changes, error estimates, safe sides and observed order;
//! * [`reference`]: the issue-23 reference tether and its gust and
//!   turbulence cases (shared by the tests, the MoorDyn peer and the bench).
//!
//! **Step.** The generalized-α method of Chung & Hulbert (1993, J. Appl.
//! Mech. 60, 371–375) on `M(t) R̈ = P(t, R, Ṙ)`:
//!
//! ```text
//! α_m = (2ρ∞ − 1)/(ρ∞ + 1),  α_f = ρ∞/(ρ∞ + 1),  γ = ½ − α_m + α_f,  β = ¼(1 − α_m + α_f)²
//! R_{n+1} = R_n + h Ṙ_n + h² ((½ − β) a_n + β a_{n+1}),   Ṙ_{n+1} = Ṙ_n + h ((1 − γ) a_n + γ a_{n+1})
//! M((1 − α_m) a_{n+1} + α_m a_n) = P(t_{n+1−α_f}, R_{n+1−α_f}, Ṙ_{n+1−α_f})
//! ```
//!
//! second-order accurate and unconditionally stable for every spectral
//! radius `ρ∞ ∈ [0, 1]` at infinite frequency: modes with `ω h ≫ 1` (the
//! stiff axial waves of a 1000 m tether, `√(EA/ρA)` ≈ 3.6 km/s) are damped
//! by the factor `ρ∞` per step instead of limiting the step, so the step is
//! chosen for the motion of interest. `ρ∞ = 1` is the trapezoidal rule
//! (no numerical dissipation: the energy of the undamped, unforced tether
//! is conserved to `O(h²)`, checked in `tests/verification_dynamics.rs`).
//! Each step solves the residual in `a_{n+1}` by Newton's method with the
//! block-tridiagonal iteration matrix of [`model`] (`O(N)` per iteration);
//! a step whose Newton iteration fails is retried as two half steps (up to
//! [`MAX_HALVINGS`] times), and a run that still fails stops with
//! [`Outcome::NewtonFailed`]: an outcome, not an error. A step that
//! starts with a slack segment, or in the wave of a winch rate jump, is
//! refined to a sixteenth of a segment's axial period (a slack segment
//! snaps taut within one). After every step the run checks its energy
//! balance (`run::EnergyCheck`): a tether and aerostat holding more
//! mechanical energy than they started with plus all the winch and the
//! air could have put in (past [`ENERGY_ALLOWANCE`] and [`ENERGY_FLOOR`])
//! stop with [`Outcome::EnergyGained`], never `Completed`.
//!
//! **Start.** The run starts at rest in the static equilibrium of the
//! steady flow: the shooting solution of SPEC §6
//! ([`crate::numerics::tether::equilibrium`]) integrated with `N` steps
//! places the nodes at `s_i = i L/N`, and a static Newton iteration on the
//! discrete forces (`P(R) = 0`, same assembly) removes the `O(N⁻²)`
//! difference between the continuum and the lumped model, so the run does
//! not start with a spurious transient.

pub mod blocks;
pub mod converged;
mod integrator;
pub mod limits;
pub mod model;
mod outputs;
mod problem;
pub mod reference;
mod run;
mod start;
mod state;
pub mod wind;

pub use outputs::{Extreme, Sample, Shape, ShapeNode, SlackEvent};
pub use problem::{
    Aerostat, DynamicsConfig, DynamicsError, DynamicsProblem, LengthSchedule, Tether,
};
pub use run::{
    ENERGY_ALLOWANCE, ENERGY_FLOOR, Outcome, Run, State, Statistics, StepView, aerostat, magnitude,
    simulate, simulate_from,
};
pub use start::{StaticStart, static_start};
pub use wind::{GustHistory, SpectrumModel, Turbulence, TurbulenceField};

pub use limits::{
    MAX_HALVINGS, MAX_SAMPLES, MAX_SEGMENTS, MAX_SHAPES, MAX_STEPS, MAX_WORK, MIN_SEGMENTS,
};

#[cfg(test)]
mod tests {
    use super::*;
    use reference::reference_problem as problem;

    #[test]
    fn static_start_is_close_to_the_shooting_solution() {
        let p = problem(8.0);
        let s = static_start(&p, 50).unwrap();
        let top = s.state.positions[49];
        // Roundoff floor of the discrete static Newton: about 1e-9 of the
        // ~1000 N tension (measured 6.3e-7 N).
        assert!(s.residual_n < 1e-5, "{}", s.residual_n);
        assert!(
            (top[1] - s.equilibrium.altitude_m).abs() < 1e-3 * 1000.0,
            "{} {}",
            top[1],
            s.equilibrium.altitude_m
        );
    }

    #[test]
    fn equilibrium_stays_put_for_a_minute() {
        let p = problem(8.0);
        let cfg = DynamicsConfig {
            duration_s: 60.0,
            ..Default::default()
        };
        let run = simulate(&p, &cfg).unwrap();
        assert_eq!(run.outcome, Outcome::Completed);
        let s0 = run.samples[0];
        let s1 = *run.samples.last().unwrap();
        assert!((s1.aerostat_altitude_m - s0.aerostat_altitude_m).abs() < 1e-6);
        // Relative 1e-7 of the tension (measured 7e-9 over 60 s: the static
        // start's roundoff floor carried by the integrator).
        assert!(
            (s1.winch_tension_n - s0.winch_tension_n).abs() < 1e-7 * s0.winch_tension_n.abs(),
            "{} {}",
            s0.winch_tension_n,
            s1.winch_tension_n
        );
    }
}
