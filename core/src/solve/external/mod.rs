//! Solve and predict through external axes: a robot carried by a linear
//! track ([`track`]), and a track value per row of a joints file ([`rows`]).

pub mod rows;
pub mod track;

pub use rows::{track_values, RowValue, TrackColumnError, TRACK_COLUMN};
pub use track::{carried, TrackPoseError, TrackSolver};
