//! `/v1/robots/{id}/measurement-sets`: upload (JSON rows or the measurement CSV
//! of DESIGN as `text/csv`), list, get (rows read back bit for bit), the
//! original upload, delete.
//!
//! Declared units (`length_unit` mm|m, `angle_unit` deg|rad) convert the rows to
//! millimetres and degrees when they are stored; the upload itself is kept
//! verbatim and served by `GET .../original`.

use super::input::{
    check_name, check_payload, from_json_object, objects, page_fields, present, PageQuery,
};
use super::robots::robot_not_found;
use super::{ApiError, ApiPath, ApiQuery, AppState};
use crate::db::{AngleUnit, LengthUnit, NewSet, SetFormat, SetRow};
use crate::measure::csv::{self, CsvError};
use crate::measure::{MeasuredPose, SetRole};
use axum::body::Bytes;
use axum::extract::rejection::BytesRejection;
use axum::extract::State;
use axum::http::{header, HeaderMap, StatusCode};
use axum::response::{IntoResponse, Response};
use serde::{Deserialize, Serialize};

/// Most sets one calibration may use.
pub const MAX_SETS: usize = 100;

/// Largest joint reading accepted, in degrees (as the CSV parser).
const MAX_JOINT_DEG: f64 = 720.0;

pub(crate) fn set_not_found(robot: i64, id: i64) -> ApiError {
    ApiError::NotFound(format!(
        "measurement set {id} of robot {robot} does not exist; list them with GET /v1/robots/{robot}/measurement-sets"
    ))
}

/// Metadata of an upload: query parameters for CSV, body fields for JSON.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SetParams {
    pub name: Option<String>,
    pub role: Option<String>,
    pub session: Option<String>,
    pub payload_kg: Option<f64>,
    pub length_unit: Option<String>,
    pub angle_unit: Option<String>,
}

/// One row of a JSON upload, in the declared units.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RowInput {
    #[serde(alias = "q_deg")]
    pub q: Vec<f64>,
    #[serde(alias = "xyz_mm")]
    pub xyz: [f64; 3],
    #[serde(default, alias = "rpy_deg")]
    pub rpy: Option<[f64; 3]>,
    #[serde(default)]
    pub payload_kg: Option<f64>,
    #[serde(default)]
    pub temperature_c: Option<f64>,
    #[serde(default)]
    pub set: Option<SetRole>,
}

/// A JSON upload (optional fields may be left out, not `null`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JsonUpload {
    #[serde(default, deserialize_with = "present")]
    pub name: Option<String>,
    #[serde(default, deserialize_with = "present")]
    pub role: Option<String>,
    #[serde(default, deserialize_with = "present")]
    pub session: Option<String>,
    #[serde(default, deserialize_with = "present")]
    pub payload_kg: Option<f64>,
    #[serde(default, deserialize_with = "present")]
    pub length_unit: Option<String>,
    #[serde(default, deserialize_with = "present")]
    pub angle_unit: Option<String>,
    #[serde(deserialize_with = "objects")]
    pub rows: Vec<RowInput>,
}

impl JsonUpload {
    fn params(&self) -> SetParams {
        SetParams {
            name: self.name.clone(),
            role: self.role.clone(),
            session: self.session.clone(),
            payload_kg: self.payload_kg,
            length_unit: self.length_unit.clone(),
            angle_unit: self.angle_unit.clone(),
        }
    }
}

#[derive(Debug, Serialize)]
pub struct Units {
    pub length: String,
    pub angle: String,
}

/// A measurement set as the API returns it.
#[derive(Debug, Serialize)]
pub struct MeasurementSet {
    pub id: i64,
    pub robot_id: i64,
    pub name: String,
    pub role: String,
    pub session: String,
    pub payload_kg: Option<f64>,
    pub units: Units,
    pub format: String,
    pub row_count: i64,
    pub dof: i64,
    pub created_at: String,
    /// The rows in mm/deg (single-set responses only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rows: Option<Vec<MeasuredPose>>,
}

impl MeasurementSet {
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
            rows,
        }
    }
}

type Length = LengthUnit;
type Angle = AngleUnit;

struct Checked {
    name: String,
    role: Option<SetRole>,
    session: String,
    payload_kg: Option<f64>,
    length: Length,
    angle: Angle,
}

fn check_params(p: &SetParams) -> Result<Checked, ApiError> {
    let role = p
        .role
        .as_deref()
        .map(|r| {
            SetRole::parse(r).ok_or_else(|| {
                ApiError::invalid(format!(
                    "`role` must be identification, training or validation, got `{r}`"
                ))
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

/// Position columns of both CSV layouts.
const POSITION_COLUMNS: [&str; 9] = [
    "x", "y", "z", "x_t", "y_t", "z_t", "x_dif", "y_dif", "z_dif",
];

/// Scales the position columns of a CSV text (metres → millimetres) before it
/// is parsed; fields that are not numbers are left for the parser to report.
fn scale_csv_positions(text: &str, factor: f64) -> String {
    let mut out = String::with_capacity(text.len() + text.len() / 4);
    let mut cols: Option<Vec<bool>> = None;
    for line in text.lines() {
        let t = line.trim();
        if t.is_empty() || t.starts_with('#') {
            out.push_str(line);
            out.push('\n');
            continue;
        }
        match &cols {
            None => {
                cols = Some(
                    t.trim_start_matches('\u{feff}')
                        .split(',')
                        .map(|c| {
                            let c = c.trim().trim_matches('"').trim().to_ascii_lowercase();
                            POSITION_COLUMNS.contains(&c.as_str())
                        })
                        .collect(),
                );
                out.push_str(line);
            }
            Some(scale) => {
                let fields: Vec<String> = t
                    .split(',')
                    .enumerate()
                    .map(|(i, f)| {
                        let v = f.trim().trim_matches('"').trim();
                        match (scale.get(i), v.parse::<f64>()) {
                            (Some(true), Ok(x)) if x.is_finite() => (x * factor).to_string(),
                            _ => f.to_string(),
                        }
                    })
                    .collect();
                out.push_str(&fields.join(","));
            }
        }
        out.push('\n');
    }
    out
}

fn csv_error(e: CsvError) -> ApiError {
    let hint = match e {
        CsvError::PositionUnits => "; if the file is in metres, upload it with ?length_unit=m",
        _ => "",
    };
    ApiError::invalid(format!("measurement CSV: {e}{hint}"))
}

/// Converts angles to degrees in place.
fn to_degrees(rows: &mut [MeasuredPose]) {
    for r in rows {
        for q in r.q_deg.iter_mut() {
            *q = q.to_degrees();
        }
        if let Some(rpy) = r.rpy_deg.as_mut() {
            for a in rpy.iter_mut() {
                *a = a.to_degrees();
            }
        }
    }
}

fn json_rows(rows: Vec<RowInput>, c: &Checked) -> Result<Vec<MeasuredPose>, ApiError> {
    if rows.is_empty() {
        return Err(ApiError::invalid(
            "`rows` is empty: upload at least one measured pose",
        ));
    }
    let lf = if c.length == Length::M { 1e3 } else { 1.0 };
    let mut out = Vec::with_capacity(rows.len());
    for (i, r) in rows.into_iter().enumerate() {
        let n = i + 1;
        let bad = |what: &str| ApiError::invalid(format!("row {n}: {what} must be finite numbers"));
        if r.q.iter().any(|v| !v.is_finite()) {
            return Err(bad("joint values `q`"));
        }
        if r.xyz.iter().any(|v| !v.is_finite()) {
            return Err(bad("position `xyz`"));
        }
        if r.rpy.is_some_and(|a| a.iter().any(|v| !v.is_finite())) {
            return Err(bad("orientation `rpy`"));
        }
        if let Some(p) = r.payload_kg {
            check_payload(&format!("row {n}: `payload_kg`"), p)?;
        }
        if r.temperature_c.is_some_and(|t| !t.is_finite()) {
            return Err(bad("`temperature_c`"));
        }
        out.push(MeasuredPose {
            q_deg: r.q,
            xyz_mm: r.xyz.map(|v| v * lf),
            rpy_deg: r.rpy,
            payload_kg: r.payload_kg,
            temperature_c: r.temperature_c,
            set: r.set,
            session: None,
        });
    }
    if c.angle == Angle::Rad {
        to_degrees(&mut out);
    }
    // The same bounds as the measurement CSV (after unit conversion).
    for (i, r) in out.iter().enumerate() {
        let n = i + 1;
        if let Some(q) = r.q_deg.iter().find(|q| q.abs() > csv::MAX_JOINT_DEG) {
            return Err(ApiError::invalid(format!(
                "row {n}: joint value {q:.4e} deg is beyond ±{} deg: wrong units (encoder counts, or radians declared as degrees)?",
                csv::MAX_JOINT_DEG
            )));
        }
        if let Some(x) = r.xyz_mm.iter().find(|x| x.abs() > csv::MAX_POSITION_MM) {
            return Err(ApiError::invalid(format!(
                "row {n}: position coordinate {x:.4e} mm is beyond ±{} m of the tracker",
                csv::MAX_POSITION_MM / 1e3
            )));
        }
    }
    if out
        .iter()
        .all(|r| r.xyz_mm.iter().all(|v| v.abs() < csv::METRES_SUSPECT_MM))
    {
        return Err(ApiError::invalid(format!(
            "every position coordinate is within ±{} mm: looks like metres; declare \"length_unit\": \"m\" or send millimetres",
            csv::METRES_SUSPECT_MM
        )));
    }
    Ok(out)
}

fn check_rows(rows: &[MeasuredPose], dof: usize, max_rows: usize) -> Result<(), ApiError> {
    if rows.len() > max_rows {
        return Err(ApiError::invalid(format!(
            "{} rows in one set; at most {max_rows} (`--max-poses-per-set`): split the upload",
            rows.len()
        )));
    }
    csv::check_joint_count(rows, dof).map_err(|e| {
        ApiError::invalid(format!("{e} (the robot has {dof} joints: send q1..q{dof})"))
    })?;
    for (i, r) in rows.iter().enumerate() {
        if let Some(p) = r.payload_kg {
            check_payload(&format!("row {}: `payload_kg`", i + 1), p)?;
        }
        if let Some((k, v)) = r
            .q_deg
            .iter()
            .enumerate()
            .find(|(_, v)| v.abs() > MAX_JOINT_DEG)
        {
            return Err(ApiError::invalid(format!(
                "row {}: joint q{} = {v} deg is beyond ±{MAX_JOINT_DEG} deg; check the angle unit",
                i + 1,
                k + 1
            )));
        }
    }
    Ok(())
}

fn content_type(headers: &HeaderMap) -> String {
    headers
        .get(header::CONTENT_TYPE)
        .and_then(|v| v.to_str().ok())
        .map(|v| {
            v.split(';')
                .next()
                .unwrap_or("")
                .trim()
                .to_ascii_lowercase()
        })
        .unwrap_or_default()
}

pub async fn upload(
    State(state): State<AppState>,
    ApiPath(robot_id): ApiPath<i64>,
    ApiQuery(query): ApiQuery<SetParams>,
    headers: HeaderMap,
    body: Result<Bytes, BytesRejection>,
) -> Result<Response, ApiError> {
    let ct = content_type(&headers);
    let is_csv = matches!(ct.as_str(), "text/csv" | "application/csv" | "text/plain");
    let is_json = ct == "application/json" || ct.ends_with("+json");
    if !is_csv && !is_json {
        return Err(ApiError::UnsupportedMediaType(format!(
            "upload the measurement CSV as `Content-Type: text/csv` or rows as `application/json`{}",
            if ct.is_empty() {
                String::new()
            } else {
                format!(", not `{ct}`")
            }
        )));
    }
    let body = body?;
    let robot = state
        .db()
        .robot(robot_id)
        .await?
        .ok_or_else(|| robot_not_found(robot_id))?;
    let dof = robot.dof as usize;
    let max_rows = state.limits().poses_per_set;
    let text = String::from_utf8(body.to_vec())
        .map_err(|_| ApiError::invalid("the upload is not UTF-8 text"))?;

    let parsed = tokio::task::spawn_blocking(move || -> Result<_, ApiError> {
        if is_csv {
            let c = check_params(&query)?;
            let mut rows = if c.length == Length::M {
                csv::parse(&scale_csv_positions(&text, 1e3)).map_err(csv_error)?
            } else {
                csv::parse(&text).map_err(csv_error)?
            };
            if c.angle == Angle::Rad {
                to_degrees(&mut rows);
            }
            // A set is one tracker session: a `session` column must agree.
            if let Some((i, s)) = rows
                .iter()
                .enumerate()
                .find_map(|(i, r)| r.session.as_ref().filter(|s| **s != c.session).map(|s| (i, s)))
            {
                return Err(ApiError::invalid(format!(
                    "row {}: the `session` column says `{s}` but this set's session is `{}`; upload each tracker session as its own set (`?session=`)",
                    i + 1,
                    c.session
                )));
            }
            check_rows(&rows, dof, max_rows)?;
            Ok((c, rows, SetFormat::Csv, text))
        } else {
            if query.name.is_some()
                || query.role.is_some()
                || query.session.is_some()
                || query.payload_kg.is_some()
                || query.length_unit.is_some()
                || query.angle_unit.is_some()
            {
                return Err(ApiError::invalid(
                    "for JSON uploads give name, role, session, payload_kg and units in the body, not the query string",
                ));
            }
            let up: JsonUpload = from_json_object(text.as_bytes())?;
            let c = check_params(&up.params())?;
            let rows = json_rows(up.rows, &c)?;
            check_rows(&rows, dof, max_rows)?;
            Ok((c, rows, SetFormat::Json, text))
        }
    })
    .await
    .map_err(|e| ApiError::Internal(format!("upload parser: {e}")))??;
    let (c, rows, format, original) = parsed;

    // Role: declared, else the rows' common `set` value, else identification.
    let role = c.role.unwrap_or_else(|| {
        let first = rows[0].set;
        match first {
            Some(r) if rows.iter().all(|x| x.set == Some(r)) => r,
            _ => SetRole::Identification,
        }
    });
    let name = if c.name.is_empty() {
        role.as_str().to_string()
    } else {
        c.name.clone()
    };
    let row = state
        .db()
        .insert_set(&NewSet {
            robot_id,
            name: &name,
            role: role.into(),
            session: &c.session,
            payload_kg: c.payload_kg,
            length_unit: c.length,
            angle_unit: c.angle,
            format,
            original: &original,
            rows: &rows,
            row_count: rows.len() as i64,
            dof: dof as i64,
        })
        .await?
        .ok_or_else(|| robot_not_found(robot_id))?;
    let location = format!("/v1/robots/{robot_id}/measurement-sets/{}", row.id);
    Ok((
        StatusCode::CREATED,
        [(header::LOCATION, location)],
        axum::Json(MeasurementSet::from_row(row, None)),
    )
        .into_response())
}

pub async fn list(
    State(state): State<AppState>,
    ApiPath(robot_id): ApiPath<i64>,
    ApiQuery(page): ApiQuery<PageQuery>,
) -> Result<Response, ApiError> {
    let page = page.check(state.limits().page_max)?;
    if state.db().robot(robot_id).await?.is_none() {
        return Err(robot_not_found(robot_id));
    }
    let (rows, total) = state
        .db()
        .sets_page(robot_id, page.limit, page.offset)
        .await?;
    let sets: Vec<MeasurementSet> = rows
        .into_iter()
        .map(|r| MeasurementSet::from_row(r, None))
        .collect();
    let mut out = page_fields(page, total);
    out["measurement_sets"] =
        serde_json::to_value(sets).map_err(|e| ApiError::Internal(e.to_string()))?;
    Ok(axum::Json(out).into_response())
}

/// Loads the parsed rows of a set.
pub(crate) async fn load_rows(
    state: &AppState,
    robot_id: i64,
    set_id: i64,
) -> Result<Vec<MeasuredPose>, ApiError> {
    state
        .db()
        .set_rows(robot_id, set_id)
        .await?
        .ok_or_else(|| set_not_found(robot_id, set_id))
}

pub async fn get_one(
    State(state): State<AppState>,
    ApiPath((robot_id, set_id)): ApiPath<(i64, i64)>,
) -> Result<Response, ApiError> {
    let row = state
        .db()
        .set(robot_id, set_id)
        .await?
        .ok_or_else(|| set_not_found(robot_id, set_id))?;
    let rows = load_rows(&state, robot_id, set_id).await?;
    Ok(axum::Json(MeasurementSet::from_row(row, Some(rows))).into_response())
}

pub async fn original(
    State(state): State<AppState>,
    ApiPath((robot_id, set_id)): ApiPath<(i64, i64)>,
) -> Result<Response, ApiError> {
    let (format, text) = state
        .db()
        .set_original(robot_id, set_id)
        .await?
        .ok_or_else(|| set_not_found(robot_id, set_id))?;
    let ct = if format == SetFormat::Csv {
        "text/csv; charset=utf-8"
    } else {
        "application/json"
    };
    Ok(([(header::CONTENT_TYPE, ct)], text).into_response())
}

pub async fn delete(
    State(state): State<AppState>,
    ApiPath((robot_id, set_id)): ApiPath<(i64, i64)>,
) -> Result<Response, ApiError> {
    if !state.db().delete_set(robot_id, set_id).await? {
        return Err(set_not_found(robot_id, set_id));
    }
    Ok(StatusCode::NO_CONTENT.into_response())
}

/// The routes of measurement sets.
pub fn routes() -> Vec<super::Route> {
    use super::route;
    use axum::http::Method;
    const SETS: &str = "/v1/robots/{id}/measurement-sets";
    vec![
        route(Method::GET, SETS, list),
        route(Method::POST, SETS, upload),
        route(
            Method::GET,
            "/v1/robots/{id}/measurement-sets/{sid}",
            get_one,
        ),
        route(
            Method::DELETE,
            "/v1/robots/{id}/measurement-sets/{sid}",
            delete,
        ),
        route(
            Method::GET,
            "/v1/robots/{id}/measurement-sets/{sid}/original",
            original,
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn metres_are_scaled_in_position_columns_only() {
        let t = "# c\nq1,q2,x,y,z\n1.5,2,1.25,-0.5,2\n";
        let s = scale_csv_positions(t, 1e3);
        assert_eq!(s, "# c\nq1,q2,x,y,z\n1.5,2,1250,-500,2000\n");
    }
}
