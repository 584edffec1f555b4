//! Rewrites every table of figures in README.md and docs/ from real runs, and the pictures drawn
//! from the same runs: `cargo run --release --example figures` (add `--deterministic` to skip
//! the timed ones). Each table sits between `<!-- figure: NAME -->` and `<!-- /figure -->`.

use std::path::Path;

use physlab::report::figures::{self, Figure};

fn main() -> anyhow::Result<()> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut all: Vec<Figure> = figures::deterministic();
    if !std::env::args().any(|a| a == "--deterministic") {
        let runs = figures::work_precision_pendulum_runs(physlab::study::DEFAULT_REPEATS);
        all.extend(figures::timed_from(&runs));
        let written = physlab::diagram::pendulum_work_precision_picture(&runs)
            .write(&root.join("docs"), "")?;
        // docs/results.md shows the PNG; the SVG beside it would only be a second copy to keep.
        std::fs::remove_file(&written.svg)?;
        println!("wrote {}", written.png.display());
    }
    // Deterministic: drawn in either mode.
    let drift = figures::drift_pendulum_runs();
    let written = physlab::diagram::pendulum_drift_picture(&drift).write(&root.join("docs"), "")?;
    std::fs::remove_file(&written.svg)?;
    println!("wrote {}", written.png.display());
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
