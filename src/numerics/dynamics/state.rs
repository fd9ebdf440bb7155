//! The types a run shares between its start, its step, its outputs and
//! its loop: the state of the mesh, how a run ended and its counters (in
//! a file of their own so that `start`, `integrator`, `outputs` and `run`
//! import them without importing each other in a circle).

use super::blocks::V2;

/// Nodal positions and velocities (nodes `1 … N`; the winch is the origin).
#[derive(Clone, Debug, PartialEq)]
pub struct State {
    pub time_s: f64,
    pub positions: Vec<V2>,
    pub velocities: Vec<V2>,
}

/// How a run ended. Only [`Outcome::Completed`] covers the whole duration;
/// every other outcome's figures cover the run up to its `time_s`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Outcome {
    Completed,
    /// Newton failed even on the smallest sub-step.
    NewtonFailed {
        time_s: f64,
    },
    /// A non-finite state.
    Diverged {
        time_s: f64,
    },
    /// The aerostat went below the winch (the model has no ground: the
    /// state left the physical), at `altitude_m`.
    AerostatBelowWinch {
        time_s: f64,
        altitude_m: f64,
    },
    /// The tether and aerostat held `gained_j` more mechanical energy than
    /// they started with plus every joule the winch and the air could have
    /// put in (`put_in_j`, an upper bound), beyond the run's allowance
    /// (see `run::EnergyCheck`): the step made energy, so the state left
    /// the physical.
    EnergyGained {
        time_s: f64,
        gained_j: f64,
        put_in_j: f64,
    },
    /// The observer asked to stop.
    Stopped {
        time_s: f64,
    },
}

impl Outcome {
    /// Whether the run covered its whole duration.
    pub fn completed(&self) -> bool {
        matches!(self, Self::Completed)
    }
}

/// Counters.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Statistics {
    pub steps: usize,
    pub newton_iterations: usize,
    pub halvings: usize,
    /// Jumps of the winch rate (a stop, a start, a rate table's step)
    /// stepped onto and carried through (see `Stepper::rate_jump`).
    pub rate_jumps: usize,
    /// Steps retried as two halves because a segment went slack or
    /// snapped taut within them (see `Stepper::step`).
    pub refinements: usize,
    /// The largest energy gain over the run's allowance (see
    /// [`Outcome::EnergyGained`]), as a share of it: above 1 ends the run.
    pub energy_gain_nondim: f64,
}
