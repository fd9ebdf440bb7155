//! What a job computes: one request of a known kind, or a batch of them.
//!
//! A submission is `{"kind": K, "request": {...}}` with `K` one of
//! [`JobItem::KINDS`] and the request the same JSON as `POST /api/v1/<K>`,
//! or `{"kind": "batch", "request": [{"kind": K, "request": {...}}, ...]}`.
//!
//! Adding a kind: implement [`JobKind`] for its request type and add one
//! line to the `job_kinds!` invocation below.

use std::sync::atomic::{AtomicUsize, Ordering};

use rayon::prelude::*;
use serde::Serialize;
use serde_json::Value;
use serde_json::value::RawValue;
use utoipa::ToSchema;

use crate::contract::dto::*;
use crate::contract::ge_charts::{self, AnyChartRequest, AnyFrequencyResponseRequest};
use crate::contract::ge_critical::{self, AnyCriticalRequest, AnyStabilityRequest};
use crate::contract::run::{self, MAX_MODES};
use crate::contract::simulate::{self, AnySimulateRequest};
use crate::contract::transient::{self, FrequencyResponseRequest};
use crate::contract::{self, Progress, RequestError};
use crate::limits::Limits;
use crate::numerics::chart::{self, MAX_CHART_POINTS, Parallelism};
use crate::numerics::params::{InvalidInput, require_finite, require_positive};

/// A request type that can run as a job.
pub trait JobKind: Serialize + Sized {
    /// The `kind` of the submission, also the path of its synchronous route.
    const NAME: &'static str;
    /// Parses the request body (errors name the field).
    fn parse_body(body: &[u8]) -> Result<Self, RequestError>;
    /// Every check that needs no solve, so that bad input is refused at
    /// submission (422) instead of failing later.
    fn validate(&self) -> Result<(), RequestError>;
    /// Computes the answer (JSON text). Long kinds report progress and stop
    /// when `progress.cancelled()`.
    fn run(&self, progress: &dyn Progress) -> Result<String, RequestError>;
    /// An upper estimate of the answer's size, from the validated request
    /// (see [`crate::jobs::estimate`]).
    fn estimate(&self) -> Estimate;
}

pub use super::estimate::Estimate;
use super::estimate::{self as est, Estimate as E};

/// The answer as JSON; never one holding a non-finite number (the job
/// fails `invalid_input`).
fn to_json(value: &impl Serialize) -> Result<String, RequestError> {
    crate::contract::finite::to_string(value)
}

impl JobKind for StabilityRequest {
    const NAME: &'static str = "stability";
    fn parse_body(body: &[u8]) -> Result<Self, RequestError> {
        contract::parse(body)
    }
    fn validate(&self) -> Result<(), RequestError> {
        self.system.model()?;
        require_positive("state.length_m", self.params.state.length_m)?;
        require_finite("state.rate_m_s", self.params.state.rate_m_s)?;
        require_finite(
            "state.acceleration_m_s2",
            self.params.state.acceleration_m_s2,
        )?;
        if self.params.modes == 0 || self.params.modes > MAX_MODES {
            return Err(InvalidInput::new(
                "modes",
                format!(
                    "must be between 1 and {MAX_MODES}, got {}",
                    self.params.modes
                ),
            )
            .into());
        }
        Ok(())
    }
    fn run(&self, _: &dyn Progress) -> Result<String, RequestError> {
        to_json(&run::stability(self)?)
    }
    fn estimate(&self) -> Estimate {
        E::bytes(
            "modes",
            est::STABILITY_BASE as f64 + self.params.modes as f64 * est::PER_EIGENVALUE as f64,
        )
    }
}

impl JobKind for CriticalRequest {
    const NAME: &'static str = "critical";
    fn parse_body(body: &[u8]) -> Result<Self, RequestError> {
        contract::parse(body)
    }
    fn validate(&self) -> Result<(), RequestError> {
        // the synchronous route's own checks
        run::check_critical(self)
    }
    fn run(&self, _: &dyn Progress) -> Result<String, RequestError> {
        to_json(&run::critical(self)?)
    }
    fn estimate(&self) -> Estimate {
        E::new("profile", est::SMALL_ANSWER)
    }
}

impl JobKind for SafeRateRequest {
    const NAME: &'static str = "safe_rate";
    fn parse_body(body: &[u8]) -> Result<Self, RequestError> {
        contract::parse(body)
    }
    fn validate(&self) -> Result<(), RequestError> {
        let model = self.system.model()?;
        let target = require_positive("target_elevation_m", self.params.target_elevation_m)?;
        let l0 = model.system.initial_length_m;
        if target <= l0 {
            return Err(InvalidInput::new(
                "target_elevation_m",
                format!("must be a finite length above initial_length_m = {l0} m, got {target}"),
            )
            .into());
        }
        Ok(())
    }
    fn run(&self, _: &dyn Progress) -> Result<String, RequestError> {
        to_json(&run::safe_rate(self)?)
    }
    fn estimate(&self) -> Estimate {
        E::new("target_elevation_m", est::SMALL_ANSWER)
    }
}

/// Rates per chunk of a chart job (times the buoyancies): progress is
/// persisted and cancellation checked between chunks.
const CHART_CHUNK_POINTS: usize = 512;

impl JobKind for ChartRequest {
    const NAME: &'static str = "chart";
    fn parse_body(body: &[u8]) -> Result<Self, RequestError> {
        contract::parse(body)
    }
    fn validate(&self) -> Result<(), RequestError> {
        let model = self.system.model()?;
        let points = run::chart_points(self);
        if points > MAX_CHART_POINTS {
            return Err(InvalidInput::new(
                "rates_m_s.count",
                format!(
                    "the chart would have {points} points; at most {MAX_CHART_POINTS} are allowed"
                ),
            )
            .into());
        }
        self.params.rates_m_s.rates("rates_m_s").map(drop)?;
        chart::deployment_chart_with(
            &model.system,
            self.system.discretisation()?,
            &[],
            &self.buoyancies(&model.system),
            Parallelism::Serial,
            &|_, _| {},
        )?;
        Ok(())
    }

    /// The chart in chunks of rates: the same points as
    /// [`run::chart`] (each point is independent), with progress and
    /// cancellation between chunks.
    fn run(&self, progress: &dyn Progress) -> Result<String, RequestError> {
        self.validate()?;
        let model = self.system.model()?;
        let sys = model.system;
        let rates = self.params.rates_m_s.rates("rates_m_s")?;
        let buoyancies = self.buoyancies(&sys);
        let total = rates.len() * buoyancies.len();
        let chunk_rates = (CHART_CHUNK_POINTS / buoyancies.len()).max(1);
        let mut series: Vec<ChartSeriesOutput> = Vec::with_capacity(buoyancies.len());
        for (c, chunk) in rates.chunks(chunk_rates).enumerate() {
            if progress.cancelled() {
                return Err(RequestError::Cancelled);
            }
            let before = c * chunk_rates * buoyancies.len();
            let report = |done: usize, _: usize| progress.report(before + done, total);
            let part = chart::deployment_chart_with(
                &sys,
                self.system.discretisation()?,
                chunk,
                &buoyancies,
                Parallelism::Rayon,
                &report,
            )?;
            for (i, s) in part.into_iter().enumerate() {
                if series.len() <= i {
                    series.push(ChartSeriesOutput {
                        net_buoyancy_n: s.net_buoyancy_n,
                        wave_speed_m_s: (s.net_buoyancy_n / sys.mass_per_length_kg_m).sqrt(),
                        points: Vec::with_capacity(rates.len()),
                    });
                }
                series[i]
                    .points
                    .extend(s.points.into_iter().map(|p| ChartPointOutput {
                        rate_m_s: p.rate_m_s,
                        critical_time_s: p.critical_time_s,
                        max_elevation_m: p.max_elevation_m,
                        closed_form_elevation_m: p.closed_form_elevation_m,
                        critical_time_error_s: p.critical_time_error_s,
                        max_elevation_error_m: p.max_elevation_error_m,
                        winch_tension_at_onset_n: s.net_buoyancy_n
                            - sys.mass_per_length_kg_m * sys.gravity_m_s2 * p.max_elevation_m,
                        kinematic_tension_n: sys.mass_per_length_kg_m * p.rate_m_s * p.rate_m_s,
                    }));
            }
        }
        if progress.cancelled() {
            return Err(RequestError::Cancelled);
        }
        to_json(&ChartResponse {
            series,
            elements: run::chart_elements(self.system.discretisation()?),
            converged: self.system.model.elements.is_none(),
        })
    }
    fn estimate(&self) -> Estimate {
        let series = self.params.net_buoyancies_n.len().max(1) as f64;
        let points = series * self.params.rates_m_s.count() as f64;
        E::bytes(
            "rates_m_s.count",
            (est::CHART_BASE as f64)
                + series * est::PER_CHART_SERIES as f64
                + points * est::PER_CHART_POINT as f64,
        )
    }
}

trait Buoyancies {
    fn buoyancies(&self, sys: &crate::numerics::params::AerostatSystem) -> Vec<f64>;
}

impl Buoyancies for ChartRequest {
    fn buoyancies(&self, sys: &crate::numerics::params::AerostatSystem) -> Vec<f64> {
        if self.params.net_buoyancies_n.is_empty() {
            vec![sys.net_buoyancy_n]
        } else {
            self.params.net_buoyancies_n.clone()
        }
    }
}

/// Parses `request` as `T`, naming fields from `prefix` (`request`,
/// `request[2].request`).
fn parse_as<T: JobKind>(request: &Value, prefix: &str) -> Result<T, RequestError> {
    let bytes = serde_json::to_vec(request).expect("values serialise");
    T::parse_body(&bytes).map_err(|e| prefixed(e, prefix))
}

/// Progress that is cancelled from the start: running a request with it
/// performs every input check and stops before the first step.
struct CancelledFromTheStart;

impl Progress for CancelledFromTheStart {
    fn report(&self, _: usize, _: usize) {}
    fn cancelled(&self) -> bool {
        true
    }
}

/// Validates by running with [`CancelledFromTheStart`]: invalid input is
/// the error; a cancellation (or an answer) means the input is good.
fn validate_by_cancelled_run<T>(
    run: impl FnOnce(&dyn Progress) -> Result<T, RequestError>,
) -> Result<(), RequestError> {
    match run(&CancelledFromTheStart) {
        Ok(_) | Err(RequestError::Cancelled) => Ok(()),
        Err(e) => Err(e),
    }
}

impl JobKind for AnySimulateRequest {
    const NAME: &'static str = "simulate";
    fn parse_body(body: &[u8]) -> Result<Self, RequestError> {
        simulate::parse_simulate(body)
    }
    fn validate(&self) -> Result<(), RequestError> {
        validate_by_cancelled_run(|p| simulate::simulate_any(self, p))
    }
    fn run(&self, progress: &dyn Progress) -> Result<String, RequestError> {
        to_json(&simulate::simulate_any(self, progress)?)
    }
    fn estimate(&self) -> Estimate {
        match self {
            Self::LinearString(r) => {
                let samples = r.params.samples as f64;
                let tracks = r.params.eigenvalues.as_ref().map_or(0.0, |e| {
                    let solves = (r.params.duration_s / e.interval_s).ceil() + 1.0;
                    solves
                        * (est::PER_EIGEN_TRACK as f64
                            + e.count as f64 * est::PER_EIGENVALUE as f64)
                });
                E::bytes(
                    "samples",
                    est::SIMULATE_BASE as f64 + samples * est::PER_SIMULATE_SAMPLE as f64 + tracks,
                )
            }
            Self::GeometricallyExact(r) => {
                let steps = (r.duration_s / r.time_step_s).ceil();
                let samples = (steps / r.output_every_steps.max(1) as f64).ceil() + 1.0;
                let spectra = if r.eigenvalues_every_steps > 0 {
                    (steps / r.eigenvalues_every_steps as f64).ceil() + 1.0
                } else {
                    0.0
                };
                E::bytes(
                    "output_every_steps",
                    est::SIMULATE_BASE as f64
                        + samples * est::PER_GE_SAMPLE as f64
                        + spectra
                            * (est::PER_EIGEN_TRACK as f64
                                + r.modes as f64 * est::PER_EIGENVALUE as f64),
                )
            }
        }
    }
}

impl JobKind for FrequencyResponseRequest {
    const NAME: &'static str = "frequency_response";
    fn parse_body(body: &[u8]) -> Result<Self, RequestError> {
        contract::parse(body)
    }
    fn validate(&self) -> Result<(), RequestError> {
        validate_by_cancelled_run(|p| transient::frequency_response(self, Parallelism::Serial, p))
    }
    fn run(&self, progress: &dyn Progress) -> Result<String, RequestError> {
        to_json(&transient::frequency_response(
            self,
            Parallelism::Rayon,
            progress,
        )?)
    }
    fn estimate(&self) -> Estimate {
        AnyFrequencyResponseRequest::Wind(Box::new(self.clone())).estimate()
    }
}

impl JobKind for AnyChartRequest {
    const NAME: &'static str = "chart";
    fn parse_body(body: &[u8]) -> Result<Self, RequestError> {
        ge_charts::parse_chart(body)
    }
    fn validate(&self) -> Result<(), RequestError> {
        match self {
            Self::LinearString(r) => r.validate(),
            Self::GeometricallyExact(r) => {
                ge_charts::prepare_chart(r).map(drop).map_err(Into::into)
            }
        }
    }
    fn run(&self, progress: &dyn Progress) -> Result<String, RequestError> {
        match self {
            Self::LinearString(r) => r.run(progress),
            Self::GeometricallyExact(r) => {
                to_json(&ge_charts::ge_chart(r, Parallelism::Rayon, progress)?)
            }
        }
    }
    fn estimate(&self) -> Estimate {
        match self {
            Self::LinearString(r) => r.estimate(),
            Self::GeometricallyExact(r) => {
                let points = ge_charts::prepare_chart(r).map_or(0, |c| c.point_count()) as f64;
                E::bytes(
                    "rates_m_s",
                    est::CHART_BASE as f64
                        + points * (est::PER_GE_CHART_POINT + est::PER_CHART_SERIES) as f64,
                )
            }
        }
    }
}

impl JobKind for AnyFrequencyResponseRequest {
    const NAME: &'static str = "frequency_response";
    fn parse_body(body: &[u8]) -> Result<Self, RequestError> {
        ge_charts::parse_frequency_response(body)
    }
    fn validate(&self) -> Result<(), RequestError> {
        validate_by_cancelled_run(|p| {
            ge_charts::frequency_response_any(self, Parallelism::Serial, p)
        })
    }
    fn run(&self, progress: &dyn Progress) -> Result<String, RequestError> {
        to_json(&ge_charts::frequency_response_any(
            self,
            Parallelism::Rayon,
            progress,
        )?)
    }
    fn estimate(&self) -> Estimate {
        match self {
            Self::Wind(r) => {
                let f = r.params.frequencies_rad_s.count() as f64;
                let n = r.params.samples as f64;
                E::bytes(
                    "frequencies_rad_s.count",
                    est::SIMULATE_BASE as f64 + (f * (n + 4.0) + n) * est::PER_NUMBER as f64,
                )
            }
            Self::Base(r) => E::bytes(
                "frequencies_rad_s.count",
                est::SIMULATE_BASE as f64
                    + r.frequencies_rad_s.count() as f64 * est::PER_BASE_POINT as f64,
            ),
        }
    }
}

impl JobKind for AnyStabilityRequest {
    const NAME: &'static str = "stability";
    fn parse_body(body: &[u8]) -> Result<Self, RequestError> {
        ge_critical::parse_stability(body)
    }
    fn validate(&self) -> Result<(), RequestError> {
        match self {
            Self::LinearString(r) => r.validate(),
            Self::GeometricallyExact(r) => ge_critical::validate_stability(r).map_err(Into::into),
        }
    }
    fn run(&self, progress: &dyn Progress) -> Result<String, RequestError> {
        match self {
            Self::LinearString(r) => r.run(progress),
            Self::GeometricallyExact(r) => to_json(&ge_critical::ge_stability(r)?),
        }
    }
    fn estimate(&self) -> Estimate {
        match self {
            Self::LinearString(r) => r.estimate(),
            Self::GeometricallyExact(r) => E::new(
                "modes",
                est::STABILITY_BASE + r.modes as u64 * est::PER_EIGENVALUE,
            ),
        }
    }
}

impl JobKind for AnyCriticalRequest {
    const NAME: &'static str = "critical";
    fn parse_body(body: &[u8]) -> Result<Self, RequestError> {
        ge_critical::parse_critical(body)
    }
    fn validate(&self) -> Result<(), RequestError> {
        match self {
            Self::LinearString(r) => r.validate(),
            Self::GeometricallyExact(r) => ge_critical::prepare_critical(r)
                .map(drop)
                .map_err(Into::into),
        }
    }
    fn run(&self, progress: &dyn Progress) -> Result<String, RequestError> {
        match self {
            Self::LinearString(r) => r.run(progress),
            Self::GeometricallyExact(r) => to_json(&ge_critical::ge_critical(r, progress)?),
        }
    }
    fn estimate(&self) -> Estimate {
        match self {
            Self::LinearString(r) => r.estimate(),
            Self::GeometricallyExact(_) => E::new("profile", est::SMALL_ANSWER),
        }
    }
}

impl JobKind for crate::contract::bands::BandsRequest {
    const NAME: &'static str = "bands";
    fn parse_body(body: &[u8]) -> Result<Self, RequestError> {
        crate::contract::bands::parse_bands(body)
    }
    fn validate(&self) -> Result<(), RequestError> {
        crate::contract::bands::prepare(self).map(drop)
    }
    fn run(&self, progress: &dyn Progress) -> Result<String, RequestError> {
        to_json(&crate::contract::bands::bands(
            self,
            Parallelism::Rayon,
            progress,
        )?)
    }
    fn estimate(&self) -> Estimate {
        let samples = self.params.uncertainty.samples.max(1);
        let rates = (crate::contract::bands::evaluations(self) / samples) as u64;
        E::new(
            "rates_m_s",
            est::CHART_BASE + rates.saturating_mul(est::PER_BAND_POINT),
        )
    }
}

fn prefixed(e: RequestError, prefix: &str) -> RequestError {
    match e {
        RequestError::Invalid(InvalidInput { field, reason }) => {
            let field = if field == "body" {
                prefix.to_string()
            } else {
                format!("{prefix}.{field}")
            };
            RequestError::Invalid(InvalidInput { field, reason })
        }
        other => other,
    }
}

macro_rules! job_kinds {
    ($($(#[$doc:meta])* $variant:ident($req:ty)),* $(,)?) => {
        /// One request: `kind` names the route, `request` is its body.
        #[derive(Clone, Debug, Serialize, ToSchema)]
        #[serde(tag = "kind", content = "request", rename_all = "snake_case")]
        pub enum JobItem {
            $($(#[$doc])* $variant($req)),*
        }

        impl JobItem {
            /// The kinds, as written in `kind`.
            pub const KINDS: &'static [&'static str] = &[$(<$req as JobKind>::NAME),*];

            fn parse_kind(kind: &str, request: &Value, prefix: &str) -> Option<Result<Self, RequestError>> {
                $(if kind == <$req as JobKind>::NAME {
                    return Some(parse_as::<$req>(request, prefix).map(Self::$variant));
                })*
                None
            }

            pub fn kind(&self) -> &'static str {
                match self { $(Self::$variant(_) => <$req as JobKind>::NAME),* }
            }

            fn validate_kind(&self) -> Result<(), RequestError> {
                match self { $(Self::$variant(r) => r.validate()),* }
            }

            fn run_kind(&self, progress: &dyn Progress) -> Result<String, RequestError> {
                match self { $(Self::$variant(r) => r.run(progress)),* }
            }

            /// Upper estimate of the answer's size.
            pub fn estimate(&self) -> Estimate {
                match self { $(Self::$variant(r) => r.estimate()),* }
            }
        }
    };
}

job_kinds!(
    /// `POST /api/v1/stability` (either cable model).
    Stability(AnyStabilityRequest),
    /// `POST /api/v1/critical` (either cable model).
    Critical(AnyCriticalRequest),
    /// `POST /api/v1/safe-rate`.
    SafeRate(SafeRateRequest),
    /// `POST /api/v1/charts`, up to 1 000 000 points (GE: 2 000).
    Chart(AnyChartRequest),
    /// `POST /api/v1/simulate` (either cable model).
    Simulate(AnySimulateRequest),
    /// `POST /api/v1/frequency-response`.
    FrequencyResponse(AnyFrequencyResponseRequest),
    /// `POST /api/v1/equilibrium`.
    Equilibrium(crate::contract::equilibrium::dto::EquilibriumRequest),
    /// `POST /api/v1/envelope`, up to 250 000 points (with progress).
    Envelope(crate::contract::envelope::dto::EnvelopeRequest),
    /// `POST /api/v1/bands`, up to 2 000 000 chart points (samples × rates).
    Bands(crate::contract::bands::BandsRequest),
    /// `POST /api/v1/plan`: the deployment plan (progress of its transient check).
    Plan(crate::contract::plan::PlanRequest),
    /// `POST /api/v1/plan/bands`.
    PlanBands(crate::contract::bands::PlanBandsRequest),
    /// `POST /api/v1/envelope/bands`, up to 2 000 000 equilibria (samples × cells).
    EnvelopeBands(crate::contract::bands::EnvelopeBandsRequest),
    /// `POST /api/v1/dynamics`: one run in time (progress in steps).
    Dynamics(crate::contract::dynamics::DynamicsRequest),
    /// `POST /api/v1/dynamics/peaks`: Monte Carlo over turbulence seeds, chunked by sample.
    DynamicsPeaks(crate::contract::dynamics::DynamicsPeaksRequest),
    /// `POST /api/v1/windows`: launch windows from a forecast (progress in plans).
    Windows(crate::contract::windows::WindowsRequest),
);

impl JobItem {
    #[cfg(test)]
    fn parse(value: &Value, prefix: &str) -> Result<Self, RequestError> {
        Self::parse_bounded(value, prefix, u64::MAX)
    }

    /// Parses, refuses an answer estimated above `max_result_bytes` (before
    /// the costlier validation), then validates.
    fn parse_bounded(
        value: &Value,
        prefix: &str,
        max_result_bytes: u64,
    ) -> Result<Self, RequestError> {
        let obj = value.as_object().ok_or_else(|| {
            InvalidInput::new(
                prefix.to_string(),
                "must be a JSON object with `kind` and `request`",
            )
        })?;
        let kind_field = if prefix == "body" {
            "kind".to_string()
        } else {
            format!("{prefix}.kind")
        };
        let request_field = if prefix == "body" {
            "request".to_string()
        } else {
            format!("{prefix}.request")
        };
        refuse_unknown_keys(obj, prefix)?;
        let kind = obj.get("kind").and_then(Value::as_str).ok_or_else(|| {
            InvalidInput::new(
                kind_field.clone(),
                format!("is required: one of {}", Self::KINDS.join(", ")),
            )
        })?;
        let request = obj.get("request").ok_or_else(|| {
            InvalidInput::new(
                request_field.clone(),
                "is required: the body of the request",
            )
        })?;
        let item = Self::parse_kind(kind, request, &request_field).unwrap_or_else(|| {
            Err(InvalidInput::new(
                kind_field,
                format!("unknown kind `{kind}`: one of {}", Self::KINDS.join(", ")),
            )
            .into())
        })?;
        est::check(&item.estimate().prefixed(&request_field), max_result_bytes)?;
        item.validate_kind()
            .map_err(|e| prefixed(e, &request_field))?;
        Ok(item)
    }
}

/// A submission envelope holds `kind` and `request` only: any other key is
/// refused, named with its path.
fn refuse_unknown_keys(
    obj: &serde_json::Map<String, Value>,
    prefix: &str,
) -> Result<(), RequestError> {
    match obj.keys().find(|k| *k != "kind" && *k != "request") {
        None => Ok(()),
        Some(k) => Err(InvalidInput::new(
            if prefix == "body" {
                k.clone()
            } else {
                format!("{prefix}.{k}")
            },
            format!("unknown field `{k}`; expected one of `kind`, `request`"),
        )
        .into()),
    }
}

/// `kind` of a batch submission.
#[derive(Clone, Copy, Debug, Serialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum BatchKind {
    Batch,
}

/// Several requests answered together (1 to 1000).
#[derive(Clone, Debug, Serialize, ToSchema)]
pub struct BatchSubmission {
    pub kind: BatchKind,
    /// The requests; each is answered (or fails) on its own.
    pub request: Vec<JobItem>,
}

/// The body of `POST /api/v1/jobs`: one request, or a batch.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[serde(untagged)]
pub enum JobSubmission {
    One(JobItem),
    Batch(BatchSubmission),
}

/// The answer of one request of a batch: `result` or `error`.
#[derive(Debug, Serialize, ToSchema)]
pub struct BatchItemOutcome {
    /// The kind of the request.
    pub kind: String,
    /// The answer, as the synchronous route gives it.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(schema_with = item_result_schema)]
    pub result: Option<Box<RawValue>>,
    /// Why this request failed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<ErrorBody>,
}

/// The schemas of one request's answer: those of the synchronous routes.
pub const ITEM_RESULT_SCHEMAS: &[&str] = &[
    "AnyStabilityResponse",
    "AnyCriticalResponse",
    "SafeRateResponse",
    "AnyChartResponse",
    "AnySimulateResponse",
    "AnyFrequencyResponseResponse",
    "EquilibriumResponse",
    "EnvelopeResponse",
    "BandsResponse",
    "PlanResponse",
    "PlanBandsResponse",
    "EnvelopeBandsResponse",
    "DynamicsResponse",
    "DynamicsPeaksResponse",
    "WindowsResponse",
];

fn item_result_schema() -> impl Into<utoipa::openapi::RefOr<utoipa::openapi::schema::Schema>> {
    use utoipa::openapi::schema::{OneOfBuilder, Ref};
    let mut one_of = OneOfBuilder::new();
    for name in ITEM_RESULT_SCHEMAS {
        one_of = one_of.item(Ref::from_schema_name(*name));
    }
    one_of.description(Some(
        "The answer, as the synchronous route gives it; absent on error.",
    ))
}

/// The answer of a batch job, in submission order.
#[derive(Debug, Serialize, ToSchema)]
pub struct BatchOutcome {
    pub items: Vec<BatchItemOutcome>,
}

/// Progress of a batch: items done of total; cancellation is passed on.
struct BatchProgress<'a> {
    outer: &'a dyn Progress,
    done: &'a AtomicUsize,
    total: usize,
}

impl Progress for BatchProgress<'_> {
    fn report(&self, _: usize, _: usize) {}
    fn cancelled(&self) -> bool {
        self.outer.cancelled()
    }
}

impl BatchProgress<'_> {
    fn item_done(&self) {
        let done = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        self.outer.report(done, self.total);
    }
}

impl JobSubmission {
    /// Parses and validates a submission (body of `POST /api/v1/jobs`).
    pub fn parse(body: &[u8], limits: &Limits) -> Result<Self, RequestError> {
        let value: Value =
            serde_json::from_slice(body).map_err(|e| RequestError::Malformed(e.to_string()))?;
        if value.get("kind").and_then(Value::as_str) != Some("batch") {
            let item = JobItem::parse_bounded(&value, "body", limits.max_job_result_bytes)?;
            return Ok(Self::One(item));
        }
        if let Some(obj) = value.as_object() {
            refuse_unknown_keys(obj, "body")?;
        }
        let list = value
            .get("request")
            .and_then(Value::as_array)
            .ok_or_else(|| {
                InvalidInput::new(
                    "request",
                    "a batch needs `request`: a list of {\"kind\", \"request\"} objects",
                )
            })?;
        if list.is_empty() || list.len() > limits.max_batch_items {
            return Err(InvalidInput::new(
                "request",
                format!(
                    "a batch holds 1 to {} requests, got {}",
                    limits.max_batch_items,
                    list.len()
                ),
            )
            .into());
        }
        let request = list
            .iter()
            .enumerate()
            .map(|(i, v)| {
                JobItem::parse_bounded(v, &format!("request[{i}]"), limits.max_job_result_bytes)
            })
            .collect::<Result<Vec<_>, _>>()?;
        est::check_batch(
            request.iter().map(JobItem::estimate),
            limits.max_job_result_bytes,
        )?;
        Ok(Self::Batch(BatchSubmission {
            kind: BatchKind::Batch,
            request,
        }))
    }

    /// Upper estimate of the answer's size, bytes of JSON (a batch: the
    /// sum of its items'); the store reserves it until the answer is stored.
    pub fn answer_bytes_estimate(&self) -> u64 {
        match self {
            Self::One(item) => item.estimate().result_bytes,
            Self::Batch(b) => b
                .request
                .iter()
                .map(|i| i.estimate().result_bytes)
                .fold(0u64, u64::saturating_add),
        }
    }

    /// `kind` as stored: a request kind, or `batch`.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::One(item) => item.kind(),
            Self::Batch(_) => "batch",
        }
    }

    /// Computes the answer (JSON text) on the current rayon pool.
    pub fn run(&self, progress: &dyn Progress) -> Result<String, RequestError> {
        match self {
            Self::One(item) => item.run_kind(progress),
            Self::Batch(b) => {
                let done = AtomicUsize::new(0);
                let batch = BatchProgress {
                    outer: progress,
                    done: &done,
                    total: b.request.len(),
                };
                let items: Vec<BatchItemOutcome> = b
                    .request
                    .par_iter()
                    .map(|item| {
                        let out = if batch.cancelled() {
                            Err(RequestError::Cancelled)
                        } else {
                            item.run_kind(&batch)
                        };
                        batch.item_done();
                        match out {
                            Ok(json) => BatchItemOutcome {
                                kind: item.kind().into(),
                                result: Some(
                                    RawValue::from_string(json).expect("answers are JSON"),
                                ),
                                error: None,
                            },
                            Err(e) => BatchItemOutcome {
                                kind: item.kind().into(),
                                result: None,
                                error: Some(e.body()),
                            },
                        }
                    })
                    .collect();
                if progress.cancelled() {
                    return Err(RequestError::Cancelled);
                }
                to_json(&BatchOutcome { items })
            }
        }
    }
}

// ------------------------------------------------------------ chunks (split/assemble)

use super::chunks::ChunkPlan;

/// Seconds per element-step of a GE search, QEP checks included (measured:
/// 24 points of 10 elements, 6 100 steps in 0.48 s on one core), for sizing
/// chunks; a point is costed at its whole horizon, an upper bound (most
/// end at the onset).
const GE_ELEMENT_STEP_S: f64 = 8e-6;
/// Seconds per element of one chart point of a bands sample on a uniform
/// mesh (measured: 6 400 points of 500 elements in 1.2 s on one core).
const BAND_ELEMENT_POINT_S: f64 = 4e-7;
/// Seconds per converged chart point of a bands sample (measured: 9 600
/// points in 0.06 s).
const BAND_CONVERGED_POINT_S: f64 = 1e-5;
/// Seconds per element of one point of a string chart on a uniform mesh
/// (measured: 300 rates × 3 buoyancies at 400 elements in 0.21-0.23 s on
/// one core, 5.9-6.5e-7 s, timing `run_chunk` on one rayon thread).
const STRING_CHART_ELEMENT_POINT_S: f64 = 7e-7;
/// Seconds per converged point of a string chart (measured: 74 points in
/// 0.5 ms, 6.5-7.3e-6 s, on one core; slower near the wave speed).
const STRING_CHART_CONVERGED_POINT_S: f64 = 1e-5;
/// Seconds per sample × schedule instant of a plan bands chunk, its wire
/// result included (measured: 3 000 samples × 2 003 instants in 1.36 s on
/// one core, 2.2e-7 s, most of it writing the result; the nominal plan,
/// computed again by every chunk, 0.02 s).
const PLAN_BAND_VALUE_S: f64 = 2.5e-7;
/// Sample × instant values of one plan bands chunk at most: its result
/// holds every value of three traces, about 60 bytes a value (15 MB).
const MAX_PLAN_BAND_CHUNK_VALUES: usize = 250_000;
/// Seconds per sample × cell × integration step of an envelope bands job
/// (measured: 200 samples × 42 cells × 100 steps in 0.94 s on one core,
/// 1.1e-6 s).
const ENVELOPE_BAND_CELL_STEP_S: f64 = 1.2e-6;
/// Seconds assumed for one request of a kind that is not chunked.
const OTHER_ITEM_S: f64 = 0.05;
/// Seconds per envelope cell per element of the quasi-static GE verdict,
/// the row's critical length and rate searches included (measured: 40 ×
/// 50 cells at 20 elements in 12.1 s on 2 loaded cores, 5.8 s quiet;
/// costed at the loaded figure, 12 ms a cell on one core).
const GE_ENVELOPE_CELL_ELEMENT_S: f64 = 6e-4;

impl JobItem {
    /// The independent items of this request and the seconds each may
    /// take (None: it runs as one piece).
    fn items(&self) -> Option<(usize, f64)> {
        match self {
            Self::Chart(AnyChartRequest::GeometricallyExact(r)) => {
                let core = ge_charts::prepare_chart(r).ok()?;
                let steps = core.config.horizon_s / core.config.time_step_s;
                let cost = steps * core.system.elements as f64 * GE_ELEMENT_STEP_S;
                Some((core.point_count(), cost))
            }
            Self::Bands(r) => {
                let samples = r.params.uncertainty.samples;
                let rates = crate::contract::bands::evaluations(r) / samples.max(1);
                let point = match r.system.discretisation().ok()? {
                    crate::numerics::chart::Discretisation::Elements(n) => {
                        n as f64 * BAND_ELEMENT_POINT_S
                    }
                    _ => BAND_CONVERGED_POINT_S,
                };
                Some((samples, rates as f64 * point))
            }
            Self::Chart(AnyChartRequest::LinearString(r)) => {
                let series = r.params.net_buoyancies_n.len().max(1) as f64;
                let point = match r.system.discretisation().ok()? {
                    crate::numerics::chart::Discretisation::Elements(n) => {
                        n as f64 * STRING_CHART_ELEMENT_POINT_S
                    }
                    _ => STRING_CHART_CONVERGED_POINT_S,
                };
                Some((
                    crate::contract::chart_chunks::chart_rate_count(r),
                    series * point,
                ))
            }
            Self::PlanBands(r) => {
                let samples = r.params.uncertainty.samples;
                let values = crate::contract::bands::plan::plan_band_values(r);
                let instants = values / samples.max(1);
                Some((samples, instants as f64 * PLAN_BAND_VALUE_S))
            }
            Self::Envelope(r) => {
                let (_, config, spec) = r.ge_problem().ok()?;
                let cell = match spec {
                    Some(spec) => spec.elements as f64 * GE_ENVELOPE_CELL_ELEMENT_S,
                    // A string cell costs what an envelope bands cell does.
                    None => config.steps as f64 * ENVELOPE_BAND_CELL_STEP_S,
                };
                let lengths = r.tether_lengths_m.count() as f64;
                Some((
                    crate::contract::envelope::chunks::envelope_row_count(r),
                    lengths * cell,
                ))
            }
            Self::EnvelopeBands(r) => {
                let samples = r.params.uncertainty.samples;
                let (_, config) = r.envelope.problem().ok()?;
                let cells = r.envelope.points() as f64;
                let cost = cells * config.steps as f64 * ENVELOPE_BAND_CELL_STEP_S;
                Some((samples, cost))
            }
            Self::DynamicsPeaks(r) => {
                let per = r.prepare().ok()?.work() * super::dynamics::SEGMENT_STEP_S;
                Some((r.samples, per))
            }
            _ => None,
        }
    }

    /// How this request splits into chunks (None: it runs as one piece).
    fn chunk_plan(&self) -> Option<ChunkPlan> {
        let plan = self.items().map(|(n, cost)| ChunkPlan::for_cost(n, cost))?;
        match self {
            // A split plan bands job: chunk results of bounded size.
            Self::PlanBands(r) if plan.count() > 1 => {
                let samples = r.params.uncertainty.samples.max(1);
                let instants = crate::contract::bands::plan::plan_band_values(r) / samples;
                let most = (MAX_PLAN_BAND_CHUNK_VALUES / instants.max(1)).max(1);
                Some(ChunkPlan {
                    per_chunk: plan.per_chunk.min(most),
                    ..plan
                })
            }
            _ => Some(plan),
        }
    }

    /// Seconds one run of this request may take (sizing batch chunks).
    fn cost_s(&self) -> f64 {
        self.items().map_or(OTHER_ITEM_S, |(n, c)| n as f64 * c)
    }

    /// The items `range` of this request as JSON text.
    fn run_range(
        &self,
        range: std::ops::Range<usize>,
        progress: &dyn Progress,
    ) -> Result<String, RequestError> {
        match self {
            Self::Chart(AnyChartRequest::GeometricallyExact(r)) => to_json(
                &ge_charts::ge_chart_points(r, range, Parallelism::Rayon, progress)?,
            ),
            Self::Bands(r) => {
                crate::contract::bands::bands_chunk(r, range, Parallelism::Rayon, progress)
            }
            Self::Chart(AnyChartRequest::LinearString(r)) => {
                crate::contract::chart_chunks::chart_chunk(r, range, Parallelism::Rayon, progress)
            }
            Self::PlanBands(r) => crate::contract::bands::plan::plan_bands_chunk(
                r,
                range,
                Parallelism::Rayon,
                progress,
            ),
            Self::Envelope(r) => to_json(&crate::contract::envelope::chunks::envelope_chunk(
                r,
                range,
                Parallelism::Rayon,
                progress,
            )?),
            Self::EnvelopeBands(r) => crate::contract::bands::envelope::envelope_bands_chunk(
                r,
                range,
                Parallelism::Rayon,
                progress,
            ),
            Self::DynamicsPeaks(r) => crate::contract::dynamics::peaks::peaks_chunk(
                r,
                range,
                Parallelism::Rayon,
                progress,
            ),
            _ => self.run_kind(progress),
        }
    }

    /// The answer from the chunks' results, in chunk order.
    fn assemble(&self, parts: &[String]) -> Result<String, RequestError> {
        let bad = |e: serde_json::Error| RequestError::Malformed(format!("a chunk result: {e}"));
        match self {
            Self::Chart(AnyChartRequest::GeometricallyExact(r)) => {
                let mut points = Vec::new();
                for part in parts {
                    let chunk: Vec<ge_charts::GeChartPointOutput> =
                        serde_json::from_str(part).map_err(bad)?;
                    points.extend(chunk);
                }
                to_json(&ge_charts::ge_chart_assemble(r, points)?)
            }
            Self::Bands(r) => to_json(&crate::contract::bands::bands_from_chunks(r, parts)?),
            Self::Chart(AnyChartRequest::LinearString(r)) => {
                to_json(&crate::contract::chart_chunks::chart_from_chunks(r, parts)?)
            }
            Self::PlanBands(r) => to_json(&crate::contract::bands::plan::plan_bands_from_chunks(
                r, parts,
            )?),
            Self::Envelope(r) => to_json(&crate::contract::envelope::chunks::envelope_from_chunks(
                r, parts,
            )?),
            Self::EnvelopeBands(r) => {
                to_json(&crate::contract::bands::envelope::envelope_bands_from_chunks(r, parts)?)
            }
            Self::DynamicsPeaks(r) => to_json(
                &crate::contract::dynamics::peaks::peaks_from_chunks(r, parts)?,
            ),
            _ => parts
                .first()
                .cloned()
                .ok_or_else(|| RequestError::Malformed("no chunk result".into())),
        }
    }
}

/// A batch answer put together from the items of its chunks, unparsed.
#[derive(Serialize)]
struct RawBatchOutcome {
    items: Vec<Box<RawValue>>,
}

impl JobSubmission {
    /// How the job splits into chunks: a GE chart into its points, a
    /// string chart into its rates, bands (chart, plan, envelope) into
    /// their samples, a batch into its requests (None: one piece).
    pub fn chunk_plan(&self) -> Option<ChunkPlan> {
        match self {
            Self::One(item) => item.chunk_plan(),
            Self::Batch(b) => {
                let cost = b.request.iter().map(JobItem::cost_s).sum::<f64>()
                    / b.request.len().max(1) as f64;
                Some(ChunkPlan::for_cost(b.request.len(), cost))
            }
        }
    }

    /// One chunk's result (JSON text): the items `range` of the plan.
    pub fn run_chunk(
        &self,
        range: std::ops::Range<usize>,
        progress: &dyn Progress,
    ) -> Result<String, RequestError> {
        match self {
            Self::One(item) => item.run_range(range, progress),
            Self::Batch(b) => {
                let items = b.request.get(range).unwrap_or(&[]);
                let outcomes: Vec<BatchItemOutcome> = items
                    .par_iter()
                    .map(|item| batch_item(item, progress))
                    .collect();
                if progress.cancelled() {
                    return Err(RequestError::Cancelled);
                }
                to_json(&outcomes)
            }
        }
    }

    /// The job's answer from its chunks' results in index order: the same
    /// JSON as [`JobSubmission::run`] gives in one process.
    pub fn assemble(&self, plan: ChunkPlan, parts: &[String]) -> Result<String, RequestError> {
        if parts.len() != plan.count() {
            return Err(RequestError::Malformed(format!(
                "{} chunk results for {} chunks",
                parts.len(),
                plan.count()
            )));
        }
        match self {
            Self::One(item) => item.assemble(parts),
            Self::Batch(_) => {
                let mut items = Vec::new();
                for part in parts {
                    let chunk: Vec<Box<RawValue>> = serde_json::from_str(part)
                        .map_err(|e| RequestError::Malformed(format!("a chunk result: {e}")))?;
                    items.extend(chunk);
                }
                to_json(&RawBatchOutcome { items })
            }
        }
    }
}

/// One request of a batch run with `progress`'s cancellation: its outcome.
fn batch_item(item: &JobItem, progress: &dyn Progress) -> BatchItemOutcome {
    struct Quiet<'a>(&'a dyn Progress);
    impl Progress for Quiet<'_> {
        fn report(&self, _: usize, _: usize) {}
        fn cancelled(&self) -> bool {
            self.0.cancelled()
        }
    }
    let out = if progress.cancelled() {
        Err(RequestError::Cancelled)
    } else {
        item.run_kind(&Quiet(progress))
    };
    match out {
        Ok(json) => BatchItemOutcome {
            kind: item.kind().into(),
            result: Some(RawValue::from_string(json).expect("answers are JSON")),
            error: None,
        },
        Err(e) => BatchItemOutcome {
            kind: item.kind().into(),
            result: None,
            error: Some(e.body()),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn valid(kind: &str) -> Value {
        if let Some(v) = crate::jobs::tether::example_request(kind) {
            return v;
        }
        if let Some(v) = crate::jobs::bands::example_request(kind) {
            return v;
        }
        if let Some(v) = crate::jobs::dynamics::example_request(kind) {
            return v;
        }
        if let Some(v) = crate::jobs::windows::example_request(kind) {
            return v;
        }
        let mut v = json!({"cable": {"mass_per_length_kg_m": 0.078}, "aerostat": {"net_buoyancy_n": 1000.0}});
        let extra = match kind {
            "stability" => json!({"state": {"length_m": 10.0}}),
            "critical" => json!({"profile": {"kind": "constant_rate", "rate_m_s": 10.0}}),
            "safe_rate" => json!({"target_elevation_m": 100.0}),
            "chart" => json!({"rates_m_s": {"min": 1.0, "max": 2.0, "count": 2}}),
            "simulate" => {
                json!({"profile": {"kind": "constant_rate", "rate_m_s": 1.0}, "duration_s": 1.0})
            }
            "frequency_response" => {
                json!({"profile": {"kind": "constant_rate", "rate_m_s": 1.0}, "duration_s": 1.0,
                "aero": {"radius_m": 0.5}, "wind_amplitude_m_s": 1.0,
                "frequencies_rad_s": {"min": 1.0, "max": 2.0, "count": 2}})
            }
            "bands" => json!({"rates_m_s": [10.0], "uncertainty": {"samples": 4, "inputs": [
                {"field": "aerostat.net_buoyancy_n", "distribution": "uniform", "low": 900.0, "high": 1100.0}]}}),
            "plan" => json!({"target_elevation_m": 100.0,
                "winch": {"max_rate_m_s": 10.0, "max_acceleration_m_s2": 1.0}}),
            other => panic!("a new kind needs a valid request here: {other}"),
        };
        v.as_object_mut()
            .unwrap()
            .extend(extra.as_object().unwrap().clone());
        v
    }

    #[test]
    fn kind_names_are_the_serde_tags() {
        for kind in JobItem::KINDS {
            let item =
                JobItem::parse(&json!({"kind": kind, "request": valid(kind)}), "body").unwrap();
            assert_eq!(item.kind(), *kind);
            assert_eq!(serde_json::to_value(&item).unwrap()["kind"], *kind);
        }
    }

    #[test]
    fn errors_name_the_field_inside_the_submission() {
        let limits = Limits::default();
        let body = json!({"kind": "batch", "request": [
            {"kind": "critical", "request": valid("critical")},
            {"kind": "chart", "request": {"cable": {}, "aerostat": {"net_buoyancy_n": 1000.0}, "rates_m_s": {"min": 1.0, "max": 2.0, "count": 2}}},
        ]});
        let err = JobSubmission::parse(&serde_json::to_vec(&body).unwrap(), &limits).unwrap_err();
        assert_eq!(
            err.body().error.field.as_deref(),
            Some("request[1].request.cable.mass_per_length_kg_m")
        );
    }
}
