//! The synchronous routes, one per analysis kind, made from the one list
//! of kinds ([`crate::contract::catalogue`]): `POST <route>` parses the
//! body (a named system merged in first), applies the kind's synchronous
//! limit ([`Analysis::check_sync`]: 422 `too_large` pointing at the job
//! queue) and its price ([`Analysis::price`]: refused past the budget, 503
//! while other priced work fills the pool) and runs it on the rayon pool ([`AppState::solve`]) with a
//! [`Deadline`]. Each handler carries its OpenAPI operation (every status
//! listed; summary and description from the kind).

use axum::Router;
use axum::extract::State;
use axum::response::Response;
use axum::routing::post;

use crate::api::AppState;
use crate::api::auth::Caller;
use crate::api::error::{ApiError, JsonBody};
use crate::api::solve::{Deadline, SolveCtx};
use crate::contract::analysis::Analysis;
use crate::contract::catalogue::for_each_kind;
use crate::contract::error::ErrorBody;

/// Parse, check the synchronous limit, solve: the route of kind `A`.
async fn solve_kind<A: Analysis>(
    app: AppState,
    caller: Caller,
    body: axum::body::Bytes,
) -> Result<Response, ApiError> {
    let resolver = app.clone();
    app.solve(move |ctx: &SolveCtx| {
        // A named system is merged in before the body is parsed.
        let resolved = resolver.resolve_body(&caller, &body)?;
        let body: &[u8] = resolved.as_deref().unwrap_or(&body);
        let req = A::parse(body)?;
        req.check_sync(ctx)?;
        // A kind prices only what its run would accept (None otherwise:
        // the run refuses the input, naming its field).
        let _admitted = match req.price() {
            Some(price) => Some(ctx.charge(&price, A::NAME)?),
            None => None,
        };
        let answer = req.run(&Deadline::after(ctx))?;
        Ok(crate::contract::finite::to_vec(&answer)?)
    })
    .await
}

macro_rules! kind_routes {
    ($($(#[$doc:meta])* $variant:ident($req:ty => $resp:ty) $path:literal $op:ident),* $(,)?) => {
        $(
            #[utoipa::path(
                post, path = $path, tag = "solve",
                summary = <$req as Analysis>::SUMMARY,
                description = <$req as Analysis>::DESCRIPTION,
                request_body(content = $req, description = "The system and the question (SI units)"),
                responses(
                    (status = 200, description = "The answer", body = $resp),
                    (status = 400, description = "Malformed JSON", body = ErrorBody),
                    (status = 413, description = "Body larger than the limit", body = ErrorBody),
                    (status = 415, description = "Content type is not JSON", body = ErrorBody),
                    (status = 422, description = "Invalid input (`invalid_input`) or too large for a synchronous answer (`too_large`: use /api/v1/jobs); `field` names the culprit", body = ErrorBody),
                    (status = 500, description = "Numerical failure on valid input (a bug)", body = ErrorBody),
                    (status = 503, description = "Too many solves in flight", body = ErrorBody,
                        headers(("Retry-After" = u32, description = "Seconds to wait before retrying"))),
                    (status = 504, description = "No answer within the solve timeout", body = ErrorBody),
                )
            )]
            pub async fn $op(
                State(app): State<AppState>,
                axum::Extension(caller): axum::Extension<Caller>,
                JsonBody(body): JsonBody,
            ) -> Result<Response, ApiError> {
                solve_kind::<$req>(app, caller, body).await
            }
        )*

        /// Every kind's synchronous route.
        pub fn routes(router: Router<AppState>) -> Router<AppState> {
            router$(.route($path, post($op)))*
        }
    };
}
for_each_kind!(kind_routes);
