//! The ISO 9283 files: the plan CSV (what `robocal iso9283 plan` writes and
//! `robocal iso9283` reads back for the commands) and the measured cycles.
//!
//! Plan: `pose,x_mm,y_mm,z_mm,rx_deg,ry_deg,rz_deg,j1_deg,…` — one row per
//! pose P1 … P5: the commanded position (measurement frame, mm), orientation
//! (`R = Rz(rz)·Ry(ry)·Rx(rx)`, deg) and the joint command (controller
//! convention, deg).
//!
//! Cycles: `pose,cycle,x_mm,y_mm,z_mm` and optionally `rx_deg,ry_deg,rz_deg`
//! — one row per attained pose, in the same frame; `pose` is `P1` … or `1` …,
//! `cycle` a positive integer (distances pair the same cycle of two poses).
//! Columns are found by name, in any order; the delimiter and decimal
//! separator follow robocal's CSV rules (`csv_text`).
//!
//! Refused, naming line and column: a row whose field count is not the
//! header's (a decimal comma in a comma-separated file, a missing field:
//! every column after it would be read shifted), one or two of the three
//! orientation columns, and values beyond the bounds of the JSON form
//! (`outcome`: positions within ±[`XYZ_MAX_MM`], angles within
//! ±[`ABC_MAX_DEG`], cycles 1 to [`CYCLES_MAX`]).

use super::cube::CubePlan;
use super::figures::PoseCycles;
use super::outcome::{CommandedPose, CycleReading, PoseData, ABC_MAX_DEG, CYCLES_MAX, XYZ_MAX_MM};
use super::Iso9283Error;
use crate::csv_write::{push_header, push_row, read_text, Cell};
use crate::measure::csv_text::{read, short_text, Dialect, Record, Table};
use crate::model::bounds::show;

/// A commanded pose read from a plan CSV.
#[derive(Debug, Clone, PartialEq)]
pub struct Commanded {
    /// The pose's name (`P1` … `P5`).
    pub name: String,
    /// Commanded position, measurement (cell) frame [mm].
    pub xyz_mm: [f64; 3],
    /// Commanded `a, b, c` (`R = Rz(c)·Ry(b)·Rx(a)`) [deg], when the plan gives them.
    pub abc_deg: Option<[f64; 3]>,
}

/// The plan as CSV text.
pub fn plan_csv(plan: &CubePlan) -> String {
    let dof = plan.poses.first().map_or(0, |p| p.joints_deg.len());
    let mut header: Vec<String> = ["pose", "x_mm", "y_mm", "z_mm", "rx_deg", "ry_deg", "rz_deg"]
        .map(String::from)
        .to_vec();
    header.extend((1..=dof).map(|j| format!("j{j}_deg")));
    let mut s = String::new();
    push_header(&mut s, &header);
    for p in &plan.poses {
        let mut row = vec![Cell::text(&p.name)];
        row.extend(
            p.commanded_mm
                .iter()
                .chain(&p.commanded_abc_deg)
                .chain(&p.joints_deg)
                .map(|v| Cell::fixed(*v, 6)),
        );
        push_row(&mut s, &row);
    }
    s
}

/// `P3` from `P3`, `p3` or `3`.
fn pose_name(field: &str) -> Option<String> {
    let digits = field.trim().trim_start_matches(['P', 'p']);
    let n: u32 = digits.parse().ok()?;
    (n >= 1).then(|| format!("P{n}"))
}

/// The text as a table, every row of the header's width.
fn table(text: &str, what: &str) -> Result<Table, Iso9283Error> {
    let t = read(text, Dialect::default())
        .map_err(|e| Iso9283Error::Csv {
            line: 0,
            message: format!("{what}: {e}"),
        })?
        .ok_or_else(|| Iso9283Error::InvalidInput(format!("the {what} is empty")))?;
    t.check_shapes()?;
    Ok(t)
}

fn column(t: &Table, name: &str, what: &str) -> Result<usize, Iso9283Error> {
    t.header
        .iter()
        .position(|h| h.eq_ignore_ascii_case(name))
        .ok_or_else(|| Iso9283Error::Csv {
            line: t.header_line,
            message: format!(
                "the {what} has no `{name}` column (header: {})",
                short_text(&t.header.join(","))
            ),
        })
}

/// The orientation columns: all three or none; one or two of them are an
/// error naming those missing.
fn optional_columns(
    t: &Table,
    names: [&str; 3],
    what: &str,
) -> Result<Option<[usize; 3]>, Iso9283Error> {
    let found = names.map(|n| t.header.iter().position(|h| h.eq_ignore_ascii_case(n)));
    match found {
        [Some(a), Some(b), Some(c)] => Ok(Some([a, b, c])),
        [None, None, None] => Ok(None),
        _ => {
            let missing: Vec<String> = names
                .iter()
                .zip(found)
                .filter(|(_, f)| f.is_none())
                .map(|(n, _)| format!("`{n}`"))
                .collect();
            Err(Iso9283Error::Csv {
                line: t.header_line,
                message: format!(
                    "the {what} has some orientation columns but not {}: give {} all three or none",
                    missing.join(", "),
                    names.join(", ")
                ),
            })
        }
    }
}

/// A number of column `col` within ±`max` `unit` (the JSON form's bound).
fn number(t: &Table, r: &Record, col: usize, max: f64, unit: &str) -> Result<f64, Iso9283Error> {
    let f = r.fields[col].as_str();
    let at = |message: String| Iso9283Error::Csv {
        line: r.line,
        message: format!("column `{}`: {message}", t.header[col]),
    };
    let v = t
        .number(f)
        .filter(|v| v.is_finite())
        .ok_or_else(|| at(format!("`{}` is not a finite number", short_text(f))))?;
    if v.abs() > max {
        return Err(at(format!(
            "{} {unit} is beyond the bound ±{max} {unit}",
            show(v)
        )));
    }
    Ok(v)
}

fn positions(t: &Table, r: &Record, cols: [usize; 3]) -> Result<[f64; 3], Iso9283Error> {
    Ok([
        number(t, r, cols[0], XYZ_MAX_MM, "mm")?,
        number(t, r, cols[1], XYZ_MAX_MM, "mm")?,
        number(t, r, cols[2], XYZ_MAX_MM, "mm")?,
    ])
}

fn angles(t: &Table, r: &Record, cols: [usize; 3]) -> Result<[f64; 3], Iso9283Error> {
    Ok([
        number(t, r, cols[0], ABC_MAX_DEG, "deg")?,
        number(t, r, cols[1], ABC_MAX_DEG, "deg")?,
        number(t, r, cols[2], ABC_MAX_DEG, "deg")?,
    ])
}

fn pose_of(t: &Table, r: &Record, col: usize) -> Result<String, Iso9283Error> {
    let f = read_text(&r.fields[col]);
    pose_name(&f).ok_or_else(|| Iso9283Error::Csv {
        line: r.line,
        message: format!(
            "column `{}`: pose `{}` is not P1, P2, … or 1, 2, …",
            t.header[col],
            short_text(&f)
        ),
    })
}

/// The cycle number of column `col`: an integer from 1 to [`CYCLES_MAX`].
fn cycle_of(t: &Table, r: &Record, col: usize) -> Result<u32, Iso9283Error> {
    let f = r.fields[col].trim();
    f.parse::<u32>()
        .ok()
        .filter(|c| (1..=CYCLES_MAX as u32).contains(c))
        .ok_or_else(|| Iso9283Error::Csv {
            line: r.line,
            message: format!(
                "column `{}`: cycle `{}` is not an integer from 1 to {CYCLES_MAX}",
                t.header[col],
                short_text(f)
            ),
        })
}

/// The commanded poses of a plan CSV, in its order.
pub fn read_plan_csv(text: &str) -> Result<Vec<Commanded>, Iso9283Error> {
    let t = table(text, "plan CSV")?;
    let pose = column(&t, "pose", "plan CSV")?;
    let xyz = [
        column(&t, "x_mm", "plan CSV")?,
        column(&t, "y_mm", "plan CSV")?,
        column(&t, "z_mm", "plan CSV")?,
    ];
    let abc = optional_columns(&t, ["rx_deg", "ry_deg", "rz_deg"], "plan CSV")?;
    let mut out: Vec<Commanded> = Vec::new();
    for r in &t.records {
        let name = pose_of(&t, r, pose)?;
        if out.iter().any(|c| c.name == name) {
            return Err(Iso9283Error::Csv {
                line: r.line,
                message: format!("pose {name} appears twice in the plan"),
            });
        }
        out.push(Commanded {
            name,
            xyz_mm: positions(&t, r, xyz)?,
            abc_deg: abc.map(|c| angles(&t, r, c)).transpose()?,
        });
    }
    if out.is_empty() {
        return Err(Iso9283Error::InvalidInput(
            "the plan CSV has no poses".into(),
        ));
    }
    Ok(out)
}

/// The measured cycles joined to their commands, one entry per commanded pose.
pub fn read_cycles_csv(text: &str, plan: &[Commanded]) -> Result<Vec<PoseCycles>, Iso9283Error> {
    let t = table(text, "cycles CSV")?;
    let pose = column(&t, "pose", "cycles CSV")?;
    let cycle = column(&t, "cycle", "cycles CSV")?;
    let xyz = [
        column(&t, "x_mm", "cycles CSV")?,
        column(&t, "y_mm", "cycles CSV")?,
        column(&t, "z_mm", "cycles CSV")?,
    ];
    let abc = optional_columns(&t, ["rx_deg", "ry_deg", "rz_deg"], "cycles CSV")?;
    let mut out: Vec<PoseCycles> = plan
        .iter()
        .map(|c| PoseCycles {
            name: c.name.clone(),
            commanded_mm: c.xyz_mm,
            commanded_abc_deg: c.abc_deg,
            cycles: Vec::new(),
            attained_mm: Vec::new(),
            attained_abc_deg: abc.map(|_| Vec::new()),
        })
        .collect();
    for r in &t.records {
        let name = pose_of(&t, r, pose)?;
        let Some(p) = out.iter_mut().find(|p| p.name == name) else {
            return Err(Iso9283Error::Csv {
                line: r.line,
                message: format!("pose {name} is not in the plan"),
            });
        };
        let c = cycle_of(&t, r, cycle)?;
        if p.cycles.contains(&c) {
            return Err(Iso9283Error::Csv {
                line: r.line,
                message: format!("pose {name} has cycle {c} twice"),
            });
        }
        p.cycles.push(c);
        p.attained_mm.push(positions(&t, r, xyz)?);
        if let (Some(cols), Some(v)) = (abc, p.attained_abc_deg.as_mut()) {
            v.push(angles(&t, r, cols)?);
        }
    }
    if let Some(p) = out.iter().find(|p| p.attained_mm.is_empty()) {
        return Err(Iso9283Error::InvalidInput(format!(
            "pose {} of the plan has no measured cycles",
            p.name
        )));
    }
    Ok(out)
}

/// The poses of a plan CSV and its cycles CSV as [`super::assess`] takes
/// them: every commanded pose with its measured cycles.
pub fn read_pose_data(plan_text: &str, cycles_text: &str) -> Result<Vec<PoseData>, Iso9283Error> {
    let commanded = read_plan_csv(plan_text)?;
    let cycles = read_cycles_csv(cycles_text, &commanded)?;
    Ok(pose_data(&commanded, cycles))
}

/// [`read_pose_data`] of texts already read.
pub fn pose_data(commanded: &[Commanded], cycles: Vec<PoseCycles>) -> Vec<PoseData> {
    commanded
        .iter()
        .zip(cycles)
        .map(|(c, p)| {
            let abc = p.attained_abc_deg.as_ref();
            PoseData {
                name: c.name.clone(),
                commanded: Some(CommandedPose {
                    xyz_mm: c.xyz_mm,
                    abc_deg: c.abc_deg,
                }),
                measured: Some(
                    p.cycles
                        .iter()
                        .zip(&p.attained_mm)
                        .enumerate()
                        .map(|(k, (cycle, xyz))| CycleReading {
                            cycle: *cycle,
                            xyz_mm: *xyz,
                            abc_deg: abc.map(|a| a[k]),
                        })
                        .collect(),
                ),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cycles_join_to_the_plan_by_pose_name() {
        let plan = read_plan_csv(
            "pose,x_mm,y_mm,z_mm,rx_deg,ry_deg,rz_deg,j1_deg\nP1,1,2,3,180,0,0,10\nP2,4,5,6,180,0,0,11\n",
        )
        .unwrap();
        assert_eq!(plan[1].xyz_mm, [4.0, 5.0, 6.0]);
        assert_eq!(plan[0].abc_deg, Some([180.0, 0.0, 0.0]));
        let cycles = "# measured\ncycle;pose;x_mm;y_mm;z_mm\n1;1;1,5;2;3\n1;P2;4;5;6\n2;p1;1;2;3\n2;2;4;5;6\n";
        let c = read_cycles_csv(cycles, &plan).unwrap();
        assert_eq!(c[0].attained_mm, vec![[1.5, 2.0, 3.0], [1.0, 2.0, 3.0]]);
        assert_eq!(c[1].cycles, vec![1, 2]);
        assert!(c[0].attained_abc_deg.is_none());
    }

    /// The files: one attained position written with a decimal comma
    /// in a comma-separated file (read shifted, it gave AP 194 mm instead of
    /// 8.85), a plan row missing a field; refused naming line and column.
    #[test]
    fn rows_of_another_width_are_refused_naming_line_and_column() {
        let plan_text = "pose,x_mm,y_mm,z_mm,rx_deg,ry_deg,rz_deg\nP1,600,0,400,180,0,0\nP2,360,-240,160,180,0,0\n";
        let plan = read_plan_csv(plan_text).unwrap();
        let cycles = "pose,cycle,x_mm,y_mm,z_mm\nP1,1,600,0,400\nP2,1,360,-240,160\n\
                      P1,2,608,85,0,400\nP2,2,360,-240,160\n";
        let e = read_cycles_csv(cycles, &plan).unwrap_err().to_string();
        assert!(
            e.starts_with(
                "line 4: 6 fields, the header has 5: field 6 `400` is beyond the last column `z_mm`; \
                 a decimal comma splits a number in two"
            ),
            "{e}"
        );
        // A `;`-separated file reads the same decimal comma as a number.
        let semi = cycles.replace(',', ";").replace("608;85", "608,85");
        let c = read_cycles_csv(&semi, &plan).unwrap();
        assert_eq!(c[0].attained_mm[1], [608.85, 0.0, 400.0]);
        // A plan row one field short: the orientation would shift left.
        let short =
            "pose,x_mm,y_mm,z_mm,rx_deg,ry_deg,rz_deg\nP1,600,0,400,180,0,0\nP2,360,-240,180,0,0\n";
        assert_eq!(
            read_plan_csv(short).unwrap_err().to_string(),
            "line 3: 6 fields, the header has 7: column 7 `rz_deg` has no field"
        );
    }

    #[test]
    fn partial_orientation_columns_and_values_beyond_the_json_bounds_are_refused() {
        let e = read_plan_csv("pose,x_mm,y_mm,z_mm,rx_deg,rz_deg\nP1,600,0,400,180,0\n");
        assert_eq!(
            e.unwrap_err().to_string(),
            "line 1: the plan CSV has some orientation columns but not `ry_deg`: give rx_deg, ry_deg, rz_deg all three or none"
        );
        let plan = read_plan_csv("pose,x_mm,y_mm,z_mm\nP1,600,0,400\n").unwrap();
        let head = "pose,cycle,x_mm,y_mm,z_mm,rx_deg,ry_deg,rz_deg\n";
        for (row, want) in [
            (
                "P1,1001,600,0,400,180,0,0",
                "line 2: column `cycle`: cycle `1001` is not an integer from 1 to 1000",
            ),
            (
                "P1,1,600,1e6,400,180,0,0",
                "line 2: column `y_mm`: 1e6 mm is beyond the bound ±100000 mm",
            ),
            (
                "P1,1,600,0,400,180,0,361",
                "line 2: column `rz_deg`: 361 deg is beyond the bound ±360 deg",
            ),
            (
                "P1,1,600,0,400,180,,0",
                "line 2: column `ry_deg`: `` is not a finite number",
            ),
        ] {
            let e = read_cycles_csv(&format!("{head}{row}\n"), &plan).unwrap_err();
            assert_eq!(e.to_string(), want);
        }
        // At the bounds: read.
        let c = read_cycles_csv(
            &format!("{head}P1,1000,100000,0,-100000,360,-360,0\n"),
            &plan,
        )
        .unwrap();
        assert_eq!(c[0].cycles, [1000]);
    }

    #[test]
    fn bad_rows_name_their_line() {
        let plan = read_plan_csv("pose,x_mm,y_mm,z_mm\nP1,0,0,0\n").unwrap();
        let e = read_cycles_csv("pose,cycle,x_mm,y_mm,z_mm\nP1,1,0,0,0\nP7,1,0,0,0\n", &plan);
        assert_eq!(
            e.unwrap_err().to_string(),
            "line 3: pose P7 is not in the plan"
        );
        let e = read_cycles_csv("pose,cycle,x_mm,y_mm,z_mm\nP1,0,0,0,0\n", &plan);
        assert_eq!(
            e.unwrap_err().to_string(),
            "line 2: column `cycle`: cycle `0` is not an integer from 1 to 1000"
        );
        let e = read_cycles_csv("pose,cycle,x_mm,y_mm\nP1,1,0,0\n", &plan);
        assert!(e.unwrap_err().to_string().contains("no `z_mm` column"));
    }
}
