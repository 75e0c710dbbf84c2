//! What a TCP or work-object fit gives: the fitted tool (`ToolFit`, SI in
//! `tcp`, mm and degrees in the fields named so), the fitted work object
//! (`WorkObjectFit`), and why a fit was refused (`FitError`, its
//! `NotFittedReason` and the `JudgedFit` figures), read by every method of
//! `tcp` and by `work_object`.

use super::limits::Limits;
use crate::model::Pose;
use nalgebra::{Matrix3, Vector3};
use serde::Serialize;

/// Why a tool or work object was not fitted: the readings do not determine
/// it (a closed set: the API's `reason` enum and the CLI's text derive from
/// it). `measured` and `needed` of a [`FitError`] carry the figure each
/// reason names, in the unit given here.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NotFittedReason {
    /// Fewer rows than the method needs (rows).
    TooFewReadings,
    /// A row's joint count is not the robot's (joints).
    JointCount,
    /// A row lacks the joint readings the method needs.
    MissingJoints,
    /// A tracker method's row lacks the position x, y, z.
    MissingPosition,
    /// A 6-D probe's row lacks the orientation rx, ry, rz.
    MissingOrientation,
    /// An axis given with a 6-D probe, which gives the orientation itself.
    AxisWithProbe,
    /// A work object lacks its origin, x or xy point, or a row names no point.
    MissingPoint,
    /// Work-object touches (joint readings) without the tool that made them.
    TouchesNeedTool,
    /// A value is not finite.
    NotFinite,
    /// The calibrated model's forward kinematics failed at a row.
    Kinematics,
    /// Fixed point: the orientations differ too little about some direction
    /// (degrees).
    OrientationsTooSimilar,
    /// The least-squares problem is singular.
    Singular,
    /// The second axis point is too near the tip (mm).
    AxisPointTooClose,
    /// The plane touches lie on a line (spread across it, mm).
    PlaneTouchesInLine,
    /// The work object's x point is too near its origin (mm).
    XPointTooClose,
    /// The xy point is (nearly) on the x axis (angle between OX and OY,
    /// degrees).
    XyPointOnXAxis,
    /// The residuals' RMS is beyond what the readings' noise explains (mm;
    /// for a work object the worst point's scatter), `judge`.
    ResidualsTooLarge,
    /// One row's residual is beyond what the noise explains (mm), `judge`.
    ResidualOutlier,
    /// A 6-D probe's orientation residuals' RMS is beyond the noise (deg).
    OrientationResidualsTooLarge,
    /// A point is off the plane beyond the noise (mm), `judge`.
    OffPlane,
    /// The TCP is farther from the flange than the arm is long (mm).
    TcpTooFar,
    /// The method fits the TCP's position only, and the tool has no stored
    /// orientation to keep and none was given.
    OrientationUnknown,
}

impl NotFittedReason {
    /// Every reason, in declaration order.
    pub const ALL: [NotFittedReason; 22] = [
        NotFittedReason::TooFewReadings,
        NotFittedReason::JointCount,
        NotFittedReason::MissingJoints,
        NotFittedReason::MissingPosition,
        NotFittedReason::MissingOrientation,
        NotFittedReason::AxisWithProbe,
        NotFittedReason::MissingPoint,
        NotFittedReason::TouchesNeedTool,
        NotFittedReason::NotFinite,
        NotFittedReason::Kinematics,
        NotFittedReason::OrientationsTooSimilar,
        NotFittedReason::Singular,
        NotFittedReason::AxisPointTooClose,
        NotFittedReason::PlaneTouchesInLine,
        NotFittedReason::XPointTooClose,
        NotFittedReason::XyPointOnXAxis,
        NotFittedReason::ResidualsTooLarge,
        NotFittedReason::ResidualOutlier,
        NotFittedReason::OrientationResidualsTooLarge,
        NotFittedReason::OffPlane,
        NotFittedReason::TcpTooFar,
        NotFittedReason::OrientationUnknown,
    ];

    /// The reason's name in the API's `reason` and the command line's text (snake_case).
    pub fn as_str(self) -> &'static str {
        match self {
            NotFittedReason::TooFewReadings => "too_few_readings",
            NotFittedReason::JointCount => "joint_count",
            NotFittedReason::MissingJoints => "missing_joints",
            NotFittedReason::MissingPosition => "missing_position",
            NotFittedReason::MissingOrientation => "missing_orientation",
            NotFittedReason::AxisWithProbe => "axis_with_probe",
            NotFittedReason::MissingPoint => "missing_point",
            NotFittedReason::TouchesNeedTool => "touches_need_tool",
            NotFittedReason::NotFinite => "not_finite",
            NotFittedReason::Kinematics => "kinematics",
            NotFittedReason::OrientationsTooSimilar => "orientations_too_similar",
            NotFittedReason::Singular => "singular",
            NotFittedReason::AxisPointTooClose => "axis_point_too_close",
            NotFittedReason::PlaneTouchesInLine => "plane_touches_in_line",
            NotFittedReason::XPointTooClose => "x_point_too_close",
            NotFittedReason::XyPointOnXAxis => "xy_point_on_x_axis",
            NotFittedReason::ResidualsTooLarge => "residuals_too_large",
            NotFittedReason::ResidualOutlier => "residual_outlier",
            NotFittedReason::OrientationResidualsTooLarge => "orientation_residuals_too_large",
            NotFittedReason::OffPlane => "off_plane",
            NotFittedReason::TcpTooFar => "tcp_too_far",
            NotFittedReason::OrientationUnknown => "orientation_unknown",
        }
    }

    /// A verdict of `judge` on a computed fit, which the user may overrule
    /// by forcing it to be stored.
    pub fn forcible(self) -> bool {
        matches!(
            self,
            NotFittedReason::ResidualsTooLarge
                | NotFittedReason::ResidualOutlier
                | NotFittedReason::OrientationResidualsTooLarge
                | NotFittedReason::OffPlane
                | NotFittedReason::TcpTooFar
        )
    }
}

/// A fit that was computed and judged not plausible, with its figures.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum JudgedFit {
    /// A fitted tool.
    Tool(ToolFit),
    /// A fitted work object.
    WorkObject(WorkObjectFit),
}

/// Why a tool or work object was not fitted, with what the user can act on:
/// the reason, a message naming the fix, the row at fault (1-based, in the
/// list the message names), the figure the reason names against what it
/// needs, and for a tool whose axis failed the tip's own fit.
#[derive(Debug, Clone, PartialEq, Serialize, thiserror::Error)]
#[error("{message}")]
pub struct FitError {
    /// Why the fit was refused.
    pub reason: NotFittedReason,
    /// What went wrong and how to fix it, for the user.
    pub message: String,
    /// The row at fault (1-based, in the list the message names).
    pub row: Option<usize>,
    /// The figure the reason names, in the unit [`NotFittedReason`] gives for it.
    pub measured: Option<f64>,
    /// The bound that figure had to meet, in the same unit.
    pub needed: Option<f64>,
    /// The tip, fitted before its axis could not be.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tip: Option<Box<ToolFit>>,
    /// The fit itself (residuals, σ, the limits it broke), when it was
    /// computed and judged not plausible (`judge`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fit: Option<Box<JudgedFit>>,
}

impl FitError {
    /// A refusal for `reason` with `message`, without row, figures or fit.
    pub fn new(reason: NotFittedReason, message: impl Into<String>) -> Self {
        FitError {
            reason,
            message: message.into(),
            row: None,
            measured: None,
            needed: None,
            tip: None,
            fit: None,
        }
    }

    /// The row at fault (1-based).
    pub fn at_row(mut self, row: usize) -> Self {
        self.row = Some(row);
        self
    }

    /// The figure the reason names and what it needs.
    pub fn figures(mut self, measured: f64, needed: f64) -> Self {
        self.measured = Some(measured);
        self.needed = Some(needed);
        self
    }

    /// The tip's fit, when only the axis failed.
    pub fn with_tip(mut self, tip: ToolFit) -> Self {
        self.tip = Some(Box::new(tip));
        self
    }

    /// The fit judged not plausible.
    pub fn with_fit(mut self, fit: JudgedFit) -> Self {
        self.fit = Some(Box::new(fit));
        self
    }
}

/// How a TCP was found (a closed set: CLI values, API enums and labels).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TcpMethod {
    /// Tip held at one fixed point in ≥ 4 orientations (joint readings only).
    FixedPoint,
    /// A reflector on the tool measured by the tracker.
    TrackerPoint,
    /// A 6-D probe on the tool measured by the tracker (full frame).
    TrackerFrame,
}

impl TcpMethod {
    /// Every method, in declaration order.
    pub const ALL: [TcpMethod; 3] = [
        TcpMethod::FixedPoint,
        TcpMethod::TrackerPoint,
        TcpMethod::TrackerFrame,
    ];

    /// The method's name on the command line and in the API (snake_case).
    pub fn as_str(self) -> &'static str {
        match self {
            TcpMethod::FixedPoint => "fixed_point",
            TcpMethod::TrackerPoint => "tracker_point",
            TcpMethod::TrackerFrame => "tracker_frame",
        }
    }
}

impl std::str::FromStr for TcpMethod {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let k = s.trim().replace('-', "_").to_ascii_lowercase();
        TcpMethod::ALL
            .into_iter()
            .find(|m| m.as_str() == k)
            .ok_or_else(|| {
                let all: Vec<&str> = TcpMethod::ALL.iter().map(|m| m.as_str()).collect();
                format!("method `{s}`: one of {}", all.join(", "))
            })
    }
}

/// A fitted tool: its TCP frame in the flange frame and how well it fits.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ToolFit {
    /// How the TCP was found.
    pub method: TcpMethod,
    /// Flange → TCP [m]; the rotation is the flange's unless an axis or a
    /// 6-D probe gave one ([`Self::rpy_deg`]).
    #[serde(skip)]
    pub tcp: Pose,
    /// The TCP in the flange frame [mm].
    pub xyz_mm: [f64; 3],
    /// The tool's orientation, fixed-axis `[rx, ry, rz]` [deg], when the
    /// readings determined it (an axis or a 6-D probe); absent when they
    /// fit the position only.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rpy_deg: Option<[f64; 3]>,
    /// Distance of the TCP from the flange centre [mm].
    pub distance_mm: f64,
    /// Per pose: distance of the fitted tip from where it should be [mm].
    pub residual_mm: Vec<f64>,
    /// RMS of `residual_mm` [mm].
    pub rms_mm: f64,
    /// Largest of `residual_mm` [mm].
    pub max_mm: f64,
    /// 1σ of the TCP position per flange axis [mm] (covariance of the fit).
    pub sigma_mm: [f64; 3],
    /// Per pose: angle between the fitted and the measured frame [deg] (6-D
    /// probe and plane axis only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub orientation_residual_deg: Option<Vec<f64>>,
    /// 1σ of the tool's orientation [deg], when one was fitted.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sigma_deg: Option<f64>,
    /// The fixed point in the base frame [mm] (fixed-point method).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fixed_point_mm: Option<[f64; 3]>,
    /// The smallest orientation spread of the poses [deg] (fixed-point method):
    /// how far the orientations differ about the worst direction.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub orientation_spread_deg: Option<f64>,
    /// Where the tool's z came from, when an axis was fitted.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub axis: Option<AxisSource>,
    /// Distance from the tip to the second axis point [mm] (axis point).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub axis_length_mm: Option<f64>,
    /// Per touch: the tip's distance from the fitted plane [mm] (plane axis).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plane_residual_mm: Option<Vec<f64>>,
    /// The bounds the fit was judged against (`judge`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub limits: Option<Limits>,
}

impl ToolFit {
    /// A fit of the TCP's position `t` (flange frame, m) with its residuals
    /// and σ; the orientation is not determined.
    pub fn position(
        method: TcpMethod,
        t: Vector3<f64>,
        residual_mm: Vec<f64>,
        sigma_mm: [f64; 3],
    ) -> Self {
        let (rms_mm, max_mm) = rms_max(&residual_mm);
        ToolFit {
            method,
            tcp: Pose::from_translation(t),
            xyz_mm: [t.x * 1e3, t.y * 1e3, t.z * 1e3],
            rpy_deg: None,
            distance_mm: t.norm() * 1e3,
            residual_mm,
            rms_mm,
            max_mm,
            sigma_mm,
            orientation_residual_deg: None,
            sigma_deg: None,
            fixed_point_mm: None,
            orientation_spread_deg: None,
            axis: None,
            axis_length_mm: None,
            plane_residual_mm: None,
            limits: None,
        }
    }

    /// Sets the tool's orientation (flange frame), as the readings determined it.
    pub fn set_orientation(&mut self, r: Matrix3<f64>) {
        self.tcp.r = r;
        self.rpy_deg = Some(crate::model::orientation::fixed_xyz_angles(&r).map(f64::to_degrees));
    }
}

/// Root mean square and maximum of `v` (0 for none).
pub(crate) fn rms_max(v: &[f64]) -> (f64, f64) {
    if v.is_empty() {
        return (0.0, 0.0);
    }
    let rms = (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt();
    (rms, v.iter().cloned().fold(0.0, f64::max))
}

/// Where a tool's z came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum AxisSource {
    /// A second point on the tool's axis.
    Point,
    /// Touches with the tool flat on a plane.
    Plane,
}

/// A fitted work object and how well the points agree.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WorkObjectFit {
    /// Base → work object [m].
    #[serde(skip)]
    pub pose: Pose,
    /// The origin in the robot base frame [mm].
    pub xyz_mm: [f64; 3],
    /// The orientation, fixed-axis `[rx, ry, rz]` [deg].
    pub rpy_deg: [f64; 3],
    /// RMS scatter of the repeated touches of the origin, x and xy points [mm]
    /// (0 for a point touched once).
    pub scatter_mm: [f64; 3],
    /// The extra plane points' distances from the fitted xy plane [mm].
    pub plane_residual_mm: Vec<f64>,
    /// Angle between `OX` and `OY` [deg].
    pub xy_angle_deg: f64,
    /// 1σ of the origin per axis [mm], from repeated touches.
    pub sigma_mm: Option<f64>,
    /// 1σ of the orientation [deg], from repeated touches.
    pub sigma_deg: Option<f64>,
    /// The bounds the fit was judged against (`tcp::judge`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub limits: Option<Limits>,
}
