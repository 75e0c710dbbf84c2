//! ISO 9283 pose characteristics from measured cycles (`core::iso9283`):
//! per test, the commanded poses and the attained positions of every cycle
//! give AP, RP, APa/b/c, ±RPa/b/c, AD and RD, each with its outcome
//! (`core::iso9283::outcome`). The tests come as poses ([`figures`]) or as
//! the two CSV texts of `robocal iso9283` ([`figures_csv`]). Nothing is
//! stored. The report's conditions name the robot and the model version
//! (its SHA-256) from the store ([`conditions`]); [`plan`] lays out the test
//! cube on a robot's version and writes its cycle program.

use super::solve::{chosen_model, ModelChoice};
use super::{robots, versions, AppState, ServiceError};
use crate::model::orientation::fixed_xyz_matrix;
use crate::plan::WorkspaceBox;
use crate::program::{Language, ProgramFile};
use crate::report::iso9283::{cycles_of, is_date, today_utc, Iso9283Conditions, MeasuredSet};
use robocal_core::check::iso9283::csv::{plan_csv, pose_data, read_cycles_csv, read_plan_csv};
use robocal_core::check::iso9283::outcome::PoseData;
use robocal_core::check::iso9283::program::cycle_program;
use robocal_core::check::iso9283::{
    assess, plan_cube, Assessment, Commands, CubePlan, CubeSettings, Iso9283Error,
};
use sha2::{Digest, Sha256};

/// Most tests in one request (a nominal and a filtered run side by side).
pub const TESTS_MAX: usize = 8;

/// One test: a label and its poses (commanded and measured).
#[derive(Debug, Clone)]
pub struct Iso9283Test {
    /// The test's label.
    pub label: String,
    /// Its poses P1 … P5, each with its command and measured cycles where given.
    pub poses: Vec<PoseData>,
}

/// One test as CSV: the plan CSV (`robocal iso9283 plan --csv`) and its
/// measured cycles (`pose,cycle,x_mm,y_mm,z_mm[,rx_deg,ry_deg,rz_deg]`).
#[derive(Debug, Clone)]
pub struct Iso9283CsvTest {
    /// The test's label.
    pub label: String,
    /// The plan CSV's text.
    pub plan_csv: String,
    /// The measured cycles' CSV text.
    pub measured_csv: String,
}

fn count(n: usize) -> Result<(), ServiceError> {
    if n == 0 || n > TESTS_MAX {
        return Err(ServiceError::Invalid(format!(
            "send 1 to {TESTS_MAX} tests, got {n}"
        )));
    }
    Ok(())
}

fn invalid(label: &str, what: &str, e: Iso9283Error) -> ServiceError {
    ServiceError::Invalid(format!("test `{label}`, {what}: {e}"))
}

/// The figures of each test, in order; values out of bounds name the test.
pub async fn figures(
    state: &AppState,
    tests: Vec<Iso9283Test>,
) -> Result<Vec<(String, Assessment)>, ServiceError> {
    count(tests.len())?;
    super::heavy::run(state, "iso9283", move |_| assess_all(tests)).await?
}

fn assess_all(tests: Vec<Iso9283Test>) -> Result<Vec<(String, Assessment)>, ServiceError> {
    tests
        .into_iter()
        .map(|t| {
            let a = assess(&t.poses).map_err(|e| invalid(&t.label, "poses", e))?;
            Ok((t.label, a))
        })
        .collect()
}

fn csv_poses(t: &Iso9283CsvTest) -> Result<Vec<PoseData>, ServiceError> {
    let commanded = read_plan_csv(&t.plan_csv).map_err(|e| invalid(&t.label, "plan_csv", e))?;
    let cycles = read_cycles_csv(&t.measured_csv, &commanded)
        .map_err(|e| invalid(&t.label, "measured_csv", e))?;
    Ok(pose_data(&commanded, cycles))
}

/// The figures of each CSV test, in order; a CSV that cannot be read says
/// which test, which file and where.
pub async fn figures_csv(
    state: &AppState,
    tests: Vec<Iso9283CsvTest>,
) -> Result<Vec<(String, Assessment)>, ServiceError> {
    count(tests.len())?;
    super::heavy::run(state, "iso9283", move |_| {
        let tests = tests
            .iter()
            .map(|t| {
                Ok(Iso9283Test {
                    label: t.label.clone(),
                    poses: csv_poses(t)?,
                })
            })
            .collect::<Result<Vec<_>, ServiceError>>()?;
        assess_all(tests)
    })
    .await?
}

/// What a request says of the test (the report's conditions).
#[derive(Debug, Clone, Default)]
pub struct ConditionsCommand {
    /// The robot tested; its name, and the model version's number and
    /// SHA-256, come from the store.
    pub robot_id: Option<i64>,
    /// The version the commands were solved with (default: the active one;
    /// the nominal model when the robot has none).
    pub version: Option<i64>,
    /// `YYYY-MM-DD` (default: today, UTC).
    pub date: Option<String>,
    /// Load carried during the test [kg].
    pub load_kg: Option<f64>,
    /// Speed of the motions between the poses [% of the rated speed].
    pub speed_percent: Option<f64>,
    /// What was measured with what (tracker, reflector, session).
    pub measurement: Option<String>,
}

fn sha256_hex(text: &str) -> String {
    Sha256::digest(text.as_bytes())
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// The report's conditions: the request's, the robot's name and the model
/// version's number and SHA-256 (of the stored model file, as
/// `GET …/versions/{v}/model.json` serves it) from the store.
pub async fn conditions(
    state: &AppState,
    cmd: ConditionsCommand,
    sets: Vec<MeasuredSet>,
) -> Result<Iso9283Conditions, ServiceError> {
    let (robot, model_version, model_sha256) = match (cmd.robot_id, cmd.version) {
        (None, None) => (None, None, None),
        (None, Some(_)) => {
            return Err(ServiceError::Invalid(
                "`conditions.version` needs `conditions.robot_id`".into(),
            ))
        }
        (Some(id), v) => {
            let row = robots::get(state, id).await?;
            match v.or(row.active_version) {
                Some(v) => {
                    let (_, text) =
                        versions::with_model(state, id, v)
                            .await
                            .map_err(|e| match e {
                                ServiceError::NotFound(m) => ServiceError::Conflict(m),
                                e => e,
                            })?;
                    (Some(row.name), Some(v.to_string()), Some(sha256_hex(&text)))
                }
                None => (
                    Some(row.name),
                    Some("nominal (no calibrated version)".to_string()),
                    Some(sha256_hex(&row.model_json)),
                ),
            }
        }
    };
    let date = match cmd.date {
        Some(d) if is_date(&d) => d,
        Some(d) => {
            return Err(ServiceError::Invalid(format!(
                "`conditions.date`: a calendar date YYYY-MM-DD, got `{d}`"
            )))
        }
        None => today_utc(),
    };
    Ok(Iso9283Conditions {
        robot,
        model_version,
        model_sha256,
        date,
        load_kg: cmd.load_kg,
        speed_percent: cmd.speed_percent,
        measurement: cmd.measurement,
        sets,
        robocal_version: env!("CARGO_PKG_VERSION"),
    })
}

/// The measured sets of assessed tests: label, cycles and (for CSV tests)
/// the SHA-256 of the cycles text.
pub fn measured_sets(tests: &[(String, Assessment)], texts: &[Option<String>]) -> Vec<MeasuredSet> {
    tests
        .iter()
        .enumerate()
        .map(|(i, (label, a))| MeasuredSet {
            label: label.clone(),
            cycles: cycles_of(a),
            sha256: texts.get(i).and_then(|t| t.as_deref()).map(sha256_hex),
        })
        .collect()
}

/// An ISO 9283 plan of a robot's model version.
#[derive(Debug, Clone)]
pub struct CubeCommand {
    /// The robot whose model the cube is solved on.
    pub robot_id: i64,
    /// `None`: the active version.
    pub version: Option<i64>,
    /// The box the cube must fit in, base frame [mm].
    pub workspace: WorkspaceBox,
    /// Fixed-axis `rx, ry, rz` [deg], base frame.
    pub rpy_deg: [f64; 3],
    /// Which joint commands: solved on the nominal or on the calibrated, compensated model.
    pub commands: Commands,
    /// The cycle program: language, name, cycles, wait [s].
    pub program: Option<(Language, String, u32, f64)>,
}

/// The plan, its CSV and its cycle program, and the version it was solved on.
#[derive(Debug)]
pub struct CubeOutcome {
    /// The cube, its five poses and their joint commands.
    pub plan: CubePlan,
    /// The plan as the CSV `robocal iso9283 --plan` reads.
    pub plan_csv: String,
    /// The cycle program's files, when one was asked for.
    pub program: Option<Vec<ProgramFile>>,
    /// The robot's name.
    pub robot: String,
    /// The model version solved on.
    pub version: i64,
    /// SHA-256 (hex) of that version's stored `model.json`.
    pub model_sha256: String,
}

/// Lays out the test cube on a version of the robot's model.
pub async fn plan(state: &AppState, cmd: CubeCommand) -> Result<CubeOutcome, ServiceError> {
    let row = robots::get(state, cmd.robot_id).await?;
    let choice = cmd
        .version
        .map_or(ModelChoice::Active, ModelChoice::Version);
    let chosen = chosen_model(state, cmd.robot_id, choice).await?;
    let version = chosen.version.ok_or_else(|| {
        ServiceError::Conflict(format!(
            "robot {} has no calibrated version to plan on",
            cmd.robot_id
        ))
    })?;
    let (_, text) = versions::with_model(state, cmd.robot_id, version).await?;
    let model = chosen.model;
    super::heavy::run(state, "iso9283", move |_| {
        let r = cmd.rpy_deg.map(f64::to_radians);
        let settings = CubeSettings::new(
            cmd.workspace,
            fixed_xyz_matrix(r[0], r[1], r[2]),
            cmd.commands,
        );
        let plan =
            plan_cube(&model, &settings).map_err(|e| ServiceError::Invalid(e.to_string()))?;
        let program = match &cmd.program {
            Some((language, name, cycles, wait_s)) => Some(
                cycle_program(&plan, *language, name, *cycles, *wait_s)
                    .map_err(|e| ServiceError::Invalid(e.to_string()))?,
            ),
            None => None,
        };
        Ok(CubeOutcome {
            plan_csv: plan_csv(&plan),
            plan,
            program,
            robot: row.name,
            version,
            model_sha256: sha256_hex(&text),
        })
    })
    .await?
}
