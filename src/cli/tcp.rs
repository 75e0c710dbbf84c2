//! `robocal tcp` and `robocal work-object`: a production tool's TCP (and
//! axis) or a work object fitted on the calibrated model from joint
//! readings (controller degrees) or tracker measurements (mm, degrees, the
//! measurement frame of the calibration), judged (`tcp::judge`), printed and
//! optionally written into a cell file as an entry (`core::cell_fit::tcp::entry`:
//! a refit keeps the entry's load and number; a tool's orientation is the
//! fitted one, `--rpy-deg`, or the cell's kept — never zeros). Readings that
//! do not determine the item, or a fit beyond what the readings' noise
//! explains, exit non-zero saying why with the figures ([`NotFitted`]) and
//! write nothing, unless `--force` stores a judged fit; with `--json` the
//! outcome is printed as the service answers it (`fitted`, `reason`,
//! `message`, `fit`, `orientation`, `replaced`, …).

use super::model_files::load_compensated;
use crate::cell_fit::tcp::entry::{self, Answer, Fitted, Outcome, StoreRequest, StoredEntry};
use crate::cell_fit::tcp::{self, AxisRequest, Reading, TcpMethod, ToolFit, ToolRequest};
use crate::cell_fit::work_object::WorkObjectFit;
use crate::solve::cell::file::CellDescription;
use crate::solve::cell::CellRef;
use anyhow::{bail, Context};
use clap::Args;
use serde::Serialize;

/// Arguments of `robocal tcp`.
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
    /// The controller's tool number (default: a refitted tool's own).
    #[arg(long)]
    pub number: Option<u32>,
    /// The tool's orientation RX,RY,RZ [deg] (fixed-axis, R = Rz·Ry·Rx) when the
    /// method fits its position only (default: the cell's tool's, kept).
    #[arg(long, value_parser = parse_rpy, allow_hyphen_values = true)]
    pub rpy_deg: Option<[f64; 3]>,
    /// Cell file to add the tool to (replacing one of the same name); created when missing.
    #[arg(long)]
    pub cell: Option<String>,
    /// Write a fit judged beyond what the readings' noise explains (it stays `fitted: false`).
    #[arg(long)]
    pub force: bool,
    /// Print JSON (the cell-file entry and the fit) instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `robocal work-object`.
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
    /// The controller's work object (base / user frame) number (default: a refitted one's own).
    #[arg(long)]
    pub number: Option<u32>,
    /// Cell file holding `--tool` and to add the work object to; created when missing.
    #[arg(long)]
    pub cell: Option<String>,
    /// Write a fit judged beyond what the readings' noise explains (it stays `fitted: false`).
    #[arg(long)]
    pub force: bool,
    /// Print JSON (the cell-file entry and the fit) instead of text.
    #[arg(long)]
    pub json: bool,
}

/// `RX,RY,RZ` in degrees.
fn parse_rpy(s: &str) -> Result<[f64; 3], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("`{s}`: give RX,RY,RZ in degrees, e.g. 0,30,0"))?;
    <[f64; 3]>::try_from(v.as_slice())
        .ok()
        .filter(|a| a.iter().all(|x| x.is_finite() && x.abs() <= 360.0))
        .ok_or_else(|| format!("`{s}`: give three angles RX,RY,RZ within ±360°"))
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

/// A fit's answer: the part the service answers alike, and the cell-file
/// entry (absent when a tool's orientation is unknown and nothing is
/// written).
#[derive(Serialize)]
struct Output<'a, E: Serialize, F: Serialize> {
    #[serde(flatten)]
    answer: Answer<'a, F>,
    entry: Option<E>,
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

/// The stored entry of `name` in the cell file `path` (created when missing).
fn cell_and_entry(
    path: Option<&str>,
    find: impl Fn(&CellDescription) -> Option<StoredEntry>,
) -> anyhow::Result<(Option<CellDescription>, Option<StoredEntry>)> {
    match path {
        Some(p) => {
            let cell = read_cell(p)?;
            let existing = find(&cell);
            Ok((Some(cell), existing))
        }
        None => Ok((None, None)),
    }
}

/// The lines every text report ends with: a forced verdict and what the
/// entry replaced.
fn verdict_and_replaced<F: Serialize>(f: &Fitted<F>, what: &str) -> String {
    let mut s = String::new();
    if let Some(v) = &f.overruled {
        s += &format!(
            "forced: not fitted ({}): {}\n",
            v.reason.as_str(),
            v.message
        );
    }
    if let Some(r) = &f.replaced {
        s += &format!("replaces {what}:\n{}", r.describe());
    }
    s
}

fn limits_line(l: &Option<tcp::Limits>) -> String {
    match l {
        Some(l) => format!(
            "limits: rms ≤ {:.3} mm, each ≤ {:.3} mm (σ {:.3} mm per axis, {}){}\n",
            l.rms_mm,
            l.max_mm,
            l.sigma_mm,
            super::judged_fit::code(&l.noise),
            l.distance_mm
                .map(|d| format!(", TCP ≤ {d:.1} mm from the flange"))
                .unwrap_or_default()
        ),
        None => String::new(),
    }
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
    if a.rpy_deg.is_some() && req.determines_orientation() {
        bail!("--rpy-deg: the readings determine the tool's orientation (an axis or a 6-D probe); leave --rpy-deg out");
    }
    let (cell, existing) = cell_and_entry(a.cell.as_deref(), |c| {
        c.tools
            .iter()
            .find(|t| t.name.eq_ignore_ascii_case(&a.name))
            .map(StoredEntry::of_tool)
    })?;
    let sreq = StoreRequest {
        existing,
        number: a.number,
        rpy_deg: a.rpy_deg,
        store: cell.is_some(),
        force: a.force,
    };
    let f = match entry::tool(tcp::fit_tool(&model, &req), &sreq) {
        Outcome::NotFitted(why) => return Err(NotFitted(why).into()),
        Outcome::Fitted(f) => f,
    };
    let desc = f.entry.as_ref().map(|e| e.tool_description(&a.name));
    if let (Some(path), Some(mut cell), Some(d)) = (&a.cell, cell, &desc) {
        cell.tools.retain(|t| !t.name.eq_ignore_ascii_case(&a.name));
        cell.tools.push(d.clone());
        write_cell(path, &cell)?;
    }
    if a.json {
        return Ok(serde_json::to_string_pretty(&Output {
            answer: f.answer(),
            entry: desc,
        })? + "\n");
    }
    Ok(tool_text(a, method, &f))
}

fn tool_text(a: &TcpArgs, method: TcpMethod, f: &Fitted<ToolFit>) -> String {
    let fit = &f.fit;
    let [x, y, z] = fit.xyz_mm;
    let orientation = f.orientation.map_or("", |o| o.as_str());
    let rpy = match &f.entry {
        Some(e) => {
            let [rx, ry, rz] = e.rpy_deg;
            format!("[{rx:.4}, {ry:.4}, {rz:.4}] ({orientation})")
        }
        None => {
            "unknown: the method fits the position only (give --rpy-deg, an axis, or a 6-D probe)"
                .into()
        }
    };
    let mut s = format!(
        "tool {} ({}): xyz_mm = [{x:.4}, {y:.4}, {z:.4}], rpy_deg = {rpy}\n",
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
    s += &format!("distance from the flange: {:.4} mm\n", fit.distance_mm);
    s += &limits_line(&fit.limits);
    s + &verdict_and_replaced(f, &format!("tool {}", a.name))
}

/// The work object fit's report (text or JSON); writes the cell file when asked.
pub fn work_object_to_string(a: &WorkObjectArgs) -> anyhow::Result<String> {
    let model = load_compensated(&a.model).map_err(|e| anyhow::anyhow!("{e}"))?;
    let (cell, existing) = cell_and_entry(a.cell.as_deref(), |c| {
        c.work_objects
            .iter()
            .find(|w| w.name.eq_ignore_ascii_case(&a.name))
            .map(StoredEntry::of_work_object)
    })?;
    let tcp_point = match (&a.tool, &cell) {
        (Some(t), Some(c)) => {
            let r: CellRef = t.parse().unwrap_or(CellRef::Name(t.clone()));
            Some(c.to_cell()?.tool(&r)?.tcp.p)
        }
        _ => None,
    };
    let rows = read_rows(&a.readings)?;
    if tcp_point.is_none() && rows.iter().any(|r| r.xyz_mm.is_none()) {
        bail!("rows with joint readings only are touches: name the tool that made them with --tool and --cell");
    }
    let sreq = StoreRequest {
        existing,
        number: a.number,
        rpy_deg: None,
        store: cell.is_some(),
        force: a.force,
    };
    let fitted = tcp::fit_work_object(&model, &rows, tcp_point.as_ref());
    let f = match entry::work_object(fitted, &sreq) {
        Outcome::NotFitted(why) => return Err(NotFitted(why).into()),
        Outcome::Fitted(f) => f,
    };
    let desc = f.entry.as_ref().map(|e| e.work_object_description(&a.name));
    if let (Some(path), Some(mut cell), Some(d)) = (&a.cell, cell, &desc) {
        cell.work_objects
            .retain(|w| !w.name.eq_ignore_ascii_case(&a.name));
        cell.work_objects.push(d.clone());
        write_cell(path, &cell)?;
    }
    if a.json {
        return Ok(serde_json::to_string_pretty(&Output {
            answer: f.answer(),
            entry: desc,
        })? + "\n");
    }
    Ok(work_object_text(a, &f))
}

fn work_object_text(a: &WorkObjectArgs, f: &Fitted<WorkObjectFit>) -> String {
    let fit = &f.fit;
    let [x, y, z] = fit.xyz_mm;
    let [rx, ry, rz] = fit.rpy_deg;
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
    s += &limits_line(&fit.limits);
    s + &verdict_and_replaced(f, &format!("work object {}", a.name))
}

/// Fits the tool and prints the outcome (text, or JSON with `--json`); a fit refused is an
/// error (with `--json`, its reasons are printed first).
pub fn run_tcp(a: TcpArgs) -> anyhow::Result<()> {
    print_outcome(tcp_to_string(&a), a.json)
}

/// Fits the work object and prints the outcome (text, or JSON with `--json`); a fit refused
/// is an error (with `--json`, its reasons are printed first).
pub fn run_work_object(a: WorkObjectArgs) -> anyhow::Result<()> {
    print_outcome(work_object_to_string(&a), a.json)
}
