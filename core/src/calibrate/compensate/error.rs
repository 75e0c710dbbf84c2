//! Why training a compensator failed.

use super::rbf::RbfTrainError;

/// Why training failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TrainError {
    /// The progress callback asked to stop.
    #[error("training cancelled")]
    Cancelled,
    /// Fewer than 5 training samples.
    #[error("a compensator needs at least 5 training poses, got {got}")]
    TooFewSamples {
        /// Samples given.
        got: usize,
    },
    /// A sample's joints or torques do not match the first's joint count, or a residual is not
    /// finite.
    #[error("training samples must have the same number of joints and finite residuals")]
    InconsistentSamples,
    /// The MLP's spec has no hidden unit.
    #[error("the MLP needs at least one hidden unit")]
    NoHiddenUnits,
    /// The RBF network's training failed.
    #[error(transparent)]
    Rbf(#[from] RbfTrainError),
    /// No candidate length scale and noise ratio gave a positive definite system.
    #[error("gp: no length scale and noise gave a positive definite system")]
    GpSingular,
}
