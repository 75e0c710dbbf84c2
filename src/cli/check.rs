//! `robocal check`: score a check set against a calibrated model without any
//! fitting (`core::check`): per-pose error, mean / p95 / max, whether a rigid
//! frame shift explains the errors, and the status (`core::check::CheckStatus`:
//! ok, degraded, recalibrate, shifted) for the thresholds; the exit code is
//! the status's (`cli::exit`), 0 only for ok.
//!
//! ```text
//! robocal check --model cal.json --measurements check.csv [--degraded-mm 0.5] [--recalibrate-mm 1.0] [--json]
//! robocal compare --model v1.json --model v2.json --measurements check.csv [--json]
//! ```
//!
//! `compare` scores the same poses against each model, so versions compare
//! where their own validation figures (from different sets) cannot.

use anyhow::Context;
use clap::Args;
use robocal_core::check::{score, CheckResult, CheckThresholds};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Arguments of `robocal check`.
#[derive(Debug, Args)]
pub struct CheckArgs {
    /// A calibrated model file (`calibrate --save`), a model JSON file or a preset.
    #[arg(long)]
    pub model: String,
    /// The poses it scores, the thresholds of the statuses and the output.
    #[command(flatten)]
    pub check: CheckOptions,
}

/// The poses a check scores, its thresholds and its output.
#[derive(Debug, Args)]
pub struct CheckOptions {
    /// The check poses: a measurement CSV in the model's measurement frame.
    #[arg(long)]
    pub measurements: PathBuf,
    /// Convention of the files' `rx, ry, rz` columns (`qw, qx, qy, qz` columns are
    /// recognised as a quaternion without it; default fixed_xyz).
    #[arg(long, value_parser = super::orientation_arg::OrientationValues)]
    pub orientation: Option<crate::measure::convention::MeasuredOrientation>,
    /// Mean position error above which the status is `degraded` [mm].
    #[arg(long, default_value_t = CheckThresholds::default().degraded_mm)]
    pub degraded_mm: f64,
    /// Mean position error above which the status is `recalibrate` [mm] (default 1.0).
    #[arg(long, conflicts_with = "margin_mm")]
    pub recalibrate_mm: Option<f64>,
    /// Or the step from `--degraded-mm` up to the `recalibrate` level [mm] (≥ 0),
    /// as the service's thresholds are set.
    #[arg(long)]
    pub margin_mm: Option<f64>,
    /// A frame shift explains the errors when it leaves at most this fraction of the mean.
    #[arg(long, default_value_t = CheckThresholds::default().frame_shift_ratio)]
    pub frame_shift_ratio: f64,
    /// Print the result as JSON.
    #[arg(long)]
    pub json: bool,
}

/// The result as text.
pub fn check_text(r: &CheckResult) -> String {
    let p = &r.position;
    let mut s = format!(
        "status: {}{}\n{}\nposition error [mm] over {} poses: mean {:.4}, p95 {:.4}, max {:.4}\n",
        r.status.name(),
        r.shift().map_or(String::new(), |f| format!(
            " (frame shift {:.3} mm, {:.4}°: {})",
            f.translation_mm,
            f.rotation_deg,
            r.status.action()
        )),
        r.summary,
        p.n,
        p.mean_mm,
        p.p95_mm,
        p.max_mm
    );
    if let Some(o) = &r.orientation {
        let _ = writeln!(
            s,
            "orientation error [deg] over {} poses: mean {:.4}, p95 {:.4}, max {:.4}",
            o.n, o.mean_deg, o.p95_deg, o.max_deg
        );
    }
    if let Some(f) = &r.frame_shift {
        let _ = writeln!(
            s,
            "best rigid frame shift: {:.3} mm, {:.4}°, leaves mean {:.4} mm ({})",
            f.translation_mm,
            f.rotation_deg,
            f.residual_mean_mm,
            if f.explains {
                "explains the errors"
            } else {
                "does not explain the errors"
            }
        );
    }
    s
}

/// Scores the check file against the model.
pub fn check_file(a: &CheckArgs) -> anyhow::Result<CheckResult> {
    let c = &a.check;
    let rows = read_rows(c)?;
    score_model(&a.model, &rows, &c.thresholds(), &c.measurements)
}

fn read_rows(c: &CheckOptions) -> anyhow::Result<Vec<crate::measure::MeasuredPose>> {
    let read = crate::measure::csv::ReadOptions {
        orientation: c.orientation,
        ..Default::default()
    };
    super::orientation_arg::read_measurements(&c.measurements, read)
}

impl CheckOptions {
    fn thresholds(&self) -> CheckThresholds {
        match self.margin_mm {
            Some(m) => CheckThresholds::from_margin(self.degraded_mm, m, self.frame_shift_ratio),
            None => CheckThresholds {
                degraded_mm: self.degraded_mm,
                recalibrate_mm: self
                    .recalibrate_mm
                    .unwrap_or(CheckThresholds::default().recalibrate_mm),
                frame_shift_ratio: self.frame_shift_ratio,
            },
        }
    }
}

fn score_model(
    model: &str,
    rows: &[crate::measure::MeasuredPose],
    t: &CheckThresholds,
    path: &Path,
) -> anyhow::Result<CheckResult> {
    let m = super::model_files::load_compensated(model)?;
    score(&m, rows, t).with_context(|| format!("{model} on {}", path.display()))
}

/// Arguments of `robocal compare`.
#[derive(Debug, Args)]
pub struct CompareArgs {
    /// The model files to compare (at least two), each as `check --model` takes it.
    #[arg(long = "model", required = true, num_args = 1)]
    pub models: Vec<String>,
    /// The poses all are scored on, the thresholds of the statuses.
    #[command(flatten)]
    pub check: CheckOptions,
}

/// One model's score in a comparison.
#[derive(Debug, serde::Serialize)]
pub struct ModelScore {
    /// The model file as given to `--model`.
    pub model: String,
    /// The model's score on the check poses (its fields inline in JSON).
    #[serde(flatten)]
    pub result: CheckResult,
}

/// Scores the same poses against each model.
pub fn compare_files(a: &CompareArgs) -> anyhow::Result<Vec<ModelScore>> {
    if a.models.len() < 2 {
        anyhow::bail!("compare needs at least two models (--model A --model B)");
    }
    let c = &a.check;
    let rows = read_rows(c)?;
    let t = c.thresholds();
    a.models
        .iter()
        .map(|m| {
            Ok(ModelScore {
                model: m.clone(),
                result: score_model(m, &rows, &t, &c.measurements)?,
            })
        })
        .collect()
}

/// The comparison as a table: a row per model.
pub fn compare_text(scores: &[ModelScore]) -> String {
    let mut s = String::from(
        "model | status | position mean / p95 / max [mm] | orientation mean / max [deg] | frame shift [mm, deg] | explains\n",
    );
    for m in scores {
        let (p, r) = (&m.result.position, &m.result);
        let o = r.orientation.as_ref().map_or("—".to_string(), |o| {
            format!("{:.4} / {:.4}", o.mean_deg, o.max_deg)
        });
        let (shift, f) = r.frame_shift.as_ref().map_or(("—".into(), "—"), |f| {
            (
                format!("{:.3}, {:.4}", f.translation_mm, f.rotation_deg),
                if f.explains { "yes" } else { "no" },
            )
        });
        let _ = writeln!(
            s,
            "{} | {} | {:.4} / {:.4} / {:.4} | {o} | {shift} | {f}",
            m.model,
            r.status.name(),
            p.mean_mm,
            p.p95_mm,
            p.max_mm
        );
    }
    s
}

/// Prints each model's score (a table, or JSON with `--json`); the exit code is 0 whatever
/// the statuses.
pub fn compare(a: CompareArgs) -> anyhow::Result<()> {
    let scores = compare_files(&a)?;
    if a.check.json {
        println!("{}", serde_json::to_string_pretty(&scores)?);
    } else {
        print!("{}", compare_text(&scores));
    }
    Ok(())
}

/// Prints the result; the exit code is the status's.
pub fn run(a: CheckArgs) -> anyhow::Result<super::exit::Exit> {
    let r = check_file(&a)?;
    if a.check.json {
        println!("{}", serde_json::to_string_pretty(&r)?);
    } else {
        print!("{}", check_text(&r));
    }
    Ok(super::exit::Exit::of_check(r.status))
}
