//! `robocal export`: the (calibrated) geometric model for other tools — URDF,
//! standard-DH or modified-DH CSV, or robocal's JSON (`crate::model::export` makes the
//! text; this command reads the model and writes the file or stdout).

use super::model_files::load_compensated;
use crate::model::export::{export, ExportFormat, ExportSource};
use anyhow::Context;
use clap::Args;

/// Arguments of `robocal export`.
#[derive(Debug, Args)]
pub struct ExportArgs {
    /// Robot model: a preset (ys100, hh800, ur5, ur10), a model JSON file, or a
    /// calibrated model file written by `robocal calibrate --save`.
    #[arg(long)]
    pub model: String,
    /// urdf | dh-csv | mdh-csv | json.
    #[arg(long)]
    pub format: String,
    /// Output file (default: stdout).
    #[arg(long)]
    pub out: Option<String>,
}

/// The exported text of `args`.
pub fn export_to_string(a: &ExportArgs) -> anyhow::Result<String> {
    let format: ExportFormat = a.format.parse()?;
    let model = load_compensated(&a.model).map_err(|e| anyhow::anyhow!("{e}"))?;
    // Robot name and method from a calibrated model file; otherwise nominal.
    let header: Option<serde_json::Value> = std::fs::read_to_string(&a.model)
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok());
    let field = |k: &str| {
        header
            .as_ref()
            .and_then(|v| v.get(k))
            .and_then(|v| v.as_str())
            .map(str::to_string)
    };
    let robot = field("robot").unwrap_or_else(|| model.nominal.name.clone());
    let method = field("method").unwrap_or_else(|| "nominal".to_string());
    let source = ExportSource {
        robot: &robot,
        method: &method,
    };
    Ok(export(&model, &source, format)?)
}

/// Writes the export to `--out` (saying so on standard error), else to standard output.
pub fn run(a: ExportArgs) -> anyhow::Result<()> {
    let text = export_to_string(&a)?;
    match &a.out {
        Some(path) => {
            std::fs::write(path, &text).with_context(|| format!("cannot write {path}"))?;
            eprintln!("wrote the {} export to {path}", a.format);
        }
        None => print!("{text}"),
    }
    Ok(())
}
