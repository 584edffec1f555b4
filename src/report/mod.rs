//! What people read outside the viewer: the summary tables, the registry table, study tables
//! and CSV. Plain text; nothing here knows Rerun or clap.

pub mod drift;
pub mod figures;
pub mod hair;
pub mod methods;
pub mod pendulum;
pub mod rope;
pub mod study;
pub mod table;
