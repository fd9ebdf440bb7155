//! Writes the OpenAPI document to `openapi/openapi.json` (or the path given
//! as the first argument). Run after changing a route or a DTO:
//! `cargo run --release --bin gen_openapi`.

fn main() -> std::io::Result<()> {
    let path = std::env::args()
        .nth(1)
        .unwrap_or_else(|| concat!(env!("CARGO_MANIFEST_DIR"), "/openapi/openapi.json").into());
    if let Some(dir) = std::path::Path::new(&path).parent() {
        std::fs::create_dir_all(dir)?;
    }
    std::fs::write(&path, tetherplan::api::openapi::openapi_json())?;
    eprintln!("wrote {path}");
    Ok(())
}
