//! robocal: calibration of industrial robots and false targets for offline programming.
//!
//! Flow: measure (`measure`, `sim`) → calibrate (`identify`) → store (`db`) →
//! solve (`compensate`, `ik`), served over HTTP (`http`) and the command line (`cli`);
//! `report` renders a stored calibration report as HTML.
//! The numerical core lives in the `robocal-core` crate (re-exported here under
//! the same module names), whose dependency tree has no HTTP, database, async
//! runtime or command-line crates.

#![warn(missing_docs)]
#![warn(unreachable_pub)]

pub use robocal_core::{
    calibrate, cell_fit, check, measure, model, optim, plan, program, sim, solve, stats,
};

pub mod cli;
pub mod db;
pub mod http;
pub mod records;
pub mod report;
pub mod service;
