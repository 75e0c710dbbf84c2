//! Identification: registration of the measurement frame, identifiability
//! analysis, and the model-based methods of the seed: KM (§2.2, eqs. 2.3–2.4),
//! SKCM (§2.3, eq. 2.8; closed loop eq. 4.17) and SKCM-C by TLBO (ch. 7,
//! eqs. 7.7–7.12), and SKCM with the payload's centre of mass (beyond the
//! seed); the compensator methods KM-RBF, SKCM-NN, SKCM-IWONN, SKCM-TLBONN
//! (ch. 3–6) and `auto` on top of them. The methods are one table
//! (`methods::METHODS`). Statistics per set follow docs/design.md "Data roles".
//!
//! Units: SI inside; reports speak millimetres and degrees (compliance in
//! rad/(N·m), stiffness in N·m/rad).

pub mod checks;
mod evaluate;
pub mod evidence;
pub mod identifiability;
pub mod joint_maps;
pub mod least_squares;
pub mod methods;
pub mod model_file;
pub mod network;
pub mod options;
mod pipeline;
pub mod progress;
pub mod registration;
pub mod report;

pub use checks::CalibrationError;
pub use identifiability::{DropKind, IdentifiabilityReport, IdentifiabilitySettings};
pub use least_squares::{LmReport, LmSettings, StopReason};
pub use methods::{Method, MethodChoice, MethodFailure, MethodListError, MethodRow, METHODS};
pub use model_file::calibrated_model_file;
pub use options::{CalibrationOptions, CalibrationSettings, CompensatorOptions};
pub use pipeline::{calibrate, calibrate_with_training};
pub use progress::{Clock, Fold, Phase, Progress, ProgressReporter, SystemClock};
pub use registration::{register, Registration};
pub use report::{
    AutoCandidate, AutoDecision, AutoSummary, BaseFallback, CalibrationReport, CompensatorSummary,
    FailedMethod, JointMapExtent, JointMapsSummary, MethodReport, MethodWarning, NominalErrors,
    ParamEstimate, PoseSource, PoseSources, SetErrors, WarningKind, REPORT_FORMAT_VERSION,
};
