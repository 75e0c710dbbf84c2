//! The Gaussian process's entry in the stored compensators' table
//! ([`StoredFamily`]): its checks, bounds and report shape; it becomes a
//! compensator as its prepared form ([`PreparedGp`]).

use super::model::Gp;
use super::predict::PreparedGp;
use crate::model::bounds::compensator::check_gp;
use crate::model::bounds::outputs::Outputs;
use crate::model::calibrated::compensator::Compensator;
use crate::model::calibrated::invalid::InvalidCompensator;
use crate::model::calibrated::stored::{NetworkShape, StoredFamily};
use crate::model::error::ModelError;
use std::sync::Arc;

impl StoredFamily for Gp {
    fn validate(&self) -> Result<(), InvalidCompensator> {
        Gp::validate(self)
    }

    fn dof(&self) -> usize {
        self.dof
    }

    fn check_bounds(&self, field: &str, outputs: &Outputs) -> Result<(), ModelError> {
        check_gp(field, self, outputs)
    }

    fn into_arc(self) -> Arc<dyn Compensator> {
        Arc::new(PreparedGp::new(self))
    }

    fn shape(&self) -> NetworkShape {
        NetworkShape {
            units: self.units(),
            inputs: "q".into(),
        }
    }
}
