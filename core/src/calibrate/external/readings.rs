//! A positioner fit's readings from a measurement set: the reflector's
//! position `x, y, z` [mm, cell frame] of each row and the values of the two
//! external-axis columns that hold the positioner's axes (which column is
//! the tilt and which the rotate axis is the caller's: [`PositionerColumns`]).
//! One set holds one reflector's readings (a tracker's file per nest); the
//! request gathers the sets of every reflector. A turntable's readings are
//! read alike from its one column ([`turntable_readings`]).

use super::outcome::PositionerReading;
use super::turntable::TurntableReading;
use crate::measure::external::{ExternalAxis, MeasurementSet};

/// Which external-axis column holds which positioner axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PositionerColumns {
    /// Axis 1 (tilt) [deg].
    pub tilt: ExternalAxis,
    /// Axis 2 (rotate) [deg].
    pub rotate: ExternalAxis,
}

/// Why a set's rows are not a positioner's readings.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ColumnsError {
    /// One column named for both axes.
    #[error("the tilt and rotate axes are both column `{0}`: name two columns")]
    SameColumn(ExternalAxis),
    /// The set has no column for an axis.
    #[error("the set has no column `{column}` (it has: {has}); the {role} axis's values are read from it")]
    Missing {
        /// The column named for the axis.
        column: ExternalAxis,
        /// `tilt`, `rotate` or `turntable`.
        role: &'static str,
        /// The set's external-axis columns, comma-separated (`none`).
        has: String,
    },
    /// A row without a value in an axis's column.
    #[error("row {row} has no value of column `{column}`")]
    MissingValue {
        /// 1-based row of the set.
        row: usize,
        /// The column.
        column: ExternalAxis,
    },
}

/// Every row of `set` as a reading of reflector `reflector` at the values of
/// `columns`.
pub fn positioner_readings(
    set: &MeasurementSet,
    columns: PositionerColumns,
    reflector: usize,
) -> Result<Vec<PositionerReading>, ColumnsError> {
    if columns.tilt == columns.rotate {
        return Err(ColumnsError::SameColumn(columns.tilt));
    }
    for (column, role) in [(columns.tilt, "tilt"), (columns.rotate, "rotate")] {
        has_column(set, column, role)?;
    }
    set.readings()
        .enumerate()
        .map(|(i, r)| {
            let value = |column: ExternalAxis| {
                r.external
                    .get(column)
                    .ok_or(ColumnsError::MissingValue { row: i + 1, column })
            };
            Ok(PositionerReading {
                reflector,
                values_deg: [value(columns.tilt)?, value(columns.rotate)?],
                xyz_mm: r.pose.xyz_mm,
            })
        })
        .collect()
}

/// Every row of `set` as a turntable's reading of reflector `reflector` at
/// the value of `column` [deg] (one set per reflector, as a positioner's).
pub fn turntable_readings(
    set: &MeasurementSet,
    column: ExternalAxis,
    reflector: usize,
) -> Result<Vec<TurntableReading>, ColumnsError> {
    has_column(set, column, "turntable")?;
    set.readings()
        .enumerate()
        .map(|(i, r)| {
            Ok(TurntableReading {
                reflector,
                value_deg: r
                    .external
                    .get(column)
                    .ok_or(ColumnsError::MissingValue { row: i + 1, column })?,
                xyz_mm: r.pose.xyz_mm,
            })
        })
        .collect()
}

/// `Missing` unless `set` has `column` (read for the axis `role`).
fn has_column(
    set: &MeasurementSet,
    column: ExternalAxis,
    role: &'static str,
) -> Result<(), ColumnsError> {
    if set.has(column) {
        return Ok(());
    }
    let has: Vec<&str> = set.axes.iter().map(|a| a.column()).collect();
    Err(ColumnsError::Missing {
        column,
        role,
        has: if has.is_empty() {
            "none".into()
        } else {
            has.join(", ")
        },
    })
}
