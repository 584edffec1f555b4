//! Records the git commit physlab is built from, for the provenance in every recording: the
//! commit, with `-dirty` when the files the binary is built from (`src/`, `build.rs`,
//! `Cargo.toml`, `Cargo.lock`) differ from it, untracked source files included.

use std::process::Command;

/// What the binary is compiled from: a change anywhere else (docs, tests) does not make it dirty.
const SOURCES: [&str; 4] = ["src", "build.rs", "Cargo.toml", "Cargo.lock"];

fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git").args(args).output().ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
}

fn main() {
    let commit = git(&["rev-parse", "--short=12", "HEAD"]).unwrap_or_else(|| "unknown".to_string());
    let mut status = vec!["status", "--porcelain", "--untracked-files=normal", "--"];
    status.extend(SOURCES);
    let dirty = git(&status).is_some_and(|s| !s.is_empty());
    println!(
        "cargo:rustc-env=PHYSLAB_GIT_COMMIT={commit}{}",
        if dirty { "-dirty" } else { "" }
    );
    // Run again when a source changes (dirty or clean again) and when HEAD moves. In a worktree
    // `.git` is a file: ask git where HEAD and the index live. Refs are shared (common dir).
    for path in SOURCES {
        println!("cargo:rerun-if-changed={path}");
    }
    let git_dir = git(&["rev-parse", "--git-dir"]);
    let common = git(&["rev-parse", "--git-common-dir"]);
    if let Some(dir) = &git_dir {
        for file in ["HEAD", "index"] {
            println!("cargo:rerun-if-changed={dir}/{file}");
        }
    }
    if let Some(dir) = common.or(git_dir) {
        for file in ["refs/heads", "packed-refs"] {
            println!("cargo:rerun-if-changed={dir}/{file}");
        }
    }
}
