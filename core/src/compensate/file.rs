//! The calibrated model file (`robocal calibrate --save cal.json`) and the model
//! loader used by `robocal solve`.
//!
//! Format `robocal-calibrated-model/1`, boundary units millimetres and degrees:
//!
//! ```json
//! {
//!   "format": "robocal-calibrated-model/1",
//!   "robot": "ys100",
//!   "method": "skcm",
//!   "model":   { ...model description, calibrated, includes compliance... },
//!   "nominal": { ...model description of the controller's nominal model... },
//!   "cell_from_base": { "xyz_mm": [0, -3240, 0], "rpy_deg": [0, 0, 90] },
//!   "payload_kg": 110
//! }
//! ```
//!
//! `cell_from_base` maps the registered robot base frame into the measurement
//! (cell / tracker) frame; its rotation is `Rz(rz)·Ry(ry)·Rx(rx)` with
//! `rpy_deg = [rx, ry, rz]` (fixed-axis XYZ, as the tool of a model description).
//! A learned compensator is not stored in this version of the format.

use super::{CompensateError, CompensatedModel};
use crate::model::{preset, ModelDescription, RobotModel};
use serde::{Deserialize, Serialize};

/// The `format` value of a calibrated model file.
pub const CALIBRATED_MODEL_FORMAT: &str = "robocal-calibrated-model/1";

pub use crate::model::description::PoseDescription;

/// The on-disk calibrated model (see module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CalibratedModelFile {
    /// Always [`CALIBRATED_MODEL_FORMAT`].
    pub format: String,
    /// Robot name (preset or model name).
    pub robot: String,
    /// Calibration method that produced the model (e.g. `km`, `skcm`).
    pub method: String,
    /// Calibrated model (mm/deg), including joint compliance.
    pub model: ModelDescription,
    /// The controller's nominal model (mm/deg).
    pub nominal: ModelDescription,
    /// Registered base frame → measurement frame.
    pub cell_from_base: PoseDescription,
    /// Payload mass [kg] the model applies by default.
    pub payload_kg: f64,
}

impl CalibratedModelFile {
    /// The file contents of a compensated model (the compensator, if any, is not stored).
    pub fn from_compensated(m: &CompensatedModel, robot: &str, method: &str) -> Self {
        CalibratedModelFile {
            format: CALIBRATED_MODEL_FORMAT.to_string(),
            robot: robot.to_string(),
            method: method.to_string(),
            model: ModelDescription::from_model(&m.calibrated),
            nominal: ModelDescription::from_model(&m.nominal),
            cell_from_base: PoseDescription::from_pose(&m.cell_from_base),
            payload_kg: m.payload_kg,
        }
    }

    /// Validates the file and builds the SI model.
    pub fn to_compensated(&self) -> Result<CompensatedModel, CompensateError> {
        if self.format != CALIBRATED_MODEL_FORMAT {
            return Err(CompensateError::Format(format!(
                "unsupported format `{}` (expected `{CALIBRATED_MODEL_FORMAT}`)",
                self.format
            )));
        }
        let calibrated = self.model.to_model()?;
        let nominal = self.nominal.to_model()?;
        if calibrated.dof() != nominal.dof() {
            return Err(CompensateError::Format(format!(
                "the calibrated model has {} joints but the nominal model has {}",
                calibrated.dof(),
                nominal.dof()
            )));
        }
        if !(self.payload_kg.is_finite() && self.payload_kg >= 0.0) {
            return Err(CompensateError::Format(format!(
                "payload_kg must be a non-negative number, got {}",
                self.payload_kg
            )));
        }
        Ok(CompensatedModel {
            calibrated,
            nominal,
            cell_from_base: self.cell_from_base.to_pose().ok_or_else(|| {
                CompensateError::Format("cell_from_base values must be finite numbers".into())
            })?,
            payload_kg: self.payload_kg,
            compensator: None,
        })
    }

    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("calibrated model file serialises")
    }

    pub fn from_json(text: &str) -> Result<Self, CompensateError> {
        serde_json::from_str(text).map_err(|e| CompensateError::Format(e.to_string()))
    }

    /// Writes the file as pretty JSON.
    pub fn save(&self, path: &std::path::Path) -> Result<(), CompensateError> {
        std::fs::write(path, self.to_json() + "\n").map_err(|e| CompensateError::Io {
            path: path.display().to_string(),
            reason: e.to_string(),
        })
    }
}

/// Parses either a calibrated model file or a plain model description. A plain
/// model is its own nominal model, with the identity frame and its default payload.
pub fn parse_compensated(text: &str) -> Result<CompensatedModel, CompensateError> {
    let value: serde_json::Value =
        serde_json::from_str(text).map_err(|e| CompensateError::Format(e.to_string()))?;
    if value.get("format").is_some() {
        CalibratedModelFile::from_json(text)?.to_compensated()
    } else {
        Ok(CompensatedModel::from_nominal(RobotModel::from_json(text)?))
    }
}

/// Loads a calibrated model file, a model JSON file or a preset name.
pub fn load_compensated(arg: &str) -> Result<CompensatedModel, CompensateError> {
    let path = std::path::Path::new(arg);
    if path.exists() {
        let text = std::fs::read_to_string(path).map_err(|e| CompensateError::Io {
            path: arg.to_string(),
            reason: e.to_string(),
        })?;
        parse_compensated(&text).map_err(|e| match e {
            CompensateError::Io { .. } => e,
            other => CompensateError::Io {
                path: arg.to_string(),
                reason: other.to_string(),
            },
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Pose;

    #[test]
    fn file_round_trip_keeps_model_frame_and_payload() {
        let mut cal = preset("hh800").unwrap();
        cal.links[1].compliance = 2e-7;
        cal.links[2].a += 1e-3;
        let mut frame = Pose::identity();
        frame.tr_y(-3.24);
        frame.rot_z(1.0);
        frame.rot_x(0.1);
        let m = CompensatedModel {
            calibrated: cal,
            nominal: preset("hh800").unwrap(),
            cell_from_base: frame,
            payload_kg: 500.0,
            compensator: None,
        };
        let text = CalibratedModelFile::from_compensated(&m, "hh800", "skcm").to_json();
        let back = parse_compensated(&text).unwrap();
        assert!((back.cell_from_base.p - frame.p).norm() < 1e-12);
        assert!((back.cell_from_base.r - frame.r).norm() < 1e-12);
        assert_eq!(back.payload_kg, 500.0);
        assert_eq!(back.calibrated.links[1].compliance, 2e-7);
        let q = [0.1, 1.5, 0.1, 0.2, 0.3, 0.4];
        let (a, b) = (m.predict(&q).unwrap(), back.predict(&q).unwrap());
        assert!((a.p - b.p).norm() < 1e-9);
    }

    #[test]
    fn plain_models_and_presets_load_as_nominal() {
        let m = load_compensated("ur10").unwrap();
        assert_eq!(m.calibrated, m.nominal);
        assert_eq!(m.cell_from_base, Pose::identity());
        let text = preset("ys100").unwrap().to_json();
        let m = parse_compensated(&text).unwrap();
        assert_eq!(m.payload_kg, 110.0);
        assert!(load_compensated("missing.json").is_err());
        let mut f = CalibratedModelFile::from_compensated(&m, "ys100", "km");
        f.format = "robocal-calibrated-model/9".into();
        assert!(parse_compensated(&f.to_json()).is_err());
    }
}
