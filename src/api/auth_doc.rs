//! The API tokens in the OpenAPI document: a `bearer` security scheme,
//! optional on every `/api` operation (a server without tokens is open),
//! and the 401 answer each of them gives without a valid token.

use utoipa::Modify;
use utoipa::openapi::security::{HttpAuthScheme, HttpBuilder, SecurityRequirement, SecurityScheme};
use utoipa::openapi::{ContentBuilder, HeaderBuilder, OpenApi, Ref, ResponseBuilder, schema::Type};

/// Name of the security scheme.
pub const SCHEME: &str = "bearer";

/// Adds the scheme, the security requirement and the 401 response.
pub struct BearerTokens;

impl Modify for BearerTokens {
    fn modify(&self, doc: &mut OpenApi) {
        let components = doc.components.get_or_insert_with(Default::default);
        components.add_security_scheme(
            SCHEME,
            SecurityScheme::Http(
                HttpBuilder::new()
                    .scheme(HttpAuthScheme::Bearer)
                    .description(Some(
                        "One of the tokens in TETHERPLAN_API_TOKENS, when the server has any; \
                         jobs are visible to the token that submitted them only",
                    ))
                    .build(),
            ),
        );
        let unauthorized = ResponseBuilder::new()
            .description(
                "Missing or unknown API token (only when the server has TETHERPLAN_API_TOKENS)",
            )
            .header(
                "WWW-Authenticate",
                HeaderBuilder::new()
                    .schema(Some(
                        utoipa::openapi::schema::ObjectBuilder::new().schema_type(Type::String),
                    ))
                    .description(Some("`Bearer realm=\"tetherplan\"`"))
                    .build(),
            )
            .content(
                "application/json",
                ContentBuilder::new()
                    .schema(Some(Ref::from_schema_name("ErrorBody")))
                    .build(),
            )
            .build();
        for (path, item) in doc.paths.paths.iter_mut() {
            if !path.starts_with("/api/") {
                continue;
            }
            for op in [
                &mut item.get,
                &mut item.post,
                &mut item.put,
                &mut item.delete,
                &mut item.patch,
            ]
            .into_iter()
            .flatten()
            {
                op.responses
                    .responses
                    .insert("401".into(), unauthorized.clone().into());
                op.security = Some(vec![
                    SecurityRequirement::default(),
                    SecurityRequirement::new(SCHEME, Vec::<String>::new()),
                ]);
            }
        }
    }
}
