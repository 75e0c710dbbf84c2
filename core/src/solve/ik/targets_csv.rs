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
//! A malformed row (a field count other than the header's, a value that is
//! not a number, a position beyond 100 m, some orientation values empty)
//! fails alone: its result is `invalid_target`, naming the line and the
//! column. Header errors reject the file. Ids are read as `csv_write` wrote
//! them (`read_text`).
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
use super::targets::{SolveMode, TargetInput, TargetResult};
use crate::csv_write::{self, push_row, read_text, Cell};
use crate::measure::bounds::{within, POSITION_MM};
use crate::measure::csv_text::{self, Dialect, Record, TextError};
use crate::model::orientation::{rotation_from, rotation_to, OrientationConvention};

/// One row of a targets file: the target, or why the row is invalid.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetRow {
    /// The row's `id`, or its 1-based target number when the column is absent or empty.
    pub id: String,
    /// 1-based line in the file.
    pub line: usize,
    /// The target, or why the row is not one (the row fails alone).
    pub target: Result<TargetInput, RowError>,
}

/// A parsed targets file.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetsCsv {
    /// The file's orientation convention (`None`: position columns only).
    pub convention: Option<OrientationConvention>,
    /// The rows after the header, in file order.
    pub rows: Vec<TargetRow>,
}

/// Why a targets file is rejected as a whole.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TargetsCsvError {
    /// The text is not a table (`csv_text`).
    #[error(transparent)]
    Text(#[from] TextError),
    /// The text holds no header.
    #[error("the targets file has no header row")]
    NoHeader,
    /// A column is named twice.
    #[error("line {line}: duplicate column `{column}`")]
    DuplicateColumn {
        /// 1-based line of the header.
        line: usize,
        /// The column's name.
        column: String,
    },
    /// A column is neither `id`, a position nor an orientation column.
    #[error("line {line}: unknown column `{column}`; expected id, x, y, z and the orientation columns of one convention: {}", CONVENTION_COLUMNS)]
    UnknownColumn {
        /// 1-based line of the header.
        line: usize,
        /// The column's name.
        column: String,
    },
    /// One of `x`, `y`, `z` is missing.
    #[error("line {line}: missing column `{column}`")]
    MissingColumn {
        /// 1-based line of the header.
        line: usize,
        /// The missing column's name.
        column: String,
    },
    /// The orientation columns of more than one convention are present.
    #[error("line {line}: orientation columns of several conventions ({names}); use one")]
    SeveralConventions {
        /// 1-based line of the header.
        line: usize,
        /// The conventions present, comma-separated.
        names: String,
    },
    /// A convention's orientation columns are present but not all of them.
    #[error(
        "line {line}: {convention} orientation needs columns {columns}; `{missing}` is missing"
    )]
    IncompleteConvention {
        /// 1-based line of the header.
        line: usize,
        /// The convention's name.
        convention: &'static str,
        /// Its columns, comma-separated.
        columns: String,
        /// The first missing column.
        missing: String,
    },
}

/// The orientation columns of every convention, for messages.
pub const CONVENTION_COLUMNS: &str =
    "qw,qx,qy,qz | q1,q2,q3,q4 | a,b,c | w,p,r | ur_rx_rad,ur_ry_rad,ur_rz_rad | r11..r33";

/// Parses a targets file (see the module docs).
pub fn parse_targets_csv(text: &str, dialect: Dialect) -> Result<TargetsCsv, TargetsCsvError> {
    parse_targets_csv_beside(text, dialect, &[])
}

/// Parses a targets file whose columns named in `beside` (lower case) are
/// read by the caller (a track value per row, `solve::external::targets`):
/// they are passed over here instead of refused as unknown.
pub fn parse_targets_csv_beside(
    text: &str,
    dialect: Dialect,
    beside: &[&str],
) -> Result<TargetsCsv, TargetsCsvError> {
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
            || beside.contains(&c)
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
                .map(|s| read_text(s).into_owned())
                .unwrap_or_else(|| (n + 1).to_string());
            let columns = Columns {
                names: &cols,
                xyz: &xyz,
                orientation: &ori_idx,
                convention,
            };
            let target = parse_row(rec, &columns, &table).map(|mut t| {
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

/// Where a targets file holds what (lower-cased header names, indices).
struct Columns<'a> {
    names: &'a [String],
    xyz: &'a [usize; 3],
    orientation: &'a [usize],
    convention: Option<OrientationConvention>,
}

fn parse_row(
    rec: &Record,
    cols: &Columns,
    table: &csv_text::Table,
) -> Result<TargetInput, RowError> {
    table.check_shape(rec)?;
    let (line, cells) = (rec.line, &rec.fields);
    let num = |i: usize| -> Result<f64, RowError> {
        table.number(&cells[i]).ok_or_else(|| RowError::NotNumber {
            line,
            column: cols.names[i].clone(),
            value: cells[i].to_string(),
        })
    };
    let mut xyz_mm = [0.0; 3];
    for (v, &i) in xyz_mm.iter_mut().zip(cols.xyz) {
        *v = num(i)?;
        if !within(*v, &POSITION_MM) {
            return Err(RowError::Position {
                line,
                column: cols.names[i].clone(),
                value: *v,
            });
        }
    }
    let empty: Vec<&str> = cols
        .orientation
        .iter()
        .filter(|&&i| cells[i].is_empty())
        .map(|&i| cols.names[i].as_str())
        .collect();
    let (convention, orientation) = if empty.len() == cols.orientation.len() {
        (None, Vec::new())
    } else if !empty.is_empty() {
        return Err(RowError::PartialOrientation {
            line,
            columns: empty.join(", "),
        });
    } else {
        let values = cols
            .orientation
            .iter()
            .map(|&i| num(i))
            .collect::<Result<Vec<f64>, RowError>>()?;
        (cols.convention.map(|k| k.name().to_string()), values)
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
        let mode = if path {
            SolveMode::Path
        } else {
            SolveMode::Parallel
        };
        let mut solved = solver.solve_targets(&valid, mode, options).into_iter();
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
/// (converted when a result carries another one); numbers as numbers, texts
/// (ids, messages, warnings) as `csv_write` writes every text.
pub fn results_csv(
    results: &[TargetResult],
    dof: usize,
    convention: OrientationConvention,
) -> String {
    let header = results_header(dof, convention);
    let n_ori = convention.n_values();
    let mut out = String::new();
    csv_write::push_header(&mut out, &header);
    let mut row: Vec<Cell> = Vec::with_capacity(header.len());
    for r in results {
        let s = &r.solution;
        row.clear();
        row.push(Cell::text(&r.id));
        row.push(Cell::text(r.status()));
        row.push(Cell::text(
            s.reason.as_ref().map(|x| x.code()).unwrap_or_default(),
        ));
        row.push(
            s.branch
                .map_or_else(Cell::empty, |b| Cell::text(b.to_string())),
        );
        let joints = r.joints_deg.as_deref().unwrap_or_default();
        row.extend((0..dof).map(|k| {
            joints
                .get(k)
                .map_or_else(Cell::empty, |v| Cell::fixed(*v, 6))
        }));
        match &r.false_target {
            Some(f) => {
                row.extend(f.xyz_mm.iter().map(|v| Cell::fixed(*v, 4)));
                let values = if f.convention == convention {
                    f.orientation.clone()
                } else {
                    rotation_from(f.convention, &f.orientation)
                        .map(|m| rotation_to(convention, &m))
                        .unwrap_or_default()
                };
                row.extend((0..n_ori).map(|k| {
                    values
                        .get(k)
                        .map_or_else(Cell::empty, |v| Cell::fixed(*v, 9))
                }));
            }
            None => row.extend((0..3 + n_ori).map(|_| Cell::empty())),
        }
        row.push(Cell::sci(s.position_residual_mm, 6));
        row.push(Cell::sci(s.orientation_residual_rad, 6));
        row.push(Cell::int(s.iterations));
        match r.jump {
            Some(j) => {
                row.push(Cell::int(j.joint));
                row.push(Cell::fixed(j.delta_deg, 3));
            }
            None => row.extend([Cell::empty(), Cell::empty()]),
        }
        row.push(Cell::text(
            s.reason.as_ref().map(|x| x.to_string()).unwrap_or_default(),
        ));
        match &r.compensation {
            Some(c) => {
                row.push(Cell::text(c.label()));
                row.push(Cell::text(c.warning().unwrap_or_default()));
                row.push(
                    c.expected_error_mm
                        .map_or_else(Cell::empty, |v| Cell::sci(v, 6)),
                );
            }
            None => row.extend([Cell::empty(), Cell::empty(), Cell::empty()]),
        }
        push_row(&mut out, &row);
    }
    out
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
                "line 2: 2 fields, the header has 6: column 3 `z` has no field",
                "line 3: orientation column(s) b empty; give every orientation value or none"
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

    /// A row one field longer than the header (a decimal comma in a
    /// comma-separated file) and a position beyond 100 m fail alone, naming
    /// line and column; the other rows are read, ids as they were written.
    #[test]
    fn misaligned_rows_and_positions_beyond_the_bound_fail_alone() {
        let t = parse("id,x,y,z,a,b,c\n'=p1,1500,0,1200,180,0,180\np2,1500,0,1200,5,180,0,180\np3,1e6,0,1200,180,0,180\n")
            .unwrap();
        assert_eq!(t.rows[0].id, "=p1");
        assert!(t.rows[0].target.is_ok());
        let errors: Vec<String> = t.rows[1..]
            .iter()
            .map(|r| r.target.as_ref().unwrap_err().to_string())
            .collect();
        assert_eq!(errors[0], "line 3: 8 fields, the header has 7: field 8 `180` is beyond the last column `c`; a decimal comma splits a number in two in a comma-separated file (write `8.85`, quote `\"8,85\"`, or separate the fields with `;`)");
        assert_eq!(
            errors[1],
            "line 4: column `x`: 1e6 mm is beyond the bound ±100000 mm"
        );
        // The JSON form has the same bound: the target fails alone.
        let far = TargetInput {
            xyz_mm: [0.0, -100_000.5, 0.0],
            ..TargetInput::default()
        };
        assert_eq!(
            far.to_goal().unwrap_err().to_string(),
            "position y is -100000.5 mm; must be finite and within ±100000 mm"
        );
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
