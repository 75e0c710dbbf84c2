//! Solve and predict through external axes: a robot carried by a linear
//! track ([`track`]), a track value per row of a joints file ([`rows`]) and
//! of a targets file ([`targets`]), and a part on a positioner's face plate
//! carried to the cell and base frames at the axes' values ([`positioner`]).

pub mod positioner;
pub mod rows;
pub mod targets;
pub mod track;

pub use positioner::{
    base_from_part, base_from_part_at, cell_from_part, part_from_cell, AxisValues,
};
pub use rows::{track_values, RowValue, TrackColumnError, TRACK_COLUMN};
pub use targets::{
    place_on_positioner, place_on_track, place_on_track_and_positioner, positioner_columns,
    target_column_values, target_track_values, PlacedRows, TargetValue, ROTATE_COLUMN, TILT_COLUMN,
};
pub use track::{carried, TrackPoseError, TrackSolver};
