//! Solve: turn target poses into joint commands with a calibrated model
//! (`ik`), place tools, loads and work objects in the cell (`cell`), and read
//! and filter robot programs (`program`).

pub mod cell;
pub mod ik;
pub mod program;
