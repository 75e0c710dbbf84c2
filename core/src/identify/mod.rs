//! Identification: registration of the measurement frame, identifiability
//! analysis, and the model-based methods of the seed: KM (§2.2, eqs. 2.3–2.4),
//! SKCM (§2.3, eq. 2.8; closed loop eq. 4.17) and SKCM-C by TLBO (ch. 7,
//! eqs. 7.7–7.12). Statistics per set follow DESIGN "Data roles".
//!
//! Units: SI inside; reports speak millimetres and degrees (compliance in
//! rad/(N·m), stiffness in N·m/rad).

pub mod calibrate;
pub mod identifiability;
pub mod least_squares;
pub mod pose_selection;
pub mod registration;
pub mod stats;
pub mod tlbo;

pub use calibrate::{
    calibrate, CalibrationError, CalibrationOptions, CalibrationReport, Method, MethodReport,
    ParamEstimate, Progress, SetErrors,
};
pub use identifiability::{IdentifiabilityReport, IdentifiabilitySettings};
pub use least_squares::{LmReport, LmSettings};
pub use registration::{register, Registration};
pub use stats::ErrorStats;
pub use tlbo::TlboSettings;
