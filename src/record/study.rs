//! A study as a recording: its diagrams (log-log PNGs drawn by `crate::diagram`, the scenes'
//! colours) beside its tables as a rendered markdown document.

use rerun::blueprint::{
    Blueprint, ContainerLike, Horizontal, Spatial2DView, TextDocumentView, TimePanel, Vertical,
};

use super::{Destinations, Recording};

/// Writes the study recording: one 2D view per diagram (title, PNG bytes), the tables beside.
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
    // The diagrams (wide pictures) across the top, the tables below; the side and time panels
    // collapsed, since everything is static: the picture gets the window.
    let n = views.len() as f32;
    let table_view = TextDocumentView::new("tables").with_origin("/study/tables");
    let blueprint = super::views::panels_collapsed(
        Blueprint::new(
            Vertical::new([Horizontal::new(views).into(), table_view.into()])
                .with_row_shares([2.0 + n, 2.0]),
        ),
        TimePanel::new(),
    );
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
