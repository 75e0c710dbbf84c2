//! `/v1/robots/{id}/measurement-sets`: upload (JSON rows or the measurement CSV
//! of docs/design.md as `text/csv`), list, get (rows read back bit for bit), the
//! original upload, delete.
//!
//! Declared units (`length_unit` mm|m, `angle_unit` deg|rad) convert the rows to
//! millimetres and degrees when they are stored; the upload itself is kept
//! verbatim and served by `GET .../original`.

use super::error::{content_type, json_content_type};
use super::input::{
    check_name, check_payload, from_json_object, objects, page_body, present, PageQuery,
};
use super::robots::robot_list_page;
use super::{ApiError, ApiPath, ApiQuery, AppState};
use crate::measure::bounds;
use crate::measure::convention::MeasuredOrientation;
use crate::measure::csv::{self, DifSign, ReadOptions};
use crate::measure::{MeasuredPose, SetRole};
use crate::model::bounds::{show, Bound};
use crate::records::{AngleUnit, LengthUnit, SetFormat, SetRow};
use crate::service::{
    self,
    sets::{NewSetCommand, SetContent},
};
use axum::body::Bytes;
use axum::extract::rejection::BytesRejection;
use axum::extract::State;
use axum::http::{header, HeaderMap, StatusCode};
use axum::response::{IntoResponse, Response};
use serde::{Deserialize, Serialize};

/// Options of an upload: the query string of a CSV upload, the body fields of
/// a JSON upload. A JSON upload takes the set's name, role, session and
/// payload from the query for the fields its body leaves out; the options that
/// say how to read a CSV text (units, `dif_sign`, `decimal`) are for CSV only.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SetParams {
    /// The set's name; absent: the role's name.
    pub name: Option<String>,
    /// The set's role (`identification`, `training`, `validation` or `check`); absent: the rows'
    /// common `set`, else identification.
    pub role: Option<String>,
    /// The tracker session it was measured in; absent: `default`.
    pub session: Option<String>,
    /// Payload of rows that carry none [kg].
    pub payload_kg: Option<f64>,
    /// Length unit of the rows: `mm` (default) or `m`.
    pub length_unit: Option<String>,
    /// Angle unit of the rows: `deg` (default) or `rad`.
    pub angle_unit: Option<String>,
    /// CSV only: sign of the real-data `*_dif` columns (`plus` | `minus`).
    pub dif_sign: Option<String>,
    /// CSV only: `point` or `comma` (detected when absent).
    pub decimal: Option<String>,
    /// CSV only: convention of the `rx, ry, rz` columns
    /// ([`MeasuredOrientation`]; default from the header).
    pub orientation: Option<String>,
}

/// One row of a JSON upload, in the declared units.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RowInput {
    /// Controller joint readings (declared angle unit).
    #[serde(alias = "q_deg")]
    pub q: Vec<f64>,
    /// Measured TCP position in the measurement frame (declared length unit).
    #[serde(alias = "xyz_mm")]
    pub xyz: [f64; 3],
    /// Measured orientation, fixed-axis XYZ `[rx, ry, rz]` (declared angle unit).
    #[serde(default, alias = "rpy_deg")]
    pub rpy: Option<[f64; 3]>,
    /// Standard deviations of `xyz` (declared length unit).
    #[serde(default)]
    pub std_mm: Option<[f64; 3]>,
    /// Standard deviations of `rpy` (declared angle unit).
    #[serde(default)]
    pub std_deg: Option<[f64; 3]>,
    /// Payload mass at this pose [kg]; absent: the set's.
    #[serde(default)]
    pub payload_kg: Option<f64>,
    /// Temperature during the measurement [°C].
    #[serde(default)]
    pub temperature_c: Option<f64>,
    /// The pose's data role (the CSV's `set` column), when given.
    #[serde(default)]
    pub set: Option<SetRole>,
}

/// A JSON upload (optional fields may be left out, not `null`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JsonUpload {
    /// The set's name; absent: the query's, else the role's name.
    #[serde(default, deserialize_with = "present")]
    pub name: Option<String>,
    /// The set's role; absent: the query's, else the rows' common `set`, else identification.
    #[serde(default, deserialize_with = "present")]
    pub role: Option<String>,
    /// The tracker session it was measured in; absent: the query's, else `default`.
    #[serde(default, deserialize_with = "present")]
    pub session: Option<String>,
    /// Payload of rows that carry none [kg]; absent: the query's.
    #[serde(default, deserialize_with = "present")]
    pub payload_kg: Option<f64>,
    /// Length unit of the rows: `mm` (default) or `m`.
    #[serde(default, deserialize_with = "present")]
    pub length_unit: Option<String>,
    /// Angle unit of the rows: `deg` (default) or `rad`.
    #[serde(default, deserialize_with = "present")]
    pub angle_unit: Option<String>,
    /// The rows, in the declared units.
    #[serde(deserialize_with = "objects")]
    pub rows: Vec<RowInput>,
}

impl JsonUpload {
    /// The body's options, with the query's set metadata for the fields the
    /// body leaves out.
    fn params(&self, query: &SetParams) -> SetParams {
        SetParams {
            name: self.name.clone().or_else(|| query.name.clone()),
            role: self.role.clone().or_else(|| query.role.clone()),
            session: self.session.clone().or_else(|| query.session.clone()),
            payload_kg: self.payload_kg.or(query.payload_kg),
            length_unit: self.length_unit.clone(),
            angle_unit: self.angle_unit.clone(),
            ..SetParams::default()
        }
    }
}

/// The units an upload declared.
#[derive(Debug, Serialize)]
pub struct Units {
    /// The length unit: `mm` or `m`.
    pub length: String,
    /// The angle unit: `deg` or `rad`.
    pub angle: String,
}

/// A measurement set as the API returns it.
#[derive(Debug, Serialize)]
pub struct MeasurementSet {
    /// The set's id.
    pub id: i64,
    /// The robot it belongs to.
    pub robot_id: i64,
    /// The set's name.
    pub name: String,
    /// Its data role.
    pub role: String,
    /// The tracker session it was measured in.
    pub session: String,
    /// Payload of rows that carry none [kg], as declared.
    pub payload_kg: Option<f64>,
    /// The units the upload declared.
    pub units: Units,
    /// The format the upload came in: `csv` or `json`.
    pub format: String,
    /// Number of rows.
    pub row_count: i64,
    /// Joints per row.
    pub dof: i64,
    /// When it was stored (UTC, RFC 3339).
    pub created_at: String,
    /// A track's station set: the track's column and its value there.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub station: Option<StationValue>,
    /// The rows in mm/deg (single-set responses only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rows: Option<Vec<MeasuredPose>>,
}

/// The track's value a station set was measured at.
#[derive(Debug, Serialize)]
pub struct StationValue {
    /// The track's column, `e1` … `e6`.
    pub column: String,
    /// Its value at every row of the set [mm], as the file gave it.
    pub value_mm: f64,
}

impl MeasurementSet {
    /// The set as the API returns it, with its rows (mm, deg) when given.
    pub fn from_row(r: SetRow, rows: Option<Vec<MeasuredPose>>) -> Self {
        MeasurementSet {
            id: r.id,
            robot_id: r.robot_id,
            name: r.name,
            role: SetRole::from(r.role).as_str().to_string(),
            session: r.session,
            payload_kg: r.payload_kg,
            units: Units {
                length: r.length_unit.as_str().to_string(),
                angle: r.angle_unit.as_str().to_string(),
            },
            format: r.format.as_str().to_string(),
            row_count: r.row_count,
            dof: r.dof,
            created_at: r.created_at,
            station: r
                .axis_column
                .zip(r.axis_value)
                .map(|(column, value_mm)| StationValue { column, value_mm }),
            rows,
        }
    }
}

type Length = LengthUnit;
type Angle = AngleUnit;

pub(super) struct Checked {
    pub(super) name: String,
    pub(super) role: Option<SetRole>,
    pub(super) session: String,
    pub(super) payload_kg: Option<f64>,
    pub(super) length: Length,
    pub(super) angle: Angle,
}

pub(super) fn check_params(p: &SetParams) -> Result<Checked, ApiError> {
    let role = p
        .role
        .as_deref()
        .map(|r| {
            // The names exactly as the spec lists them.
            SetRole::parse(r)
                .filter(|role| role.as_str() == r)
                .ok_or_else(|| {
                    ApiError::invalid(format!("`role` must be {}, got `{r}`", SetRole::names()))
                })
        })
        .transpose()?;
    let session = p.session.clone().unwrap_or_else(|| "default".into());
    check_name(&session, "`session`")?;
    if let Some(n) = &p.name {
        check_name(n, "`name`")?;
    }
    if let Some(m) = p.payload_kg {
        check_payload("`payload_kg`", m)?;
    }
    let length = match p.length_unit.as_deref().unwrap_or("mm") {
        "mm" => Length::Mm,
        "m" => Length::M,
        other => {
            return Err(ApiError::invalid(format!(
                "`length_unit` must be mm or m, got `{other}`"
            )))
        }
    };
    let angle = match p.angle_unit.as_deref().unwrap_or("deg") {
        "deg" => Angle::Deg,
        "rad" => Angle::Rad,
        other => {
            return Err(ApiError::invalid(format!(
                "`angle_unit` must be deg or rad, got `{other}`"
            )))
        }
    };
    Ok(Checked {
        name: p.name.clone().unwrap_or_default(),
        role,
        session,
        payload_kg: p.payload_kg,
        length,
        angle,
    })
}

/// The JSON rows' bounds in their declared units: the stored bounds
/// (`measure::bounds`: `|q| ≤ 720°`, positions within ±100 m, orientation
/// angles within ±360°, σ of a position 1e-6..1000 mm and of an angle
/// 1e-6..180°, temperatures −100..200 °C) converted into the units, so that
/// `openapi.yaml` states them exactly; not every coordinate within ±5 mm.
/// Converting a value within a declared bound gives a value within the
/// stored bound (`declared_bounds_convert_into_the_stored_ones`), which the
/// service checks again on the rows as stored.
pub(crate) struct RowBounds {
    pub(crate) joint: Bound,
    pub(crate) position: Bound,
    pub(crate) angle: Bound,
    pub(crate) std_position: Bound,
    pub(crate) std_angle: Bound,
    metres_suspect: f64,
}

impl RowBounds {
    pub(crate) fn of(length: Length, angle: Angle) -> RowBounds {
        let (lu, au) = (length.as_str(), angle.as_str());
        let len = |b: Bound| match length {
            Length::Mm => b,
            Length::M => Bound {
                min: b.min / 1e3,
                max: b.max / 1e3,
                unit: lu,
            },
        };
        let ang = |b: Bound| match angle {
            Angle::Deg => b,
            Angle::Rad => Bound {
                min: b.min.to_radians(),
                max: b.max.to_radians(),
                unit: au,
            },
        };
        RowBounds {
            joint: ang(bounds::JOINT_DEG),
            position: len(bounds::POSITION_MM),
            angle: ang(bounds::ANGLE_DEG),
            std_position: len(bounds::STD_MM),
            std_angle: ang(bounds::STD_DEG),
            metres_suspect: match length {
                Length::Mm => csv::METRES_SUSPECT_MM,
                Length::M => csv::METRES_SUSPECT_MM / 1e3,
            },
        }
    }
}

/// Each of `values` within `b` (declared units), else a 422 naming the row,
/// the field, the value and the bound.
fn check_field(n: usize, field: &str, values: &[f64], b: &Bound) -> Result<(), ApiError> {
    match values
        .iter()
        .enumerate()
        .find(|(_, v)| !bounds::within(**v, b))
    {
        None => Ok(()),
        Some((i, v)) => {
            let at = if values.len() == 1 {
                format!("`{field}`")
            } else {
                format!("`{field}[{i}]`")
            };
            Err(ApiError::invalid(format!(
                "row {n}: {at} = {} {} is outside the bound {}",
                show(*v),
                b.unit,
                bounds::describe(b)
            )))
        }
    }
}

fn json_rows(rows: Vec<RowInput>, c: &Checked) -> Result<Vec<MeasuredPose>, ApiError> {
    if rows.is_empty() {
        return Err(ApiError::invalid(
            "`rows` is empty: upload at least one measured pose",
        ));
    }
    let b = RowBounds::of(c.length, c.angle);
    let (lu, au) = (c.length.as_str(), c.angle.as_str());
    for (i, r) in rows.iter().enumerate() {
        let n = i + 1;
        let bad = |what: &str| ApiError::invalid(format!("row {n}: {what} must be finite numbers"));
        if r.q.iter().any(|v| !v.is_finite()) {
            return Err(bad("joint values `q`"));
        }
        if r.xyz.iter().any(|v| !v.is_finite()) {
            return Err(bad("position `xyz`"));
        }
        check_std(n, r, rows[0].std_mm.is_some())?;
        if let Some(p) = r.payload_kg {
            check_payload(&format!("row {n}: `payload_kg`"), p)?;
        }
        if let Some(q) = r.q.iter().find(|q| q.abs() > b.joint.max) {
            return Err(ApiError::invalid(format!(
                "row {n}: joint value {q:.4e} {au} is beyond ±{} {au} (±{} deg): wrong units (encoder counts, or radians declared as degrees)?",
                b.joint.max,
                csv::MAX_JOINT_DEG
            )));
        }
        if let Some(x) = r.xyz.iter().find(|x| x.abs() > b.position.max) {
            return Err(ApiError::invalid(format!(
                "row {n}: position coordinate {x:.4e} {lu} is beyond ±{} m of the tracker",
                csv::MAX_POSITION_MM / 1e3
            )));
        }
        let optional = [
            ("rpy", r.rpy.as_ref().map(|v| &v[..]), &b.angle),
            ("std_mm", r.std_mm.as_ref().map(|v| &v[..]), &b.std_position),
            ("std_deg", r.std_deg.as_ref().map(|v| &v[..]), &b.std_angle),
            (
                "temperature_c",
                r.temperature_c.as_ref().map(std::slice::from_ref),
                &bounds::TEMPERATURE_C,
            ),
        ];
        for (field, values, bound) in optional {
            if let Some(values) = values {
                check_field(n, field, values, bound)?;
            }
        }
    }
    if rows
        .iter()
        .all(|r| r.xyz.iter().all(|v| v.abs() < b.metres_suspect))
    {
        return Err(ApiError::invalid(if c.length == Length::M {
            format!(
                "every position coordinate is within ±{} m: the rows do not look like tracker positions",
                b.metres_suspect
            )
        } else {
            format!(
                "every position coordinate is within ±{} mm: looks like metres; declare \"length_unit\": \"m\" or send millimetres",
                csv::METRES_SUSPECT_MM
            )
        }));
    }
    let lf = if c.length == Length::M { 1e3 } else { 1.0 };
    let rad = c.angle == Angle::Rad;
    let angle = |a: f64| if rad { a.to_degrees() } else { a };
    Ok(rows
        .into_iter()
        .map(|r| MeasuredPose {
            q_deg: r.q.into_iter().map(angle).collect(),
            xyz_mm: r.xyz.map(|v| v * lf),
            rpy_deg: r.rpy.map(|a| a.map(angle)),
            std_mm: r.std_mm.map(|s| s.map(|v| v * lf)),
            std_deg: r.std_deg.map(|s| s.map(angle)),
            payload_kg: r.payload_kg,
            temperature_c: r.temperature_c,
            set: r.set,
            session: None,
        })
        .collect())
}

/// A JSON row's standard deviations: finite and > 0, `std_deg` only with
/// `rpy` and `std_mm`, and on every row or none (`first`: the first row has them).
fn check_std(n: usize, r: &RowInput, first: bool) -> Result<(), ApiError> {
    for (what, v) in [("std_mm", r.std_mm), ("std_deg", r.std_deg)] {
        if v.is_some_and(|a| a.iter().any(|x| !(x.is_finite() && *x > 0.0))) {
            return Err(ApiError::invalid(format!(
                "row {n}: `{what}` must be three finite numbers > 0"
            )));
        }
    }
    if r.std_mm.is_some() != first {
        return Err(ApiError::invalid(format!(
            "row {n}: `std_mm` is given on some rows and not on others; give it on every row or none"
        )));
    }
    if r.std_deg.is_some() && (r.rpy.is_none() || r.std_mm.is_none()) {
        return Err(ApiError::invalid(format!(
            "row {n}: `std_deg` needs `rpy` and `std_mm` on the same row"
        )));
    }
    Ok(())
}

/// The CSV reading options of an upload's query.
pub(super) fn read_options(q: &SetParams, c: &Checked) -> Result<ReadOptions, ApiError> {
    let dif = match q.dif_sign.as_deref() {
        None | Some("plus") => DifSign::Plus,
        Some("minus") => DifSign::Minus,
        Some(other) => {
            return Err(ApiError::invalid(format!(
                "`dif_sign` must be plus (measured = target + dif) or minus, got `{other}`"
            )))
        }
    };
    let orientation = match q.orientation.as_deref() {
        None => None,
        Some(name) => Some(MeasuredOrientation::from_name(name).ok_or_else(|| {
            ApiError::invalid(format!(
                "`orientation` must be one of {}, got `{name}`",
                MeasuredOrientation::names()
            ))
        })?),
    };
    Ok(ReadOptions {
        dif,
        dialect: super::solve::dialect(q.decimal.as_deref())?,
        metres: c.length == Length::M,
        radians: c.angle == Angle::Rad,
        orientation,
    })
}

/// The upload's body as a service command: a CSV with its query options, or
/// JSON rows with their metadata in the body (422 naming what is wrong).
fn upload_command(
    robot_id: i64,
    query: &SetParams,
    is_csv: bool,
    text: String,
) -> Result<NewSetCommand, ApiError> {
    let (c, content) = if is_csv {
        let c = check_params(query)?;
        let read = read_options(query, &c)?;
        (c, SetContent::Csv { text, read })
    } else {
        let up: JsonUpload = from_json_object(text.as_bytes())?;
        let c = check_params(&up.params(query))?;
        let rows = json_rows(up.rows, &c)?;
        let original = text;
        (c, SetContent::Rows { rows, original })
    };
    Ok(NewSetCommand {
        robot_id,
        name: c.name,
        role: c.role,
        session: c.session,
        payload_kg: c.payload_kg,
        length: c.length,
        angle: c.angle,
        content,
    })
}

/// Whether the upload is a CSV (else JSON rows); 415 for other media types.
fn upload_is_csv(headers: &HeaderMap) -> Result<bool, ApiError> {
    let ct = content_type(headers);
    let is_csv = ct == "text/csv";
    let is_json = json_content_type(headers);
    if !is_csv && !is_json {
        let not = if ct.is_empty() {
            String::new()
        } else {
            format!(", not `{ct}`")
        };
        return Err(ApiError::UnsupportedMediaType(format!(
            "upload the measurement CSV as `Content-Type: text/csv` or rows as `application/json`{not}"
        )));
    }
    Ok(is_csv)
}

/// `POST /v1/robots/{id}/measurement-sets`: stores a JSON or CSV upload (201, `Location` the set).
pub async fn upload(
    State(state): State<AppState>,
    ApiPath(robot_id): ApiPath<i64>,
    ApiQuery(query): ApiQuery<SetParams>,
    headers: HeaderMap,
    body: Result<Bytes, BytesRejection>,
) -> Result<Response, ApiError> {
    let is_csv = upload_is_csv(&headers)?;
    let text = String::from_utf8(body?.to_vec())
        .map_err(|_| ApiError::invalid("the upload is not UTF-8 text"))?;
    let cmd = upload_command(robot_id, &query, is_csv, text)?;
    let row = service::sets::upload(&state, cmd).await?;
    let location = format!("/v1/robots/{robot_id}/measurement-sets/{}", row.id);
    Ok(super::located(
        StatusCode::CREATED,
        location,
        MeasurementSet::from_row(row, None),
    ))
}

/// `GET /v1/robots/{id}/measurement-sets`: one page of the robot's sets, without rows.
pub async fn list(
    State(state): State<AppState>,
    ApiPath(robot_id): ApiPath<i64>,
    ApiQuery(page): ApiQuery<PageQuery>,
) -> Result<Response, ApiError> {
    let (page, _) = robot_list_page(&state, robot_id, page).await?;
    let listing = service::sets::page(&state, robot_id, page.limit, page.offset).await?;
    let total = listing.total;
    let sets: Vec<MeasurementSet> = listing
        .rows
        .into_iter()
        .map(|r| MeasurementSet::from_row(r, None))
        .collect();
    Ok(axum::Json(page_body(page, total, "measurement_sets", sets)?).into_response())
}

/// `GET /v1/robots/{id}/measurement-sets/{sid}`: one set with its rows in mm and degrees.
pub async fn get_one(
    State(state): State<AppState>,
    ApiPath((robot_id, set_id)): ApiPath<(i64, i64)>,
) -> Result<Response, ApiError> {
    let (row, rows) = service::sets::get(&state, robot_id, set_id).await?;
    Ok(axum::Json(MeasurementSet::from_row(row, Some(rows))).into_response())
}

/// `GET /v1/robots/{id}/measurement-sets/{sid}/original`: the upload as it came, with its content
/// type.
pub async fn original(
    State(state): State<AppState>,
    ApiPath((robot_id, set_id)): ApiPath<(i64, i64)>,
) -> Result<Response, ApiError> {
    let (format, text) = service::sets::original(&state, robot_id, set_id).await?;
    let ct = if format == SetFormat::Csv {
        "text/csv; charset=utf-8"
    } else {
        "application/json"
    };
    Ok(([(header::CONTENT_TYPE, ct)], text).into_response())
}

/// `DELETE /v1/robots/{id}/measurement-sets/{sid}`: deletes the set (204).
pub async fn delete(
    State(state): State<AppState>,
    ApiPath((robot_id, set_id)): ApiPath<(i64, i64)>,
) -> Result<Response, ApiError> {
    service::sets::delete(&state, robot_id, set_id).await?;
    Ok(StatusCode::NO_CONTENT.into_response())
}

/// The routes of measurement sets.
pub fn routes() -> Vec<super::Route> {
    use super::{get, post};
    const SETS: &str = "/v1/robots/{id}/measurement-sets";
    const SET: &str = "/v1/robots/{id}/measurement-sets/{sid}";
    vec![
        get(SETS, list),
        post(SETS, upload),
        get(SET, get_one),
        super::delete(SET, delete),
        get("/v1/robots/{id}/measurement-sets/{sid}/original", original),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A value within a declared bound converts (as `json_rows` converts it)
    /// into a value within the stored bound, at both ends and in every unit,
    /// so the service's check on the stored rows never refuses what the
    /// handler and `openapi.yaml` accept; and the declared bounds are the
    /// numbers the spec states.
    #[test]
    fn declared_bounds_convert_into_the_stored_ones() {
        for length in [Length::Mm, Length::M] {
            for angle in [Angle::Deg, Angle::Rad] {
                let b = RowBounds::of(length, angle);
                let len = |v: f64| if length == Length::M { v * 1e3 } else { v };
                let ang = |v: f64| {
                    if angle == Angle::Rad {
                        v.to_degrees()
                    } else {
                        v
                    }
                };
                for (declared, stored, convert) in [
                    (b.joint, bounds::JOINT_DEG, &ang as &dyn Fn(f64) -> f64),
                    (b.position, bounds::POSITION_MM, &len),
                    (b.angle, bounds::ANGLE_DEG, &ang),
                    (b.std_position, bounds::STD_MM, &len),
                    (b.std_angle, bounds::STD_DEG, &ang),
                ] {
                    for v in [declared.min, declared.max] {
                        assert!(
                            bounds::within(convert(v), &stored),
                            "{v} {} → {} {}",
                            declared.unit,
                            convert(v),
                            stored.unit
                        );
                    }
                }
            }
        }
        let si = RowBounds::of(Length::M, Angle::Rad);
        assert_eq!((si.std_position.min, si.std_position.max), (1e-8, 1.0));
        assert_eq!(si.std_angle.max, std::f64::consts::PI);
        assert_eq!(si.angle.max, std::f64::consts::TAU);
        assert_eq!(si.joint.max, 12.566370614359172);
    }
}
