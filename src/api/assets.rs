//! The chart page's files, built into the binary (`static/` at compile
//! time, through `include_dir`), so `tetherplan serve` serves `/` from any
//! working directory. `--static-dir` (env `TETHERPLAN_STATIC_DIR`) serves a
//! directory instead (for editing the page without rebuilding).

use axum::http::{HeaderValue, Method, StatusCode, Uri, header};
use axum::response::{IntoResponse, Response};
use include_dir::{Dir, include_dir};

/// `static/` as it was when the binary was built.
pub static STATIC: Dir<'static> = include_dir!("$CARGO_MANIFEST_DIR/static");

/// The media type of a file, by extension.
pub fn content_type(path: &str) -> &'static str {
    match path.rsplit_once('.').map(|(_, e)| e.to_ascii_lowercase()) {
        Some(e) => match e.as_str() {
            "html" | "htm" => "text/html; charset=utf-8",
            "js" | "mjs" => "text/javascript; charset=utf-8",
            "css" => "text/css; charset=utf-8",
            "json" => "application/json",
            "svg" => "image/svg+xml",
            "png" => "image/png",
            "ico" => "image/x-icon",
            "txt" | "md" | "license" => "text/plain; charset=utf-8",
            "csv" => "text/csv; charset=utf-8",
            "wasm" => "application/wasm",
            _ => "application/octet-stream",
        },
        None => "text/plain; charset=utf-8",
    }
}

/// Serves an embedded file (`/` and directories: their `index.html`);
/// 404 for anything else.
pub async fn serve_embedded(method: Method, uri: Uri) -> Response {
    if method != Method::GET && method != Method::HEAD {
        return (
            StatusCode::METHOD_NOT_ALLOWED,
            [(header::ALLOW, HeaderValue::from_static("GET, HEAD"))],
        )
            .into_response();
    }
    let path = uri.path().trim_start_matches('/');
    let file = if path.is_empty() || path.ends_with('/') {
        STATIC.get_file(format!("{path}index.html"))
    } else if path.split('/').any(|seg| seg == ".." || seg == ".") {
        None
    } else {
        STATIC
            .get_file(path)
            .or_else(|| STATIC.get_file(format!("{path}/index.html")))
    };
    match file {
        Some(f) => {
            let name = f.path().to_string_lossy().into_owned();
            let body = if method == Method::HEAD {
                axum::body::Body::empty()
            } else {
                axum::body::Body::from(f.contents())
            };
            (
                [
                    (header::CONTENT_TYPE, content_type(&name)),
                    (header::CACHE_CONTROL, "no-cache"),
                ],
                body,
            )
                .into_response()
        }
        None => (StatusCode::NOT_FOUND, "not found").into_response(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_page_and_its_scripts_are_embedded() {
        for f in [
            "index.html",
            "app.js",
            "plan.js",
            "shared/api.js",
            "shared/form.js",
            "shared/plot.js",
            "shared/export.js",
            "style.css",
            "vendor/uPlot.iife.min.js",
        ] {
            let file = STATIC
                .get_file(f)
                .unwrap_or_else(|| panic!("{f} is embedded"));
            let on_disk = std::fs::read(
                std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                    .join("static")
                    .join(f),
            )
            .unwrap();
            assert_eq!(file.contents(), on_disk.as_slice(), "{f}");
        }
        assert_eq!(content_type("a/b.JS"), "text/javascript; charset=utf-8");
    }

    /// Every script and stylesheet `index.html` loads is built in (the
    /// shared modules live in `static/shared/`).
    #[test]
    fn every_file_the_page_loads_is_embedded() {
        let html = std::str::from_utf8(STATIC.get_file("index.html").unwrap().contents()).unwrap();
        let mut loaded = 0;
        for attr in ["src=\"", "href=\""] {
            for part in html.split(attr).skip(1) {
                let target = part.split('"').next().unwrap();
                if !(target.ends_with(".js") || target.ends_with(".css")) {
                    continue;
                }
                assert!(STATIC.get_file(target).is_some(), "{target} is embedded");
                loaded += 1;
            }
        }
        assert!(
            loaded >= 12,
            "index.html loads {loaded} scripts and stylesheets"
        );
    }
}
