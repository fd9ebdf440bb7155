//! Named systems per token (SPEC §9): `PUT/GET/DELETE /api/v1/systems/{name}`,
//! `GET /api/v1/systems`, kept in the job store (SQLite or PostgreSQL) under
//! (token owner, name), at most [`MAX_SYSTEMS_PER_OWNER`] per token; and
//! `GET /api/v1/presets`, the tether and aerostat presets with their
//! figures and sources. A request names a stored system with
//! `"system": "name"` ([`crate::contract::system::resolve`]).

use axum::Extension;
use axum::extract::{Path, State};
use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::api::AppState;
use crate::api::auth::Caller;
use crate::api::error::{ApiError, JsonBody};
use crate::contract::RequestError;
use crate::contract::error::ErrorBody;
use crate::contract::system::presets::PresetsResponse;
use crate::contract::system::resolve::check_name;
use crate::contract::system::{SystemDescription, validate};
use crate::jobs::store::{MAX_SYSTEMS_PER_OWNER, PutSystem, StoredSystem};

/// A stored system.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
pub struct SystemView {
    pub name: String,
    pub created_at: String,
    pub updated_at: String,
    /// The system objects as stored.
    #[schema(value_type = SystemDescription)]
    pub system: serde_json::Value,
}

/// One line of the listing.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
pub struct SystemEntry {
    pub name: String,
    pub updated_at: String,
}

/// The token's stored systems, by name.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
pub struct SystemList {
    pub systems: Vec<SystemEntry>,
}

use crate::api::jobs::{blocking, json_response};

fn owner(caller: &Caller) -> String {
    caller.owner.clone().unwrap_or_default()
}

fn name_of(name: &str) -> Result<(), ApiError> {
    check_name("name", name).map_err(|e| ApiError::from(RequestError::from(e)))
}

fn view(s: StoredSystem) -> SystemView {
    SystemView {
        system: serde_json::from_str(&s.body).unwrap_or(serde_json::Value::Null),
        name: s.name,
        created_at: s.created_at,
        updated_at: s.updated_at,
    }
}

/// Checks a system body: the §9 objects (every part optional, unknown
/// fields refused), each given part within its bounds.
pub fn check_description(body: &[u8]) -> Result<serde_json::Value, RequestError> {
    let d: SystemDescription = crate::contract::parse_plain(body)?;
    if let Some(c) = &d.cable {
        c.check_given("cable")?;
        let forms = c.mass_per_length_kg_m.is_some() as u8
            + (c.density_kg_m3.is_some() || c.area_m2.is_some()) as u8;
        if forms > 0 || c.preset.is_some() {
            c.mass_per_length()?;
        }
    }
    if let Some(a) = &d.aerostat {
        a.check_given("aerostat")?;
        if a.net_buoyancy_n.is_some() {
            a.net_buoyancy("aerostat")?;
        }
    }
    if let Some(w) = &d.wind {
        w.check()?;
    }
    if let Some(w) = &d.winch {
        w.check("winch")?;
    }
    if let Some(v) = d.required_safety_factor_nondim {
        validate::required_safety_factor(v)?;
    }
    if let Some(v) = d.lift_reserve_nondim {
        validate::lift_reserve(v)?;
    }
    if let Some(v) = d.initial_length_m {
        crate::numerics::params::ranges::INITIAL_LENGTH_M.check("initial_length_m", v)?;
    }
    if let Some(v) = d.gravity_m_s2 {
        crate::numerics::params::ranges::GRAVITY_M_S2.check("gravity_m_s2", v)?;
    }
    Ok(serde_json::from_slice(body).expect("parsed above"))
}

/// Store (or replace) a named system for this token.
#[utoipa::path(
    put, path = "/api/v1/systems/{name}", operation_id = "put_system", tag = "systems",
    params(("name" = String, Path, description = "1 to 64 letters, digits, '-', '_' or '.', starting with a letter or digit, with single dots between other characters (never `.`, `..` or anything read as a path)", min_length = 1, max_length = 64, pattern = r"^[A-Za-z0-9](\.?[A-Za-z0-9_-])*$")),
    request_body(content = SystemDescription, description = "The system objects (SPEC §9), without `system`"),
    responses(
        (status = 200, description = "Replaced", body = SystemView),
        (status = 201, description = "Stored", body = SystemView),
        (status = 400, description = "Malformed JSON", body = ErrorBody),
        (status = 413, description = "Body larger than the limit", body = ErrorBody),
        (status = 415, description = "Content type is not JSON", body = ErrorBody),
        (status = 422, description = "Invalid system or name, or this token already has 100 systems", body = ErrorBody),
        (status = 429, description = "This token's store quota (`store_quota_full`): its jobs and named systems would keep more than `TETHERPLAN_TOKEN_MAX_STORED_BYTES` (1 GiB by default)", body = ErrorBody,
            headers(("Retry-After" = u32, description = "Seconds until this token's oldest finished job expires (absent when none has finished)"))),
        (status = 500, description = "Job store failure", body = ErrorBody),
    )
)]
pub async fn put_system(
    State(app): State<AppState>,
    Extension(caller): Extension<Caller>,
    Path(name): Path<String>,
    JsonBody(body): JsonBody,
) -> Result<Response, ApiError> {
    name_of(&name)?;
    let value = check_description(&body)?;
    let text = serde_json::to_string(&value).expect("JSON serialises");
    let queue = app.queue.clone();
    let owner = owner(&caller);
    let quota = queue.limits().max_stored_bytes_per_token;
    let retention_s = queue.limits().job_retention.as_secs_f64();
    let (put, stored) = blocking(move || {
        let put = queue
            .store
            .put_system(&owner, &name, &text, MAX_SYSTEMS_PER_OWNER, quota)?;
        let stored = queue.store.get_system(&owner, &name)?;
        Ok((put, stored))
    })
    .await?;
    let status = match put {
        PutSystem::Created => StatusCode::CREATED,
        PutSystem::Updated => StatusCode::OK,
        PutSystem::Full { max } => {
            return Err(ApiError::new(
                StatusCode::UNPROCESSABLE_ENTITY,
                "too_many_systems",
                Some("name"),
                format!("this token already has {max} stored systems: delete one first"),
            ));
        }
        PutSystem::StoreFull {
            stored,
            limit,
            oldest_finished_s,
        } => {
            return Err(crate::api::jobs::store_quota_full(
                format!(
                    "this token keeps {stored} bytes of jobs and named systems and this system \
                     would take it past the {limit} bytes kept per token: delete systems it no \
                     longer needs, or wait until its finished jobs expire"
                ),
                oldest_finished_s,
                retention_s,
            ));
        }
    };
    let stored = stored.ok_or_else(|| ApiError::internal("the stored system vanished"))?;
    Ok(json_response(status, &view(stored)))
}

/// One stored system of this token.
#[utoipa::path(
    get, path = "/api/v1/systems/{name}", operation_id = "get_system", tag = "systems",
    params(("name" = String, Path, description = "The system's name", min_length = 1, max_length = 64, pattern = r"^[A-Za-z0-9](\.?[A-Za-z0-9_-])*$")),
    responses(
        (status = 200, description = "The system", body = SystemView),
        (status = 404, description = "No such system for this token", body = ErrorBody),
        (status = 422, description = "Invalid name", body = ErrorBody),
        (status = 500, description = "Job store failure", body = ErrorBody),
    )
)]
pub async fn get_system(
    State(app): State<AppState>,
    Extension(caller): Extension<Caller>,
    Path(name): Path<String>,
) -> Result<Response, ApiError> {
    name_of(&name)?;
    let queue = app.queue.clone();
    let owner = owner(&caller);
    let n = name.clone();
    let stored = blocking(move || Ok(queue.store.get_system(&owner, &n)?)).await?;
    match stored {
        Some(s) => Ok(json_response(StatusCode::OK, &view(s))),
        None => Err(ApiError::not_found(format!("no system named `{name}`"))),
    }
}

/// Delete a stored system of this token.
#[utoipa::path(
    delete, path = "/api/v1/systems/{name}", operation_id = "delete_system", tag = "systems",
    params(("name" = String, Path, description = "The system's name", min_length = 1, max_length = 64, pattern = r"^[A-Za-z0-9](\.?[A-Za-z0-9_-])*$")),
    responses(
        (status = 204, description = "Deleted"),
        (status = 404, description = "No such system for this token", body = ErrorBody),
        (status = 422, description = "Invalid name", body = ErrorBody),
        (status = 500, description = "Job store failure", body = ErrorBody),
    )
)]
pub async fn delete_system(
    State(app): State<AppState>,
    Extension(caller): Extension<Caller>,
    Path(name): Path<String>,
) -> Result<Response, ApiError> {
    name_of(&name)?;
    let queue = app.queue.clone();
    let owner = owner(&caller);
    let n = name.clone();
    if blocking(move || Ok(queue.store.delete_system(&owner, &n)?)).await? {
        Ok(StatusCode::NO_CONTENT.into_response())
    } else {
        Err(ApiError::not_found(format!("no system named `{name}`")))
    }
}

/// The stored systems of this token, by name.
#[utoipa::path(
    get, path = "/api/v1/systems", operation_id = "list_systems", tag = "systems",
    responses(
        (status = 200, description = "The systems", body = SystemList),
        (status = 500, description = "Job store failure", body = ErrorBody),
    )
)]
pub async fn list_systems(
    State(app): State<AppState>,
    Extension(caller): Extension<Caller>,
) -> Result<Response, ApiError> {
    let queue = app.queue.clone();
    let owner = owner(&caller);
    let list = blocking(move || Ok(queue.store.list_systems(&owner)?)).await?;
    Ok(json_response(
        StatusCode::OK,
        &SystemList {
            systems: list
                .into_iter()
                .map(|s| SystemEntry {
                    name: s.name,
                    updated_at: s.updated_at,
                })
                .collect(),
        },
    ))
}

/// The tether and aerostat presets, each with its figures and sources.
#[utoipa::path(
    get, path = "/api/v1/presets", operation_id = "list_presets", tag = "systems",
    responses((status = 200, description = "The presets", body = PresetsResponse))
)]
pub async fn list_presets() -> Response {
    json_response(StatusCode::OK, &crate::contract::system::presets::presets())
}

impl AppState {
    /// A synchronous request with its named system resolved (the body as
    /// it is when it names none). Called on the solve thread.
    pub(crate) fn resolve_body(
        &self,
        caller: &Caller,
        body: &[u8],
    ) -> Result<Option<Vec<u8>>, ApiError> {
        let queue = self.queue.clone();
        crate::contract::system::resolve::resolve_body::<ApiError>(body, &mut |name| {
            Ok(queue.stored_system(caller.owner.as_deref(), name)?)
        })
    }
}
