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
//! `temperature_c`, `set` (`identification`, `training`, `validation`, `check`).
//! Optional external-axis values `e1…e6` (mm for a linear axis, degrees for
//! a rotary one, as the controller shows them; all rows or none), read only
//! by [`parse_set`] ([`crate::measure::external`]): [`parse`] refuses a file
//! with them, naming the column. Columns are found by name;
//! unit checks reject what looks like wrong units, naming line and column.
//! The real data's layout (`x_t`, `x_dif`, `joint_i`) reads as
//! `measured = x_t + dif` ([`DifSign::Plus`]); [`parse_with`] flips it.
//! [`ReadOptions`] declares the dialect (`;`/tab, decimal comma), metres or
//! radians. The header is read in `csv/header.rs`, each row in `csv/row.rs`;
//! the tests are in `csv/tests.rs`.

use super::external::{ExternalAxis, ExternalValues, MeasurementSet};
use super::MeasuredPose;
#[cfg(test)]
use super::RowStd;
use crate::csv_write::{push_header, push_row, Cell};
use crate::measure::csv_text;
use header::parse_header;

mod format;
mod header;
mod row;

pub use format::{
    short_number, CsvError, DifSign, ReadOptions, MAX_JOINTS, MAX_JOINT_DEG, MAX_PAYLOAD_KG,
    MAX_POSITION_MM, METRES_SUSPECT_MM, MIN_JOINTS,
};

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

/// Parses a measurement CSV read as `opts` says; a file with external-axis
/// columns is refused naming the first ([`CsvError::ExternalNotComposed`]).
pub fn parse_opts(text: &str, opts: &ReadOptions) -> Result<Vec<MeasuredPose>, CsvError> {
    let (set, header_line) = read_set(text, opts)?;
    if let Some(axis) = set.axes.first() {
        return Err(CsvError::ExternalNotComposed {
            line: header_line,
            column: axis.column().to_string(),
        });
    }
    Ok(set.poses)
}

/// Parses a measurement CSV with its external-axis columns `e1…e6`, if any
/// (a set without them reads as [`parse`] reads it).
pub fn parse_set(text: &str) -> Result<MeasurementSet, CsvError> {
    parse_set_opts(text, &ReadOptions::default())
}

/// [`parse_set`] read as `opts` says (declaring metres or radians is refused
/// for a file with external-axis columns: their units are the axes').
pub fn parse_set_opts(text: &str, opts: &ReadOptions) -> Result<MeasurementSet, CsvError> {
    read_set(text, opts).map(|(set, _)| set)
}

/// The set and its header's line.
fn read_set(text: &str, opts: &ReadOptions) -> Result<(MeasurementSet, usize), CsvError> {
    let table = csv_text::read(text, opts.dialect)?.ok_or(CsvError::Empty)?;
    let mut header = parse_header(table.header_line, &table.header, opts)?;
    header.decimal_comma = table.decimal_comma;
    let mut rows = Vec::with_capacity(table.records.len());
    let mut external = Vec::with_capacity(table.records.len());
    for r in &table.records {
        table.check_shape(r)?;
        let fields: Vec<&str> = r.fields.iter().map(String::as_str).collect();
        rows.push(header.row(r.line, &fields, opts.dif)?);
        external.push(header.external_values(r.line, &fields)?);
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
    let set = MeasurementSet {
        poses: rows,
        external,
        axes: header.external.iter().map(|&(a, _)| a).collect(),
    };
    Ok((set, header.line))
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
    write_rows(rows, &[], &[])
}

/// Writes a set with its external-axis columns after the joints
/// (`q1..qN,e…,x,y,z,…`); without external axes, as [`write`] writes its
/// poses. `parse_set(&write_set(set)) == set` for sets that pass the checks.
pub fn write_set(set: &MeasurementSet) -> String {
    write_rows(&set.poses, &set.external, &set.axes)
}

/// The canonical text of `rows`, with `axes`' columns from `external` (one
/// entry per row, or none when `axes` is empty).
fn write_rows(rows: &[MeasuredPose], external: &[ExternalValues], axes: &[ExternalAxis]) -> String {
    let n = rows.iter().map(|r| r.q_deg.len()).max().unwrap_or(0);
    let rot = rows.iter().any(|r| r.rpy_deg.is_some());
    let std_pos = rows.iter().any(|r| r.std_mm.is_some());
    let std_rot = rows.iter().any(|r| r.std_deg.is_some());
    let payload = rows.iter().any(|r| r.payload_kg.is_some());
    let temp = rows.iter().any(|r| r.temperature_c.is_some());
    let set = rows.iter().any(|r| r.set.is_some());
    let session = rows.iter().any(|r| r.session.is_some());

    let mut header: Vec<String> = (1..=n).map(|i| format!("q{i}")).collect();
    header.extend(axes.iter().map(|a| a.column().to_string()));
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
    let none = ExternalValues::default();
    for (k, r) in rows.iter().enumerate() {
        f.clear();
        f.extend((0..n).map(|i| r.q_deg.get(i).copied().map_or_else(Cell::empty, Cell::num)));
        let e = external.get(k).unwrap_or(&none);
        f.extend(
            axes.iter()
                .map(|&a| e.get(a).map_or_else(Cell::empty, Cell::num)),
        );
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
mod external_tests;
#[cfg(test)]
mod orientation_tests;
#[cfg(test)]
mod tests;
