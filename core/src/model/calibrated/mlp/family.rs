//! The MLP's entry in the stored compensators' table ([`StoredFamily`]):
//! its checks, bounds and report shape.

use super::model::Mlp;
use crate::model::bounds::compensator::check_mlp;
use crate::model::bounds::outputs::Outputs;
use crate::model::calibrated::compensator::Compensator;
use crate::model::calibrated::invalid::InvalidCompensator;
use crate::model::calibrated::stored::{NetworkShape, StoredFamily};
use crate::model::error::ModelError;
use std::sync::Arc;

impl StoredFamily for Mlp {
    fn validate(&self) -> Result<(), InvalidCompensator> {
        Mlp::validate(self)
    }

    fn dof(&self) -> usize {
        self.dof
    }

    fn check_bounds(&self, field: &str, outputs: &Outputs) -> Result<(), ModelError> {
        check_mlp(field, self, outputs)
    }

    fn into_arc(self) -> Arc<dyn Compensator> {
        Arc::new(self)
    }

    fn shape(&self) -> NetworkShape {
        let mut inputs = String::from("q");
        if self.features.sin_cos {
            inputs.push_str(", sin q, cos q");
        }
        if self.features.payload {
            inputs.push_str(", payload mass");
        }
        NetworkShape {
            units: self.hidden,
            inputs,
        }
    }
}
