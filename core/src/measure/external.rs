//! External-axis values carried with measurement readings: the CSV columns
//! `e1…e6` beside the joints, one value per axis and reading, as the
//! controller shows it (mm for a linear axis such as a track, degrees for a
//! rotary one such as a positioner's; the reader cannot tell which and
//! converts nothing).
//!
//! A file without these columns reads as before; a file with them reads
//! through [`super::csv::parse_set`] into a [`MeasurementSet`], each reading's
//! values in [`ExternalValues`] (every row gives every column the header
//! names). The robot-only readers ([`super::csv::parse`]) refuse such a file
//! naming the column: a robot calibration does not compose through external
//! axes, and reading the rows as if the axes stood still would be wrong.

use super::MeasuredPose;

/// How many external axes a reading carries at most (`e1…e6`).
pub const MAX_EXTERNAL_AXES: usize = 6;

/// An external axis by its controller number (a closed set; the column
/// names, lists and messages derive from it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum ExternalAxis {
    /// External axis 1, column `e1`.
    E1,
    /// External axis 2, column `e2`.
    E2,
    /// External axis 3, column `e3`.
    E3,
    /// External axis 4, column `e4`.
    E4,
    /// External axis 5, column `e5`.
    E5,
    /// External axis 6, column `e6`.
    E6,
}

impl ExternalAxis {
    /// Every axis, in column order.
    pub const ALL: [ExternalAxis; MAX_EXTERNAL_AXES] = [
        ExternalAxis::E1,
        ExternalAxis::E2,
        ExternalAxis::E3,
        ExternalAxis::E4,
        ExternalAxis::E5,
        ExternalAxis::E6,
    ];

    /// 0 for `e1` … 5 for `e6`.
    pub fn index(self) -> usize {
        self as usize
    }

    /// The axis of 1-based controller number `n`.
    pub fn from_number(n: usize) -> Option<ExternalAxis> {
        n.checked_sub(1).and_then(|i| Self::ALL.get(i).copied())
    }

    /// The CSV column: `e1` … `e6`.
    pub fn column(self) -> &'static str {
        ["e1", "e2", "e3", "e4", "e5", "e6"][self.index()]
    }
}

impl std::fmt::Display for ExternalAxis {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.column())
    }
}

/// One reading's external-axis values, by axis (mm or degrees as the
/// controller shows them); `None` for an axis the set does not carry.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ExternalValues(pub [Option<f64>; MAX_EXTERNAL_AXES]);

impl ExternalValues {
    /// The value of `axis`, if the reading carries it.
    pub fn get(&self, axis: ExternalAxis) -> Option<f64> {
        self.0[axis.index()]
    }

    /// Whether the reading carries no external axis.
    pub fn is_empty(&self) -> bool {
        self.0.iter().all(Option::is_none)
    }
}

/// A measurement set as read with its external-axis columns: the readings
/// and, per reading in the same order, its external-axis values. `axes` are
/// the columns the file had (in column order); every reading carries exactly
/// those. A set without external axes has `axes` empty and every reading's
/// values empty.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MeasurementSet {
    /// The readings, in file order.
    pub poses: Vec<MeasuredPose>,
    /// Each reading's external-axis values, in the order of `poses`.
    pub external: Vec<ExternalValues>,
    /// The external-axis columns the file had, in column order.
    pub axes: Vec<ExternalAxis>,
}

impl MeasurementSet {
    /// A set of `poses` without external axes.
    pub fn without_axes(poses: Vec<MeasuredPose>) -> Self {
        let external = vec![ExternalValues::default(); poses.len()];
        MeasurementSet {
            poses,
            external,
            axes: Vec::new(),
        }
    }

    /// The readings one by one with their external-axis values.
    pub fn readings(&self) -> impl Iterator<Item = Reading<'_>> {
        self.poses
            .iter()
            .zip(&self.external)
            .map(|(pose, external)| Reading {
                pose,
                external: *external,
            })
    }

    /// Whether the set carries `axis`.
    pub fn has(&self, axis: ExternalAxis) -> bool {
        self.axes.contains(&axis)
    }

    /// The readings as robot-only rows, each in its own tracker session per
    /// value of the track's `axis` (its label `e1=400`, after the row's own
    /// `session` label when it has one): at one track value the robot's
    /// base stands still in the tracker's frame, so a robot calibration can
    /// take each station as a session whose frame it fits, and identify the
    /// robot over every station. Refused, naming the column: a set without
    /// `axis`, or with another external axis (whose motion the robot's
    /// calibration would ignore).
    pub fn stations_as_sessions(
        &self,
        axis: ExternalAxis,
    ) -> Result<Vec<MeasuredPose>, StationSessionsError> {
        if !self.has(axis) {
            return Err(StationSessionsError::MissingColumn(axis));
        }
        if let Some(other) = self.axes.iter().find(|a| **a != axis) {
            return Err(StationSessionsError::OtherAxis {
                axis,
                other: *other,
            });
        }
        Ok(self
            .readings()
            .map(|r| {
                let value = r
                    .external
                    .get(axis)
                    .expect("every reading carries the set's axes");
                let session = station_session(r.pose.session.as_deref(), axis, value);
                MeasuredPose {
                    session: Some(session),
                    ..r.pose.clone()
                }
            })
            .collect())
    }
}

/// The tracker session of a reading at the track's `axis` value `value`:
/// `e1=400`, after the reading's own `session` label when it has one
/// (`S e1=400`).
pub fn station_session(session: Option<&str>, axis: ExternalAxis, value: f64) -> String {
    match session {
        Some(s) => format!("{s} {axis}={value}"),
        None => format!("{axis}={value}"),
    }
}

/// The reading's own session label back from its station session
/// ([`station_session`] at `axis` and `value`): `None` where it had none,
/// or where `label` is not a session of that station.
pub fn session_before_station(label: &str, axis: ExternalAxis, value: f64) -> Option<String> {
    label
        .strip_suffix(&station_session(None, axis, value))
        .and_then(|rest| rest.strip_suffix(' '))
        .map(str::to_string)
}

/// Why a set's stations cannot be read as tracker sessions
/// ([`MeasurementSet::stations_as_sessions`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StationSessionsError {
    /// The set has no column for the track.
    #[error("the file has no `{0}` column: give the track's value of every reading")]
    MissingColumn(ExternalAxis),
    /// The set carries another external axis too.
    #[error("the file has an `{other}` column besides the track's `{axis}`: a robot calibration over track stations composes through the track alone, and would read `{other}` as standing still")]
    OtherAxis {
        /// The track's column.
        axis: ExternalAxis,
        /// The other column.
        other: ExternalAxis,
    },
}

/// One reading of a [`MeasurementSet`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reading<'a> {
    /// The reading's joints, position and the rest of its row.
    pub pose: &'a MeasuredPose,
    /// Its external-axis values (mm or degrees as the controller shows them).
    pub external: ExternalValues,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A reading's own session comes back from its station session, with
    /// or without one, and a label of another station gives none.
    #[test]
    fn a_station_session_gives_back_the_readings_own() {
        for (own, value) in [(Some("S 2"), 400.0), (None, 1250.5), (Some("x"), -0.25)] {
            let label = station_session(own, ExternalAxis::E1, value);
            assert_eq!(
                session_before_station(&label, ExternalAxis::E1, value).as_deref(),
                own,
                "{label}"
            );
        }
        assert_eq!(
            station_session(Some("S"), ExternalAxis::E2, 400.0),
            "S e2=400"
        );
        assert_eq!(
            session_before_station("S e1=400", ExternalAxis::E1, 800.0),
            None
        );
    }
}
