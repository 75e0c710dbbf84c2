//! The measurement CSV format (docs/design.md "Measurement CSV"): [`parse`]
//! and [`write`].
//!
//! Canonical layout (what [`write`] produces):
//!
//! ```text
//! # comments start with '#', anywhere; blank lines are ignored
//! q1,q2,q3,q4,q5,q6,x,y,z,rx,ry,rz,payload_kg,temperature_c,set
//! 10,95,-20,0,30,0,1523.2,12.5,980.1,,,,110,21.5,identification
//! ```
//!
//! Units: `q1..qN` controller joint readings [deg] (N = 2..7), `x, y, z` the
//! TCP position in the measurement (tracker) frame [mm], optional orientation:
//! `rx, ry, rz` in degrees, fixed-axis XYZ `R = Rz(rz)·Ry(ry)·Rx(rx)` (not a
//! rotation vector) unless [`ReadOptions::orientation`] declares the intrinsic
//! order, or `qw, qx, qy, qz` (a quaternion; [`MeasuredOrientation`]), stored
//! as fixed-axis angles whatever the file's convention. Optional per-row
//! standard deviations `std_x, std_y, std_z` [mm] and `std_rx, std_ry, std_rz`
//! [deg] (all rows or none). Optional `session`, `payload_kg`,
//! `temperature_c`, `set` (`identification`, `training`, `validation`, `check`). Columns are found by name;
//! unit checks reject what looks like wrong units, naming line and column.
//! The real data's layout (`x_t`, `x_dif`, `joint_i`) reads as
//! `measured = x_t + dif` ([`DifSign::Plus`]); [`parse_with`] flips it.
//! [`ReadOptions`] declares the dialect (`;`/tab, decimal comma), metres or
//! radians. The header is read in `csv/header.rs`, each row in `csv/row.rs`;
//! the tests are in `csv/tests.rs`.

use super::bounds;
use super::convention::MeasuredOrientation;
#[cfg(test)]
use super::RowStd;
use super::{MeasuredPose, SetRole};
use crate::measure::csv_text::{self, short_text, Dialect, TextError};
use crate::measure::csv_write::{push_header, push_row, Cell};
use header::parse_header;

mod header;
mod row;

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

const ACCEPTED: &str =
    "q1..q7 (alias joint_1..joint_7), x, y, z, rx, ry, rz (degrees, fixed-axis XYZ unless \
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
    fn factor(self) -> f64 {
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

/// Parses a measurement CSV (either layout; real-data `dif` added: [`DifSign::Plus`]).
pub fn parse(text: &str) -> Result<Vec<MeasuredPose>, CsvError> {
    parse_opts(text, &ReadOptions::default())
}

/// Parses a measurement CSV with an explicit sign for the real-data `*_dif` columns.
pub fn parse_with(text: &str, dif: DifSign) -> Result<Vec<MeasuredPose>, CsvError> {
    parse_opts(
        text,
        &ReadOptions {
            dif,
            ..ReadOptions::default()
        },
    )
}

/// Parses a measurement CSV read as `opts` says.
pub fn parse_opts(text: &str, opts: &ReadOptions) -> Result<Vec<MeasuredPose>, CsvError> {
    let table = csv_text::read(text, opts.dialect)?.ok_or(CsvError::Empty)?;
    let mut header = parse_header(table.header_line, &table.header, opts)?;
    header.decimal_comma = table.decimal_comma;
    let mut rows = Vec::with_capacity(table.records.len());
    for r in &table.records {
        table.check_shape(r)?;
        let fields: Vec<&str> = r.fields.iter().map(String::as_str).collect();
        rows.push(header.row(r.line, &fields, opts.dif)?);
    }
    if rows.is_empty() {
        return Err(CsvError::NoDataRows {
            header_line: header.line,
        });
    }
    let all_small = rows
        .iter()
        .all(|r| r.xyz_mm.iter().all(|v| v.abs() < METRES_SUSPECT_MM));
    if all_small {
        return Err(CsvError::PositionUnits);
    }
    Ok(rows)
}

/// Checks that every row has `dof` joint values.
pub fn check_joint_count(rows: &[MeasuredPose], dof: usize) -> Result<(), CsvError> {
    match rows.iter().position(|r| r.q_deg.len() != dof) {
        None => Ok(()),
        Some(i) => Err(CsvError::JointCount {
            row: i + 1,
            expected: dof,
            got: rows[i].q_deg.len(),
        }),
    }
}

/// Writes rows in the canonical layout
/// `q1..qN,x,y,z[,rx,ry,rz][,std_x,std_y,std_z][,std_rx,std_ry,std_rz][,payload_kg][,temperature_c][,set][,session]`.
///
/// N is the largest joint count among the rows (rows are expected to agree); an
/// optional column is written when any row has it, rows without it get an empty
/// field. Numbers use Rust's shortest exact representation and texts (the
/// session) are written as `csv_write` writes every text, so
/// `parse(&write(rows)) == rows` bit for bit (for rows that pass the unit checks).
pub fn write(rows: &[MeasuredPose]) -> String {
    let n = rows.iter().map(|r| r.q_deg.len()).max().unwrap_or(0);
    let rot = rows.iter().any(|r| r.rpy_deg.is_some());
    let std_pos = rows.iter().any(|r| r.std_mm.is_some());
    let std_rot = rows.iter().any(|r| r.std_deg.is_some());
    let payload = rows.iter().any(|r| r.payload_kg.is_some());
    let temp = rows.iter().any(|r| r.temperature_c.is_some());
    let set = rows.iter().any(|r| r.set.is_some());
    let session = rows.iter().any(|r| r.session.is_some());

    let mut header: Vec<String> = (1..=n).map(|i| format!("q{i}")).collect();
    header.extend(["x", "y", "z"].map(String::from));
    if rot {
        header.extend(["rx", "ry", "rz"].map(String::from));
    }
    if std_pos {
        header.extend(["std_x", "std_y", "std_z"].map(String::from));
    }
    if std_rot {
        header.extend(["std_rx", "std_ry", "std_rz"].map(String::from));
    }
    if payload {
        header.push("payload_kg".into());
    }
    if temp {
        header.push("temperature_c".into());
    }
    if set {
        header.push("set".into());
    }
    if session {
        header.push("session".into());
    }
    let mut out = String::new();
    push_header(&mut out, &header);
    let blank3 = || [Cell::empty(), Cell::empty(), Cell::empty()];
    let three = |v: Option<[f64; 3]>| v.map_or_else(blank3, |a| a.map(Cell::num));
    let mut f: Vec<Cell> = Vec::with_capacity(header.len());
    for r in rows {
        f.clear();
        f.extend((0..n).map(|i| r.q_deg.get(i).copied().map_or_else(Cell::empty, Cell::num)));
        f.extend(r.xyz_mm.map(Cell::num));
        if rot {
            f.extend(three(r.rpy_deg));
        }
        for (on, v) in [(std_pos, r.std_mm), (std_rot, r.std_deg)] {
            if on {
                f.extend(three(v));
            }
        }
        for (on, v) in [(payload, r.payload_kg), (temp, r.temperature_c)] {
            if on {
                f.push(v.map_or_else(Cell::empty, Cell::num));
            }
        }
        if set {
            f.push(Cell::text(r.set.map(|s| s.as_str()).unwrap_or_default()));
        }
        if session {
            f.push(Cell::text(r.session.as_deref().unwrap_or_default()));
        }
        push_row(&mut out, &f);
    }
    out
}

#[cfg(test)]
mod orientation_tests;
#[cfg(test)]
mod tests;
