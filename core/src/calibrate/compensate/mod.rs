//! Training the learned compensator on what the calibrated model leaves
//! (thesis eq. 2.1; the model that predicts with it, its stored forms and
//! its file are `model::calibrated`): the training samples (`sample.rs`),
//! what a family answers for training (`family.rs`) and which one to train
//! (`spec.rs`, derived from the families' table), training with the checks
//! every family shares (`training.rs`, `error.rs`, `report.rs`), the
//! orientation part's samples (`oriented.rs`), cross-validation and the
//! choice of `auto` (`select.rs`), and a folder per family's trainers
//! (`gp/`, `mlp/`, `rbf/`).

pub mod error;
pub mod family;
pub mod gp;
pub mod mlp;
pub mod oriented;
pub mod rbf;
pub mod report;
pub mod sample;
pub mod select;
pub mod spec;
pub mod training;

pub use error::TrainError;
pub use family::Family;
pub use gp::{train_gp, GpReport, GpSettings};
pub use mlp::{
    IwoSettings, LmTrainSettings, MlpSettings, MlpSpec, OutputLayer, TlboTrainSettings, Trainer,
};
pub use oriented::OrientationSamples;
pub use rbf::{train_rbf, train_rbf_with_progress, RbfReport, RbfSettings, RbfTrainError};
pub use report::TrainReport;
pub use sample::{samples_of, Sample};
pub use select::{blocked_fold_assignment, choose, cross_validate, BlockedFold, Choice, CvStats};
pub use spec::CompensatorSpec;
pub use training::train;
