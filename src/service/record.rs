//! The calibration record: what a calibration was fitted and validated on,
//! so a report printed today still identifies it — the robocal version, the
//! robot, the job's dates, method and settings, the model versions it made,
//! and each measurement set with its row count and a SHA-256 of the upload
//! as received (sets a version uses cannot be deleted: `db::set_usage`).

use super::{calibrations, robots, AppState, ServiceError};
use serde::Serialize;
use serde_json::Value;
use sha2::{Digest, Sha256};

/// One set of the record.
#[derive(Debug, Clone, Serialize)]
pub struct RecordSet {
    /// The set's id.
    pub id: i64,
    /// `identification` or `validation`: how the calibration used it.
    pub used_as: &'static str,
    /// `None` when the set no longer exists (deleted before it was protected).
    pub name: Option<String>,
    /// Its number of rows; `None` when the set no longer exists.
    pub row_count: Option<i64>,
    /// SHA-256 of the upload as received (hex).
    pub sha256: Option<String>,
}

/// One version the calibration made.
#[derive(Debug, Clone, Serialize)]
pub struct RecordVersion {
    /// The version number.
    pub version: i64,
    /// Name of the method that fitted it.
    pub method: String,
    /// Whether it is the robot's active version now.
    pub active: bool,
}

/// The record of one calibration.
#[derive(Debug, Clone, Serialize)]
pub struct CalibrationRecord {
    /// The version of robocal that wrote the record.
    pub robocal_version: &'static str,
    /// The robot's id.
    pub robot_id: i64,
    /// The robot's name.
    pub robot_name: String,
    /// The calibration job's id.
    pub calibration_id: i64,
    /// The job's state: queued, running, succeeded, failed or cancelled.
    pub status: String,
    /// When the job was queued (UTC, RFC 3339).
    pub created_at: String,
    /// When it ended (UTC, RFC 3339).
    pub finished_at: Option<String>,
    /// Names of the methods it ran, in order.
    pub methods: Vec<String>,
    /// The request's settings (seed, population, register, ...).
    pub options: Value,
    /// The model versions it made.
    pub versions: Vec<RecordVersion>,
    /// The identification sets, then the validation sets it read.
    pub sets: Vec<RecordSet>,
}

/// The record of calibration `id` of robot `robot_id`.
pub async fn calibration_record(
    state: &AppState,
    robot_id: i64,
    id: i64,
) -> Result<CalibrationRecord, ServiceError> {
    let robot = robots::get(state, robot_id).await?;
    let job = calibrations::get(state, robot_id, id).await?;
    let versions = state
        .db()
        .versions(robot_id)
        .await?
        .into_iter()
        .filter(|v| v.calibration_id == Some(id))
        .map(|v| RecordVersion {
            version: v.version,
            method: v.method,
            active: v.active,
        })
        .collect();
    let mut sets = Vec::new();
    let roles = [
        ("identification", &job.identification_set_ids.0),
        ("validation", &job.validation_set_ids.0),
    ];
    for (used_as, ids) in roles {
        for &sid in ids.iter() {
            let row = state.db().set(robot_id, sid).await?;
            let original = state.db().set_original(robot_id, sid).await?;
            sets.push(RecordSet {
                id: sid,
                used_as,
                name: row.as_ref().map(|r| r.name.clone()),
                row_count: row.as_ref().map(|r| r.row_count),
                sha256: original.map(|(_, text)| hex(&Sha256::digest(text.as_bytes()))),
            });
        }
    }
    Ok(CalibrationRecord {
        robocal_version: env!("CARGO_PKG_VERSION"),
        robot_id,
        robot_name: robot.name,
        calibration_id: id,
        status: job.status.to_string(),
        created_at: job.created_at,
        finished_at: job.finished_at,
        methods: job.methods.0,
        options: job.options.0,
        versions,
        sets,
    })
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

#[cfg(test)]
mod tests {
    #[test]
    fn hex_of_the_sha256_of_abc_is_the_fips_180_example() {
        use sha2::{Digest, Sha256};
        assert_eq!(
            super::hex(&Sha256::digest(b"abc")),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }
}
