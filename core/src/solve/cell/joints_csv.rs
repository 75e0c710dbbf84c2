//! Joint readings as CSV, the input of `predict` (read through `csv_text`:
//! `,` / `;` / tab delimiter, decimal comma with `;` or tab, `#` comment
//! lines; columns by name, case-insensitive, any order):
//!
//! ```text
//! id,q1,q2,q3,q4,q5,q6
//! p1,10,-80,95,0,45,0
//! ```
//!
//! - `id` (optional; default: the 1-based row number);
//! - `q1..qN` (aliases `j1..jN`, `joint_1..joint_N`): controller joint
//!   readings in degrees, one column per joint of the robot, nothing missing;
//! - any other column (`x, y, z, rx, ry, rz, payload_kg`, … of a measurements
//!   file) is ignored, so a measurements file can be predicted as it is.
//!
//! Every error names its line (and column); a file with one is rejected
//! whole (a reading is never silently dropped): a row whose field count is
//! not the header's (every column after the place they part would be read
//! shifted), a value that is not a number, a reading beyond two turns
//! (`measure::bounds::JOINT_DEG`, the bound of the measurement files and
//! of a JSON prediction). Ids are read as `csv_write` wrote them.

use crate::csv_write::read_text;
use crate::measure::bounds::{within, JOINT_DEG};
use crate::measure::csv_text::{self, short_text, Dialect, FieldCount, TextError};
use crate::model::bounds::show;

/// One joint reading.
#[derive(Debug, Clone, PartialEq)]
pub struct JointReading {
    /// The row's `id`, or its 1-based row number when the column is absent or empty.
    pub id: String,
    /// 1-based line in the file (0 for readings that come from elsewhere).
    pub line: usize,
    /// Controller joint readings [deg].
    pub joints_deg: Vec<f64>,
}

/// Why a joints file cannot be read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum JointsCsvError {
    /// The text is not a table (`csv_text`).
    #[error(transparent)]
    Text(#[from] TextError),
    /// The text holds no header.
    #[error(
        "the joints file is empty: give a header `id,q1,...,qN` (N joints) and one row per reading"
    )]
    Empty,
    /// No column names a joint.
    #[error("no joint columns: the header needs q1..q{dof} (or j1..j{dof}), controller degrees")]
    NoJointColumns {
        /// Joints of the robot.
        dof: usize,
    },
    /// The joint columns are not `q1..q{dof}` (too few, too many, or a gap).
    #[error("{got} joint columns, the robot has {dof} joints: give q1..q{dof}")]
    JointColumns {
        /// Joint columns found.
        got: usize,
        /// Joints of the robot.
        dof: usize,
    },
    /// Two columns name one joint.
    #[error("joint column q{joint} appears twice")]
    Duplicate {
        /// The 1-based joint named twice.
        joint: usize,
    },
    /// A row whose field count is not the header's.
    #[error(transparent)]
    FieldCount(#[from] FieldCount),
    /// A joint value is not a finite number.
    #[error("line {line}, column {column}: `{value}` is not a number (controller degrees)")]
    NotNumber {
        /// 1-based line in the file.
        line: usize,
        /// The column's name as in the header.
        column: String,
        /// The value read (shortened).
        value: String,
    },
    /// A joint value is beyond ±`JOINT_DEG.max` (two turns).
    #[error("line {line}, column {column}: {} deg is beyond the bound ±{} deg (controller degrees; wrong units?)", show(*value), JOINT_DEG.max)]
    OutOfBounds {
        /// 1-based line in the file.
        line: usize,
        /// The column's name as in the header.
        column: String,
        /// The value read [deg].
        value: f64,
    },
    /// The header is followed by no reading.
    #[error("no readings after the header")]
    NoRows,
}

/// The 1-based joint a column name stands for.
fn joint_of(name: &str) -> Option<usize> {
    let n = name.trim().to_ascii_lowercase();
    let digits = n
        .strip_prefix("joint_")
        .or_else(|| n.strip_prefix('q'))
        .or_else(|| n.strip_prefix('j'))?;
    let digits = digits.strip_suffix("_deg").unwrap_or(digits);
    digits.parse::<usize>().ok().filter(|k| (1..=9).contains(k))
}

/// Reads a joints file for a robot of `dof` joints.
pub fn parse_joints_csv(
    text: &str,
    dialect: Dialect,
    dof: usize,
) -> Result<Vec<JointReading>, JointsCsvError> {
    let table = csv_text::read(text, dialect)?.ok_or(JointsCsvError::Empty)?;
    let mut cols: Vec<Option<usize>> = vec![None; dof.max(9)];
    let mut id_idx = None;
    for (i, h) in table.header.iter().enumerate() {
        if h.eq_ignore_ascii_case("id") {
            id_idx = Some(i);
        } else if let Some(k) = joint_of(h) {
            if k > cols.len() {
                cols.resize(k, None);
            }
            if cols[k - 1].replace(i).is_some() {
                return Err(JointsCsvError::Duplicate { joint: k });
            }
        }
    }
    let got = cols.iter().filter(|c| c.is_some()).count();
    if got == 0 {
        return Err(JointsCsvError::NoJointColumns { dof });
    }
    if got != dof || cols.iter().take(dof).any(Option::is_none) {
        return Err(JointsCsvError::JointColumns { got, dof });
    }
    let idx: Vec<usize> = cols.iter().take(dof).map(|c| c.unwrap_or(0)).collect();
    let mut out = Vec::with_capacity(table.records.len());
    for (n, rec) in table.records.iter().enumerate() {
        let line = rec.line;
        table.check_shape(rec)?;
        let joints_deg = idx
            .iter()
            .map(|&i| {
                let (v, column) = (&rec.fields[i], || table.header[i].clone());
                let x = table.number(v).filter(|x| x.is_finite()).ok_or_else(|| {
                    JointsCsvError::NotNumber {
                        line,
                        column: column(),
                        value: short_text(v),
                    }
                })?;
                if !within(x, &JOINT_DEG) {
                    return Err(JointsCsvError::OutOfBounds {
                        line,
                        column: column(),
                        value: x,
                    });
                }
                Ok(x)
            })
            .collect::<Result<Vec<f64>, _>>()?;
        let id = id_idx
            .and_then(|i| rec.fields.get(i))
            .filter(|s| !s.is_empty())
            .map(|s| read_text(s).into_owned())
            .unwrap_or_else(|| (n + 1).to_string());
        out.push(JointReading {
            id,
            line,
            joints_deg,
        });
    }
    if out.is_empty() {
        return Err(JointsCsvError::NoRows);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_named_columns_in_any_order_and_ignores_measurement_columns() {
        let text = "# readings\nx,q2,id,q1,y\n1,20.5,a,-10,2\n3,0,,1e1,4\n";
        let r = parse_joints_csv(text, Dialect::default(), 2).unwrap();
        assert_eq!(r[0].id, "a");
        assert_eq!(r[0].joints_deg, vec![-10.0, 20.5]);
        assert_eq!(r[1].id, "2");
        assert_eq!(r[1].joints_deg, vec![10.0, 0.0]);
        assert_eq!(r[1].line, 4);
    }

    #[test]
    fn decimal_commas_with_semicolons() {
        let r = parse_joints_csv("j1;j2\n1,5;-2,25\n", Dialect::default(), 2).unwrap();
        assert_eq!(r[0].joints_deg, vec![1.5, -2.25]);
    }

    #[test]
    fn bad_files_name_the_problem() {
        let d = Dialect::default();
        let e = parse_joints_csv("q1,q2,q3\n1,2,3\n", d, 6).unwrap_err();
        assert_eq!(e, JointsCsvError::JointColumns { got: 3, dof: 6 });
        assert!(e.to_string().contains("the robot has 6 joints"));
        let e = parse_joints_csv("x,y\n1,2\n", d, 2).unwrap_err();
        assert_eq!(e, JointsCsvError::NoJointColumns { dof: 2 });
        let e = parse_joints_csv("q1,q2\n1,2,3\n", d, 2).unwrap_err();
        assert!(e.to_string().starts_with("line 2: 3 fields"), "{e}");
        // A decimal comma in a comma-separated file, a row one field short:
        // refused naming line and column, never read shifted.
        let e = parse_joints_csv("id,q1,q2\na,10,20\nb,12,5,20\n", d, 2).unwrap_err();
        assert!(
            e.to_string().starts_with(
                "line 3: 4 fields, the header has 3: field 4 `20` is beyond the last column `q2`; a decimal comma"
            ),
            "{e}"
        );
        let e = parse_joints_csv("q1,q2,id\n10,20\n", d, 2).unwrap_err();
        assert_eq!(
            e.to_string(),
            "line 2: 2 fields, the header has 3: column 3 `id` has no field"
        );
        // Beyond two turns: wrong units, as in a measurement file.
        let e = parse_joints_csv("q1,q2\n1,2\n1,-720.5\n", d, 2).unwrap_err();
        assert_eq!(
            e.to_string(),
            "line 3, column q2: -720.5 deg is beyond the bound ±720 deg (controller degrees; wrong units?)"
        );
        let r = parse_joints_csv("id,q1,q2\n'=x,720,-720\n", d, 2).unwrap();
        assert_eq!(
            (r[0].id.as_str(), &r[0].joints_deg[..]),
            ("=x", &[720.0, -720.0][..])
        );
        let e = parse_joints_csv("q1,q2\n1,abc\n", d, 2).unwrap_err();
        assert!(e.to_string().contains("column q2: `abc`"), "{e}");
        let e = parse_joints_csv("q1,q3\n1,2\n", d, 2).unwrap_err();
        assert_eq!(e, JointsCsvError::JointColumns { got: 2, dof: 2 });
        assert_eq!(
            parse_joints_csv("q1,q2\n", d, 2).unwrap_err(),
            JointsCsvError::NoRows
        );
        assert_eq!(
            parse_joints_csv("q1,Q1\n1,2\n", d, 1).unwrap_err(),
            JointsCsvError::Duplicate { joint: 1 }
        );
    }
}
