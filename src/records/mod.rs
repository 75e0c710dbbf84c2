//! What the store keeps, as the service and the HTTP layer see it: robots,
//! measurement sets, calibration jobs, model versions, checks, tools and work
//! objects, linear tracks, positioners, turntables. Plain data shared by the store (`crate::db`, which reads and
//! writes these rows and maps its columns onto them) and the service (which
//! answers with them); neither layer owns the vocabulary, so the HTTP layer
//! reads it here without naming the store.

mod calibrations;
mod cell;
mod checks;
mod positioners;
mod robots;
mod sets;
mod stored_axis;
mod tracks;
mod turntables;
mod versions;

pub use calibrations::{CalibrationRow, JobStatus, JobSummary, ProgressDetail};
pub use cell::{CellItemRow, CellKind, CellPut, ItemFrame, NewCellItem};
pub use checks::CheckRow;
pub use positioners::{NewPositioner, PositionerRow};
pub use robots::{NewRobot, RobotRow};
pub use sets::{AngleUnit, LengthUnit, SetFormat, SetRow, StoredRole};
pub use stored_axis::StoredAxis;
pub use tracks::{NewTrack, TrackRow};
pub use turntables::{NewTurntable, TurntableRow};
pub use versions::VersionRow;

/// A JSON document stored as text (its column mapping: `crate::db`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Json<T>(pub T);
