//! physlab: numerical integrators compared side by side on small physics scenes, with every
//! run recorded for the Rerun viewer.
//!
//! Layers, each importing only those below it (see ARCHITECTURE.md):
//! - the core: `integrate` (methods), `scene` (the scenes and the one harness), `study`
//!   (measurements), `report` (tables), plus `format`, `elliptic`, `interrupt` and `error`; no clap, no
//!   Rerun;
//! - `record` (writing) and `rrd` (reading): the only modules that call Rerun (cargo feature
//!   `rerun`, on by default);
//! - `cli` (clap types) and `app` (the command pipeline) on top.

pub mod elliptic;
pub mod error;
pub mod format;
pub mod integrate;
pub mod interrupt;
pub mod output;
pub mod palette;
pub mod report;
pub mod scene;
pub mod shell;
pub mod study;

#[cfg(feature = "rerun")]
pub mod app;
#[cfg(feature = "rerun")]
pub mod cli;
#[cfg(feature = "diagrams")]
pub mod diagram;
#[cfg(feature = "rerun")]
pub mod record;
#[cfg(feature = "rerun")]
pub mod rrd;
