//! External axes: the rotary axes of positioners (a line, a zero offset and a
//! scale, [`rotary`]), the two-axis tilt-rotate positioner that chains two
//! of them to carry a face plate ([`positioner`]), the one-axis turntable
//! that carries one with one of them ([`turntable`]), and the linear track that
//! carries a robot's base along a rail ([`track`]) with the carriage's errors
//! as maps over the travel measured ([`travel_map`]). Frames and units are stated
//! in each file; m and rad inside, mm and degrees in the stored descriptions.

pub mod positioner;
pub mod rotary;
pub mod track;
pub mod travel_map;
pub mod turntable;

pub use positioner::{TiltRotate, TiltRotateDescription};
pub use rotary::{Line, RotaryAxis, RotaryAxisDescription};
pub use track::{CarriageTerm, LinearTrack, TrackDescription};
pub use travel_map::{OutsideTravel, Travel, TravelMap};
pub use turntable::{Turntable, TurntableDescription};
