//! What a job computes: one request of a known kind, or a batch of them.
//! The catalogue of kinds as the job engine sees it: [`JobItem`] is made
//! from the one list of kinds ([`crate::contract::catalogue`]), and each
//! kind's checks, run, answer size and chunking are its
//! [`Analysis`] impl (in its `contract/<kind>/` folder). Nothing here, nor
//! in the engine (`queue.rs`, `execute.rs`, `chunks.rs`), names a kind.
//!
//! A submission is `{"kind": K, "request": {...}}` with `K` one of
//! [`JobItem::KINDS`] and the request the same JSON as `POST /api/v1/<K>`,
//! or `{"kind": "batch", "request": [{"kind": K, "request": {...}}, ...]}`.

use std::ops::Range;
use std::sync::atomic::{AtomicUsize, Ordering};

use rayon::prelude::*;
use serde::Serialize;
use serde_json::Value;
use serde_json::value::RawValue;
use utoipa::ToSchema;

use super::split::ChunkPlan;
use crate::contract::analysis::{Analysis, to_json};
use crate::contract::catalogue::{self, for_each_kind};
use crate::contract::error::ErrorBody;
use crate::contract::estimate::{self as est, Estimate};
use crate::contract::{Progress, RequestError};
use crate::limits::Limits;
use crate::numerics::params::InvalidInput;

/// Seconds assumed for one request of a kind that is not chunked.
const OTHER_ITEM_S: f64 = 0.05;

/// Parses `request` as `T`, naming fields from `prefix` (`request`,
/// `request[2].request`).
fn parse_as<T: Analysis>(request: &Value, prefix: &str) -> Result<T, RequestError> {
    let bytes = serde_json::to_vec(request).expect("values serialise");
    T::parse(&bytes).map_err(|e| prefixed(e, prefix))
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

macro_rules! job_items {
    ($($(#[$doc:meta])* $variant:ident($req:ty => $resp:ty) $path:literal $op:ident),* $(,)?) => {
        /// One request: `kind` names the route, `request` is its body.
        #[derive(Clone, Debug, Serialize, ToSchema)]
        #[serde(tag = "kind", content = "request", rename_all = "snake_case")]
        pub enum JobItem {
            $($(#[$doc])* $variant($req)),*
        }

        impl JobItem {
            /// The kinds, as written in `kind`.
            pub const KINDS: &'static [&'static str] = &[$(<$req as Analysis>::NAME),*];

            fn parse_kind(kind: &str, request: &Value, prefix: &str) -> Option<Result<Self, RequestError>> {
                $(if kind == <$req as Analysis>::NAME {
                    return Some(parse_as::<$req>(request, prefix).map(Self::$variant));
                })*
                None
            }

            pub fn kind(&self) -> &'static str {
                match self { $(Self::$variant(_) => <$req as Analysis>::NAME),* }
            }

            fn validate_kind(&self) -> Result<(), RequestError> {
                match self { $(Self::$variant(r) => <$req as Analysis>::prepare(r)),* }
            }

            /// The answer as JSON text.
            fn run_kind(&self, progress: &dyn Progress) -> Result<String, RequestError> {
                match self { $(Self::$variant(r) => to_json(&<$req as Analysis>::run(r, progress)?)),* }
            }

            /// Upper estimate of the answer's size.
            pub fn estimate(&self) -> Estimate {
                match self { $(Self::$variant(r) => <$req as Analysis>::estimate(r)),* }
            }

            fn items(&self) -> Option<crate::contract::analysis::Items> {
                match self { $(Self::$variant(r) => <$req as Analysis>::items(r)),* }
            }

            /// The items `range` of this request as JSON text.
            fn run_range(&self, range: Range<usize>, progress: &dyn Progress) -> Result<String, RequestError> {
                match self { $(Self::$variant(r) => <$req as Analysis>::run_items(r, range, progress)),* }
            }

            /// The answer from the chunks' results, in chunk order.
            fn assemble(&self, parts: &[String]) -> Result<String, RequestError> {
                match self { $(Self::$variant(r) => <$req as Analysis>::assemble(r, parts)),* }
            }
        }
    };
}
for_each_kind!(job_items);

impl JobItem {
    /// How this request splits into chunks (None: it runs as one piece).
    fn chunk_plan(&self) -> Option<ChunkPlan> {
        let items = self.items()?;
        let plan = ChunkPlan::for_cost(items.count, items.seconds_each);
        match items.most_per_chunk {
            Some(most) if plan.count() > 1 => Some(ChunkPlan {
                per_chunk: plan.per_chunk.min(most),
                ..plan
            }),
            _ => Some(plan),
        }
    }

    /// Seconds one run of this request may take (sizing batch chunks).
    fn cost_s(&self) -> f64 {
        self.items()
            .map_or(OTHER_ITEM_S, |i| i.count as f64 * i.seconds_each)
    }
}

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

/// The schemas of one request's answer: those of the synchronous routes
/// (every kind's answer, [`catalogue::response_schemas`]).
fn item_result_schema() -> impl Into<utoipa::openapi::RefOr<utoipa::openapi::schema::Schema>> {
    use utoipa::openapi::schema::{OneOfBuilder, Ref};
    let mut one_of = OneOfBuilder::new();
    for name in catalogue::response_schemas() {
        one_of = one_of.item(Ref::from_schema_name(name));
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

    /// A kind's schema example (its request type's `example`).
    fn schema_example(kind: &str) -> Option<Value> {
        macro_rules! examples {
            ($($(#[$doc:meta])* $variant:ident($req:ty => $resp:ty) $path:literal $op:ident),* $(,)?) => {{
                $(if kind == <$req as Analysis>::NAME {
                    let schema = <$req as utoipa::PartialSchema>::schema();
                    return serde_json::to_value(&schema).ok()?.get("example").cloned();
                })*
                None
            }};
        }
        for_each_kind!(examples)
    }

    fn valid(kind: &str) -> Value {
        let by_example = [
            "equilibrium",
            "envelope",
            "plan_bands",
            "envelope_bands",
            "dynamics",
            "dynamics_peaks",
            "windows",
        ];
        if by_example.contains(&kind) {
            return schema_example(kind).expect("the schema has an example");
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
