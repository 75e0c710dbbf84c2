//! The RBF family, KM-RBF (thesis ch. 3, eqs. 3.10–3.12): a radial basis
//! network from the gravity torques to the position residual, grown greedily;
//! the network and its prediction (`model`) and its entry in the stored
//! compensators' table (`family`); its training is `calibrate::compensate::rbf`.
//!
//! Hidden unit `i`: `o_i = exp(−n²)`, `n = ‖w_i − p‖·b` (eqs. 3.10–3.11) with the
//! input `p` the normalised gravity torques and one bias `b = √ln2 / spread` for
//! all units (MATLAB `newrb`: a unit answers 0.5 at distance `spread`). Linear
//! output layer with bias. Training (§3.2, as `newrb`): start with no unit; run
//! the network, add a unit centred on the training input with the largest
//! residual error, re-solve the linear layer by least squares (SVD), repeat up to
//! `max_neurons` (40 in the seed). The spread and the number of units are chosen
//! on a held-out part of the training set (`RbfSettings`); the network is then
//! re-grown on all training samples with that spread and size.
//!
//! Inputs: the gravity torques τ [N·m] at the commanded joints, min–max
//! normalised to `[−1, 1]` per joint over the training set (joints whose torque
//! never changes, e.g. joint 1 of a floor robot, drop out). Outputs: the residual
//! [m], in the registered base frame (`OutputFrame::Base`, the thesis's choice)
//! or turned by `−q1` about the base z axis (`OutputFrame::Joint1`): gravity
//! torques do not see `q1`, while an error caused by them turns with the arm
//! about joint 1, so a network of τ alone can only learn it in a frame that
//! turns with joint 1 (exact for a floor or ceiling robot whose joint 1 axis is
//! the base z axis). The derivative in `q` is that of the frame rotation; the
//! torques' own dependence on `q` is neglected as in the IK's quasi-Newton
//! Jacobian (see [`CompensatedModel::predict_base_with_jacobian`](crate::model::calibrated::CompensatedModel::predict_base_with_jacobian)).

mod family;
pub mod model;

pub use model::{OutputFrame, Rbf};
