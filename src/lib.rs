//! physlab: numerical integrators compared side by side on small physics scenes, with every
//! run recorded for the Rerun viewer.
//!
//! The simulation core (`method`, `elliptic`, `scene`) is plain Rust and never touches Rerun;
//! `record` is the only module that does.

pub mod app;
pub mod cli;
pub mod config;
pub mod elliptic;
pub mod interrupt;
pub mod method;
pub mod progress;
pub mod record;
pub mod scene;
pub mod study;
pub mod table;
