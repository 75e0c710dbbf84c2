//! Why a method did not deliver: cancelled, or a [`MethodFailure`] the report
//! lists with its message (`FailedMethod::reason`) while the other methods go on.

use super::Method;
use crate::calibrate::compensate::TrainError;
use crate::calibrate::identify::joint_maps::MapFitError;
use crate::calibrate::identify::least_squares::Cancelled;
use crate::model::kinematics::KinematicsError;
use crate::model::ModelError;

/// A method stopped: the calibration was cancelled, or the method failed.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum MethodError {
    Cancelled,
    Failed(MethodFailure),
}

impl From<Cancelled> for MethodError {
    fn from(_: Cancelled) -> Self {
        MethodError::Cancelled
    }
}

impl From<MethodFailure> for MethodError {
    fn from(f: MethodFailure) -> Self {
        MethodError::Failed(f)
    }
}

/// Why a method failed on these data (the message says what to do instead).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MethodFailure {
    /// A compliance method on a model without link masses and data without a payload.
    #[error("the model has no link masses and the measurements carry no payload, so gravity puts no torque on any joint and no compliance can be identified; add link masses (`mass_kg`, `com_mm`) to the model or a payload (`payload_kg`), or use km")]
    NoGravityTorque,
    /// A compliance method where the identifiability analysis kept no joint compliance.
    #[error("gravity puts no torque on any joint in these poses, so no compliance can be identified; use km")]
    NoComplianceIdentifiable,
    /// SKCM-C's frozen KM Jacobian cannot be factorised at the KM fit's geometry.
    #[error("the KM fit's Jacobian is singular at the reference geometry")]
    SingularReference,
    /// `skcm-payload` on identification poses whose payload mass is 0 everywhere.
    #[error("no identification pose carries a payload (payload_kg is 0 everywhere), so its centre of mass has no effect; give the payload mass (`payload_kg`) or use skcm")]
    NoPayload,
    /// `skcm-payload` after an SKCM fit that identified no compliance.
    #[error("SKCM identified no compliance, so the payload's centre of mass has no effect on the measurements; use skcm or km")]
    NoComplianceIdentified,
    /// `skcm-payload` where the poses identify neither the payload's centre of mass nor its
    /// mass offset.
    #[error("the poses do not excite the payload (neither its centre of mass nor its mass is identifiable); measure poses that turn the tool through different orientations")]
    PayloadNotExcited,
    /// The fitted model's description does not load back into a model.
    #[error("the {method} model does not load back: {cause}")]
    DoesNotLoadBack {
        /// The method whose fit it is.
        method: Method,
        /// Why the description does not load.
        cause: ModelError,
    },
    /// A compensator method's base method failed.
    #[error("its base method {base} failed: {cause}")]
    BaseFailed {
        /// The base method.
        base: Method,
        /// Why it failed.
        cause: Box<MethodFailure>,
    },
    /// The fitted base model cannot predict a training pose, so it has no residual to learn.
    #[error("the base model cannot predict training pose {pose}")]
    UnpredictableTrainingPose {
        /// The training pose, 1-based.
        pose: usize,
    },
    /// The fitted base model's kinematics failed at a training pose's joints.
    #[error("training pose {pose}: {cause}")]
    TrainingPose {
        /// The training pose, 1-based.
        pose: usize,
        /// Why the kinematics failed.
        cause: KinematicsError,
    },
    /// The torque-input RBF where every training pose's gravity torques are zero.
    #[error("the model has no masses, so every gravity torque is zero and the torque-input RBF has nothing to learn from; use skcm-nn or km")]
    NoTorqueToLearn,
    /// The joint maps could not be fitted.
    #[error("joint maps: {0}")]
    JointMaps(MapFitError),
    /// The compensator's training refused its data (any [`TrainError`] but a cancel).
    #[error(transparent)]
    Training(TrainError),
    /// `auto`: neither base fitted; the notes say why.
    #[error("no base method succeeded: {}", .notes.join("; "))]
    NoBaseSucceeded {
        /// Per base, why it did not fit.
        notes: Vec<String>,
    },
}
