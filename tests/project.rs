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
