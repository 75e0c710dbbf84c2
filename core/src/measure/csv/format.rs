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
    #[error("the CSV file is empty: no header row")]
    Empty,
    #[error(transparent)]
    Text(#[from] TextError),
    #[error("no data rows after the header on line {header_line}")]
    NoDataRows { header_line: usize },
    #[error("line {line}: missing column `{column}`")]
    MissingColumn { line: usize, column: String },
    #[error("line {line}: unknown column `{column}`; accepted columns: {accepted}")]
    UnknownColumn {
        line: usize,
        column: String,
        accepted: String,
    },
    #[error("line {line}: duplicate column `{column}` (column `{previous}` already given)")]
    DuplicateColumn {
        line: usize,
        column: String,
        previous: String,
    },
    #[error("line {line}: conflicting columns `{first}` and `{second}` (use one position layout: x,y,z or x_t,y_t,z_t + x_dif,y_dif,z_dif)")]
    ConflictingColumns {
        line: usize,
        first: String,
        second: String,
    },
    #[error("line {line}: joint columns must be q1..qN with {min} <= N <= {max}, found {found}")]
    JointColumns {
        line: usize,
        found: String,
        min: usize,
        max: usize,
    },
    /// A row whose field count is not the header's.
    #[error(transparent)]
    FieldCount(#[from] csv_text::FieldCount),
    #[error(
        "line {line}, column `{column}`: `{}` is not a number",
        short_text(value)
    )]
    NotNumeric {
        line: usize,
        column: String,
        value: String,
    },
    #[error(
        "line {line}, column `{column}`: `{}` is not a finite number",
        short_text(value)
    )]
    NotFinite {
        line: usize,
        column: String,
        value: String,
    },
    #[error("line {line}, column `set`: unknown set `{value}` (expected {names}, or q1, q2, q3)", names = SetRole::names())]
    UnknownSet { line: usize, value: String },
    #[error("line {line}, column `session`: `{value}` is not a session label (at most 64 characters, no control characters)")]
    BadSession { line: usize, value: String },
    #[error("line {line}, columns rx, ry, rz: give all three orientation angles or none")]
    PartialOrientation { line: usize },
    #[error("line {line}, columns {columns}: give all {n} values or none", n = columns.split(", ").count())]
    PartialColumns { line: usize, columns: String },
    #[error("line {line}: {detail}")]
    OrientationColumns { line: usize, detail: String },
    #[error("line {line}, columns qw, qx, qy, qz: the quaternion's norm is {}, not 1 (within {tol}); check the column order (qw first) and that the values are not scaled or truncated", short_number(*norm), tol = crate::model::orientation::QUATERNION_NORM_TOLERANCE)]
    NonUnitQuaternion { line: usize, norm: f64 },
    #[error("line {line}, column `{column}`: {what}")]
    BadStd {
        line: usize,
        column: String,
        what: String,
    },
    #[error("line {line}, column `{column}`: {} deg looks like wrong units (|q| > {max} deg; joint readings must be in degrees)", short_number(*value), max = MAX_JOINT_DEG)]
    JointUnits {
        line: usize,
        column: String,
        value: f64,
    },
    /// A value (as stored: after unit conversion) beyond its bound
    /// (`measure::bounds`).
    #[error("line {line}, column `{column}`: {} {} is outside {}{hint}", short_number(*value), bound.unit, bounds::describe(bound))]
    OutOfRange {
        line: usize,
        column: String,
        value: f64,
        bound: crate::model::bounds::Bound,
        hint: &'static str,
    },
    #[error("line {line}, column `{column}`: empty; the file has this external-axis column, so every row gives its value (or leave the column out)")]
    MissingExternal { line: usize, column: String },
    #[error("line {line}, column `{column}`: external-axis values are read as written (mm for a linear axis, degrees for a rotary one); read the file without declaring metres or radians")]
    ExternalUnits { line: usize, column: String },
    #[error("line {line}, column `{column}`: external-axis values are read by the track and positioner fits only (docs/external-axes.md); a robot calibration, check or solve does not compose through external axes yet, so the file is refused rather than read as if the axes stood still")]
    ExternalNotComposed { line: usize, column: String },
    #[error("every position coordinate is within ±{limit} mm: looks like metres, expected millimetres", limit = METRES_SUSPECT_MM)]
    PositionUnits,
    #[error("row {row}: {got} joint values, but the model has {expected} joints")]
    JointCount {
        row: usize,
        expected: usize,
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
