//! The header line of a measurement CSV: which column holds what
//! (`super` module docs for the names and units).

use super::format::{CsvError, ReadOptions, ACCEPTED, MAX_JOINTS, MIN_JOINTS};
use crate::measure::convention::MeasuredOrientation;
use crate::measure::external::ExternalAxis;

/// What one header column means.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Col {
    Joint(usize),
    /// `e1…e6`, by 0-based index.
    External(usize),
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
    if let Some(n) = name.strip_prefix('e') {
        return match n.as_bytes() {
            [d @ b'1'..=b'6'] => Some(Col::External(usize::from(d - b'1'))),
            _ => None,
        };
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
        Col::External(i) => ExternalAxis::ALL[i].column().to_string(),
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
pub(super) struct Header {
    pub(super) line: usize,
    pub(super) names: Vec<String>,
    pub(super) joints: Vec<usize>,
    /// The external-axis columns `e1…e6` the file has, in axis order.
    pub(super) external: Vec<(ExternalAxis, usize)>,
    /// Canonical `x,y,z` or the real-data `(target, dif)` triples.
    pub(super) position: PositionCols,
    /// The orientation columns (in the convention's order) and their convention.
    pub(super) rot: Option<(MeasuredOrientation, Vec<usize>)>,
    pub(super) std_pos: Option<[usize; 3]>,
    pub(super) std_rot: Option<[usize; 3]>,
    pub(super) payload: Option<usize>,
    pub(super) temperature: Option<usize>,
    pub(super) set: Option<usize>,
    pub(super) session: Option<usize>,
    /// How numbers and units are read (from [`ReadOptions`] and the text).
    pub(super) decimal_comma: bool,
    pub(super) metres: bool,
    pub(super) radians: bool,
}

pub(super) enum PositionCols {
    Measured([usize; 3]),
    TargetPlusDif([usize; 3], [usize; 3]),
}

/// The recognised columns of a header line (lower-cased `names`), each
/// once.
fn columns(line: usize, names: &[String]) -> Result<Vec<(Col, usize)>, CsvError> {
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
    Ok(cols)
}

/// The missing-column error for `c`.
fn missing(line: usize, c: Col) -> CsvError {
    CsvError::MissingColumn {
        line,
        column: canonical_name(c),
    }
}

/// Joints: `q1..qN` contiguous, `MIN_JOINTS <= N <= MAX_JOINTS`; none at
/// all only in a file with external-axis columns (`external`: a positioner's
/// readings carry no robot joints).
fn joint_columns(
    line: usize,
    cols: &[(Col, usize)],
    find: &dyn Fn(Col) -> Option<usize>,
    external: bool,
) -> Result<Vec<usize>, CsvError> {
    let mut idx: Vec<usize> = cols
        .iter()
        .filter_map(|(c, _)| match c {
            Col::Joint(i) => Some(*i),
            _ => None,
        })
        .collect();
    idx.sort_unstable();
    let n = idx.last().copied().unwrap_or(0);
    if n == 0 && external {
        return Ok(Vec::new());
    }
    if n == 0 {
        return Err(missing(line, Col::Joint(1)));
    }
    if !(MIN_JOINTS..=MAX_JOINTS).contains(&n) {
        return Err(CsvError::JointColumns {
            line,
            found: idx
                .iter()
                .map(|i| format!("q{i}"))
                .collect::<Vec<_>>()
                .join(","),
            min: MIN_JOINTS,
            max: MAX_JOINTS,
        });
    }
    (1..=n)
        .map(|i| find(Col::Joint(i)).ok_or_else(|| missing(line, Col::Joint(i))))
        .collect()
}

/// Position: the canonical `x, y, z` or the real-data `(target, dif)`
/// triples, not both.
fn position_columns(
    line: usize,
    names: &[String],
    find: &dyn Fn(Col) -> Option<usize>,
) -> Result<PositionCols, CsvError> {
    let any_pos = (0..3).find_map(|i| find(Col::Pos(i)));
    let any_real = (0..3)
        .flat_map(|i| [Col::Target(i), Col::Dif(i)])
        .find_map(find);
    match (any_pos, any_real) {
        (Some(a), Some(b)) => Err(CsvError::ConflictingColumns {
            line,
            first: names[a.min(b)].clone(),
            second: names[a.max(b)].clone(),
        }),
        (None, Some(_)) => {
            // Each target column before its dif, as the file is checked.
            let mut t = [0; 3];
            let mut d = [0; 3];
            for i in 0..3 {
                t[i] = find(Col::Target(i)).ok_or_else(|| missing(line, Col::Target(i)))?;
                d[i] = find(Col::Dif(i)).ok_or_else(|| missing(line, Col::Dif(i)))?;
            }
            Ok(PositionCols::TargetPlusDif(t, d))
        }
        _ => Ok(PositionCols::Measured(three(line, find, Col::Pos)?)),
    }
}

/// The three columns `col(0..3)`, or the first missing one named (line `line`).
fn three(
    line: usize,
    find: &dyn Fn(Col) -> Option<usize>,
    col: fn(usize) -> Col,
) -> Result<[usize; 3], CsvError> {
    let mut r = [0; 3];
    for (i, slot) in r.iter_mut().enumerate() {
        *slot = find(col(i)).ok_or_else(|| missing(line, col(i)))?;
    }
    Ok(r)
}

/// The standard-deviation triples (position, orientation): all three
/// columns of a triple or none; orientation ones need the position ones
/// and orientation columns.
#[allow(clippy::type_complexity)]
fn std_columns(
    line: usize,
    find: &dyn Fn(Col) -> Option<usize>,
    has_orientation: bool,
) -> Result<(Option<[usize; 3]>, Option<[usize; 3]>), CsvError> {
    let triple = |col: fn(usize) -> Col| -> Result<Option<[usize; 3]>, CsvError> {
        if (0..3).all(|i| find(col(i)).is_none()) {
            return Ok(None);
        }
        three(line, find, col).map(Some)
    };
    let std_pos = triple(Col::StdPos)?;
    let std_rot = triple(Col::StdRot)?;
    if std_rot.is_some() && std_pos.is_none() {
        return Err(missing(line, Col::StdPos(0)));
    }
    if std_rot.is_some() && !has_orientation {
        return Err(CsvError::OrientationColumns {
            line,
            detail: "std_rx, std_ry, std_rz given but no orientation columns".into(),
        });
    }
    Ok((std_pos, std_rot))
}

/// Reads the header line `fields` (at `line`) as `opts` says.
pub(super) fn parse_header(
    line: usize,
    fields: &[String],
    opts: &ReadOptions,
) -> Result<Header, CsvError> {
    let names: Vec<String> = fields.iter().map(|s| s.to_ascii_lowercase()).collect();
    let cols = columns(line, &names)?;
    let find = |c: Col| cols.iter().find(|(x, _)| *x == c).map(|(_, i)| *i);
    let external: Vec<(ExternalAxis, usize)> = ExternalAxis::ALL
        .into_iter()
        .filter_map(|a| find(Col::External(a.index())).map(|c| (a, c)))
        .collect();
    if let Some(&(axis, _)) = external.first() {
        if opts.metres || opts.radians {
            return Err(CsvError::ExternalUnits {
                line,
                column: axis.column().to_string(),
            });
        }
    }
    let joints = joint_columns(line, &cols, &find, !external.is_empty())?;
    let position = position_columns(line, &names, &find)?;
    let rot = orientation_columns(line, &find, opts.orientation)?;
    let (std_pos, std_rot) = std_columns(line, &find, rot.is_some())?;
    Ok(Header {
        line,
        joints,
        external,
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
