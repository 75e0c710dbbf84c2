//! The tool an IK solver is built for: a production TCP on the calibrated
//! flange and the load it carries, applied once at the solver's construction.
//!
//! Frames: the TCP is the flange → TCP pose (the last link's frame of the
//! model, before the model's own tool) [m, rad]; the load's centre of mass is
//! in the flange frame ([`crate::model::load`]), where a real payload hangs
//! whichever TCP is declared. The tool's load sets the gravity torques of the
//! compliance deflection (thesis eqs. 3.7–3.9), so the solver prepares its
//! model for one tool: a different tool needs a new solver.

use crate::model::calibrated::CompensatedModel;
use crate::model::load::{self, Load};
use crate::model::{Pose, RobotModel};
use serde::{Deserialize, Serialize};

/// A production tool as the IK takes it: the TCP in the flange frame and the
/// load it carries (flange frame; `None`: the model's payload at its flange
/// point, never moved with the TCP).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TcpTool {
    /// Flange → TCP [m].
    pub tcp: Pose,
    /// The load on the flange, if stated.
    #[serde(default)]
    pub load: Option<Load>,
}

/// `model` with the tool `tcp` on its calibrated flange and on its nominal
/// flange (the controller's tool data), carrying `load` (flange frame) or,
/// for `None`, each model's own payload at its flange point
/// ([`load::on_tool`]).
pub fn carrying(model: &CompensatedModel, tcp: &Pose, load: Option<&Load>) -> CompensatedModel {
    let carried = |m: &RobotModel| {
        let l = load.copied().unwrap_or_else(|| Load::of_model(m));
        load::on_tool(m, tcp, &l)
    };
    let mut m = model.clone();
    m.calibrated = carried(&model.calibrated);
    m.nominal = carried(&model.nominal);
    if let Some(l) = load {
        m.payload_kg = l.mass_kg;
    }
    m
}
