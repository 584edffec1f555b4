//! A study as a recording: its diagrams (log-log PNGs drawn by `crate::diagram`, the scenes'
//! colours), each in a tab of its own, and its tables as a rendered markdown document in the last.

use rerun::blueprint::{
    Blueprint, ContainerLike, Spatial2DView, Tabs, TextDocumentView, TimePanel,
};

use super::{Destinations, Recording};

/// Writes the study recording: one 2D view per diagram (title, PNG bytes), the tables after.
pub fn record_study(
    d: &Destinations,
    scene: &str,
    diagrams: &[(String, Vec<u8>)],
    tables: &str,
    (config, methods): (&str, &[&str]),
) -> anyhow::Result<Option<u64>> {
    let mut views: Vec<ContainerLike> = diagrams
        .iter()
        .enumerate()
        .map(|(i, (title, _))| {
            Spatial2DView::new(title.as_str())
                .with_origin(format!("/study/diagrams/{i}"))
                .into()
        })
        .collect();
    if views.is_empty() {
        views.push(
            TextDocumentView::new("no diagram")
                .with_origin("/study/no_diagram")
                .into(),
        );
    }
    // One tab per diagram, the first shown, and the tables in the last; the side and time
    // panels collapsed, since everything is static. A diagram gets the whole window, so its
    // labels are drawn near their own size: beside the tables it was shrunk to about half.
    views.push(
        TextDocumentView::new("tables")
            .with_origin("/study/tables")
            .into(),
    );
    let blueprint =
        super::views::panels_collapsed(Blueprint::new(Tabs::new(views)), TimePanel::new());
    let recording = Recording::create(d, "physlab-study", &format!("study {scene}"), blueprint)?;
    let rec = recording.stream();
    super::send_provenance(rec, &format!("study {scene}"), config, methods)?;
    for (i, (_, png)) in diagrams.iter().enumerate() {
        rec.log_static(
            format!("study/diagrams/{i}"),
            &rerun::EncodedImage::from_file_contents(png.clone())
                .with_media_type(rerun::components::MediaType::PNG),
        )?;
    }
    rec.log_static(
        "study/tables",
        // The tables are markdown already: the viewer renders them as tables.
        &rerun::TextDocument::from_markdown(tables),
    )?;
    recording.commit()
}
