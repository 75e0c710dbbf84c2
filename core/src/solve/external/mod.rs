//! Solve and predict through external axes: a robot carried by a linear
//! track ([`track`]), a track value per row of a joints file ([`rows`]) and
//! of a targets file ([`targets`]).

pub mod rows;
pub mod targets;
pub mod track;

pub use rows::{track_values, RowValue, TrackColumnError, TRACK_COLUMN};
pub use targets::{place_on_track, target_track_values, PlacedRows, TargetTrackValue};
pub use track::{carried, TrackPoseError, TrackSolver};
