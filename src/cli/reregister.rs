//! `robocal reregister`: a calibrated model moved to a new measurement
//! session (tracker moved, reflector remounted) by refitting only its
//! measurement frame and measurement tool on a small set
//! (`core::check::reregister`); the robot's identified geometry, compliance,
//! joint maps and compensator are kept. Refused, with what to measure, when
//! the poses cannot tell the frame from the tool.
//!
//! ```text
//! robocal reregister --model cal.json --measurements new.csv --save cal-new.json [--json]
//! ```

use anyhow::Context;
use clap::Args;
use robocal_core::check::{reregister, Reregistration};
use std::path::PathBuf;

/// Arguments of `robocal reregister`.
#[derive(Debug, Args)]
pub struct ReregisterArgs {
    /// The calibrated model file to move (`calibrate --save`, `export --format json`).
    #[arg(long)]
    pub model: String,
    /// 20–30 poses of the new session: a measurement CSV in its measurement frame.
    #[arg(long)]
    pub measurements: PathBuf,
    /// Convention of the files' `rx, ry, rz` columns (`qw, qx, qy, qz` columns are
    /// recognised as a quaternion without it; default fixed_xyz).
    #[arg(long, value_parser = super::orientation_arg::OrientationValues)]
    pub orientation: Option<crate::measure::convention::MeasuredOrientation>,
    /// Write the re-registered model file here.
    #[arg(long)]
    pub save: Option<PathBuf>,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

/// The report as text.
pub fn report_text(r: &Reregistration) -> String {
    let mut s = format!(
        "re-registered on {} poses: refitted {}\nposition error [mm]: before mean {:.4} max {:.4}; after mean {:.4} max {:.4}\n",
        r.poses,
        r.refitted.join(", "),
        r.before.mean_mm,
        r.before.max_mm,
        r.after.mean_mm,
        r.after.max_mm
    );
    if let Some(o) = &r.orientation_after {
        s.push_str(&format!(
            "orientation error after [deg]: mean {:.4} max {:.4}\n",
            o.mean_deg, o.max_deg
        ));
    }
    s.push_str(&format!(
        "tool point moved {:.3} mm; measurement frame turned {:.4}° and moved {:.3} mm; condition number {:.0}; {} after {} iterations\n",
        r.tool_shift_mm,
        r.frame_rotation_deg,
        r.frame_translation_mm,
        r.condition_number,
        if r.converged { "converged" } else { "not converged" },
        r.iterations
    ));
    s
}

/// Re-registers the model on the file's poses; the report, and the model
/// file written when `--save` is given.
pub fn reregister_file(a: &ReregisterArgs) -> anyhow::Result<Reregistration> {
    let model = super::model_files::load_compensated(&a.model)?;
    let path = &a.measurements;
    let read = crate::measure::csv::ReadOptions {
        orientation: a.orientation,
        ..Default::default()
    };
    let rows = super::orientation_arg::read_measurements(path, read)?;
    let (moved, report) =
        reregister(&model, &rows).with_context(|| format!("{} on {}", a.model, path.display()))?;
    if let Some(out) = &a.save {
        let file = robocal_core::model::calibrated::CalibratedModelFile::from_compensated(
            &moved,
            &model.nominal.name,
            "reregister",
        );
        super::model_files::save_model_file(&file, out)?;
    }
    Ok(report)
}

/// Re-registers the model and prints the report (text, or JSON with `--json`), saying on
/// standard error where `--save` wrote the moved model.
pub fn run(a: ReregisterArgs) -> anyhow::Result<()> {
    let r = reregister_file(&a)?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&r)?);
    } else {
        print!("{}", report_text(&r));
    }
    if let Some(out) = &a.save {
        eprintln!("saved the re-registered model to {}", out.display());
    }
    Ok(())
}
