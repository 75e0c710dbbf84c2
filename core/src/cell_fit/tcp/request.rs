//! A tool or work-object calibration as the command line and the service ask
//! for it: rows of [`Reading`]s, a method, an optional axis, and the result
//! as a cell-file entry (mm, degrees).

use super::judge::{self, Limits, Noise};
use super::readings::{Reading, WoPoint};
use super::{
    axis, cell_points_to_base, fixed_point, flange_poses, tracker, FitError, NotFittedReason,
    TcpMethod, ToolFit,
};
use crate::cell_fit::work_object::{self, WorkObjectFit, WorkObjectPoints};
use crate::model::calibrated::CompensatedModel;
use crate::model::pose::rpy_matrix;
use crate::model::Pose;
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
    /// How the TCP is to be found.
    pub method: TcpMethod,
    /// The readings of the tool's tip, one per pose.
    pub rows: Vec<Reading>,
    /// How the tool's axis is given, when its orientation is to be fitted.
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

/// What a tool fit's residuals are made of ([`judge`]).
fn noise_of(method: TcpMethod) -> Noise {
    match method {
        TcpMethod::FixedPoint => Noise::Pointing,
        TcpMethod::TrackerPoint | TcpMethod::TrackerFrame => Noise::Tracker,
    }
}

impl ToolRequest {
    /// Whether the readings determine the tool's orientation (an axis or a
    /// 6-D probe); an orientation given besides is refused at the boundary.
    pub fn determines_orientation(&self) -> bool {
        self.method == TcpMethod::TrackerFrame || self.axis.is_some()
    }
}

/// Fits a tool on `model`'s calibrated flange and judges it ([`judge`]):
/// a fit beyond its limits is an error carrying the fit.
pub fn fit_tool(model: &CompensatedModel, req: &ToolRequest) -> Result<ToolFit, FitError> {
    let noise = noise_of(req.method);
    let tip = fit_tip(model, req.method, &req.rows, "tip")?;
    let fit = match &req.axis {
        None => tip,
        Some(_) if req.method == TcpMethod::TrackerFrame => {
            return Err(FitError::new(
                NotFittedReason::AxisWithProbe,
                "a 6-D probe gives the tool's orientation itself; leave the axis out",
            )
            .with_tip(tip))
        }
        Some(AxisRequest::Point(rows)) => {
            let second = fit_tip(model, req.method, rows, "axis point").and_then(|second| {
                judge::check_residuals(
                    &second.residual_mm,
                    &Limits::of(noise),
                    "axis point",
                    "the axis point's readings do not hold it at one point",
                )
                .map(|()| second)
            });
            match second {
                Ok(second) => axis::with_axis_point(tip, &second.tcp.p, &second.sigma_mm)?,
                Err(e) => return Err(e.with_tip(tip)),
            }
        }
        Some(AxisRequest::Plane(rows)) => {
            match joints(rows, "plane").and_then(|q| flange_poses(model, &q)) {
                Ok(flanges) => axis::with_plane(tip, &flanges)?,
                Err(e) => return Err(e.with_tip(tip)),
            }
        }
    };
    judge::judge_tool(fit, &model.nominal, noise)
}

/// Fits a work object from rows naming their point: tracker rows (x, y, z in
/// the measurement frame) or touches (joint readings) with the calibrated
/// tool tip `tcp` (flange frame, m), and judges it ([`judge`]: tracker
/// noise when every row is a tracker reading, else a touch's). The result
/// is in the robot base frame.
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
        let p = match (&r.xyz_mm, &r.joints_deg, tcp) {
            (Some(x), _, _) => cell_points_to_base(model, &[Vector3::from(*x) * 1e-3])[0],
            (None, Some(q), Some(t)) => {
                work_object::touched_tips(model, t, std::slice::from_ref(q)).map_err(|e| {
                    FitError {
                        message: format!(
                            "row {}: {}",
                            i + 1,
                            e.message.trim_start_matches("row 1: ")
                        ),
                        row: Some(i + 1),
                        ..e
                    }
                })?[0]
            }
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
    let noise = if rows.iter().all(|r| r.xyz_mm.is_some()) {
        Noise::TrackerOnly
    } else {
        Noise::Pointing
    };
    judge::judge_work_object(work_object::fit(&pts)?, noise)
}
