//! Every deterministic table of figures in README.md and docs/ is what the code produces today
//! (`cargo run --release --example figures` rewrites them).

use physlab::report::figures;

#[test]
fn documents_show_the_figures_the_code_produces() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut stale = Vec::new();
    for f in figures::deterministic() {
        let text = std::fs::read_to_string(root.join(f.document)).unwrap();
        match figures::block(&text, f.name) {
            None => stale.push(format!("{}: no figure {}", f.document, f.name)),
            Some(shown) if shown != f.markdown => stale.push(format!(
                "{}: figure {} is stale; the code gives\n{}",
                f.document, f.name, f.markdown
            )),
            Some(_) => {}
        }
    }
    assert!(
        stale.is_empty(),
        "run `cargo run --release --example figures`:\n{}",
        stale.join("\n")
    );
}

/// The sizes docs/results.md gives for the default recordings are what the runs write today, to
/// the 0.1 MB it shows. The files are not byte-identical between runs: each row id carries a
/// clock and random bits that LZ4 packs a little differently every time (five default `all` runs
/// wrote 25.240–25.250 MB), so a shown figure may sit 0.05 MB from the size plus that 0.02 MB.
#[cfg(feature = "rerun")]
#[test]
fn the_documented_recording_sizes_are_what_the_default_runs_write() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join("docs/results.md")).unwrap();
    let text = text.split_whitespace().collect::<Vec<_>>().join(" ");
    let dir = std::env::temp_dir().join(format!("physlab-docs-sizes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bytes = |command: &str| -> u64 {
        let out = dir.join(format!("{command}.rrd"));
        let status = std::process::Command::new(env!("CARGO_BIN_EXE_physlab"))
            .args([command, "-q", "-o", out.to_str().unwrap()])
            .stdout(std::process::Stdio::null())
            .status()
            .unwrap();
        assert!(status.success(), "{command}");
        std::fs::metadata(&out).unwrap().len()
    };
    let all_bytes = bytes("all");
    // The budget the default `all` keeps to (its 3D frames, plots and layout together); 0.5 MB
    // above 25 MB since the rope's energy balance (its W and E + W − E0 per method) came in.
    assert!(
        all_bytes <= 25_500_000,
        "the default `all` writes {all_bytes} B, over 25.5 MB"
    );
    let written = [all_bytes, bytes("pendulum"), bytes("rope"), bytes("hair")];
    std::fs::remove_dir_all(&dir).unwrap();
    let lead = "The default `physlab all` takes 0.5 s and writes ";
    let sentence = &text[text
        .find(lead)
        .expect("docs/results.md gives the default sizes")
        + lead.len()..];
    // "25.2 MB (pendulum 3.3 MB, rope 2.0 MB, hair 20.1 MB;"
    let sentence = &sentence[..sentence.find(';').unwrap()];
    let shown: Vec<f64> = sentence
        .split_whitespace()
        .filter_map(|w| w.parse::<f64>().ok())
        .collect();
    assert_eq!(shown.len(), 4, "four sizes in: {sentence}");
    for ((name, mb), b) in ["all", "pendulum", "rope", "hair"]
        .iter()
        .zip(&shown)
        .zip(written)
    {
        let size = b as f64 / 1e6;
        assert!(
            (mb - size).abs() <= 0.05 + 0.02,
            "docs/results.md says {name} writes {mb} MB; it writes {size:.3} MB"
        );
    }
}

/// The pictures in docs/ show what the code draws today: each PNG carries what it draws (methods,
/// settings, evaluation counts and errors; no wall times) as a text chunk, and that is what the
/// same runs give now (`cargo run --release --example figures` redraws them).
#[test]
fn pictures_show_what_the_code_draws() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let png = std::fs::read(root.join("docs/pendulum-work-precision.png")).unwrap();
    let shown = physlab::diagram::stamp::text(&png, physlab::diagram::stamp::KEY)
        .expect("docs/pendulum-work-precision.png carries what it draws: redraw it");
    // One timing per run: what is drawn besides the wall times does not depend on it.
    let runs = figures::work_precision_pendulum_runs(1);
    let drawn = physlab::diagram::pendulum_work_precision_picture(&runs).data();
    assert_eq!(
        shown, drawn,
        "docs/pendulum-work-precision.png is stale: run `cargo run --release --example figures`"
    );
    for method in physlab::integrate::Method::ALL {
        assert!(
            shown.contains(&format!("\n{} dt=", method.name())),
            "{method:?} not drawn"
        );
    }
    let png = std::fs::read(root.join("docs/pendulum-drift.png")).unwrap();
    let shown = physlab::diagram::stamp::text(&png, physlab::diagram::stamp::KEY)
        .expect("docs/pendulum-drift.png carries what it draws: redraw it");
    let drawn = physlab::diagram::pendulum_drift_picture(&figures::drift_pendulum_runs()).data();
    assert_eq!(
        shown, drawn,
        "docs/pendulum-drift.png is stale: run `cargo run --release --example figures`"
    );
}

#[test]
fn blocks_are_found_and_replaced_between_their_markers() {
    let doc = "a\n<!-- figure: x -->\n| old |\n<!-- /figure -->\nb\n";
    assert_eq!(figures::block(doc, "x"), Some("| old |\n"));
    assert_eq!(figures::block(doc, "y"), None);
    let new = figures::replace(doc, "x", "| new |\n").unwrap();
    assert_eq!(new, "a\n<!-- figure: x -->\n| new |\n<!-- /figure -->\nb\n");
}
