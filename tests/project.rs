//! Properties of the project itself rather than of its numerics: the two README commands share
//! one build.

use std::collections::{BTreeMap, BTreeSet};
use std::process::Command;

/// Each crate's enabled features as `cargo tree` resolves them for the given dependency kinds:
/// a set per crate, since a crate built for build scripts too is compiled once per feature set.
fn features(edges: &str) -> BTreeMap<String, BTreeSet<String>> {
    let out = Command::new(env!("CARGO"))
        .args([
            "tree",
            "--offline",
            "--prefix",
            "none",
            "-f",
            "{p}|{f}",
            "-e",
            edges,
        ])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("cargo runs");
    assert!(
        out.status.success(),
        "cargo tree: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut crates: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for line in String::from_utf8(out.stdout).unwrap().lines() {
        if let Some((package, features)) = line.trim_end_matches(" (*)").split_once('|') {
            crates
                .entry(package.trim().to_string())
                .or_default()
                .insert(features.trim().to_string());
        }
    }
    crates
}

/// `cargo test` turns on the dev-dependencies; if they turned on a feature in a crate that
/// `cargo run` also builds, every crate above it (most of Rerun) would compile twice. Every crate
/// of the run's build has the same features in the tests' build.
#[test]
fn tests_reuse_every_crate_of_the_run_build() {
    let run = features("normal");
    let test = features("normal,dev");
    assert!(run.len() > 100, "cargo tree listed {} crates", run.len());
    let differ: Vec<String> = run
        .iter()
        .filter_map(|(package, f)| {
            let t = test.get(package)?;
            (!f.is_subset(t)).then(|| format!("{package}: run {f:?}, test {t:?}"))
        })
        .collect();
    assert!(
        differ.is_empty(),
        "features that differ between `cargo run` and `cargo test` (pin them in Cargo.toml):\n{}",
        differ.join("\n")
    );
}

/// Which of physlab's top-level modules each module may name (`crate::<module>` or, from the
/// binary, `physlab::<module>`): the layering of ARCHITECTURE.md. A module not listed here fails
/// the test until its layer is stated.
const MAY_IMPORT: &[(&str, &[&str])] = &[
    (
        "main",
        &["app", "cli", "error", "interrupt", "output", "shell"],
    ),
    (
        "app",
        &[
            "cli",
            "record",
            "rrd",
            "diagram",
            "report",
            "study",
            "scene",
            "integrate",
            "elliptic",
            "interrupt",
            "error",
            "format",
            "palette",
            "output",
            "shell",
        ],
    ),
    (
        "cli",
        &[
            "scene",
            "integrate",
            "study",
            "error",
            "format",
            "interrupt",
            "output",
            "shell",
        ],
    ),
    (
        "record",
        &[
            "shell",
            "rrd",
            "diagram",
            "report",
            "scene",
            "integrate",
            "study",
            "elliptic",
            "interrupt",
            "error",
            "format",
            "palette",
            "output",
        ],
    ),
    ("rrd", &["interrupt", "error", "format"]),
    (
        "diagram",
        &[
            "report",
            "study",
            "scene",
            "integrate",
            "palette",
            "error",
            "format",
            "output",
        ],
    ),
    (
        "report",
        &[
            "study",
            "scene",
            "integrate",
            "elliptic",
            "error",
            "format",
            "palette",
        ],
    ),
    (
        "study",
        &[
            "scene",
            "integrate",
            "elliptic",
            "interrupt",
            "error",
            "format",
        ],
    ),
    (
        "scene",
        &["integrate", "elliptic", "interrupt", "error", "format"],
    ),
    ("integrate", &[]),
    ("output", &["interrupt", "error", "format", "shell"]),
    ("format", &[]),
    ("shell", &[]),
    ("elliptic", &[]),
    ("interrupt", &["error"]),
    ("error", &[]),
    ("palette", &[]),
    ("lib", &[]),
];

/// Every `.rs` file under `dir`, recursively.
fn rust_files(dir: &std::path::Path, out: &mut Vec<std::path::PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The layering holds in the code: every `crate::X` / `physlab::X` a module names is one it may
/// import, so arrows point down only and there are no cycles.
#[test]
fn modules_import_only_the_layers_below_them() {
    let src = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut violations = Vec::new();
    for file in &files {
        let rel = file.strip_prefix(&src).unwrap();
        let module = rel
            .components()
            .next()
            .unwrap()
            .as_os_str()
            .to_str()
            .unwrap()
            .trim_end_matches(".rs");
        let allowed = MAY_IMPORT
            .iter()
            .find(|(m, _)| *m == module)
            .unwrap_or_else(|| panic!("src/{}: module `{module}` has no layer", rel.display()))
            .1;
        let text = std::fs::read_to_string(file).unwrap();
        for prefix in ["crate::", "physlab::"] {
            for (at, _) in text.match_indices(prefix) {
                let name: String = text[at + prefix.len()..]
                    .chars()
                    .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                    .collect();
                let known = MAY_IMPORT.iter().any(|(m, _)| *m == name);
                if known && name != module && !allowed.contains(&name.as_str()) {
                    violations.push(format!("src/{}: {module} names {name}", rel.display()));
                }
            }
        }
    }
    assert!(files.len() > 50, "read {} files", files.len());
    assert!(violations.is_empty(), "{}", violations.join("\n"));
}

/// No message a user reads carries a run of spaces inside its text: a string wrapped over lines
/// without its `\` keeps the next line's indentation ("killed or the              file cut
/// short"). Checked on every string literal of `src/` (a run of 6 or more spaces between two
/// words; tables are padded by format widths, not literal runs).
#[test]
fn no_message_carries_the_indentation_of_a_wrapped_line() {
    let src = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut found = Vec::new();
    for file in &files {
        let text = std::fs::read_to_string(file).unwrap();
        for (n, line) in text.lines().enumerate() {
            if line.trim_start().starts_with("//") {
                continue;
            }
            // The text between the quotes of each literal on the line.
            for (i, literal) in line.split('"').enumerate() {
                let inside = i % 2 == 1;
                let words = literal.trim();
                if inside && words.contains("      ") && !words.starts_with('|') {
                    found.push(format!("{}:{}: {line}", file.display(), n + 1));
                }
            }
        }
    }
    assert!(found.is_empty(), "{}", found.join("\n"));
}
