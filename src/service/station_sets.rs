//! A robot on a linear track measured at several track values, uploaded as
//! one measurement CSV with the track's column and stored as one set per
//! value (station): at one track value the base stands still in the
//! tracker's frame, so each station is a tracker session of its own
//! (`MeasurementSet::stations_as_sessions`, the command line's `calibrate
//! --track-column`), and a calibration over the station sets identifies the
//! robot over every station.
//!
//! Each station's set keeps, as its original, the upload's lines up to its
//! header and the lines of its own rows, verbatim; the stations' originals
//! together hold every line of the upload once. Each names the track's
//! column and its value there, so the track can be fitted from the stored
//! sets (`super::tracks`). Every station is checked
//! before any is stored, and they are stored in one transaction.

use super::sets::{check_rows, csv_error, refuse_nul, role_of};
use super::{AppState, ServiceError};
use crate::db::NewSet;
use crate::measure::csv::{self, ReadOptions};
use crate::measure::csv_text;
use crate::measure::external::{
    session_before_station, ExternalAxis, ExternalValues, MeasurementSet,
};
use crate::measure::{MeasuredPose, SetRole};
use crate::records::{AngleUnit, LengthUnit, SetFormat, SetRow};
use crate::service::limits::{MAX_SETS, NAME_MAX};

/// One station of an upload: its session, rows and lines.
#[derive(Debug, Clone, PartialEq)]
pub struct Station {
    /// The tracker session, `e1=400` (after the upload's session when given).
    pub session: String,
    /// The track's value at every row of the station [mm], as the file gave it.
    pub value: f64,
    /// Its rows (mm, deg).
    pub rows: Vec<MeasuredPose>,
    /// The upload's lines up to its header, then its rows' lines, verbatim.
    pub original: String,
}

/// Splits a measurement CSV with the track's `column` into its stations in
/// order of first appearance; `session`, when given, goes before each
/// station's label (and a `session` column must agree with it).
pub fn stations_of(
    text: &str,
    read: &ReadOptions,
    column: ExternalAxis,
    session: Option<&str>,
) -> Result<Vec<Station>, ServiceError> {
    let mut set = csv::parse_set_opts(text, read).map_err(csv_error)?;
    for (i, r) in set.poses.iter_mut().enumerate() {
        match (&r.session, session) {
            (Some(s), Some(given)) if s != given => {
                return Err(ServiceError::Invalid(format!(
                    "row {}: the `session` column says `{s}` but the upload's session is `{given}`",
                    i + 1
                )))
            }
            (None, Some(given)) => r.session = Some(given.to_string()),
            _ => {}
        }
    }
    let rows = set
        .stations_as_sessions(column)
        .map_err(|e| ServiceError::Invalid(format!("measurement CSV: {e}")))?;
    let values: Vec<f64> = set
        .external
        .iter()
        .map(|e| e.get(column).expect("every reading carries the set's axes"))
        .collect();
    let table = csv_text::read(text, read.dialect)
        .map_err(|e| ServiceError::Invalid(format!("measurement CSV: {e}")))?
        .ok_or_else(|| ServiceError::Invalid("measurement CSV: empty".into()))?;
    let lines: Vec<&str> = text
        .strip_prefix('\u{feff}')
        .unwrap_or(text)
        .split_inclusive('\n')
        .collect();
    let head: String = lines[..table.header_line.min(lines.len())].concat();
    let mut stations: Vec<Station> = Vec::new();
    for (k, row) in rows.into_iter().enumerate() {
        let start = table.records[k].line - 1;
        let end = table
            .records
            .get(k + 1)
            .map_or(lines.len(), |r| r.line - 1)
            .min(lines.len());
        let label = row
            .session
            .clone()
            .expect("every station row has a session");
        let i = match stations.iter().position(|s| s.session == label) {
            Some(i) => i,
            None => {
                stations.push(Station {
                    session: label,
                    value: values[k],
                    rows: Vec::new(),
                    original: head.clone(),
                });
                stations.len() - 1
            }
        };
        stations[i].rows.push(row);
        stations[i].original.push_str(&lines[start..end].concat());
    }
    if stations.len() > MAX_SETS {
        return Err(ServiceError::Invalid(format!(
            "{} track values in one upload; at most {MAX_SETS} (a calibration takes at most {MAX_SETS} sets of a role)",
            stations.len()
        )));
    }
    Ok(stations)
}

/// A track's measurement upload, in domain terms.
#[derive(Debug, Clone)]
pub struct StationUpload {
    /// The robot the sets belong to.
    pub robot_id: i64,
    /// Goes before each set's session in its name (empty: the role's name).
    pub name: String,
    /// Declared role of every set; `None`: each station's rows' common `set`,
    /// else identification.
    pub role: Option<SetRole>,
    /// Goes before each station's session label, when given.
    pub session: Option<String>,
    /// Payload of rows that carry none [kg].
    pub payload_kg: Option<f64>,
    /// The track's column.
    pub column: ExternalAxis,
    /// The CSV text as uploaded.
    pub text: String,
    /// How to read it (millimetres and degrees: the external-axis columns
    /// are read as written).
    pub read: ReadOptions,
}

/// Reads, checks and stores a track's measurement CSV as one set per
/// station (module docs); the sets in order of first appearance.
pub async fn upload(state: &AppState, cmd: StationUpload) -> Result<Vec<SetRow>, ServiceError> {
    let robot_id = cmd.robot_id;
    let robot = state
        .db()
        .robot(robot_id)
        .await?
        .ok_or_else(|| ServiceError::robot_not_found(robot_id))?;
    let dof = robot.dof as usize;
    let max_rows = state.limits().poses_per_set;
    refuse_nul(&cmd.text)?;
    let (text, read, column, session) = (cmd.text, cmd.read, cmd.column, cmd.session);
    let stations = tokio::task::spawn_blocking(move || {
        let stations = stations_of(&text, &read, column, session.as_deref())?;
        for s in &stations {
            check_rows(&s.rows, dof, max_rows).map_err(|e| at_station(e, &s.session))?;
        }
        Ok::<_, ServiceError>(stations)
    })
    .await
    .map_err(|e| ServiceError::Internal(format!("upload parser: {e}")))??;

    let names: Vec<(String, SetRole)> = stations
        .iter()
        .map(|s| {
            let role = role_of(cmd.role, &s.rows);
            let base = if cmd.name.is_empty() {
                role.as_str()
            } else {
                cmd.name.as_str()
            };
            (format!("{base} {}", s.session), role)
        })
        .collect();
    for (name, _) in &names {
        if name.chars().count() > NAME_MAX {
            return Err(ServiceError::Invalid(format!(
                "the station set's name `{name}` is longer than {NAME_MAX} characters: give a shorter `name` or `session`"
            )));
        }
    }
    let sets: Vec<NewSet> = stations
        .iter()
        .zip(&names)
        .map(|(s, (name, role))| NewSet {
            robot_id,
            name,
            role: (*role).into(),
            session: &s.session,
            payload_kg: cmd.payload_kg,
            length_unit: LengthUnit::Mm,
            angle_unit: AngleUnit::Deg,
            format: SetFormat::Csv,
            original: &s.original,
            rows: &s.rows,
            row_count: s.rows.len() as i64,
            dof: dof as i64,
            axis: Some((column.column(), s.value)),
        })
        .collect();
    state
        .db()
        .insert_sets(robot_id, &sets)
        .await?
        .ok_or_else(|| ServiceError::robot_not_found(robot_id))
}

/// The readings of the robot's stored station sets `ids`, in the order
/// given, as the measurement file they were uploaded in reads (each row's
/// value in the track's `column`, its session as the file gave it, the
/// set's payload on rows without their own): a track is fitted from them
/// as from that file. Refused: an id given twice, a set that is not a
/// station set of `column` (`Invalid`, naming it), one the robot does not
/// have (`Conflict`), more than `max_readings` rows together.
pub async fn track_readings(
    state: &AppState,
    robot_id: i64,
    ids: &[i64],
    column: ExternalAxis,
    max_readings: usize,
) -> Result<MeasurementSet, ServiceError> {
    if ids.is_empty() || ids.len() > MAX_SETS {
        return Err(ServiceError::Invalid(format!(
            "`set_ids`: 1 to {MAX_SETS} station sets, got {}",
            ids.len()
        )));
    }
    if let Some(i) = (1..ids.len()).find(|&i| ids[..i].contains(&ids[i])) {
        return Err(ServiceError::Invalid(format!(
            "`set_ids`: set {} is given twice",
            ids[i]
        )));
    }
    super::robots::get(state, robot_id).await?;
    let mut set = MeasurementSet {
        axes: vec![column],
        ..MeasurementSet::default()
    };
    for &id in ids {
        // A set the body names that the robot lacks is the robot's state
        // (409), as for a check's or a calibration's sets; 404 is the path's.
        let missing = || super::checks::conflict(ServiceError::set_not_found(robot_id, id));
        let row = state.db().set(robot_id, id).await?.ok_or_else(missing)?;
        let value = match (row.axis_column.as_deref(), row.axis_value) {
            (Some(c), Some(v)) if c == column.column() => v,
            (Some(c), Some(_)) => {
                return Err(ServiceError::Invalid(format!(
                    "measurement set {id} (`{}`) is a station of the track's `{c}`, not of `{column}`: give `column` `{c}`",
                    row.name
                )))
            }
            _ => {
                return Err(ServiceError::Invalid(format!(
                    "measurement set {id} (`{}`) holds no track value: only sets stored by POST /v1/robots/{robot_id}/track/measurement-sets do (since migrations sqlite/0016, postgres/0015); post the file as `csv`, or upload it there again",
                    row.name
                )))
            }
        };
        let rows = state
            .db()
            .set_rows(robot_id, id)
            .await?
            .ok_or_else(missing)?;
        for mut pose in rows {
            // The row's session as the file gave it, before the station's label.
            pose.session = pose
                .session
                .as_deref()
                .and_then(|s| session_before_station(s, column, value));
            pose.payload_kg = pose.payload_kg.or(row.payload_kg);
            let mut values = ExternalValues::default();
            values.0[column.index()] = Some(value);
            set.poses.push(pose);
            set.external.push(values);
        }
        if set.poses.len() > max_readings {
            return Err(ServiceError::Invalid(format!(
                "`set_ids`: more than {max_readings} readings in one fit"
            )));
        }
    }
    Ok(set)
}

/// A station's refusal, naming the station.
fn at_station(e: ServiceError, station: &str) -> ServiceError {
    match e {
        ServiceError::Invalid(m) => ServiceError::Invalid(format!("station `{station}`: {m}")),
        ServiceError::Conflict(m) => ServiceError::Conflict(format!("station `{station}`: {m}")),
        other => other,
    }
}
