//! `robocal predict`: joint readings → the pose of the measured point or of a
//! production tool: the forward half of `robocal solve`, on the same
//! calibrated, compensated model (`core::cell::predict`).
//!
//! The joints file (`core::cell::joints_csv`): optional `id` and `q1..qN`,
//! controller readings in degrees; other columns (a measurements file's
//! `x, y, z, …`) are ignored. Output per reading: the pose in the
//! measurement (cell) frame (or `--frame base`, or `--work-object NAME`),
//! `x, y, z` [mm] and fixed-axis XYZ `rx, ry, rz` [deg] (`R = Rz·Ry·Rx`),
//! with `--convention` the orientation in a solve convention too, the joints
//! outside the controller's limits, the compensation flag and the
//! compensator's expected error as `solve` reports them. The expected error at
//! the tool (`core::cell::accuracy`) heads the output: measured on 6-D
//! validation data, or `unverified` for a tool after a position-only
//! calibration, never the measured point's figure for a tool. With
//! `--track FILE --e1 MM` the robot's base is carried along a calibrated
//! track and the cell frame is the track's (`super::track`); with `--track`
//! alone each row's track value is the joints file's `e1` column (a value
//! beyond the track's travel fails its row alone). With `--positioner FILE
//! --e1 DEG --e2 DEG` (or each row's `e1`, `e2` columns) the poses are in
//! the positioner's face plate frame at those values (`super::positioner::
//! OnPlate`): `F(v)⁻¹·cell_from_base·pose`. With both, `--track FILE
//! --positioner FILE`, the robot rides the track beside the positioner
//! (both in the track's cell frame): `e1` the track's value, `e2`, `e3` the
//! positioner's, as flags or columns: `F(v)⁻¹·B(e)·pose`.

use super::solve::OutputFormat;
use crate::measure::csv_text::dialect_from_names;
use crate::model::orientation::OrientationConvention;
use crate::solve::cell::accuracy::{measurement_tool_accuracy, tool_accuracy, ToolAccuracy};
use crate::solve::cell::joints_csv::parse_joints_csv;
use crate::solve::cell::{CellRef, Forward, PoseOut, PredictFrame, Predicted};
use crate::solve::ik::TargetFrame;
use anyhow::Context;
use clap::Args;
use robocal_core::csv_write::{push_header, push_row, Cell as CsvCell};
use robocal_core::model::calibrated::CalibratedModelFile;
use robocal_core::model::calibrated::CompensatedModel;
use robocal_core::model::calibrated::ValidationEvidence;
use robocal_core::solve::external::carried;
use serde_json::json;
use std::fmt::Write as _;

/// Arguments of `robocal predict`.
#[derive(Debug, Args)]
#[command(group = clap::ArgGroup::new("external_axis").multiple(true).args(["track", "positioner", "turntable"]))]
#[command(group = clap::ArgGroup::new("plate").args(["positioner", "turntable"]))]
pub struct PredictArgs {
    /// Robot model: a calibrated model file (`robocal calibrate --save`), a
    /// model JSON file or a preset (ys100, hh800, ur5, ur10).
    #[arg(long)]
    pub model: String,
    /// Joints CSV: optional `id` and `q1..qN` (controller readings, degrees).
    #[arg(long)]
    pub joints: String,
    /// Cell file (tools and work objects) that --tool and --work-object name from.
    #[arg(long)]
    pub cell: Option<String>,
    /// Production tool on the calibrated flange: a name or number of the cell
    /// file (default: the measured point, the model's own tool).
    #[arg(long, requires = "cell")]
    pub tool: Option<String>,
    /// Work object (name or number of the cell file) the poses are given in.
    #[arg(long, requires = "cell")]
    pub work_object: Option<String>,
    /// Frame of the poses: cell (measurement frame of the calibration) or base.
    #[arg(long, default_value = "cell")]
    pub frame: String,
    /// The orientation in this solve convention too (quaternion, kuka_abc,
    /// fanuc_wpr, matrix, ur_rotvec, abb_q1q4).
    #[arg(long)]
    pub convention: Option<String>,
    /// Payload mass [kg] (default: the model file's payload, or the tool's load).
    #[arg(long)]
    pub payload_kg: Option<f64>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = OutputFormat::Table)]
    pub format: OutputFormat,
    /// Same as `--format json`.
    #[arg(long, conflicts_with = "format")]
    pub json: bool,
    /// Field delimiter of the joints file: `,`, `;` or `tab` (default: detected).
    #[arg(long)]
    pub delimiter: Option<String>,
    /// Decimal separator of the joints file: `point` or `comma` (default: detected).
    #[arg(long)]
    pub decimal: Option<String>,
    /// `--allow-failures`: the exit code when some rows fail.
    #[command(flatten)]
    pub failures: super::exit::AllowFailures,
    /// `--track FILE --e1 MM`: the robot carried along a linear track.
    #[command(flatten)]
    pub track: super::track::OnTrack,
    /// Calibrated positioner (`robocal positioner calibrate --out`, in the
    /// robot's measurement frame): the poses are stated in its face plate
    /// frame at `--e1` (tilt) and `--e2` (rotate) [deg], or at each row's
    /// `e1` and `e2` columns; beside --track (in the track's cell frame) at
    /// `--e2` (tilt) and `--e3` (rotate) or each row's `e2`, `e3`, the
    /// track's value `--e1` or each row's `e1`.
    #[arg(long, conflicts_with_all = ["work_object", "frame"])]
    pub positioner: Option<String>,
    /// Calibrated one-axis turntable (`robocal turntable calibrate --out`,
    /// in the robot's measurement frame): the poses are stated in its face
    /// plate frame at `--e1` [deg] or each row's `e1`; beside --track at
    /// `--e2` or each row's `e2`, the track's value `--e1` or each row's `e1`.
    #[arg(long, conflicts_with_all = ["work_object", "frame", "positioner"])]
    pub turntable: Option<String>,
    /// The positioner's rotate (axis 2) value [deg], beside `--e1` its tilt;
    /// beside --track, its tilt (axis 1), or a turntable's value.
    #[arg(long, requires = "plate", allow_hyphen_values = true)]
    pub e2: Option<f64>,
    /// Beside --track: the positioner's rotate (axis 2) value [deg].
    #[arg(long, requires_all = ["positioner", "track"], allow_hyphen_values = true)]
    pub e3: Option<f64>,
}

/// The validation evidence of a calibrated model file (none for presets and
/// model descriptions).
fn evidence(path: &str) -> Option<ValidationEvidence> {
    let text = std::fs::read_to_string(path).ok()?;
    CalibratedModelFile::from_json(&text).ok()?.validation
}

struct Row {
    id: String,
    joints_deg: Vec<f64>,
    result: Result<Predicted, String>,
}

/// Runs the command and returns what it prints.
pub fn predict_to_string(a: &PredictArgs) -> anyhow::Result<String> {
    predict_outcome(a).map(|o| o.text)
}

/// `--positioner`: the positioner and the values each reading is stated at,
/// read from the flags or the joints file's columns (`--e1`, `--e2`; beside
/// `--track`, `--e2`, `--e3`, the track's value `--e1`).
fn on_plate(
    a: &PredictArgs,
    text: &str,
    dialect: crate::measure::csv_text::Dialect,
) -> anyhow::Result<Option<super::positioner::OnPlate>> {
    let on_track = a.track.track.is_some();
    let flags = if on_track {
        [a.e2, a.e3]
    } else {
        [a.track.e1, a.e2]
    };
    if let Some(path) = &a.turntable {
        if !on_track && a.e2.is_some() {
            anyhow::bail!(
                "--e2: a turntable has one axis, its value is --e1 (--e2 beside --track)"
            );
        }
        let turntable = super::turntable::read_turntable(path)?;
        return super::positioner::OnPlate::read_turntable(
            path, &turntable, flags[0], on_track, &a.joints, text, dialect,
        )
        .map(Some);
    }
    a.positioner
        .as_ref()
        .map(|path| {
            super::positioner::OnPlate::read(path, flags, on_track, &a.joints, text, dialect)
        })
        .transpose()
}

/// Where each reading is predicted: one forward model, or (a track value
/// per row) one per distinct value, or why a value has none.
struct Placed {
    forward: Forward,
    frame: PredictFrame,
}

/// What the command prints and how many readings failed.
pub fn predict_outcome(a: &PredictArgs) -> anyhow::Result<super::exit::Outcome> {
    let loaded = super::model_files::load_with_payload(&a.model, a.payload_kg)?;
    let text = std::fs::read_to_string(&a.joints)
        .with_context(|| format!("cannot read joints file {}", a.joints))?;
    let dialect = dialect_from_names(a.delimiter.as_deref(), a.decimal.as_deref())
        .map_err(anyhow::Error::msg)?;
    let plate = on_plate(a, &text, dialect)?;
    // `--track` without `--e1`: each row's value from the file's `e1` column.
    let per_row = a.track.per_row(&a.joints, &text, dialect)?;
    let model = match per_row {
        Some(_) => loaded,
        None => a.track.carry(loaded)?,
    };
    let frame: TargetFrame = a.frame.parse().map_err(anyhow::Error::msg)?;
    let conv = a
        .convention
        .as_deref()
        .map(OrientationConvention::from_name)
        .transpose()
        .map_err(|e| anyhow::anyhow!("--convention: {e}"))?;
    let cell = super::model_files::load_cell(a.cell.as_deref())?;
    let tool = match &a.tool {
        Some(t) => Some(cell.tool(&t.parse::<CellRef>()?)?),
        None => None,
    };
    let ev = evidence(&a.model);
    let probe = crate::model::kinematics::chain::tool_pose(&model.calibrated);
    let accuracy = match &tool {
        Some(t) => tool_accuracy(ev.as_ref(), &probe, &t.tcp),
        None => measurement_tool_accuracy(ev.as_ref()),
    };
    let wobj = match &a.work_object {
        Some(w) => Some(cell.work_object(&w.parse::<CellRef>()?)?),
        None => None,
    };
    let place = |model: &CompensatedModel| {
        let forward = Forward::new(
            model,
            tool.as_ref().map(|t| &t.tcp),
            tool.as_ref().and_then(|t| t.load.as_ref()),
        );
        let frame = match &wobj {
            None => PredictFrame::Frame(frame),
            Some(w) => PredictFrame::WorkObject(w.in_base(forward.model())),
        };
        Placed { forward, frame }
    };
    let frame_label = match (&plate, &wobj) {
        (Some(p), _) => p.label(),
        (None, Some(w)) => format!("work object {}", w.name),
        (None, None) => frame.to_string(),
    };
    let frame_label = match (&per_row, &wobj) {
        (_, Some(_)) => frame_label,
        (Some(_), None) => a.track.label_per_row(frame_label),
        (None, None) => a.track.label(frame_label),
    };
    let one = place(&model);
    let dof = model.dof();
    let readings = parse_joints_csv(&text, dialect, dof).with_context(|| a.joints.clone())?;
    // Per row: one placement per distinct track value, a value beyond the
    // travel failing its rows alone.
    let mut at: Vec<(f64, Result<Placed, String>)> = Vec::new();
    if let Some((track, values)) = &per_row {
        for v in values {
            if !at.iter().any(|(x, _)| *x == v.value_mm) {
                let placed = carried(&model, track, v.value_mm)
                    .map(|m| place(&m))
                    .map_err(|e| e.to_string());
                at.push((v.value_mm, placed));
            }
        }
    }
    let value_of = |line: usize| {
        per_row
            .as_ref()
            .and_then(|(_, values)| values.iter().find(|v| v.line == line))
            .map(|v| v.value_mm)
    };
    let rows: Vec<Row> = readings
        .into_iter()
        .map(|r| {
            let placed = match value_of(r.line) {
                None => Ok(&one),
                Some(v) => at
                    .iter()
                    .find(|(x, _)| *x == v)
                    .map(|(_, p)| p.as_ref().map_err(|e| format!("line {}: e1: {e}", r.line)))
                    .unwrap_or(Ok(&one)),
            };
            Row {
                result: placed.and_then(|p| {
                    // On a positioner: the face plate at the row's values.
                    let frame = match &plate {
                        None => p.frame,
                        Some(plate) => plate.frame_at(r.line, p.forward.model())?,
                    };
                    p.forward
                        .predict_deg(&r.joints_deg, &frame)
                        .map_err(|e| format!("line {}: {e}", r.line))
                }),
                id: r.id,
                joints_deg: r.joints_deg,
            }
        })
        .collect();
    let forward = one.forward;
    let h = Header {
        model: &a.model,
        tool: tool.as_ref().map(|t| t.name.as_str()),
        frame: frame_label,
        payload_kg: forward.model().payload_kg,
        accuracy,
        conv,
        dof,
    };
    Ok(rendered(a, &h, &rows))
}

/// What the command prints of `rows`, in the format asked for, and how many
/// readings failed.
fn rendered(a: &PredictArgs, h: &Header, rows: &[Row]) -> super::exit::Outcome {
    let format = if a.json { OutputFormat::Json } else { a.format };
    let text = match format {
        OutputFormat::Json => render_json(h, rows),
        OutputFormat::Table => render_table(h, rows),
        OutputFormat::Csv => render_csv(h, rows),
    };
    super::exit::Outcome {
        text,
        not_done: rows.iter().filter(|r| r.result.is_err()).count(),
        total: rows.len(),
    }
}

struct Header<'a> {
    model: &'a str,
    tool: Option<&'a str>,
    frame: String,
    payload_kg: f64,
    accuracy: ToolAccuracy,
    conv: Option<OrientationConvention>,
    dof: usize,
}

/// `status, mean, max` of the accuracy as CSV fields.
fn accuracy_fields(a: &ToolAccuracy) -> [CsvCell; 3] {
    match a {
        ToolAccuracy::Measured {
            mean_mm, max_mm, ..
        } => [
            CsvCell::text("measured"),
            CsvCell::num(*mean_mm),
            CsvCell::num(*max_mm),
        ],
        ToolAccuracy::Unverified { .. } => [
            CsvCell::text("unverified"),
            CsvCell::empty(),
            CsvCell::empty(),
        ],
        ToolAccuracy::Unknown { .. } => {
            [CsvCell::text("unknown"), CsvCell::empty(), CsvCell::empty()]
        }
    }
}

fn accuracy_line(a: &ToolAccuracy, tool: Option<&str>) -> String {
    let at = tool.map_or("the measured point".to_string(), |t| format!("tool {t}"));
    match a {
        ToolAccuracy::Measured {
            poses,
            mean_mm,
            max_mm,
            from_orientation,
        } => format!(
            "expected error at {at}: {mean_mm:.3} mm mean, {max_mm:.3} mm max over {poses} validation poses{}",
            if *from_orientation { " (6-D: position + orientation × lever arm)" } else { "" }
        ),
        ToolAccuracy::Unverified { message } => format!("expected error at {at}: unverified: {message}"),
        ToolAccuracy::Unknown { message } => format!("expected error at {at}: unknown: {message}"),
    }
}

/// The output columns and one row's fields.
fn columns(h: &Header) -> Vec<String> {
    let mut c = vec!["id".to_string()];
    c.extend((1..=h.dof).map(|k| format!("j{k}_deg")));
    c.extend(["x_mm", "y_mm", "z_mm", "rx_deg", "ry_deg", "rz_deg"].map(String::from));
    if let Some(conv) = h.conv {
        c.extend(conv.column_names().iter().map(|s| s.to_string()));
    }
    c.extend(
        [
            "outside_limits",
            "compensation",
            "warning",
            "expected_error_mm",
            "message",
        ]
        .map(String::from),
    );
    c
}

/// One row's cells: numbers as numbers, texts as texts.
fn fields(h: &Header, r: &Row) -> Vec<CsvCell> {
    let mut f = vec![CsvCell::text(&r.id)];
    f.extend(r.joints_deg.iter().map(|v| CsvCell::num(*v)));
    let n_ori = h.conv.map_or(0, |c| c.n_values());
    match &r.result {
        Ok(p) => {
            let o = PoseOut::of(&p.pose, h.conv);
            f.extend(
                o.xyz_mm
                    .iter()
                    .chain(&o.rxyz_deg)
                    .map(|v| CsvCell::fixed(*v, 6)),
            );
            if let Some((_, v)) = &o.orientation {
                f.extend(v.iter().map(|v| CsvCell::fixed(*v, 9)));
            }
            let c = p.compensation.as_ref();
            f.push(CsvCell::text(
                p.outside_limits
                    .iter()
                    .map(|j| format!("J{j}"))
                    .collect::<Vec<_>>()
                    .join(" "),
            ));
            f.push(CsvCell::text(c.map(|c| c.label()).unwrap_or_default()));
            f.push(CsvCell::text(
                c.and_then(|c| c.warning()).unwrap_or_default(),
            ));
            f.push(
                c.and_then(|c| c.expected_error_mm)
                    .map_or_else(CsvCell::empty, CsvCell::num),
            );
            f.push(CsvCell::empty());
        }
        Err(e) => {
            f.extend((0..6 + n_ori + 4).map(|_| CsvCell::empty()));
            f.push(CsvCell::text(e));
        }
    }
    f
}

/// The CSV: numbers as numbers, every text as `csv_write` writes it.
fn render_csv(h: &Header, rows: &[Row]) -> String {
    let mut cols = columns(h);
    cols.extend(["tool_accuracy", "tool_error_mean_mm", "tool_error_max_mm"].map(String::from));
    let acc = accuracy_fields(&h.accuracy);
    let mut out = String::new();
    push_header(&mut out, &cols);
    for r in rows {
        let mut f = fields(h, r);
        f.extend(acc.iter().cloned());
        push_row(&mut out, &f);
    }
    out
}

fn render_table(h: &Header, rows: &[Row]) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "# robocal predict: model {}, {}, poses in the {} frame, payload {} kg",
        h.model,
        h.tool
            .map_or("the measured point".to_string(), |t| format!("tool {t}")),
        h.frame,
        h.payload_kg
    );
    let _ = writeln!(out, "# {}", accuracy_line(&h.accuracy, h.tool));
    let _ = writeln!(
        out,
        "# joints: controller convention [deg]; x, y, z [mm]; rx, ry, rz fixed-axis XYZ [deg]"
    );
    let mut table = vec![columns(h)];
    table.extend(rows.iter().map(|r| {
        fields(h, r)
            .iter()
            .map(|c| match c.shown() {
                "" => "-".to_string(),
                v => v.to_string(),
            })
            .collect()
    }));
    let widths: Vec<usize> = (0..table[0].len())
        .map(|c| table.iter().map(|r| r[c].len()).max().unwrap_or(0))
        .collect();
    for r in &table {
        let line: Vec<String> = r
            .iter()
            .zip(&widths)
            .map(|(v, w)| format!("{v:>w$}"))
            .collect();
        let _ = writeln!(out, "{}", line.join("  ").trim_end());
    }
    out
}

fn render_json(h: &Header, rows: &[Row]) -> String {
    let results: Vec<serde_json::Value> = rows
        .iter()
        .map(|r| match &r.result {
            Ok(p) => {
                let o = PoseOut::of(&p.pose, h.conv);
                let c = p.compensation.as_ref();
                json!({
                    "id": r.id, "status": "ok", "joints_deg": r.joints_deg,
                    "x": o.xyz_mm[0], "y": o.xyz_mm[1], "z": o.xyz_mm[2],
                    "rx": o.rxyz_deg[0], "ry": o.rxyz_deg[1], "rz": o.rxyz_deg[2],
                    "orientation": o.orientation.map(|(c, v)| json!({"convention": c.name(), "values": v})),
                    "outside_limits": p.outside_limits,
                    "compensation": c.map(|c| c.label()),
                    "warning": c.and_then(|c| c.warning()),
                    "expected_error_mm": c.and_then(|c| c.expected_error_mm),
                })
            }
            Err(e) => json!({"id": r.id, "status": "failed", "joints_deg": r.joints_deg, "message": e}),
        })
        .collect();
    let doc = json!({
        "model": h.model,
        "tool": h.tool,
        "frame": h.frame,
        "payload_kg": h.payload_kg,
        "accuracy": h.accuracy,
        "readings": rows.len(),
        "results": results,
    });
    serde_json::to_string_pretty(&doc).expect("JSON output serialises") + "\n"
}

/// Prints the poses; the exit code says whether a reading failed.
pub fn run(args: PredictArgs) -> anyhow::Result<super::exit::Exit> {
    let out = predict_outcome(&args)?;
    print!("{}", out.text);
    Ok(out.exit("readings", &args.failures))
}
