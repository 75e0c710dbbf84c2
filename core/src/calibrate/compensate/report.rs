//! What a compensator's training run did, as its report keeps it.

use super::gp::GpReport;
use super::rbf::RbfReport;
use serde::{Deserialize, Serialize};

/// What a training run did.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrainReport {
    /// `lm`, `iwo`, `tlbo` or `rbf`.
    pub trainer: String,
    /// Training samples (poses).
    pub samples: usize,
    /// Epochs (LM), iterations (IWO) or generations (TLBO) run; RBF units.
    pub epochs: usize,
    /// Loss evaluations (MLP), units added (RBF) or candidates fitted (GP).
    pub evaluations: usize,
    /// Final training loss (normalised units, see module docs).
    pub loss: f64,
    /// Why it stopped.
    pub stop: String,
    /// Training RMS of the residual error norm after compensation [mm].
    pub rms_mm: f64,
    /// What the RBF training chose (RBF only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rbf: Option<RbfReport>,
    /// How the GP's hyperparameters were chosen (GP only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gp: Option<GpReport>,
}
