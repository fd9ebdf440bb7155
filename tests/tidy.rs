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

/// One Rust file of a module tree: its module path below the root
/// (`["ge", "critical"]`; `[]` for the root's `mod.rs`) and its text
/// without comments and without its `#[cfg(test)]` module.
struct ModuleFile {
    module: Vec<String>,
    is_dir_module: bool,
    text: String,
}

fn module_files(root: &Path) -> Vec<ModuleFile> {
    let mut files = Vec::new();
    rust_files(root, &mut files);
    files
        .into_iter()
        .filter(|file| {
            // binaries are crates of their own: `main.rs`, `bin/`
            let rel = file.strip_prefix(root).unwrap();
            rel != Path::new("main.rs") && !rel.starts_with("bin")
        })
        .map(|file| {
            let rel = file.strip_prefix(root).unwrap().with_extension("");
            let mut module: Vec<String> = rel
                .components()
                .map(|c| c.as_os_str().to_string_lossy().into_owned())
                .collect();
            // `lib.rs` is the crate's root module, a `mod.rs` of `src/`
            let is_dir_module = module.last().is_some_and(|m| m == "mod") || module == ["lib"];
            if is_dir_module {
                module.pop();
            }
            let mut text = std::fs::read_to_string(&file).unwrap();
            for tests in ["#[cfg(test)]\nmod ", "#[cfg(test)]\npub(crate) mod "] {
                if let Some(i) = text.find(tests) {
                    text.truncate(i);
                }
            }
            let text = text
                .lines()
                .map(|l| match l.find("//") {
                    Some(i) => &l[..i],
                    None => l,
                })
                .collect::<Vec<_>>()
                .join("\n");
            ModuleFile {
                module,
                is_dir_module,
                text,
            }
        })
        .collect()
}

fn is_ident(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

/// The paths a use tree names, each with the name it is imported as:
/// `a::{b, c::{d as e}}` at `prefix` gives `prefix::a::b` (as `b`) and
/// `prefix::a::c::d` (as `e`); `*` and `self` name the module itself.
fn use_tree(prefix: &[String], tree: &str) -> Vec<(Vec<String>, String)> {
    let tree = tree.trim_start();
    let mut segments = prefix.to_vec();
    let mut rest = tree;
    loop {
        let end = rest.find(|c: char| !is_ident(c)).unwrap_or(rest.len());
        if end > 0 && rest[end..].starts_with("::") {
            segments.push(rest[..end].to_string());
            rest = &rest[end + 2..];
        } else {
            break;
        }
    }
    if let Some(inner) = rest.strip_prefix('{') {
        let (mut depth, mut start, mut out) = (0usize, 0usize, Vec::new());
        for (i, c) in inner.char_indices() {
            match c {
                '{' => depth += 1,
                '}' if depth == 0 => {
                    out.extend(use_tree(&segments, &inner[start..i]));
                    return out;
                }
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    out.extend(use_tree(&segments, &inner[start..i]));
                    start = i + 1;
                }
                _ => {}
            }
        }
        return out;
    }
    if rest.starts_with('*') {
        return vec![(segments, "*".to_string())];
    }
    let end = rest.find(|c: char| !is_ident(c)).unwrap_or(rest.len());
    if end == 0 {
        return Vec::new();
    }
    let last = &rest[..end];
    let after = rest[end..].trim_start();
    let alias = after
        .strip_prefix("as ")
        .map(|a| {
            let a = a.trim_start();
            a[..a.find(|c: char| !is_ident(c)).unwrap_or(a.len())].to_string()
        })
        .unwrap_or_else(|| {
            if last == "self" {
                segments.last().cloned().unwrap_or_default()
            } else {
                last.to_string()
            }
        });
    if last != "self" {
        segments.push(last.to_string());
    }
    vec![(segments, alias)]
}

/// The file-level import graph of the module tree at `root` (its
/// `crate::<crate_path>::…`, `super::…`, `self::…` paths, and a `mod.rs`'s
/// paths into its children). A `pub use` is a re-export: a path through it
/// is followed to the file that defines the item, and the re-export itself
/// is an import of the file holding it (it cannot build without the file it
/// re-exports from: a circle through a `pub use` is a circle).
/// `crate_path` empty: the tree is the whole crate (`crate::…`).
fn import_graph(root: &Path, crate_path: &str) -> (Vec<String>, Vec<Vec<usize>>) {
    let files = module_files(root);
    let index: std::collections::HashMap<Vec<String>, usize> = files
        .iter()
        .enumerate()
        .map(|(i, f)| (f.module.clone(), i))
        .collect();
    let absolute = if crate_path.is_empty() {
        "crate::".to_string()
    } else {
        format!("crate::{crate_path}::")
    };
    // the module a path starts from, and the rest of the path
    let starts = |f: &ModuleFile, text: &str, at: usize| -> Option<(Vec<String>, usize)> {
        let before = text[..at].chars().next_back();
        if before.is_some_and(|c| is_ident(c) || c == ':') {
            return None;
        }
        let rest = &text[at..];
        if rest.starts_with(&absolute) {
            return Some((Vec::new(), absolute.len()));
        }
        if rest.starts_with("self::") {
            return Some((f.module.clone(), "self::".len()));
        }
        let mut base = f.module.clone();
        let mut len = 0;
        while rest[len..].starts_with("super::") {
            base.pop();
            len += "super::".len();
        }
        if len > 0 {
            return Some((base, len));
        }
        // a mod.rs naming its children directly
        if f.is_dir_module {
            let end = rest.find(|c: char| !is_ident(c)).unwrap_or(rest.len());
            let mut child = f.module.clone();
            child.push(rest[..end].to_string());
            if end > 0 && rest[end..].starts_with("::") && index.contains_key(&child) {
                return Some((f.module.clone(), 0));
            }
        }
        None
    };
    let reexports = |f: &ModuleFile| -> Vec<(usize, usize)> {
        let mut spans = Vec::new();
        for key in ["pub use ", "pub(crate) use ", "pub(super) use "] {
            let mut from = 0;
            while let Some(i) = f.text[from..].find(key) {
                let start = from + i;
                let end = start + f.text[start..].find(';').unwrap_or(f.text.len() - start);
                spans.push((start + key.len(), end));
                from = end;
            }
        }
        spans
    };
    // re-exports: (module, name) → the path it stands for
    let mut aliases: std::collections::HashMap<Vec<String>, Vec<String>> = Default::default();
    for f in &files {
        for (start, end) in reexports(f) {
            let tree = &f.text[start..end];
            let (base, skip) = starts(f, tree, 0).unwrap_or((f.module.clone(), 0));
            for (path, alias) in use_tree(&base, &tree[skip..]) {
                if alias != "*" {
                    let mut key = f.module.clone();
                    key.push(alias);
                    aliases.insert(key, path);
                }
            }
        }
    }
    let resolve = |path: &[String]| -> Option<usize> {
        let mut path = path.to_vec();
        for _ in 0..32 {
            let k = (0..=path.len())
                .rev()
                .find(|&k| index.contains_key(&path[..k]))?;
            match path.get(k).and_then(|_| aliases.get(&path[..=k])) {
                Some(target) => path = [target.clone(), path[k + 1..].to_vec()].concat(),
                None => return Some(index[&path[..k]]),
            }
        }
        None
    };
    let mut edges = vec![Vec::new(); files.len()];
    for (i, f) in files.iter().enumerate() {
        let mut text = f.text.clone();
        for (start, end) in reexports(f) {
            // the re-export's own path goes to the file defining the item
            let tree = &f.text[start..end];
            let (base, skip) = starts(f, tree, 0).unwrap_or((f.module.clone(), 0));
            for (path, _) in use_tree(&base, &tree[skip..]) {
                if let Some(j) = resolve(&path)
                    && j != i
                    && !edges[i].contains(&j)
                {
                    edges[i].push(j);
                }
            }
            text.replace_range(start..end, &" ".repeat(end - start));
        }
        for (at, _) in text.char_indices() {
            if let Some((base, skip)) = starts(f, &text, at) {
                for (path, _) in use_tree(&base, &text[at + skip..]) {
                    if let Some(j) = resolve(&path)
                        && j != i
                        && !edges[i].contains(&j)
                    {
                        edges[i].push(j);
                    }
                }
            }
        }
    }
    let names = files
        .iter()
        .map(|f| {
            if f.is_dir_module {
                format!("{}/mod.rs", f.module.join("/"))
                    .trim_start_matches('/')
                    .to_string()
            } else {
                format!("{}.rs", f.module.join("/"))
            }
        })
        .collect();
    (names, edges)
}

/// One cycle through each strongly connected part of the graph with more
/// than one file, as `a -> b -> a`.
fn cycles(names: &[String], edges: &[Vec<usize>]) -> Vec<String> {
    let n = names.len();
    let reach = |from: usize| {
        let mut seen = vec![false; n];
        let mut stack = vec![from];
        while let Some(v) = stack.pop() {
            for &w in &edges[v] {
                if !seen[w] {
                    seen[w] = true;
                    stack.push(w);
                }
            }
        }
        seen
    };
    let reaches: Vec<Vec<bool>> = (0..n).map(reach).collect();
    let mut done = vec![false; n];
    let mut out = Vec::new();
    for v in 0..n {
        if done[v] || !reaches[v][v] {
            continue;
        }
        // the part of v: every w with v → w → v; the shortest way round
        for w in 0..n {
            if reaches[v][w] && reaches[w][v] {
                done[w] = true;
            }
        }
        let mut prev = vec![usize::MAX; n];
        let mut queue = std::collections::VecDeque::from([v]);
        let mut seen = vec![false; n];
        'bfs: while let Some(x) = queue.pop_front() {
            for &y in &edges[x] {
                if y == v {
                    let mut path = vec![v];
                    let mut z = x;
                    while z != v {
                        path.push(z);
                        z = prev[z];
                    }
                    path.push(v);
                    let len = path.len();
                    path[1..len - 1].reverse();
                    let shown: Vec<&str> = path.iter().map(|&k| names[k].as_str()).collect();
                    let part: Vec<&str> = (0..n)
                        .filter(|&w| reaches[v][w] && reaches[w][v] && !path.contains(&w))
                        .map(|w| names[w].as_str())
                        .collect();
                    let mut cycle = shown.join(" -> ");
                    if !part.is_empty() {
                        // the rest of the strongly connected part
                        cycle += &format!(" (with {})", part.join(", "));
                    }
                    out.push(cycle);
                    break 'bfs;
                }
                if !seen[y] {
                    seen[y] = true;
                    prev[y] = x;
                    queue.push_back(y);
                }
            }
        }
    }
    out
}

#[test]
fn contract_files_import_each_other_without_cycles() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/contract");
    let (names, edges) = import_graph(&root, "contract");
    assert!(names.len() >= 30, "found {} files", names.len());
    let arrows: usize = edges.iter().map(Vec::len).sum();
    assert!(
        arrows >= 40,
        "found only {arrows} imports: is the parser blind?"
    );
    let found = cycles(&names, &edges);
    assert!(
        found.is_empty(),
        "src/contract files import each other in a circle:\n  {}",
        found.join("\n  ")
    );
}

#[test]
fn the_cycle_finder_sees_a_cycle() {
    // A tree written for the test: a → b → c → a through `crate::`,
    // `super::` and a parent's path into its child; d only re-exports c.
    let dir = std::env::temp_dir().join(format!("tidy-cycle-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("b")).unwrap();
    let write = |p: &str, s: &str| std::fs::write(dir.join(p), s).unwrap();
    write("mod.rs", "pub mod a;\npub mod b;\npub mod d;\n");
    write("a.rs", "use crate::m::b::{self, X};\n");
    write("b/mod.rs", "pub mod c;\nfn f() { c::g() }\n");
    write("b/c.rs", "use super::super::d::Y;\n");
    write("d.rs", "pub use crate::m::a::{Z as Y};\n");
    let (names, edges) = import_graph(&dir, "m");
    let found = cycles(&names, &edges);
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(found.len(), 1, "{found:?}");
    let mut files: Vec<&str> = found[0].split(" -> ").collect();
    assert_eq!(files.first(), files.last(), "{found:?}");
    files.pop();
    files.sort_unstable();
    // c.rs's path through d.rs's re-export goes to a.rs; d.rs imports
    // a.rs, but nothing imports d.rs's own items, so it is off the circle
    assert_eq!(files, ["a.rs", "b/c.rs", "b/mod.rs"], "{found:?}");
}

#[test]
fn the_cycle_finder_sees_a_cycle_through_a_reexport() {
    // x.rs re-exports y.rs's item and y.rs imports x.rs's own: a circle
    // that no `use` line shows as one (contract/ge/critical ↔ stability).
    let dir = std::env::temp_dir().join(format!("tidy-reexport-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let write = |p: &str, s: &str| std::fs::write(dir.join(p), s).unwrap();
    write("lib.rs", "pub mod x;\npub mod y;\npub mod z;\n");
    write("x.rs", "pub use super::y::T;\npub struct U;\n");
    write("y.rs", "use crate::x::U;\npub struct T;\n");
    write("z.rs", "use crate::x::T;\n");
    write("main.rs", "use crate::z;\n");
    let (names, edges) = import_graph(&dir, "");
    let found = cycles(&names, &edges);
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(found, ["x.rs -> y.rs -> x.rs"], "{names:?} {edges:?}");
    // z.rs's import through the re-export is an arrow to y.rs
    let z = names.iter().position(|n| n == "z.rs").unwrap();
    assert_eq!(
        edges[z]
            .iter()
            .map(|&j| names[j].as_str())
            .collect::<Vec<_>>(),
        ["y.rs"]
    );
}

/// The crate's file-level import graph (`src/`, binaries left out).
fn crate_graph() -> (Vec<String>, Vec<Vec<usize>>) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    import_graph(&root, "")
}

#[test]
fn src_files_import_each_other_without_cycles() {
    // every folder of src/ (and across folders): no file reaches itself
    // through `use`, paths or `pub use` re-exports
    let (names, edges) = crate_graph();
    assert!(names.len() >= 140, "found {} files", names.len());
    let arrows: usize = edges.iter().map(Vec::len).sum();
    assert!(
        arrows >= 600,
        "found only {arrows} imports: is the parser blind?"
    );
    let found = cycles(&names, &edges);
    assert!(
        found.is_empty(),
        "{} circles of files importing each other in src/:\n  {}",
        found.len(),
        found.join("\n  ")
    );
}

/// The layers of the crate, bottom first: a file imports only its own
/// layer or those below (`numerics` pure; `contract` JSON ↔ numerics; the
/// job engine and catalogue; `config` the flags; `api` the HTTP service).
const LAYERS: [&[&str]; 5] = [
    &["numerics", "limits", "shutdown"],
    &["contract"],
    &["jobs"],
    &["config"],
    &["api"],
];

#[test]
fn no_arrow_runs_back_up() {
    let (names, edges) = crate_graph();
    let layer = |name: &str| -> usize {
        let top = name.split(['/', '.']).next().unwrap();
        if name == "mod.rs" {
            return LAYERS.len(); // lib.rs: the crate root, above all
        }
        LAYERS
            .iter()
            .position(|l| l.contains(&top))
            .unwrap_or_else(|| panic!("src/{name}: its top module {top} has no layer in tidy.rs"))
    };
    let mut up = Vec::new();
    for (i, out) in edges.iter().enumerate() {
        for &j in out {
            if layer(&names[j]) > layer(&names[i]) {
                up.push(format!("{} -> {}", names[i], names[j]));
            }
        }
    }
    assert!(
        up.is_empty(),
        "imports running up the layers:\n  {}",
        up.join("\n  ")
    );
}

#[test]
fn jobs_do_not_import_config() {
    // config.rs sits above jobs/: it builds the job store and limits from
    // the flags; the jobs take what they need as their own types.
    let mut files = Vec::new();
    rust_files(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("src/jobs"),
        &mut files,
    );
    assert!(files.len() >= 5, "found {} files", files.len());
    for file in files {
        let text = std::fs::read_to_string(&file).unwrap();
        assert!(
            !text.contains("crate::config"),
            "{} names crate::config",
            file.display()
        );
    }
}
