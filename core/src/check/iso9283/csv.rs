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

use super::cube::CubePlan;
use super::figures::PoseCycles;
use super::Iso9283Error;
use crate::measure::csv_text::{read, short_text, Dialect, Table};
use std::fmt::Write as _;

/// A commanded pose read from a plan CSV.
#[derive(Debug, Clone, PartialEq)]
pub struct Commanded {
    pub name: String,
    pub xyz_mm: [f64; 3],
    pub abc_deg: Option<[f64; 3]>,
}

/// The plan as CSV text.
pub fn plan_csv(plan: &CubePlan) -> String {
    let dof = plan.poses.first().map_or(0, |p| p.joints_deg.len());
    let mut s = String::from("pose,x_mm,y_mm,z_mm,rx_deg,ry_deg,rz_deg");
    for j in 1..=dof {
        let _ = write!(s, ",j{j}_deg");
    }
    s.push('\n');
    for p in &plan.poses {
        let _ = write!(s, "{}", p.name);
        for v in p.commanded_mm.iter().chain(&p.commanded_abc_deg) {
            let _ = write!(s, ",{v:.6}");
        }
        for v in &p.joints_deg {
            let _ = write!(s, ",{v:.6}");
        }
        s.push('\n');
    }
    s
}

/// `P3` from `P3`, `p3` or `3`.
fn pose_name(field: &str) -> Option<String> {
    let digits = field.trim().trim_start_matches(['P', 'p']);
    let n: u32 = digits.parse().ok()?;
    (n >= 1).then(|| format!("P{n}"))
}

fn table(text: &str, what: &str) -> Result<Table, Iso9283Error> {
    read(text, Dialect::default())
        .map_err(|e| Iso9283Error::Csv {
            line: 0,
            message: format!("{what}: {e}"),
        })?
        .ok_or_else(|| Iso9283Error::InvalidInput(format!("the {what} is empty")))
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

fn optional_columns(t: &Table, names: [&str; 3]) -> Option<[usize; 3]> {
    let found: Vec<usize> = names
        .iter()
        .filter_map(|n| t.header.iter().position(|h| h.eq_ignore_ascii_case(n)))
        .collect();
    (found.len() == 3).then(|| [found[0], found[1], found[2]])
}

fn number(t: &Table, fields: &[String], line: usize, col: usize) -> Result<f64, Iso9283Error> {
    let f = fields.get(col).map(String::as_str).unwrap_or("");
    t.number(f)
        .filter(|v| v.is_finite())
        .ok_or_else(|| Iso9283Error::Csv {
            line,
            message: format!(
                "`{}` in column `{}` is not a finite number",
                short_text(f),
                t.header[col]
            ),
        })
}

fn three(
    t: &Table,
    r: &crate::measure::csv_text::Record,
    cols: [usize; 3],
) -> Result<[f64; 3], Iso9283Error> {
    Ok([
        number(t, &r.fields, r.line, cols[0])?,
        number(t, &r.fields, r.line, cols[1])?,
        number(t, &r.fields, r.line, cols[2])?,
    ])
}

fn pose_of(r: &crate::measure::csv_text::Record, col: usize) -> Result<String, Iso9283Error> {
    let f = r.fields.get(col).map(String::as_str).unwrap_or("");
    pose_name(f).ok_or_else(|| Iso9283Error::Csv {
        line: r.line,
        message: format!("pose `{}` is not P1, P2, … or 1, 2, …", short_text(f)),
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
    let abc = optional_columns(&t, ["rx_deg", "ry_deg", "rz_deg"]);
    let mut out: Vec<Commanded> = Vec::new();
    for r in &t.records {
        let name = pose_of(r, pose)?;
        if out.iter().any(|c| c.name == name) {
            return Err(Iso9283Error::Csv {
                line: r.line,
                message: format!("pose {name} appears twice in the plan"),
            });
        }
        out.push(Commanded {
            name,
            xyz_mm: three(&t, r, xyz)?,
            abc_deg: abc.map(|c| three(&t, r, c)).transpose()?,
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
    let abc = optional_columns(&t, ["rx_deg", "ry_deg", "rz_deg"]);
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
        let name = pose_of(r, pose)?;
        let Some(p) = out.iter_mut().find(|p| p.name == name) else {
            return Err(Iso9283Error::Csv {
                line: r.line,
                message: format!("pose {name} is not in the plan"),
            });
        };
        let c = r.fields.get(cycle).map(String::as_str).unwrap_or("");
        let c: u32 =
            c.trim()
                .parse()
                .ok()
                .filter(|c| *c >= 1)
                .ok_or_else(|| Iso9283Error::Csv {
                    line: r.line,
                    message: format!("cycle `{}` is not a positive integer", short_text(c)),
                })?;
        if p.cycles.contains(&c) {
            return Err(Iso9283Error::Csv {
                line: r.line,
                message: format!("pose {name} has cycle {c} twice"),
            });
        }
        p.cycles.push(c);
        p.attained_mm.push(three(&t, r, xyz)?);
        if let (Some(cols), Some(v)) = (abc, p.attained_abc_deg.as_mut()) {
            v.push(three(&t, r, cols)?);
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

    #[test]
    fn bad_rows_name_their_line() {
        let plan = read_plan_csv("pose,x_mm,y_mm,z_mm\nP1,0,0,0\n").unwrap();
        let e = read_cycles_csv("pose,cycle,x_mm,y_mm,z_mm\nP1,1,0,0,0\nP7,1,0,0,0\n", &plan);
        assert_eq!(
            e.unwrap_err().to_string(),
            "line 3: pose P7 is not in the plan"
        );
        let e = read_cycles_csv("pose,cycle,x_mm,y_mm,z_mm\nP1,0,0,0,0\n", &plan);
        assert!(e.unwrap_err().to_string().contains("cycle `0`"));
        let e = read_cycles_csv("pose,cycle,x_mm,y_mm\nP1,1,0,0\n", &plan);
        assert!(e.unwrap_err().to_string().contains("no `z_mm` column"));
    }
}
