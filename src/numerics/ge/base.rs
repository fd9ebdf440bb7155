//! Base excitation of the GE cable (thesis ch. 8.2–8.3): the platform
//! moves as `r(t) = R0 sin(ω0 t)` across the guide; the equations are
//! written in the platform frame ([`BaseMotion`]: inertial load `−A_ρ r̈`
//! on the transverse equation, the `−γ̃ l² r̈` of (8.2)). For each forcing
//! frequency on a grid the cable is marched from rest over a fixed
//! duration, and the response is the largest absolute sideways excursion
//! of the cable's top, `max_t |u2(1, t) + r(t)|`. The amplitude gain (8.3)
//! is `20 log10(A(ω0)/A(ω_ref))` with the reference run at `ω_ref` (the
//! thesis uses `ω̄_ref = 0.01`), so slow shaking has a gain near 0 dB.
//!
//! Runs are independent: they fan out on rayon when asked and the result
//! equals the serial sweep bit for bit.
//!
//! The thesis's GE scales (§5.6): `t̄ = t √(EI/I_ρ)/L0`, `ω̄ = ω L0 √(I_ρ/EI)`,
//! `ṽ = L̇ √(I_ρ/EI)` — see [`Section::time_scale_s`].

use std::sync::atomic::{AtomicUsize, Ordering};

use rayon::prelude::*;

use super::element::TipLoad;
use super::solver::{
    self, BaseMotion, Damping, Drive, EndLoads, Integrator, LengthHistory, NewtonConfig, State,
};
use super::{GeModel, Section};
use crate::numerics::parallel::Parallelism;
use crate::numerics::params::{InvalidInput, require_positive};

/// Largest number of forcing frequencies of one sweep.
pub const MAX_FREQUENCIES: usize = 2_000;

impl Section {
    /// The GE time scale `L0 √(I_ρ/EI)` (s): `t = t̄ · scale`,
    /// `ω = ω̄ / scale`, `L̇ = ṽ L0 / scale`.
    pub fn time_scale_s(&self, reference_length_m: f64) -> f64 {
        reference_length_m * (self.rotary_inertia_kg_m / self.bending_stiffness_n_m2).sqrt()
    }
}

/// A frequency sweep under base excitation.
#[derive(Clone, Debug)]
pub struct BaseExcitationProblem {
    pub model: GeModel,
    pub length: LengthHistory,
    /// Steady load on the aerostat (net buoyancy along `E1`), if any.
    pub steady_tip_load: TipLoad,
    /// Platform amplitude `R0` (m).
    pub amplitude_m: f64,
    /// Forcing frequencies `ω0` (rad/s).
    pub frequencies_rad_s: Vec<f64>,
    /// The normalising run's frequency (rad/s).
    pub reference_frequency_rad_s: f64,
    pub duration_s: f64,
    pub time_step_s: f64,
    pub newton: NewtonConfig,
}

/// Response at one forcing frequency.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ResponsePoint {
    pub frequency_rad_s: f64,
    /// `max_t |u2(1,t) + r(t)|` (m).
    pub max_tip_amplitude_m: f64,
    /// Amplitude gain (8.3) (dB).
    pub gain_db: f64,
    /// `false` if Newton failed or the run was cancelled before the end
    /// (the amplitude is then the largest seen so far).
    pub completed: bool,
    pub steps: usize,
}

#[derive(Clone, Debug, PartialEq)]
pub struct FrequencyResponse {
    /// The reference run (gain 0 dB by definition).
    pub reference: ResponsePoint,
    pub points: Vec<ResponsePoint>,
}

impl BaseExcitationProblem {
    pub fn validate(&self) -> Result<(), InvalidInput> {
        require_positive("base.amplitude_m", self.amplitude_m)?;
        require_positive(
            "base.reference_frequency_rad_s",
            self.reference_frequency_rad_s,
        )?;
        require_positive("duration_s", self.duration_s)?;
        require_positive("numerics.time_step_s", self.time_step_s)?;
        if self.frequencies_rad_s.is_empty() || self.frequencies_rad_s.len() > MAX_FREQUENCIES {
            return Err(InvalidInput::new(
                "frequencies_rad_s",
                format!(
                    "must list between 1 and {MAX_FREQUENCIES} frequencies, got {}",
                    self.frequencies_rad_s.len()
                ),
            ));
        }
        for (i, &w) in self.frequencies_rad_s.iter().enumerate() {
            require_positive(&format!("frequencies_rad_s[{i}]"), w)?;
        }
        let steps = self.duration_s / self.time_step_s;
        if steps > solver::MAX_STEPS as f64 {
            return Err(InvalidInput::new(
                "numerics.time_step_s",
                format!(
                    "the run would take {steps:.0} steps; at most {} are allowed",
                    solver::MAX_STEPS
                ),
            ));
        }
        if let LengthHistory::Profile(p) = &self.length
            && let Some(stop) = p.stop_time_s()
            && stop < self.duration_s
            && p.kinematics(stop).length_m <= 0.0
        {
            return Err(InvalidInput::new(
                "profile",
                format!("the cable is fully retrieved at {stop:.3} s, before the run ends"),
            ));
        }
        Ok(())
    }

    fn drive(&self, frequency_rad_s: f64) -> Drive {
        Drive {
            length: self.length.clone(),
            loads: EndLoads::steady(self.steady_tip_load),
            damping: Damping::default(),
            base: BaseMotion {
                amplitude_m: self.amplitude_m,
                circular_frequency_rad_s: frequency_rad_s,
            },
            aero: None,
        }
    }

    /// One run at `ω0`: the largest absolute tip excursion.
    pub fn run_one(
        &self,
        frequency_rad_s: f64,
        cancel: &(dyn Fn() -> bool + Sync),
    ) -> ResponsePoint {
        let model = &self.model;
        let drive = self.drive(frequency_rad_s);
        let kin = drive.length.kinematics(0.0);
        let mut point = ResponsePoint {
            frequency_rad_s,
            max_tip_amplitude_m: 0.0,
            gain_db: 0.0,
            completed: false,
            steps: 0,
        };
        let Ok(q) = solver::static_solve(model, kin, self.steady_tip_load, 2, self.newton) else {
            return point;
        };
        let v = vec![0.0; q.len()];
        let Some(a) = solver::initial_acceleration(model, &drive, 0.0, &q, &v) else {
            return point;
        };
        let start = State {
            time_s: 0.0,
            q,
            v,
            a,
        };
        let top = GeModel::dof(model.elements, 1);
        let steps = (self.duration_s / self.time_step_s).round() as usize;
        let mut integrator = Integrator::new(model, &drive, start, self.time_step_s, self.newton);
        for step in 1..=steps {
            if step % 64 == 0 && cancel() {
                return point;
            }
            if integrator.step().is_err() {
                return point;
            }
            point.steps = step;
            let s = &integrator.state;
            let x = (s.q[top] + drive.base.displacement_m(s.time_s)).abs();
            point.max_tip_amplitude_m = point.max_tip_amplitude_m.max(x);
        }
        point.completed = true;
        point
    }
}

/// The sweep. `progress(done, total)` is called as runs finish (the
/// reference run included).
pub fn frequency_response(
    problem: &BaseExcitationProblem,
    parallelism: Parallelism,
    progress: &(dyn Fn(usize, usize) + Sync),
    cancel: &(dyn Fn() -> bool + Sync),
) -> Result<FrequencyResponse, InvalidInput> {
    problem.validate()?;
    let mut omegas = vec![problem.reference_frequency_rad_s];
    omegas.extend_from_slice(&problem.frequencies_rad_s);
    let total = omegas.len();
    let done = AtomicUsize::new(0);
    let run = |w: &f64| {
        let p = problem.run_one(*w, cancel);
        progress(done.fetch_add(1, Ordering::Relaxed) + 1, total);
        p
    };
    let mut all: Vec<ResponsePoint> = match parallelism {
        Parallelism::Serial => omegas.iter().map(run).collect(),
        Parallelism::Rayon => omegas.par_iter().map(run).collect(),
    };
    let reference_amplitude = all[0].max_tip_amplitude_m;
    for p in &mut all {
        p.gain_db = 20.0 * (p.max_tip_amplitude_m / reference_amplitude).log10();
    }
    let reference = all.remove(0);
    Ok(FrequencyResponse {
        reference,
        points: all,
    })
}

/// Indices of the local maxima of the gain (strictly above both
/// neighbours), in frequency order.
pub fn resonance_peaks(points: &[ResponsePoint]) -> Vec<usize> {
    (1..points.len().saturating_sub(1))
        .filter(|&i| {
            points[i].gain_db > points[i - 1].gain_db && points[i].gain_db > points[i + 1].gain_db
        })
        .collect()
}
