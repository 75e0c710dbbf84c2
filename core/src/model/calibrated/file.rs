//! The calibrated model file (`robocal calibrate --save cal.json`) and the model
//! loader used by `robocal solve`.
//!
//! Format `robocal-calibrated-model/2`, boundary units millimetres and degrees
//! (`/1` files, which have no compensator, still load):
//!
//! ```json
//! {
//!   "format": "robocal-calibrated-model/2",
//!   "robot": "ys100",
//!   "method": "skcm",
//!   "model":   { ...model description, calibrated, includes compliance... },
//!   "nominal": { ...model description of the controller's nominal model... },
//!   "cell_from_base": { "xyz_mm": [0, -3240, 0], "rpy_deg": [0, 0, 90] },
//!   "payload_kg": 110,
//!   "compensator": { "kind": "mlp", ... }
//! }
//! ```
//!
//! `cell_from_base` maps the registered robot base frame into the measurement
//! (cell / tracker) frame; its rotation is `Rz(rz)·Ry(ry)·Rx(rx)` with
//! `rpy_deg = [rx, ry, rz]` (fixed-axis XYZ, as the tool of a model description).
//!
//! `compensator` (optional, format 2) is the learned residual compensator,
//! tagged by `kind`: `mlp` ([`Mlp`](super::mlp::Mlp): `dof`, `hidden`, `features`,
//! flat `weights`, `input_norm`, `output_norm`) or `rbf` ([`Rbf`](super::rbf::Rbf):
//! `dof`, `output_frame`, `input_norm`, `spread`, `centres`, `weights`). Its
//! values are SI (inputs rad, kg, N·m; outputs m) as the network computes them.
//! A file with an unknown `kind` is rejected; every value of the compensator
//! and its support must lie within the bounds of `model::bounds::compensator`
//! (the error names the field, its value and the bound).
//!
//! `compensator_orientation` (optional, beside `compensator`; files without it
//! load as before) is the compensator's orientation part, trained where the
//! data measured orientations ([`StoredOrientation`],
//! `model/calibrated/orientation.rs`): `point_m`, the measured point in the flange
//! frame [m] the correction turns about, and `network`, a compensator of the
//! same form whose three outputs are the rotation vector `ω` [rad] in the
//! registered base frame (`R_measured = exp(ω)·R_predicted`). It fades with
//! `compensator_support` like the position part.
//!
//! `validation` (optional) keeps the validation poses' errors that the
//! accuracy at a production tool's tip is computed from
//! ([`ValidationEvidence`], `model/calibrated/evidence.rs`: the measured point's mean and max
//! error [mm] and, per pose with a measured orientation, the position error
//! [mm] and `R_measured − R_predicted`).

use super::compensated::{CompensateError, CompensatedModel};
use super::evidence::ValidationEvidence;
use super::orientation::StoredOrientation;
use super::stored::StoredCompensator;
use super::support::Support;
use crate::model::bounds::compensator::check_compensator;
use crate::model::{ModelDescription, RobotModel};
use serde::{Deserialize, Serialize};

/// The `format` value of a calibrated model file written now.
pub const CALIBRATED_MODEL_FORMAT: &str = "robocal-calibrated-model/2";

/// Older formats that still load.
pub const OLDER_FORMATS: [&str; 1] = ["robocal-calibrated-model/1"];

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
    /// Learned residual compensator (format 2).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compensator: Option<StoredCompensator>,
    /// Where the compensator was trained; beyond it its correction fades to
    /// zero (`support`). Absent in files written before it existed: the
    /// compensator then applies everywhere.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compensator_support: Option<Support>,
    /// The compensator's orientation part (module docs); absent for a
    /// compensator of the position only and in files written before it existed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compensator_orientation: Option<StoredOrientation>,
    /// What the calibration's validation poses say about the error at a
    /// production tool's tip (`cell::accuracy`); absent in files without
    /// validation data or written before it existed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub validation: Option<ValidationEvidence>,
}

impl CalibratedModelFile {
    /// The file contents of a compensated model, with its compensator when it
    /// has a stored form ([`Compensator::stored`](super::Compensator::stored)).
    pub fn from_compensated(m: &CompensatedModel, robot: &str, method: &str) -> Self {
        CalibratedModelFile {
            format: CALIBRATED_MODEL_FORMAT.to_string(),
            robot: robot.to_string(),
            method: method.to_string(),
            model: ModelDescription::from_model(&m.calibrated),
            nominal: ModelDescription::from_model(&m.nominal),
            cell_from_base: PoseDescription::from_pose(&m.cell_from_base),
            payload_kg: m.payload_kg,
            compensator: m.compensator.as_ref().and_then(|c| c.stored()),
            compensator_support: m.compensator.as_ref().and_then(|c| c.support().cloned()),
            compensator_orientation: m.compensator.as_ref().and_then(|c| c.stored_orientation()),
            validation: None,
        }
    }

    /// Validates the file and builds the SI model.
    pub fn to_compensated(&self) -> Result<CompensatedModel, CompensateError> {
        let old = OLDER_FORMATS.contains(&self.format.as_str());
        if self.format != CALIBRATED_MODEL_FORMAT && !old {
            return Err(CompensateError::Format(format!(
                "unsupported format `{}` (expected `{CALIBRATED_MODEL_FORMAT}` or one of {OLDER_FORMATS:?})",
                self.format
            )));
        }
        if old && self.compensator.is_some() {
            return Err(CompensateError::Format(format!(
                "format `{}` cannot carry a compensator; use `{CALIBRATED_MODEL_FORMAT}`",
                self.format
            )));
        }
        if let Some(c) = &self.compensator {
            // Every value within its bound, named (model::bounds), then the
            // sizes consistent.
            check_compensator(
                c,
                self.compensator_support.as_ref(),
                self.compensator_orientation.as_ref(),
            )?;
            c.validate()
                .map_err(|e| CompensateError::Format(format!("compensator: {e}")))?;
        }
        match (&self.compensator, &self.compensator_support) {
            (None, Some(_)) => {
                return Err(CompensateError::Format(
                    "compensator_support without a compensator".into(),
                ))
            }
            (Some(c), Some(s)) => s
                .validate(c.dof())
                .map_err(|e| CompensateError::Format(e.to_string()))?,
            _ => {}
        }
        match (&self.compensator, &self.compensator_orientation) {
            (None, Some(_)) => {
                return Err(CompensateError::Format(
                    "compensator_orientation without a compensator".into(),
                ))
            }
            (Some(c), Some(o)) => o.validate(c.dof()).map_err(CompensateError::Format)?,
            _ => {}
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
            compensator: match &self.compensator {
                Some(c) if c.dof() != nominal.dof() => {
                    return Err(CompensateError::Format(format!(
                        "the compensator was trained for {} joints but the model has {}",
                        c.dof(),
                        nominal.dof()
                    )))
                }
                Some(c) => Some(c.clone().into_arc_oriented(
                    self.compensator_orientation.clone(),
                    self.compensator_support.clone(),
                )),
                None => None,
            },
            nominal,
            cell_from_base: self.cell_from_base.to_pose().ok_or_else(|| {
                CompensateError::Format("cell_from_base values must be finite numbers".into())
            })?,
            payload_kg: self.payload_kg,
        })
    }

    /// The file as pretty-printed JSON.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("calibrated model file serialises")
    }

    /// Parses a calibrated model file from JSON; structure only (the loader
    /// checks values and bounds).
    pub fn from_json(text: &str) -> Result<Self, CompensateError> {
        serde_json::from_str(text).map_err(|e| CompensateError::Format(e.to_string()))
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{preset, Pose};

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
    fn plain_models_load_as_nominal() {
        let text = preset("ys100").unwrap().to_json();
        let m = parse_compensated(&text).unwrap();
        assert_eq!(m.calibrated, m.nominal);
        assert_eq!(m.cell_from_base, Pose::identity());
        assert_eq!(m.payload_kg, 110.0);
        let mut f = CalibratedModelFile::from_compensated(&m, "ys100", "km");
        f.format = "robocal-calibrated-model/9".into();
        assert!(parse_compensated(&f.to_json()).is_err());
    }

    fn mlp_compensated() -> CompensatedModel {
        use crate::calibrate::compensate::{
            train, CompensatorSpec, LmTrainSettings, MlpSettings, MlpSpec, Sample, Trainer,
        };
        use rand::SeedableRng;
        let nominal = preset("ys100").unwrap();
        let mut m = CompensatedModel::from_nominal(nominal.clone());
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(2);
        let qs = crate::sim::random_configurations(&nominal, 40, &mut rng);
        let samples: Vec<Sample> = qs
            .iter()
            .map(|q| Sample {
                q: q.clone(),
                tau: m.torques(q).unwrap(),
                payload_kg: 110.0,
                residual: nalgebra::Vector3::new(1e-4 * q[1].sin(), 2e-4 * q[2].cos(), 1e-5),
            })
            .collect();
        let spec = CompensatorSpec::Mlp(MlpSettings {
            spec: MlpSpec::SMALL,
            trainer: Trainer::Lm(LmTrainSettings {
                max_epochs: 5,
                ..Default::default()
            }),
        });
        let (c, _) = train(&spec, &samples, &mut rng, &mut |_, _| true).unwrap();
        m.compensator = Some(c.into_arc_oriented(None, None));
        m
    }

    #[test]
    fn compensator_round_trips_and_version_1_still_loads() {
        let m = mlp_compensated();
        let file = CalibratedModelFile::from_compensated(&m, "ys100", "skcm-nn");
        assert_eq!(file.format, CALIBRATED_MODEL_FORMAT);
        let text = file.to_json();
        assert!(text.contains("\"kind\": \"mlp\""));
        let back = parse_compensated(&text).unwrap();
        let q = [0.1, 1.2, -0.3, 0.4, 0.5, -0.6];
        // Bit for bit: the weights are printed with round-trip precision.
        assert_eq!(m.predict(&q).unwrap().p, back.predict(&q).unwrap().p);
        assert_ne!(
            m.predict(&q).unwrap().p,
            CompensatedModel {
                compensator: None,
                ..m.clone()
            }
            .predict(&q)
            .unwrap()
            .p
        );
        // A version-1 file (no compensator) loads as before.
        let mut v1: serde_json::Value = serde_json::from_str(&text).unwrap();
        v1["format"] = "robocal-calibrated-model/1".into();
        v1.as_object_mut().unwrap().remove("compensator");
        let old = parse_compensated(&v1.to_string()).unwrap();
        assert!(old.compensator.is_none());
    }

    /// An orientation part round-trips, turns the prediction, and is refused
    /// without a position part or with a broken network.
    #[test]
    fn orientation_part_round_trips_and_is_checked() {
        let m = mlp_compensated();
        let net = m.compensator.as_ref().unwrap().stored().unwrap();
        let mut file = CalibratedModelFile::from_compensated(&m, "ys100", "skcm-nn");
        assert!(file.compensator_orientation.is_none());
        file.compensator_orientation = Some(StoredOrientation {
            point_m: [0.0, 0.0, 0.1],
            network: net,
        });
        let text = file.to_json();
        let back = parse_compensated(&text).unwrap();
        let q = [0.1, 1.2, -0.3, 0.4, 0.5, -0.6];
        let (a, b) = (m.predict(&q).unwrap(), back.predict(&q).unwrap());
        assert!(
            (a.r - b.r).norm() > 1e-6,
            "the orientation part turns the pose"
        );
        let again = CalibratedModelFile::from_compensated(&back, "ys100", "skcm-nn");
        assert_eq!(again.compensator_orientation, file.compensator_orientation);
        let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
        v.as_object_mut().unwrap().remove("compensator");
        let e = parse_compensated(&v.to_string()).unwrap_err().to_string();
        assert!(
            e.contains("compensator_orientation without a compensator"),
            "{e}"
        );
        let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
        v["compensator_orientation"]["network"]["weights"]
            .as_array_mut()
            .unwrap()
            .pop();
        let e = parse_compensated(&v.to_string()).unwrap_err().to_string();
        assert!(
            e.contains("compensator_orientation") && e.contains("weights"),
            "{e}"
        );
    }

    #[test]
    fn unknown_or_broken_compensators_fail_loudly() {
        let m = mlp_compensated();
        let text = CalibratedModelFile::from_compensated(&m, "ys100", "skcm-nn").to_json();
        let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
        v["compensator"]["kind"] = "gaussian-process".into();
        let e = parse_compensated(&v.to_string()).unwrap_err().to_string();
        assert!(e.contains("gaussian-process") && e.contains("mlp"), "{e}");
        let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
        v["compensator"]["weights"].as_array_mut().unwrap().pop();
        let e = parse_compensated(&v.to_string()).unwrap_err().to_string();
        assert!(e.contains("weights"), "{e}");
        let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
        v["format"] = "robocal-calibrated-model/1".into();
        let e = parse_compensated(&v.to_string()).unwrap_err().to_string();
        assert!(e.contains("cannot carry a compensator"), "{e}");
    }
}
