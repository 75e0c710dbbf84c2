//! Measurement-set uploads: reading a measurement CSV off the async runtime
//! (declared or detected delimiter and decimal separator, metres or radians
//! converted to mm and degrees, the sign of the real-data `dif` columns),
//! the checks that need the robot (joint count) or the service (rows per set),
//! the set's role and name, and storing it with the upload kept verbatim.
//!
//! Units: rows are stored in mm and degrees (`MeasuredPose`), whatever the
//! upload declared.

use super::{AppState, ServiceError};
use crate::db::{Listing, NewSet};
use crate::measure::csv::{self, CsvError, ReadOptions};
use crate::measure::{MeasuredPose, SetRole};
use crate::records::{AngleUnit, LengthUnit, SetFormat, SetRow};

/// What the upload carries.
#[derive(Debug, Clone)]
pub enum SetContent {
    /// A measurement CSV, read as `read` says (its units must agree with the
    /// command's `length` and `angle`).
    Csv {
        /// The CSV text as uploaded.
        text: String,
        /// How to read it: `*_dif` sign, delimiter and decimal mark, units, orientation convention.
        read: ReadOptions,
    },
    /// Rows already in mm and degrees, with the original JSON text.
    Rows {
        /// The rows in mm and degrees.
        rows: Vec<MeasuredPose>,
        /// The JSON upload as received.
        original: String,
    },
}

/// A measurement-set upload, in domain terms.
#[derive(Debug, Clone)]
pub struct NewSetCommand {
    /// The robot the set belongs to.
    pub robot_id: i64,
    /// Set name (empty: the role's name).
    pub name: String,
    /// Declared role; `None`: the rows' common `set` value, else identification.
    pub role: Option<SetRole>,
    /// The tracker session it was measured in.
    pub session: String,
    /// Payload of rows that carry none [kg].
    pub payload_kg: Option<f64>,
    /// The length unit the upload declared (stored rows are in mm).
    pub length: LengthUnit,
    /// The angle unit the upload declared (stored rows are in degrees).
    pub angle: AngleUnit,
    /// The upload's text or rows.
    pub content: SetContent,
}

pub(super) fn csv_error(e: CsvError) -> ServiceError {
    let hint = match e {
        CsvError::PositionUnits => "; if the file is in metres, upload it with ?length_unit=m",
        CsvError::ExternalNotComposed { .. } => {
            "; over HTTP, a robot on a track read at several track values is uploaded to POST /v1/robots/{id}/track/measurement-sets, one set per station"
        }
        _ => "",
    };
    ServiceError::Invalid(format!("measurement CSV: {e}{hint}"))
}

/// Reads a CSV upload; a set is one tracker session, so a `session` column
/// must agree with the set's.
fn read_csv(
    text: &str,
    read: &ReadOptions,
    session: &str,
) -> Result<Vec<MeasuredPose>, ServiceError> {
    let rows = csv::parse_opts(text, read).map_err(csv_error)?;
    if let Some((i, s)) = rows
        .iter()
        .enumerate()
        .find_map(|(i, r)| r.session.as_ref().filter(|s| *s != session).map(|s| (i, s)))
    {
        return Err(ServiceError::Invalid(format!(
            "row {}: the `session` column says `{s}` but this set's session is `{session}`; upload each tracker session as its own set (`?session=`)",
            i + 1
        )));
    }
    Ok(rows)
}

/// The checks that need the robot and the service's limits, and every
/// row's bounds as it will be stored (`MeasuredPose::check_bounds`, after any
/// unit conversion: the readers check them first, naming line or row; this
/// is what keeps a record that could not be read back out of the store).
/// Rows whose joint count is not the robot's conflict with the robot.
pub(super) fn check_rows(
    rows: &[MeasuredPose],
    dof: usize,
    max_rows: usize,
) -> Result<(), ServiceError> {
    if rows.len() > max_rows {
        return Err(ServiceError::Invalid(format!(
            "{} rows in one set; at most {max_rows} (`--max-poses-per-set`): split the upload",
            rows.len()
        )));
    }
    csv::check_joint_count(rows, dof).map_err(|e| {
        ServiceError::Conflict(format!("{e} (the robot has {dof} joints: send q1..q{dof})"))
    })?;
    for (i, r) in rows.iter().enumerate() {
        r.check_bounds().map_err(|e| {
            ServiceError::Invalid(format!("row {}: {e} (as stored, in mm and degrees)", i + 1))
        })?;
    }
    Ok(())
}

/// Refuses an upload holding NUL: text columns hold none on PostgreSQL, and
/// SQLite refuses it alike.
pub(super) fn refuse_nul(text: &str) -> Result<(), ServiceError> {
    if text.contains('\0') {
        return Err(ServiceError::Invalid(
            "the upload contains the NUL character (U+0000); measurement files are text".into(),
        ));
    }
    Ok(())
}

/// A set's role: `declared`, else the rows' common `set` value, else
/// identification.
pub(super) fn role_of(declared: Option<SetRole>, rows: &[MeasuredPose]) -> SetRole {
    declared.unwrap_or_else(|| match rows.first().and_then(|r| r.set) {
        Some(r) if rows.iter().all(|x| x.set == Some(r)) => r,
        _ => SetRole::Identification,
    })
}

/// Reads, checks and stores a measurement set.
pub async fn upload(state: &AppState, cmd: NewSetCommand) -> Result<SetRow, ServiceError> {
    let robot_id = cmd.robot_id;
    let robot = state
        .db()
        .robot(robot_id)
        .await?
        .ok_or_else(|| ServiceError::robot_not_found(robot_id))?;
    let dof = robot.dof as usize;
    let max_rows = state.limits().poses_per_set;
    let session = cmd.session.clone();
    let (rows, format, original) = tokio::task::spawn_blocking(move || {
        let (rows, format, original) = match cmd.content {
            SetContent::Csv { text, read } => {
                refuse_nul(&text)?;
                (read_csv(&text, &read, &session)?, SetFormat::Csv, text)
            }
            SetContent::Rows { rows, original } => (rows, SetFormat::Json, original),
        };
        check_rows(&rows, dof, max_rows)?;
        Ok::<_, ServiceError>((rows, format, original))
    })
    .await
    .map_err(|e| ServiceError::Internal(format!("upload parser: {e}")))??;

    let role = role_of(cmd.role, &rows);
    let name = if cmd.name.is_empty() {
        role.as_str().to_string()
    } else {
        cmd.name
    };
    state
        .db()
        .insert_set(&NewSet {
            robot_id,
            name: &name,
            role: role.into(),
            session: &cmd.session,
            payload_kg: cmd.payload_kg,
            length_unit: cmd.length,
            angle_unit: cmd.angle,
            format,
            original: &original,
            rows: &rows,
            row_count: rows.len() as i64,
            dof: dof as i64,
            axis: None,
        })
        .await?
        .ok_or_else(|| ServiceError::robot_not_found(robot_id))
}

/// One page of a robot's sets by id (the robot must exist).
pub async fn page(
    state: &AppState,
    robot_id: i64,
    limit: i64,
    offset: i64,
) -> Result<Listing<SetRow>, ServiceError> {
    Ok(state.db().sets_page(robot_id, limit, offset).await?)
}

/// Every set of a robot by id.
pub async fn list(state: &AppState, robot_id: i64) -> Result<Vec<SetRow>, ServiceError> {
    Ok(state.db().sets(robot_id).await?)
}

/// A set and its parsed rows (mm/deg).
pub async fn get(
    state: &AppState,
    robot_id: i64,
    id: i64,
) -> Result<(SetRow, Vec<MeasuredPose>), ServiceError> {
    let missing = || ServiceError::set_not_found(robot_id, id);
    let row = state.db().set(robot_id, id).await?.ok_or_else(missing)?;
    let rows = state
        .db()
        .set_rows(robot_id, id)
        .await?
        .ok_or_else(missing)?;
    Ok((row, rows))
}

/// The upload of a set as received: its format and text.
pub async fn original(
    state: &AppState,
    robot_id: i64,
    id: i64,
) -> Result<(SetFormat, String), ServiceError> {
    state
        .db()
        .set_original(robot_id, id)
        .await?
        .ok_or_else(|| ServiceError::set_not_found(robot_id, id))
}

/// Deletes a set no version and no pending calibration uses (409 naming them otherwise).
pub async fn delete(state: &AppState, robot_id: i64, id: i64) -> Result<(), ServiceError> {
    match state.db().delete_unused_set(robot_id, id).await? {
        crate::db::SetDeletion::Deleted => Ok(()),
        crate::db::SetDeletion::NotFound => Err(ServiceError::set_not_found(robot_id, id)),
        crate::db::SetDeletion::InUse { versions, jobs } => {
            Err(ServiceError::Conflict(set_in_use(id, &versions, &jobs)))
        }
    }
}

/// Why a set in use is kept.
fn set_in_use(id: i64, versions: &[i64], jobs: &[i64]) -> String {
    let list = |v: &[i64]| v.iter().map(i64::to_string).collect::<Vec<_>>().join(", ");
    let mut users = Vec::new();
    if !versions.is_empty() {
        users.push(format!(
            "model version(s) {} were fitted, validated or re-registered on it",
            list(versions)
        ));
    }
    if !jobs.is_empty() {
        users.push(format!("calibration job(s) {} will read it", list(jobs)));
    }
    format!(
        "measurement set {id} is part of the calibration record and is kept: {}",
        users.join("; ")
    )
}
