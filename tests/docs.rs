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
