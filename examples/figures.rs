//! Rewrites every table of figures in README.md and docs/ from real runs:
//! `cargo run --release --example figures` (add `--deterministic` to skip the timed ones).
//! Each table sits between `<!-- figure: NAME -->` and `<!-- /figure -->`.

use std::path::Path;

use physlab::report::figures::{self, Figure};

fn main() -> anyhow::Result<()> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut all: Vec<Figure> = figures::deterministic();
    if !std::env::args().any(|a| a == "--deterministic") {
        all.extend(figures::timed());
    }
    for f in &all {
        let path = root.join(f.document);
        let text = std::fs::read_to_string(&path)?;
        let Some(new) = figures::replace(&text, f.name, &f.markdown) else {
            anyhow::bail!("{}: no markers for figure {}", f.document, f.name);
        };
        if new != text {
            std::fs::write(&path, new)?;
            println!("updated {} in {}", f.name, f.document);
        } else {
            println!("unchanged {} in {}", f.name, f.document);
        }
    }
    Ok(())
}
