//! API tokens. With `TETHERPLAN_API_TOKENS` set (comma-separated), every
//! `/api` route needs `Authorization: Bearer <token>`; anything else is 401
//! with the API's error body and `WWW-Authenticate: Bearer`. Without
//! tokens every route is open, as on a loopback-only server.
//!
//! Only SHA-256 hashes of the tokens are kept; the presented token is
//! hashed and compared with every configured hash in constant time (no
//! early exit, no length leak). A request's [`Caller`] carries the hash in
//! hex: it is stored as the owner of the jobs it submits, so a job is
//! visible to and cancellable by its own token only.

use std::sync::Arc;

use axum::extract::{Request, State};
use axum::http::{HeaderValue, StatusCode, header};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};
use sha2::{Digest, Sha256};

use crate::api::error::ApiError;

/// The realm named in `WWW-Authenticate`.
pub const REALM: &str = "tetherplan";

/// The configured tokens, as SHA-256 hashes.
#[derive(Clone, Debug, Default)]
pub struct Tokens {
    hashes: Vec<[u8; 32]>,
}

/// Who is calling: the owner of the jobs it submits (hex SHA-256 of its
/// token; None when the server has no tokens).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Caller {
    pub owner: Option<String>,
}

fn hash(token: &str) -> [u8; 32] {
    Sha256::digest(token.as_bytes()).into()
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// Equality of two digests in time independent of where they differ.
fn ct_eq(a: &[u8; 32], b: &[u8; 32]) -> bool {
    let diff = a
        .iter()
        .zip(b)
        .fold(0u8, |acc, (x, y)| acc | std::hint::black_box(x ^ y));
    std::hint::black_box(diff) == 0
}

impl Tokens {
    pub fn new(tokens: &[String]) -> Self {
        Self {
            hashes: tokens.iter().map(|t| hash(t)).collect(),
        }
    }

    pub fn is_enabled(&self) -> bool {
        !self.hashes.is_empty()
    }

    /// The owner id (hex hash) of `token`, if it is one of ours. Every
    /// configured hash is compared, whatever matches first.
    pub fn owner_of(&self, token: &str) -> Option<String> {
        let presented = hash(token);
        let mut found: Option<&[u8; 32]> = None;
        for h in &self.hashes {
            if ct_eq(h, &presented) {
                found = Some(h);
            }
        }
        found.map(|h| hex(h))
    }

    /// The owner id of a token, whether or not it is configured (tests, tools).
    pub fn owner_id(token: &str) -> String {
        hex(&hash(token))
    }
}

fn unauthorized(message: &str, invalid_token: bool) -> Response {
    let mut resp =
        ApiError::new(StatusCode::UNAUTHORIZED, "unauthorized", None, message).into_response();
    let challenge = if invalid_token {
        format!("Bearer realm=\"{REALM}\", error=\"invalid_token\"")
    } else {
        format!("Bearer realm=\"{REALM}\"")
    };
    resp.headers_mut().insert(
        header::WWW_AUTHENTICATE,
        HeaderValue::from_str(&challenge).expect("a valid header"),
    );
    resp
}

/// Middleware: checks the bearer token of every `/api` request (when
/// tokens are configured) and attaches the [`Caller`] to every request.
pub async fn require_token(
    State(tokens): State<Arc<Tokens>>,
    mut req: Request,
    next: Next,
) -> Response {
    let path = req.uri().path();
    let guarded = tokens.is_enabled() && (path == "/api" || path.starts_with("/api/"));
    if !guarded {
        req.extensions_mut().insert(Caller::default());
        return next.run(req).await;
    }
    let presented = req
        .headers()
        .get(header::AUTHORIZATION)
        .and_then(|v| v.to_str().ok())
        .and_then(|v| {
            let (scheme, token) = v.trim().split_once(' ')?;
            scheme.eq_ignore_ascii_case("bearer").then(|| token.trim())
        })
        .filter(|t| !t.is_empty());
    let Some(token) = presented else {
        return unauthorized(
            "this server needs an API token: send `Authorization: Bearer <token>`",
            false,
        );
    };
    let Some(owner) = tokens.owner_of(token) else {
        return unauthorized("the API token is not valid on this server", true);
    };
    req.extensions_mut().insert(Caller { owner: Some(owner) });
    next.run(req).await
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::parse_tokens;

    #[test]
    fn tokens_are_parsed_hashed_and_matched() {
        let list = parse_tokens(Some(" alpha, ,beta ,"));
        assert_eq!(list, ["alpha", "beta"]);
        let tokens = Tokens::new(&list);
        assert!(tokens.is_enabled());
        assert_eq!(tokens.owner_of("alpha"), Some(Tokens::owner_id("alpha")));
        assert_eq!(tokens.owner_of("beta"), Some(Tokens::owner_id("beta")));
        assert_ne!(Tokens::owner_id("alpha"), Tokens::owner_id("beta"));
        assert_eq!(tokens.owner_of("alph"), None);
        assert_eq!(tokens.owner_of("alphaa"), None);
        assert_eq!(tokens.owner_of(""), None);
        assert!(!Tokens::new(&parse_tokens(None)).is_enabled());
        // SHA-256("abc"), FIPS 180-2 appendix B.1.
        assert_eq!(
            Tokens::owner_id("abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }
}
