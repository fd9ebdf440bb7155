//! Frequency responses of the linear string (SPEC §2): the JSON contract
//! of `POST /api/v1/frequency-response` with a sinusoidal wind on the
//! aerostat (and the CLI subcommand and job kind that share it), its
//! validation and its run over [`crate::numerics::string::transient`]
//! (one run per frequency); and the dispatch between it and the GE
//! base excitation ([`crate::contract::ge::charts`]) on `excitation`.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::aero::AeroBodyInput;
use super::simulate::{
    InitialStateInput, ProgressObserver, config_from, from_transient, outcome_name,
};
use crate::contract::error::{Progress, RequestError};
use crate::contract::system::grid::FrequencyGridInput;
use crate::contract::system::input::{ProfileInput, SystemInput};
use crate::contract::system::output::{Groups, groups};
use crate::numerics::aero::AirFlow;
use crate::numerics::parallel::Parallelism;
use crate::numerics::params::{InvalidInput, require_finite};
use crate::numerics::string::transient::{self, RunOutcome};

/// Most numbers (frequencies × samples) one frequency response returns.
pub const MAX_RESPONSE_VALUES: usize = 2_000_000;

fn default_response_samples() -> usize {
    200
}

/// `POST /api/v1/frequency-response`: one run per frequency of a uniform
/// wind u = U0 sin(ω t) on the aerostat; tip envelope against ω and time.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
pub struct FrequencyResponseRequest {
    #[serde(flatten)]
    pub system: SystemInput,
    #[serde(flatten)]
    pub params: FrequencyResponseParams,
}

impl std::ops::Deref for FrequencyResponseRequest {
    type Target = FrequencyResponseParams;
    fn deref(&self) -> &FrequencyResponseParams {
        &self.params
    }
}

impl std::ops::DerefMut for FrequencyResponseRequest {
    fn deref_mut(&mut self) -> &mut FrequencyResponseParams {
        &mut self.params
    }
}

/// The fields of a frequency response request besides the system.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct FrequencyResponseParams {
    pub profile: ProfileInput,
    #[schema(example = 60.0, minimum = 1e-6, maximum = 1e7)]
    pub duration_s: f64,
    /// Time step (s), shared by all runs; default set by the highest frequency.
    #[serde(default)]
    #[schema(minimum = 1e-9, maximum = 1000.0)]
    pub time_step_s: Option<f64>,
    /// Samples of the envelope in time (2..=100000).
    #[serde(default = "default_response_samples")]
    #[schema(example = 200, minimum = 2, maximum = 100000)]
    pub samples: usize,
    #[serde(default)]
    pub initial: InitialStateInput,
    /// The aerostat as an aerodynamic body.
    pub aero: AeroBodyInput,
    /// U0 (m/s).
    #[schema(example = 10.0, minimum = -200.0, maximum = 200.0)]
    pub wind_amplitude_m_s: f64,
    /// ω (rad/s): a list, or `{min, max, count}` evenly spaced.
    pub frequencies_rad_s: FrequencyGridInput,
}

#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct FrequencyResponseResponse {
    pub frequencies_rad_s: Vec<f64>,
    pub time_s: Vec<f64>,
    /// `envelope_m[i][j]`: max |tip deflection| for frequency i over the
    /// window ending at time_s[j] (m).
    pub envelope_m: Vec<Vec<f64>>,
    /// Largest tip deflection of each run (m) and when (s).
    pub peak_amplitude_m: Vec<f64>,
    pub peak_time_s: Vec<f64>,
    /// Outcome of each run (`completed`, `diverged`, `length_collapsed`).
    pub outcomes: Vec<String>,
    pub time_step_s: f64,
    pub steps_per_run: usize,
    pub groups: Groups,
    pub elements: usize,
}

/// Number of runs a frequency-response request asks for (admission limits).
pub fn frequency_response_runs(req: &FrequencyResponseRequest) -> usize {
    req.frequencies_rad_s.count()
}

/// A frequency response as a request sets it up: the model, the profile,
/// the frequencies and the configuration of each run.
struct Setup {
    model: crate::numerics::string::StringModel,
    profile: crate::numerics::profile::Profile,
    frequencies: Vec<f64>,
    config: transient::TransientConfig,
}

fn setup(req: &FrequencyResponseRequest) -> Result<Setup, RequestError> {
    let model = req.system.model()?;
    let sys = model.system;
    let profile = req.profile.profile(sys.initial_length_m)?;
    let frequencies = req
        .frequencies_rad_s
        .values("frequencies_rad_s", FrequencyGridInput::BOUNDS)?;
    if frequencies.len().saturating_mul(req.samples) > MAX_RESPONSE_VALUES {
        return Err(InvalidInput::new(
            "samples",
            format!(
                "{} frequencies × {} samples exceed the limit of {MAX_RESPONSE_VALUES} values",
                frequencies.len(),
                req.samples
            ),
        )
        .into());
    }
    require_finite("wind_amplitude_m_s", req.wind_amplitude_m_s)?;
    let highest = frequencies.iter().copied().fold(0.0, f64::max);
    let aero = req.aero.aerodynamics(
        AirFlow::sinusoidal(req.wind_amplitude_m_s, highest)?,
        sys.aerostat_mass_kg,
        "aero",
    )?;
    let config = config_from(
        req.duration_s,
        req.time_step_s,
        req.samples,
        &req.initial,
        Some(aero),
        None,
    )?;
    Ok(Setup {
        model,
        profile,
        frequencies,
        config,
    })
}

/// The size of the runs a request asks for: runs, time steps of each and
/// elements, as the runs fix them (None: the request is invalid, and its
/// run says why).
pub fn run_size(req: &FrequencyResponseRequest) -> Option<(usize, usize, usize)> {
    let Setup {
        model,
        profile,
        frequencies,
        config,
    } = setup(req).ok()?;
    let plan = transient::plan(&model, &profile, &config).ok()?;
    Some((frequencies.len(), plan.steps, model.elements()))
}

/// Runs a [`FrequencyResponseRequest`]: the runs fan out on rayon when
/// `parallelism` says so (results identical to serial). Progress counts
/// finished runs.
pub fn frequency_response(
    req: &FrequencyResponseRequest,
    parallelism: Parallelism,
    progress: &dyn Progress,
) -> Result<FrequencyResponseResponse, RequestError> {
    let Setup {
        model,
        profile,
        frequencies,
        config,
    } = setup(req)?;
    let sys = model.system;
    let fr = crate::numerics::string::frequency_response::frequency_response(
        &model,
        &profile,
        &config,
        req.wind_amplitude_m_s,
        &frequencies,
        parallelism,
        &ProgressObserver(progress),
    )
    .map_err(from_transient)?;
    if progress.cancelled()
        || fr
            .outcomes
            .iter()
            .any(|o| matches!(o, RunOutcome::Cancelled { .. }))
    {
        return Err(RequestError::Cancelled);
    }
    Ok(FrequencyResponseResponse {
        frequencies_rad_s: fr.frequencies_rad_s,
        time_s: fr.time_s,
        envelope_m: fr.envelope_m,
        peak_amplitude_m: fr.peak_m,
        peak_time_s: fr.peak_time_s,
        outcomes: fr
            .outcomes
            .iter()
            .map(|o| outcome_name(*o).0.to_string())
            .collect(),
        time_step_s: fr.time_step_s,
        steps_per_run: fr.steps,
        groups: groups(&sys),
        elements: model.elements(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contract::error::NoProgress;
    use crate::contract::parse;

    const SYSTEM: &str = r#""cable": {"density_kg_m3": 7800, "area_m2": 1e-5},
        "aerostat": {"net_buoyancy_n": 1000, "mass_kg": 10}, "initial_length_m": 1, "model": {"elements": 20}"#;

    #[test]
    fn frequency_response_runs_and_validates() {
        let body = format!(
            r#"{{ {SYSTEM}, "profile": {{"kind": "constant_rate", "rate_m_s": 1}}, "duration_s": 10, "samples": 20,
                "aero": {{"radius_m": 0.5}}, "wind_amplitude_m_s": 10,
                "frequencies_rad_s": {{"min": 1, "max": 4, "count": 4}} }}"#
        );
        let req: FrequencyResponseRequest = parse(body.as_bytes()).unwrap();
        let resp = frequency_response(&req, Parallelism::Rayon, &NoProgress).unwrap();
        assert_eq!(resp.frequencies_rad_s, vec![1.0, 2.0, 3.0, 4.0]);
        assert_eq!(resp.envelope_m.len(), 4);
        assert!(resp.envelope_m.iter().all(|e| e.len() == 20));
        assert!(resp.outcomes.iter().all(|o| o == "completed"));
        let grid = |v: serde_json::Value| serde_json::from_value::<FrequencyGridInput>(v).unwrap();
        let refused = |g: serde_json::Value| {
            let mut bad = req.clone();
            bad.frequencies_rad_s = grid(g);
            match frequency_response(&bad, Parallelism::Serial, &NoProgress) {
                Err(RequestError::Invalid(e)) => e.field,
                other => panic!("accepted: {:?}", other.map(|r| r.frequencies_rad_s)),
            }
        };
        let max = crate::numerics::string::frequency_response::MAX_FREQUENCIES;
        assert_eq!(
            refused(serde_json::json!({"min": 1, "max": 4, "count": max + 1})),
            "frequencies_rad_s.count"
        );
        assert_eq!(
            refused(serde_json::json!({"min": 1, "max": 0.5, "count": 4})),
            "frequencies_rad_s.max"
        );
        assert_eq!(
            refused(serde_json::json!({"min": -1, "max": 4, "count": 4})),
            "frequencies_rad_s.min"
        );
        assert_eq!(
            refused(serde_json::json!([1, 2, 20000])),
            "frequencies_rad_s[2]"
        );
        assert_eq!(
            refused(serde_json::json!(vec![1.0; max + 1])),
            "frequencies_rad_s"
        );
        // The list of the grid's values gives the same answer, bit for bit.
        let mut listed = req.clone();
        listed.frequencies_rad_s = grid(serde_json::json!([1.0, 2.0, 3.0, 4.0]));
        assert_eq!(
            frequency_response(&listed, Parallelism::Serial, &NoProgress).unwrap(),
            resp
        );
    }
}
