//! The OpenAPI document (utoipa): every route, status and schema. Served at
//! `GET /openapi.json`, committed as `openapi/openapi.json` (written by
//! `cargo run --release --bin gen_openapi`; a test fails when it is stale).

use utoipa::OpenApi;

use crate::api::auth_doc::BearerTokens;
use crate::api::{Health, jobs};
use crate::contract::catalogue::for_each_kind;
use crate::contract::dto::*;
use crate::jobs::kinds::{
    BatchItemOutcome, BatchKind, BatchOutcome, BatchSubmission, JobItem, JobSubmission,
};
use crate::jobs::store::JobStatus;

/// The document's routes: every kind's (from the one list of kinds), the
/// named systems, the jobs and the meta routes.
macro_rules! api_doc {
    ($($(#[$doc:meta])* $variant:ident($req:ty => $resp:ty) $path:literal $op:ident),* $(,)?) => {
    #[derive(OpenApi)]
    #[openapi(
        info(
            title = "tetherplan",
            description = "Deployment planning for tethered aerostats: stability, critical time, safe rates and \
                deployment charts of a lengthening heavy cable. JSON in SI units; every field name ends in its unit \
                (`_m`, `_s`, `_m_s`, `_n`, `_kg`), non-dimensional values end in `_nondim`.\n\n\
                Every error is `{\"error\": {\"code\", \"field\", \"message\"}}`: 400 malformed JSON, 404 unknown \
                job or path (or another token's job), 401 missing or wrong API token (when the server has tokens; \
                `WWW-Authenticate: Bearer`), 405 wrong method, 409 cancelling a finished job, 413 oversize body, 415 not JSON, \
                422 invalid input or too large for a synchronous answer (`field` names the culprit), 429 job \
                queue full and 503 too many solves in flight (both with `Retry-After`), 504 no answer within the \
                solve timeout, 500 a bug."
        ),
        paths(
            $(crate::api::kinds::$op,)*
            crate::api::systems::put_system,
            crate::api::systems::get_system,
            crate::api::systems::delete_system,
            crate::api::systems::list_systems,
            crate::api::systems::list_presets,
            jobs::create_job,
            jobs::list_jobs,
            jobs::get_job,
            jobs::delete_job,
            crate::api::health::get_health,
            crate::api::forecast::get_forecast,
            get_openapi,
        ),
        components(schemas(
            ErrorBody, ErrorDetail, JobStatus, JobItem, JobSubmission, BatchSubmission, BatchKind,
            BatchOutcome, BatchItemOutcome, StabilityResponse, CriticalResponse, SafeRateResponse, ChartResponse,
            Health,
            crate::contract::ge_critical::GeCriticalResponse, crate::contract::ge::stability::GeStabilityResponse,
            Health, crate::contract::bands::BandsResponse,
            crate::contract::bands::PlanBandsResponse, crate::contract::bands::EnvelopeBandsResponse,
            crate::contract::dynamics::DynamicsResponse, crate::contract::dynamics::DynamicsPeaksResponse,
            crate::contract::windows::WindowsResponse,
        )),
        modifiers(&BearerTokens),
        tags(
            (name = "solve", description = "Synchronous answers (about a second at most)"),
            (name = "jobs", description = "Persisted batch jobs for large or many requests"),
            (name = "systems", description = "Named systems per token (SPEC §9) and the presets"),
            (name = "meta", description = "Liveness and this document"),
        )
    )]
    pub struct ApiDoc;
    };
}
for_each_kind!(api_doc);

/// The OpenAPI document of this service (JSON).
#[utoipa::path(
    get, path = "/openapi.json", operation_id = "get_openapi", tag = "meta",
    responses((status = 200, description = "This document (OpenAPI 3.1)", content_type = "application/json"))
)]
#[allow(dead_code)]
fn get_openapi() {}

/// The document, with the request examples, the cable's two forms and the
/// synchronous limits ([`crate::api::spec`]).
pub fn openapi() -> utoipa::openapi::OpenApi {
    let mut doc = ApiDoc::openapi();
    // A kind whose route has no description beyond its summary.
    for item in doc.paths.paths.values_mut() {
        if let Some(op) = item.post.as_mut()
            && op.description.as_deref() == Some("")
        {
            op.description = None;
        }
    }
    doc.merge(crate::api::flights::FlightsDoc::openapi());
    // The flights' operations are merged in after the derive's modifiers
    // ran: they need the token scheme and its 401 too.
    utoipa::Modify::modify(&BearerTokens, &mut doc);
    crate::api::spec::refine(doc)
}

/// The document as committed in `openapi/openapi.json` (pretty, newline-terminated).
pub fn openapi_json() -> String {
    let mut s = openapi().to_pretty_json().expect("the document serialises");
    s.push('\n');
    s
}
