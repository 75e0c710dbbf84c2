//! Training the Gaussian-process family (KM-GP, SKCM-GP; the model, its
//! equations and its prediction: `model::calibrated::gp`): the length scales
//! (per joint, as fractions of the joint's trained range) and `σ²/s²` chosen
//! on a 20 % holdout drawn by the samples themselves, a grid, then one pass of per-joint refinement
//! (halve, double, drop).
//!
//! Files: its training (`train`), its entry in the training table
//! (`family`).

mod family;
mod train;

pub use train::{train_gp, GpReport, GpSettings};
