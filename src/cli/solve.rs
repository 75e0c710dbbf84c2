//! `robocal solve`: target poses → joint commands and false targets.
//!
//! Targets CSV (`#` starts a comment line; blank lines are ignored; columns by
//! name, case-insensitive, any order):
//!
//! ```text
//! id,x,y,z,a,b,c
//! p1,1500,-3240,1200,180,0,180
//! ```
//!
//! - `id` (optional; default: the 1-based target number);
//! - `x, y, z`: TCP position [mm] in the measurement (cell) frame, or in the
//!   registered base frame with `--frame base`;
//! - the orientation columns of exactly one convention, angles in degrees:
//!   `qw,qx,qy,qz` (quaternion) | `q1,q2,q3,q4` (ABB, q1 scalar) |
//!   `ur_rx_rad,ur_ry_rad,ur_rz_rad` (UR rotation vector, radians) |
//!   `a,b,c` (KUKA, `Rz(A)·Ry(B)·Rx(C)`) |
//!   `w,p,r` (Fanuc, `Rz(R)·Ry(P)·Rx(W)`) | `r11..r33` (row-major matrix).
//!   With `--position-only` they may be omitted (or left empty in a row).
//!
//! A malformed row (a number that does not parse, NaN, a non-unit quaternion)
//! fails alone with an `invalid_target` reason; header errors reject the file.
//!
//! Output per target: id, status, reason, configuration branch, joint commands
//! (controller convention, degrees), position [mm] and orientation [rad]
//! residuals of the compensated prediction, and the false target
//! (`FK_nominal(q_cmd)`, controller base frame, mm, same orientation convention
//! as the input), as a table or, with `--json`, as JSON.

use crate::compensate::load_compensated;
use crate::ik::{
    Configuration, IkSettings, IkSolution, IkSolver, SolveOptions, TargetFrame, TargetInput,
    TargetResult,
};
use crate::model::orientation::OrientationConvention;
use anyhow::{bail, Context};
use clap::Args;
use serde_json::json;
use std::fmt::Write as _;

#[derive(Debug, Args)]
pub struct SolveArgs {
    /// Robot model: a preset (ys100, hh800, ur5, ur10), a model JSON file, or a
    /// calibrated model file written by `robocal calibrate --save`.
    #[arg(long)]
    pub model: String,
    /// Targets CSV: optional `id`, `x,y,z` [mm] and the orientation columns of
    /// one convention, angles in degrees: `qw,qx,qy,qz` (quaternion) |
    /// `q1,q2,q3,q4` (ABB) | `ur_rx_rad,ur_ry_rad,ur_rz_rad` (UR, radians) | `a,b,c`
    /// (KUKA) | `w,p,r` (Fanuc) | `r11..r33` (matrix); `#` starts a comment line.
    #[arg(long)]
    pub targets: String,
    /// Payload mass [kg] (default: the model file's payload).
    #[arg(long)]
    pub payload_kg: Option<f64>,
    /// Configuration branch, e.g. `front,up,noflip` (shoulder front|back, elbow
    /// up|down, wrist noflip|flip) or a branch index 0..7.
    #[arg(long)]
    pub branch: Option<String>,
    /// Joint seed in the controller convention [deg], e.g. "0,90,0,0,45,0": the
    /// branch nearest it is chosen.
    #[arg(long, allow_hyphen_values = true)]
    pub seed_deg: Option<String>,
    /// Path mode: seed each target with the previous solution, keep the branch
    /// and report joint jumps.
    #[arg(long)]
    pub path: bool,
    /// Frame of the targets: cell (measurement frame of the calibration) or base.
    #[arg(long, default_value = "cell")]
    pub frame: String,
    /// Solve the position only (the orientation, if given, guides the seed).
    #[arg(long)]
    pub position_only: bool,
    /// Joint jump threshold of path mode [deg].
    #[arg(long, default_value_t = 30.0)]
    pub jump_deg: f64,
    /// Worker threads (0: all cores).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// One parsed CSV row: the target or why the row is invalid.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetRow {
    pub id: String,
    pub target: Result<TargetInput, String>,
}

/// Targets parsed from a CSV text, with the orientation convention of the file.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetsCsv {
    pub convention: Option<OrientationConvention>,
    pub rows: Vec<TargetRow>,
}

/// Parses a targets CSV (see the module docs).
pub fn parse_targets_csv(text: &str) -> anyhow::Result<TargetsCsv> {
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let Some((hline, header)) = lines.next() else {
        bail!("the targets file has no header row");
    };
    let cols: Vec<String> = header
        .split(',')
        .map(|c| c.trim().to_ascii_lowercase())
        .collect();
    let find = |name: &str| cols.iter().position(|c| c == name);
    for (i, c) in cols.iter().enumerate() {
        if cols[..i].contains(c) {
            bail!("line {hline}: duplicate column `{c}`");
        }
    }
    let known = |c: &str| {
        c == "id"
            || c == "x"
            || c == "y"
            || c == "z"
            || OrientationConvention::ALL
                .iter()
                .any(|k| k.column_names().contains(&c))
    };
    if let Some(c) = cols.iter().find(|c| !known(c)) {
        bail!(
            "line {hline}: unknown column `{c}`; expected id, x, y, z and the orientation \
             columns of one convention: qw,qx,qy,qz | q1,q2,q3,q4 | a,b,c | w,p,r | ur_rx_rad,ur_ry_rad,ur_rz_rad | r11..r33"
        );
    }
    let xyz: Vec<usize> = ["x", "y", "z"]
        .iter()
        .map(|n| find(n).with_context(|| format!("line {hline}: missing column `{n}`")))
        .collect::<anyhow::Result<_>>()?;
    let present: Vec<OrientationConvention> = OrientationConvention::ALL
        .into_iter()
        .filter(|k| k.column_names().iter().any(|n| find(n).is_some()))
        .collect();
    let convention = match present.as_slice() {
        [] => None,
        [k] => Some(*k),
        _ => bail!(
            "line {hline}: orientation columns of several conventions ({}); use one",
            present
                .iter()
                .map(|k| k.name())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    let ori_idx: Vec<usize> = match convention {
        None => Vec::new(),
        Some(k) => k
            .column_names()
            .iter()
            .map(|n| {
                find(n).with_context(|| {
                    format!(
                        "line {hline}: {} orientation needs columns {}; `{n}` is missing",
                        k.name(),
                        k.column_names().join(", ")
                    )
                })
            })
            .collect::<anyhow::Result<_>>()?,
    };
    let id_idx = find("id");
    let mut rows = Vec::new();
    for (n, (lineno, line)) in lines.enumerate() {
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        let id = id_idx
            .and_then(|i| cells.get(i))
            .filter(|s| !s.is_empty())
            .map(|s| s.to_string())
            .unwrap_or_else(|| (n + 1).to_string());
        let target = parse_row(&cells, &cols, &xyz, &ori_idx, convention)
            .map(|mut t| {
                t.id = Some(id.clone());
                t
            })
            .map_err(|e| format!("line {lineno}: {e}"));
        rows.push(TargetRow { id, target });
    }
    Ok(TargetsCsv { convention, rows })
}

fn parse_row(
    cells: &[&str],
    cols: &[String],
    xyz: &[usize],
    ori_idx: &[usize],
    convention: Option<OrientationConvention>,
) -> Result<TargetInput, String> {
    if cells.len() != cols.len() {
        return Err(format!(
            "{} fields, the header has {}",
            cells.len(),
            cols.len()
        ));
    }
    let num = |i: usize| -> Result<f64, String> {
        cells[i]
            .parse::<f64>()
            .map_err(|_| format!("column `{}`: `{}` is not a number", cols[i], cells[i]))
    };
    let xyz_mm = [num(xyz[0])?, num(xyz[1])?, num(xyz[2])?];
    let empty = ori_idx.iter().filter(|&&i| cells[i].is_empty()).count();
    let (convention, orientation) = if ori_idx.is_empty() || empty == ori_idx.len() {
        (None, Vec::new())
    } else if empty > 0 {
        return Err("some orientation fields are empty".into());
    } else {
        let values = ori_idx
            .iter()
            .map(|&i| num(i))
            .collect::<Result<Vec<f64>, String>>()?;
        (convention.map(|k| k.name().to_string()), values)
    };
    Ok(TargetInput {
        id: None,
        xyz_mm,
        convention,
        orientation,
    })
}

fn parse_seed(text: &str) -> anyhow::Result<Vec<f64>> {
    text.split(',')
        .map(|s| {
            let v: f64 = s
                .trim()
                .parse()
                .with_context(|| format!("--seed-deg: `{}` is not a number", s.trim()))?;
            if !v.is_finite() {
                bail!("--seed-deg values must be finite");
            }
            Ok(v.to_radians())
        })
        .collect()
}

/// Runs the command and returns what it prints.
pub fn solve_to_string(a: &SolveArgs) -> anyhow::Result<String> {
    let mut model = load_compensated(&a.model).map_err(|e| anyhow::anyhow!("{e}"))?;
    if let Some(p) = a.payload_kg {
        if !(p.is_finite() && p >= 0.0) {
            bail!("--payload-kg must be a non-negative number, got {p}");
        }
        model.payload_kg = p;
    }
    let frame: TargetFrame = a.frame.parse().map_err(anyhow::Error::msg)?;
    let branch = a
        .branch
        .as_deref()
        .map(Configuration::parse)
        .transpose()
        .map_err(|e| anyhow::anyhow!("--branch: {e}"))?;
    let seed = match &a.seed_deg {
        None => None,
        Some(s) => {
            let q = parse_seed(s)?;
            if q.len() != model.dof() {
                bail!(
                    "--seed-deg needs {} joint values, got {}",
                    model.dof(),
                    q.len()
                );
            }
            Some(model.nominal.joints_from_controller(&q))
        }
    };
    if !(a.jump_deg.is_finite() && a.jump_deg > 0.0) {
        bail!("--jump-deg must be a positive number of degrees");
    }
    let text = std::fs::read_to_string(&a.targets)
        .with_context(|| format!("cannot read targets file {}", a.targets))?;
    let csv = parse_targets_csv(&text).with_context(|| a.targets.clone())?;
    if csv.convention.is_none() && !a.position_only {
        bail!(
            "{}: no orientation columns (qw,qx,qy,qz | q1,q2,q3,q4 | a,b,c | w,p,r | ur_rx_rad,ur_ry_rad,ur_rz_rad | r11..r33); add them or pass --position-only",
            a.targets
        );
    }
    let settings = IkSettings {
        threads: a.threads,
        jump_threshold_rad: a.jump_deg.to_radians(),
        ..IkSettings::default()
    };
    let payload = model.payload_kg;
    let solver = IkSolver::new(model, settings);
    let options = SolveOptions {
        frame,
        position_only: a.position_only,
        branch,
        seed,
    };
    let valid: Vec<TargetInput> = csv
        .rows
        .iter()
        .filter_map(|r| r.target.as_ref().ok().cloned())
        .collect();
    let mut solved = if a.path {
        solver.solve_targets_path(&valid, &options)
    } else {
        solver.solve_targets(&valid, &options)
    }
    .into_iter();
    let results: Vec<TargetResult> = csv
        .rows
        .iter()
        .map(|r| match &r.target {
            Ok(_) => solved.next().expect("one result per valid target"),
            Err(msg) => TargetResult {
                id: r.id.clone(),
                solution: IkSolution::invalid(msg.clone()),
                joints_deg: None,
                false_target: None,
                jump: None,
            },
        })
        .collect();
    let conv = csv.convention.unwrap_or(OrientationConvention::Quaternion);
    let header = Header {
        model: &a.model,
        frame,
        convention: conv,
        payload_kg: payload,
        path: a.path,
        position_only: a.position_only,
        closed_form: solver.analytic().is_some(),
    };
    Ok(if a.json {
        render_json(&header, &results)
    } else {
        render_table(&header, &results, solver.model().dof())
    })
}

struct Header<'a> {
    model: &'a str,
    frame: TargetFrame,
    convention: OrientationConvention,
    payload_kg: f64,
    path: bool,
    position_only: bool,
    closed_form: bool,
}

fn render_json(h: &Header, results: &[TargetResult]) -> String {
    let solved = results.iter().filter(|r| r.solution.converged).count();
    let cols = h.convention.column_names();
    let targets: Vec<serde_json::Value> = results
        .iter()
        .map(|r| {
            let s = &r.solution;
            let false_target = r.false_target.as_ref().map(|f| {
                let mut m = serde_json::Map::new();
                for (k, v) in ["x", "y", "z"].iter().zip(f.xyz_mm) {
                    m.insert(k.to_string(), json!(v));
                }
                for (k, v) in f.convention.column_names().iter().zip(&f.orientation) {
                    m.insert(k.to_string(), json!(v));
                }
                serde_json::Value::Object(m)
            });
            json!({
                "id": r.id,
                "status": r.status(),
                "reason": s.reason.as_ref().map(|x| x.code()),
                "message": s.reason.as_ref().map(|x| x.to_string()),
                "branch": s.branch.map(|b| b.to_string()),
                "joints_deg": r.joints_deg,
                "position_residual_mm": s.position_residual_mm,
                "orientation_residual_rad": s.orientation_residual_rad,
                "iterations": s.iterations,
                "false_target": false_target,
                "jump": r.jump.map(|j| json!({"joint": j.joint, "delta_deg": j.delta_deg})),
            })
        })
        .collect();
    let doc = json!({
        "model": h.model,
        "frame": h.frame.to_string(),
        "convention": h.convention.name(),
        "columns": cols,
        "payload_kg": h.payload_kg,
        "path": h.path,
        "position_only": h.position_only,
        "closed_form_seed": h.closed_form,
        "solved": solved,
        "total": results.len(),
        "targets": targets,
    });
    serde_json::to_string_pretty(&doc).expect("JSON output serialises") + "\n"
}

fn render_table(h: &Header, results: &[TargetResult], dof: usize) -> String {
    let mut out = String::new();
    let solved = results.iter().filter(|r| r.solution.converged).count();
    let _ = writeln!(
        out,
        "# robocal solve: model {}, targets in the {} frame, payload {} kg{}{}",
        h.model,
        h.frame,
        h.payload_kg,
        if h.path { ", path mode" } else { "" },
        if h.position_only {
            ", position only"
        } else {
            ""
        }
    );
    let _ = writeln!(
        out,
        "# joints: controller convention [deg]; residuals of the compensated model; false target: nominal model, controller base frame [mm], {}",
        h.convention.name()
    );
    let mut head = vec![
        "id".to_string(),
        "status".into(),
        "reason".into(),
        "branch".into(),
    ];
    head.extend((1..=dof).map(|k| format!("j{k}")));
    head.extend(["pos_mm", "ori_rad", "iter", "x", "y", "z"].map(String::from));
    head.extend(h.convention.column_names().iter().map(|c| c.to_string()));
    head.push("jump".into());
    let mut rows = vec![head];
    for r in results {
        let s = &r.solution;
        let mut row = vec![
            r.id.clone(),
            r.status().to_string(),
            s.reason
                .as_ref()
                .map(|x| x.code().to_string())
                .unwrap_or_else(|| "-".into()),
            s.branch
                .map(|b| b.to_string())
                .unwrap_or_else(|| "-".into()),
        ];
        match &r.joints_deg {
            Some(j) => row.extend(j.iter().map(|v| format!("{v:.4}"))),
            None => row.extend((0..dof).map(|_| "-".to_string())),
        }
        let num = |v: f64, p: usize| {
            if v.is_finite() {
                format!("{v:.p$e}")
            } else {
                "-".into()
            }
        };
        row.push(num(s.position_residual_mm, 2));
        row.push(num(s.orientation_residual_rad, 2));
        row.push(s.iterations.to_string());
        match &r.false_target {
            Some(f) => {
                row.extend(f.xyz_mm.iter().map(|v| format!("{v:.4}")));
                row.extend(f.orientation.iter().map(|v| format!("{v:.6}")));
            }
            None => row.extend((0..3 + h.convention.n_values()).map(|_| "-".to_string())),
        }
        row.push(
            r.jump
                .map(|j| format!("j{}:{:+.1}", j.joint, j.delta_deg))
                .unwrap_or_else(|| "-".into()),
        );
        rows.push(row);
    }
    let ncol = rows[0].len();
    let widths: Vec<usize> = (0..ncol)
        .map(|c| rows.iter().map(|r| r[c].len()).max().unwrap_or(0))
        .collect();
    for r in &rows {
        let line: Vec<String> = r
            .iter()
            .zip(&widths)
            .map(|(v, w)| format!("{v:>w$}"))
            .collect();
        let _ = writeln!(out, "{}", line.join("  ").trim_end());
    }
    for r in results {
        if let Some(reason) = &r.solution.reason {
            let _ = writeln!(out, "# {}: {}", r.id, reason);
        }
    }
    let _ = writeln!(out, "# {solved} of {} targets solved", results.len());
    out
}

pub fn run(args: SolveArgs) -> anyhow::Result<()> {
    print!("{}", solve_to_string(&args)?);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_conventions_and_row_errors() {
        let t = parse_targets_csv("# c\nid,x,y,z,qw,qx,qy,qz\np,1,2,3,1,0,0,0\nq,1,2,x,1,0,0,0\n")
            .unwrap();
        assert_eq!(t.convention, Some(OrientationConvention::Quaternion));
        assert_eq!(t.rows.len(), 2);
        assert!(t.rows[0].target.is_ok());
        assert!(t.rows[1].target.as_ref().unwrap_err().contains("`z`"));
        let t = parse_targets_csv("x,y,z,W,P,R\n1,2,3,0,0,0\n").unwrap();
        assert_eq!(t.convention, Some(OrientationConvention::FanucWpr));
        assert_eq!(t.rows[0].id, "1");
        assert!(parse_targets_csv("x,y,z,a,b,c,w\n").is_err());
        assert!(parse_targets_csv("x,y,z,a,b\n").is_err());
        assert!(parse_targets_csv("x,y,z,rx\n").is_err());
        assert!(parse_targets_csv("x,y\n").is_err());
        assert!(parse_targets_csv("# only a comment\n").is_err());
        let t = parse_targets_csv("x,y,z\n1,2,3\n").unwrap();
        assert_eq!(t.convention, None);
    }
}
