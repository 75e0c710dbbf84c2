//! The simulated two-axis tilt-rotate positioner the positioner tests share:
//! the library's example (`robocal_core::sim::positioner_example`, which
//! `robocal positioner simulate` measures too).

// Each test crate that includes `common` uses a part of it, some none.
#[allow(unused_imports)]
pub use robocal_core::sim::positioner_example::*;
