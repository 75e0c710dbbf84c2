//! What a measurement CSV may hold and how it is read: the limits of its
//! values, the columns it accepts, the sign of the real data's `*_dif`
//! columns, the read options and why a file is refused.

use crate::measure::bounds;
use crate::measure::convention::MeasuredOrientation;
use crate::measure::csv_text::{self, short_text, Dialect, TextError};
use crate::measure::SetRole;

/// Maximum joint count of a CSV row.
pub const MAX_JOINTS: usize = 7;
/// Minimum joint count of a CSV row.
pub const MIN_JOINTS: usize = 2;
/// A joint reading beyond this magnitude [deg] is rejected as wrong units
/// (`bounds::JOINT_DEG`).
pub const MAX_JOINT_DEG: f64 = bounds::JOINT_DEG.max;
/// If every position coordinate of the file is below this magnitude [mm], the
/// file is rejected as metres.
pub const METRES_SUSPECT_MM: f64 = 5.0;
/// Largest accepted magnitude of a position coordinate [mm] (100 m,
/// `bounds::POSITION_MM`).
pub const MAX_POSITION_MM: f64 = bounds::POSITION_MM.max;
/// Largest accepted payload [kg] (`bounds::PAYLOAD_KG`).
pub const MAX_PAYLOAD_KG: f64 = bounds::PAYLOAD_KG.max;

/// A number for a message: plain when moderate, scientific otherwise (never
/// hundreds of digits).
pub fn short_number(v: f64) -> String {
    if v != 0.0 && !(1e-3..1e6).contains(&v.abs()) {
        format!("{v:.3e}")
    } else {
        format!("{}", (v * 1e6).round() / 1e6)
    }
}

pub(super) const ACCEPTED: &str =
    "q1..q7 (alias joint_1..joint_7), e1..e6 (external axes: mm for a linear axis, degrees \
for a rotary one), x, y, z, rx, ry, rz (degrees, fixed-axis XYZ unless \
declared intrinsic_xyz; alias rx_deg, ry_deg, rz_deg) or qw, qx, qy, qz (quaternion), \
std_x, std_y, std_z, std_rx, std_ry, std_rz, payload_kg, \
temperature_c, set, session; real-data layout: x_t, y_t, z_t, x_dif, y_dif, z_dif, step_order";

/// Sign of the `*_dif` columns of the real-data layout.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DifSign {
    /// `measured = target + dif` (working assumption; fits gravity sag).
    #[default]
    Plus,
    /// `measured = target − dif`.
    Minus,
}

impl DifSign {
    pub(super) fn factor(self) -> f64 {
        match self {
            DifSign::Plus => 1.0,
            DifSign::Minus => -1.0,
        }
    }
}

/// An error in a measurement CSV, with the 1-based line number and column name
/// where they apply.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CsvError {
    /// The text has no header row.
    #[error("the CSV file is empty: no header row")]
    Empty,
    /// The text cannot be read as CSV (delimiter, quoting, decimal separator).
    #[error(transparent)]
    Text(#[from] TextError),
    /// The header is not followed by any data row.
    #[error("no data rows after the header on line {header_line}")]
    NoDataRows {
        /// 1-based line of the header.
        header_line: usize,
    },
    /// A column the file needs is not in the header.
    #[error("line {line}: missing column `{column}`")]
    MissingColumn {
        /// 1-based line of the header.
        line: usize,
        /// The missing column's canonical name.
        column: String,
    },
    /// The header names a column the reader does not know.
    #[error("line {line}: unknown column `{column}`; accepted columns: {accepted}")]
    UnknownColumn {
        /// 1-based line of the header.
        line: usize,
        /// The column as written.
        column: String,
        /// The accepted columns, as one list for the message.
        accepted: String,
    },
    /// Two header columns give the same value (a name twice, or a name and
    /// its alias).
    #[error("line {line}: duplicate column `{column}` (column `{previous}` already given)")]
    DuplicateColumn {
        /// 1-based line of the header.
        line: usize,
        /// The later column, as written.
        column: String,
        /// The earlier column it repeats, as written.
        previous: String,
    },
    /// The header mixes the two position layouts (`x, y, z` and `x_t, …, x_dif, …`).
    #[error("line {line}: conflicting columns `{first}` and `{second}` (use one position layout: x,y,z or x_t,y_t,z_t + x_dif,y_dif,z_dif)")]
    ConflictingColumns {
        /// 1-based line of the header.
        line: usize,
        /// A column of one layout.
        first: String,
        /// A column of the other layout.
        second: String,
    },
    /// The joint columns are not `q1..qN` with `N` in `min..=max`.
    #[error("line {line}: joint columns must be q1..qN with {min} <= N <= {max}, found {found}")]
    JointColumns {
        /// 1-based line of the header.
        line: usize,
        /// The joint columns found, comma-separated.
        found: String,
        /// Fewest joints a row may have ([`MIN_JOINTS`]).
        min: usize,
        /// Most joints a row may have ([`MAX_JOINTS`]).
        max: usize,
    },
    /// A row whose field count is not the header's.
    #[error(transparent)]
    FieldCount(#[from] csv_text::FieldCount),
    /// A field that must be a number is not one.
    #[error(
        "line {line}, column `{column}`: `{}` is not a number",
        short_text(value)
    )]
    NotNumeric {
        /// 1-based line of the record.
        line: usize,
        /// The column's name.
        column: String,
        /// The field as written.
        value: String,
    },
    /// A field reads as infinite or NaN.
    #[error(
        "line {line}, column `{column}`: `{}` is not a finite number",
        short_text(value)
    )]
    NotFinite {
        /// 1-based line of the record.
        line: usize,
        /// The column's name.
        column: String,
        /// The field as written.
        value: String,
    },
    /// The `set` field names no [`SetRole`].
    #[error("line {line}, column `set`: unknown set `{value}` (expected {names}, or q1, q2, q3)", names = SetRole::names())]
    UnknownSet {
        /// 1-based line of the record.
        line: usize,
        /// The field as written.
        value: String,
    },
    /// The `session` field is longer than 64 characters or holds control characters.
    #[error("line {line}, column `session`: `{value}` is not a session label (at most 64 characters, no control characters)")]
    BadSession {
        /// 1-based line of the record.
        line: usize,
        /// The field as written.
        value: String,
    },
    /// A row gives some of `rx, ry, rz` but not all three.
    #[error("line {line}, columns rx, ry, rz: give all three orientation angles or none")]
    PartialOrientation {
        /// 1-based line of the record.
        line: usize,
    },
    /// A row gives some of a non-angle orientation's values (a quaternion, a
    /// matrix, a rotation vector) but not all.
    #[error("line {line}, columns {columns}: give all {n} values or none", n = columns.split(", ").count())]
    PartialColumns {
        /// 1-based line of the record.
        line: usize,
        /// The group's columns, comma-separated.
        columns: String,
    },
    /// The orientation columns do not fit together (angles and a quaternion,
    /// standard deviations without an orientation).
    #[error("line {line}: {detail}")]
    OrientationColumns {
        /// 1-based line of the header or record.
        line: usize,
        /// What does not fit, for the user.
        detail: String,
    },
    /// A quaternion's norm is not 1 within the tolerance.
    #[error("line {line}, columns qw, qx, qy, qz: the quaternion's norm is {}, not 1 (within {tol}); check the column order (qw first) and that the values are not scaled or truncated", short_number(*norm), tol = crate::model::orientation::QUATERNION_NORM_TOLERANCE)]
    NonUnitQuaternion {
        /// 1-based line of the record.
        line: usize,
        /// The norm read.
        norm: f64,
    },
    /// A standard deviation is not a positive number, or is given where no
    /// value it belongs to is.
    #[error("line {line}, column `{column}`: {what}")]
    BadStd {
        /// 1-based line of the record.
        line: usize,
        /// The column's name.
        column: String,
        /// What is wrong, for the user.
        what: String,
    },
    /// A joint reading beyond [`MAX_JOINT_DEG`]: wrong units (joint readings
    /// are degrees).
    #[error("line {line}, column `{column}`: {} deg looks like wrong units (|q| > {max} deg; joint readings must be in degrees)", short_number(*value), max = MAX_JOINT_DEG)]
    JointUnits {
        /// 1-based line of the record.
        line: usize,
        /// The joint's column.
        column: String,
        /// The reading [deg].
        value: f64,
    },
    /// A value (as stored: after unit conversion) beyond its bound
    /// (`measure::bounds`).
    #[error("line {line}, column `{column}`: {} {} is outside {}{hint}", short_number(*value), bound.unit, bounds::describe(bound))]
    OutOfRange {
        /// 1-based line of the record.
        line: usize,
        /// The column's name.
        column: String,
        /// The value as stored, in the bound's unit.
        value: f64,
        /// The bound it is beyond.
        bound: crate::model::bounds::Bound,
        /// Text after the message naming the unit expected, or empty.
        hint: &'static str,
    },
    /// An external-axis column is empty on a row.
    #[error("line {line}, column `{column}`: empty; the file has this external-axis column, so every row gives its value (or leave the column out)")]
    MissingExternal {
        /// 1-based line of the record.
        line: usize,
        /// The external axis's column (`e1..e6`).
        column: String,
    },
    /// A file with external-axis columns was read declaring metres or radians.
    #[error("line {line}, column `{column}`: external-axis values are read as written (mm for a linear axis, degrees for a rotary one); read the file without declaring metres or radians")]
    ExternalUnits {
        /// 1-based line of the header.
        line: usize,
        /// The external axis's column (`e1..e6`).
        column: String,
    },
    /// External-axis values given to a reader that does not compose them (a
    /// robot calibration, check or solve).
    #[error("line {line}, column `{column}`: external-axis values are read by the track and positioner fits only (docs/external-axes.md); a robot calibration, check or solve does not compose through external axes yet, so the file is refused rather than read as if the axes stood still (a robot on a track is calibrated over its stations with `robocal calibrate --track-column {column}`)")]
    ExternalNotComposed {
        /// 1-based line of the header.
        line: usize,
        /// The external axis's column (`e1..e6`).
        column: String,
    },
    /// Every position coordinate is within ±[`METRES_SUSPECT_MM`]: the file
    /// looks like metres.
    #[error("every position coordinate is within ±{limit} mm: looks like metres, expected millimetres", limit = METRES_SUSPECT_MM)]
    PositionUnits,
    /// A row's joint count is not the model's.
    #[error("row {row}: {got} joint values, but the model has {expected} joints")]
    JointCount {
        /// 1-based index of the row (not the line).
        row: usize,
        /// The model's joint count.
        expected: usize,
        /// The row's joint count.
        got: usize,
    },
}

/// How a measurement CSV is read; the default reads the canonical file
/// (mm, degrees, delimiter and decimal separator detected, `dif` added).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ReadOptions {
    /// Sign of the real-data `*_dif` columns.
    pub dif: DifSign,
    /// Delimiter and decimal separator; `None` fields are detected.
    pub dialect: Dialect,
    /// Positions are in metres (converted to mm).
    pub metres: bool,
    /// Joint and orientation angles are in radians (converted to degrees).
    pub radians: bool,
    /// The convention of the orientation columns; `None`: from the header
    /// (`rx, ry, rz` fixed-axis, `qw, qx, qy, qz` quaternion).
    pub orientation: Option<MeasuredOrientation>,
}
