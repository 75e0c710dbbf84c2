//! Solve and predict through external axes: a robot carried by a linear
//! track ([`track`]).

pub mod track;

pub use track::{carried, TrackPoseError, TrackSolver};
