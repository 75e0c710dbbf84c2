//! TCP calibration: a production tool's TCP in the flange frame from joint
//! readings on the CALIBRATED model.
//!
//! Frames: the flange frame is the calibrated model's last link frame (the
//! model's own measurement tool removed, `solve::cell::with_tool` with the identity);
//! its pose `F_i = (R_i, p_i)` in the registered base frame comes from
//! [`CompensatedModel::predict_base`] (compliance, joint maps and the
//! compensator's position residual included, as every solve sees them). A
//! tracker measures in the measurement frame; `cell_from_base` (the
//! calibration's registration) maps it into the base frame. The tool's TCP is
//! `t` (flange frame); its orientation is the flange's unless an axis is
//! given ([`axis`]), with the tool's z pointing out of the tip.
//!
//! Methods:
//! - [`fixed_point`]: the tip held at one fixed point `p` in ≥ 4 orientations,
//!   `R_i·t + p_i = p` solved for `(t, p)` by linear least squares;
//! - [`tracker`]: a reflector (`x_i`) or a 6-D probe (`M_i`) on the tool,
//!   `t = mean R_i^T (x_i − p_i)`, the frame `F_i⁻¹·M_i` averaged;
//! - [`axis`]: the tool's z from a second point on its axis or from touches
//!   with the tool flat on a plane.
//!
//! Every fit is judged before it is stored ([`judge`]: residuals against the
//! readings' noise, the TCP's distance from the flange); what a fit then
//! stores, where its orientation comes from and what it replaces is
//! [`entry`].
//!
//! Units: SI (m, rad) in poses and points; the reported residuals and σ are in
//! mm and degrees (fields named so). Joint readings are controller degrees.

pub mod axis;
pub mod entry;
pub mod fixed_point;
pub mod judge;
mod limits;
mod outcome;
pub mod readings;
pub mod request;
pub mod tracker;

pub use entry::{EntryField, OrientationSource, Outcome, Replaced, StoreRequest, StoredEntry};
pub use limits::{Limits, Noise};
pub(crate) use outcome::rms_max;
pub use outcome::{
    AxisSource, FitError, JudgedFit, NotFittedReason, TcpMethod, ToolFit, WorkObjectFit,
};
pub use readings::{Reading, WoPoint};
pub use request::{fit_tool, fit_work_object, AxisRequest, ToolRequest};

use crate::model::calibrated::CompensatedModel;
use crate::model::Pose;
use nalgebra::{Matrix3, Vector3};

/// The calibrated flange pose (registered base frame) at every row of
/// controller joint readings [deg].
pub fn flange_poses(
    model: &CompensatedModel,
    joints_deg: &[Vec<f64>],
) -> Result<Vec<Pose>, FitError> {
    let flange = crate::solve::cell::with_tool(model, &Pose::identity());
    let dof = model.dof();
    joints_deg
        .iter()
        .enumerate()
        .map(|(i, q)| {
            if q.len() != dof {
                return Err(FitError::new(
                    NotFittedReason::JointCount,
                    format!(
                        "row {}: {} joint readings, the robot has {dof} joints (controller degrees)",
                        i + 1,
                        q.len()
                    ),
                )
                .at_row(i + 1)
                .figures(q.len() as f64, dof as f64));
            }
            if q.iter().any(|v| !v.is_finite()) {
                return Err(FitError::new(
                    NotFittedReason::NotFinite,
                    format!(
                        "row {}: joint readings must be finite (controller degrees)",
                        i + 1
                    ),
                )
                .at_row(i + 1));
            }
            let rad: Vec<f64> = q.iter().map(|d| d.to_radians()).collect();
            let qm = model.nominal.joints_from_controller(&rad);
            flange.predict_base(&qm).map_err(|e| {
                FitError::new(
                    NotFittedReason::Kinematics,
                    format!("forward kinematics failed at row {}: {e}", i + 1),
                )
                .at_row(i + 1)
            })
        })
        .collect()
}

/// Points given in the measurement frame, in the registered base frame.
pub fn cell_points_to_base(model: &CompensatedModel, points: &[Vector3<f64>]) -> Vec<Vector3<f64>> {
    let to_base = model.cell_from_base.inverse();
    points.iter().map(|x| to_base.transform_point(x)).collect()
}

/// The rotation nearest (Frobenius) to `m`: the chordal mean of rotations
/// when `m` is their sum.
pub fn nearest_rotation(m: &Matrix3<f64>) -> Matrix3<f64> {
    let svd = m.svd(true, true);
    let (u, vt) = (svd.u.unwrap(), svd.v_t.unwrap());
    let d = (u * vt).determinant().signum();
    u * Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, d)) * vt
}

/// Rejects non-finite points.
pub(crate) fn check_finite(points: &[Vector3<f64>], what: &str) -> Result<(), FitError> {
    match points.iter().position(|p| !p.iter().all(|v| v.is_finite())) {
        Some(i) => Err(FitError::new(
            NotFittedReason::NotFinite,
            format!("{what} {}: coordinates must be finite", i + 1),
        )
        .at_row(i + 1)),
        None => Ok(()),
    }
}
