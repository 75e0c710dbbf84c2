//! `robocal solve`: target poses → joint commands and false targets.
//!
//! The targets file is read by `ik::targets_csv` (the same parser as the
//! service's `text/csv` solve): optional `id`, `x,y,z` [mm] in the measurement
//! (cell) frame, or the registered base frame with `--frame base`, and the
//! orientation columns of exactly one convention (see that module); `,`, `;`
//! or tab delimited, decimal commas with `;` or tabs. With `--position-only`
//! the orientation columns may be omitted (or left empty in a row). A
//! malformed row fails alone with an `invalid_target` reason; header errors
//! reject the file.
//!
//! Output per target: id, status, reason, configuration branch, joint commands
//! (controller convention, degrees), position [mm] and orientation [rad]
//! residuals of the compensated prediction, and the false target
//! (`FK_nominal(q_cmd)`, controller base frame, mm, same orientation convention
//! as the input), as a table (`--format table`, the default), CSV
//! (`--format csv`, the columns of `ik::targets_csv::results_csv`) or JSON.
//!
//! With `--cell FILE --tool NAME` the production tool of the cell file is on
//! the calibrated flange; with `--work-object NAME` the targets and the false
//! targets are poses in that work object (`core::cell`). With `--track FILE
//! --e1 MM` the robot's base is carried along a calibrated track to that
//! value and the cell frame is the track's (`super::track`); with `--track`
//! alone each row's value is the targets file's `e1` column
//! (`solve::external::targets`: a row beyond the travel, or without a
//! number there, fails alone). With `--positioner FILE` the targets are in
//! a calibrated positioner's face plate frame, each row at its `e1` (tilt)
//! and `e2` (rotate) values [deg] (`solve::external::place_on_positioner`);
//! with `--track` beside it, at its `e2` (tilt) and `e3` (rotate), the
//! robot carried to the row's `e1` (or `--e1`) along the track, both in the
//! track's cell frame (`place_on_track_and_positioner`: `B(e)⁻¹·F(v)·T`).
//! The false targets stay in the controller's base frame (or the work
//! object).

use crate::measure::csv_text::dialect_from_names;
use crate::model::orientation::OrientationConvention;
use crate::solve::cell::{CellRef, CellSolver};
use crate::solve::ik::targets_csv::{parse_targets_csv_beside, CONVENTION_COLUMNS};
use crate::solve::ik::{
    results_csv, Configuration, IkSettings, SolveOptions, TargetFrame, TargetResult,
};
use anyhow::{bail, Context};
use clap::{Args, ValueEnum};
use robocal_core::model::calibrated::CompensatedModel;
use robocal_core::model::external::{LinearTrack, TiltRotate};
use robocal_core::solve::external::{
    place_on_positioner, place_on_track, place_on_track_and_positioner, positioner_columns,
    target_column_values, TargetValue, TRACK_COLUMN,
};
use serde_json::json;
use std::fmt::Write as _;

/// `--branch` in `robocal solve --help`: the branches and how each
/// controller's flags name them (`program::Flags`; set out in
/// docs/configurations.md).
pub const CONFIGURATIONS_HELP: &str = "\
Configuration branch: `front,up,noflip` (shoulder front|back, elbow up|down, wrist noflip|flip) or its index \
0..7 (bit 0 back, bit 1 down, bit 2 flip). Without it, the solution nearest the previous target's joints \
(--path), else --seed-deg, else the middle of the joint ranges.

The branch is geometric, the same on every robot:
  shoulder  front: the wrist centre in front of axis 1 (x >= 0 in link 1's frame); back: over the robot's back.
  elbow     up: the elbow on the base-z side of the shoulder-wrist line, seen with the shoulder in front (so
            with the shoulder back, `up` is physically below that line); down: the other side.
  wrist     noflip: sin(theta5) >= 0 for joint 5's angle in the kinematic chain; flip: < 0.

Controller flags, as robocal reads them in programs (filter) and writes them (reports, exports):
  KUKA KRL   S = 1*back + 2*down + 4*[A5 < 0];  T: bit i set when axis i+1 < 0 (A1 = bit 0 ... A6 = bit 5).
  ABB RAPID  [cf1, cf4, cf6, cfx]: cf1, cf4, cf6 the quadrant floor(A/90 deg) of axes 1, 4, 6;
             cfx = 4*back + 2*down + [A5 < 0].
  Fanuc      CONFIG 'F|N U|D T|B, t1, t4, t6': F when A5 < 0, U when the elbow is up, T when the shoulder is
             in front; t = floor((A + 180 deg)/360 deg) of axes 1, 4, 6.
  URScript   none: the controller takes the solution nearest its joints.
A1 ... A6 are this model's controller joints (its per-joint `sign` and `zero`), so the A5 and turn bits follow
this model's axis directions, which can differ from the maker's: the Hyundai presets use the kinematic angles (the
YS100's A2 is 90 deg with the arm upright, where a KUKA's is -90 deg, so T bit 1 is never set on it).
A required branch the target lacks, or program flags no solution carries, fails naming the branches (and
their flags) that do reach it within the joint limits. Per robot family: docs/configurations.md.";

/// Arguments of `robocal solve`.
#[derive(Debug, Args)]
#[command(group = clap::ArgGroup::new("external_axis").multiple(true).args(["track"]))]
pub struct SolveArgs {
    /// Robot model: a preset (ys100, hh800, ur5, ur10), a model JSON file, or a
    /// calibrated model file written by `robocal calibrate --save`.
    #[arg(long)]
    pub model: String,
    /// Targets CSV: optional `id`, `x,y,z` [mm] and the orientation columns of
    /// one convention, angles in degrees: `qw,qx,qy,qz` (quaternion) |
    /// `q1,q2,q3,q4` (ABB) | `ur_rx_rad,ur_ry_rad,ur_rz_rad` (UR, radians) | `a,b,c`
    /// (KUKA) | `w,p,r` (Fanuc) | `r11..r33` (matrix); `#` starts a comment line.
    /// With --track and no --e1, an `e1` column: each row's track value [mm].
    #[arg(long)]
    pub targets: String,
    /// Payload mass [kg] (default: the model file's payload).
    #[arg(long)]
    pub payload_kg: Option<f64>,
    /// Configuration branch, e.g. `front,up,noflip` (shoulder front|back, elbow
    /// up|down, wrist noflip|flip) or a branch index 0..7.
    #[arg(long, long_help = CONFIGURATIONS_HELP)]
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
    /// Cell file (tools and work objects, mm and degrees, e.g.
    /// examples/programs/cell.json) that --tool and --work-object name from.
    #[arg(long)]
    pub cell: Option<String>,
    /// Production tool on the calibrated flange: a name or number of the cell file.
    #[arg(long, requires = "cell")]
    pub tool: Option<String>,
    /// Work object (name or number of the cell file) the targets and false
    /// targets are in; --frame does not apply then.
    #[arg(long, requires = "cell")]
    pub work_object: Option<String>,
    /// Solve the position only (the orientation, if given, guides the seed).
    #[arg(long)]
    pub position_only: bool,
    /// Joint jump threshold of path mode [deg].
    #[arg(long, default_value_t = 30.0)]
    pub jump_deg: f64,
    /// Worker threads (0: all cores).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// Output format.
    #[arg(long, value_enum, default_value_t = OutputFormat::Table)]
    pub format: OutputFormat,
    /// Same as `--format json`.
    #[arg(long, conflicts_with = "format")]
    pub json: bool,
    /// Field delimiter of the targets file: `,`, `;` or `tab` (default: detected).
    #[arg(long)]
    pub delimiter: Option<String>,
    /// Decimal separator of the targets file: `point` or `comma` (default:
    /// detected; with `,` delimiters a decimal comma is read in quoted fields).
    #[arg(long)]
    pub decimal: Option<String>,
    /// `--allow-failures`: the exit code when some rows fail.
    #[command(flatten)]
    pub failures: super::exit::AllowFailures,
    /// `--track FILE --e1 MM`: the robot carried along a linear track.
    #[command(flatten)]
    pub track: super::track::OnTrack,
    /// Calibrated positioner (`robocal positioner calibrate --out`, in the
    /// robot's measurement frame): the targets are in its face plate frame,
    /// each row at its `e1` (tilt) and `e2` (rotate) values [deg]; beside
    /// --track (in the track's cell frame) at `e2` (tilt) and `e3` (rotate),
    /// the track's value its `e1` column or --e1.
    #[arg(long, conflicts_with_all = ["work_object"])]
    pub positioner: Option<String>,
    /// Calibrated one-axis turntable (`robocal turntable calibrate --out`,
    /// in the robot's measurement frame): the targets are in its face plate
    /// frame, each row at its `e1` value [deg]; beside --track (in the
    /// track's cell frame) at `e2`, the track's value its `e1` column or --e1.
    #[arg(long, conflicts_with_all = ["work_object", "positioner"])]
    pub turntable: Option<String>,
}

/// How `robocal solve` prints its results.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum OutputFormat {
    /// Aligned columns with `#` comment lines (for people).
    Table,
    /// One header row and one row per target (for programs and spreadsheets).
    Csv,
    /// One JSON document.
    Json,
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
    solve_outcome(a).map(|o| o.text)
}

/// What the command prints and how many targets failed.
pub fn solve_outcome(a: &SolveArgs) -> anyhow::Result<super::exit::Outcome> {
    let text = std::fs::read_to_string(&a.targets)
        .with_context(|| format!("cannot read targets file {}", a.targets))?;
    let dialect = dialect_from_names(a.delimiter.as_deref(), a.decimal.as_deref())
        .map_err(anyhow::Error::msg)?;
    let on_track = a.track.track.is_some();
    let on_plate = match (&a.positioner, &a.turntable) {
        (Some(path), _) => Some(positioner_rows(path, &a.targets, &text, dialect, on_track)?),
        (None, Some(path)) => Some(turntable_rows(path, &a.targets, &text, dialect, on_track)?),
        (None, None) => None,
    };
    // `--track` without `--e1`: each row's value from the file's `e1` column
    // (on a positioner without a track, `e1` is its tilt).
    let per_row = match (&on_plate, on_track) {
        (Some(_), false) => None,
        _ => a.track.per_target(&a.targets, &text, dialect)?,
    };
    let loaded = super::model_files::load_with_payload(&a.model, a.payload_kg)?;
    let model = match per_row {
        Some(_) => loaded,
        None => a.track.carry(loaded)?,
    };
    let mut frame: TargetFrame = a.frame.parse().map_err(anyhow::Error::msg)?;
    let mut frame_label = match per_row {
        Some(_) => a.track.label_per_row(frame.to_string()),
        None => a.track.label(frame.to_string()),
    };
    let (tool, work_object) = cell_items(a)?;
    if let Some(w) = &work_object {
        frame = TargetFrame::Base;
        frame_label = format!("work object {}", w.name);
    }
    let branch = a
        .branch
        .as_deref()
        .map(Configuration::parse)
        .transpose()
        .map_err(|e| anyhow::anyhow!("--branch: {e}"))?;
    let seed = seed_joints(a, &model)?;
    if !(a.jump_deg.is_finite() && a.jump_deg > 0.0) {
        bail!("--jump-deg must be a positive number of degrees");
    }
    // The external-axis columns read per row, passed over by the parser.
    let mut beside: Vec<&str> = match &per_row {
        Some(_) => vec![TRACK_COLUMN],
        None => vec![],
    };
    if let Some(rows) = &on_plate {
        beside.extend(rows.columns.iter());
    }
    let mut csv = read_targets(a, &text, dialect, &beside)?;
    let settings = IkSettings {
        threads: a.threads,
        jump_threshold_rad: a.jump_deg.to_radians(),
        ..IkSettings::default()
    };
    let cell_solver = CellSolver::for_tool(&model, tool.as_ref(), settings);
    // Per row: each target moved into the base frame at its own values.
    let on_track = match (&on_plate, &per_row) {
        (None, Some((track, values))) => Some(place_on_track(
            &mut csv,
            values,
            track,
            frame,
            work_object.as_ref(),
        )),
        (Some(rows), Some((track, values))) => {
            frame_label = rows.place_beside_track(&mut csv, track, values, &a.track);
            None
        }
        (Some(rows), None) => {
            frame_label = rows.place(&mut csv, &model, &a.track);
            None
        }
        (None, None) => None,
    };
    if on_track.is_some() || on_plate.is_some() {
        frame = TargetFrame::Base;
    }
    let in_work_object = match (&work_object, &on_track) {
        (Some(w), None) => Some(cell_solver.targets_in(
            w,
            csv.rows.iter_mut().filter_map(|r| r.target.as_mut().ok()),
        )),
        _ => None,
    };
    let solver = cell_solver.solver();
    let payload = solver.model().payload_kg;
    let options = SolveOptions {
        frame,
        position_only: a.position_only,
        branch,
        seed,
        false_target_convention: csv.convention,
    };
    let mut results: Vec<TargetResult> = csv.solve(solver, &options, a.path);
    if let Some(w) = &in_work_object {
        w.false_targets_back(&mut results);
    }
    if let Some(placed) = &on_track {
        placed.false_targets_back(&mut results);
    }
    let conv = csv.convention.unwrap_or(OrientationConvention::Quaternion);
    let header = Header {
        model: &a.model,
        frame: frame_label,
        convention: conv,
        payload_kg: payload,
        path: a.path,
        position_only: a.position_only,
        closed_form: solver.analytic().is_some(),
    };
    let format = if a.json { OutputFormat::Json } else { a.format };
    Ok(super::exit::Outcome {
        text: render(format, &header, &results, solver.model().dof()),
        not_done: results.iter().filter(|r| !r.solution.converged).count(),
        total: results.len(),
    })
}

/// `--tool` and `--work-object` from `--cell`.
fn cell_items(
    a: &SolveArgs,
) -> anyhow::Result<(
    Option<crate::solve::cell::Tool>,
    Option<crate::solve::cell::WorkObject>,
)> {
    let cell = super::model_files::load_cell(a.cell.as_deref())?;
    let tool = match &a.tool {
        Some(t) => Some(cell.tool(&t.parse::<CellRef>()?)?),
        None => None,
    };
    let work_object = match &a.work_object {
        Some(w) => Some(cell.work_object(&w.parse::<CellRef>()?)?),
        None => None,
    };
    Ok((tool, work_object))
}

/// The targets file's rows, the columns `beside` passed over (read as
/// external-axis values); a file without orientation columns is refused
/// unless `--position-only`.
fn read_targets(
    a: &SolveArgs,
    text: &str,
    dialect: crate::measure::csv_text::Dialect,
    beside: &[&str],
) -> anyhow::Result<crate::solve::ik::TargetsCsv> {
    let csv = parse_targets_csv_beside(text, dialect, beside).with_context(|| a.targets.clone())?;
    if csv.convention.is_none() && !a.position_only {
        bail!(
            "{}: no orientation columns ({CONVENTION_COLUMNS}); add them or pass --position-only",
            a.targets
        );
    }
    Ok(csv)
}

/// The results as `format` prints them.
fn render(format: OutputFormat, h: &Header, results: &[TargetResult], dof: usize) -> String {
    match format {
        OutputFormat::Json => render_json(h, results),
        OutputFormat::Table => render_table(h, results, dof),
        OutputFormat::Csv => results_csv(results, dof, h.convention),
    }
}

/// `--seed-deg` in the model's joint convention, checked against its joint count.
fn seed_joints(a: &SolveArgs, model: &CompensatedModel) -> anyhow::Result<Option<Vec<f64>>> {
    let Some(s) = &a.seed_deg else {
        return Ok(None);
    };
    let q = parse_seed(s)?;
    if q.len() != model.dof() {
        bail!(
            "--seed-deg needs {} joint values, got {}",
            model.dof(),
            q.len()
        );
    }
    Ok(Some(model.nominal.joints_from_controller(&q)))
}

/// A targets file's rows on a positioner: the positioner and each row's
/// values of its two axes [deg]. A turntable is the positioner whose axis 1
/// stands at 0 (`Turntable::as_tilt_rotate`), its one column the rotate's.
struct PlateRows {
    /// The positioner file.
    path: String,
    positioner: TiltRotate,
    /// The columns read: the tilt's and the rotate's (`positioner_columns`),
    /// or a turntable's one.
    columns: Vec<&'static str>,
    tilt: Vec<TargetValue>,
    rotate: Vec<TargetValue>,
}

impl PlateRows {
    /// Moves `csv`'s targets (face plate frame) into `model`'s base frame
    /// at each row's values (`model` carried to `--e1` by `track`, if
    /// given); the frame's name for the output's header.
    fn place(
        &self,
        csv: &mut crate::solve::ik::TargetsCsv,
        model: &CompensatedModel,
        track: &super::track::OnTrack,
    ) -> String {
        place_on_positioner(
            csv,
            &self.tilt,
            &self.rotate,
            &self.positioner,
            &model.cell_from_base,
        );
        track.label(self.label())
    }

    /// Moves `csv`'s targets (face plate frame) into the base frame of the
    /// robot carried by `track` to each row's `e1`, at each row's values.
    fn place_beside_track(
        &self,
        csv: &mut crate::solve::ik::TargetsCsv,
        track: &LinearTrack,
        values: &[TargetValue],
        on_track: &super::track::OnTrack,
    ) -> String {
        place_on_track_and_positioner(
            csv,
            values,
            track,
            &self.tilt,
            &self.rotate,
            &self.positioner,
        );
        on_track.label_per_row(self.label())
    }

    fn label(&self) -> String {
        match self.columns[..] {
            [tilt, rotate] => format!(
                "face plate of positioner {} at each row's {tilt} (tilt), {rotate} (rotate)",
                self.path
            ),
            _ => format!(
                "face plate of turntable {} at each row's {}",
                self.path, self.columns[0]
            ),
        }
    }
}

/// `--positioner FILE`: the positioner and the targets file's tilt and
/// rotate columns, both required: `e1`, `e2`, or beside a track
/// (`on_track`) `e2`, `e3`.
fn positioner_rows(
    path: &str,
    file: &str,
    text: &str,
    dialect: crate::measure::csv_text::Dialect,
    on_track: bool,
) -> anyhow::Result<PlateRows> {
    let positioner = super::positioner::read_positioner(path)?;
    let column = |name: &str, role: &str| -> anyhow::Result<Vec<TargetValue>> {
        target_column_values(text, dialect, name)
            .with_context(|| file.to_string())?
            .with_context(|| {
                format!("{file}: --positioner reads each row's {role} value [deg] from an `{name}` column, and the file has none")
            })
    };
    let columns = positioner_columns(on_track);
    Ok(PlateRows {
        path: path.to_string(),
        tilt: column(columns[0], "tilt (axis 1)")?,
        rotate: column(columns[1], "rotate (axis 2)")?,
        columns: columns.to_vec(),
        positioner,
    })
}

/// `--turntable FILE`: the turntable as the positioner whose axis 1 stands
/// at 0, and the targets file's column of its value, required: `e1`, or
/// `e2` beside a track (`on_track`).
fn turntable_rows(
    path: &str,
    file: &str,
    text: &str,
    dialect: crate::measure::csv_text::Dialect,
    on_track: bool,
) -> anyhow::Result<PlateRows> {
    let turntable = super::turntable::read_turntable(path)?;
    let name = if on_track { "e2" } else { "e1" };
    let rotate = target_column_values(text, dialect, name)
        .with_context(|| file.to_string())?
        .with_context(|| {
            format!("{file}: --turntable reads each row's value [deg] from an `{name}` column, and the file has none")
        })?;
    Ok(PlateRows {
        path: path.to_string(),
        tilt: TargetValue::held_at_zero(&rotate),
        rotate,
        columns: vec![name],
        positioner: turntable.as_tilt_rotate(),
    })
}

struct Header<'a> {
    model: &'a str,
    /// `cell`, `base` or `work object NAME`.
    frame: String,
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
                "compensation": r.compensation.as_ref().map(|c| c.label()),
                "warning": r.compensation.as_ref().and_then(|c| c.warning()),
                "expected_error_mm": r.compensation.as_ref().and_then(|c| c.expected_error_mm),
            })
        })
        .collect();
    let doc = json!({
        "model": h.model,
        "frame": h.frame,
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

/// Prints the results; the exit code says whether a target failed.
pub fn run(args: SolveArgs) -> anyhow::Result<super::exit::Exit> {
    let out = solve_outcome(&args)?;
    print!("{}", out.text);
    Ok(out.exit("targets", &args.failures))
}
