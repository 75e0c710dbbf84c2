//! Why training a compensator failed.

use super::rbf::RbfTrainError;

/// Why training failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TrainError {
    #[error("training cancelled")]
    Cancelled,
    #[error("a compensator needs at least 5 training poses, got {got}")]
    TooFewSamples { got: usize },
    #[error("training samples must have the same number of joints and finite residuals")]
    InconsistentSamples,
    #[error("the MLP needs at least one hidden unit")]
    NoHiddenUnits,
    #[error(transparent)]
    Rbf(#[from] RbfTrainError),
    #[error("gp: no length scale and noise gave a positive definite system")]
    GpSingular,
}
