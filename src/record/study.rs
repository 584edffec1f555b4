//! A study as a recording: work-precision curves (log10 error against log10 cost, one coloured
//! line per method, the scenes' colours) and the tables as a text document.

use rerun::blueprint::{Blueprint, Horizontal, Spatial2DView, TextDocumentView, Vertical};

use super::{Destinations, Recording, method_color};
use crate::integrate::Method;
use crate::study::{Limit, Row};

pub fn record_study(
    d: &Destinations,
    scene: &str,
    rows: &[Row],
    limits: &[Limit],
    tables: &str,
    (config, methods): (&str, &[&str]),
) -> anyhow::Result<Option<u64>> {
    let blueprint = Blueprint::new(Horizontal::new([
        Vertical::new([
            Spatial2DView::new(
                "x = log10 median wall time [s], y = log10 error (accurate at the top)",
            )
            .with_origin("/study/wall")
            .into(),
            Spatial2DView::new(
                "x = log10 force evaluations, y = log10 error (accurate at the top)",
            )
            .with_origin("/study/evals")
            .into(),
        ])
        .into(),
        TextDocumentView::new("tables")
            .with_origin("/study/tables")
            .into(),
    ]))
    .with_auto_views(false);
    let recording = Recording::create(d, "physlab-study", &format!("study {scene}"), blueprint)?;
    let rec = recording.stream();
    super::send_provenance(rec, &format!("study {scene}"), config, methods)?;
    let mut methods: Vec<Method> = Vec::new();
    for r in rows {
        if !methods.contains(&r.method) {
            methods.push(r.method);
        }
    }
    for m in methods {
        let mine: Vec<&Row> = rows
            .iter()
            .filter(|r| r.method == m && r.error.is_some_and(|e| e > 0.0))
            .collect();
        for (axis, cost) in [
            ("wall", &(|r: &Row| r.wall_seconds) as &dyn Fn(&Row) -> f64),
            ("evals", &|r: &Row| r.evals as f64),
        ] {
            // 2D views point y down, so log10 error (negative) puts the accurate runs on top.
            let pts: Vec<[f32; 2]> = mine
                .iter()
                .filter_map(|r| Some([cost(r).log10() as f32, r.error?.log10() as f32]))
                .collect();
            if pts.is_empty() {
                continue;
            }
            let color = method_color(m.name());
            rec.log_static(
                format!("study/{axis}/{}", m.name()),
                &rerun::LineStrips2D::new([pts.clone()])
                    .with_colors([color])
                    .with_labels([m.name()]),
            )?;
            rec.log_static(
                format!("study/{axis}/{}/runs", m.name()),
                &rerun::Points2D::new(pts)
                    .with_colors([color])
                    .with_radii([rerun::Radius::new_ui_points(3.0)]),
            )?;
        }
    }
    let _ = limits; // the stability table is part of `tables`
    rec.log_static(
        "study/tables",
        // The tables are markdown already: the viewer renders them as tables.
        &rerun::TextDocument::from_markdown(tables),
    )?;
    recording.commit()
}
