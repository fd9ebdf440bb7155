//! Layout rules: the numerical core stays pure.

use std::path::Path;

fn rust_files(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

#[test]
fn numerics_has_no_io_or_serialisation() {
    let mut files = Vec::new();
    rust_files(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("src/numerics"),
        &mut files,
    );
    assert!(files.len() >= 8, "found {} files", files.len());
    for file in files {
        let text = std::fs::read_to_string(&file).unwrap();
        for banned in [
            "tokio", "axum", "serde", "rusqlite", "std::fs", "println!", "std::net",
        ] {
            assert!(
                !text.contains(banned),
                "{} mentions {banned}",
                file.display()
            );
        }
        assert!(
            text.starts_with("//!"),
            "{} lacks a //! module doc",
            file.display()
        );
    }
}
