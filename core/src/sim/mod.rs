//! The "true robot" simulator: a perturbed robot that the calibration has to
//! discover, measured by a simulated laser tracker. No I/O; every random draw comes
//! from an injected, seeded generator (`&mut impl Rng`, e.g.
//! `rand_chacha::ChaCha8Rng::seed_from_u64(seed)` at the call site).
//!
//! The simulated position follows the thesis's error model (eq. 2.1 / 7.6):
//! `P_real = P_kin + ΔP_kin + ΔP_c + ΔP_extra`
//! - `ΔP_kin`: the truth's geometry differs from nominal ([`perturb_geometry`], or
//!   the thesis's §7.4 robot [`ys100_table_7_1`]);
//! - `ΔP_c`: joint compliance `Δθ = c ∘ τ(q)` with gravity torques at the
//!   commanded configuration (eqs. 7.1–7.5), optionally with the cubic spring of
//!   eq. 7.3;
//! - `ΔP_extra`: unmodelled effects ([`UnmodelledEffects`]: gear transmission
//!   error, backlash, link bending), all off by default;
//! - plus tracker noise `N(0, σ)` per axis (σ = 0.01 mm in §7.4).
//!
//! Frames and units: joint values in the model convention [rad] inside, controller
//! readings [deg] in the produced [`MeasuredPose`](crate::measure::MeasuredPose)
//! rows; positions [m] inside, [mm] in the rows. `TrueRobot::tracker_from_base`
//! maps robot-base coordinates to tracker coordinates
//! (`x_tracker = R·x_base + p`, i.e. it is the pose of the base frame in the
//! tracker frame); measured points are expressed in the tracker frame.

mod perturb;
mod poses;
pub mod positioner;
pub mod positioner_example;
pub mod positioner_sets;
pub mod study;
mod synthetic;
pub mod track;
mod truth;
pub mod turntable_example;

pub use perturb::{
    perturb_geometry, perturb_geometry_with, ys100_table_7_1, ErrorDistribution, ErrorMagnitudes,
    TABLE_7_2_STIFFNESS,
};
pub use poses::{
    random_configurations, random_configurations_with, try_random_configurations, PoseFilter,
};
pub use synthetic::{synthetic_calibration, unmodelled_truth, SyntheticErrors};
pub use truth::{fine_transmission_errors, tracker_frame, Harmonic, TrueRobot, UnmodelledEffects};

use crate::model::kinematics::KinematicsError;

/// Simulation errors.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    /// Forward kinematics failed at one of the configurations measured.
    #[error("configuration {index}: {source}")]
    Kinematics {
        /// Index of that configuration in the measured list (0-based).
        index: usize,
        /// The kinematics error at that configuration.
        #[source]
        source: KinematicsError,
    },
    /// Random draws inside the limits and the pose filter gave too few
    /// admissible configurations.
    #[error("found only {found} of {wanted} admissible configurations after {attempts} random draws; relax the pose filter")]
    TooFewConfigurations {
        /// Number of configurations asked for.
        wanted: usize,
        /// Number of admissible configurations found before giving up.
        found: usize,
        /// Number of random draws made (the cap is `10_000 + 1_000·wanted`).
        attempts: usize,
    },
    /// Forward kinematics of the true robot failed at a configuration not tied
    /// to a list index.
    #[error(transparent)]
    Fk(KinematicsError),
    /// An input of the simulation (noise, unmodelled effects) is out of range;
    /// the text says which.
    #[error("invalid simulation input: {0}")]
    InvalidInput(String),
}
