//! robocal: calibration of industrial robots and false targets for offline programming.
//!
//! Flow: measure (`measure`, `sim`) → calibrate (`identify`) → store (`db`) →
//! solve (`compensate`, `ik`), served over HTTP (`http`) and the command line (`cli`).
//! The numerical core (`model`, `kinematics`, `identify`, `compensate`, `ik`, `sim`)
//! never touches HTTP, the database or the async runtime.

pub mod cli;
pub mod compensate;
pub mod db;
pub mod http;
pub mod identify;
pub mod ik;
pub mod kinematics;
pub mod measure;
pub mod model;
pub mod sim;
