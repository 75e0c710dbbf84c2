//! The Gaussian-process family (KM-GP, SKCM-GP): a sparse GP with per-joint
//! length scales and an expected error per pose (beyond the thesis; docs/design.md "Gaussian-process
//! compensator").
//!
//! Inputs: model-convention joints `q` [rad]; outputs: the three components of
//! the residual [m] in the registered base frame, one shared kernel
//! `k(a, b) = s²·exp(−½·Σ_j ((a_j − b_j)/ℓ_j)²)` (ℓ_j = ∞: joint j ignored).
//! The DTC approximation (Quiñonero-Candela & Rasmussen, JMLR 2005, eqs. 20–21)
//! on `M` inducing configurations `Z` (300 by default), chosen by
//! farthest-point sampling among the training joints:
//!
//! - mean `μ(q) = r̄ + k_Z(q)ᵀ·α`, `α = (σ²·K_ZZ + K_ZX·K_XZ)⁻¹·K_ZX·(Y − r̄)`;
//! - variance per component `v(q) = s² − k_Zᵀ·(K_ZZ⁻¹ − σ²·A⁻¹)·k_Z + σ²`,
//!   `A = σ²·K_ZZ + K_ZX·K_XZ`;
//! - expected position error `u(q) = κ·√(3·v(q))` [m], `κ` the ratio of the
//!   held-out RMS error to the held-out RMS of `√(3·v)`.
//!
//! The length scales (per joint, as fractions of the joint's trained range),
//! and `σ²/s²` are chosen on a 20 % holdout drawn by the samples themselves: a grid, then one pass of
//! per-joint refinement (halve, double, drop). Hand-written on nalgebra's
//! Cholesky: no maintained Rust crate offers sparse GP regression with an
//! analytic input gradient, which the IK needs.

//!
//! Files: the stored model and its reference evaluation (`model`), the
//! prepared form that predicts (`predict`, with `exp`, `avx2` and the
//! single-precision `rough`), its entry in the stored compensators' table
//! (`family`). Its training is `calibrate::compensate::gp`.

#[cfg(target_arch = "x86_64")]
mod avx2;
mod exp;
mod family;
pub mod model;
pub(crate) mod predict;
mod rough;

pub use model::Gp;
pub use predict::PreparedGp;
