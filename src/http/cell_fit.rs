//! `POST /v1/robots/{id}/tools/{name}/fit` and
//! `POST /v1/robots/{id}/frames/{name}/fit`: a tool's TCP (and axis) or a
//! work object fitted on the robot's calibrated version from joint readings
//! (controller degrees) or tracker measurements (mm, degrees, the
//! calibration's measurement frame), stored as the robot's tool or work
//! object (base frame) and returned with the fit's residuals and σ
//! (`core::cell_fit::tcp`). Readings that do not determine the item, or a fit
//! beyond what the readings' noise explains (`tcp::judge`), are a 200 with
//! `fitted: false`, a typed `reason`, the figures and what to change;
//! nothing is stored then unless the body says `"force": true` for a judged
//! fit. A tool whose orientation the readings do not determine keeps the
//! stored one, or takes `rpy_deg`; it is never written as zeros.

use super::cell::{check_item_name, ItemOut, CELL_NUMBER_MAX};
use super::input::{objects, present, Int};
use super::{ApiError, ApiJson, ApiPath, AppState};
use crate::cell_fit::tcp::entry::Answer;
use crate::cell_fit::tcp::{AxisRequest, FitError, Reading, TcpMethod, ToolRequest, WoPoint};
use crate::service;
use crate::service::cell_fit::{FitTarget, Fitted};
use axum::extract::State;
use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use serde::{Deserialize, Serialize};

/// Most rows of one fit (each list).
pub const FIT_ROWS_MAX: usize = 1000;
/// Largest joint reading magnitude [deg].
const JOINT_MAX_DEG: f64 = 720.0;
/// Largest tracker coordinate magnitude [mm].
const XYZ_MAX_MM: f64 = 100_000.0;
/// Largest angle magnitude [deg].
const ANGLE_MAX_DEG: f64 = 360.0;

/// One row of a tool fit: joint readings (every method needs them) and, for
/// the tracker methods, the tracker's measurement.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ToolReadingIn {
    /// The controller's joint readings [deg].
    pub joints_deg: Vec<f64>,
    /// The tracker's measurement of the point [mm], in the calibration's measurement frame (tracker
    /// methods).
    #[serde(default, deserialize_with = "present")]
    pub xyz_mm: Option<Vec<f64>>,
    /// The tracker's measured orientation `[rx, ry, rz]` [deg] (a 6-D probe, `tracker_frame`).
    #[serde(default, deserialize_with = "present")]
    pub rpy_deg: Option<Vec<f64>>,
}

/// One row of a work-object fit: which point, measured by the tracker
/// (`xyz_mm`) or touched (`joints_deg`).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrameReadingIn {
    /// Which point of the work object the row measures.
    pub point: WoPoint,
    /// The controller's joint readings [deg] with the tool's tip on the point (touched).
    #[serde(default, deserialize_with = "present")]
    pub joints_deg: Option<Vec<f64>>,
    /// The tracker's measurement of the point [mm], in the calibration's measurement frame.
    #[serde(default, deserialize_with = "present")]
    pub xyz_mm: Option<Vec<f64>>,
}

/// A row in the common form the bounds are checked on.
struct RowIn<'a> {
    point: Option<WoPoint>,
    joints_deg: Option<&'a Vec<f64>>,
    xyz_mm: &'a Option<Vec<f64>>,
    rpy_deg: &'a Option<Vec<f64>>,
}

impl<'a> From<&'a ToolReadingIn> for RowIn<'a> {
    fn from(r: &'a ToolReadingIn) -> Self {
        RowIn {
            point: None,
            joints_deg: Some(&r.joints_deg),
            xyz_mm: &r.xyz_mm,
            rpy_deg: &r.rpy_deg,
        }
    }
}

impl<'a> From<&'a FrameReadingIn> for RowIn<'a> {
    fn from(r: &'a FrameReadingIn) -> Self {
        RowIn {
            point: Some(r.point),
            joints_deg: r.joints_deg.as_ref(),
            xyz_mm: &r.xyz_mm,
            rpy_deg: &None,
        }
    }
}

/// `POST …/tools/{name}/fit` body.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ToolFitIn {
    /// How the TCP is found; default `fixed_point`.
    #[serde(default, deserialize_with = "present")]
    pub method: Option<TcpMethod>,
    /// The rows that find the TCP.
    #[serde(deserialize_with = "objects")]
    pub readings: Vec<ToolReadingIn>,
    /// Rows of a second point on the tool's axis, nearer the flange, measured like the tip (not
    /// with `plane`).
    #[serde(default, deserialize_with = "present_objects")]
    pub axis_point: Option<Vec<ToolReadingIn>>,
    /// Joint readings with the tool flat on a plane, at least 3 (not with `axis_point`).
    #[serde(default, deserialize_with = "present_objects")]
    pub plane: Option<Vec<ToolReadingIn>>,
    /// The controller's number; absent keeps a refitted tool's number.
    #[serde(default)]
    pub number: Option<Int<i64>>,
    /// The calibrated version fitted on; absent: the active one.
    #[serde(default)]
    pub version: Option<Int<i64>>,
    /// The tool's orientation [deg] when the readings fit its position only.
    #[serde(default, deserialize_with = "present")]
    pub rpy_deg: Option<Vec<f64>>,
    /// Store a fit judged not plausible.
    #[serde(default, deserialize_with = "present")]
    pub force: Option<bool>,
}

/// `POST …/frames/{name}/fit` body.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WorkObjectFitIn {
    /// The rows that find the work object.
    #[serde(deserialize_with = "objects")]
    pub readings: Vec<FrameReadingIn>,
    /// The stored tool whose tip touched the points (rows with `joints_deg`).
    #[serde(default, deserialize_with = "present")]
    pub tool: Option<String>,
    /// The controller's number; absent keeps a refitted work object's number.
    #[serde(default)]
    pub number: Option<Int<i64>>,
    /// The calibrated version fitted on; absent: the active one.
    #[serde(default)]
    pub version: Option<Int<i64>>,
    /// Store a fit judged not plausible.
    #[serde(default, deserialize_with = "present")]
    pub force: Option<bool>,
}

fn present_objects<'de, D: serde::Deserializer<'de>>(
    d: D,
) -> Result<Option<Vec<ToolReadingIn>>, D::Error> {
    objects(d).map(Some)
}

fn triple(
    v: &Option<Vec<f64>>,
    what: &str,
    row: usize,
    max: f64,
) -> Result<Option<[f64; 3]>, ApiError> {
    let Some(v) = v else { return Ok(None) };
    let t = <[f64; 3]>::try_from(v.as_slice())
        .map_err(|_| ApiError::invalid(format!("{what} {row}: needs 3 values, got {}", v.len())))?;
    if t.iter().any(|x| x.abs() > max) {
        return Err(ApiError::invalid(format!(
            "{what} {row}: values must be within ±{max}"
        )));
    }
    Ok(Some(t))
}

/// The rows checked against the spec's bounds.
fn rows<'a, T: 'a>(list: &'a [T], what: &str) -> Result<Vec<Reading>, ApiError>
where
    RowIn<'a>: From<&'a T>,
{
    if list.is_empty() || list.len() > FIT_ROWS_MAX {
        return Err(ApiError::invalid(format!(
            "`{what}`: 1 to {FIT_ROWS_MAX} rows, got {}",
            list.len()
        )));
    }
    list.iter()
        .map(RowIn::from)
        .enumerate()
        .map(|(i, r)| {
            let row = i + 1;
            if r.joints_deg.is_none() && r.xyz_mm.is_none() {
                return Err(ApiError::invalid(format!(
                    "`{what}` row {row}: give a tracker position `xyz_mm` or joint readings `joints_deg`"
                )));
            }
            if let Some(q) = r.joints_deg {
                if !(1..=7).contains(&q.len()) || q.iter().any(|v| v.abs() > JOINT_MAX_DEG) {
                    return Err(ApiError::invalid(format!(
                        "`{what}` row {row}: `joints_deg` needs 1 to 7 controller readings within ±{JOINT_MAX_DEG}°"
                    )));
                }
            }
            Ok(Reading {
                point: r.point,
                joints_deg: r.joints_deg.cloned(),
                xyz_mm: triple(r.xyz_mm, &format!("`{what}` row, `xyz_mm`,"), row, XYZ_MAX_MM)?,
                rpy_deg: triple(r.rpy_deg, &format!("`{what}` row, `rpy_deg`,"), row, ANGLE_MAX_DEG)?,
            })
        })
        .collect()
}

fn target(
    robot_id: i64,
    name: &str,
    number: Option<i64>,
    version: Option<i64>,
) -> Result<FitTarget, ApiError> {
    check_item_name(name)?;
    let number = match number {
        Some(n) if !(0..=CELL_NUMBER_MAX).contains(&n) => {
            return Err(ApiError::invalid(format!(
                "`number` must be between 0 and {CELL_NUMBER_MAX}, got {n}"
            )))
        }
        Some(n) => Some(n as u32),
        None => None,
    };
    if let Some(v) = version {
        if v < 1 {
            return Err(ApiError::invalid(format!(
                "`version` numbers start at 1, got {v}"
            )));
        }
    }
    Ok(FitTarget {
        robot_id,
        name: name.to_string(),
        number,
        version,
        ..FitTarget::default()
    })
}

#[derive(Serialize)]
struct FitOut<'a, F: Serialize> {
    #[serde(flatten)]
    answer: Answer<'a, F>,
    item: ItemOut,
    /// The calibrated version the fit was made on.
    version: i64,
}

#[derive(Serialize)]
struct NotFittedOut<'a> {
    /// Always false: nothing was stored.
    fitted: bool,
    #[serde(flatten)]
    why: &'a FitError,
    version: i64,
}

/// 201 created, 200 replaced, or 200 with `fitted: false` and why.
fn answer<F: Serialize>(done: Fitted<F>) -> Response {
    match done {
        Fitted::Stored(s) => {
            let status = if s.put.created {
                StatusCode::CREATED
            } else {
                StatusCode::OK
            };
            let body = FitOut {
                answer: s.fitted.answer(),
                item: ItemOut::from_row(s.put.row),
                version: s.version,
            };
            (status, axum::Json(body)).into_response()
        }
        Fitted::NotFitted { why, version } => {
            let body = NotFittedOut {
                fitted: false,
                why: &why,
                version,
            };
            (StatusCode::OK, axum::Json(body)).into_response()
        }
    }
}

/// `POST /v1/robots/{id}/tools/{name}/fit`: the tool fitted and stored (201 or 200), or a 200 with
/// `fitted: false` and why.
pub async fn fit_tool(
    State(s): State<AppState>,
    ApiPath((id, name)): ApiPath<(i64, String)>,
    ApiJson(body): ApiJson<ToolFitIn>,
) -> Result<Response, ApiError> {
    let t = target(
        id,
        &name,
        body.number.map(|n| n.0),
        body.version.map(|v| v.0),
    )?;
    let axis = match (&body.axis_point, &body.plane) {
        (Some(_), Some(_)) => {
            return Err(ApiError::invalid(
                "give the tool's axis by `axis_point` or by `plane`, not both",
            ))
        }
        (Some(a), None) => Some(AxisRequest::Point(rows(a, "axis_point")?)),
        (None, Some(p)) => Some(AxisRequest::Plane(rows(p, "plane")?)),
        (None, None) => None,
    };
    let req = ToolRequest {
        method: body.method.unwrap_or(TcpMethod::FixedPoint),
        rows: rows(&body.readings, "readings")?,
        axis,
    };
    let mut t = t;
    t.force = body.force.unwrap_or(false);
    if let Some(v) = &body.rpy_deg {
        let rpy = <[f64; 3]>::try_from(v.as_slice())
            .ok()
            .filter(|a| a.iter().all(|x| x.abs() <= ANGLE_MAX_DEG))
            .ok_or_else(|| {
                ApiError::invalid(format!(
                    "`rpy_deg`: 3 angles within ±{ANGLE_MAX_DEG}°, got {v:?}"
                ))
            })?;
        t.rpy_deg = Some(rpy);
    }
    if t.rpy_deg.is_some() && req.determines_orientation() {
        return Err(ApiError::invalid(
            "`rpy_deg`: the readings determine the tool's orientation (an axis or a 6-D probe); leave `rpy_deg` out",
        ));
    }
    Ok(answer(service::cell_fit::fit_tool(&s, &t, &req).await?))
}

/// `POST /v1/robots/{id}/frames/{name}/fit`: the work object fitted and stored in the base frame
/// (201 or 200), or a 200 with `fitted: false` and why.
pub async fn fit_frame(
    State(s): State<AppState>,
    ApiPath((id, name)): ApiPath<(i64, String)>,
    ApiJson(body): ApiJson<WorkObjectFitIn>,
) -> Result<Response, ApiError> {
    let t = target(
        id,
        &name,
        body.number.map(|n| n.0),
        body.version.map(|v| v.0),
    )?;
    let mut t = t;
    t.force = body.force.unwrap_or(false);
    if let Some(tool) = &body.tool {
        check_item_name(tool)?;
    }
    let readings = rows(&body.readings, "readings")?;
    let done = service::cell_fit::fit_work_object(&s, &t, &readings, body.tool.as_deref()).await?;
    Ok(answer(done))
}

/// The routes of tool and work-object fits.
pub fn routes() -> Vec<super::Route> {
    use super::post;
    vec![
        post("/v1/robots/{id}/tools/{name}/fit", fit_tool),
        post("/v1/robots/{id}/frames/{name}/fit", fit_frame),
    ]
}
