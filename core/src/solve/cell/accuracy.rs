//! Accuracy at a production tool: what the calibration's validation poses
//! say about the error at a tool's tip.
//!
//! A tracker measures the pose `M_i` of its own target (reflector or 6-D
//! probe: the calibrated model's tool, flange → probe `P`). A production tool
//! `T` (flange → TCP) has its tip at `d = P⁻¹·T.p` in the probe frame, so the
//! measured and predicted tips of validation pose `i` are `M_i·d` and
//! `P̂_i·d`, and the tip error is exactly
//!
//! `e_tip,i = e_i + (R_meas,i − R_pred,i)·d`
//!
//! (position error plus orientation error times the lever arm). The
//! calibration stores, per validation pose with a measured orientation, `e_i`
//! [mm] and `D_i = R_meas,i − R_pred,i` in the registered base frame of the
//! pose's session ([`ValidationEvidence`], written into the model file), so
//! the tip error of any tool is computed later from its TCP alone. The
//! prediction is the compensated model's (`CompensatedModel::predict_detailed_at`
//! at the pose's payload, session frame applied), as for the reported
//! validation errors. The tool's own load is not re-applied to the stored
//! poses: they carry the payload they were measured with.
//!
//! Without orientation measurements nothing bounds `(R_meas − R_pred)·d`: the
//! tool's orientation, and so its tip error, is unverified (`Unverified`),
//! and the reflector's figure is never given for a tool.

use crate::model::calibrated::evidence::ValidationEvidence;
use crate::model::Pose;
use crate::stats::ErrorStats;
use nalgebra::Vector3;
use serde::Serialize;

/// Below this lever arm [m] the tool's tip is the measured point itself.
const SAME_POINT_M: f64 = 1e-6;

/// The expected error at a tool's tip.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "status", rename_all = "snake_case")]
pub enum ToolAccuracy {
    /// Measured on validation poses (with the tool applied when it is not
    /// the measured point itself).
    Measured {
        /// Validation poses the figure is taken over.
        poses: usize,
        /// Mean error at the tip [mm].
        mean_mm: f64,
        /// Largest error at the tip [mm].
        max_mm: f64,
        /// Whether the figure is the tip's from 6-D data (`false`: the
        /// measured point itself).
        from_orientation: bool,
    },
    /// Position-only validation data: the tool's orientation is unverified,
    /// its tip error unknown.
    Unverified {
        /// Why the tip error is unknown and how to know it, for the user.
        message: String,
    },
    /// No validation data was stored with the model.
    Unknown {
        /// What is missing, for the user.
        message: String,
    },
}

/// The expected error at the tip of tool `tcp` (flange → TCP) of a model
/// whose measured frame is `probe` (flange → probe: the calibrated model's
/// tool), from `evidence`.
pub fn tool_accuracy(
    evidence: Option<&ValidationEvidence>,
    probe: &Pose,
    tcp: &Pose,
) -> ToolAccuracy {
    let Some(ev) = evidence else {
        return ToolAccuracy::Unknown {
            message: "no validation data is stored with this model: calibrate with a validation set to know the error at the tool".into(),
        };
    };
    let d = probe.inverse().transform_point(&tcp.p);
    if d.norm() < SAME_POINT_M {
        return measured_point(ev);
    }
    if ev.tip_terms.is_empty() {
        return ToolAccuracy::Unverified {
            message: format!(
                "the calibration measured positions only: the tool's orientation is unverified and its tip error ({:.1} mm from the measured point) unknown; the measured point's validation error ({:.3} mm mean) does not apply to the tip — calibrate with orientation measurements (rx, ry, rz) to know it",
                d.norm() * 1e3,
                ev.position_mean_mm
            ),
        };
    }
    let e = tool_errors(ev, &d);
    ToolAccuracy::Measured {
        poses: e.n,
        mean_mm: e.mean_mm,
        max_mm: e.max_mm,
        from_orientation: true,
    }
}

fn tool_errors(ev: &ValidationEvidence, d: &Vector3<f64>) -> ErrorStats {
    ErrorStats::from_errors_mm(&ev.tip_errors_mm(d))
}

/// The measured point's own validation error.
pub fn measured_point(ev: &ValidationEvidence) -> ToolAccuracy {
    ToolAccuracy::Measured {
        poses: ev.poses,
        mean_mm: ev.position_mean_mm,
        max_mm: ev.position_max_mm,
        from_orientation: false,
    }
}

/// The measured point's accuracy, or `Unknown` without evidence.
pub fn measurement_tool_accuracy(evidence: Option<&ValidationEvidence>) -> ToolAccuracy {
    match evidence {
        Some(ev) => measured_point(ev),
        None => ToolAccuracy::Unknown {
            message: "no validation data is stored with this model".into(),
        },
    }
}
