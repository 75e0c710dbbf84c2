//! The stored compensators: one closed set of families, one row each in
//! [`compensator_families!`], from which [`StoredCompensator`] (what a model
//! file's `compensator` holds, tagged by its `kind`) and its dispatch derive
//! here, and the training side's `CompensatorSpec` in
//! `calibrate::compensate::spec`. What a family's stored model answers is
//! [`StoredFamily`], implemented in its folder (`gp/`, `mlp/`, `rbf/`);
//! SI units as [`Compensator`] states them.

use super::compensator::Compensator;
use super::invalid::InvalidCompensator;
use crate::model::bounds::outputs::Outputs;
use crate::model::error::ModelError;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use std::fmt::Debug;
use std::sync::Arc;

/// What a compensator report says of the network: its units and inputs
/// (the kind is the family's table name).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NetworkShape {
    /// Hidden units, RBF units or inducing configurations.
    pub units: usize,
    /// Its inputs, in words (`q, sin q, cos q`, `gravity torques`).
    pub inputs: String,
}

/// One family's stored model: how it checks itself and becomes a
/// compensator (its training is `calibrate::compensate::Family`).
pub trait StoredFamily: Sized + Clone + Debug + PartialEq + Serialize + DeserializeOwned {
    /// Sizes consistent with each other and values finite (file input).
    fn validate(&self) -> Result<(), InvalidCompensator>;
    /// Joints it takes.
    fn dof(&self) -> usize;
    /// Every stored value within the bound of its quantity, the error naming
    /// `field`'s member (`model::bounds::compensator`).
    fn check_bounds(&self, field: &str, outputs: &Outputs) -> Result<(), ModelError>;
    /// The compensator that predicts with it.
    fn into_arc(self) -> Arc<dyn Compensator>;
    /// Units and inputs, for the report.
    fn shape(&self) -> NetworkShape;
}

/// The families of learned compensators, one row each: its variant, its
/// `kind` (the tag of the stored form in model files, stored versions and
/// the HTTP JSON), its model type and a description. Invokes `$then!` with
/// the rows, so that every list of families derives from this one.
macro_rules! compensator_families {
    ($then:ident) => {
        $then! {
            Mlp {
                kind: "mlp",
                model: $crate::model::calibrated::mlp::Mlp,
                description: "Joint-space MLP (SKCM-NN, SKCM-IWONN, SKCM-TLBONN).",
            }
            Rbf {
                kind: "rbf",
                model: $crate::model::calibrated::rbf::Rbf,
                description: "Torque-space RBF (KM-RBF).",
            }
            Gp {
                kind: "gp",
                model: $crate::model::calibrated::gp::Gp,
                description: "Joint-space sparse Gaussian process (KM-GP, SKCM-GP).",
            }
        }
    };
}

pub(crate) use compensator_families;

/// Generates [`StoredCompensator`] (one variant per row holding the
/// family's model, serialised with `"kind": name`), `From` each model, and
/// the dispatch of [`StoredFamily`]'s functions.
macro_rules! stored_table {
    ($(
        $variant:ident {
            kind: $kind:literal,
            model: $model:ty,
            description: $description:literal $(,)?
        }
    )+) => {
        /// A compensator as the model file stores it, tagged by `kind`. An
        /// unknown kind fails to parse.
        #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
        #[serde(tag = "kind")]
        pub enum StoredCompensator {
            $(#[doc = $description] #[serde(rename = $kind)] $variant($model),)+
        }

        $(impl From<$model> for StoredCompensator {
            fn from(m: $model) -> Self {
                StoredCompensator::$variant(m)
            }
        })+

        impl StoredCompensator {
            /// Every family's `kind`, in the table's order.
            pub const KINDS: &'static [&'static str] = &[$($kind),+];

            /// The family's `kind` (`mlp`, `rbf`, `gp`).
            pub fn kind(&self) -> &'static str {
                match self {
                    $(StoredCompensator::$variant(_) => $kind,)+
                }
            }

            /// Checks the stored network's sizes and values (file input).
            pub fn validate(&self) -> Result<(), InvalidCompensator> {
                match self {
                    $(StoredCompensator::$variant(m) => StoredFamily::validate(m),)+
                }
            }

            /// Joints of the robot the network was trained for.
            pub fn dof(&self) -> usize {
                match self {
                    $(StoredCompensator::$variant(m) => StoredFamily::dof(m),)+
                }
            }

            /// [`StoredFamily::check_bounds`] of the family.
            pub fn check_bounds(&self, field: &str, outputs: &Outputs) -> Result<(), ModelError> {
                match self {
                    $(StoredCompensator::$variant(m) => StoredFamily::check_bounds(m, field, outputs),)+
                }
            }

            /// The compensator that predicts with it, unfaded and without
            /// an orientation part (`LearnedCompensator` adds both).
            pub fn into_arc(self) -> Arc<dyn Compensator> {
                match self {
                    $(StoredCompensator::$variant(m) => StoredFamily::into_arc(m),)+
                }
            }

            /// Units and inputs, for the report.
            pub fn shape(&self) -> NetworkShape {
                match self {
                    $(StoredCompensator::$variant(m) => StoredFamily::shape(m),)+
                }
            }
        }
    };
}

compensator_families!(stored_table);
