//! Measurements: joint readings paired with measured TCP positions (and
//! optionally orientations), as uploaded by a cell engineer.
//!
//! Two forms:
//! - [`MeasuredPose`]: boundary units of the CSV format (controller joint readings
//!   in degrees, positions in millimetres in the measurement frame, optional
//!   orientation as fixed-axis XYZ angles `rx, ry, rz` in degrees, i.e.
//!   `R = Rz(rz)·Ry(ry)·Rx(rx)`, whatever convention the file used
//!   ([`convention::MeasuredOrientation`]), optional standard deviations of
//!   the position [mm] and orientation angles [deg] per axis).
//! - [`Measurement`]: SI form used by the numerical core (model-convention joint
//!   values in radians after the controller's sign/zero conversion, metres).

use crate::model::pose::rpy_matrix;
use crate::model::RobotModel;
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

pub mod bounds;
pub mod convention;
pub mod csv;
pub mod csv_text;
pub mod external;

/// Role of a measurement in the calibration (docs/design.md "Data roles").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SetRole {
    /// Q1: identifies the model-based parameters.
    Identification,
    /// Q2: trains the compensator.
    Training,
    /// Q3: validates; never used for fitting.
    Validation,
    /// Check poses: scored against a model version without fitting
    /// (`check`), or the small set a re-registration refits the frames on;
    /// never an identification or training set of a calibration.
    Check,
}

impl SetRole {
    /// Every role, in the order lists and messages name them.
    pub const ALL: [SetRole; 4] = [
        SetRole::Identification,
        SetRole::Training,
        SetRole::Validation,
        SetRole::Check,
    ];

    /// The role named by `s` (case-insensitive; `identify`, `train`, `validate`
    /// and `q1`..`q3` too), or `None`.
    pub fn parse(s: &str) -> Option<SetRole> {
        match s.trim().to_ascii_lowercase().as_str() {
            "identification" | "identify" | "q1" => Some(SetRole::Identification),
            "training" | "train" | "q2" => Some(SetRole::Training),
            "validation" | "validate" | "q3" => Some(SetRole::Validation),
            "check" => Some(SetRole::Check),
            _ => None,
        }
    }
    /// The role's name in CSV `set` fields, the API and messages.
    pub fn as_str(&self) -> &'static str {
        match self {
            SetRole::Identification => "identification",
            SetRole::Training => "training",
            SetRole::Validation => "validation",
            SetRole::Check => "check",
        }
    }
    /// The role names as a message lists them: `identification, training, validation or check`.
    pub fn names() -> String {
        let names: Vec<&str> = SetRole::ALL.iter().map(|r| r.as_str()).collect();
        let (last, rest) = names.split_last().expect("roles");
        format!("{} or {last}", rest.join(", "))
    }
    /// Whether a calibration may fit on a set of this role (identification
    /// or training); validation and check sets are only ever scored.
    pub fn fits(&self) -> bool {
        matches!(self, SetRole::Identification | SetRole::Training)
    }
}

/// One measured pose in boundary units (mm, deg), as in the CSV.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MeasuredPose {
    /// Controller joint readings [deg].
    pub q_deg: Vec<f64>,
    /// Measured TCP position in the measurement frame [mm].
    pub xyz_mm: [f64; 3],
    /// Measured orientation, fixed-axis XYZ `[rx, ry, rz]` [deg].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rpy_deg: Option<[f64; 3]>,
    /// Standard deviations of the measured `x, y, z` [mm] (CSV `std_x, std_y, std_z`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub std_mm: Option<[f64; 3]>,
    /// Standard deviations of the measured `rx, ry, rz` [deg] (CSV `std_rx, std_ry, std_rz`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub std_deg: Option<[f64; 3]>,
    /// Payload mass at this pose [kg] (CSV `payload_kg`; `None`: the model's
    /// default payload).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub payload_kg: Option<f64>,
    /// Temperature during the measurement [°C] (CSV `temperature_c`), when given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub temperature_c: Option<f64>,
    /// The set the pose belongs to (CSV `set`), when given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub set: Option<SetRole>,
    /// Tracker-session label (CSV `session` column), when given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub session: Option<String>,
}

/// One measured pose in SI units, ready for identification.
#[derive(Debug, Clone, PartialEq)]
pub struct Measurement {
    /// Model-convention joint values [rad].
    pub q: Vec<f64>,
    /// Measured TCP position in the measurement frame [m].
    pub position: Vector3<f64>,
    /// Measured TCP orientation in the measurement frame, when available.
    pub orientation: Option<Matrix3<f64>>,
    /// Payload mass during the measurement [kg].
    pub payload_mass: f64,
    /// Measurement session (tracker placement) index; 0 for a single session.
    pub session: usize,
    /// The row's standard deviations, when the file gave them: the fits weigh
    /// its residual rows by their inverse (`identify::evaluate`).
    pub std: Option<RowStd>,
}

/// One row's measurement standard deviations in SI, each the RMS of its three
/// per-axis figures (`√((σx² + σy² + σz²)/3)`): the fit works in the registered
/// base frame, where the tracker's axes are rotated, so a row's weight is one
/// figure for its position and one for its orientation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RowStd {
    /// Position [m].
    pub position: f64,
    /// Orientation [rad], when the row measured one and gave its deviations.
    pub orientation: Option<f64>,
}

impl RowStd {
    /// From the CSV's per-axis figures (mm, deg).
    pub fn from_axes(std_mm: [f64; 3], std_deg: Option<[f64; 3]>) -> RowStd {
        let rms = |v: [f64; 3]| (v.iter().map(|x| x * x).sum::<f64>() / 3.0).sqrt();
        RowStd {
            position: rms(std_mm) * 1e-3,
            orientation: std_deg.map(|d| rms(d).to_radians()),
        }
    }
}

impl MeasuredPose {
    /// A row of joints `q_deg` (controller degrees) and a reflector point
    /// `xyz_mm` [mm], nothing else stated (no orientation, σ, payload,
    /// temperature, set or session).
    pub fn position_only(q_deg: Vec<f64>, xyz_mm: [f64; 3]) -> Self {
        MeasuredPose {
            q_deg,
            xyz_mm,
            rpy_deg: None,
            std_mm: None,
            std_deg: None,
            payload_kg: None,
            temperature_c: None,
            set: None,
            session: None,
        }
    }

    /// Converts to SI with the model's controller conventions; `default_payload`
    /// applies when the row gives no payload.
    pub fn to_measurement(&self, model: &RobotModel, default_payload: f64) -> Measurement {
        let q_ctrl: Vec<f64> = self.q_deg.iter().map(|d| d.to_radians()).collect();
        Measurement {
            q: model.joints_from_controller(&q_ctrl),
            position: Vector3::new(self.xyz_mm[0], self.xyz_mm[1], self.xyz_mm[2]) * 1e-3,
            orientation: self
                .rpy_deg
                .map(|r| rpy_matrix(r[0].to_radians(), r[1].to_radians(), r[2].to_radians())),
            payload_mass: self.payload_kg.unwrap_or(default_payload),
            session: 0,
            std: self
                .std_mm
                .map(|p| RowStd::from_axes(p, self.std_deg.filter(|_| self.rpy_deg.is_some()))),
        }
    }
}

/// Converts rows to SI measurements.
pub fn to_measurements(
    model: &RobotModel,
    rows: &[MeasuredPose],
    default_payload: f64,
) -> Vec<Measurement> {
    rows.iter()
        .map(|r| r.to_measurement(model, default_payload))
        .collect()
}
