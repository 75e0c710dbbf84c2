//! Which of a robot's stored external axes a request names.

/// A robot's stored external axis: its track, positioner or turntable.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StoredAxis {
    /// The linear track carrying the robot.
    Track,
    /// The two-axis positioner in its cell.
    Positioner,
    /// The one-axis turntable in its cell.
    Turntable,
}

impl StoredAxis {
    /// The axis as the API names it: `track`, `positioner`, `turntable`.
    pub fn name(self) -> &'static str {
        match self {
            StoredAxis::Track => "track",
            StoredAxis::Positioner => "positioner",
            StoredAxis::Turntable => "turntable",
        }
    }
}
