//! Solve: turn target poses into joint commands with a calibrated model
//! (`ik`), place tools, loads and work objects in the cell (`cell`) and
//! carry the robot on external axes (`external`). The
//! robot programs a solve filters are the floor above (`crate::program`).

pub mod cell;
pub mod external;
pub mod ik;
