//! External axes: the rotary axes of positioners (a line, a zero offset and a
//! scale, [`rotary`]) and the two-axis tilt-rotate positioner that chains two
//! of them to carry a face plate ([`positioner`]). Frames and units are stated
//! in each file; m and rad inside, mm and degrees in the stored descriptions.

pub mod positioner;
pub mod rotary;

pub use positioner::{TiltRotate, TiltRotateDescription};
pub use rotary::{Line, RotaryAxis, RotaryAxisDescription};
