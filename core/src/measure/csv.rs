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
//! radians. The tests are in `csv/tests.rs`.

use super::convention::{MeasuredOrientation, OrientationValueError};
#[cfg(test)]
use super::RowStd;
use super::{MeasuredPose, SetRole};
use crate::measure::csv_text::{self, short_text, Dialect, TextError};
use std::fmt::Write as _;

/// Maximum joint count of a CSV row.
pub const MAX_JOINTS: usize = 7;
/// Minimum joint count of a CSV row.
pub const MIN_JOINTS: usize = 2;
/// A joint reading beyond this magnitude [deg] is rejected as wrong units.
pub const MAX_JOINT_DEG: f64 = 720.0;
/// If every position coordinate of the file is below this magnitude [mm], the
/// file is rejected as metres.
pub const METRES_SUSPECT_MM: f64 = 5.0;
/// Largest accepted magnitude of a position coordinate [mm] (100 m).
pub const MAX_POSITION_MM: f64 = 100_000.0;
/// Largest accepted payload [kg].
pub const MAX_PAYLOAD_KG: f64 = 10_000.0;

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
    #[error("line {line}: expected {expected} fields, got {got}")]
    FieldCount {
        line: usize,
        expected: usize,
        got: usize,
    },
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
    #[error("line {line}, column `{column}`: {} {unit} is outside {range}", short_number(*value))]
    OutOfRange {
        line: usize,
        column: String,
        value: f64,
        unit: &'static str,
        range: &'static str,
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

/// What one header column means.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Col {
    Joint(usize),
    Pos(usize),
    Rot(usize),
    Quat(usize),
    StdPos(usize),
    StdRot(usize),
    Payload,
    Temperature,
    Set,
    Session,
    Target(usize),
    Dif(usize),
    StepOrder,
}

fn classify(name: &str) -> Option<Col> {
    let fixed = match name {
        "x" => Some(Col::Pos(0)),
        "y" => Some(Col::Pos(1)),
        "z" => Some(Col::Pos(2)),
        "rx" | "rx_deg" => Some(Col::Rot(0)),
        "ry" | "ry_deg" => Some(Col::Rot(1)),
        "rz" | "rz_deg" => Some(Col::Rot(2)),
        "qw" => Some(Col::Quat(0)),
        "qx" => Some(Col::Quat(1)),
        "qy" => Some(Col::Quat(2)),
        "qz" => Some(Col::Quat(3)),
        "std_x" => Some(Col::StdPos(0)),
        "std_y" => Some(Col::StdPos(1)),
        "std_z" => Some(Col::StdPos(2)),
        "std_rx" => Some(Col::StdRot(0)),
        "std_ry" => Some(Col::StdRot(1)),
        "std_rz" => Some(Col::StdRot(2)),
        "payload_kg" => Some(Col::Payload),
        "temperature_c" => Some(Col::Temperature),
        "set" => Some(Col::Set),
        "session" => Some(Col::Session),
        "x_t" => Some(Col::Target(0)),
        "y_t" => Some(Col::Target(1)),
        "z_t" => Some(Col::Target(2)),
        "x_dif" => Some(Col::Dif(0)),
        "y_dif" => Some(Col::Dif(1)),
        "z_dif" => Some(Col::Dif(2)),
        "step_order" => Some(Col::StepOrder),
        _ => None,
    };
    if fixed.is_some() {
        return fixed;
    }
    let num = name
        .strip_prefix("joint_")
        .or_else(|| name.strip_prefix('q'))?;
    if num.is_empty() || !num.bytes().all(|b| b.is_ascii_digit()) || num.starts_with('0') {
        return None;
    }
    num.parse::<usize>().ok().map(Col::Joint)
}

fn canonical_name(c: Col) -> String {
    const XYZ: [&str; 3] = ["x", "y", "z"];
    match c {
        Col::Joint(i) => format!("q{i}"),
        Col::Pos(i) => XYZ[i].to_string(),
        Col::Rot(i) => format!("r{}", XYZ[i]),
        Col::Quat(i) => MeasuredOrientation::Quaternion.columns()[i].to_string(),
        Col::StdPos(i) => format!("std_{}", XYZ[i]),
        Col::StdRot(i) => format!("std_r{}", XYZ[i]),
        Col::Payload => "payload_kg".into(),
        Col::Temperature => "temperature_c".into(),
        Col::Set => "set".into(),
        Col::Session => "session".into(),
        Col::Target(i) => format!("{}_t", XYZ[i]),
        Col::Dif(i) => format!("{}_dif", XYZ[i]),
        Col::StepOrder => "step_order".into(),
    }
}

/// Column indices of the recognised header.
struct Header {
    line: usize,
    names: Vec<String>,
    joints: Vec<usize>,
    /// Canonical `x,y,z` or the real-data `(target, dif)` triples.
    position: PositionCols,
    /// The orientation columns (in the convention's order) and their convention.
    rot: Option<(MeasuredOrientation, Vec<usize>)>,
    std_pos: Option<[usize; 3]>,
    std_rot: Option<[usize; 3]>,
    payload: Option<usize>,
    temperature: Option<usize>,
    set: Option<usize>,
    session: Option<usize>,
    /// How numbers and units are read (from [`ReadOptions`] and the text).
    decimal_comma: bool,
    metres: bool,
    radians: bool,
}

enum PositionCols {
    Measured([usize; 3]),
    TargetPlusDif([usize; 3], [usize; 3]),
}

fn parse_header(line: usize, fields: &[String], opts: &ReadOptions) -> Result<Header, CsvError> {
    let names: Vec<String> = fields.iter().map(|s| s.to_ascii_lowercase()).collect();
    let mut cols: Vec<(Col, usize)> = Vec::new();
    for (i, name) in names.iter().enumerate() {
        let col = classify(name).ok_or_else(|| CsvError::UnknownColumn {
            line,
            column: name.clone(),
            accepted: ACCEPTED.into(),
        })?;
        if let Some((_, j)) = cols.iter().find(|(c, _)| *c == col) {
            return Err(CsvError::DuplicateColumn {
                line,
                column: name.clone(),
                previous: names[*j].clone(),
            });
        }
        cols.push((col, i));
    }
    let find = |c: Col| cols.iter().find(|(x, _)| *x == c).map(|(_, i)| *i);
    let missing = |c: Col| CsvError::MissingColumn {
        line,
        column: canonical_name(c),
    };

    // Joints: q1..qN contiguous, 2 <= N <= 7.
    let mut idx: Vec<usize> = cols
        .iter()
        .filter_map(|(c, _)| match c {
            Col::Joint(i) => Some(*i),
            _ => None,
        })
        .collect();
    idx.sort_unstable();
    let n = idx.last().copied().unwrap_or(0);
    if n == 0 {
        return Err(missing(Col::Joint(1)));
    }
    let found = || {
        idx.iter()
            .map(|i| format!("q{i}"))
            .collect::<Vec<_>>()
            .join(",")
    };
    if !(MIN_JOINTS..=MAX_JOINTS).contains(&n) {
        return Err(CsvError::JointColumns {
            line,
            found: found(),
            min: MIN_JOINTS,
            max: MAX_JOINTS,
        });
    }
    let mut joints = Vec::with_capacity(n);
    for i in 1..=n {
        joints.push(find(Col::Joint(i)).ok_or_else(|| missing(Col::Joint(i)))?);
    }

    // Position: canonical or real-data layout, not both.
    let any_pos = (0..3).find_map(|i| find(Col::Pos(i)).map(|c| (i, c)));
    let any_real = (0..3)
        .flat_map(|i| [Col::Target(i), Col::Dif(i)])
        .find_map(|c| find(c).map(|j| (c, j)));
    let position = match (any_pos, any_real) {
        (Some((_, a)), Some((_, b))) => {
            return Err(CsvError::ConflictingColumns {
                line,
                first: names[a.min(b)].clone(),
                second: names[a.max(b)].clone(),
            })
        }
        (None, Some(_)) => {
            let mut t = [0; 3];
            let mut d = [0; 3];
            for i in 0..3 {
                t[i] = find(Col::Target(i)).ok_or_else(|| missing(Col::Target(i)))?;
                d[i] = find(Col::Dif(i)).ok_or_else(|| missing(Col::Dif(i)))?;
            }
            PositionCols::TargetPlusDif(t, d)
        }
        _ => {
            let mut p = [0; 3];
            for (i, slot) in p.iter_mut().enumerate() {
                *slot = find(Col::Pos(i)).ok_or_else(|| missing(Col::Pos(i)))?;
            }
            PositionCols::Measured(p)
        }
    };

    let rot = orientation_columns(line, &find, opts.orientation)?;
    let triple = |col: fn(usize) -> Col| -> Result<Option<[usize; 3]>, CsvError> {
        if (0..3).all(|i| find(col(i)).is_none()) {
            return Ok(None);
        }
        let mut r = [0; 3];
        for (i, slot) in r.iter_mut().enumerate() {
            *slot = find(col(i)).ok_or_else(|| missing(col(i)))?;
        }
        Ok(Some(r))
    };
    let std_pos = triple(Col::StdPos)?;
    let std_rot = triple(Col::StdRot)?;
    if std_rot.is_some() && std_pos.is_none() {
        return Err(missing(Col::StdPos(0)));
    }
    if std_rot.is_some() && rot.is_none() {
        return Err(CsvError::OrientationColumns {
            line,
            detail: "std_rx, std_ry, std_rz given but no orientation columns".into(),
        });
    }

    Ok(Header {
        line,
        joints,
        position,
        rot,
        std_pos,
        std_rot,
        payload: find(Col::Payload),
        temperature: find(Col::Temperature),
        set: find(Col::Set),
        session: find(Col::Session),
        names,
        decimal_comma: false,
        metres: opts.metres,
        radians: opts.radians,
    })
}

/// The orientation columns of a header: `rx, ry, rz` (fixed-axis unless
/// `declared` says intrinsic) or `qw, qx, qy, qz`, never both; a declared
/// convention must match the columns present.
fn orientation_columns(
    line: usize,
    find: &dyn Fn(Col) -> Option<usize>,
    declared: Option<MeasuredOrientation>,
) -> Result<Option<(MeasuredOrientation, Vec<usize>)>, CsvError> {
    let angles = (0..3).any(|i| find(Col::Rot(i)).is_some());
    let quat = (0..4).any(|i| find(Col::Quat(i)).is_some());
    let wrong = |detail: String| Err(CsvError::OrientationColumns { line, detail });
    let conv = match (angles, quat, declared) {
        (false, false, _) => return Ok(None),
        (true, true, _) => {
            return wrong(
                "both rx, ry, rz and qw, qx, qy, qz given: write one orientation convention".into(),
            )
        }
        (true, false, Some(MeasuredOrientation::Quaternion)) => {
            return wrong(
                "the orientation is declared quaternion but the file has rx, ry, rz columns (declare fixed_xyz or intrinsic_xyz)".into(),
            )
        }
        (false, true, Some(c)) if c.is_angles() => {
            return wrong(format!(
                "the orientation is declared {c} but the file has qw, qx, qy, qz columns (declare quaternion or nothing)"
            ))
        }
        (true, false, c) => c.unwrap_or_default(),
        (false, true, _) => MeasuredOrientation::Quaternion,
    };
    let col = |i: usize| {
        if conv.is_angles() {
            Col::Rot(i)
        } else {
            Col::Quat(i)
        }
    };
    let cols = (0..conv.columns().len())
        .map(|i| {
            find(col(i)).ok_or_else(|| CsvError::MissingColumn {
                line,
                column: canonical_name(col(i)),
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Some((conv, cols)))
}

/// Parses one numeric field; `None` for an empty field.
fn number(
    line: usize,
    column: &str,
    s: &str,
    decimal_comma: bool,
) -> Result<Option<f64>, CsvError> {
    if s.is_empty() {
        return Ok(None);
    }
    let v: f64 = csv_text::parse_number(s, decimal_comma).ok_or_else(|| CsvError::NotNumeric {
        line,
        column: column.to_string(),
        value: s.to_string(),
    })?;
    if !v.is_finite() {
        return Err(CsvError::NotFinite {
            line,
            column: column.to_string(),
            value: s.to_string(),
        });
    }
    Ok(Some(v))
}

fn required(line: usize, column: &str, s: &str, decimal_comma: bool) -> Result<f64, CsvError> {
    number(line, column, s, decimal_comma)?.ok_or_else(|| CsvError::NotNumeric {
        line,
        column: column.to_string(),
        value: String::new(),
    })
}

impl Header {
    fn row(&self, line: usize, fields: &[&str], sign: DifSign) -> Result<MeasuredPose, CsvError> {
        if fields.len() != self.names.len() {
            return Err(CsvError::FieldCount {
                line,
                expected: self.names.len(),
                got: fields.len(),
            });
        }
        let dc = self.decimal_comma;
        let req = |c: usize| required(line, &self.names[c], fields[c], dc);
        let opt = |c: usize| number(line, &self.names[c], fields[c], dc);
        let angle = |v: f64| if self.radians { v.to_degrees() } else { v };
        let length = if self.metres { 1e3 } else { 1.0 };

        let mut q_deg = Vec::with_capacity(self.joints.len());
        for &c in &self.joints {
            let v = angle(req(c)?);
            if v.abs() > MAX_JOINT_DEG {
                return Err(CsvError::JointUnits {
                    line,
                    column: self.names[c].clone(),
                    value: v,
                });
            }
            q_deg.push(v);
        }
        let mut xyz_mm = [0.0; 3];
        match &self.position {
            PositionCols::Measured(p) => {
                for (x, &c) in xyz_mm.iter_mut().zip(p) {
                    *x = length * req(c)?;
                }
            }
            PositionCols::TargetPlusDif(t, d) => {
                for i in 0..3 {
                    xyz_mm[i] = length * (req(t[i])? + sign.factor() * req(d[i])?);
                }
            }
        }
        let position_cols = match &self.position {
            PositionCols::Measured(p) => *p,
            PositionCols::TargetPlusDif(t, _) => *t,
        };
        for (x, &c) in xyz_mm.iter().zip(&position_cols) {
            if x.abs() > MAX_POSITION_MM {
                return Err(CsvError::OutOfRange {
                    line,
                    column: self.names[c].clone(),
                    value: *x,
                    unit: "mm",
                    range: "±100 m (positions are in millimetres)",
                });
            }
        }
        let rpy_deg = match &self.rot {
            None => None,
            Some((conv, cols)) => {
                let v = cols
                    .iter()
                    .map(|&c| opt(c))
                    .collect::<Result<Vec<_>, _>>()?;
                if v.iter().all(Option::is_none) {
                    None
                } else if v.iter().any(Option::is_none) {
                    return Err(if conv.is_angles() {
                        CsvError::PartialOrientation { line }
                    } else {
                        self.partial(line, cols)
                    });
                } else {
                    let v: Vec<f64> = v.into_iter().flatten().collect();
                    let v: Vec<f64> = if conv.is_angles() {
                        v.into_iter().map(angle).collect()
                    } else {
                        v
                    };
                    Some(conv.to_fixed_xyz_deg(&v).map_err(|e| match e {
                        OrientationValueError::NonUnitQuaternion { norm } => {
                            CsvError::NonUnitQuaternion { line, norm }
                        }
                    })?)
                }
            }
        };
        let std_mm = self.std(line, fields, self.std_pos, length)?;
        let std_deg = match self.std_rot {
            Some(cols) if rpy_deg.is_none() => {
                if let Some(&c) = cols.iter().find(|&&c| !fields[c].is_empty()) {
                    return Err(CsvError::BadStd {
                        line,
                        column: self.names[c].clone(),
                        what: "an orientation standard deviation on a row without an orientation"
                            .into(),
                    });
                }
                None
            }
            cols => self.std(
                line,
                fields,
                cols,
                if self.radians { 1f64.to_degrees() } else { 1.0 },
            )?,
        };
        let payload_kg = self.payload.map(opt).transpose()?.flatten();
        if let (Some(kg), Some(c)) = (payload_kg, self.payload) {
            if !(0.0..=MAX_PAYLOAD_KG).contains(&kg) {
                return Err(CsvError::OutOfRange {
                    line,
                    column: self.names[c].clone(),
                    value: kg,
                    unit: "kg",
                    range: "0..10000 kg",
                });
            }
        }
        let temperature_c = self.temperature.map(opt).transpose()?.flatten();
        let set = match self.set {
            Some(c) if !fields[c].is_empty() => Some(SetRole::parse(fields[c]).ok_or_else(
                || CsvError::UnknownSet {
                    line,
                    value: fields[c].to_string(),
                },
            )?),
            _ => None,
        };
        let session = match self.session {
            Some(c) if !fields[c].is_empty() => {
                let v = fields[c];
                if v.chars().count() > 64 || v.chars().any(|ch| ch.is_control()) {
                    return Err(CsvError::BadSession {
                        line,
                        value: short_text(v),
                    });
                }
                Some(v.to_string())
            }
            _ => None,
        };
        Ok(MeasuredPose {
            q_deg,
            xyz_mm,
            rpy_deg,
            std_mm,
            std_deg,
            payload_kg,
            temperature_c,
            set,
            session,
        })
    }

    fn partial(&self, line: usize, cols: &[usize]) -> CsvError {
        CsvError::PartialColumns {
            line,
            columns: cols
                .iter()
                .map(|&c| self.names[c].as_str())
                .collect::<Vec<_>>()
                .join(", "),
        }
    }

    /// Three standard deviations (scaled by `unit` into mm or degrees); when
    /// the columns exist every row gives all three, each finite and > 0.
    fn std(
        &self,
        line: usize,
        fields: &[&str],
        cols: Option<[usize; 3]>,
        unit: f64,
    ) -> Result<Option<[f64; 3]>, CsvError> {
        let Some(cols) = cols else { return Ok(None) };
        let mut out = [0.0; 3];
        for (o, &c) in out.iter_mut().zip(&cols) {
            let bad = |what: String| CsvError::BadStd {
                line,
                column: self.names[c].clone(),
                what,
            };
            let v = number(line, &self.names[c], fields[c], self.decimal_comma)?;
            *o = match v {
                None => {
                    return Err(bad(
                        "empty: the file has standard-deviation columns, so every row gives them (or leave the columns out)"
                            .into(),
                    ))
                }
                Some(v) if v <= 0.0 => {
                    return Err(bad(format!(
                        "{} is not a standard deviation (must be > 0)",
                        short_number(v)
                    )))
                }
                Some(v) => v * unit,
            };
        }
        Ok(Some(out))
    }
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

/// Shortest text that parses back to exactly `x` (plain decimal, or exponent
/// notation when the decimal would be long, e.g. `1e-17`).
fn num(x: f64) -> String {
    let s = x.to_string();
    if s.len() > 24 {
        format!("{x:e}")
    } else {
        s
    }
}

/// Writes rows in the canonical layout
/// `q1..qN,x,y,z[,rx,ry,rz][,std_x,std_y,std_z][,std_rx,std_ry,std_rz][,payload_kg][,temperature_c][,set][,session]`.
///
/// N is the largest joint count among the rows (rows are expected to agree); an
/// optional column is written when any row has it, rows without it get an empty
/// field. Numbers use Rust's shortest exact representation, so
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
    let mut out = header.join(",");
    out.push('\n');

    let opt = |v: Option<f64>| v.map(num).unwrap_or_default();
    for r in rows {
        let mut f: Vec<String> = (0..n)
            .map(|i| r.q_deg.get(i).copied().map(num).unwrap_or_default())
            .collect();
        f.extend(r.xyz_mm.iter().copied().map(num));
        if rot {
            match r.rpy_deg {
                Some(a) => f.extend(a.iter().copied().map(num)),
                None => f.extend([String::new(), String::new(), String::new()]),
            }
        }
        for (on, v) in [(std_pos, r.std_mm), (std_rot, r.std_deg)] {
            if on {
                match v {
                    Some(a) => f.extend(a.iter().copied().map(num)),
                    None => f.extend([String::new(), String::new(), String::new()]),
                }
            }
        }
        if payload {
            f.push(opt(r.payload_kg));
        }
        if temp {
            f.push(opt(r.temperature_c));
        }
        if set {
            f.push(r.set.map(|s| s.as_str().to_string()).unwrap_or_default());
        }
        if session {
            f.push(r.session.clone().unwrap_or_default());
        }
        let _ = writeln!(out, "{}", f.join(","));
    }
    out
}

#[cfg(test)]
mod orientation_tests;
#[cfg(test)]
mod tests;
