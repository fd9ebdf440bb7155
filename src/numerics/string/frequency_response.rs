//! Frequency response of the linear string to a sinusoidal wind (SPEC §2,
//! thesis ch. 4.4): one transient run ([`super::transient`]) per forcing
//! frequency of a uniform flow `u = U0 sin(ω t)`, all on one time step,
//! each reporting the tip envelope against time; serial or on rayon with
//! identical results.

use std::sync::atomic::{AtomicUsize, Ordering};

use rayon::prelude::*;

use crate::numerics::aero::AirFlow;
use crate::numerics::parallel::Parallelism;
use crate::numerics::params::{InvalidInput, require_finite};
use crate::numerics::profile::Profile;
use crate::numerics::string::StringModel;
use crate::numerics::string::transient::{
    Observer, RunOutcome, TransientConfig, TransientError, TransientRun, plan, run_planned,
};

/// Most forcing frequencies of one frequency response.
pub const MAX_FREQUENCIES: usize = 1_024;
/// Most `steps × elements × frequencies` of one frequency response.
pub const MAX_RESPONSE_WORK: usize = 20_000_000_000;

/// Frequency response: one run per forcing frequency of a uniform flow
/// `u = U0 sin(ω t)`, reporting the tip envelope against time.
#[derive(Clone, Debug, PartialEq)]
pub struct FrequencyResponse {
    pub frequencies_rad_s: Vec<f64>,
    /// Sample times (s), common to all runs.
    pub time_s: Vec<f64>,
    /// `envelope_m[i][j]`: `max |y_tip|` for frequency `i` over the window
    /// ending at `time_s[j]`.
    pub envelope_m: Vec<Vec<f64>>,
    /// Largest tip deflection of each run (m) and when (s).
    pub peak_m: Vec<f64>,
    pub peak_time_s: Vec<f64>,
    pub outcomes: Vec<RunOutcome>,
    pub time_step_s: f64,
    pub steps: usize,
}

/// Runs the frequency response. `config.aero` gives the force model and
/// the body; its flow is replaced by `U0 sin(ω t)` for each `ω`. All runs
/// share one time step (set by the highest frequency when automatic), so
/// the sample times agree. `observer.report(done, total)` counts finished
/// runs. Parallel and serial results are identical.
pub fn frequency_response(
    model: &StringModel,
    profile: &Profile,
    config: &TransientConfig,
    amplitude_m_s: f64,
    frequencies_rad_s: &[f64],
    parallelism: Parallelism,
    observer: &dyn Observer,
) -> Result<FrequencyResponse, TransientError> {
    require_finite("wind_amplitude_m_s", amplitude_m_s)?;
    if frequencies_rad_s.is_empty() || frequencies_rad_s.len() > MAX_FREQUENCIES {
        return Err(InvalidInput::new(
            "frequencies_rad_s.count",
            format!(
                "must be between 1 and {MAX_FREQUENCIES}, got {}",
                frequencies_rad_s.len()
            ),
        )
        .into());
    }
    let Some(aero) = config.aero.as_ref() else {
        return Err(InvalidInput::new(
            "aero",
            "a frequency response needs the aerostat's aerodynamics",
        )
        .into());
    };
    let with_frequency = |w: f64| -> Result<TransientConfig, InvalidInput> {
        let mut c = config.clone();
        c.eigen = None;
        let mut a = aero.clone();
        a.flow = AirFlow::sinusoidal(amplitude_m_s, w)?;
        c.aero = Some(a);
        Ok(c)
    };
    let w_max = frequencies_rad_s.iter().copied().fold(0.0, f64::max);
    for (i, &w) in frequencies_rad_s.iter().enumerate() {
        with_frequency(w)
            .map_err(|e| InvalidInput::new(format!("frequencies_rad_s[{i}]"), e.reason))?;
    }
    let plan = plan(model, profile, &with_frequency(w_max)?)?;
    let work = plan.steps as f64 * model.elements() as f64 * frequencies_rad_s.len() as f64;
    if work > MAX_RESPONSE_WORK as f64 {
        return Err(InvalidInput::new(
            "frequencies_rad_s.count",
            format!(
                "{} runs of {} steps on {} elements exceed the limit of {MAX_RESPONSE_WORK} step-elements",
                frequencies_rad_s.len(),
                plan.steps,
                model.elements()
            ),
        )
        .into());
    }
    let total = frequencies_rad_s.len();
    let done = AtomicUsize::new(0);
    observer.report(0, total);
    let one = |w: f64| -> Result<TransientRun, TransientError> {
        let c = with_frequency(w)?;
        let run = run_planned(model, profile, &c, plan, observer, false)?;
        observer.report(done.fetch_add(1, Ordering::Relaxed) + 1, total);
        Ok(run)
    };
    let runs: Vec<Result<TransientRun, TransientError>> = match parallelism {
        Parallelism::Serial => frequencies_rad_s.iter().map(|&w| one(w)).collect(),
        Parallelism::Rayon => frequencies_rad_s.par_iter().map(|&w| one(w)).collect(),
    };
    let runs = runs.into_iter().collect::<Result<Vec<_>, _>>()?;
    let time_s = runs[0].samples.iter().map(|s| s.time_s).collect();
    let mut out = FrequencyResponse {
        frequencies_rad_s: frequencies_rad_s.to_vec(),
        time_s,
        envelope_m: vec![],
        peak_m: vec![],
        peak_time_s: vec![],
        outcomes: vec![],
        time_step_s: plan.time_step_s,
        steps: plan.steps,
    };
    for run in runs {
        let (peak, at) = run.samples.iter().fold((0.0f64, 0.0), |(p, t), s| {
            if s.tip_envelope_m > p {
                (s.tip_envelope_m, s.time_s)
            } else {
                (p, t)
            }
        });
        out.envelope_m
            .push(run.samples.iter().map(|s| s.tip_envelope_m).collect());
        out.peak_m.push(peak);
        out.peak_time_s.push(at);
        out.outcomes.push(run.outcome);
    }
    Ok(out)
}
