//! The RBF's entry in the stored compensators' table ([`StoredFamily`]):
//! its checks, bounds and report shape.

use super::model::Rbf;
use crate::model::bounds::compensator::check_rbf;
use crate::model::bounds::outputs::Outputs;
use crate::model::calibrated::compensator::Compensator;
use crate::model::calibrated::invalid::InvalidCompensator;
use crate::model::calibrated::stored::{NetworkShape, StoredFamily};
use crate::model::error::ModelError;
use std::sync::Arc;

impl StoredFamily for Rbf {
    fn validate(&self) -> Result<(), InvalidCompensator> {
        Rbf::validate(self)
    }

    fn dof(&self) -> usize {
        self.dof
    }

    fn check_bounds(&self, field: &str, _outputs: &Outputs) -> Result<(), ModelError> {
        check_rbf(field, self)
    }

    fn into_arc(self) -> Arc<dyn Compensator> {
        Arc::new(self)
    }

    fn shape(&self) -> NetworkShape {
        NetworkShape {
            units: self.units(),
            inputs: "gravity torques".into(),
        }
    }
}
