//! The calibrated model as a solve, a check or an export uses it: the
//! identified geometry and compliance, the registered cell frame, the
//! payload and the learned compensator that predicts what they leave
//! (`compensated.rs`, thesis eq. 2.1), the stored compensators (one table,
//! `stored.rs`, a folder per family: `gp/`, `mlp/`, `rbf/`), where they were
//! trained and how they fade (`support.rs`, `learned.rs`), their
//! orientation part (`orientation.rs`), the calibrated model file and its
//! loader (`file.rs`) and the validation evidence it keeps (`evidence.rs`).
//! Training, selection and identification are `calibrate`'s.

pub mod compensated;
pub mod compensation;
pub mod compensator;
pub mod evidence;
pub mod file;
pub mod gp;
pub mod invalid;
pub mod learned;
pub mod mlp;
pub mod orientation;
pub mod rbf;
pub mod stored;
pub mod support;

pub use compensated::{CompensateError, CompensatedModel, Prediction};
pub use compensation::Compensation;
pub use compensator::{Compensator, Uncertainty};
pub use evidence::{TipTerm, ValidationEvidence};
pub use file::{parse_compensated, CalibratedModelFile, PoseDescription, CALIBRATED_MODEL_FORMAT};
pub use gp::{Gp, PreparedGp};
pub use invalid::InvalidCompensator;
pub use learned::LearnedCompensator;
pub use mlp::{Features, Mlp, Normalisation};
pub use orientation::StoredOrientation;
pub use rbf::{OutputFrame, Rbf};
pub use stored::{NetworkShape, StoredCompensator, StoredFamily};
pub use support::{Support, SupportCoverage};
