//! The physics scenes. Plain Rust over f64 / glam: nothing here knows about Rerun.

pub mod hair;
pub mod pendulum;
pub mod rope;
pub mod schedule;
