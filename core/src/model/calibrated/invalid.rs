//! Why a stored compensator is not a usable network: the sizes and values
//! each family checks of its stored form (file input), before it predicts.

/// Why a stored compensator is not a usable network (file input).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum InvalidCompensator {
    #[error("mlp: dof and hidden must be positive")]
    MlpSize,
    #[error("mlp: {got} weights, a {inputs}-{hidden}-3 network has {expected}")]
    MlpWeightCount {
        got: usize,
        inputs: usize,
        hidden: usize,
        expected: usize,
    },
    #[error("mlp: weights must be finite")]
    MlpWeightsNotFinite,
    #[error("rbf: centres must hold dof values per unit")]
    RbfCentres,
    #[error("rbf: {got} output weights, {units} units need {expected}")]
    RbfWeightCount {
        got: usize,
        units: usize,
        expected: usize,
    },
    #[error("rbf: spread must be positive")]
    RbfSpread,
    #[error("rbf: centres and weights must be finite")]
    RbfNotFinite,
    #[error("gp: inducing points, weights, variance and length scales must match dof and units")]
    GpSizes,
    #[error("gp: values must be finite, variances and scales positive")]
    GpValues,
    #[error("{what} normalisation must have {n} values")]
    NormalisationLength { what: &'static str, n: usize },
    #[error("{what} normalisation values must be finite")]
    NormalisationNotFinite { what: &'static str },
    #[error("{what} normalisation scales must be non-zero")]
    NormalisationZeroScale { what: &'static str },
}
