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
//!   send one.

use std::net::{IpAddr, SocketAddr};
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
        if let Some(host) = request.headers().get(header::HOST) {
            let ok = host.to_str().map(|h| list.allows(h)).unwrap_or(false);
            if !ok {
                let shown = String::from_utf8_lossy(host.as_bytes())
                    .chars()
                    .take(100)
                    .collect::<String>();
                return ApiError::new(
                    StatusCode::MISDIRECTED_REQUEST,
                    "host_not_allowed",
                    Some("Host"),
                    format!(
                        "host {shown:?} is not served here; the operator can allow it with TETHERPLAN_ALLOWED_HOSTS"
                    ),
                )
                .into_response();
            }
        }
        next.run(request).await
    }
}

fn host_of_ip(ip: IpAddr) -> String {
    match ip {
        IpAddr::V4(v4) => v4.to_string(),
        IpAddr::V6(v6) => format!("[{v6}]"),
    }
}

/// `host:port` → `host`; `[v6]:port` → `[v6]`.
fn strip_port(h: &str) -> &str {
    if h.starts_with('[') {
        return match h.find(']') {
            Some(end) => &h[..=end],
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
        ] {
            assert!(!list.allows(bad), "{bad}");
        }
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
