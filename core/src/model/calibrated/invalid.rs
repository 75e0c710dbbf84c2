//! Why a stored compensator is not a usable network: the sizes and values
//! each family checks of its stored form (file input), before it predicts.

/// Why a stored compensator is not a usable network (file input).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum InvalidCompensator {
    /// `dof` or `hidden` is zero.
    #[error("mlp: dof and hidden must be positive")]
    MlpSize,
    /// The flat weight vector's length is not the network's.
    #[error("mlp: {got} weights, a {inputs}-{hidden}-3 network has {expected}")]
    MlpWeightCount {
        /// Weights stored.
        got: usize,
        /// Network inputs (the features of `dof` joints).
        inputs: usize,
        /// Hidden units.
        hidden: usize,
        /// Weights an `inputs`-`hidden`-3 network has.
        expected: usize,
    },
    /// A weight is not finite.
    #[error("mlp: weights must be finite")]
    MlpWeightsNotFinite,
    /// `dof` is zero or the centres are not `dof` values per unit.
    #[error("rbf: centres must hold dof values per unit")]
    RbfCentres,
    /// The output weights are not `3 × (units + 1)`.
    #[error("rbf: {got} output weights, {units} units need {expected}")]
    RbfWeightCount {
        /// Output weights stored.
        got: usize,
        /// Hidden units (centres).
        units: usize,
        /// Output weights `units` units need.
        expected: usize,
    },
    /// The spread is not a positive number.
    #[error("rbf: spread must be positive")]
    RbfSpread,
    /// A centre or weight is not finite.
    #[error("rbf: centres and weights must be finite")]
    RbfNotFinite,
    /// The GP's arrays do not match its `dof` and number of inducing configurations.
    #[error("gp: inducing points, weights, variance and length scales must match dof and units")]
    GpSizes,
    /// A GP value is not finite, or a variance or scale not positive.
    #[error("gp: values must be finite, variances and scales positive")]
    GpValues,
    /// A normalisation's centres or scales are not one per column.
    #[error("{what} normalisation must have {n} values")]
    NormalisationLength {
        /// Which normalisation (`mlp input`, `rbf input`, …).
        what: &'static str,
        /// Columns it must have.
        n: usize,
    },
    /// A normalisation's value is not finite.
    #[error("{what} normalisation values must be finite")]
    NormalisationNotFinite {
        /// Which normalisation.
        what: &'static str,
    },
    /// An output normalisation has a zero scale (it cannot be inverted).
    #[error("{what} normalisation scales must be non-zero")]
    NormalisationZeroScale {
        /// Which normalisation.
        what: &'static str,
    },
}
