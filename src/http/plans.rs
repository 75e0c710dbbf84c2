//! `POST /v1/robots/{id}/measurement-plans`: N poses chosen for
//! identifiability on the robot's nominal model, within its joint limits, a
//! workspace box and the tracker's line of sight, with the parameter standard
//! deviations they predict for the tracker noise; the joints as a CSV and,
//! when `language` is given, as a program visiting them with a wait at each.
//! The same as `robocal plan`; with `track` (a linear track's JSON
//! description) the same as `robocal plan --track`: `poses` per station at
//! stations over its travel, each pose with the track's value; with
//! `positioner` or `turntable` (its nominal model and reflectors) the same as
//! `robocal plan --positioner` or `--turntable`: the axes' sweeps.

use super::input::{external_axis, present_int};
use super::programs::FileIn;
use super::{ApiError, ApiJson, ApiPath, AppState};
use crate::calibrate::external::readings::PositionerColumns;
use crate::calibrate::external::AxisSigma;
use crate::measure::external::ExternalAxis;
use crate::model::external::LinearTrack;
use crate::model::external::{TiltRotate, Turntable};
use crate::plan::{program_columns, PositionerPlanSettings, TurntablePlanSettings};
use crate::plan::{
    stations_over, FilterCounts, PlanPoint, PlanSettings, PlannedStation, PredictedStd,
    TrackerSight, WorkspaceBox,
};
use crate::program::Language;
use crate::service;
use crate::service::plans::PlanCommand;
use crate::service::plans::{ForPositioner, ForTurntable, OverTrack, PlanKind, PlanMade};
use axum::extract::State;
use axum::response::{IntoResponse, Response};
use serde::{Deserialize, Serialize};

/// Most poses in a plan.
pub const PLAN_POSES_MAX: usize = 300;
/// Most candidates drawn.
pub const PLAN_CANDIDATES_MAX: usize = 5000;
/// Longest wait at a pose [s].
pub const WAIT_MAX_S: f64 = 3600.0;
/// Most stations of a plan over a track.
pub const STATIONS_MAX: usize = 100;

/// A box for the TCP, base frame [mm].
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoxIn {
    /// The box's lowest corner [mm].
    pub min_mm: [f64; 3],
    /// The box's highest corner [mm], above `min_mm` on every axis.
    pub max_mm: [f64; 3],
}

/// The tracker's position and the reflector's allowed angle to it.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrackerIn {
    /// The tracker's position in the base frame (with `track`, the cell frame) [mm].
    pub position_mm: [f64; 3],
    /// The reflector's axis in the tool frame (default: z).
    #[serde(default)]
    pub axis: Option<[f64; 3]>,
    /// Largest angle between the reflector's axis and the line to the tracker [deg].
    pub max_angle_deg: f64,
}

/// `POST /v1/robots/{id}/measurement-plans` body; every field optional.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlanRequest {
    /// Poses to choose, 1 to [`PLAN_POSES_MAX`]; absent: 50. With `track`,
    /// per station, at least 3; absent: 4.
    #[serde(default, deserialize_with = "present_int")]
    pub poses: Option<usize>,
    /// A linear track carrying the robot, its JSON description (as `robocal
    /// track calibrate --out` writes it): plan over its stations.
    pub track: Option<serde_json::Value>,
    /// Stations over the track's travel, 5 to [`STATIONS_MAX`]; absent: one
    /// every 400 mm (needs `track`).
    #[serde(default, deserialize_with = "present_int")]
    pub stations: Option<usize>,
    /// The stations' lowest and highest value [mm]; absent: the track's
    /// travel (needs `track`).
    pub travel_mm: Option<[f64; 2]>,
    /// The track's column, `e1` … `e6`; absent: `e1` (needs `track`).
    pub column: Option<String>,
    /// A tilt-rotate positioner's sweeps instead of robot poses.
    pub positioner: Option<PositionerPlanIn>,
    /// A one-axis turntable's sweep instead of robot poses.
    pub turntable: Option<TurntablePlanIn>,
    /// Random configurations drawn, from `poses` to [`PLAN_CANDIDATES_MAX`]; absent: 1000 (or
    /// `poses` when more).
    #[serde(default, deserialize_with = "present_int")]
    pub candidates: Option<usize>,
    /// The box the TCP must stay in; absent: no box.
    pub workspace: Option<BoxIn>,
    /// The tracker's line of sight the TCP must keep; absent: not checked.
    pub tracker: Option<TrackerIn>,
    /// Tracker noise, standard deviation per axis [mm], above 0 and at most 100; absent: 0.01.
    pub noise_mm: Option<f64>,
    /// Payload mass [kg]; absent: the model's.
    pub payload_kg: Option<f64>,
    /// Seed of the random candidates (the same seed gives the same plan); absent: 1.
    #[serde(default, deserialize_with = "present_int")]
    pub seed: Option<u64>,
    /// krl, rapid, fanuc or urscript: also return the plan as a program.
    pub language: Option<String>,
    /// The program's name: a letter, then up to 23 letters, digits or `_`; absent: `plan` (needs
    /// `language`).
    pub name: Option<String>,
    /// Wait at each pose [s], 0 to [`WAIT_MAX_S`]; absent: 1 (needs `language`).
    pub wait_s: Option<f64>,
}

/// A positioner's plan: its nominal model, the reflectors and the sweeps.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PositionerPlanIn {
    /// The nominal positioner's JSON description (the file `robocal plan
    /// --positioner` reads).
    pub nominal: serde_json::Value,
    /// The reflectors' design positions on the face plate [mm]; the first is
    /// the reference.
    pub reflectors: Vec<[f64; 3]>,
    /// Axis 1's sweep, lowest and highest value [deg]; absent: −90, 90.
    pub tilt_deg: Option<[f64; 2]>,
    /// Values of axis 1's sweep, 4 to [`SWEEP_VALUES_MAX`]; absent: 13.
    #[serde(default, deserialize_with = "present_int")]
    pub tilt_values: Option<usize>,
    /// Axis 2's sweep [deg]; absent: −165, 165.
    pub rotate_deg: Option<[f64; 2]>,
    /// Values of axis 2's sweep, 4 to [`SWEEP_VALUES_MAX`]; absent: 12.
    #[serde(default, deserialize_with = "present_int")]
    pub rotate_values: Option<usize>,
    /// Axis 1's column, `e1` … `e6`; absent: `e1`.
    pub tilt_column: Option<String>,
    /// Axis 2's column; absent: `e2`.
    pub rotate_column: Option<String>,
}

/// A turntable's plan: its nominal model, the reflectors and the sweep.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TurntablePlanIn {
    /// The nominal turntable's JSON description (the file `robocal plan
    /// --turntable` reads).
    pub nominal: serde_json::Value,
    /// The reflectors' design positions on the face plate [mm]; the first is
    /// the reference.
    pub reflectors: Vec<[f64; 3]>,
    /// The sweep, lowest and highest value [deg]; absent: −165, 165.
    pub travel_deg: Option<[f64; 2]>,
    /// Values of the sweep, 4 to [`SWEEP_VALUES_MAX`]; absent: 12.
    #[serde(default, deserialize_with = "present_int")]
    pub values: Option<usize>,
    /// The axis's column, `e1` … `e6`; absent: `e1`.
    pub column: Option<String>,
}

/// Most values of one sweep of a positioner's plan.
pub const SWEEP_VALUES_MAX: usize = 150;
/// Most reflectors of a positioner's plan.
pub const REFLECTORS_MAX: usize = 16;

/// The plan as a program.
#[derive(Debug, Serialize)]
pub struct ProgramOut {
    /// The program's language.
    pub language: Language,
    /// The program's files, each with its name and text.
    pub files: Vec<FileIn>,
}

impl ProgramOut {
    /// The program's files as answered, `None` without a program.
    pub fn of(
        files: Option<Vec<crate::program::ProgramFile>>,
        language: Option<Language>,
    ) -> Option<Self> {
        files.zip(language).map(|(files, language)| ProgramOut {
            language,
            files: files
                .into_iter()
                .map(|f| FileIn {
                    name: f.name,
                    content: f.text,
                })
                .collect(),
        })
    }
}

/// The answer.
#[derive(Debug, Serialize)]
pub struct PlanResponse {
    /// The robot planned for.
    pub robot_id: i64,
    /// Poses chosen.
    pub poses: usize,
    /// How many candidates passed each filter, in order (robot poses).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub counts: Option<FilterCounts>,
    /// The tracker noise the prediction used, standard deviation per axis [mm].
    pub noise_mm: f64,
    /// The payload mass the plan used [kg] (a plan on a fixed base).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub payload_kg: Option<f64>,
    /// Per method, the parameter standard deviations the poses predict (a
    /// plan on a fixed base).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub predicted: Option<Vec<PredictedStd>>,
    /// The track's column (a plan over a track).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub column: Option<String>,
    /// Per station its value, points and predicted σ of the base's pose (a
    /// plan over a track).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stations: Option<Vec<PlannedStation>>,
    /// A positioner's or a turntable's plan: the predicted σ of each axis's
    /// parameters (a turntable's one, `rotate`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sigma: Option<Vec<AxisSigma>>,
    /// A positioner's or a turntable's plan: the predicted σ of each
    /// reflector's position [mm].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reflector_sigma_mm: Option<Vec<f64>>,
    /// The chosen poses: point names, controller joints [deg] and, over a
    /// track or for a positioner, `external: {"e1": …}` (no joints for a
    /// positioner).
    pub points: Vec<PlanPoint>,
    /// The chosen poses' joints as a CSV.
    pub joints_csv: String,
    /// The plan as a program, when `language` was given.
    pub program: Option<ProgramOut>,
}

fn finite3(what: &str, v: &[f64; 3]) -> Result<(), ApiError> {
    if v.iter().all(|x| x.is_finite() && x.abs() <= 1e6) {
        Ok(())
    } else {
        Err(ApiError::invalid(format!(
            "`{what}`: three finite numbers of at most 1e6 mm"
        )))
    }
}

/// The track of a plan over one (422 naming what is wrong): its
/// description, stations, travel and column, within the request's limits.
fn over_track(req: &PlanRequest, poses: usize) -> Result<Option<OverTrack>, ApiError> {
    let Some(description) = &req.track else {
        if req.stations.is_some() || req.travel_mm.is_some() || req.column.is_some() {
            return Err(ApiError::invalid(
                "`stations`, `travel_mm` and `column` lay out a plan over a track: give `track` too",
            ));
        }
        return Ok(None);
    };
    let track = LinearTrack::from_json(&description.to_string())
        .map_err(|e| ApiError::invalid(format!("`track`: {e}")))?;
    let axis = external_axis("column", req.column.as_deref(), ExternalAxis::E1)?;
    let over = OverTrack {
        track,
        stations: req.stations,
        axis,
        travel_mm: req.travel_mm,
    };
    let settings = over.settings(&PlanSettings {
        poses,
        ..PlanSettings::default()
    });
    let (_, stations) =
        stations_over(&over.track, &settings).map_err(|e| ApiError::invalid(e.to_string()))?;
    if stations > STATIONS_MAX || stations * poses > PLAN_POSES_MAX {
        return Err(ApiError::invalid(format!(
            "{stations} stations of {poses} poses: at most {STATIONS_MAX} stations and {PLAN_POSES_MAX} poses in all in one request; give fewer `stations` or `poses`, or use `robocal plan --track`"
        )));
    }
    Ok(Some(over))
}

/// A face plate's plan (`what`: `positioner` or `turntable`): a field that
/// lays out robot poses is a 422 naming it; its reflectors (1 to
/// [`REFLECTORS_MAX`]) and `noise_mm` checked, the noise returned.
fn plate_only(req: &PlanRequest, what: &str, reflectors: usize) -> Result<f64, ApiError> {
    let robot_fields = [
        ("poses", req.poses.is_some()),
        ("candidates", req.candidates.is_some()),
        ("workspace", req.workspace.is_some()),
        ("tracker", req.tracker.is_some()),
        ("payload_kg", req.payload_kg.is_some()),
        ("seed", req.seed.is_some()),
        ("track", req.track.is_some()),
        ("stations", req.stations.is_some()),
        ("travel_mm", req.travel_mm.is_some()),
        ("column", req.column.is_some()),
    ];
    if let Some((field, _)) = robot_fields.iter().find(|(_, given)| *given) {
        return Err(ApiError::invalid(format!(
            "`{field}` lays out robot poses; a {what}'s plan takes `{what}` and `noise_mm`"
        )));
    }
    if !(1..=REFLECTORS_MAX).contains(&reflectors) {
        return Err(ApiError::invalid(format!(
            "`{what}.reflectors`: 1 to {REFLECTORS_MAX} design positions, got {reflectors}"
        )));
    }
    let noise_mm = req.noise_mm.unwrap_or(PlanSettings::default().noise_mm);
    if !(noise_mm.is_finite() && noise_mm > 0.0 && noise_mm <= 100.0) {
        return Err(ApiError::invalid(format!(
            "`noise_mm`: above 0 and at most 100 mm, got {noise_mm}"
        )));
    }
    Ok(noise_mm)
}

/// A turntable's plan as a service command (422 naming what is wrong).
fn turntable_command(
    robot_id: i64,
    req: &PlanRequest,
    t: &TurntablePlanIn,
) -> Result<PlanCommand, ApiError> {
    if req.positioner.is_some() {
        return Err(ApiError::invalid(
            "`positioner` and `turntable` each lay out a face plate's sweeps: give one",
        ));
    }
    let noise_mm = plate_only(req, "turntable", t.reflectors.len())?;
    let program = program_of(req)?;
    let nominal = Turntable::from_json(&t.nominal.to_string())
        .map_err(|e| ApiError::invalid(format!("`turntable.nominal`: {e}")))?;
    let d = TurntablePlanSettings::default();
    let values = t.values.unwrap_or(d.values);
    if values > SWEEP_VALUES_MAX {
        return Err(ApiError::invalid(format!(
            "`turntable.values`: at most {SWEEP_VALUES_MAX}, got {values}"
        )));
    }
    let settings = TurntablePlanSettings {
        reflectors_mm: t.reflectors.clone(),
        travel_deg: t.travel_deg.unwrap_or(d.travel_deg),
        values,
        column: external_axis("turntable.column", t.column.as_deref(), d.column)?,
        noise_mm,
    };
    Ok(PlanCommand {
        robot_id,
        settings: PlanSettings {
            noise_mm,
            ..PlanSettings::default()
        },
        program,
        kind: PlanKind::Turntable(ForTurntable { nominal, settings }),
    })
}

/// A positioner's plan as a service command (422 naming what is wrong).
fn positioner_command(
    robot_id: i64,
    req: &PlanRequest,
    p: &PositionerPlanIn,
) -> Result<PlanCommand, ApiError> {
    let noise_mm = plate_only(req, "positioner", p.reflectors.len())?;
    let program = program_of(req)?;
    let nominal = TiltRotate::from_json(&p.nominal.to_string())
        .map_err(|e| ApiError::invalid(format!("`positioner.nominal`: {e}")))?;
    let d = PositionerPlanSettings::default();
    let values = |field: &str, v: Option<usize>, default: usize| {
        let n = v.unwrap_or(default);
        if n > SWEEP_VALUES_MAX {
            return Err(ApiError::invalid(format!(
                "`positioner.{field}`: at most {SWEEP_VALUES_MAX}, got {n}"
            )));
        }
        Ok(n)
    };
    let settings = PositionerPlanSettings {
        reflectors_mm: p.reflectors.clone(),
        tilt_deg: p.tilt_deg.unwrap_or(d.tilt_deg),
        tilt_values: values("tilt_values", p.tilt_values, d.tilt_values)?,
        rotate_deg: p.rotate_deg.unwrap_or(d.rotate_deg),
        rotate_values: values("rotate_values", p.rotate_values, d.rotate_values)?,
        columns: PositionerColumns {
            tilt: external_axis(
                "positioner.tilt_column",
                p.tilt_column.as_deref(),
                d.columns.tilt,
            )?,
            rotate: external_axis(
                "positioner.rotate_column",
                p.rotate_column.as_deref(),
                d.columns.rotate,
            )?,
        },
        noise_mm,
    };
    if let Some((language, _, _)) = &program {
        program_columns(&settings.columns, *language)
            .map_err(|e| ApiError::invalid(e.to_string()))?;
    }
    Ok(PlanCommand {
        robot_id,
        settings: PlanSettings {
            noise_mm,
            ..PlanSettings::default()
        },
        program,
        kind: PlanKind::Positioner(ForPositioner { nominal, settings }),
    })
}

/// A program's `name` (`default` when absent): a letter, then up to 23
/// letters, digits or `_`, a name every language takes.
pub(super) fn program_name(name: Option<String>, default: &str) -> Result<String, ApiError> {
    let name = name.unwrap_or_else(|| default.into());
    let ok = name.len() <= 24
        && name.chars().next().is_some_and(|c| c.is_ascii_alphabetic())
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    if !ok {
        return Err(ApiError::invalid(format!(
            "`name`: a letter, then up to 23 letters, digits or `_`, got `{name}`"
        )));
    }
    Ok(name)
}

/// A program's wait at each pose, `wait_s` [s] (`default` when absent), 0 to
/// [`WAIT_MAX_S`].
pub(super) fn program_wait(wait_s: Option<f64>, default: f64) -> Result<f64, ApiError> {
    let wait_s = wait_s.unwrap_or(default);
    if !(wait_s.is_finite() && (0.0..=WAIT_MAX_S).contains(&wait_s)) {
        return Err(ApiError::invalid(format!(
            "`wait_s`: 0 to {WAIT_MAX_S} s, got {wait_s}"
        )));
    }
    Ok(wait_s)
}

/// The program a request asks (`language`, `name`, `wait_s`), if any.
fn program_of(req: &PlanRequest) -> Result<Option<(Language, String, f64)>, ApiError> {
    let program = match req.language.as_deref() {
        None => None,
        Some(l @ ("krl" | "rapid" | "fanuc" | "urscript")) => {
            let language = l
                .parse::<Language>()
                .map_err(|e| ApiError::invalid(format!("`language`: {e}")))?;
            let name = program_name(req.name.clone(), "plan")?;
            let wait_s = program_wait(req.wait_s, 1.0)?;
            Some((language, name, wait_s))
        }
        Some(l) => {
            return Err(ApiError::invalid(format!(
                "`language` must be krl, rapid, fanuc or urscript, got `{l}`"
            )))
        }
    };
    if program.is_none() && (req.name.is_some() || req.wait_s.is_some()) {
        return Err(ApiError::invalid(
            "`name` and `wait_s` shape the program: give `language` too",
        ));
    }
    Ok(program)
}

/// The request as a service command (422 naming what is wrong).
fn command(robot_id: i64, req: PlanRequest) -> Result<PlanCommand, ApiError> {
    if let Some(t) = &req.turntable {
        return turntable_command(robot_id, &req, t);
    }
    if let Some(p) = &req.positioner {
        return positioner_command(robot_id, &req, p);
    }
    let d = PlanSettings::default();
    let poses = req
        .poses
        .unwrap_or(if req.track.is_some() { 4 } else { d.poses });
    if !(1..=PLAN_POSES_MAX).contains(&poses) {
        return Err(ApiError::invalid(format!(
            "`poses`: 1 to {PLAN_POSES_MAX}, got {poses}"
        )));
    }
    let over_track = over_track(&req, poses)?;
    let program = program_of(&req)?;
    let candidates = req.candidates.unwrap_or(d.candidates.max(poses));
    if !(poses..=PLAN_CANDIDATES_MAX).contains(&candidates) {
        return Err(ApiError::invalid(format!(
            "`candidates`: from `poses` ({poses}) to {PLAN_CANDIDATES_MAX}, got {candidates}"
        )));
    }
    let workspace = match req.workspace {
        Some(b) => {
            finite3("workspace.min_mm", &b.min_mm)?;
            finite3("workspace.max_mm", &b.max_mm)?;
            if (0..3).any(|i| b.min_mm[i] >= b.max_mm[i]) {
                return Err(ApiError::invalid(
                    "`workspace`: each of min_mm must be below max_mm",
                ));
            }
            Some(WorkspaceBox {
                min_mm: b.min_mm,
                max_mm: b.max_mm,
            })
        }
        None => None,
    };
    let tracker = match req.tracker {
        Some(t) => {
            finite3("tracker.position_mm", &t.position_mm)?;
            let axis = t.axis.unwrap_or([0.0, 0.0, 1.0]);
            let norm = axis.iter().map(|x| x * x).sum::<f64>().sqrt();
            if !(axis.iter().all(|x| x.is_finite()) && norm > 1e-9 && norm.is_finite()) {
                return Err(ApiError::invalid(
                    "`tracker.axis`: a non-zero finite vector",
                ));
            }
            if !(t.max_angle_deg.is_finite() && t.max_angle_deg > 0.0 && t.max_angle_deg <= 180.0) {
                return Err(ApiError::invalid(format!(
                    "`tracker.max_angle_deg`: above 0 and at most 180, got {}",
                    t.max_angle_deg
                )));
            }
            Some(TrackerSight {
                position_mm: t.position_mm,
                axis,
                max_angle_deg: t.max_angle_deg,
            })
        }
        None => None,
    };
    let noise_mm = req.noise_mm.unwrap_or(d.noise_mm);
    if !(noise_mm.is_finite() && noise_mm > 0.0 && noise_mm <= 100.0) {
        return Err(ApiError::invalid(format!(
            "`noise_mm`: above 0 and at most 100 mm, got {noise_mm}"
        )));
    }
    if let Some(p) = req.payload_kg {
        super::input::check_payload("`payload_kg`", p)?;
    }
    Ok(PlanCommand {
        robot_id,
        settings: PlanSettings {
            poses,
            candidates,
            workspace,
            tracker,
            noise_mm,
            payload_kg: req.payload_kg,
            seed: req.seed.unwrap_or(d.seed),
            ..d
        },
        program,
        kind: over_track.map_or(PlanKind::FixedBase, PlanKind::Track),
    })
}

/// `POST /v1/robots/{id}/measurement-plans`: poses chosen for identifiability on the nominal model,
/// with their predicted standard deviations, joints CSV and optional program.
pub async fn plan(
    State(state): State<AppState>,
    ApiPath(robot_id): ApiPath<i64>,
    ApiJson(req): ApiJson<PlanRequest>,
) -> Result<Response, ApiError> {
    let cmd = command(robot_id, req)?;
    let language = cmd.program.as_ref().map(|p| p.0);
    let done = service::plans::make(&state, cmd).await?;
    let program = ProgramOut::of(done.program, language);
    Ok(axum::Json(response(robot_id, done.plan, done.joints_csv, program)).into_response())
}

/// The answer of a plan made.
fn response(
    robot_id: i64,
    plan: PlanMade,
    joints_csv: String,
    program: Option<ProgramOut>,
) -> PlanResponse {
    let mut out = PlanResponse {
        robot_id,
        poses: plan.points().len(),
        counts: None,
        noise_mm: 0.0,
        payload_kg: None,
        predicted: None,
        column: None,
        stations: None,
        sigma: None,
        reflector_sigma_mm: None,
        points: Vec::new(),
        joints_csv,
        program,
    };
    match plan {
        PlanMade::FixedBase(p) => {
            out.counts = Some(p.counts);
            out.noise_mm = p.noise_mm;
            out.payload_kg = Some(p.payload_kg);
            out.predicted = Some(p.predicted);
            out.points = p.points;
        }
        PlanMade::Track(p) => {
            out.counts = Some(p.counts);
            out.noise_mm = p.noise_mm;
            out.column = Some(p.axis.column().into());
            out.stations = Some(p.stations);
            out.points = p.points;
        }
        PlanMade::Positioner(p) => {
            out.noise_mm = p.noise_mm;
            out.sigma = Some(p.sigma.to_vec());
            out.reflector_sigma_mm = Some(p.reflector_sigma_mm);
            out.points = p.points;
        }
        PlanMade::Turntable(p) => {
            out.noise_mm = p.noise_mm;
            out.sigma = Some(vec![p.sigma]);
            out.reflector_sigma_mm = Some(p.reflector_sigma_mm);
            out.points = p.points;
        }
    }
    out
}

/// The route of measurement plans.
pub fn routes() -> Vec<super::Route> {
    vec![super::post("/v1/robots/{id}/measurement-plans", plan)]
}
