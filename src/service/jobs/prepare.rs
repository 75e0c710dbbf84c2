//! What a job reads before it runs: the sets of its command by role (checked
//! against the robot's sets), their tracker sessions and poses, and the
//! [`Job`] that the runner takes. The rows of the chosen sets are read when
//! the job is prepared: later changes to the sets do not affect it.

use super::command::StartCommand;
use crate::calibrate::identify::{CalibrationOptions, PoseSource, PoseSources};
use crate::measure::Measurement;
use crate::model::RobotModel;
use crate::records::{SetRow, StoredRole};
use crate::service::limits::{Ticket, MAX_SETS};
use crate::service::{AppState, ServiceError};

fn set_vanished(robot_id: i64, set_id: i64) -> ServiceError {
    // Deleted meanwhile (alone, or with its robot): the set is not found.
    ServiceError::NotFound(format!(
        "measurement set {set_id} of robot {robot_id} does not exist (deleted while the job was being queued)"
    ))
}

/// A set list of the command (`ids`), or every set of the robot with `role`.
fn pick_sets(
    all_sets: &[SetRow],
    ids: &Option<Vec<i64>>,
    role: StoredRole,
    field: &str,
    robot_id: i64,
) -> Result<Vec<SetRow>, ServiceError> {
    let Some(ids) = ids else {
        return Ok(all_sets
            .iter()
            .filter(|s| s.role == role)
            .cloned()
            .collect());
    };
    if ids.len() > MAX_SETS {
        return Err(ServiceError::Invalid(format!(
            "`{field}` lists {} sets; at most {MAX_SETS}",
            ids.len()
        )));
    }
    let mut out: Vec<SetRow> = Vec::new();
    for id in ids {
        // A reference in the body to a set the robot does not have (yet): a
        // conflict with its state, not a missing URL.
        let s = all_sets.iter().find(|s| s.id == *id).ok_or_else(|| {
            ServiceError::Conflict(format!(
                "`{field}`: measurement set {id} does not exist for robot {robot_id}; list them with GET /v1/robots/{robot_id}/measurement-sets"
            ))
        })?;
        if !out.iter().any(|o| o.id == s.id) {
            out.push(s.clone());
        }
    }
    Ok(out)
}

/// The sets of a job by role (Q1, Q3, Q2).
struct SelectedSets {
    ident: Vec<SetRow>,
    valid: Vec<SetRow>,
    train: Vec<SetRow>,
}

/// The sets of a command, each in one role, with at least one identification set.
fn select_sets(
    all_sets: &[SetRow],
    cmd: &StartCommand,
    robot_id: i64,
) -> Result<SelectedSets, ServiceError> {
    use StoredRole::{Identification, Training, Validation};
    let ids = &cmd.identification_set_ids;
    let ident = pick_sets(
        all_sets,
        ids,
        Identification,
        "identification_set_ids",
        robot_id,
    )?;
    let ids = &cmd.validation_set_ids;
    let valid = pick_sets(all_sets, ids, Validation, "validation_set_ids", robot_id)?;
    let train = pick_sets(
        all_sets,
        &cmd.training_set_ids,
        Training,
        "training_set_ids",
        robot_id,
    )?;
    // A check set is only ever scored: fitting on it would leave the checks
    // and the re-registrations scored on it no independent data.
    for (sets, field) in [
        (&ident, "identification_set_ids"),
        (&train, "training_set_ids"),
    ] {
        if let Some(s) = sets.iter().find(|s| s.role == StoredRole::Check) {
            return Err(ServiceError::Conflict(format!(
                "`{field}`: measurement set {} has role check; check sets are scored (checks, re-registration, validation), never fitted on",
                s.id
            )));
        }
    }
    if ident.is_empty() {
        // The robot's data, not the request, is missing: a state conflict.
        return Err(ServiceError::Conflict(format!(
            "no identification set: upload one with role identification (POST /v1/robots/{robot_id}/measurement-sets) or list its id in `identification_set_ids`"
        )));
    }
    // A set in two roles conflicts with the job's data roles (each set plays
    // one), which the request's schema cannot state.
    if let Some(s) = valid.iter().find(|v| ident.iter().any(|i| i.id == v.id)) {
        return Err(ServiceError::Conflict(format!(
            "measurement set {} is listed for both identification and validation; validation data must never be used for fitting",
            s.id
        )));
    }
    if let Some(s) = train
        .iter()
        .find(|t| ident.iter().any(|i| i.id == t.id) || valid.iter().any(|v| v.id == t.id))
    {
        return Err(ServiceError::Conflict(format!(
            "measurement set {} is listed for training and for identification or validation; each set plays one role",
            s.id
        )));
    }
    Ok(SelectedSets {
        ident,
        valid,
        train,
    })
}

/// Tracker sessions: the identification sets' sessions in order of first
/// appearance; a validation or training set of another session cannot be
/// registered (a state conflict).
fn sessions_of(sets: &SelectedSets) -> Result<Vec<String>, ServiceError> {
    let mut sessions: Vec<String> = Vec::new();
    for s in &sets.ident {
        if !sessions.contains(&s.session) {
            sessions.push(s.session.clone());
        }
    }
    for (what, list) in [("validation", &sets.valid), ("training", &sets.train)] {
        if let Some(v) = list.iter().find(|v| !sessions.contains(&v.session)) {
            return Err(ServiceError::Conflict(format!(
                "{what} set {} was measured in tracker session `{}`, which no identification set has, so its frame cannot be registered; measure identification poses in that session too",
                v.id, v.session
            )));
        }
    }
    Ok(sessions)
}

/// The poses of `sets` (SI, session indices into `sessions`) and where each
/// came from, for the report's per-pose table.
async fn load_sets(
    state: &AppState,
    robot_id: i64,
    sets: &[SetRow],
    sessions: &[String],
    nominal: &RobotModel,
    default_payload: f64,
) -> Result<(Vec<Measurement>, Vec<PoseSource>), ServiceError> {
    let mut out = Vec::new();
    let mut sources = Vec::new();
    for s in sets {
        let rows = state
            .db()
            .set_rows(robot_id, s.id)
            .await?
            .ok_or_else(|| set_vanished(robot_id, s.id))?;
        let session = sessions.iter().position(|x| *x == s.session).unwrap_or(0);
        let payload = s.payload_kg.unwrap_or(default_payload);
        for (i, r) in rows.iter().enumerate() {
            let mut m = r.to_measurement(nominal, payload);
            m.session = session;
            out.push(m);
            sources.push(PoseSource {
                set: s.name.clone(),
                row: i + 1,
                session: s.session.clone(),
            });
        }
    }
    Ok((out, sources))
}

/// A job's data, read from the store: the poses by role, where each came
/// from, the tracker sessions, and the command with its sets and payload
/// resolved (what the store keeps).
pub(crate) struct Prepared {
    ident: Vec<Measurement>,
    valid: Vec<Measurement>,
    training: Vec<Measurement>,
    session_names: Vec<String>,
    pose_sources: PoseSources,
    /// Payload [kg] of sets that declare none.
    payload_kg: f64,
    /// The command as resolved: the set ids read and the payload used.
    pub(crate) command: StartCommand,
}

/// Selects and reads the sets of `cmd` for robot `robot_id`.
pub(crate) async fn prepare(
    state: &AppState,
    robot_id: i64,
    nominal: &RobotModel,
    cmd: &StartCommand,
) -> Result<Prepared, ServiceError> {
    let all_sets = state.db().sets(robot_id).await?;
    // A delete of the robot may have run between the robot lookup and the set
    // list (the cascade removes its sets): the robot still existing now means
    // it existed when the sets were read, so the list is that robot's.
    if state.db().robot(robot_id).await?.is_none() {
        return Err(ServiceError::robot_not_found(robot_id));
    }
    let sets = select_sets(&all_sets, cmd, robot_id)?;
    let sessions = sessions_of(&sets)?;
    let default_payload = cmd.payload_kg.unwrap_or(nominal.payload.mass);
    let (ident, ident_sources) = load_sets(
        state,
        robot_id,
        &sets.ident,
        &sessions,
        nominal,
        default_payload,
    )
    .await?;
    let (valid, valid_sources) = load_sets(
        state,
        robot_id,
        &sets.valid,
        &sessions,
        nominal,
        default_payload,
    )
    .await?;
    let (training, train_sources) = load_sets(
        state,
        robot_id,
        &sets.train,
        &sessions,
        nominal,
        default_payload,
    )
    .await?;
    let pose_sources = PoseSources {
        identification: ident_sources,
        validation: valid_sources,
        training: train_sources,
    };
    let ids = |list: &[SetRow]| list.iter().map(|s| s.id).collect::<Vec<i64>>();
    let command = cmd.resolved(
        ids(&sets.ident),
        ids(&sets.valid),
        ids(&sets.train),
        default_payload,
    );
    Ok(Prepared {
        ident,
        valid,
        training,
        session_names: sessions,
        pose_sources,
        payload_kg: default_payload,
        command,
    })
}

/// Everything a queued job needs; the rows are read when it is queued.
pub(crate) struct Job {
    pub(super) id: i64,
    pub(super) robot_id: i64,
    pub(super) robot_name: String,
    pub(super) nominal: RobotModel,
    pub(super) ident: Vec<Measurement>,
    pub(super) valid: Vec<Measurement>,
    /// Compensator training poses (Q2).
    pub(super) training: Vec<Measurement>,
    pub(super) opts: CalibrationOptions,
    pub(super) payload_kg: f64,
    /// Tracker session names in the order of the measurements' session index.
    pub(super) session_names: Vec<String>,
    /// Set, row and session of every identification and validation pose.
    pub(super) pose_sources: PoseSources,
    /// Its place in this process's job queue, released when the job ends
    /// (`None`: queued in the shared store).
    pub(super) ticket: Option<Ticket>,
}

impl Job {
    /// The job `id` of a prepared calibration.
    pub(crate) fn new(
        id: i64,
        robot_id: i64,
        robot_name: String,
        nominal: RobotModel,
        p: Prepared,
        ticket: Option<Ticket>,
    ) -> Job {
        Job {
            id,
            robot_id,
            robot_name,
            nominal,
            ident: p.ident,
            valid: p.valid,
            training: p.training,
            session_names: p.session_names,
            pose_sources: p.pose_sources,
            opts: p.command.calibration_options(),
            payload_kg: p.payload_kg,
            ticket,
        }
    }
}
