//! A family of learned compensators ([`Family`]) and the table that makes
//! the families one closed set ([`compensator_table!`], invoked once in
//! `compensate/mod.rs`).
//!
//! A family is a stored model type (what a model file's `compensator` holds,
//! tagged by its `kind`) with its training settings: how it checks itself,
//! becomes a compensator, describes itself in a report and trains. The table
//! lists each family once, and from it derive [`StoredCompensator`] (the
//! stored form, `{"kind": …, …}`), [`CompensatorSpec`] (what to train, tagged
//! the same way) and their dispatch; a family's model, prediction and
//! training live in its folder (`compensate/gp/`, `mlp/`, `rbf/`).
//!
//! [`StoredCompensator`]: super::StoredCompensator
//! [`CompensatorSpec`]: super::CompensatorSpec

use super::{Compensator, InvalidCompensator, Sample, TrainError, TrainReport};
use crate::model::bounds::compensator::Outputs;
use crate::model::ModelError;
use rand::Rng;
use serde::de::DeserializeOwned;
use serde::Serialize;
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

/// One family of learned compensators: its stored model (`Self`, SI units
/// as [`Compensator`] states them) and its training settings.
pub trait Family: Sized + Clone + Debug + PartialEq + Serialize + DeserializeOwned {
    /// What [`Family::train`] takes.
    type Settings: Clone + Debug + PartialEq + Serialize + DeserializeOwned;

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

    /// Trains it on `samples` (at least 5, of one joint count, finite:
    /// checked before). `progress(epoch, loss)` after every epoch /
    /// iteration / generation / fit returns false to cancel. The report's
    /// `rms_mm` is filled in by the caller.
    fn train(
        settings: &Self::Settings,
        samples: &[Sample],
        rng: &mut impl Rng,
        progress: &mut dyn FnMut(usize, f64) -> bool,
    ) -> Result<(Self, TrainReport), TrainError>;
    /// The most epochs a training with `settings` may report (progress
    /// percentages; at least 1 is taken).
    fn max_epochs(settings: &Self::Settings) -> usize;
    /// Short name of the network and trainer (`nn`, `rbf`, `gp`).
    fn label(settings: &Self::Settings) -> &'static str;
    /// Trains on every pose of the pool, not on a seeded subsample of at
    /// most `max_network_poses` (its training grows linearly with them).
    const EVERY_POSE: bool = false;
    /// Its input is the gravity torques: a pool without any has nothing to
    /// learn.
    const TORQUE_INPUT: bool = false;
}

/// Generates [`StoredCompensator`](super::StoredCompensator) (one variant per
/// row holding the family's model, serialised with `"kind": name`),
/// [`CompensatorSpec`](super::CompensatorSpec) (one variant per row holding
/// its settings, tagged the same way), `From` each model, and the dispatch
/// of [`Family`]'s functions on both.
macro_rules! compensator_table {
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

        /// Which compensator to train: a family's settings, tagged by its
        /// `kind`.
        #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
        #[serde(tag = "kind")]
        pub enum CompensatorSpec {
            $(#[doc = $description] #[serde(rename = $kind)]
              $variant(<$model as Family>::Settings),)+
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

            pub fn validate(&self) -> Result<(), InvalidCompensator> {
                match self {
                    $(StoredCompensator::$variant(m) => Family::validate(m),)+
                }
            }

            pub fn dof(&self) -> usize {
                match self {
                    $(StoredCompensator::$variant(m) => Family::dof(m),)+
                }
            }

            /// [`Family::check_bounds`] of the family.
            pub fn check_bounds(
                &self,
                field: &str,
                outputs: &$crate::model::bounds::compensator::Outputs,
            ) -> Result<(), $crate::model::ModelError> {
                match self {
                    $(StoredCompensator::$variant(m) => Family::check_bounds(m, field, outputs),)+
                }
            }

            pub fn into_arc(self) -> Arc<dyn Compensator> {
                match self {
                    $(StoredCompensator::$variant(m) => Family::into_arc(m),)+
                }
            }

            /// Units and inputs, for the report.
            pub fn shape(&self) -> NetworkShape {
                match self {
                    $(StoredCompensator::$variant(m) => Family::shape(m),)+
                }
            }
        }

        impl CompensatorSpec {
            /// The family's `kind`.
            pub fn kind(&self) -> &'static str {
                match self {
                    $(CompensatorSpec::$variant(_) => $kind,)+
                }
            }

            /// Short name of the network and trainer (`nn`, `iwonn`,
            /// `tlbonn`, `rbf`, `gp`).
            pub fn label(&self) -> &'static str {
                match self {
                    $(CompensatorSpec::$variant(s) => <$model as Family>::label(s),)+
                }
            }

            /// Epochs / iterations / generations a training may take at
            /// most (for progress percentages), at least 1.
            pub fn max_epochs(&self) -> usize {
                match self {
                    $(CompensatorSpec::$variant(s) => <$model as Family>::max_epochs(s),)+
                }
                .max(1)
            }

            /// [`Family::EVERY_POSE`] of the family.
            pub fn every_pose(&self) -> bool {
                match self {
                    $(CompensatorSpec::$variant(_) => <$model as Family>::EVERY_POSE,)+
                }
            }

            /// [`Family::TORQUE_INPUT`] of the family.
            pub fn torque_input(&self) -> bool {
                match self {
                    $(CompensatorSpec::$variant(_) => <$model as Family>::TORQUE_INPUT,)+
                }
            }

            /// [`Family::train`] of the family, its model stored.
            fn train_family(
                &self,
                samples: &[Sample],
                rng: &mut impl rand::Rng,
                progress: &mut dyn FnMut(usize, f64) -> bool,
            ) -> Result<(StoredCompensator, TrainReport), TrainError> {
                match self {
                    $(CompensatorSpec::$variant(s) => {
                        let (m, report) = <$model as Family>::train(s, samples, rng, progress)?;
                        Ok((StoredCompensator::$variant(m), report))
                    })+
                }
            }
        }
    };
}

pub(crate) use compensator_table;
