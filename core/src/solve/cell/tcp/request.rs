//! A tool or work-object calibration as the command line and the service ask
//! for it: rows of [`Reading`]s, a method, an optional axis, and the result
//! as a cell-file entry (mm, degrees).

use super::readings::{Reading, WoPoint};
use super::{
    axis, cell_points_to_base, fixed_point, flange_poses, tracker, FitError, NotFittedReason,
    TcpMethod, ToolFit,
};
use crate::calibrate::compensate::CompensatedModel;
use crate::model::orientation::fixed_xyz_angles;
use crate::model::pose::rpy_matrix;
use crate::model::Pose;
use crate::solve::cell::file::{PoseMmDeg, ToolDescription, WorkObjectDescription};
use crate::solve::cell::work_object_fit::{self, WorkObjectFit, WorkObjectPoints};
use crate::solve::cell::WorkObjectFrame;
use nalgebra::Vector3;

/// How the tool's axis is given.
#[derive(Debug, Clone, PartialEq)]
pub enum AxisRequest {
    /// A second point on the axis, nearer the flange, measured like the tip.
    Point(Vec<Reading>),
    /// Joint readings with the tool flat on a plane (≥ 3 touches).
    Plane(Vec<Reading>),
}

/// A tool calibration.
#[derive(Debug, Clone, PartialEq)]
pub struct ToolRequest {
    pub method: TcpMethod,
    pub rows: Vec<Reading>,
    pub axis: Option<AxisRequest>,
}

fn joints(rows: &[Reading], what: &str) -> Result<Vec<Vec<f64>>, FitError> {
    rows.iter()
        .enumerate()
        .map(|(i, r)| {
            r.joints_deg.clone().ok_or_else(|| {
                FitError::new(
                    NotFittedReason::MissingJoints,
                    format!(
                        "{what} row {}: joint readings missing (controller degrees)",
                        i + 1
                    ),
                )
                .at_row(i + 1)
            })
        })
        .collect()
}

fn points_mm(rows: &[Reading], what: &str) -> Result<Vec<Vector3<f64>>, FitError> {
    rows.iter()
        .enumerate()
        .map(|(i, r)| {
            r.xyz_mm.map(|p| Vector3::from(p) * 1e-3).ok_or_else(|| {
                FitError::new(
                    NotFittedReason::MissingPosition,
                    format!(
                        "{what} row {}: the tracker position x, y, z (mm) is missing",
                        i + 1
                    ),
                )
                .at_row(i + 1)
            })
        })
        .collect()
}

fn fit_tip(
    model: &CompensatedModel,
    method: TcpMethod,
    rows: &[Reading],
    what: &str,
) -> Result<ToolFit, FitError> {
    let flanges = flange_poses(model, &joints(rows, what)?)?;
    match method {
        TcpMethod::FixedPoint => fixed_point::fit(&flanges),
        TcpMethod::TrackerPoint => {
            let base = cell_points_to_base(model, &points_mm(rows, what)?);
            tracker::fit_points(&flanges, &base)
        }
        TcpMethod::TrackerFrame => {
            let points = points_mm(rows, what)?;
            let frames = rows
                .iter()
                .zip(points)
                .enumerate()
                .map(|(i, (r, p))| {
                    let [rx, ry, rz] = r.rpy_deg.ok_or_else(|| {
                        FitError::new(
                            NotFittedReason::MissingOrientation,
                            format!(
                                "{what} row {}: a 6-D probe needs rx, ry, rz (degrees)",
                                i + 1
                            ),
                        )
                        .at_row(i + 1)
                    })?;
                    let m = Pose::new(
                        rpy_matrix(rx.to_radians(), ry.to_radians(), rz.to_radians()),
                        p,
                    );
                    Ok(model.cell_to_base(&m))
                })
                .collect::<Result<Vec<_>, FitError>>()?;
            tracker::fit_frames(&flanges, &frames)
        }
    }
}

/// Fits a tool on `model`'s calibrated flange.
pub fn fit_tool(model: &CompensatedModel, req: &ToolRequest) -> Result<ToolFit, FitError> {
    let tip = fit_tip(model, req.method, &req.rows, "tip")?;
    match &req.axis {
        None => Ok(tip),
        Some(_) if req.method == TcpMethod::TrackerFrame => Err(FitError::new(
            NotFittedReason::AxisWithProbe,
            "a 6-D probe gives the tool's orientation itself; leave the axis out",
        )
        .with_tip(tip)),
        Some(AxisRequest::Point(rows)) => match fit_tip(model, req.method, rows, "axis point") {
            Ok(second) => axis::with_axis_point(tip, &second.tcp.p, &second.sigma_mm),
            Err(e) => Err(e.with_tip(tip)),
        },
        Some(AxisRequest::Plane(rows)) => {
            match joints(rows, "plane").and_then(|q| flange_poses(model, &q)) {
                Ok(flanges) => axis::with_plane(tip, &flanges),
                Err(e) => Err(e.with_tip(tip)),
            }
        }
    }
}

/// Fits a work object from rows naming their point: tracker rows (x, y, z in
/// the measurement frame) or touches (joint readings) with the calibrated
/// tool tip `tcp` (flange frame, m). The result is in the robot base frame.
pub fn fit_work_object(
    model: &CompensatedModel,
    rows: &[Reading],
    tcp: Option<&Vector3<f64>>,
) -> Result<WorkObjectFit, FitError> {
    let mut pts = WorkObjectPoints::default();
    for (i, r) in rows.iter().enumerate() {
        let point = r.point.ok_or_else(|| {
            FitError::new(
                NotFittedReason::MissingPoint,
                format!(
                    "row {}: which point is it? give `point`: origin, x, xy or plane",
                    i + 1
                ),
            )
            .at_row(i + 1)
        })?;
        let p =
            match (&r.xyz_mm, &r.joints_deg, tcp) {
                (Some(x), _, _) => cell_points_to_base(model, &[Vector3::from(*x) * 1e-3])[0],
                (None, Some(q), Some(t)) => work_object_fit::touched_tips(
                    model,
                    t,
                    std::slice::from_ref(q),
                )
                .map_err(|e| FitError {
                    message: format!("row {}: {}", i + 1, e.message.trim_start_matches("row 1: ")),
                    row: Some(i + 1),
                    ..e
                })?[0],
                (None, Some(_), None) => {
                    return Err(FitError::new(
                        NotFittedReason::TouchesNeedTool,
                        format!(
                    "row {}: touches with joint readings need the calibrated tool that made them",
                    i + 1
                ),
                    )
                    .at_row(i + 1))
                }
                (None, None, _) => {
                    return Err(FitError::new(
                        NotFittedReason::MissingPosition,
                        format!(
                            "row {}: give a tracker position (x, y, z mm) or joint readings",
                            i + 1
                        ),
                    )
                    .at_row(i + 1))
                }
            };
        match point {
            WoPoint::Origin => pts.origin.push(p),
            WoPoint::X => pts.x.push(p),
            WoPoint::Xy => pts.xy.push(p),
            WoPoint::Plane => pts.plane.push(p),
        }
    }
    work_object_fit::fit(&pts)
}

/// A pose in boundary units (mm, fixed-axis degrees).
pub fn pose_mm_deg(p: &Pose) -> PoseMmDeg {
    PoseMmDeg {
        xyz_mm: [p.p.x * 1e3, p.p.y * 1e3, p.p.z * 1e3],
        rpy_deg: fixed_xyz_angles(&p.r).map(f64::to_degrees),
    }
}

/// The fitted tool as a cell-file entry.
pub fn tool_description(name: &str, number: Option<u32>, fit: &ToolFit) -> ToolDescription {
    ToolDescription {
        name: name.to_string(),
        number,
        tcp: pose_mm_deg(&fit.tcp),
        load: None,
    }
}

/// The fitted work object as a cell-file entry (base frame).
pub fn work_object_description(
    name: &str,
    number: Option<u32>,
    fit: &WorkObjectFit,
) -> WorkObjectDescription {
    WorkObjectDescription {
        name: name.to_string(),
        number,
        frame: WorkObjectFrame::Base,
        pose: pose_mm_deg(&fit.pose),
    }
}
