//! Solve: turn target poses into joint commands with a calibrated model
//! (`ik`), place tools, loads and work objects in the cell (`cell`) and
//! carry the robot on external axes (`external`). The
//! robot programs a solve filters are the floor above (`crate::program`).

// `missing_docs` is warned module by module rather than on the whole
// floor: the external axes' solve (`external`) is not documented item by
// item yet.
#[warn(missing_docs)]
pub mod cell;
pub mod external;
#[warn(missing_docs)]
pub mod ik;
