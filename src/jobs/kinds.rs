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

use crate::config::Limits;
use crate::contract::dto::*;
use crate::contract::ge_charts::{self, AnyChartRequest, AnyFrequencyResponseRequest};
use crate::contract::run::{self, MAX_MODES};
use crate::contract::simulate::{self, AnySimulateRequest};
use crate::contract::transient::{self, FrequencyResponseRequest};
use crate::contract::{self, Progress, RequestError};
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
}

fn to_json(value: &impl Serialize) -> Result<String, RequestError> {
    Ok(serde_json::to_string(value).expect("responses serialise"))
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
}

impl JobKind for CriticalRequest {
    const NAME: &'static str = "critical";
    fn parse_body(body: &[u8]) -> Result<Self, RequestError> {
        contract::parse(body)
    }
    fn validate(&self) -> Result<(), RequestError> {
        let model = self.system.model()?;
        self.params.profile.profile(model.system.initial_length_m)?;
        Ok(())
    }
    fn run(&self, _: &dyn Progress) -> Result<String, RequestError> {
        to_json(&run::critical(self)?)
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
        let grid = &self.params.rates_m_s;
        chart::rate_grid(grid.min, grid.max, grid.count.min(2))?;
        chart::rate_grid(grid.min, grid.max, grid.count).map(drop)?;
        chart::deployment_chart(
            &model.system,
            model.elements(),
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
        let grid = &self.params.rates_m_s;
        let rates = chart::rate_grid(grid.min, grid.max, grid.count)?;
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
            let part = chart::deployment_chart(
                &sys,
                model.elements(),
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
            elements: model.elements(),
        })
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
        }
    };
}

job_kinds!(
    /// `POST /api/v1/stability`.
    Stability(StabilityRequest),
    /// `POST /api/v1/critical`.
    Critical(CriticalRequest),
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
);

impl JobItem {
    fn parse(value: &Value, prefix: &str) -> Result<Self, RequestError> {
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
        item.validate_kind()
            .map_err(|e| prefixed(e, &request_field))?;
        Ok(item)
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
    #[schema(value_type = Option<Object>)]
    pub result: Option<Box<RawValue>>,
    /// Why this request failed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<ErrorBody>,
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
            return JobItem::parse(&value, "body").map(Self::One);
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
            .map(|(i, v)| JobItem::parse(v, &format!("request[{i}]")))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self::Batch(BatchSubmission {
            kind: BatchKind::Batch,
            request,
        }))
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

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn valid(kind: &str) -> Value {
        if let Some(v) = crate::jobs::tether::example_request(kind) {
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
