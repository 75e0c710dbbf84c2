//! Solve: turn target poses into joint commands with a calibrated model
//! (`ik`) and place tools, loads and work objects in the cell (`cell`). The
//! robot programs a solve filters are the floor above (`crate::program`).

pub mod cell;
pub mod ik;
