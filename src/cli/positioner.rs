//! `robocal positioner calibrate`: a two-axis tilt-rotate positioner fitted
//! from tracker readings of reflectors on its face plate (`positioner
//! simulate` writes such readings of an example positioner:
//! `super::positioner_sim`).
//!
//! `positioner calibrate SET… --nominal NOMINAL.json --reflector X,Y,Z…
//! --out POSITIONER.json` reads one measurement file per reflector
//! (docs/csv.md: the axes' values in degrees in two external-axis columns,
//! `e1` the tilt and `e2` the rotate axis by default, `x, y, z` in mm in
//! the tracker frame; no robot joints), the k-th file holding the readings
//! of the k-th `--reflector` (its design position on the face plate, mm,
//! face plate frame; the first is the reference whose azimuth defines axis
//! 2's zero). The nominal positioner (`model::external::TiltRotate`'s JSON:
//! what the controller computes from the drawing, and the frames the fit
//! states its lines in) is the start. It fits the positioner
//! (`calibrate::external::fit_positioner`), judges it as the core does,
//! writes the calibrated model's JSON (the same description as the nominal
//! file) and prints the report: both axes' lines, zero offsets and scales
//! with their σ, the residuals against their limits, each sweep's circle and
//! the reflectors' fitted positions. With `--validate FILE…` (the k-th file
//! held-out readings of reflector k) the held-out readings are predicted
//! through the fitted positioner: their RMS and maximum. A refused fit
//! writes nothing and exits with `refused` (1), printing its reason code and
//! message (with `--json` also the refusal as JSON on stdout). With
//! `--touched-with MODEL --cell CELL --tool NAME` the files are touches of
//! features with a calibrated tool (`super::positioner_touches`).
//!
//! `predict --positioner FILE` states the predicted poses in the
//! positioner's face plate frame at `--e1` (tilt) and `--e2` (rotate)
//! [deg], or at each row's `e1` and `e2` columns of the joints file
//! ([`OnPlate`]): `F(v)⁻¹·cell_from_base·pose`, the inverse of what `solve
//! --positioner` does (`solve::external::positioner`), where the tool is on
//! the part.

use super::judged_fit;
use super::positioner_touches::Touches;
use crate::service::positioners::{held_out, set_readings, HeldOut, ReadingsFrom};
use anyhow::Context;
use clap::{Args, Subcommand};
use robocal_core::calibrate::external::readings::PositionerColumns;
use robocal_core::calibrate::external::{
    fit_positioner, PositionerFit, PositionerFitRequest, PositionerReading, Refused,
};
use robocal_core::measure::csv_text::Dialect;
use robocal_core::measure::external::ExternalAxis;
use robocal_core::model::calibrated::CompensatedModel;
use robocal_core::model::external::{TiltRotate, Turntable};
use robocal_core::model::Pose;
use robocal_core::solve::cell::PredictFrame;
use robocal_core::solve::external::{
    base_from_part, positioner_columns, target_column_values, AxisValues, TargetValue,
};
use serde::Serialize;
use std::fmt::Write as _;

/// Arguments of `robocal positioner`.
#[derive(Debug, Args)]
pub struct PositionerArgs {
    /// The positioner subcommand to run.
    #[command(subcommand)]
    pub command: PositionerCommand,
}

/// The subcommands of `robocal positioner`.
#[derive(Debug, Subcommand)]
pub enum PositionerCommand {
    /// Fit a two-axis tilt-rotate positioner from tracker readings of reflectors on its face plate.
    Calibrate(CalibrateArgs),
    /// Write an example positioner's nominal model and simulated tracker readings (the files `calibrate` reads).
    Simulate(super::positioner_sim::SimulateArgs),
}

/// Arguments of `robocal positioner calibrate`.
#[derive(Debug, Args)]
pub struct CalibrateArgs {
    /// Measurement CSVs, one per reflector in the order of --reflector: the
    /// axes' values (degrees) in their columns and `x,y,z` (mm, tracker
    /// frame); each axis swept over ≥ 90° at ≥ 4 values with the other held.
    #[arg(required = true)]
    pub sets: Vec<String>,
    /// The nominal positioner (JSON, mm and degrees, the description this
    /// command writes): the start and the frames the fit is stated in.
    #[arg(long)]
    pub nominal: String,
    /// A reflector's design position on the face plate, `x,y,z` [mm, face
    /// plate frame], once per file; the first is the reference.
    #[arg(long, required = true, allow_hyphen_values = true)]
    pub reflector: Vec<String>,
    /// Where to write the calibrated positioner (JSON, mm, degrees).
    #[arg(long)]
    pub out: String,
    /// The tilt axis's (axis 1's) column, e1 … e6.
    #[arg(long, default_value = "e1", value_parser = parse_axis)]
    pub tilt_column: ExternalAxis,
    /// The rotate axis's (axis 2's) column, e1 … e6.
    #[arg(long, default_value = "e2", value_parser = parse_axis)]
    pub rotate_column: ExternalAxis,
    /// The readings' noise per coordinate, 1σ [mm]: the fit is judged
    /// against it (default: a tracker's 0.01; with --touched-with it must be
    /// given, the robot's accuracy at the tool's tip).
    #[arg(long)]
    pub sigma_mm: Option<f64>,
    /// The files are touches with a calibrated tool, not tracker readings:
    /// joints files (`q1…qN` controller degrees) with the axes' columns, one
    /// per feature touched, placed by this calibrated model carrying
    /// --tool of --cell.
    #[arg(long, requires_all = ["cell", "tool"])]
    pub touched_with: Option<String>,
    /// Cell file whose --tool touched the features.
    #[arg(long, requires = "touched_with")]
    pub cell: Option<String>,
    /// The touching tool (a name or number of --cell).
    #[arg(long, requires = "touched_with")]
    pub tool: Option<String>,
    /// Held-out readings (same columns), the k-th file of reflector k,
    /// predicted through the fitted positioner.
    #[arg(long)]
    pub validate: Vec<String>,
    /// Print the outcome as JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

pub(super) fn parse_axis(s: &str) -> Result<ExternalAxis, String> {
    ExternalAxis::ALL
        .into_iter()
        .find(|a| a.column().eq_ignore_ascii_case(s.trim()))
        .ok_or_else(|| format!("`{s}`: give an external-axis column, e1 … e6"))
}

/// The `--reflector` positions [mm], one per file of `sets`, and no more
/// `--validate` files than `sets` (a positioner's or a turntable's fit).
pub(super) fn reflectors_of(
    sets: &[String],
    reflector: &[String],
    validate: &[String],
) -> anyhow::Result<Vec<[f64; 3]>> {
    if reflector.len() != sets.len() {
        anyhow::bail!(
            "{} files and {} --reflector positions: give one design position per file (the file's reflector)",
            sets.len(),
            reflector.len()
        );
    }
    if validate.len() > sets.len() {
        anyhow::bail!(
            "{} --validate files for {} reflectors: the k-th holds reflector k's held-out readings",
            validate.len(),
            sets.len()
        );
    }
    reflector.iter().map(|s| parse_point(s)).collect()
}

/// `x,y,z` [mm] of a `--reflector`.
pub(super) fn parse_point(s: &str) -> anyhow::Result<[f64; 3]> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .ok()
        .filter(|v: &Vec<f64>| v.len() == 3 && v.iter().all(|x| x.is_finite()))
        .with_context(|| format!("--reflector `{s}`: give x,y,z in mm (three finite numbers)"))?;
    Ok([v[0], v[1], v[2]])
}

/// A fit the readings cannot carry: its reason and message (nothing is written).
#[derive(Debug, thiserror::Error)]
#[error("not fitted ({}): {}", judged_fit::code(&.0.reason), .0.message)]
pub struct PositionerNotFitted(pub Box<Refused>);

/// Held-out readings predicted through the fitted positioner [mm]: the
/// files and the figures the service gives for the same readings.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Validation {
    /// The held-out files, the k-th of reflector k.
    pub files: Vec<String>,
    /// Their readings' figures through the fitted positioner.
    #[serde(flatten)]
    pub held_out: HeldOut,
}

/// Every file's rows as readings of its reflector (the file's index);
/// with `touches`, each file's touches placed by the robot.
fn read_readings(
    files: &[String],
    columns: PositionerColumns,
    touches: Option<&Touches>,
) -> anyhow::Result<Vec<PositionerReading>> {
    let mut out = Vec::new();
    for (k, path) in files.iter().enumerate() {
        let text = std::fs::read_to_string(path).with_context(|| format!("cannot read {path}"))?;
        let read = match touches {
            Some(t) => t.readings(&text, columns, k),
            None => set_readings(&text, columns, k).map_err(anyhow::Error::from),
        };
        out.extend(read.with_context(|| path.clone())?);
    }
    Ok(out)
}

/// The held-out readings predicted through `model` at the fitted reflectors.
fn validate(
    files: &[String],
    columns: PositionerColumns,
    touches: Option<&Touches>,
    fit: &PositionerFit,
) -> anyhow::Result<Validation> {
    let readings = read_readings(files, columns, touches)?;
    let held_out = held_out(&readings, fit).context("--validate: no readings")?;
    Ok(Validation {
        files: files.to_vec(),
        held_out,
    })
}

/// Fits, judges, validates and writes the positioner; what the command prints.
pub fn calibrate_to_string(a: &CalibrateArgs) -> anyhow::Result<String> {
    let reflectors_mm = reflectors_of(&a.sets, &a.reflector, &a.validate)?;
    let text = std::fs::read_to_string(&a.nominal)
        .with_context(|| format!("cannot read nominal positioner {}", a.nominal))?;
    let nominal = TiltRotate::from_json(&text)
        .with_context(|| format!("nominal positioner {}", a.nominal))?;
    let columns = PositionerColumns {
        tilt: a.tilt_column,
        rotate: a.rotate_column,
    };
    let touches = match (&a.touched_with, &a.cell, &a.tool) {
        (Some(m), Some(c), Some(t)) => Some(Touches::read(m, c, t)?),
        _ => None,
    };
    let sigma_mm = match (a.sigma_mm, &touches) {
        (Some(s), _) => s,
        (None, None) => 0.01,
        (None, Some(_)) => anyhow::bail!(
            "--touched-with needs --sigma-mm: the touches' σ per coordinate is the robot's accuracy at the tool's tip (e.g. its validation RMS / √3), not a tracker's"
        ),
    };
    let request = PositionerFitRequest {
        nominal,
        reflectors_mm,
        readings: read_readings(&a.sets, columns, touches.as_ref())?,
        tracker_sigma_mm: sigma_mm,
    };
    let fit = match fit_positioner(&request) {
        Ok(f) => f,
        Err(refused) => {
            judged_fit::print_refusal(a.json, &judged_fit::code(&refused.reason), &refused)?;
            return Err(PositionerNotFitted(Box::new(refused)).into());
        }
    };
    let validation = if a.validate.is_empty() {
        None
    } else {
        Some(validate(&a.validate, columns, touches.as_ref(), &fit)?)
    };
    let written = judged_fit::write_fitted(
        "positioner",
        &a.out,
        fit.model.to_json(),
        Some(touches.as_ref().map_or(&ReadingsFrom::Tracker, |t| &t.from)),
        &fit,
        validation.as_ref(),
        a.json,
    )?;
    if let Some(json) = written {
        return Ok(json);
    }
    Ok(report(a, &request, &fit, validation.as_ref()))
}

fn report(
    a: &CalibrateArgs,
    request: &PositionerFitRequest,
    fit: &PositionerFit,
    v: Option<&Validation>,
) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "positioner fitted: {} readings of {} reflectors (tilt {}, rotate {}), nominal {}{}",
        request.readings.len(),
        request.reflectors_mm.len(),
        a.tilt_column,
        a.rotate_column,
        a.nominal,
        match (&a.touched_with, &a.tool) {
            (Some(m), Some(t)) => format!(", touches with tool {t} of {m}"),
            _ => String::new(),
        }
    );
    let d = &fit.description;
    for (axis, desc, sigma) in [
        ("axis 1 (tilt)", &d.tilt, &fit.sigma[0]),
        ("axis 2 (rotate)", &d.rotate, &fit.sigma[1]),
    ] {
        let [ux, uy, uz] = desc.direction;
        let [px, py, pz] = desc.point_mm;
        let _ = writeln!(
            s,
            "{axis}: direction [{ux:.6}, {uy:.6}, {uz:.6}] (σ {:.5} deg), point [{px:.4}, {py:.4}, {pz:.4}] mm (σ {:.4} mm); \
             zero offset {:.5} deg (σ {:.5}); scale {:.6} (σ {:.1e})",
            sigma.direction_deg,
            sigma.point_mm,
            desc.zero_offset_deg,
            sigma.zero_offset_deg,
            desc.scale,
            sigma.scale
        );
    }
    let l = &fit.limits;
    let _ = writeln!(
        s,
        "residuals: rms {:.4} mm, max {:.4} mm (limits: rms ≤ {:.4} mm, each ≤ {:.4} mm; σ {} mm per axis)",
        fit.rms_mm, fit.max_mm, l.rms_mm, l.max_mm, l.sigma_mm
    );
    let _ = writeln!(
        s,
        "solver: converged {}, {} iterations, start rms {:.4} mm",
        fit.solver.converged, fit.solver.iterations, fit.solver.start_rms_mm
    );
    let _ = writeln!(
        s,
        "sweeps (axis turned, reflector, other axis held at deg, values, span deg, radius mm, rms mm):"
    );
    for c in &fit.circles {
        let _ = writeln!(
            s,
            "  {}  {}  {:>8.3}  {:>3}  {:>7.2}  {:>9.3}  {:.4}",
            c.axis.name(),
            c.reflector + 1,
            c.held_deg,
            c.angles,
            c.span_deg,
            c.radius_mm,
            c.rms_mm
        );
    }
    let _ = writeln!(
        s,
        "reflectors on the face plate (design → fitted mm, σ mm):"
    );
    for (k, (design, got)) in request
        .reflectors_mm
        .iter()
        .zip(&fit.reflectors_mm)
        .enumerate()
    {
        let _ = writeln!(
            s,
            "  {}: [{:.3}, {:.3}, {:.3}] → [{:.4}, {:.4}, {:.4}], σ {:.4}",
            k + 1,
            design[0],
            design[1],
            design[2],
            got[0],
            got[1],
            got[2],
            fit.reflector_sigma_mm[k]
        );
    }
    if let Some(v) = v {
        let _ = writeln!(
            s,
            "held out: {} readings at {} pairs of axis values ({}): rms {:.4} mm, max {:.4} mm",
            v.held_out.readings,
            v.held_out.value_pairs,
            v.files.join(", "),
            v.held_out.rms_mm,
            v.held_out.max_mm
        );
    }
    let _ = writeln!(s, "written: {}", a.out);
    s
}

/// Runs `robocal positioner`.
pub fn run(a: PositionerArgs) -> anyhow::Result<()> {
    match a.command {
        PositionerCommand::Calibrate(c) => {
            print!("{}", calibrate_to_string(&c)?);
            Ok(())
        }
        PositionerCommand::Simulate(s) => {
            print!("{}", super::positioner_sim::simulate_to_string(&s)?);
            Ok(())
        }
    }
}

/// A positioner's axis values for `robocal predict --positioner`: one pair
/// for every row (`--e1`, `--e2`), or each row's `e1` and `e2` columns.
enum PlateValues {
    /// `--e1 DEG --e2 DEG`.
    Fixed(AxisValues),
    /// The joints file's columns, matched by line.
    PerRow {
        tilt: Vec<TargetValue>,
        rotate: Vec<TargetValue>,
    },
}

/// `robocal predict --positioner FILE`: the positioner and the axis values
/// each reading is stated at, its face plate frame being the output's.
pub struct OnPlate {
    path: String,
    positioner: TiltRotate,
    values: PlateValues,
    /// The tilt's and the rotate's columns (`positioner_columns`): `e1`,
    /// `e2`, or `e2`, `e3` beside a track; a turntable's one column twice.
    columns: [&'static str; 2],
    /// A one-axis turntable (`Turntable::as_tilt_rotate`): its value is
    /// axis 2's, axis 1 stands at 0.
    turntable: bool,
}

impl OnPlate {
    /// Reads the positioner file `path` and the values: the tilt and rotate
    /// flags together (`flags`: `--e1`, `--e2`; beside a track, `on_track`,
    /// `--e2`, `--e3`, the track's value being `--e1`), or (neither given)
    /// the joints file's columns of the same names; one flag alone, the
    /// flags beside such a column, or a file without both columns is
    /// refused.
    pub fn read(
        path: &str,
        flags: [Option<f64>; 2],
        on_track: bool,
        file: &str,
        text: &str,
        dialect: Dialect,
    ) -> anyhow::Result<OnPlate> {
        let positioner = read_positioner(path)?;
        let columns = positioner_columns(on_track);
        let [t_col, r_col] = columns;
        let [t_flag, r_flag] = columns.map(|c| format!("--{c}"));
        let tilt = target_column_values(text, dialect, t_col).with_context(|| file.to_string())?;
        let rotate =
            target_column_values(text, dialect, r_col).with_context(|| file.to_string())?;
        let values = match (flags, tilt, rotate) {
            ([Some(t), Some(r)], None, None) => {
                for (v, flag) in [(t, &t_flag), (r, &r_flag)] {
                    if !v.is_finite() || v.abs() > 720.0 {
                        anyhow::bail!("{flag} {v}: a positioner axis's value is a finite number of degrees within two turns (±720)");
                    }
                }
                PlateValues::Fixed(AxisValues {
                    tilt_deg: t,
                    rotate_deg: r,
                })
            }
            ([Some(_), Some(_)], _, _) => anyhow::bail!(
                "{file}: the file has an `{t_col}` or `{r_col}` column and {t_flag}, {r_flag} are given: ambiguous (give the flags or the columns)"
            ),
            ([None, None], Some(tilt), Some(rotate)) => PlateValues::PerRow { tilt, rotate },
            ([None, None], t, _) => {
                let name = if t.is_none() { t_col } else { r_col };
                anyhow::bail!(
                    "{file}: --positioner needs {t_flag} DEG {r_flag} DEG (tilt, rotate) or an `{t_col}` and an `{r_col}` column, and the file has no `{name}` column"
                )
            }
            _ => anyhow::bail!("--positioner needs both {t_flag} (tilt) and {r_flag} (rotate) [deg], or neither (each row's `{t_col}` and `{r_col}` columns)"),
        };
        Ok(OnPlate {
            path: path.to_string(),
            positioner,
            values,
            columns,
            turntable: false,
        })
    }

    /// The turntable of the file `path` and its value: the flag (`--e1`;
    /// beside a track, `on_track`, `--e2`) or (not given) the joints file's
    /// column of the same name; the flag beside such a column, or a file
    /// without it, is refused.
    pub fn read_turntable(
        path: &str,
        turntable: &Turntable,
        flag: Option<f64>,
        on_track: bool,
        file: &str,
        text: &str,
        dialect: Dialect,
    ) -> anyhow::Result<OnPlate> {
        let column = if on_track { "e2" } else { "e1" };
        let given =
            target_column_values(text, dialect, column).with_context(|| file.to_string())?;
        let values = match (flag, given) {
            (Some(v), None) => {
                if !v.is_finite() || v.abs() > 720.0 {
                    anyhow::bail!("--{column} {v}: a turntable's value is a finite number of degrees within two turns (±720)");
                }
                PlateValues::Fixed(AxisValues {
                    tilt_deg: 0.0,
                    rotate_deg: v,
                })
            }
            (Some(_), Some(_)) => anyhow::bail!(
                "{file}: the file has an `{column}` column and --{column} is given: ambiguous (give the flag or the column)"
            ),
            (None, Some(rotate)) => PlateValues::PerRow {
                tilt: TargetValue::held_at_zero(&rotate),
                rotate,
            },
            (None, None) => anyhow::bail!(
                "{file}: --turntable needs --{column} DEG or an `{column}` column, and the file has none"
            ),
        };
        Ok(OnPlate {
            path: path.to_string(),
            positioner: turntable.as_tilt_rotate(),
            values,
            columns: [column, column],
            turntable: true,
        })
    }

    /// The frame's name for the output's header.
    pub fn label(&self) -> String {
        let [t, r] = self.columns;
        if self.turntable {
            return match &self.values {
                PlateValues::Fixed(v) => format!(
                    "face plate of turntable {} at {r} {} deg",
                    self.path, v.rotate_deg
                ),
                PlateValues::PerRow { .. } => {
                    format!("face plate of turntable {} at each row's {r}", self.path)
                }
            };
        }
        match &self.values {
            PlateValues::Fixed(v) => format!(
                "face plate of positioner {} at {t} (tilt) {} deg, {r} (rotate) {} deg",
                self.path, v.tilt_deg, v.rotate_deg
            ),
            PlateValues::PerRow { .. } => format!(
                "face plate of positioner {} at each row's {t} (tilt), {r} (rotate)",
                self.path
            ),
        }
    }

    /// The face plate at row `line`'s values in `model`'s base frame,
    /// `robot.cell_from_base⁻¹·F(v)` (a pose predicted in it is
    /// `F(v)⁻¹·cell_from_base·pose`; beside a track `model` is carried to
    /// the row's value, so `F(v)⁻¹·B(e)·pose`), or the row's error naming
    /// its line and column.
    pub fn frame_at(&self, line: usize, model: &CompensatedModel) -> Result<PredictFrame, String> {
        let values = match &self.values {
            PlateValues::Fixed(v) => *v,
            PlateValues::PerRow { tilt, rotate } => {
                let at = |values: &[TargetValue], column: &str| {
                    values.iter().find(|v| v.line == line).map_or_else(
                        || Err(format!("line {line}: column `{column}`: no value")),
                        |v| v.value.clone().map_err(|e| e.to_string()),
                    )
                };
                AxisValues {
                    tilt_deg: at(tilt, self.columns[0])?,
                    rotate_deg: at(rotate, self.columns[1])?,
                }
            }
        };
        Ok(PredictFrame::WorkObject(base_from_part(
            model,
            &self.positioner,
            values,
            &Pose::identity(),
        )))
    }
}

/// A positioner description file (`model::external::positioner`, JSON).
pub(crate) fn read_positioner(path: &str) -> anyhow::Result<TiltRotate> {
    let json = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read positioner file {path}"))?;
    TiltRotate::from_json(&json).with_context(|| format!("positioner file {path}"))
}
