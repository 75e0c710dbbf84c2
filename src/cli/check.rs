//! `robocal check`: score a check set against a calibrated model without any
//! fitting (`core::check`): per-pose error, mean / p95 / max, whether a rigid
//! frame shift explains the errors, and the status (ok, degraded,
//! recalibrate) for the thresholds.
//!
//! ```text
//! robocal check --model cal.json --measurements check.csv [--degraded-mm 0.5] [--recalibrate-mm 1.0] [--json]
//! ```

use anyhow::Context;
use clap::Args;
use robocal_core::check::{score, CheckResult, CheckThresholds};
use std::fmt::Write as _;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct CheckArgs {
    /// A calibrated model file (`calibrate --save`), a model JSON file or a preset.
    #[arg(long)]
    pub model: String,
    /// The check poses: a measurement CSV in the model's measurement frame.
    #[arg(long)]
    pub measurements: PathBuf,
    /// Mean position error above which the status is `degraded` [mm].
    #[arg(long, default_value_t = CheckThresholds::default().degraded_mm)]
    pub degraded_mm: f64,
    /// Mean position error above which the status is `recalibrate` [mm].
    #[arg(long, default_value_t = CheckThresholds::default().recalibrate_mm)]
    pub recalibrate_mm: f64,
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
        "status: {}\n{}\nposition error [mm] over {} poses: mean {:.4}, p95 {:.4}, max {:.4}\n",
        r.status.name(),
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
    let model = super::model_files::load_compensated(&a.model)?;
    let path = &a.measurements;
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    let rows = crate::measure::csv::parse(&text).with_context(|| path.display().to_string())?;
    let thresholds = CheckThresholds {
        degraded_mm: a.degraded_mm,
        recalibrate_mm: a.recalibrate_mm,
        frame_shift_ratio: a.frame_shift_ratio,
    };
    score(&model, &rows, &thresholds).with_context(|| path.display().to_string())
}

pub fn run(a: CheckArgs) -> anyhow::Result<()> {
    let r = check_file(&a)?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&r)?);
    } else {
        print!("{}", check_text(&r));
    }
    Ok(())
}
