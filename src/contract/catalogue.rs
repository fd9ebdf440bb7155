//! The one list of analysis kinds ([`for_each_kind`]). Everything that
//! names the kinds is made from it: the synchronous routes and their
//! OpenAPI operations (`api/kinds.rs`, `api/openapi.rs`), the job kinds and
//! batch items (`jobs/kinds.rs`), the answer schemas of a job and of a
//! batch item ([`response_schemas`]) and the CLI subcommands ([`KINDS`]).
//!
//! Adding a kind: its numerics, its `src/contract/<kind>/` folder with an
//! [`Analysis`] impl for its request type, one line below, and its page
//! module (`static/`). The line is `Variant(Request => Response) "route"
//! operation_id`, with the job kind's description as its doc comment.

use crate::contract::analysis::Analysis;
use crate::contract::error::{Progress, RequestError};

/// Calls `$callback!` with every kind, in this order (the order of the
/// `JobItem` and answer `oneOf`s of the OpenAPI document).
macro_rules! for_each_kind {
    ($callback:ident) => {
        $callback! {
            /// `POST /api/v1/stability` (either cable model).
            Stability(
                crate::contract::ge::stability::AnyStabilityRequest
                    => crate::contract::ge::stability::AnyStabilityResponse
            ) "/api/v1/stability" compute_stability,
            /// `POST /api/v1/critical` (either cable model).
            Critical(
                crate::contract::ge::critical::AnyCriticalRequest
                    => crate::contract::ge::critical::AnyCriticalResponse
            ) "/api/v1/critical" compute_critical,
            /// `POST /api/v1/safe-rate`.
            SafeRate(
                crate::contract::string::dto::SafeRateRequest
                    => crate::contract::string::dto::SafeRateResponse
            ) "/api/v1/safe-rate" compute_safe_rate,
            /// `POST /api/v1/charts`, up to 1 000 000 points (GE: 2 000).
            Chart(
                crate::contract::ge::charts::AnyChartRequest
                    => crate::contract::ge::charts::AnyChartResponse
            ) "/api/v1/charts" create_chart,
            /// `POST /api/v1/simulate` (either cable model).
            Simulate(
                crate::contract::transient::any::AnySimulateRequest
                    => crate::contract::transient::any::AnySimulateResponse
            ) "/api/v1/simulate" run_simulation,
            /// `POST /api/v1/frequency-response`.
            FrequencyResponse(
                crate::contract::ge::charts::AnyFrequencyResponseRequest
                    => crate::contract::ge::charts::AnyFrequencyResponseResponse
            ) "/api/v1/frequency-response" compute_frequency_response,
            /// `POST /api/v1/equilibrium`.
            Equilibrium(
                crate::contract::equilibrium::dto::EquilibriumRequest
                    => crate::contract::equilibrium::dto::EquilibriumResponse
            ) "/api/v1/equilibrium" compute_equilibrium,
            /// `POST /api/v1/envelope`, up to 250 000 points (with progress).
            Envelope(
                crate::contract::envelope::dto::EnvelopeRequest
                    => crate::contract::envelope::dto::EnvelopeResponse
            ) "/api/v1/envelope" compute_envelope,
            /// `POST /api/v1/bands`, up to 2 000 000 chart points (samples × rates).
            Bands(
                crate::contract::bands::BandsRequest => crate::contract::bands::BandsResponse
            ) "/api/v1/bands" compute_bands,
            /// `POST /api/v1/plan`: the deployment plan (progress of its transient check).
            Plan(
                crate::contract::plan::PlanRequest => crate::contract::plan::PlanResponse
            ) "/api/v1/plan" compute_plan,
            /// `POST /api/v1/plan/bands`.
            PlanBands(
                crate::contract::bands::PlanBandsRequest
                    => crate::contract::bands::PlanBandsResponse
            ) "/api/v1/plan/bands" compute_plan_bands,
            /// `POST /api/v1/envelope/bands`, up to 2 000 000 equilibria (samples × cells).
            EnvelopeBands(
                crate::contract::bands::EnvelopeBandsRequest
                    => crate::contract::bands::EnvelopeBandsResponse
            ) "/api/v1/envelope/bands" compute_envelope_bands,
            /// `POST /api/v1/dynamics`: one run in time (progress in steps).
            Dynamics(
                crate::contract::dynamics::DynamicsRequest
                    => crate::contract::dynamics::DynamicsResponse
            ) "/api/v1/dynamics" run_dynamics,
            /// `POST /api/v1/dynamics/peaks`: Monte Carlo over turbulence seeds, chunked by sample.
            DynamicsPeaks(
                crate::contract::dynamics::DynamicsPeaksRequest
                    => crate::contract::dynamics::DynamicsPeaksResponse
            ) "/api/v1/dynamics/peaks" run_dynamics_peaks,
            /// `POST /api/v1/windows`: launch windows from a forecast (progress in plans).
            Windows(
                crate::contract::windows::WindowsRequest
                    => crate::contract::windows::WindowsResponse
            ) "/api/v1/windows" compute_windows,
        }
    };
}
pub(crate) use for_each_kind;

/// A kind, for code that picks it by name at run time (the CLI, tests).
#[derive(Clone, Copy)]
pub struct Kind {
    /// [`Analysis::NAME`].
    pub name: &'static str,
    /// Its synchronous route.
    pub path: &'static str,
    /// [`Analysis::ABOUT`]: the CLI subcommand's help.
    pub about: &'static str,
    /// The answer's schema name in the OpenAPI document.
    pub response_schema: fn() -> String,
    /// Parses a body, runs it with `progress` and gives the answer as
    /// pretty JSON (the CLI's output).
    pub run_pretty: fn(&[u8], &dyn Progress) -> Result<String, RequestError>,
    /// Parses a body and gives its [`Analysis::prepare`] verdict.
    pub prepare: fn(&[u8]) -> Result<(), RequestError>,
}

impl Kind {
    const fn of<A: Analysis>(path: &'static str) -> Self {
        Self {
            name: A::NAME,
            path,
            about: A::ABOUT,
            response_schema: response_schema::<A>,
            run_pretty: run_pretty::<A>,
            prepare: prepare::<A>,
        }
    }
}

fn response_schema<A: Analysis>() -> String {
    <A::Response as utoipa::ToSchema>::name().into_owned()
}

fn run_pretty<A: Analysis>(body: &[u8], progress: &dyn Progress) -> Result<String, RequestError> {
    let answer = A::parse(body)?.run(progress)?;
    Ok(serde_json::to_string_pretty(&answer).expect("answers serialise"))
}

fn prepare<A: Analysis>(body: &[u8]) -> Result<(), RequestError> {
    A::parse(body)?.prepare()
}

macro_rules! kinds_list {
    ($($(#[$doc:meta])* $variant:ident($req:ty => $resp:ty) $path:literal $op:ident),* $(,)?) => {
        /// Every kind, in the list's order.
        pub const KINDS: &[Kind] = &[$(Kind::of::<$req>($path)),*];

        // Each line's answer type is its kind's `Analysis::Response`.
        $(const _: fn(<$req as Analysis>::Response) -> $resp = |r| r;)*
    };
}
for_each_kind!(kinds_list);

/// The kind named `name`.
pub fn kind(name: &str) -> Option<&'static Kind> {
    KINDS.iter().find(|k| k.name == name)
}

/// The schema names of the kinds' answers, in the list's order: the
/// `result` of a batch item, and (with the batch's outcome) of a job.
pub fn response_schemas() -> Vec<String> {
    KINDS.iter().map(|k| (k.response_schema)()).collect()
}
