//! `robocal track calibrate` and the `--track`/`--e1` options of `predict`
//! and `solve`: a robot on a linear track (`robocal track simulate`,
//! `super::track_sim`, writes files to try them on).
//!
//! `track calibrate SET --model MODEL --out TRACK.json` reads a measurement
//! file with the track's column (`e1` by default; docs/csv.md: controller
//! joints in degrees, the track's value in mm as the controller shows it,
//! `x, y, z` in mm in the tracker frame): the reflector read at several
//! robot poses at each of several track values. It fits the track with the
//! robot's calibrated model held
//! (`calibrate::external::track::fit_track_compensated`), judges it, writes
//! the track model's JSON (`model::external::TrackDescription`) and prints
//! the fit report: residuals and limits, each carriage map's order with its
//! leave-one-station-out RMS, the stations, and the terms the readings cannot
//! see. With `--validate SET` a second file at other track values is
//! predicted through the fitted track: the held-out figures. A refused fit
//! writes nothing and exits with `refused` (1), printing its reason code and
//! message (with `--json` also the refusal as JSON on stdout).
//!
//! `predict` and `solve` with `--track TRACK.json --e1 MM` carry the robot's
//! base to that track value (`solve::external::carried`): the cell frame is
//! the track's (the tracker frame it was measured in); a value outside the
//! travel measured is refused (exit 1). `predict --track` and `solve
//! --track` without `--e1` read each row's value from the joints or targets
//! file's `e1` column (`solve::external::track_values`,
//! `solve::external::target_track_values`; a row beyond the travel fails
//! alone); `--e1` and such a column together are refused as ambiguous.

use super::judged_fit;
use super::model_files::load_with_payload;
use anyhow::Context;
use clap::{Args, Subcommand};
use robocal_core::calibrate::external::track::{
    fit_track_compensated, TrackFit, TrackRefused, DEFAULT_MAX_ORDER,
};
use robocal_core::measure::csv::parse_set;
use robocal_core::measure::csv_text::Dialect;
use robocal_core::measure::external::{ExternalAxis, MeasurementSet};
use robocal_core::model::calibrated::CompensatedModel;
use robocal_core::model::external::travel_map::MAX_MAP_ORDER;
use robocal_core::model::external::LinearTrack;
use robocal_core::solve::external::{
    carried, target_track_values, track_values, RowValue, TargetValue, TRACK_COLUMN,
};
use serde::Serialize;
use std::fmt::Write as _;

/// Arguments of `robocal track`.
#[derive(Debug, Args)]
pub struct TrackArgs {
    /// The track subcommand to run.
    #[command(subcommand)]
    pub command: TrackCommand,
}

/// The subcommands of `robocal track`.
#[derive(Debug, Subcommand)]
pub enum TrackCommand {
    /// Fit a linear track carrying the robot from tracker readings at several track values.
    Calibrate(CalibrateArgs),
    /// Write a robot on an example 4 m track measured by a simulated tracker (the files `calibrate` reads).
    Simulate(super::track_sim::SimulateArgs),
}

/// Arguments of `robocal track calibrate`.
#[derive(Debug, Args)]
pub struct CalibrateArgs {
    /// Measurement CSV with the track's column: `q1..qN` (controller degrees),
    /// `e1` (the track's value, mm), `x,y,z` (mm, tracker frame); the robot
    /// at ≥ 3 poses not on a line at each of ≥ 5 track values.
    pub set: String,
    /// The robot's calibrated model file (`robocal calibrate --save`), held by the fit.
    #[arg(long)]
    pub model: String,
    /// Where to write the track model (JSON, mm, degrees, arcsec).
    #[arg(long)]
    pub out: String,
    /// The track's column, e1 … e6.
    #[arg(long, default_value = "e1", value_parser = parse_axis)]
    pub column: ExternalAxis,
    /// The tracker's noise per coordinate, 1σ [mm]: the fit is judged against it.
    #[arg(long, default_value_t = 0.01)]
    pub sigma_mm: f64,
    /// Highest order of the carriage maps tried (0: a straight rail).
    #[arg(long, default_value_t = DEFAULT_MAX_ORDER)]
    pub max_order: usize,
    /// Payload mass [kg] of rows that give none (default: the model file's).
    #[arg(long)]
    pub payload_kg: Option<f64>,
    /// Held-out readings at other track values (same columns), predicted
    /// through the fitted track.
    #[arg(long)]
    pub validate: Option<String>,
    /// Print the outcome as JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

pub(crate) fn parse_axis(s: &str) -> Result<ExternalAxis, String> {
    ExternalAxis::ALL
        .into_iter()
        .find(|a| a.column().eq_ignore_ascii_case(s.trim()))
        .ok_or_else(|| format!("`{s}`: give the track's column, e1 … e6"))
}

/// `--track FILE --e1 MM` of `predict` and `solve`.
#[derive(Debug, Clone, Default, Args)]
pub struct OnTrack {
    /// Track model (`robocal track calibrate --out`): the robot's base is
    /// carried to `--e1` along it (without `--e1`: to each row's `e1`
    /// column of the joints or targets file), and the cell frame is the
    /// track's.
    #[arg(long)]
    pub track: Option<String>,
    /// The track's value [mm] as the controller shows it (within the travel
    /// the track was measured over); in `predict --positioner`, the
    /// positioner's tilt (axis 1) value [deg].
    #[arg(long, requires = "external_axis", allow_hyphen_values = true)]
    pub e1: Option<f64>,
}

impl OnTrack {
    /// `model` with its base carried to `--e1` (unchanged without `--track`;
    /// `--track` without `--e1` is refused).
    pub fn carry(&self, model: CompensatedModel) -> anyhow::Result<CompensatedModel> {
        let (Some(path), Some(value)) = (&self.track, self.e1) else {
            if self.track.is_some() {
                anyhow::bail!(
                    "--track needs --e1 MM, the track's value for every row, or an `{TRACK_COLUMN}` column in the file"
                );
            }
            return Ok(model);
        };
        let track = read_track(path)?;
        carried(&model, &track, value).with_context(|| format!("--e1 {value}: track {path}"))
    }

    /// A track value per row of a joints file `file` (its text `text`):
    /// with `--track` and no `--e1`, the track and the file's `e1` column
    /// (refused when the file has none); `None` otherwise. `--e1` and an
    /// `e1` column together are refused as ambiguous.
    pub fn per_row(
        &self,
        file: &str,
        text: &str,
        dialect: Dialect,
    ) -> anyhow::Result<Option<(LinearTrack, Vec<RowValue>)>> {
        if self.track.is_none() {
            return Ok(None);
        }
        let values = track_values(text, dialect).with_context(|| file.to_string())?;
        self.choose(file, values)
    }

    /// A track value per row of a targets file `file` (its text `text`), as
    /// [`Self::per_row`] for joints; a row's value that is not a number is
    /// that row's failure. Without `--track` a file with an `e1` column is
    /// refused: its rows would be solved as if the track stood still.
    pub fn per_target(
        &self,
        file: &str,
        text: &str,
        dialect: Dialect,
    ) -> anyhow::Result<Option<(LinearTrack, Vec<TargetValue>)>> {
        let values = target_track_values(text, dialect).with_context(|| file.to_string())?;
        if self.track.is_none() {
            if values.is_some() {
                anyhow::bail!(
                    "{file}: the file has an `{TRACK_COLUMN}` column (a track value per target): give --track FILE to carry the robot to each row's value"
                );
            }
            return Ok(None);
        }
        self.choose(file, values)
    }

    /// With `--track`: the track and the file's values when the file has
    /// them and `--e1` is not given; `None` with `--e1` alone; refused with
    /// both (ambiguous) or neither (no value).
    fn choose<T>(&self, file: &str, values: Option<T>) -> anyhow::Result<Option<(LinearTrack, T)>> {
        let Some(path) = &self.track else {
            return Ok(None);
        };
        match (self.e1, values) {
            (Some(v), Some(_)) => anyhow::bail!(
                "{file}: the file has an `{TRACK_COLUMN}` column and --e1 {v} is given: which track value holds is ambiguous; give one or the other"
            ),
            (Some(_), None) => Ok(None),
            (None, None) => anyhow::bail!(
                "{file}: --track without --e1 reads each row's track value from an `{TRACK_COLUMN}` column, and the file has none: add the column (mm) or give --e1 MM"
            ),
            (None, Some(values)) => Ok(Some((read_track(path)?, values))),
        }
    }

    /// `frame` as the output's header names it with a track value per row.
    pub fn label_per_row(&self, frame: String) -> String {
        match &self.track {
            Some(path) => format!("{frame} (track {path} at each row's e1)"),
            None => frame,
        }
    }

    /// `frame` as the output's header names it.
    pub fn label(&self, frame: String) -> String {
        match (&self.track, self.e1) {
            (Some(path), Some(v)) => format!("{frame} (track {path} at e1 = {v} mm)"),
            _ => frame,
        }
    }
}

/// Reads and checks a track model file.
pub fn read_track(path: &str) -> anyhow::Result<LinearTrack> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read track file {path}"))?;
    LinearTrack::from_json(&text).with_context(|| format!("track file {path}"))
}

fn read_set(path: &str) -> anyhow::Result<MeasurementSet> {
    let text = std::fs::read_to_string(path).with_context(|| format!("cannot read {path}"))?;
    parse_set(&text).with_context(|| path.to_string())
}

/// A fit the readings cannot carry: its reason and message (nothing is written).
#[derive(Debug, thiserror::Error)]
#[error("not fitted ({}): {}", judged_fit::code(&.0.reason), .0.message)]
pub struct TrackNotFitted(pub TrackRefused);

/// Held-out readings predicted through the fitted track [mm].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Validation {
    /// The held-out measurement file.
    pub file: String,
    /// Its readings, each predicted at its track value.
    pub readings: usize,
    /// The distinct track values of the readings [mm].
    pub values_mm: Vec<f64>,
    /// RMS of the readings' position errors, measured − predicted [mm].
    pub rms_mm: f64,
    /// Largest of those position errors [mm].
    pub max_mm: f64,
}

/// The held-out set's readings predicted through `track` and `model`.
fn validate(
    path: &str,
    model: &CompensatedModel,
    track: &LinearTrack,
    column: ExternalAxis,
) -> anyhow::Result<Validation> {
    let set = read_set(path)?;
    let mut errors = Vec::with_capacity(set.poses.len());
    let mut values: Vec<f64> = Vec::new();
    for (i, r) in set.readings().enumerate() {
        let row = i + 1;
        let v = r
            .external
            .get(column)
            .with_context(|| format!("{path}: reading {row} has no value of `{column}`"))?;
        let base = track
            .cell_from_base(v)
            .with_context(|| format!("{path}: reading {row}"))?;
        if r.pose.q_deg.len() != model.dof() {
            anyhow::bail!(
                "{path}: reading {row} has {} joint values, the robot has {}",
                r.pose.q_deg.len(),
                model.dof()
            );
        }
        let ctrl: Vec<f64> = r.pose.q_deg.iter().map(|d| d.to_radians()).collect();
        let q = model.nominal.joints_from_controller(&ctrl);
        let kg = r.pose.payload_kg.unwrap_or(model.payload_kg);
        let p = model
            .predict_detailed_at(&q, kg)
            .with_context(|| format!("{path}: reading {row}"))?
            .pose
            .p;
        let at = base.transform_point(&p) * 1e3;
        errors.push((at - nalgebra::Vector3::from(r.pose.xyz_mm)).norm());
        if !values.contains(&v) {
            values.push(v);
        }
    }
    if errors.is_empty() {
        anyhow::bail!("{path}: no readings");
    }
    values.sort_by(f64::total_cmp);
    let (rms_mm, max_mm) = judged_fit::rms_and_max_mm(&errors);
    Ok(Validation {
        file: path.to_string(),
        readings: errors.len(),
        values_mm: values,
        rms_mm,
        max_mm,
    })
}

/// Fits, judges, validates and writes the track; what the command prints.
pub fn calibrate_to_string(a: &CalibrateArgs) -> anyhow::Result<String> {
    if a.max_order > MAX_MAP_ORDER {
        anyhow::bail!("--max-order: at most {MAX_MAP_ORDER}");
    }
    let model = load_with_payload(&a.model, a.payload_kg)?;
    let set = read_set(&a.set)?;
    let fit = match fit_track_compensated(&model, &set, a.column, a.sigma_mm, a.max_order) {
        Ok(f) => f,
        Err(refused) => {
            judged_fit::print_refusal(a.json, &judged_fit::code(&refused.reason), &refused)?;
            return Err(TrackNotFitted(refused).into());
        }
    };
    let validation = match &a.validate {
        Some(path) => Some(validate(path, &model, &fit.model, a.column)?),
        None => None,
    };
    let written = judged_fit::write_fitted(
        "track",
        &a.out,
        fit.model.to_json(),
        None,
        &fit,
        validation.as_ref(),
        a.json,
    )?;
    if let Some(json) = written {
        return Ok(json);
    }
    Ok(report(a, &set, &fit, validation.as_ref()))
}

fn report(
    a: &CalibrateArgs,
    set: &MeasurementSet,
    fit: &TrackFit,
    v: Option<&Validation>,
) -> String {
    let d = &fit.description;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "track fitted: {} readings at {} track values ({}), robot {} held",
        set.poses.len(),
        fit.stations.len(),
        a.column,
        a.model
    );
    let [dx, dy, dz] = d.direction;
    let [px, py, pz] = d.point_mm;
    let [rx, ry, rz] = d.mount_rpy_deg;
    let _ = writeln!(
        s,
        "rail: direction [{dx:.6}, {dy:.6}, {dz:.6}], point [{px:.4}, {py:.4}, {pz:.4}] mm; \
         scale {:.6} ({:+.4} mm/m); zero {:.4} mm; travel [{}, {}] mm",
        d.scale,
        (d.scale - 1.0) * 1e3,
        d.zero_mm,
        d.travel_mm[0],
        d.travel_mm[1]
    );
    let _ = writeln!(s, "mount: rpy [{rx:.5}, {ry:.5}, {rz:.5}] deg");
    let l = &fit.limits;
    let _ = writeln!(
        s,
        "residuals: rms {:.4} mm, max {:.4} mm (limits: rms ≤ {:.4} mm, each ≤ {:.4} mm; σ {} mm per axis)",
        fit.rms_mm, fit.max_mm, l.rms_mm, l.max_mm, l.sigma_mm
    );
    let _ = writeln!(
        s,
        "carriage maps (order chosen by leave-one-station-out cross-validation; held-out rms per order):"
    );
    for m in &fit.maps {
        let cands: Vec<String> = m
            .candidates
            .iter()
            .map(|c| format!("{}:{:.4}", c.order, c.cv_rms))
            .collect();
        let _ = writeln!(
            s,
            "  {}: order {}, amplitude {:.4} {u}, stations' rms about it {:.4} {u}, station σ {:.4} {u}; held out {}",
            m.term.name(),
            m.order,
            m.amplitude,
            m.rms,
            m.station_sigma,
            cands.join(" "),
            u = m.unit
        );
    }
    let _ = writeln!(
        s,
        "stations (value mm, poses, rigid-fit rms mm, misfit along/lateral/vertical mm, roll/pitch/yaw arcsec):"
    );
    for st in &fit.stations {
        let m = st.misfit;
        let _ = writeln!(
            s,
            "  {:>10}  {:>3}  {:.4}  {:+.4} {:+.4} {:+.4}  {:+.2} {:+.2} {:+.2}",
            st.value_mm, st.poses, st.rms_mm, m[0], m[1], m[2], m[3], m[4], m[5]
        );
    }
    let _ = writeln!(s, "not seen by these readings:");
    for u in &fit.unseen {
        let _ = writeln!(s, "  {}: {}", judged_fit::code(&u.term), u.note);
    }
    if let Some(v) = v {
        let values: Vec<String> = v.values_mm.iter().map(|x| format!("{x}")).collect();
        let _ = writeln!(
            s,
            "held out: {} readings of {} at track values {} mm: rms {:.4} mm, max {:.4} mm",
            v.readings,
            v.file,
            values.join(", "),
            v.rms_mm,
            v.max_mm
        );
    }
    let _ = writeln!(s, "written: {}", a.out);
    s
}

/// Runs `robocal track`.
pub fn run(a: TrackArgs) -> anyhow::Result<()> {
    match a.command {
        TrackCommand::Calibrate(c) => {
            print!("{}", calibrate_to_string(&c)?);
            Ok(())
        }
        TrackCommand::Simulate(s) => {
            print!("{}", super::track_sim::simulate_to_string(&s)?);
            Ok(())
        }
    }
}
