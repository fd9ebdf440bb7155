//! How an oscillation responds to a schedule: the transient run of the
//! schedule itself (FE string, Newmark, [`crate::numerics::string::transient`])
//! from a small first-mode disturbance, and the WKB growth of the
//! one-mode model (thesis (3.12), [`crate::numerics::string::reduced`]):
//!
//! ```text
//! A(l) ∝ [ψ(l)(2m̃ + l)]^(-1/2),   ψ = √[(α/l + γ)/(2m̃ + l)],   Ẽ ∝ ψ
//! ```
//!
//! so the amplitude amplification from `l₀` to `l₁` is
//! `√(ψ₀(2m̃ + l₀) / (ψ₁(2m̃ + l₁)))`, independent of the rate when the
//! rate is slow (adiabatic). Shortening has negative damping at every
//! instant (the energy of the mode grows as `ψ`), which is why a retrieval
//! plan reports the growth instead of a stability verdict.
//!
//! A retrieval with an amplification limit is slowed (rate limit halved,
//! then bisected) until the transient amplification is within it.

use crate::numerics::params::{Kinematics, NondimState};
use crate::numerics::plan::schedule::{self, PlanOutcome, Schedule};
use crate::numerics::plan::{BindingLimit, PlanProblem};
use crate::numerics::profile::Profile;
use crate::numerics::string::StringModel;
use crate::numerics::string::reduced::ReducedModel;
use crate::numerics::string::transient::{
    self, InitialState, Observer, RunOutcome, TransientConfig, TransientError,
};

/// Rate intervals of the table that drives the transient run.
pub const TRANSIENT_TABLE_INTERVALS: usize = 400;
/// Output samples of the transient run (each carries the envelope since
/// the previous one, so no peak is lost).
pub const TRANSIENT_SAMPLES: usize = 4000;
/// Halvings of the rate limit tried to meet an amplification limit.
pub const MAX_HALVINGS: usize = 6;
/// Bisection steps after the halvings.
pub const BISECTIONS: usize = 6;

/// WKB growth between two lengths (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WkbGrowth {
    /// Tip amplitude at the end over the start.
    pub amplitude: f64,
    /// Mode energy at the end over the start (`ψ₁/ψ₀`).
    pub energy: f64,
}

/// WKB growth of the first mode from `start_m` to `end_m`; `None` when
/// either length is beyond the one-mode model's static limit.
pub fn wkb_growth(model: &StringModel, start_m: f64, end_m: f64) -> Option<WkbGrowth> {
    let reduced = ReducedModel::new(model.system);
    let l0 = model.system.initial_length_m;
    let (a, b) = (start_m / l0, end_m / l0);
    let amplitude = reduced.wkb_amplitude(b, a, 1.0)?;
    let energy = reduced.frequency(b)? / reduced.frequency(a)?;
    Some(WkbGrowth { amplitude, energy })
}

/// The same adiabatic invariant with the FE string's own first rest mode
/// `φ` (unit tip) in place of `sin(πζ/2)`: the symmetric part of `C` is
/// `dM/dt̄`, so `(ω φᵀMφ) A²` is conserved and `A₁/A₀ = √(ω₀ m₀ / (ω₁ m₁))`.
/// `None` when either length cannot hang at rest.
pub fn wkb_growth_fe(model: &StringModel, start_m: f64, end_m: f64) -> Option<f64> {
    let l0 = model.system.initial_length_m;
    let action = |length_m: f64| -> Option<f64> {
        let l = length_m / l0;
        let (phi, omega) =
            crate::numerics::string::rest_modes::rest_mode_shape(model, l, 0.0, 1).ok()?;
        if !(omega > 0.0) {
            return None;
        }
        let mass = model
            .matrices(NondimState {
                length: l,
                rate: 0.0,
                acceleration: 0.0,
            })
            .mass;
        let mut m_phi = vec![0.0; phi.len()];
        mass.mul_vec(&phi, &mut m_phi);
        let m: f64 = phi.iter().zip(&m_phi).map(|(a, b)| a * b).sum();
        Some(omega * m)
    };
    Some((action(start_m)? / action(end_m)?).sqrt())
}

/// The response of the FE string to the schedule.
#[derive(Clone, Debug, PartialEq)]
pub struct TransientCheck {
    pub elements: usize,
    pub time_step_s: f64,
    pub steps: usize,
    /// Run length: the schedule (s).
    pub run_duration_s: f64,
    pub initial_tip_deflection_m: f64,
    /// Largest `|y_tip|` over the run (m).
    pub peak_tip_deflection_m: f64,
    /// First-mode tip amplitude at the end, at rest (m).
    pub final_tip_amplitude_m: f64,
    /// `final / initial`.
    pub amplification: f64,
    pub outcome: RunOutcome,
}

/// The schedule as a piecewise-linear rate table: the schedule's own knots
/// (exact for a piecewise constant-acceleration schedule, whose rate is
/// piecewise linear), each interval with a jerk split into pieces of about
/// `h = duration / TRANSIENT_TABLE_INTERVALS`, and knots closer than `h`
/// to the last one kept dropped (a schedule riding the stability ceiling
/// has one knot per grid segment: its corners are then cut by at most
/// `h`, as on a uniform table). Holding at rest after the end. Few points
/// keep the run cheap: the profile's evaluation at every time step is
/// linear in the table's length.
pub fn rate_table(s: &Schedule, initial_length_m: f64) -> Result<Profile, TransientError> {
    let h = s.duration_s / TRANSIENT_TABLE_INTERVALS as f64;
    let mut candidates: Vec<f64> = Vec::with_capacity(s.knots.len() + 16);
    for w in s.knots.windows(2) {
        let (t0, t1) = (w[0].time_s, w[1].time_s);
        candidates.push(t0);
        if w[0].jerk_m_s3 != 0.0 && t1 - t0 > h {
            let pieces = ((t1 - t0) / h).ceil() as usize;
            candidates.extend((1..pieces).map(|q| t0 + (t1 - t0) * q as f64 / pieces as f64));
        }
    }
    let mut times: Vec<f64> = vec![0.0];
    for t in candidates {
        if t - times[times.len() - 1] >= h * (1.0 - 1e-9) {
            times.push(t);
        }
    }
    let end = s.duration_s;
    if end - times[times.len() - 1] < h * (1.0 - 1e-9) && times.len() > 1 {
        times.pop();
    }
    times.push(end);
    let mut points: Vec<(f64, f64)> = times.iter().map(|&t| (t, s.at(t).rate_m_s)).collect();
    if let Some(first) = points.first_mut() {
        first.1 = 0.0;
    }
    if let Some(last) = points.last_mut() {
        last.1 = 0.0;
    }
    Ok(Profile::piecewise_linear_rate(
        initial_length_m,
        &points,
        None,
    )?)
}

/// Runs the schedule on the FE string from the first mode at rest with
/// the tip displaced by `disturbance_m`. The final amplitude is the
/// first-mode amplitude of the state at the end (the cable is then at rest
/// and conservative): `√(a² + (b/ω)²)` with `a`, `b` the `M`-projections of
/// the displacement and velocity on the rest mode `φ` (unit tip), `ω` its
/// frequency.
pub fn check_transient(
    model: &StringModel,
    s: &Schedule,
    disturbance_m: f64,
    observer: &dyn Observer,
) -> Result<TransientCheck, TransientError> {
    let l_start = s.knots.first().map_or(0.0, |k| k.length_m);
    // The run's length scale is the start of the schedule.
    let mut system = model.system;
    system.initial_length_m = l_start;
    let model = StringModel::with_operators(system, model.operators.clone());
    let profile = rate_table(s, l_start)?;
    let run_duration = s.duration_s;
    let config = TransientConfig {
        duration_s: run_duration,
        time_step_s: None,
        samples: TRANSIENT_SAMPLES,
        initial: InitialState::Mode {
            mode: 1,
            tip_deflection_m: disturbance_m,
        },
        aero: None,
        eigen: None,
    };
    let run = transient::simulate(&model, &profile, &config, observer)?;
    let peak = run
        .samples
        .iter()
        .map(|x| x.tip_envelope_m.max(x.tip_deflection_m.abs()))
        .fold(0.0, f64::max);
    let final_amp = if matches!(run.outcome, RunOutcome::Completed) {
        let l_end = run.final_kinematics.length_m / l_start;
        let (phi, omega) =
            crate::numerics::string::rest_modes::rest_mode_shape(&model, l_end, 0.0, 1)?;
        let mass = model
            .matrices(NondimState {
                length: l_end,
                rate: 0.0,
                acceleration: 0.0,
            })
            .mass;
        let mut m_phi = vec![0.0; phi.len()];
        mass.mul_vec(&phi, &mut m_phi);
        let dot = |x: &[f64]| x.iter().zip(&m_phi).map(|(a, b)| a * b).sum::<f64>();
        let norm = dot(&phi);
        let a = dot(&run.final_state.displacement) / norm;
        let b = dot(&run.final_state.velocity) / norm;
        (a * a + (b / omega).powi(2)).sqrt() * l_start
    } else {
        f64::INFINITY
    };
    Ok(TransientCheck {
        elements: model.elements(),
        time_step_s: run.time_step_s,
        steps: run.steps,
        run_duration_s: run_duration,
        initial_tip_deflection_m: disturbance_m,
        peak_tip_deflection_m: peak,
        final_tip_amplitude_m: final_amp,
        amplification: final_amp / disturbance_m.abs(),
        outcome: run.outcome,
    })
}

/// A retrieval slowed to meet an amplification limit.
#[derive(Clone, Debug, PartialEq)]
pub struct BoundedRetrieval {
    pub schedule: Schedule,
    pub check: TransientCheck,
    /// Winch rate limit used (m/s): the request's, or lower.
    pub rate_limit_m_s: f64,
    /// Whether the rate limit was lowered for the amplification limit.
    pub slowed: bool,
}

/// The fastest retrieval whose transient amplification stays within
/// `limit`: the winch rate limit is halved up to [`MAX_HALVINGS`] times,
/// then bisected [`BISECTIONS`] times between the last failing and the
/// first passing rate.
pub fn bounded_retrieval(
    problem: &PlanProblem,
    model: &StringModel,
    limit: f64,
    disturbance_m: f64,
    observer: &dyn Observer,
) -> Result<Result<BoundedRetrieval, BindingLimit>, TransientError> {
    bounded_retrieval_with(
        problem,
        model,
        limit,
        disturbance_m,
        observer,
        &schedule::PlanOptions::default(),
    )
}

/// [`bounded_retrieval`] with the air and jerk limit of `options`.
pub fn bounded_retrieval_with(
    problem: &PlanProblem,
    model: &StringModel,
    limit: f64,
    disturbance_m: f64,
    observer: &dyn Observer,
    options: &schedule::PlanOptions,
) -> Result<Result<BoundedRetrieval, BindingLimit>, TransientError> {
    let try_rate = |rate: f64| -> Result<Option<(Schedule, TransientCheck)>, TransientError> {
        let mut p = *problem;
        p.winch.max_rate_m_s = rate;
        match schedule::fastest_with(&p, options) {
            PlanOutcome::Feasible(s) => {
                let c = check_transient(model, &s, disturbance_m, observer)?;
                Ok(Some((s, c)))
            }
            PlanOutcome::Infeasible(_) => Ok(None),
        }
    };
    let full = problem.winch.max_rate_m_s;
    let mut failing = full;
    let mut last_amp = f64::NAN;
    let mut rate = full;
    for halving in 0..=MAX_HALVINGS {
        let Some((s, c)) = try_rate(rate)? else {
            break;
        };
        last_amp = c.amplification;
        if c.amplification <= limit && matches!(c.outcome, RunOutcome::Completed) {
            if halving == 0 {
                return Ok(Ok(BoundedRetrieval {
                    schedule: s,
                    check: c,
                    rate_limit_m_s: rate,
                    slowed: false,
                }));
            }
            // Bisect between `rate` (passes) and `failing`.
            let mut best = (s, c, rate);
            let (mut lo, mut hi) = (rate, failing);
            for _ in 0..BISECTIONS {
                let mid = 0.5 * (lo + hi);
                match try_rate(mid)? {
                    Some((s, c))
                        if c.amplification <= limit
                            && matches!(c.outcome, RunOutcome::Completed) =>
                    {
                        lo = mid;
                        best = (s, c, mid);
                    }
                    _ => hi = mid,
                }
            }
            return Ok(Ok(BoundedRetrieval {
                schedule: best.0,
                check: best.1,
                rate_limit_m_s: best.2,
                slowed: true,
            }));
        }
        failing = rate;
        rate *= 0.5;
        if observer.cancelled() {
            break;
        }
    }
    Ok(Err(BindingLimit::Amplification {
        amplification: last_amp,
        limit,
    }))
}

/// Winch tension rise from hauling in: the largest
/// `T_winch(L, L̈) − T_winch(L, 0) = −(m + ρA L) L̈` over the samples (N),
/// and the largest winch tension (N).
pub fn tension_rise_n(problem: &PlanProblem, samples: &[(f64, Kinematics)]) -> (f64, f64) {
    samples
        .iter()
        .fold((0.0f64, f64::NEG_INFINITY), |(rise, peak), (_, k)| {
            let t = problem.winch_tension_n(k.length_m, k.acceleration_m_s2);
            let rest = problem.winch_tension_n(k.length_m, 0.0);
            (rise.max(t - rest), peak.max(t))
        })
}
