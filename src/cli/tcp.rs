//! `robocal tcp` and `robocal work-object`: a production tool's TCP (and
//! axis) or a work object fitted on the calibrated model from joint
//! readings (controller degrees) or tracker measurements (mm, degrees, the
//! measurement frame of the calibration), printed and optionally written
//! into a cell file as an entry (`core::cell::tcp`). Readings that do not
//! determine the item exit non-zero saying why ([`NotFitted`]); with
//! `--json` the outcome is also printed as the service answers it
//! (`fitted: false`, `reason`, `message`, …).

use super::model_files::load_compensated;
use crate::solve::cell::file::CellDescription;
use crate::solve::cell::tcp::{self, AxisRequest, Reading, TcpMethod, ToolRequest};
use crate::solve::cell::CellRef;
use anyhow::{bail, Context};
use clap::Args;
use serde::Serialize;

#[derive(Debug, Args)]
pub struct TcpArgs {
    /// Calibrated model file (`robocal calibrate --save`), a model JSON file or a preset.
    #[arg(long)]
    pub model: String,
    /// Readings CSV: `q1..qN` (controller degrees), with `x,y,z` (mm, measurement
    /// frame) for tracker-point and also `rx,ry,rz` (degrees) for tracker-frame.
    #[arg(long)]
    pub readings: String,
    /// fixed-point (tip held at one point, ≥ 4 orientations), tracker-point or tracker-frame.
    #[arg(long, default_value = "fixed-point")]
    pub method: String,
    /// Readings of a second point on the tool's axis (nearer the flange), same method.
    #[arg(long, conflicts_with = "plane")]
    pub axis_point: Option<String>,
    /// Joint readings with the tool flat on a plane (≥ 3 touches): the tool's z.
    #[arg(long)]
    pub plane: Option<String>,
    /// The tool's name in the cell file.
    #[arg(long, default_value = "tool1")]
    pub name: String,
    /// The controller's tool number.
    #[arg(long)]
    pub number: Option<u32>,
    /// Cell file to add the tool to (replacing one of the same name); created when missing.
    #[arg(long)]
    pub cell: Option<String>,
    /// Print JSON (the cell-file entry and the fit) instead of text.
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Args)]
pub struct WorkObjectArgs {
    /// Calibrated model file (`robocal calibrate --save`), a model JSON file or a preset.
    #[arg(long)]
    pub model: String,
    /// Points CSV: `point` (origin, x, xy, plane) and `x,y,z` (mm, measurement frame)
    /// or `q1..qN` (controller degrees, touched with `--tool`).
    #[arg(long)]
    pub readings: String,
    /// The calibrated tool (name or number in `--cell`) that touched the points.
    #[arg(long, requires = "cell")]
    pub tool: Option<String>,
    /// The work object's name in the cell file.
    #[arg(long, default_value = "wobj1")]
    pub name: String,
    /// The controller's work object (base / user frame) number.
    #[arg(long)]
    pub number: Option<u32>,
    /// Cell file holding `--tool` and to add the work object to; created when missing.
    #[arg(long)]
    pub cell: Option<String>,
    /// Print JSON (the cell-file entry and the fit) instead of text.
    #[arg(long)]
    pub json: bool,
}

fn read_rows(path: &str) -> anyhow::Result<Vec<Reading>> {
    let text = std::fs::read_to_string(path).with_context(|| format!("cannot read {path}"))?;
    tcp::readings::parse_csv(&text).with_context(|| path.to_string())
}

fn read_cell(path: &str) -> anyhow::Result<CellDescription> {
    match std::fs::read_to_string(path) {
        Ok(text) => CellDescription::from_json(&text).with_context(|| path.to_string()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(CellDescription::default()),
        Err(e) => Err(e).with_context(|| format!("cannot read cell file {path}")),
    }
}

fn write_cell(path: &str, cell: &CellDescription) -> anyhow::Result<()> {
    let text = serde_json::to_string_pretty(cell)? + "\n";
    std::fs::write(path, text).with_context(|| format!("cannot write cell file {path}"))
}

#[derive(Serialize)]
struct Output<'a, E: Serialize, F: Serialize> {
    /// Always true here (see [`NotFitted`]).
    fitted: bool,
    entry: &'a E,
    fit: &'a F,
}

/// Readings that do not determine the tool or work object: the reason and
/// the fix (nothing is written to the cell file).
#[derive(Debug, thiserror::Error)]
#[error("not fitted ({}): {}", .0.reason.as_str(), .0.message)]
pub struct NotFitted(pub tcp::FitError);

#[derive(Serialize)]
struct NotFittedJson<'a> {
    fitted: bool,
    #[serde(flatten)]
    why: &'a tcp::FitError,
}

/// Prints a report; a not-fitted outcome also as JSON with `--json`.
fn print_outcome(out: anyhow::Result<String>, json: bool) -> anyhow::Result<()> {
    match out {
        Ok(s) => {
            print!("{s}");
            Ok(())
        }
        Err(e) => {
            if let (true, Some(NotFitted(why))) = (json, e.downcast_ref::<NotFitted>()) {
                let body = NotFittedJson { fitted: false, why };
                println!("{}", serde_json::to_string_pretty(&body)?);
            }
            Err(e)
        }
    }
}

fn fmt_list(v: &[f64]) -> String {
    v.iter()
        .map(|x| format!("{x:.4}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The tool fit's report (text or JSON); writes the cell file when asked.
pub fn tcp_to_string(a: &TcpArgs) -> anyhow::Result<String> {
    let method: TcpMethod = a.method.parse().map_err(anyhow::Error::msg)?;
    let model = load_compensated(&a.model).map_err(|e| anyhow::anyhow!("{e}"))?;
    let axis = match (&a.axis_point, &a.plane) {
        (Some(p), _) => Some(AxisRequest::Point(read_rows(p)?)),
        (None, Some(p)) => Some(AxisRequest::Plane(read_rows(p)?)),
        (None, None) => None,
    };
    let req = ToolRequest {
        method,
        rows: read_rows(&a.readings)?,
        axis,
    };
    let fit = tcp::fit_tool(&model, &req).map_err(NotFitted)?;
    let entry = tcp::request::tool_description(&a.name, a.number, &fit);
    if let Some(path) = &a.cell {
        let mut cell = read_cell(path)?;
        cell.tools.retain(|t| !t.name.eq_ignore_ascii_case(&a.name));
        cell.tools.push(entry.clone());
        write_cell(path, &cell)?;
    }
    if a.json {
        return Ok(serde_json::to_string_pretty(&Output {
            fitted: true,
            entry: &entry,
            fit: &fit,
        })? + "\n");
    }
    let [x, y, z] = entry.tcp.xyz_mm;
    let [rx, ry, rz] = entry.tcp.rpy_deg;
    let mut s = format!(
        "tool {} ({}): xyz_mm = [{x:.4}, {y:.4}, {z:.4}], rpy_deg = [{rx:.4}, {ry:.4}, {rz:.4}]\n",
        a.name,
        method.as_str()
    );
    s += &format!(
        "tip residual: rms {:.4} mm, max {:.4} mm; σ = [{}] mm\nper pose [mm]: {}\n",
        fit.rms_mm,
        fit.max_mm,
        fmt_list(&fit.sigma_mm),
        fmt_list(&fit.residual_mm)
    );
    if let Some(sd) = fit.sigma_deg {
        s += &format!("orientation σ: {sd:.4}°\n");
    }
    if let Some(spread) = fit.orientation_spread_deg {
        s += &format!("orientation spread: {spread:.1}°\n");
    }
    Ok(s)
}

/// The work object fit's report (text or JSON); writes the cell file when asked.
pub fn work_object_to_string(a: &WorkObjectArgs) -> anyhow::Result<String> {
    let model = load_compensated(&a.model).map_err(|e| anyhow::anyhow!("{e}"))?;
    let mut cell = match &a.cell {
        Some(p) => read_cell(p)?,
        None => CellDescription::default(),
    };
    let tcp_point = match &a.tool {
        Some(t) => {
            let r: CellRef = t.parse().unwrap_or(CellRef::Name(t.clone()));
            let tool = cell.to_cell()?.tool(&r)?;
            Some(tool.tcp.p)
        }
        None => None,
    };
    let rows = read_rows(&a.readings)?;
    if tcp_point.is_none() && rows.iter().any(|r| r.xyz_mm.is_none()) {
        bail!("rows with joint readings only are touches: name the tool that made them with --tool and --cell");
    }
    let fit = tcp::fit_work_object(&model, &rows, tcp_point.as_ref()).map_err(NotFitted)?;
    let entry = tcp::request::work_object_description(&a.name, a.number, &fit);
    if let Some(path) = &a.cell {
        cell.work_objects
            .retain(|w| !w.name.eq_ignore_ascii_case(&a.name));
        cell.work_objects.push(entry.clone());
        write_cell(path, &cell)?;
    }
    if a.json {
        return Ok(serde_json::to_string_pretty(&Output {
            fitted: true,
            entry: &entry,
            fit: &fit,
        })? + "\n");
    }
    let [x, y, z] = entry.pose.xyz_mm;
    let [rx, ry, rz] = entry.pose.rpy_deg;
    let mut s = format!(
        "work object {} (base frame): xyz_mm = [{x:.4}, {y:.4}, {z:.4}], rpy_deg = [{rx:.4}, {ry:.4}, {rz:.4}]\n",
        a.name
    );
    s += &format!(
        "touch scatter [mm]: origin {:.4}, x {:.4}, xy {:.4}; OX–OY angle {:.3}°\n",
        fit.scatter_mm[0], fit.scatter_mm[1], fit.scatter_mm[2], fit.xy_angle_deg
    );
    if !fit.plane_residual_mm.is_empty() {
        s += &format!(
            "plane points off the plane [mm]: {}\n",
            fmt_list(&fit.plane_residual_mm)
        );
    }
    match (fit.sigma_mm, fit.sigma_deg) {
        (Some(p), Some(d)) => s += &format!("σ: origin {p:.4} mm, orientation {d:.5}°\n"),
        _ => s += "σ: unknown (touch or measure each point twice or more)\n",
    }
    Ok(s)
}

pub fn run_tcp(a: TcpArgs) -> anyhow::Result<()> {
    print_outcome(tcp_to_string(&a), a.json)
}

pub fn run_work_object(a: WorkObjectArgs) -> anyhow::Result<()> {
    print_outcome(work_object_to_string(&a), a.json)
}
