//! robocal: calibration of industrial robots and false targets for offline programming.
//!
//! Flow: measure (`measure`) → calibrate (`identify`) → store (`db`) → solve (`ik`).
//! The numerical core (`model`, `kinematics`, `identify`, `compensate`, `ik`, `sim`)
//! never touches HTTP, the database or the async runtime.

pub mod cli;
pub mod kinematics;
pub mod model;
