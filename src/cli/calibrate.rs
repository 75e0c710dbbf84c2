//! `robocal calibrate`: identify calibrated models from measurement CSVs and
//! print the comparison of methods (like the thesis's Tables 2.5/2.6) with the
//! identifiability report, or the same as JSON.

use super::progress::ProgressPrinter;
use crate::calibrate::identify::{
    calibrate_with_training, CalibrationOptions, CalibrationReport, CompensatorOptions, Method,
    PoseSource, PoseSources, SetErrors, METHODS,
};
use crate::measure::{self, csv, SetRole};
use crate::model::RobotModel;
use crate::report::method_label;
use anyhow::{bail, Context};
use clap::builder::{PossibleValue, TypedValueParser};
use clap::error::ErrorKind;
use clap::Args;
use std::fmt::Write as _;

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
    /// TLBO population and generations.
    #[arg(long, default_value_t = 50)]
    pub population: usize,
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

fn read_rows(path: &str, read: csv::ReadOptions) -> anyhow::Result<Vec<measure::MeasuredPose>> {
    super::orientation_arg::read_measurements(std::path::Path::new(path), read)
}

pub fn run(a: CalibrateArgs) -> anyhow::Result<()> {
    let (model, note) = super::model_files::load_start_model(&a.model)?;
    if let Some(note) = note {
        eprintln!("{note}");
    }
    let methods = a.method.0;
    let dif = match a.dif_sign.as_str() {
        "plus" => csv::DifSign::Plus,
        "minus" => csv::DifSign::Minus,
        other => bail!("--dif-sign must be plus or minus, got {other}"),
    };
    let read = csv::ReadOptions {
        dif,
        orientation: a.orientation,
        ..csv::ReadOptions::default()
    };
    if let Some(p) = a.payload_kg {
        if !(p.is_finite() && p >= 0.0) {
            bail!("--payload-kg must be a non-negative number, got {p}");
        }
    }
    let payload = a.payload_kg.unwrap_or(model.payload.mass);
    // Rows with their tracker-session label: the `session` column, else the file's.
    let label = |file: usize| format!("file {}", file + 1);
    let mut ident_rows: Vec<(String, measure::MeasuredPose)> = Vec::new();
    let mut valid_rows: Vec<(String, measure::MeasuredPose)> = Vec::new();
    // Each pose's source (file name, 1-based data row, session) for the report.
    let (mut ident_src, mut valid_src) = (Vec::new(), Vec::new());
    let source = |path: &str, k: usize, session: &str| PoseSource {
        set: file_name(path),
        row: k + 1,
        session: session.to_string(),
    };
    let (mut train_rows, mut train_src) = (Vec::new(), Vec::new());
    for (i, path) in a.identify.iter().enumerate() {
        let rows = read_rows(path, read)?;
        csv::check_joint_count(&rows, model.dof()).with_context(|| path.clone())?;
        for (k, r) in rows.into_iter().enumerate() {
            let s = r.session.clone().unwrap_or_else(|| label(i));
            match r.set {
                Some(SetRole::Training) => {
                    train_src.push(source(path, k, &s));
                    train_rows.push((s, r));
                }
                // Check rows are scored like validation rows, never fitted.
                Some(SetRole::Validation | SetRole::Check) => {
                    valid_src.push(source(path, k, &s));
                    valid_rows.push((s, r));
                }
                _ => {
                    ident_src.push(source(path, k, &s));
                    ident_rows.push((s, r));
                }
            }
        }
    }
    for path in &a.train {
        let more = read_rows(path, read)?;
        csv::check_joint_count(&more, model.dof()).with_context(|| path.clone())?;
        for (k, r) in more.into_iter().enumerate() {
            let s = r.session.clone().unwrap_or_else(|| label(0));
            train_src.push(source(path, k, &s));
            train_rows.push((s, r));
        }
    }
    let same_count = a.validate.len() == a.identify.len();
    for (j, path) in a.validate.iter().enumerate() {
        let more = read_rows(path, read)?;
        csv::check_joint_count(&more, model.dof()).with_context(|| path.clone())?;
        let own = label(if same_count { j } else { 0 });
        for (k, r) in more.into_iter().enumerate() {
            let s = r.session.clone().unwrap_or_else(|| own.clone());
            valid_src.push(source(path, k, &s));
            valid_rows.push((s, r));
        }
    }
    let mut sessions: Vec<String> = Vec::new();
    for (s, _) in &ident_rows {
        if !sessions.contains(s) {
            sessions.push(s.clone());
        }
    }
    if let Some((s, _)) = valid_rows.iter().find(|(s, _)| !sessions.contains(s)) {
        bail!(
            "validation rows of tracker session `{s}` have no identification rows in that session, so its frame cannot be registered; measure identification poses in that session too"
        );
    }
    if let Some((s, _)) = train_rows.iter().find(|(s, _)| !sessions.contains(s)) {
        bail!(
            "training rows of tracker session `{s}` have no identification rows in that session, so its frame cannot be registered; measure identification poses in that session too"
        );
    }
    let to_si = |rows: &[(String, measure::MeasuredPose)]| -> Vec<measure::Measurement> {
        rows.iter()
            .map(|(s, r)| {
                let mut m = r.to_measurement(&model, payload);
                m.session = sessions.iter().position(|x| x == s).unwrap_or(0);
                m
            })
            .collect()
    };
    let ident = to_si(&ident_rows);
    let valid = to_si(&valid_rows);
    let training = to_si(&train_rows);
    let opts = CalibrationOptions {
        methods,
        register: !a.no_register,
        tlbo: crate::optim::TlboSettings {
            population: a.population,
            generations: a.generations,
            seed: a.seed,
        },
        compensator: CompensatorOptions {
            seed: a.seed,
            cv_folds: a.cv_folds,
            blocked_folds: a.blocked_folds,
            ..Default::default()
        },
        ..Default::default()
    };
    let progress = ProgressPrinter::stderr(!a.json);
    let report = calibrate_with_training(&model, &ident, &training, &valid, &opts, &|p| {
        progress.update(p);
        true
    });
    progress.finish();
    let mut report = report?;
    report.pose_sources = PoseSources {
        identification: ident_src,
        validation: valid_src,
        training: train_src,
    };
    report.session_names = sessions.clone();
    if let Some(path) = &a.html {
        let files: Vec<String> = a.identify.iter().map(|p| file_name(p)).collect();
        let title = format!("Calibration of {}", files.join(", "));
        let html = crate::report::render_html(&title, &serde_json::to_value(&report)?);
        std::fs::write(path, html).with_context(|| format!("cannot write {path}"))?;
    }
    if let Some(path) = &a.save {
        save_model(&model, &report, a.save_method.as_deref(), payload, path)?;
    }
    if a.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{}", render_report(&report));
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

/// The text report: accuracy table, identifiability, parameters, stiffness.
/// A parameter value in its display unit, one format per unit: lengths and
/// angles with 6 decimals (0.001 µm, 1e-6 deg), compliances in scientific
/// notation, masses with 3 decimals.
fn param_number(v: f64, unit: &str) -> String {
    match unit {
        "rad/(N·m)" => format!("{v:.4e}"),
        "kg" => format!("{v:.3}"),
        _ => format!("{v:.6}"),
    }
}

pub fn render_report(r: &CalibrationReport) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "robot {}: {} identification poses, {} validation poses",
        r.robot, r.identification_poses, r.validation_poses
    );
    for reg in &r.registration {
        let t = &reg.tracker_to_base;
        let _ = writeln!(
            s,
            "registration (session {}): tracker->base xyz [{:.3}, {:.3}, {:.3}] mm, rpy [{:.4}, {:.4}, {:.4}] deg, nominal RMS {:.3} mm",
            reg.session, t.xyz_mm[0], t.xyz_mm[1], t.xyz_mm[2], t.rpy_deg[0], t.rpy_deg[1], t.rpy_deg[2], reg.rms_mm
        );
    }
    let _ = writeln!(s, "\nAbsolute position accuracy (mm)");
    let _ = writeln!(
        s,
        "{:<22} {:>8} {:>8} {:>8} {:>8} {:>8}   {:>8} {:>8} {:>8} {:>8} {:>8}",
        "", "id mean", "max", "std", "rms", "p95", "val mean", "max", "std", "rms", "p95"
    );
    let mut line =
        |label: &str, id: &crate::stats::ErrorStats, va: Option<&crate::stats::ErrorStats>| {
            let _ = write!(
                s,
                "{:<22} {:>8.4} {:>8.4} {:>8.4} {:>8.4} {:>8.4}",
                label, id.mean_mm, id.max_mm, id.std_mm, id.rms_mm, id.p95_mm
            );
            if let Some(v) = va {
                let _ = write!(
                    s,
                    "   {:>8.4} {:>8.4} {:>8.4} {:>8.4} {:>8.4}",
                    v.mean_mm, v.max_mm, v.std_mm, v.rms_mm, v.p95_mm
                );
            }
            let _ = writeln!(s);
        };
    line(
        "Nominal robot model",
        &r.nominal.identification.stats,
        r.nominal.validation.as_ref().map(|v| &v.stats),
    );
    for (name, m) in &r.methods {
        line(
            method_label(*name),
            &m.identification.stats,
            m.validation.as_ref().map(|v| &v.stats),
        );
    }
    let _ = write!(s, "{}", render_comparison(r));
    let _ = write!(s, "{}", render_orientation(r));
    let _ = write!(s, "{}", render_compensators(r));
    let id = &r.identifiability;
    let _ = writeln!(
        s,
        "\nIdentifiability: {} parameters kept of {} candidates (rank {}), condition number {:.2}, observability O1 {:.4}",
        id.kept.len(), id.candidates, id.rank, id.condition_number, id.observability_o1
    );
    for d in &id.dropped {
        if d.depends_on.is_empty() {
            let _ = writeln!(s, "  dropped {:<8} {}", d.name, d.reason);
        } else {
            let _ = writeln!(
                s,
                "  dropped {:<8} {} ({})",
                d.name,
                d.reason,
                d.depends_on.join(", ")
            );
        }
    }
    for p in &id.correlated_pairs {
        let _ = writeln!(s, "  correlated {} ~ {}: {:+.3}", p.a, p.b, p.correlation);
    }
    if !id.identifiable_by_orientation.is_empty() {
        let _ = writeln!(
            s,
            "  identified only thanks to the measured orientations: {}",
            id.identifiable_by_orientation.join(", ")
        );
    }
    if !id.unseen_tool_tip_terms.is_empty() {
        let _ = writeln!(
            s,
            "  not seen by position-only data (a production tool's tip depends on them; its error there is unknown): {}",
            id.unseen_tool_tip_terms.join(", ")
        );
    }
    // Parameter table across methods.
    let names: Vec<Method> = r.methods.keys().copied().collect();
    let _ = write!(
        s,
        "\nIdentified parameters (mm, deg, rad/(N·m))\n{:<10} {:>14}",
        "name", "nominal"
    );
    for n in &names {
        let _ = write!(s, " {:>14}", method_label(*n));
    }
    let _ = writeln!(s);
    let mut all: Vec<String> = Vec::new();
    for m in r.methods.values() {
        for p in &m.parameters {
            if !all.contains(&p.name) {
                all.push(p.name.clone());
            }
        }
    }
    for pname in &all {
        let nominal_v = r
            .methods
            .values()
            .flat_map(|m| &m.parameters)
            .find(|p| &p.name == pname)
            .map(|p| p.nominal)
            .unwrap_or(0.0);
        let unit = r
            .methods
            .values()
            .flat_map(|m| &m.parameters)
            .find(|p| &p.name == pname)
            .map(|p| p.unit.as_str())
            .unwrap_or("");
        let _ = write!(s, "{:<10} {:>14}", pname, param_number(nominal_v, unit));
        for n in &names {
            match r.methods[n].parameters.iter().find(|p| &p.name == pname) {
                Some(p) => {
                    let _ = write!(s, " {:>14}", param_number(p.value, unit));
                }
                None => {
                    let _ = write!(s, " {:>14}", "-");
                }
            }
        }
        let _ = writeln!(s);
    }
    let any_stiffness = r
        .methods
        .values()
        .any(|m| m.stiffness_nm_per_rad.iter().any(|k| k.is_some()));
    if any_stiffness {
        let _ = writeln!(s, "\nJoint stiffness (N·m/rad)");
    }
    for (n, m) in &r.methods {
        if m.stiffness_nm_per_rad.iter().any(|k| k.is_some()) {
            let ks: Vec<String> = m
                .stiffness_nm_per_rad
                .iter()
                .enumerate()
                .filter_map(|(k, v)| v.map(|v| format!("K{}={:.4e}", k + 1, v)))
                .collect();
            let _ = writeln!(s, "  {:<14} {}", method_label(*n), ks.join("  "));
        }
    }
    for (n, m) in &r.methods {
        let _ = writeln!(
            s,
            "solver {:<14} converged={} iterations={} reason={} ({})",
            method_label(*n),
            m.solver.converged,
            m.solver.iterations,
            m.solver.reason.code(),
            m.solver.detail
        );
    }
    if r.methods.values().any(|m| !m.warnings.is_empty()) {
        let _ = writeln!(s, "\nWarnings");
        for (n, m) in &r.methods {
            for w in &m.warnings {
                let _ = writeln!(s, "  {:<14} {}", method_label(*n), w.message);
            }
        }
    }
    if !r.failed.is_empty() {
        let _ = writeln!(s, "\nFailed methods (the others above are complete)");
        for f in &r.failed {
            let _ = writeln!(s, "  {:<14} {}", method_label(f.method), f.reason);
        }
    }
    s
}

/// The seed-style comparison (rows = methods, columns = sets, mean / max in mm),
/// the compensator training pool between identification and validation.
pub fn render_comparison(r: &CalibrationReport) -> String {
    let mut s = String::new();
    let training = r.training_poses > 0;
    let validation = r.validation_poses > 0;
    let _ = write!(
        s,
        "\nComparison, mean / max (mm)\n{:<22} {:>19}",
        "", "identification (Q1)"
    );
    if training {
        let _ = write!(s, " {:>19}", "training (Q2)");
    }
    if validation {
        let _ = write!(s, " {:>19}", "validation (Q3)");
    }
    let _ = writeln!(s);
    let cell = |e: Option<&crate::stats::ErrorStats>| match e {
        Some(e) => format!("{:>9.4} / {:<7.4}", e.mean_mm, e.max_mm),
        None => format!("{:>19}", "-"),
    };
    let _ = write!(
        s,
        "{:<22} {}",
        "Nominal robot model",
        cell(Some(&r.nominal.identification.stats))
    );
    if training {
        let _ = write!(s, " {}", cell(None));
    }
    if validation {
        let _ = write!(
            s,
            " {}",
            cell(r.nominal.validation.as_ref().map(|v| &v.stats))
        );
    }
    let _ = writeln!(s);
    for (name, m) in &r.methods {
        let _ = write!(
            s,
            "{:<22} {}",
            method_label(*name),
            cell(Some(&m.identification.stats))
        );
        if training {
            let _ = write!(s, " {}", cell(m.training.as_ref().map(|v| &v.stats)));
        }
        if validation {
            let _ = write!(s, " {}", cell(m.validation.as_ref().map(|v| &v.stats)));
        }
        let _ = writeln!(s);
    }
    s
}

/// Orientation errors per set (mean / max in degrees), for every model, when
/// some set measured orientation; empty otherwise.
pub fn render_orientation(r: &CalibrationReport) -> String {
    let mut s = String::new();
    let nominal: [Option<&SetErrors>; 2] = [
        Some(&r.nominal.identification),
        r.nominal.validation.as_ref(),
    ];
    let any = nominal
        .into_iter()
        .chain(r.methods.values().flat_map(|m| {
            [
                Some(&m.identification),
                m.training.as_ref(),
                m.validation.as_ref(),
            ]
        }))
        .flatten()
        .any(|e| e.orientation.is_some());
    if !any {
        return s;
    }
    let training = r.training_poses > 0;
    let validation = r.validation_poses > 0;
    let _ = write!(
        s,
        "\nOrientation, mean / max (deg)\n{:<22} {:>19}",
        "", "identification (Q1)"
    );
    if training {
        let _ = write!(s, " {:>19}", "training (Q2)");
    }
    if validation {
        let _ = write!(s, " {:>19}", "validation (Q3)");
    }
    let _ = writeln!(s);
    let cell = |e: Option<&SetErrors>| match e.and_then(|e| e.orientation.as_ref()) {
        Some(o) => format!("{:>9.4} / {:<7.4}", o.mean_deg, o.max_deg),
        None => format!("{:>19}", "-"),
    };
    let _ = write!(
        s,
        "{:<22} {}",
        "Nominal robot model",
        cell(Some(&r.nominal.identification))
    );
    if training {
        let _ = write!(s, " {}", cell(None));
    }
    if validation {
        let _ = write!(s, " {}", cell(r.nominal.validation.as_ref()));
    }
    let _ = writeln!(s);
    for (name, m) in &r.methods {
        let _ = write!(
            s,
            "{:<22} {}",
            method_label(*name),
            cell(Some(&m.identification))
        );
        if training {
            let _ = write!(s, " {}", cell(m.training.as_ref()));
        }
        if validation {
            let _ = write!(s, " {}", cell(m.validation.as_ref()));
        }
        let _ = writeln!(s);
    }
    let _ = writeln!(
        s,
        "(compensators correct position only: their orientation is their base's)"
    );
    s
}

/// Each compensator: network, training, cross-validation and its effect on
/// every set; `auto`'s choice and why.
pub fn render_compensators(r: &CalibrationReport) -> String {
    let mut s = String::new();
    let with: Vec<_> = r
        .methods
        .iter()
        .filter(|(_, m)| m.compensator.is_some() || m.auto.is_some())
        .collect();
    if with.is_empty() {
        return s;
    }
    let _ = writeln!(s, "\nCompensators (mean / max in mm, base -> compensated)");
    let pair = |b: &crate::stats::ErrorStats, c: &crate::stats::ErrorStats| {
        format!(
            "{:.4} -> {:.4} / {:.4} -> {:.4}",
            b.mean_mm, c.mean_mm, b.max_mm, c.max_mm
        )
    };
    for (name, m) in with {
        if let Some(a) = &m.auto {
            let _ = writeln!(
                s,
                "  {:<14} chose {}: {}",
                method_label(*name),
                method_label(a.chosen),
                a.reason
            );
        }
        let Some(c) = &m.compensator else {
            continue;
        };
        let _ = writeln!(
            s,
            "  {:<14} {} on {}, {} units, over {}; trained by {} on {} {} poses: {} epochs / iterations / generations, {} loss evaluations, stopped: {}; training RMS {:.4} mm",
            method_label(*name),
            c.kind,
            c.inputs,
            c.units,
            method_label(c.base),
            c.training.trainer,
            c.training_poses,
            c.trained_on,
            c.training.epochs,
            c.training.evaluations,
            c.training.stop,
            c.training.rms_mm
        );
        if let Some(cv) = &c.cross_validation {
            let _ = writeln!(
                s,
                "  {:<14} cross-validated ({} folds on the {} poses): {}",
                "",
                cv.folds,
                c.trained_on,
                pair(&cv.base, &cv.compensated)
            );
        }
        let _ = writeln!(
            s,
            "  {:<14} identification: {}",
            "",
            pair(&c.base_identification, &m.identification.stats)
        );
        if let (Some(b), Some(t)) = (&c.base_training, &m.training) {
            let _ = writeln!(s, "  {:<14} training:       {}", "", pair(b, &t.stats));
        }
        if let (Some(b), Some(v)) = (&c.base_validation, &m.validation) {
            let _ = writeln!(s, "  {:<14} validation:     {}", "", pair(b, &v.stats));
        }
        let o = &c.orientation_part;
        let _ = writeln!(
            s,
            "  {:<14} orientation part: {} — {}",
            "",
            o.status.name(),
            o.reason
        );
    }
    s
}
