//! Every tableau's order conditions, evaluated without rounding (double-double) on the doubles
//! physlab steps with: the explicit Runge–Kutta pairs over Butcher's rooted trees (`rk`), the
//! Nyström pairs over the special Nyström trees (`rkn`). The coefficient files are the ones the
//! integrators compile (`src/integrate/*/tables.rs`, `rkn_tables.rs`), included here as they are.

// The checkers index the stages of a tableau as the formulas do.
#![allow(clippy::needless_range_loop)]

#[allow(dead_code)]
#[path = "../../src/integrate/dop853/tables.rs"]
mod dop853;
#[allow(dead_code)]
#[path = "../../src/integrate/adaptive/tables.rs"]
mod dopri5;
#[allow(dead_code)]
#[path = "../../src/integrate/rkn_tables.rs"]
mod rkn_tables;
#[allow(dead_code)]
#[path = "../../src/integrate/verner/tables.rs"]
mod verner;

mod rk;
mod rkn;
