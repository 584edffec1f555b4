//! A study as a recording: its diagrams drawn from their data (`loglog`: each run a point that
//! says on hover which run it is; stability's methods as rows), each in a tab of its own,
//! and its tables as a rendered markdown document in the last.

use rerun::blueprint::{
    Blueprint, ContainerLike, Spatial2DView, Tabs, TextDocumentView, TimePanel,
};

use super::loglog::{CANVAS, log_plot};
use super::{Destinations, Recording, ViewProperties};
use crate::diagram::Diagram;

/// Writes the study recording: one 2D view per diagram, the tables after.
pub fn record_study(
    d: &Destinations,
    scene: &str,
    diagrams: &[Diagram],
    tables: &str,
    (config, methods): (&str, &[&str]),
) -> anyhow::Result<Option<u64>> {
    let mut properties = ViewProperties::default();
    let mut views: Vec<ContainerLike> = Vec::new();
    for (i, diagram) in diagrams.iter().enumerate() {
        let view =
            Spatial2DView::new(diagram.title.as_str()).with_origin(format!("/study/diagrams/{i}"));
        // Opened on the canvas the plot is laid out on.
        views.push(properties.bounds_2d(view, [0.0, 0.0], CANVAS));
    }
    if views.is_empty() {
        views.push(
            TextDocumentView::new("no diagram")
                .with_origin("/study/no_diagram")
                .into(),
        );
    }
    // One tab per diagram, each given the whole window so that its labels have room.
    views.push(
        TextDocumentView::new("tables")
            .with_origin("/study/tables")
            .into(),
    );
    let blueprint =
        super::views::panels_collapsed(Blueprint::new(Tabs::new(views)), TimePanel::new());
    let layout = properties.layout(blueprint);
    let recording = Recording::create(d, "physlab-study", &format!("study {scene}"), layout)?;
    let rec = recording.stream();
    super::send_provenance(rec, &format!("study {scene}"), config, methods)?;
    for (i, diagram) in diagrams.iter().enumerate() {
        let path = format!("study/diagrams/{i}");
        log_plot(rec, &path, &diagram.plot)?;
    }
    rec.log_static(
        "study/tables",
        // The tables are markdown already: the viewer renders them as tables.
        &rerun::TextDocument::from_markdown(tables),
    )?;
    recording.commit()
}
