//! Target files and solve results as CSV: the one parser of targets CSV for
//! `robocal solve` and the service's `text/csv` solve, and the one writer of
//! results as CSV.
//!
//! Targets (read through `csv_text`: `,` / `;` / tab delimiter, decimal comma
//! with `;` or tab, `#` comment lines, quoted fields; columns by name,
//! case-insensitive, any order):
//!
//! ```text
//! id,x,y,z,a,b,c
//! p1,1500,-3240,1200,180,0,180
//! ```
//!
//! - `id` (optional; default: the 1-based target number);
//! - `x, y, z`: TCP position [mm] (cell frame, or base frame when the caller
//!   says so);
//! - the orientation columns of exactly one convention (angles in degrees
//!   unless the column name says `_rad`): `qw,qx,qy,qz` (quaternion) |
//!   `q1,q2,q3,q4` (ABB, q1 scalar) | `ur_rx_rad,ur_ry_rad,ur_rz_rad` (UR
//!   rotation vector) | `a,b,c` (KUKA, `Rz(A)·Ry(B)·Rx(C)`) | `w,p,r` (Fanuc,
//!   `Rz(R)·Ry(P)·Rx(W)`) | `r11..r33` (row-major matrix). They may be left
//!   empty in a row (a position-only target).
//!
//! A malformed row fails alone (its result is `invalid_target`, naming the
//! line); header errors reject the file.
//!
//! Results ([`results_csv`]), one row per target in input order:
//! `id, status, reason, branch, j1_deg..jN_deg` (controller convention),
//! `false_x_mm, false_y_mm, false_z_mm` and `false_<column>` for each
//! orientation column of the output convention (the false target
//! `FK_nominal(q_cmd)` in the controller's base frame),
//! `position_residual_mm, orientation_residual_rad, iterations, jump_joint,
//! jump_deg, message, compensation, warning, expected_error_mm`
//! (`compensation`: `full`, `faded` or `none` of the joint maps' and the
//! compensator's correction at the solution, `warning` naming the joints
//! outside the trained range, `expected_error_mm` the compensator's expected
//! position error when it gives one). Fields that do not apply are empty.

use super::invalid::RowError;
use super::solver::{IkSolution, IkSolver, SolveOptions};
use super::targets::{TargetInput, TargetResult};
use crate::measure::csv_text::{self, Dialect, TextError};
use crate::model::orientation::{rotation_from, rotation_to, OrientationConvention};

/// One row of a targets file: the target, or why the row is invalid.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetRow {
    pub id: String,
    /// 1-based line in the file.
    pub line: usize,
    pub target: Result<TargetInput, RowError>,
}

/// A parsed targets file.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetsCsv {
    /// The file's orientation convention (`None`: position columns only).
    pub convention: Option<OrientationConvention>,
    pub rows: Vec<TargetRow>,
}

/// Why a targets file is rejected as a whole.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TargetsCsvError {
    #[error(transparent)]
    Text(#[from] TextError),
    #[error("the targets file has no header row")]
    NoHeader,
    #[error("line {line}: duplicate column `{column}`")]
    DuplicateColumn { line: usize, column: String },
    #[error("line {line}: unknown column `{column}`; expected id, x, y, z and the orientation columns of one convention: {}", CONVENTION_COLUMNS)]
    UnknownColumn { line: usize, column: String },
    #[error("line {line}: missing column `{column}`")]
    MissingColumn { line: usize, column: String },
    #[error("line {line}: orientation columns of several conventions ({names}); use one")]
    SeveralConventions { line: usize, names: String },
    #[error(
        "line {line}: {convention} orientation needs columns {columns}; `{missing}` is missing"
    )]
    IncompleteConvention {
        line: usize,
        convention: &'static str,
        columns: String,
        missing: String,
    },
}

/// The orientation columns of every convention, for messages.
pub const CONVENTION_COLUMNS: &str =
    "qw,qx,qy,qz | q1,q2,q3,q4 | a,b,c | w,p,r | ur_rx_rad,ur_ry_rad,ur_rz_rad | r11..r33";

/// Parses a targets file (see the module docs).
pub fn parse_targets_csv(text: &str, dialect: Dialect) -> Result<TargetsCsv, TargetsCsvError> {
    let table = csv_text::read(text, dialect)?.ok_or(TargetsCsvError::NoHeader)?;
    let hline = table.header_line;
    let cols: Vec<String> = table
        .header
        .iter()
        .map(|c| c.to_ascii_lowercase())
        .collect();
    let find = |name: &str| cols.iter().position(|c| c == name);
    for (i, c) in cols.iter().enumerate() {
        if cols[..i].contains(c) {
            return Err(TargetsCsvError::DuplicateColumn {
                line: hline,
                column: c.clone(),
            });
        }
    }
    let known = |c: &str| {
        matches!(c, "id" | "x" | "y" | "z")
            || OrientationConvention::ALL
                .iter()
                .any(|k| k.column_names().contains(&c))
    };
    if let Some(c) = cols.iter().find(|c| !known(c)) {
        return Err(TargetsCsvError::UnknownColumn {
            line: hline,
            column: c.clone(),
        });
    }
    let mut xyz = [0usize; 3];
    for (slot, n) in xyz.iter_mut().zip(["x", "y", "z"]) {
        *slot = find(n).ok_or_else(|| TargetsCsvError::MissingColumn {
            line: hline,
            column: n.to_string(),
        })?;
    }
    let present: Vec<OrientationConvention> = OrientationConvention::ALL
        .into_iter()
        .filter(|k| k.column_names().iter().any(|n| find(n).is_some()))
        .collect();
    let convention = match present.as_slice() {
        [] => None,
        [k] => Some(*k),
        _ => {
            return Err(TargetsCsvError::SeveralConventions {
                line: hline,
                names: present
                    .iter()
                    .map(|k| k.name())
                    .collect::<Vec<_>>()
                    .join(", "),
            })
        }
    };
    let ori_idx: Vec<usize> = match convention {
        None => Vec::new(),
        Some(k) => k
            .column_names()
            .iter()
            .map(|n| {
                find(n).ok_or_else(|| TargetsCsvError::IncompleteConvention {
                    line: hline,
                    convention: k.name(),
                    columns: k.column_names().join(", "),
                    missing: n.to_string(),
                })
            })
            .collect::<Result<_, _>>()?,
    };
    let id_idx = find("id");
    let rows = table
        .records
        .iter()
        .enumerate()
        .map(|(n, rec)| {
            let id = id_idx
                .and_then(|i| rec.fields.get(i))
                .filter(|s| !s.is_empty())
                .cloned()
                .unwrap_or_else(|| (n + 1).to_string());
            let cells: Vec<&str> = rec.fields.iter().map(String::as_str).collect();
            let row = Row {
                line: rec.line,
                cells: &cells,
            };
            let target = parse_row(&row, &cols, &xyz, &ori_idx, convention, &table).map(|mut t| {
                t.id = Some(id.clone());
                t
            });
            TargetRow {
                id,
                line: rec.line,
                target,
            }
        })
        .collect();
    Ok(TargetsCsv { convention, rows })
}

/// A record's fields and its 1-based line.
struct Row<'a> {
    line: usize,
    cells: &'a [&'a str],
}

fn parse_row(
    row: &Row,
    cols: &[String],
    xyz: &[usize; 3],
    ori_idx: &[usize],
    convention: Option<OrientationConvention>,
    table: &csv_text::Table,
) -> Result<TargetInput, RowError> {
    let (line, cells) = (row.line, row.cells);
    if cells.len() != cols.len() {
        return Err(RowError::FieldCount {
            line,
            got: cells.len(),
            expected: cols.len(),
        });
    }
    let num = |i: usize| -> Result<f64, RowError> {
        table.number(cells[i]).ok_or_else(|| RowError::NotNumber {
            line,
            column: cols[i].clone(),
            value: cells[i].to_string(),
        })
    };
    let xyz_mm = [num(xyz[0])?, num(xyz[1])?, num(xyz[2])?];
    let empty = ori_idx.iter().filter(|&&i| cells[i].is_empty()).count();
    let (convention, orientation) = if ori_idx.is_empty() || empty == ori_idx.len() {
        (None, Vec::new())
    } else if empty > 0 {
        return Err(RowError::PartialOrientation { line });
    } else {
        let values = ori_idx
            .iter()
            .map(|&i| num(i))
            .collect::<Result<Vec<f64>, RowError>>()?;
        (convention.map(|k| k.name().to_string()), values)
    };
    Ok(TargetInput {
        id: None,
        xyz_mm,
        convention,
        orientation,
    })
}

impl TargetsCsv {
    /// Solves every row in file order: valid rows by the solver (in parallel,
    /// or as a path), invalid rows as `invalid_target` results.
    pub fn solve(
        &self,
        solver: &IkSolver,
        options: &SolveOptions,
        path: bool,
    ) -> Vec<TargetResult> {
        let valid: Vec<TargetInput> = self
            .rows
            .iter()
            .filter_map(|r| r.target.as_ref().ok().cloned())
            .collect();
        let mut solved = if path {
            solver.solve_targets_path(&valid, options)
        } else {
            solver.solve_targets(&valid, options)
        }
        .into_iter();
        self.rows
            .iter()
            .map(|r| match &r.target {
                Ok(_) => solved.next().expect("one result per valid target"),
                Err(e) => TargetResult {
                    id: r.id.clone(),
                    solution: IkSolution::invalid(e.clone().into()),
                    joints_deg: None,
                    false_target: None,
                    jump: None,
                    compensation: None,
                },
            })
            .collect()
    }
}

/// The header of [`results_csv`] for `dof` joints and the output convention.
pub fn results_header(dof: usize, convention: OrientationConvention) -> Vec<String> {
    let mut h: Vec<String> = ["id", "status", "reason", "branch"]
        .map(String::from)
        .to_vec();
    h.extend((1..=dof).map(|k| format!("j{k}_deg")));
    h.extend(["false_x_mm", "false_y_mm", "false_z_mm"].map(String::from));
    h.extend(
        convention
            .column_names()
            .iter()
            .map(|c| format!("false_{c}")),
    );
    h.extend(
        [
            "position_residual_mm",
            "orientation_residual_rad",
            "iterations",
            "jump_joint",
            "jump_deg",
            "message",
            "compensation",
            "warning",
            "expected_error_mm",
        ]
        .map(String::from),
    );
    h
}

/// Solve results as CSV (see the module docs), false targets in `convention`
/// (converted when a result carries another one).
pub fn results_csv(
    results: &[TargetResult],
    dof: usize,
    convention: OrientationConvention,
) -> String {
    let mut w = csv::WriterBuilder::new()
        .terminator(csv::Terminator::Any(b'\n'))
        .from_writer(Vec::new());
    let header = results_header(dof, convention);
    let n_ori = convention.n_values();
    // Writing to a Vec cannot fail.
    let _ = w.write_record(&header);
    let finite = |v: f64| {
        if v.is_finite() {
            format!("{v:.6e}")
        } else {
            String::new()
        }
    };
    for r in results {
        let s = &r.solution;
        let mut row: Vec<String> = Vec::with_capacity(header.len());
        row.push(csv_text::safe_cell(&r.id).into_owned());
        row.push(r.status().to_string());
        row.push(
            s.reason
                .as_ref()
                .map(|x| x.code().to_string())
                .unwrap_or_default(),
        );
        row.push(s.branch.map(|b| b.to_string()).unwrap_or_default());
        match &r.joints_deg {
            Some(j) => row
                .extend((0..dof).map(|k| j.get(k).map(|v| format!("{v:.6}")).unwrap_or_default())),
            None => row.extend((0..dof).map(|_| String::new())),
        }
        match &r.false_target {
            Some(f) => {
                row.extend(f.xyz_mm.iter().map(|v| format!("{v:.4}")));
                let values = if f.convention == convention {
                    f.orientation.clone()
                } else {
                    rotation_from(f.convention, &f.orientation)
                        .map(|m| rotation_to(convention, &m))
                        .unwrap_or_default()
                };
                row.extend(
                    (0..n_ori)
                        .map(|k| values.get(k).map(|v| format!("{v:.9}")).unwrap_or_default()),
                );
            }
            None => row.extend((0..3 + n_ori).map(|_| String::new())),
        }
        row.push(finite(s.position_residual_mm));
        row.push(finite(s.orientation_residual_rad));
        row.push(s.iterations.to_string());
        match r.jump {
            Some(j) => {
                row.push(j.joint.to_string());
                row.push(format!("{:.3}", j.delta_deg));
            }
            None => row.extend([String::new(), String::new()]),
        }
        row.push(
            s.reason
                .as_ref()
                .map(|x| csv_text::safe_cell(&x.to_string()).into_owned())
                .unwrap_or_default(),
        );
        match &r.compensation {
            Some(c) => {
                row.push(c.label().to_string());
                row.push(
                    c.warning()
                        .map(|w| csv_text::safe_cell(&w).into_owned())
                        .unwrap_or_default(),
                );
                row.push(c.expected_error_mm.map(finite).unwrap_or_default());
            }
            None => row.extend([String::new(), String::new(), String::new()]),
        }
        let _ = w.write_record(&row);
    }
    let bytes = w.into_inner().unwrap_or_default();
    String::from_utf8(bytes).expect("CSV of UTF-8 fields is UTF-8")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<TargetsCsv, TargetsCsvError> {
        parse_targets_csv(text, Dialect::default())
    }

    #[test]
    fn conventions_and_row_errors() {
        let t = parse("# c\nid,x,y,z,qw,qx,qy,qz\np,1,2,3,1,0,0,0\nq,1,2,x,1,0,0,0\n").unwrap();
        assert_eq!(t.convention, Some(OrientationConvention::Quaternion));
        assert_eq!(t.rows.len(), 2);
        assert!(t.rows[0].target.is_ok());
        assert_eq!(t.rows[1].line, 4);
        let e = t.rows[1].target.as_ref().unwrap_err();
        assert_eq!(
            *e,
            RowError::NotNumber {
                line: 4,
                column: "z".into(),
                value: "x".into()
            }
        );
        assert_eq!(e.to_string(), "line 4: column `z`: `x` is not a number");
        let t = parse("x,y,z,a,b,c\n1,2\n1,2,3,0,,0\n").unwrap();
        let errors: Vec<String> = t
            .rows
            .iter()
            .map(|r| r.target.as_ref().unwrap_err().to_string())
            .collect();
        assert_eq!(
            errors,
            [
                "line 2: 2 fields, the header has 6",
                "line 3: some orientation fields are empty"
            ]
        );
        let t = parse("x,y,z,W,P,R\n1,2,3,0,0,0\n").unwrap();
        assert_eq!(t.convention, Some(OrientationConvention::FanucWpr));
        assert_eq!(t.rows[0].id, "1");
        assert!(matches!(
            parse("x,y,z,a,b,c,w\n"),
            Err(TargetsCsvError::SeveralConventions { .. })
        ));
        assert!(matches!(
            parse("x,y,z,a,b\n"),
            Err(TargetsCsvError::IncompleteConvention { .. })
        ));
        assert!(matches!(
            parse("x,y,z,rx\n"),
            Err(TargetsCsvError::UnknownColumn { .. })
        ));
        assert!(matches!(
            parse("x,y\n"),
            Err(TargetsCsvError::MissingColumn { .. })
        ));
        assert_eq!(parse("# only a comment\n"), Err(TargetsCsvError::NoHeader));
        assert_eq!(parse("x,y,z\n1,2,3\n").unwrap().convention, None);
    }

    #[test]
    fn semicolons_with_decimal_commas_read_like_the_comma_file() {
        let a = parse("id;x;y;z;a;b;c\np1;1500,5;-3240;1200,25;180;0;179,5\n").unwrap();
        let b = parse("id,x,y,z,a,b,c\np1,1500.5,-3240,1200.25,180,0,179.5\n").unwrap();
        assert_eq!(a, b);
        let t = a.rows[0].target.as_ref().unwrap();
        assert_eq!(t.xyz_mm, [1500.5, -3240.0, 1200.25]);
        assert_eq!(t.orientation, [180.0, 0.0, 179.5]);
    }

    #[test]
    fn results_header_names_units_and_the_convention() {
        let h = results_header(6, OrientationConvention::KukaAbc);
        assert_eq!(h[4], "j1_deg");
        assert_eq!(h[9], "j6_deg");
        assert_eq!(
            &h[10..16],
            [
                "false_x_mm",
                "false_y_mm",
                "false_z_mm",
                "false_a",
                "false_b",
                "false_c"
            ]
        );
        assert_eq!(
            &h[h.len() - 4..],
            ["message", "compensation", "warning", "expected_error_mm"]
        );
    }
}
