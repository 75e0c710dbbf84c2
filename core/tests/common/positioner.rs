//! The simulated two-axis tilt-rotate positioner the positioner tests share:
//! the library's example (`robocal_core::sim::positioner_example`, which
//! `robocal positioner simulate` measures too).

pub use robocal_core::sim::positioner_example::*;
