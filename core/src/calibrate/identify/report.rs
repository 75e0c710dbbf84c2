//! What a calibration reports: errors per set, identified parameters with σ,
//! stiffness, solver reports, warnings for implausible results, and the
//! methods that failed with their reasons (a failed method never hides the
//! ones that worked).
//!
//! Units: millimetres, degrees, rad/(N·m) and N·m/rad (display units); the
//! calibrated `RobotModel` inside stays SI.

use super::identifiability::IdentifiabilityReport;
use super::joint_maps::{MapCandidate, MapFit, RefusedMap};
use super::least_squares::LmReport;
use super::methods::ties::DecidingStep;
use super::methods::veto::BlockedCheck;
use super::options::Method;
use crate::calibrate::compensate::{CvStats, TrainReport};
use crate::measure::Measurement;
use crate::model::calibrated::{Compensator, LearnedCompensator, StoredCompensator, Support};
use crate::model::description::PoseDescription;
use crate::model::orientation::rotation_angle_between;
use crate::model::pose::Pose;
use crate::model::{ModelDescription, ParamId, RobotModel};
use crate::stats::{ErrorStats, OrientationStats};
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::sync::Arc;

/// Version of the serialised [`CalibrationReport`]. 1: no version field, error
/// norms only; 2: per-pose error vectors and positions, pose sources; 3: the
/// compensator training pool (`training_poses`, `pose_sources.training`), the
/// compensator summary of each compensator method and `auto`'s choice; 4:
/// orientation errors per set (`orientation_mean_deg`, …, when the set
/// measured orientation) and the parameters identifiable only through them.
pub const REPORT_FORMAT_VERSION: u32 = 4;

/// Errors of one set: statistics plus the per-pose error norms (mm), and
/// (format 2) the per-pose error vectors `measured − predicted` and the
/// measured positions, both in the registered base frame of the pose's
/// session [mm]. A pose the model cannot predict has a norm of infinity and
/// no finite vector (`[NaN; 3]` serialises as nulls).
///
/// Orientation (format 4): when some pose of the set measured an orientation,
/// `orientation` holds the statistics of the angle of
/// `R_measured·R_predictedᵀ` [deg] over those poses (serialised flat as
/// `orientation_mean_deg`, `orientation_max_deg`, …) and
/// `orientation_errors_deg` the angle per pose (`null` for a pose without
/// one). A set without any orientation measurement has neither field.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SetErrors {
    /// Statistics of the position error norms [mm] (serialised flat).
    #[serde(flatten)]
    pub stats: ErrorStats,
    /// Statistics of the orientation error angles [deg] over the poses that measured one
    /// (serialised flat).
    #[serde(flatten, default, skip_serializing_if = "Option::is_none")]
    pub orientation: Option<OrientationStats>,
    /// Position error norm per pose [mm] (infinity where the model cannot predict).
    pub errors_mm: Vec<f64>,
    /// Orientation error angle per pose [deg] (`None` for a pose without a measured orientation).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub orientation_errors_deg: Vec<Option<f64>>,
    /// Error vector `measured − predicted` per pose, registered base frame of its session [mm].
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub errors_xyz_mm: Vec<[Option<f64>; 3]>,
    /// Measured position per pose, registered base frame of its session [mm].
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub positions_mm: Vec<[f64; 3]>,
}

impl SetErrors {
    /// The set's errors from the position error norms alone [mm].
    pub fn new(errors_mm: Vec<f64>) -> Self {
        SetErrors {
            stats: ErrorStats::from_errors_mm(&errors_mm),
            orientation: None,
            errors_mm,
            orientation_errors_deg: Vec::new(),
            errors_xyz_mm: Vec::new(),
            positions_mm: Vec::new(),
        }
    }

    /// Errors of `model` on `data` with the session frames applied: norms,
    /// vectors and measured positions (eq. 2.3's residual, in mm), and the
    /// orientation errors of the poses that measured one.
    pub fn of(model: &RobotModel, frames: &[Pose], data: &[Measurement]) -> Self {
        Self::of_compensated(model, None, frames, data)
    }

    /// [`SetErrors::of`] through the compensated prediction
    /// `FK(q + c∘τ) + NN(q, τ)` (registered base frame, then the session frame),
    /// τ the gravity torques of `model` at the commanded joints with the pose's
    /// payload. The orientation is the geometric model's (with its joint maps
    /// and compliance), turned by the compensator's orientation part where it
    /// has one (`compensate::oriented`).
    pub fn of_compensated(
        model: &RobotModel,
        compensator: Option<&dyn Compensator>,
        frames: &[Pose],
        data: &[Measurement],
    ) -> Self {
        Self::from_predictions(
            frames,
            data,
            data.iter()
                .map(|m| predict_compensated(model, compensator, m)),
        )
    }

    /// [`SetErrors::of`] from the predicted poses (position [m], rotation) of
    /// `data` in the registered base frame (`None`: the model cannot predict
    /// the pose), one per measurement in order.
    pub(crate) fn from_predictions(
        frames: &[Pose],
        data: &[Measurement],
        predictions: impl Iterator<Item = Option<(Vector3<f64>, Matrix3<f64>)>>,
    ) -> Self {
        Self::from_residuals(
            data,
            data.iter().zip(predictions).map(|(m, p)| {
                p.map(|(p, r)| {
                    let e = frames.get(m.session).copied().unwrap_or_default();
                    let angle = m
                        .orientation
                        .map(|rm| rotation_angle_between(&rm, &(e.r * r)).to_degrees());
                    (m.position - e.transform_point(&p), angle)
                })
            }),
        )
    }

    /// [`SetErrors::of`] from the fitted model's residual vector on
    /// position-only `data` (`least_squares::Fit::residuals`: measured minus
    /// predicted, the same numbers [`SetErrors::of`] computes again); `None`
    /// when some pose measured an orientation (its weighted rows are then
    /// better recomputed) or the vector does not match the data.
    pub(crate) fn from_residual_vector(data: &[Measurement], r: &DVector<f64>) -> Option<Self> {
        if data.iter().any(|m| m.orientation.is_some()) || r.len() != 3 * data.len() {
            return None;
        }
        Some(Self::from_residuals(
            data,
            (0..data.len())
                .map(|i| Some((Vector3::new(r[3 * i], r[3 * i + 1], r[3 * i + 2]), None))),
        ))
    }

    /// The set's errors from the position residuals [m] (measured minus
    /// predicted, in the session frame) and orientation errors [deg] (`None`
    /// without a measured orientation) of `data`; `None`: not predictable.
    fn from_residuals(
        data: &[Measurement],
        residuals: impl Iterator<Item = Option<(Vector3<f64>, Option<f64>)>>,
    ) -> Self {
        let mut xyz = Vec::with_capacity(data.len());
        let mut norms = Vec::with_capacity(data.len());
        let mut angles = Vec::with_capacity(data.len());
        for (m, r) in data.iter().zip(residuals) {
            match r {
                Some((r, angle)) => {
                    let d = r * 1e3;
                    norms.push(d.norm());
                    xyz.push([Some(d.x), Some(d.y), Some(d.z)]);
                    angles.push(angle);
                }
                None => {
                    norms.push(f64::INFINITY);
                    xyz.push([None; 3]);
                    angles.push(m.orientation.map(|_| f64::INFINITY));
                }
            }
        }
        let orientation = OrientationStats::from_angles_deg(&angles);
        SetErrors {
            positions_mm: data
                .iter()
                .map(|m| [m.position.x * 1e3, m.position.y * 1e3, m.position.z * 1e3])
                .collect(),
            errors_xyz_mm: xyz,
            orientation_errors_deg: if orientation.is_some() {
                angles
            } else {
                Vec::new()
            },
            orientation,
            ..SetErrors::new(norms)
        }
    }
}

/// Predicted pose (position [m], rotation) in the registered base frame, the
/// position with the compensator's residual when there is one (the rotation
/// is the geometric model's: compensators correct position only); `None`
/// when the model cannot predict the pose.
pub(crate) fn predict_compensated(
    model: &RobotModel,
    compensator: Option<&dyn Compensator>,
    m: &Measurement,
) -> Option<(Vector3<f64>, Matrix3<f64>)> {
    let (p, r) = super::least_squares::predict(model, m)?;
    match compensator {
        None => Some((p, r)),
        Some(c) => {
            let ch = crate::model::kinematics::chain(model, &m.q).ok()?;
            let tau = crate::model::kinematics::gravity_torques_of(model, &ch, m.payload_mass);
            let mut pose =
                crate::model::Pose::new(r, p + c.residual_at(&m.q, &tau, m.payload_mass));
            let d = crate::model::calibrated::orientation::point_in_tcp(c, model);
            crate::model::calibrated::orientation::rotate(
                &mut pose,
                c,
                (&m.q, &tau, m.payload_mass),
                d.as_ref(),
            );
            Some((pose.p, pose.r))
        }
    }
}

/// Where a pose came from: its measurement set, the row (step) number in that
/// upload (1-based data row) and the tracker session's name. Filled by the
/// caller that knows the uploads; empty when unknown.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct PoseSource {
    /// The measurement set's name.
    pub set: String,
    /// 1-based data row in that upload.
    pub row: usize,
    /// The tracker session's name.
    pub session: String,
}

/// Pose sources of the sets, in the order of the report's per-pose vectors.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct PoseSources {
    /// Sources of the identification poses.
    #[serde(default)]
    pub identification: Vec<PoseSource>,
    /// Sources of the validation poses.
    #[serde(default)]
    pub validation: Vec<PoseSource>,
    /// The compensator training pool (Q2), when one was given.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub training: Vec<PoseSource>,
}

/// One identified parameter in display units (mm, deg or rad/(N·m)).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParamEstimate {
    /// The parameter's name (`ParamId::name`).
    pub name: String,
    /// Its display unit: `mm`, `deg`, `rad/(N·m)` or `kg`.
    pub unit: String,
    /// Its nominal value [unit].
    pub nominal: f64,
    /// Its identified value [unit].
    pub value: f64,
    /// Its standard deviation from the fit's covariance [unit] (`None`: no covariance, or held at a
    /// bound).
    pub std: Option<f64>,
}

/// TLBO summary of SKCM-C.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TlboSummary {
    /// Learners in the class.
    pub population: usize,
    /// Generations run.
    pub generations: usize,
    /// Cost evaluations (eq. 7.10).
    pub evaluations: usize,
    /// Best eq. 7.10 cost [mm²] after each generation.
    pub history: Vec<f64>,
}

/// Result of one method.
#[derive(Debug, Clone, Serialize)]
pub struct MethodReport {
    /// The method reported.
    pub method: Method,
    /// How its least-squares fit ended.
    pub solver: LmReport,
    /// Errors on the identification set.
    pub identification: SetErrors,
    /// Errors on the validation set, when one was given.
    pub validation: Option<SetErrors>,
    /// Errors on the compensator training pool (Q2), when one was given.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub training: Option<SetErrors>,
    /// The identified parameters in display units.
    pub parameters: Vec<ParamEstimate>,
    /// Identified joint stiffness 1/c [N·m/rad] (None: not identified / rigid).
    pub stiffness_nm_per_rad: Vec<Option<f64>>,
    /// The TLBO search's summary (SKCM-C by TLBO only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tlbo: Option<TlboSummary>,
    /// Physically implausible or doubtful results (the figures stay reported).
    pub warnings: Vec<MethodWarning>,
    /// The calibrated model in the registered base frame (mm/deg).
    pub model: ModelDescription,
    /// The learned compensator of a compensator method (or of `auto`'s choice):
    /// what it is, how it was trained, on which poses, and its effect per set.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub compensator: Option<CompensatorSummary>,
    /// What `auto` compared and why it chose what it did.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub auto: Option<AutoSummary>,
    /// The joint maps of a joint-map method: how they were chosen, per joint
    /// its range and amplitude.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub joint_maps: Option<JointMapsSummary>,
    /// The calibrated model in SI units, registered base frame (the model file stores it).
    #[serde(skip)]
    pub calibrated: RobotModel,
    /// The trained compensator (the model file stores it).
    #[serde(skip)]
    pub stored_compensator: Option<StoredCompensator>,
    /// Where the compensator was trained (the model file stores it).
    #[serde(skip)]
    pub stored_support: Option<Support>,
    /// The compensator's orientation part, trained where the data measured
    /// orientations (the model file stores it).
    #[serde(skip)]
    pub stored_orientation: Option<crate::model::calibrated::StoredOrientation>,
    /// The validation poses' evidence for the accuracy at a production tool
    /// (the model file stores it as `validation`).
    #[serde(skip)]
    pub validation_evidence: Option<crate::model::calibrated::ValidationEvidence>,
}

impl MethodReport {
    /// The trained compensator as predictions use it: faded beyond its
    /// support.
    pub fn compensator_arc(&self) -> Option<Arc<LearnedCompensator>> {
        self.stored_compensator.clone().map(|c| {
            c.into_arc_oriented(self.stored_orientation.clone(), self.stored_support.clone())
        })
    }

    /// The method a model file of this result names: the method itself, or
    /// for `auto` the method it chose (`auto: skcm-nn`).
    pub fn model_file_method(&self) -> String {
        match &self.auto {
            Some(a) => format!("{}: {}", self.method.name(), a.chosen.name()),
            None => self.method.name().to_string(),
        }
    }
}

/// How the joint maps were chosen (cross-validated over the poses, K = 0 is
/// the geometry alone) and what they hold per joint.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct JointMapsSummary {
    /// Poses the maps were fitted on (identification and training).
    pub poses: usize,
    /// The chosen number of harmonics (0: no maps kept) and ridge weight.
    pub harmonics: usize,
    /// The chosen ridge weight λ.
    pub ridge: f64,
    /// Cross-validated mean position error with the chosen maps [mm].
    pub cv_mean_mm: f64,
    /// Cross-validated largest position error with the chosen maps [mm].
    pub cv_max_mm: f64,
    /// The geometry alone on the same folds.
    pub cv_without_maps_mean_mm: f64,
    /// The geometry alone's cross-validated largest error on the same folds [mm].
    pub cv_without_maps_max_mm: f64,
    /// Every (K, λ) the cross-validation tried.
    pub candidates: Vec<MapCandidate>,
    /// Per joint: its trained range and largest |Δθ| [deg] (`None`: no map).
    pub joints: Vec<Option<JointMapExtent>>,
    /// Joints whose map the measurements cannot see (position-only data, the
    /// measured point near the joint's axis): not fitted, with the reason.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub refused: Vec<RefusedMap>,
}

/// One joint's map in a report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct JointMapExtent {
    /// The joint's trained range `[low, high]` [deg].
    pub range_deg: [f64; 2],
    /// Width beyond the range over which the map fades to zero [deg].
    pub fade_deg: f64,
    /// The map's largest |Δθ| [arcsec].
    pub amplitude_arcsec: f64,
}

impl JointMapsSummary {
    /// The summary of joint-map fit `fit` and the maps `model` carries.
    pub fn of(fit: &MapFit, model: &RobotModel) -> Self {
        let n = model.dof();
        let joints = match &model.joint_maps {
            None => vec![None; n],
            Some(maps) => maps
                .joints
                .iter()
                .map(|m| {
                    m.as_ref().map(|m| JointMapExtent {
                        range_deg: m.range.map(f64::to_degrees),
                        fade_deg: m.fade.to_degrees(),
                        amplitude_arcsec: m.amplitude().to_degrees() * 3600.0,
                    })
                })
                .collect(),
        };
        JointMapsSummary {
            poses: fit.poses,
            harmonics: fit.chosen.harmonics,
            ridge: fit.chosen.ridge,
            cv_mean_mm: fit.chosen.cv_mean_mm,
            cv_max_mm: fit.chosen.cv_max_mm,
            cv_without_maps_mean_mm: fit.without_maps.cv_mean_mm,
            cv_without_maps_max_mm: fit.without_maps.cv_max_mm,
            candidates: fit.candidates.clone(),
            joints,
            refused: fit.refused.clone(),
        }
    }
}

/// A compensator method's network, its training and its effect: the base
/// model's statistics next to the compensated ones on every set.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CompensatorSummary {
    /// The model-based method under it (`km` or `skcm`).
    pub base: Method,
    /// `mlp` or `rbf`.
    pub kind: String,
    /// Hidden units (MLP) or radial units (RBF).
    pub units: usize,
    /// Inputs of the network (e.g. `q, sin q, cos q` or `gravity torques`).
    pub inputs: String,
    /// The training run on the whole pool: trainer, epochs / iterations /
    /// generations, evaluations, why it stopped, training RMS.
    pub training: TrainReport,
    /// Which poses trained it: `training` (the Q2 pool) or `identification`
    /// (no training pool given; judged by k-fold cross-validation inside it).
    pub trained_on: String,
    /// Poses that trained it.
    pub training_poses: usize,
    /// k-fold cross-validation on the training pool (none when switched off).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cross_validation: Option<CvStats>,
    /// The base alone on the identification and validation sets [mm].
    pub base_identification: ErrorStats,
    /// The base alone on the validation set, when one was given [mm].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub base_validation: Option<ErrorStats>,
    /// The base alone on the training pool, when it is a set of its own [mm].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub base_training: Option<ErrorStats>,
    /// Each joint's trained range [deg]: the correction fades to zero over
    /// `fade_deg` beyond it.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub trained_ranges_deg: Vec<[f64; 2]>,
    /// Width beyond the trained ranges over which the correction fades to zero [deg].
    #[serde(default)]
    pub fade_deg: f64,
    /// The expected error per pose checked on the validation set, for
    /// compensators that give one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub uncertainty: Option<UncertaintyCheck>,
    /// With orientation measurements: what the compensator does to them (it
    /// corrects position only, the orientation figures are the base's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub orientation_note: Option<String>,
    /// Whether the compensator has an orientation part, and why (always
    /// given: position-only data say `not_measured`).
    pub orientation_part: OrientationPart,
}

/// Whether a compensator corrects the orientation (a closed set; the report
/// serialises the snake-case names).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OrientationPartStatus {
    /// Trained on the pool's orientation residuals and applied.
    Trained,
    /// No training pose measured an orientation: there is nothing to learn it
    /// from, the orientation is the base's and a production tool's
    /// orientation is unverified.
    NotMeasured,
    /// Fewer than half of the training poses (or fewer than 5) measured one.
    TooFewPoses,
    /// Its training failed; the compensator corrects the position only.
    TrainingFailed,
    /// `auto` dropped it: on held-out poses it did not lower the
    /// orientation mean below the base's.
    NotKept,
}

impl OrientationPartStatus {
    /// Every status, in declaration order.
    pub const ALL: [OrientationPartStatus; 5] = [
        OrientationPartStatus::Trained,
        OrientationPartStatus::NotMeasured,
        OrientationPartStatus::TooFewPoses,
        OrientationPartStatus::TrainingFailed,
        OrientationPartStatus::NotKept,
    ];

    /// The serialised name.
    pub fn name(self) -> &'static str {
        match self {
            OrientationPartStatus::Trained => "trained",
            OrientationPartStatus::NotMeasured => "not_measured",
            OrientationPartStatus::TooFewPoses => "too_few_poses",
            OrientationPartStatus::TrainingFailed => "training_failed",
            OrientationPartStatus::NotKept => "not_kept",
        }
    }
}

/// Out-of-fold orientation errors of a compensator's orientation part on the
/// training pool's poses that measured an orientation [deg]: the base alone
/// (`|ω|`, the angle of `R_measured·R_predictedᵀ`) and after the correction
/// trained without the pose's fold (`|ω − ω̂|`, that angle to first order).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OrientationCv {
    /// Folds of the cross-validation.
    pub folds: usize,
    /// Poses that measured an orientation.
    pub poses: usize,
    /// Mean orientation error of the base alone [deg].
    pub base_mean_deg: f64,
    /// Largest orientation error of the base alone [deg].
    pub base_max_deg: f64,
    /// Mean out-of-fold orientation error after the correction [deg].
    pub compensated_mean_deg: f64,
    /// Largest out-of-fold orientation error after the correction [deg].
    pub compensated_max_deg: f64,
}

impl OrientationCv {
    /// From a cross-validation of rotation-vector samples, whose "mm" are
    /// mrad (`compensate::cross_validate` scales residual norms by 1e3).
    pub fn of(cv: &CvStats) -> Self {
        let deg = |mrad: f64| (mrad * 1e-3).to_degrees();
        OrientationCv {
            folds: cv.folds,
            poses: cv.base.n,
            base_mean_deg: deg(cv.base.mean_mm),
            base_max_deg: deg(cv.base.max_mm),
            compensated_mean_deg: deg(cv.compensated.mean_mm),
            compensated_max_deg: deg(cv.compensated.max_mm),
        }
    }

    /// Whether the part lowered the held-out orientation mean by at least
    /// `min_gain` (relative).
    pub fn helps(&self, min_gain: f64) -> bool {
        self.compensated_mean_deg <= self.base_mean_deg * (1.0 - min_gain)
    }
}

/// A compensator's orientation part in a report: its status, why, and its
/// cross-validation where one ran.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OrientationPart {
    /// Whether it is trained and applied.
    pub status: OrientationPartStatus,
    /// Why, in words.
    pub reason: String,
    /// The cross-validation of the part, where one ran.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cross_validation: Option<OrientationCv>,
}

/// How well a compensator's expected error per pose `u` (the RMS of the 3-D
/// error it expects) matches the validation errors `e`. For Gaussian errors
/// `e > u` in 39.2 % of poses and `e > 2u` in 0.74 % (P(χ²₃ > 3), P(χ²₃ > 12)).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct UncertaintyCheck {
    /// Validation poses compared.
    pub poses: usize,
    /// Mean of `u` over the validation poses [mm].
    pub mean_expected_mm: f64,
    /// RMS of the validation errors over RMS of `u` (1: calibrated).
    pub rms_ratio: f64,
    /// Share of poses with `e > u`, and the Gaussian expectation.
    pub above_expected: f64,
    /// The Gaussian share of poses with `e > u`, 0.392.
    pub above_expected_gaussian: f64,
    /// Share of poses with `e > 2u`, and the Gaussian expectation.
    pub above_twice_expected: f64,
    /// The Gaussian share of poses with `e > 2u`, 0.0074.
    pub above_twice_expected_gaussian: f64,
}

impl UncertaintyCheck {
    /// The check of expected errors `u` against errors `e` [mm], pose by pose.
    pub fn of(expected_mm: &[f64], errors_mm: &[f64]) -> Option<Self> {
        let n = expected_mm.len().min(errors_mm.len());
        if n == 0 {
            return None;
        }
        let pairs = || expected_mm.iter().zip(errors_mm).take(n);
        let share = |k: f64| pairs().filter(|(u, e)| **e > k * **u).count() as f64 / n as f64;
        let rms =
            |v: &mut dyn Iterator<Item = f64>| (v.map(|x| x * x).sum::<f64>() / n as f64).sqrt();
        let ru = rms(&mut pairs().map(|(u, _)| *u));
        let re = rms(&mut pairs().map(|(_, e)| *e));
        Some(UncertaintyCheck {
            poses: n,
            mean_expected_mm: pairs().map(|(u, _)| *u).sum::<f64>() / n as f64,
            rms_ratio: if ru > 0.0 { re / ru } else { f64::INFINITY },
            above_expected: share(1.0),
            above_expected_gaussian: 0.392,
            above_twice_expected: share(2.0),
            above_twice_expected_gaussian: 0.0074,
        })
    }

    /// A warning when the expected errors are too optimistic: more than
    /// twice the Gaussian share of poses above `2u`, and at least 3 poses.
    pub fn warning(&self) -> Option<String> {
        let above = (self.above_twice_expected * self.poses as f64).round();
        (above >= 3.0 && self.above_twice_expected > 2.0 * self.above_twice_expected_gaussian + 0.01)
            .then(|| {
                format!(
                    "the compensator's expected errors are optimistic: {:.1} % of the validation poses are above twice theirs (Gaussian: {:.1} %)",
                    self.above_twice_expected * 100.0,
                    self.above_twice_expected_gaussian * 100.0
                )
            })
    }
}

/// One candidate `auto` weighed: cross-validated errors on the training pool
/// [mm] of the base alone and with the compensator.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AutoCandidate {
    /// The candidate method.
    pub method: Method,
    /// Cross-validation of the compensator on the training pool [mm] (`None` for a failed or a
    /// joint-map candidate).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cross_validation: Option<CvStats>,
    /// Why it was not available (training failed, base failed).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub failed: Option<String>,
    /// The cross-validation of its orientation part, where the pool
    /// measured orientations.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub orientation_cross_validation: Option<OrientationCv>,
}

/// The choice of `auto`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AutoSummary {
    /// The method whose model `auto` delivers (a base or a compensator method).
    pub chosen: Method,
    /// The choice in words: the decision, the chosen option's mean, why the others lost.
    pub reason: String,
    /// Every option `auto` weighed.
    pub candidates: Vec<AutoCandidate>,
    /// The chosen compensator's orientation part: kept only when it lowered
    /// the cross-validated orientation mean (none without a compensator or
    /// without orientation measurements).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub orientation_part: Option<OrientationPart>,
    /// How the rule between the options decided (`methods::ties`).
    pub decision: AutoDecision,
}

/// How `auto` decided between its options: a tie or not, the step of the
/// tie rule that decided, the runner-up and the margin
/// (`methods::ties::break_ties`), and the fallback from an option on the
/// weaker base.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AutoDecision {
    /// Whether another option's cross-validated mean was within
    /// `tie_margin` of the lowest.
    pub tie: bool,
    /// The step of the tie rule that decided (`methods::ties`).
    pub step: DecidingStep,
    /// What the step compares ([`DecidingStep::label`]).
    pub step_label: &'static str,
    /// The best of the options the deciding step removed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub runner_up: Option<Method>,
    /// By how much the winner led the runner-up at the deciding step, in
    /// `margin_unit` (0 without a runner-up).
    pub margin: f64,
    /// Unit of `margin`: `mm`, `physics rank` or `fitted quantities`.
    pub margin_unit: &'static str,
    /// The runner-up's cross-validated mean less the winner's [mm].
    pub mean_margin_mm: f64,
    /// The relative margin within which figures are a tie.
    pub tie_margin: f64,
    /// The option the rule chose first, set aside because it sits on the
    /// weaker base.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fallback: Option<BaseFallback>,
    /// The options the blocked-fold veto checked, in order: each vetoed
    /// one, then the one delivered (`methods::veto`); empty when the option
    /// chosen is a base alone or the veto could not run.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub blocked_checks: Vec<BlockedCheck>,
}

/// The better base took over from an option on the weaker one: beyond its
/// trained region a compensator or map fades to its base.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BaseFallback {
    /// The option the tie rule chose among all.
    pub instead_of: Method,
    /// The base under `instead_of`.
    pub weaker_base: Method,
    /// The base that beats it outside the trained region.
    pub better_base: Method,
    /// The two bases alone, weaker and better [mm], measured as `measured_by`
    /// says.
    pub weaker_mm: f64,
    /// The better base alone [mm], measured as `measured_by` says.
    pub better_mm: f64,
    /// What the two figures measure, in words.
    pub measured_by: String,
}

impl AutoDecision {
    /// The decision in words, with `winner` the chosen method.
    pub fn sentence(&self, winner: Method) -> String {
        let pct = self.tie_margin * 100.0;
        let mut s = match (self.runner_up, self.tie) {
            (None, _) => format!("{winner}: the only option"),
            (Some(r), false) => format!(
                "{winner}: no tie, its cross-validated mean {:.4} mm below {r}'s (more than {pct:.0} % apart)",
                self.mean_margin_mm
            ),
            (Some(r), true) => format!(
                "{winner}: tied with {r} on the cross-validated mean (within {pct:.0} %, {:+.4} mm), decided by {} by {:.4} {}",
                self.mean_margin_mm, self.step_label, self.margin, self.margin_unit
            ),
        };
        if let Some(f) = &self.fallback {
            s.push_str(&format!(
                "; {} was set aside: it sits on {}, which {} beats outside the trained region ({:.4} against {:.4} mm, {})",
                f.instead_of, f.weaker_base, f.better_base, f.weaker_mm, f.better_mm, f.measured_by
            ));
        }
        for c in &self.blocked_checks {
            s.push_str(&format!("; blocked-fold veto: {}", c.sentence()));
        }
        s
    }
}

/// Kind of a method warning.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WarningKind {
    /// The solver stopped without a passed convergence test.
    NotConverged,
    /// A compliance is held at its bound c = 0: the unconstrained fit wanted a
    /// negative compliance.
    ComplianceAtBound,
    /// An identified stiffness 1/c lies outside the plausible range.
    StiffnessImplausible,
    /// A parameter the method considered is not identifiable from these poses
    /// and stays at its nominal value.
    ParameterNotIdentifiable,
    /// The identified payload is physically implausible (a negative total mass).
    PayloadImplausible,
    /// The compensator's expected errors are below what validation shows.
    UncertaintyOptimistic,
    /// A joint's map was not fitted: the measurements cannot see its angle.
    MapRefused,
}

/// A warning about one method's result.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MethodWarning {
    /// What the warning is about.
    pub kind: WarningKind,
    /// Joint number (1-based) the warning is about.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub joint: Option<usize>,
    /// The warning in words.
    pub message: String,
}

/// A method that did not deliver a model, and why.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FailedMethod {
    /// The method that failed.
    pub method: Method,
    /// Why it failed, in words.
    pub reason: String,
}

/// Registration of each measurement session.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SessionRegistration {
    /// The 0-based tracker session.
    pub session: usize,
    /// Tracker → registered base frame (`x_base = R·x_tracker + t`).
    pub tracker_to_base: PoseDescription,
    /// RMS distance of the nominal model after the registration [mm].
    pub rms_mm: f64,
}

/// Nominal-model errors (before calibration) in the registered frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NominalErrors {
    /// Errors of the nominal model on the identification set.
    pub identification: SetErrors,
    /// Errors of the nominal model on the validation set, when one was given.
    pub validation: Option<SetErrors>,
}

/// Everything a calibration found.
#[derive(Debug, Clone, Serialize)]
pub struct CalibrationReport {
    /// [`REPORT_FORMAT_VERSION`] of the writer.
    pub format_version: u32,
    /// The robot model's name.
    pub robot: String,
    /// Identification poses used.
    pub identification_poses: usize,
    /// Validation poses given (0: none).
    pub validation_poses: usize,
    /// Poses of the compensator training pool (Q2; 0: none given, compensators
    /// train on the identification poses).
    #[serde(default)]
    pub training_poses: usize,
    /// Each session's registration, by session index.
    pub registration: Vec<SessionRegistration>,
    /// Which parameters were identified, and how well the poses determine them.
    pub identifiability: IdentifiabilityReport,
    /// Errors of the nominal model after registration.
    pub nominal: NominalErrors,
    /// Serialised by name, in the order of the names.
    pub methods: BTreeMap<Method, MethodReport>,
    /// Methods that failed, with their reasons (the others are still reported).
    pub failed: Vec<FailedMethod>,
    /// Names of the tracker sessions by index (empty: unnamed).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub session_names: Vec<String>,
    /// Where each pose came from (empty: unknown).
    #[serde(skip_serializing_if = "PoseSources::is_empty")]
    pub pose_sources: PoseSources,
    /// Tracker → registered base frame of session 0.
    #[serde(skip)]
    pub tracker_to_base: Pose,
}

impl CalibrationReport {
    /// The best method by validation mean (identification mean without validation).
    pub fn best_method(&self) -> Option<&MethodReport> {
        self.methods.values().min_by(|a, b| {
            let key = |m: &MethodReport| {
                m.validation
                    .as_ref()
                    .map_or(m.identification.stats.mean_mm, |v| v.stats.mean_mm)
            };
            key(a).total_cmp(&key(b))
        })
    }
}

impl PoseSources {
    /// Whether no set has pose sources.
    pub fn is_empty(&self) -> bool {
        self.identification.is_empty() && self.validation.is_empty() && self.training.is_empty()
    }
}

/// Identified parameters in display units; σ from the covariance (none for a
/// parameter held at a bound).
pub(crate) fn estimates(
    nominal: &RobotModel,
    fitted: &RobotModel,
    ids: &[ParamId],
    cov: Option<&DMatrix<f64>>,
    at_bound: &[bool],
) -> Vec<ParamEstimate> {
    ids.iter()
        .enumerate()
        .map(|(i, id)| ParamEstimate {
            name: id.name(),
            unit: id.unit_name().into(),
            nominal: id.to_display(crate::model::params::get(nominal, *id)),
            value: id.to_display(crate::model::params::get(fitted, *id)),
            std: cov
                .filter(|c| i < c.nrows() && !at_bound.get(i).copied().unwrap_or(false))
                .map(|c| id.to_display(c[(i, i)].max(0.0).sqrt())),
        })
        .collect()
}
