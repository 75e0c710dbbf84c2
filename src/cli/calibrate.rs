//! `robocal calibrate`: identify calibrated models from measurement CSVs and
//! print the comparison of methods (like the thesis's Tables 2.5/2.6) with the
//! identifiability report, or the same as JSON. With `--track-column e1` the
//! files are a robot on a linear track read at several track values, each
//! value a tracker session of its own (`MeasurementSet::stations_as_sessions`).

mod render;

pub use render::{render_comparison, render_compensators, render_orientation, render_report};

use super::progress::ProgressPrinter;
use crate::calibrate::compensate::select::Parallelism;
use crate::calibrate::identify::{
    calibrate_with_training, CalibrationOptions, CalibrationReport, CalibrationSettings, Method,
    PoseSource, PoseSources, METHODS,
};
use crate::measure::{self, csv, SetRole};
use crate::model::RobotModel;
use anyhow::{bail, Context};
use clap::builder::{PossibleValue, TypedValueParser};
use clap::error::ErrorKind;
use clap::Args;

/// Arguments of `robocal calibrate`.
#[derive(Debug, Args)]
pub struct CalibrateArgs {
    /// Robot model: a preset name (ys100, hh800, ur5, ur10) or a model JSON file.
    #[arg(long)]
    pub model: String,
    /// Identification measurements (CSV), one or more files (repeat the option
    /// or separate with commas). Each file is its own tracker session unless
    /// its rows carry a `session` column. Rows whose `set` column says
    /// validation are moved to the validation set, rows that say training to
    /// the compensator training pool.
    #[arg(long, required = true, num_args = 1.., value_delimiter = ',')]
    pub identify: Vec<String>,
    /// Validation measurements (CSV), never used for fitting. With as many
    /// files as --identify, the N-th belongs to the N-th file's session;
    /// otherwise to the first session (a `session` column overrides both).
    #[arg(long, num_args = 1.., value_delimiter = ',')]
    pub validate: Vec<String>,
    /// Compensator training measurements (CSV, the Q2 pool), never used by the
    /// model-based fit. Without them the compensators train on the
    /// identification poses and are judged by k-fold cross-validation there.
    /// Each row belongs to the session of its `session` column, else to the
    /// first session.
    #[arg(long, num_args = 1.., value_delimiter = ',')]
    pub train: Vec<String>,
    /// Methods to run and compare, comma-separated (names or aliases, any
    /// case); `all` runs every one and prints the comparison table (rows
    /// methods, columns sets).
    #[arg(long, value_parser = MethodValues, default_value_t = MethodList(Method::THESIS.to_vec()))]
    pub method: MethodList,
    /// Payload mass [kg] for rows without a payload_kg column (default: the model's payload).
    #[arg(long)]
    pub payload_kg: Option<f64>,
    /// Random seed of the TLBO search and of the compensators' training.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Folds of the compensators' cross-validation on the training pool
    /// (0: none for the explicit methods; `auto` then uses 5).
    #[arg(long, default_value_t = 5)]
    pub cv_folds: usize,
    /// Spatially blocked folds run with the cross-validation (regions of joint
    /// space held out; `auto` rejects a compensator worse on any); 0: none.
    #[arg(long, default_value_t = 4)]
    pub blocked_folds: usize,
    /// `auto`'s options whose cross-validated means differ by less than this
    /// fraction are a tie, broken by the blocked folds, the max, the base that
    /// models more physics, then fewer fitted quantities.
    #[arg(long, default_value_t = 0.05)]
    pub tie_margin: f64,
    /// Threads a cross-validation's trainings run on (0: the cores
    /// available); the results are the same for any count.
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// TLBO population and generations.
    #[arg(long, default_value_t = 50)]
    pub population: usize,
    /// TLBO generations.
    #[arg(long, default_value_t = 100)]
    pub generations: usize,
    /// Keep the measurement frame as given (data already in the robot base frame).
    #[arg(long)]
    pub no_register: bool,
    /// Tracker-data files with x_dif columns: measured = target + dif (plus) or − dif (minus).
    #[arg(long, default_value = "plus")]
    pub dif_sign: String,
    /// Convention of the files' `rx, ry, rz` columns (`qw, qx, qy, qz` columns are
    /// recognised as a quaternion without it; default fixed_xyz).
    #[arg(long, value_parser = super::orientation_arg::OrientationValues)]
    pub orientation: Option<crate::measure::convention::MeasuredOrientation>,
    /// The robot stands on a linear track and every file carries the
    /// track's column (e1 … e6, mm): each track value is a station, its own
    /// tracker session (there the base stands still in the tracker's
    /// frame), so the robot is identified over every station. `robocal
    /// track calibrate` then fits the track with the saved model.
    #[arg(long, value_parser = super::track::parse_axis)]
    pub track_column: Option<crate::measure::external::ExternalAxis>,
    /// Print the full report as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Write the report as one self-contained HTML page to this file.
    #[arg(long)]
    pub html: Option<String>,
    /// Write the calibrated model of the best method (or of --save-method) to this file.
    #[arg(long)]
    pub save: Option<String>,
    /// Method whose model --save writes (default: best validation mean).
    #[arg(long)]
    pub save_method: Option<String>,
}

/// The methods of `--method`, in order, each once.
#[derive(Debug, Clone, PartialEq)]
pub struct MethodList(pub Vec<Method>);

impl std::fmt::Display for MethodList {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let names: Vec<&str> = self.0.iter().map(|m| m.name()).collect();
        f.write_str(&names.join(","))
    }
}

/// Parses `--method` ([`Method::parse_list`]); its possible values are the
/// table's names and `all`.
#[derive(Debug, Clone, Copy)]
struct MethodValues;

impl TypedValueParser for MethodValues {
    type Value = MethodList;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<MethodList, clap::Error> {
        let text = value.to_string_lossy();
        Method::parse_list(&text).map(MethodList).map_err(|e| {
            let arg = arg.map_or_else(|| "--method".to_string(), |a| a.to_string());
            clap::Error::raw(
                ErrorKind::InvalidValue,
                format!("invalid value '{text}' for '{arg}': {e}\n"),
            )
            .with_cmd(cmd)
        })
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        let methods = METHODS.iter().map(|r| {
            PossibleValue::new(r.name)
                .aliases(r.aliases.iter().copied())
                .help(format!("{} Fits {}.", r.description, r.fits))
        });
        let all = PossibleValue::new("all").help("Every method, and the comparison table.");
        Some(Box::new(methods.chain(std::iter::once(all))))
    }
}

/// The rows of one file; with `--track-column`, each in its station's session.
fn read_rows(
    a: &CalibrateArgs,
    path: &str,
    read: csv::ReadOptions,
) -> anyhow::Result<Vec<measure::MeasuredPose>> {
    let path = std::path::Path::new(path);
    match a.track_column {
        Some(axis) => super::orientation_arg::read_stations(path, read, axis),
        None => super::orientation_arg::read_measurements(path, read),
    }
}

/// Measured rows of one role, each with its tracker-session label.
type Labelled = Vec<(String, measure::MeasuredPose)>;

/// The rows of every file by role, each with its session label, and where
/// each came from (file name, 1-based data row, session) for the report.
struct RowsByRole {
    identification: Labelled,
    validation: Labelled,
    training: Labelled,
    sources: PoseSources,
}

/// Calibrates with every method asked for and prints the report (text, or JSON with
/// `--json`), writing the HTML report and the saved model when asked.
pub fn run(a: CalibrateArgs) -> anyhow::Result<()> {
    let (model, note) = super::model_files::load_start_model(&a.model)?;
    if let Some(note) = note {
        eprintln!("{note}");
    }
    let read = read_options(&a)?;
    if let Some(p) = a.payload_kg {
        if !(p.is_finite() && p >= 0.0) {
            bail!("--payload-kg must be a non-negative number, got {p}");
        }
    }
    let payload = a.payload_kg.unwrap_or(model.payload.mass);
    let rows = read_rows_by_role(&a, read, &model)?;
    let sessions = sessions_of(&rows, a.track_column)?;
    let ident = to_si(&rows.identification, &sessions, &model, payload);
    let valid = to_si(&rows.validation, &sessions, &model, payload);
    let training = to_si(&rows.training, &sessions, &model, payload);
    let opts = calibration_options(&a);
    let progress = ProgressPrinter::stderr(!a.json);
    let report = calibrate_with_training(&model, &ident, &training, &valid, &opts, &|p| {
        progress.update(p);
        true
    });
    progress.finish();
    let mut report = report?;
    report.pose_sources = rows.sources;
    report.session_names = sessions;
    write_outputs(&a, &model, &report, payload)
}

/// How the measurement files are read: `--dif-sign` and `--orientation`.
fn read_options(a: &CalibrateArgs) -> anyhow::Result<csv::ReadOptions> {
    let dif = match a.dif_sign.as_str() {
        "plus" => csv::DifSign::Plus,
        "minus" => csv::DifSign::Minus,
        other => bail!("--dif-sign must be plus or minus, got {other}"),
    };
    Ok(csv::ReadOptions {
        dif,
        orientation: a.orientation,
        ..csv::ReadOptions::default()
    })
}

/// Reads the `--identify`, `--train` and `--validate` files (in that order)
/// and labels each row with its tracker session: the `session` column, else
/// the file's (module docs of the options).
fn read_rows_by_role(
    a: &CalibrateArgs,
    read: csv::ReadOptions,
    model: &RobotModel,
) -> anyhow::Result<RowsByRole> {
    let label = |file: usize| format!("file {}", file + 1);
    let source = |path: &str, k: usize, session: &str| PoseSource {
        set: file_name(path),
        row: k + 1,
        session: session.to_string(),
    };
    let mut out = RowsByRole {
        identification: Vec::new(),
        validation: Vec::new(),
        training: Vec::new(),
        sources: PoseSources::default(),
    };
    for (i, path) in a.identify.iter().enumerate() {
        let rows = read_rows(a, path, read)?;
        csv::check_joint_count(&rows, model.dof()).with_context(|| path.clone())?;
        for (k, r) in rows.into_iter().enumerate() {
            let s = r.session.clone().unwrap_or_else(|| label(i));
            match r.set {
                Some(SetRole::Training) => {
                    out.sources.training.push(source(path, k, &s));
                    out.training.push((s, r));
                }
                // Check rows are scored like validation rows, never fitted.
                Some(SetRole::Validation | SetRole::Check) => {
                    out.sources.validation.push(source(path, k, &s));
                    out.validation.push((s, r));
                }
                _ => {
                    out.sources.identification.push(source(path, k, &s));
                    out.identification.push((s, r));
                }
            }
        }
    }
    for path in &a.train {
        let more = read_rows(a, path, read)?;
        csv::check_joint_count(&more, model.dof()).with_context(|| path.clone())?;
        for (k, r) in more.into_iter().enumerate() {
            let s = r.session.clone().unwrap_or_else(|| label(0));
            out.sources.training.push(source(path, k, &s));
            out.training.push((s, r));
        }
    }
    let same_count = a.validate.len() == a.identify.len();
    for (j, path) in a.validate.iter().enumerate() {
        let more = read_rows(a, path, read)?;
        csv::check_joint_count(&more, model.dof()).with_context(|| path.clone())?;
        let own = label(if same_count { j } else { 0 });
        for (k, r) in more.into_iter().enumerate() {
            let s = r.session.clone().unwrap_or_else(|| own.clone());
            out.sources.validation.push(source(path, k, &s));
            out.validation.push((s, r));
        }
    }
    Ok(out)
}

/// The tracker sessions in order of their first identification row; an
/// error when validation or training rows come from a session without
/// identification rows (its frame could not be registered). With a track
/// (`--track-column`) a session is a station, and the message says so.
fn sessions_of(
    rows: &RowsByRole,
    track: Option<crate::measure::external::ExternalAxis>,
) -> anyhow::Result<Vec<String>> {
    let mut sessions: Vec<String> = Vec::new();
    for (s, _) in &rows.identification {
        if !sessions.contains(s) {
            sessions.push(s.clone());
        }
    }
    let unregistered = rows
        .validation
        .iter()
        .chain(&rows.training)
        .find(|(s, _)| !sessions.contains(s));
    if let (Some(axis), Some((s, _))) = (track, unregistered) {
        bail!(
            "readings at station `{s}` are for validation or training only: with --track-column {axis} every station needs identification readings, which fit its frame; readings at track values never fitted validate the track (`robocal track calibrate --validate`)"
        );
    }
    if let Some((s, _)) = rows.validation.iter().find(|(s, _)| !sessions.contains(s)) {
        bail!(
            "validation rows of tracker session `{s}` have no identification rows in that session, so its frame cannot be registered; measure identification poses in that session too"
        );
    }
    if let Some((s, _)) = rows.training.iter().find(|(s, _)| !sessions.contains(s)) {
        bail!(
            "training rows of tracker session `{s}` have no identification rows in that session, so its frame cannot be registered; measure identification poses in that session too"
        );
    }
    Ok(sessions)
}

/// The rows in SI units, each with the index of its session in `sessions`.
fn to_si(
    rows: &[(String, measure::MeasuredPose)],
    sessions: &[String],
    model: &RobotModel,
    payload: f64,
) -> Vec<measure::Measurement> {
    rows.iter()
        .map(|(s, r)| {
            let mut m = r.to_measurement(model, payload);
            m.session = sessions.iter().position(|x| x == s).unwrap_or(0);
            m
        })
        .collect()
}

/// The calibration's options from the command line.
/// The command line's calibration settings (the core's defaults for what it
/// does not set) and the options they build, on `--threads` threads.
fn calibration_options(a: &CalibrateArgs) -> CalibrationOptions {
    let settings = CalibrationSettings {
        methods: a.method.0.clone(),
        register: !a.no_register,
        seed: a.seed,
        population: a.population,
        generations: a.generations,
        cv_folds: a.cv_folds,
        blocked_folds: a.blocked_folds,
        tie_margin: a.tie_margin,
        ..CalibrationSettings::default()
    };
    settings.options(Parallelism { threads: a.threads })
}

/// Writes what was asked for: the HTML page (`--html`), the chosen model
/// (`--save`), and the report on stdout as JSON (`--json`) or text.
fn write_outputs(
    a: &CalibrateArgs,
    model: &RobotModel,
    report: &CalibrationReport,
    payload: f64,
) -> anyhow::Result<()> {
    if let Some(path) = &a.html {
        let files: Vec<String> = a.identify.iter().map(|p| file_name(p)).collect();
        let title = format!("Calibration of {}", files.join(", "));
        let html = crate::report::render_html(&title, &serde_json::to_value(report)?);
        std::fs::write(path, html).with_context(|| format!("cannot write {path}"))?;
    }
    if let Some(path) = &a.save {
        save_model(model, report, a.save_method.as_deref(), payload, path)?;
    }
    if a.json {
        println!("{}", serde_json::to_string_pretty(report)?);
    } else {
        print!("{}", render_report(report));
    }
    Ok(())
}

fn file_name(path: &str) -> String {
    std::path::Path::new(path)
        .file_name()
        .map_or_else(|| path.to_string(), |n| n.to_string_lossy().into_owned())
}

fn save_model(
    nominal: &RobotModel,
    report: &CalibrationReport,
    method: Option<&str>,
    payload: f64,
    path: &str,
) -> anyhow::Result<()> {
    let chosen = match method {
        Some(m) => {
            let m = Method::parse(m).with_context(|| format!("unknown --save-method {m}"))?;
            match report.methods.get(&m) {
                Some(r) => r,
                None => match report.failed.iter().find(|f| f.method == m) {
                    Some(f) => bail!("--save-method {} failed: {}", m.name(), f.reason),
                    None => bail!("--save-method {} was not run", m.name()),
                },
            }
        }
        None => report.best_method().context("no method ran")?,
    };
    let label = chosen.model_file_method();
    let file = crate::calibrate::identify::calibrated_model_file(
        report,
        chosen,
        nominal,
        &nominal.name,
        payload,
    )
    .map_err(|e| anyhow::anyhow!("the {label} model does not load back: {e}"))?;
    super::model_files::save_model_file(&file, std::path::Path::new(path))?;
    eprintln!("saved the {label} model to {path}");
    Ok(())
}
