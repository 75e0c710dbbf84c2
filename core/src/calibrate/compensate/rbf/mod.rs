//! Training the RBF family, KM-RBF (thesis ch. 3, eqs. 3.10–3.12; the
//! network: `model::calibrated::rbf`), as MATLAB `newrb`: start with no unit;
//! run the network, add a unit centred on the training input with the largest
//! residual error, re-solve the linear layer by least squares (SVD), repeat up
//! to `max_neurons` (40 in the seed). The spread and the number of units are
//! chosen on a held-out part of the training set (`RbfSettings`); the network
//! is then re-grown on all training samples with that spread and size.
//!
//! Files: its training (`train`), its entry in the training table
//! (`family`).

mod family;
mod train;

pub use train::{train_rbf, train_rbf_with_progress, RbfReport, RbfSettings, RbfTrainError};
