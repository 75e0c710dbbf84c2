//! Which compensator to train ([`CompensatorSpec`]): a family's settings,
//! tagged by its `kind` like the stored form, one variant per row of the
//! families' table (`model::calibrated::stored::compensator_families!`),
//! with the dispatch of [`Family`]'s functions.

use super::error::TrainError;
use super::family::Family;
use super::report::TrainReport;
use super::sample::Sample;
use crate::model::calibrated::stored::compensator_families;
use crate::model::calibrated::StoredCompensator;
use serde::{Deserialize, Serialize};

/// Generates [`CompensatorSpec`] (one variant per row holding its
/// settings) and the dispatch of [`Family`]'s functions on it.
macro_rules! spec_table {
    ($(
        $variant:ident {
            kind: $kind:literal,
            model: $model:ty,
            description: $description:literal $(,)?
        }
    )+) => {
        /// Which compensator to train: a family's settings, tagged by its
        /// `kind`.
        #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
        #[serde(tag = "kind")]
        pub enum CompensatorSpec {
            $(#[doc = $description] #[serde(rename = $kind)]
              $variant(<$model as Family>::Settings),)+
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
            pub(super) fn train_family(
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

compensator_families!(spec_table);
