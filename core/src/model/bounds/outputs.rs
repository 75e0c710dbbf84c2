//! The bounds of a learned network's output quantities, which differ
//! between a compensator's position part [m] and its orientation part [rad]
//! (`compensator.rs` checks a stored network against them).

use super::{Bound, GP_COEFFICIENT, GP_VARIANCE_M2, OUTPUT_SCALE, RESIDUAL_M};

/// The bounds of a network's output quantities, which differ between the
/// position part [m] and the orientation part [rad].
pub struct Outputs {
    /// Output centre, GP mean, uncompensated RMS.
    pub residual: Bound,
    /// An MLP's output scale.
    pub output_scale: Bound,
    /// A GP's signal and noise variances.
    pub variance: Bound,
    /// A GP's weights and variance matrix.
    pub coefficient: Bound,
}

/// The position part's outputs [m].
pub const POSITION_OUTPUTS: Outputs = Outputs {
    residual: RESIDUAL_M,
    output_scale: OUTPUT_SCALE,
    variance: GP_VARIANCE_M2,
    coefficient: GP_COEFFICIENT,
};

/// The orientation part's outputs, a rotation vector [rad]: a turn beyond
/// π is no residual, so ±10 rad leaves room for any centre or mean; the
/// other bounds are the position part's read in radians.
pub const ORIENTATION_OUTPUTS: Outputs = Outputs {
    residual: Bound {
        min: -10.0,
        max: 10.0,
        unit: "rad",
    },
    output_scale: Bound {
        min: 0.0,
        max: 1e13,
        unit: "1/rad",
    },
    variance: Bound {
        min: 0.0,
        max: 1e2,
        unit: "rad²",
    },
    coefficient: Bound {
        min: -1e30,
        max: 1e30,
        unit: "1/rad or 1/rad²",
    },
};
