//! Response hardening and the Host allow-list.
//!
//! * [`security_headers`]: every response carries a Content-Security-Policy
//!   (scripts, styles, fetches only from this origin; images also from
//!   `data:`/`blob:` for the PNG export; no framing, no plugins),
//!   `X-Content-Type-Options: nosniff` and `Referrer-Policy: no-referrer`.
//! * [`HostAllowList`]: a request whose `Host` header names a host not on
//!   the list gets 421 (Misdirected Request), which defeats DNS rebinding (a
//!   page on another site that re-points its own name at this server). By
//!   default the list holds the loopback names (`localhost`, `127.0.0.1`,
//!   `[::1]`) and the bind address; `TETHERPLAN_ALLOWED_HOSTS` adds names
//!   (comma-separated; `*` allows any host). The port is not checked.
//!   A request without a Host header (HTTP/1.0) passes: browsers always
//!   send one. Two Host headers are 400; an absolute-form target
//!   (`GET http://host/…`) must name an allowed host as well.

use std::net::{IpAddr, SocketAddr};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use axum::extract::Request;
use axum::http::{HeaderValue, StatusCode, header};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};

use crate::api::error::ApiError;

/// The Content-Security-Policy of every response.
pub const CONTENT_SECURITY_POLICY: &str = "default-src 'self'; script-src 'self'; \
    style-src 'self' 'unsafe-inline'; img-src 'self' data: blob:; connect-src 'self'; \
    object-src 'none'; base-uri 'self'; frame-ancestors 'none'; form-action 'self'";

/// Adds the security headers to a response (axum `map_response`).
pub async fn security_headers(mut response: Response) -> Response {
    let h = response.headers_mut();
    h.insert(
        header::CONTENT_SECURITY_POLICY,
        HeaderValue::from_static(CONTENT_SECURITY_POLICY),
    );
    h.insert(
        header::X_CONTENT_TYPE_OPTIONS,
        HeaderValue::from_static("nosniff"),
    );
    h.insert(
        header::REFERRER_POLICY,
        HeaderValue::from_static("no-referrer"),
    );
    response
}

/// Host names (lower case, without port) a request may address.
#[derive(Clone, Debug)]
pub struct HostAllowList {
    any: bool,
    hosts: Arc<Vec<String>>,
}

impl HostAllowList {
    /// Loopback names, the bind address, and `extra` (comma-separated; `*`
    /// allows every host).
    pub fn new(bind: SocketAddr, extra: Option<&str>) -> Self {
        let mut hosts: Vec<String> = vec!["localhost".into(), "127.0.0.1".into(), "[::1]".into()];
        if !bind.ip().is_unspecified() {
            hosts.push(host_of_ip(bind.ip()));
        }
        let mut any = false;
        for name in extra.unwrap_or("").split(',') {
            let name = name.trim().to_ascii_lowercase();
            if name == "*" {
                any = true;
            } else if !name.is_empty() {
                hosts.push(strip_port(&name).to_string());
            }
        }
        Self {
            any,
            hosts: Arc::new(hosts),
        }
    }

    /// Does this `Host` header value name an allowed host?
    pub fn allows(&self, host_header: &str) -> bool {
        if self.any {
            return true;
        }
        let host = strip_port(host_header.trim()).to_ascii_lowercase();
        let host = host.strip_suffix('.').unwrap_or(&host);
        self.hosts.iter().any(|h| h == host)
            || host
                .strip_suffix(".localhost")
                .is_some_and(|sub| !sub.is_empty())
    }

    /// The allowed names, for the start-up log.
    pub fn describe(&self) -> String {
        if self.any {
            "any host".into()
        } else {
            self.hosts.join(", ")
        }
    }

    /// The middleware (axum `from_fn_with_state`).
    pub async fn check(
        axum::extract::State(list): axum::extract::State<HostAllowList>,
        request: Request,
        next: Next,
    ) -> Response {
        let mut hosts = request.headers().get_all(header::HOST).iter();
        let host = hosts.next();
        if hosts.next().is_some() {
            return ApiError::new(
                StatusCode::BAD_REQUEST,
                "bad_request",
                Some("Host"),
                "a request carries one Host header (RFC 9112 §3.2), this one has several",
            )
            .into_response();
        }
        let refuse = |shown: &[u8]| {
            let shown = String::from_utf8_lossy(shown)
                .chars()
                .take(100)
                .collect::<String>();
            ApiError::new(
                StatusCode::MISDIRECTED_REQUEST,
                "host_not_allowed",
                Some("Host"),
                format!(
                    "host {shown:?} is not served here; the operator can allow it with TETHERPLAN_ALLOWED_HOSTS"
                ),
            )
            .into_response()
        };
        if let Some(host) = host {
            let ok = host.to_str().map(|h| list.allows(h)).unwrap_or(false);
            if !ok {
                return refuse(host.as_bytes());
            }
        }
        // An absolute-form target (`GET http://other.example/ HTTP/1.1`)
        // names the host it addresses: it must be allowed too.
        if let Some(authority) = request.uri().authority() {
            let named = authority.as_str();
            let named = named.rsplit_once('@').map_or(named, |(_, h)| h);
            if !list.allows(named) {
                return refuse(named.as_bytes());
            }
        }
        next.run(request).await
    }
}

/// The files of `dir` (`--static-dir`), confined to it: a path that
/// resolves (through a symlink) outside the directory is 404, as if it
/// were not there. `..` segments are already refused by `ServeDir`.
pub fn confined_static_dir(dir: &Path) -> axum::Router {
    let root = Arc::new(std::fs::canonicalize(dir).unwrap_or_else(|_| dir.to_path_buf()));
    axum::Router::new()
        .fallback_service(tower_http::services::ServeDir::new(dir))
        .layer(axum::middleware::from_fn_with_state(root, confine))
}

async fn confine(
    axum::extract::State(root): axum::extract::State<Arc<PathBuf>>,
    request: Request,
    next: Next,
) -> Response {
    let decoded = percent_decode(request.uri().path());
    let candidate = root.join(decoded.trim_start_matches('/'));
    let root2 = root.clone();
    let escapes = tokio::task::spawn_blocking(move || {
        std::fs::canonicalize(&candidate).is_ok_and(|real| !real.starts_with(&*root2))
    })
    .await
    .unwrap_or(true);
    if escapes {
        return ApiError::not_found(format!("no file {}", request.uri().path())).into_response();
    }
    next.run(request).await
}

/// `%2e%2E` → `..`: the percent-decoding of a URL path (invalid escapes
/// kept as they are; invalid UTF-8 replaced).
fn percent_decode(path: &str) -> String {
    let b = path.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            let hex = |c: u8| (c as char).to_digit(16);
            if let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

fn host_of_ip(ip: IpAddr) -> String {
    match ip {
        IpAddr::V4(v4) => v4.to_string(),
        IpAddr::V6(v6) => format!("[{v6}]"),
    }
}

/// `host:port` → `host`; `[v6]:port` → `[v6]`. Anything after `]` other
/// than `:digits` is kept (`[::1]evil.com` is not `[::1]`).
fn strip_port(h: &str) -> &str {
    if h.starts_with('[') {
        return match h.find(']') {
            Some(end) => {
                let rest = &h[end + 1..];
                let port_only = rest.is_empty()
                    || rest
                        .strip_prefix(':')
                        .is_some_and(|p| p.bytes().all(|b| b.is_ascii_digit()));
                if port_only { &h[..=end] } else { h }
            }
            None => h,
        };
    }
    match h.rsplit_once(':') {
        Some((host, port)) if port.bytes().all(|b| b.is_ascii_digit()) => host,
        _ => h,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn loopback_and_bind_address_are_allowed_by_default() {
        let list = HostAllowList::new("10.1.2.3:8080".parse().unwrap(), None);
        for ok in [
            "localhost",
            "localhost:8080",
            "LOCALHOST:1",
            "127.0.0.1:8080",
            "[::1]:8080",
            "10.1.2.3:8080",
            "app.localhost:8080",
            "localhost.",
        ] {
            assert!(list.allows(ok), "{ok}");
        }
        for bad in [
            "evil.example:8080",
            "10.1.2.4",
            "localhost.evil.example",
            "",
            "[::2]:80",
            "[::1]evil.com",
            "[::1].evil.com",
            "[::1]:80evil.com",
        ] {
            assert!(!list.allows(bad), "{bad}");
        }
    }

    #[test]
    fn percent_decoding_of_paths() {
        assert_eq!(percent_decode("/a%2Fb%2e%2E/c%20d"), "/a/b../c d");
        assert_eq!(percent_decode("/100%"), "/100%");
        assert_eq!(percent_decode("/%zz%4"), "/%zz%4");
    }

    /// A symlink in the static directory pointing outside it is not
    /// followed (404); files inside are served.
    #[tokio::test]
    async fn static_files_do_not_follow_symlinks_out() {
        use tower::ServiceExt;
        let base = std::env::temp_dir().join(format!("tp-static-{}", std::process::id()));
        let dir = base.join("static");
        let outside = base.join("secret");
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::create_dir_all(&outside).unwrap();
        std::fs::write(dir.join("index.html"), "page").unwrap();
        std::fs::write(outside.join("key.txt"), "secret").unwrap();
        std::os::unix::fs::symlink(&outside, dir.join("link")).unwrap();
        std::os::unix::fs::symlink(outside.join("key.txt"), dir.join("key.txt")).unwrap();
        let app = confined_static_dir(&dir);
        let get = |uri: &str| {
            axum::http::Request::builder()
                .uri(uri)
                .body(axum::body::Body::empty())
                .unwrap()
        };
        for (uri, status) in [
            ("/index.html", 200),
            ("/link/key.txt", 404),
            ("/key.txt", 404),
            ("/%6Cink/key.txt", 404),
        ] {
            let resp = app.clone().oneshot(get(uri)).await.unwrap();
            assert_eq!(resp.status().as_u16(), status, "{uri}");
        }
        std::fs::remove_dir_all(&base).unwrap();
    }

    #[test]
    fn extra_names_and_wildcard() {
        let list = HostAllowList::new(
            "0.0.0.0:8080".parse().unwrap(),
            Some(" Plan.Example.org:443 , [fd00::1]"),
        );
        assert!(list.allows("plan.example.org"));
        assert!(list.allows("[fd00::1]:8080"));
        assert!(!list.allows("0.0.0.0:8080"));
        let any = HostAllowList::new("0.0.0.0:8080".parse().unwrap(), Some("*"));
        assert!(any.allows("anything.example"));
    }
}
