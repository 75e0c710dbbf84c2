//! Model files on disk, for the command line (the core parses and writes
//! their text; reading and writing files happens here): a calibrated model
//! file (`robocal calibrate --save`), a model JSON file, or a preset name.

use crate::model::preset;
use crate::solve::cell::{Cell, CellDescription};
use anyhow::Context;
use robocal_core::model::calibrated::{
    parse_compensated, CalibratedModelFile, CompensateError, CompensatedModel,
};
use std::path::Path;

/// Loads a calibrated model file, a model JSON file or a preset name.
pub fn load_compensated(arg: &str) -> Result<CompensatedModel, CompensateError> {
    let path = Path::new(arg);
    if path.exists() {
        let io = |reason: String| CompensateError::Io {
            path: arg.to_string(),
            reason,
        };
        let text = std::fs::read_to_string(path).map_err(|e| io(e.to_string()))?;
        parse_compensated(&text).map_err(|e| match e {
            CompensateError::Io { .. } => e,
            other => io(other.to_string()),
        })
    } else if arg.ends_with(".json") {
        Err(CompensateError::Io {
            path: arg.to_string(),
            reason: "file does not exist".into(),
        })
    } else {
        Ok(CompensatedModel::from_nominal(preset(arg)?))
    }
}

/// The model of `--model` with `--payload-kg` applied: the payload of tools
/// without a load of their own (default: the model file's).
pub fn load_with_payload(arg: &str, payload_kg: Option<f64>) -> anyhow::Result<CompensatedModel> {
    let mut model = load_compensated(arg).map_err(|e| anyhow::anyhow!("{e}"))?;
    if let Some(p) = payload_kg {
        if !(p.is_finite() && p >= 0.0) {
            anyhow::bail!("--payload-kg must be a non-negative number, got {p}");
        }
        model.payload_kg = p;
    }
    Ok(model)
}

/// The cell of `--cell` (tools with their loads, work objects; JSON, mm and
/// degrees), or an empty cell without the option.
pub fn load_cell(path: Option<&str>) -> anyhow::Result<Cell> {
    let Some(path) = path else {
        return Ok(Cell::default());
    };
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read cell file {path}"))?;
    CellDescription::from_json(&text)
        .and_then(|d| d.to_cell())
        .with_context(|| path.to_string())
}

/// The model a calibration starts from: a preset, a model JSON file, or any
/// calibrated model file robocal writes (`calibrate --save`, a version's
/// `model.json`), whose calibrated geometry and compliance it starts from (its
/// joint maps and compensator are not part of a model-based fit; the note
/// says so).
pub fn load_start_model(arg: &str) -> anyhow::Result<(crate::model::RobotModel, Option<String>)> {
    let model = load_model(arg)?;
    let calibrated_file = std::fs::read_to_string(arg)
        .ok()
        .is_some_and(|text| CalibratedModelFile::from_json(&text).is_ok());
    let note = calibrated_file.then(|| {
        format!(
            "{arg}: starting from its calibrated model (joint maps and compensator, if any, are not refitted)"
        )
    });
    Ok((model, note))
}

/// Writes a calibrated model file as pretty JSON.
pub fn save_model_file(file: &CalibratedModelFile, path: &Path) -> Result<(), CompensateError> {
    std::fs::write(path, file.to_json() + "\n").map_err(|e| CompensateError::Io {
        path: path.display().to_string(),
        reason: e.to_string(),
    })
}

/// Loads a model from a preset name or a model JSON file path: a model
/// description, or a calibrated model file (`robocal calibrate --out`,
/// `robocal export --format json`), which gives its calibrated model.
pub fn load_model(arg: &str) -> anyhow::Result<crate::model::RobotModel> {
    let path = std::path::Path::new(arg);
    if path.exists() {
        let text = std::fs::read_to_string(path)
            .map_err(|e| anyhow::anyhow!("cannot read model file {arg}: {e}"))?;
        match crate::model::RobotModel::from_json(&text) {
            Err(crate::model::ModelError::Parse(e)) => {
                match robocal_core::model::calibrated::CalibratedModelFile::from_json(&text) {
                    Ok(file) => file
                        .model
                        .to_model()
                        .map_err(|e| anyhow::anyhow!("model file {arg}: calibrated model: {e}")),
                    Err(_) => Err(anyhow::anyhow!(
                        "model file {arg}: cannot read model JSON: {e}"
                    )),
                }
            }
            r => r.map_err(|e| anyhow::anyhow!("model file {arg}: {e}")),
        }
    } else if arg.ends_with(".json") {
        anyhow::bail!("model file {arg} does not exist")
    } else {
        crate::model::preset(arg).map_err(|e| anyhow::anyhow!("{e}"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_and_files_load_and_missing_files_fail() {
        let m = load_compensated("ur10").unwrap();
        assert_eq!(m.calibrated, m.nominal);
        assert!(load_compensated("missing.json").is_err());
        assert!(load_compensated("no-such-preset").is_err());
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("cal.json");
        let file = CalibratedModelFile::from_compensated(&m, "ur10", "km");
        save_model_file(&file, &path).unwrap();
        let back = load_compensated(path.to_str().unwrap()).unwrap();
        assert_eq!(back.calibrated, m.calibrated);
        // A calibration starts from a calibrated model file as from a preset.
        let (start, note) = load_start_model(path.to_str().unwrap()).unwrap();
        assert_eq!(start, m.calibrated);
        assert!(note.is_some());
        let (start, note) = load_start_model("ur10").unwrap();
        assert_eq!(start, m.calibrated);
        assert!(note.is_none());
        assert!(load_start_model("missing.json").is_err());
    }
}
