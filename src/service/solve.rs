//! Solve orchestration: which model a solve uses (the active version, a
//! numbered one or the nominal model), the prepared-solver cache, the joint
//! seed, and where the batch runs — inline for small batches, on the solve
//! workers behind admission control for large ones (a full queue is refused at
//! once with `Busy`, never a silent wait).
//!
//! Prepared solvers are cached per (robot, version row, payload override):
//! versions never change once written. A custom jump threshold gets a fresh
//! solver that is not cached.
//!
//! A solve may name a production tool and a work object `W`; both enter
//! through `core::cell::CellSolver`, as in the CLI and the program filter:
//! the tool on the calibrated flange with its load (the load stated by the
//! tool, else the model's payload kept at its flange point), targets `T`
//! solved as `W·T` in the base frame and false targets returned in `W`.
//!
//! A track value carries the model's base along the robot's stored track
//! (`super::tracks::carry`): the cell frame is the track's; such a solver
//! is built per request, not cached. A targets CSV with an `e1` column has
//! a value per row: each row is moved into the base frame at its value
//! along the stored track (a row beyond the travel fails alone) and solved
//! by the cached solver. A targets CSV with `e1` and `e2` columns has a
//! positioner's tilt and rotate values per row, its targets in the face
//! plate frame: each row is moved into the base frame through the robot's
//! stored positioner (`super::positioners::place_rows`) and solved by the
//! cached solver; `e1` and `e2` for the whole request place every target
//! (JSON or CSV) on the face plate at those values the same way. A robot
//! on its track beside its positioner takes `e1` (the track), `e2`, `e3`
//! (the positioner), as its programs number them: per CSV row, each target
//! moved to `B(e)⁻¹·F(v)·T` (`core::solve::external::
//! place_on_track_and_positioner`); for the whole request, the solver's
//! model carried to `e1` and the targets placed on the face plate at `e2`,
//! `e3` through it.
//!
//! Units at this boundary: targets in mm and degrees (`TargetInput`), joint
//! seeds and commands in the controller convention in degrees.

use super::limits::SMALL_SOLVE_MAX;
use super::waiting::WaitingFlag;
use super::{AppState, ServiceError};
use crate::model::{Pose, RobotModel};
use crate::records::{CellKind, ItemFrame, NewCellItem};
use crate::solve::cell::file::PoseMmDeg;
use crate::solve::cell::{CellSolver, Load, LoadDescription, Tool, WorkObject, WorkObjectFrame};
use crate::solve::ik::TargetFrame;
use crate::solve::ik::{
    IkSettings, IkSolver, SolveMode, SolveOptions, TargetInput, TargetResult, TargetsCsv,
};
use robocal_core::model::calibrated::{CalibratedModelFile, CompensatedModel};
use robocal_core::solve::external::{
    base_from_part, place_on_track, place_on_track_and_positioner, AxisValues, PlacedRows,
    TargetValue,
};
use std::sync::Arc;

/// Which model to solve with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ModelChoice {
    /// The robot's active version (a conflict when it has none).
    #[default]
    Active,
    /// The robot's nominal (uncalibrated) model.
    Nominal,
    /// A version by number (≥ 1).
    Version(i64),
}

/// The targets of a solve: checked inputs, or the rows of a targets file
/// (invalid rows fail alone).
#[derive(Debug, Clone)]
pub enum Targets {
    /// Targets checked one by one (a JSON solve), in mm and degrees.
    Inputs(Vec<TargetInput>),
    /// The parsed rows of a targets CSV.
    Csv(TargetsCsv),
}

impl Targets {
    /// Number of targets (of rows, for a targets CSV).
    pub fn len(&self) -> usize {
        match self {
            Targets::Inputs(t) => t.len(),
            Targets::Csv(c) => c.rows.len(),
        }
    }

    /// Whether there is no target.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Solves a large batch on a solve worker: JSON targets outside path mode
    /// in chunks of [`CHUNK`], `None` once `flag` says the client has gone
    /// (between chunks); a path (each target seeded by the one before) and a
    /// targets CSV run whole, bounded by the target cap.
    fn run_large(
        &mut self,
        solver: &IkSolver,
        options: &SolveOptions,
        path: bool,
        flag: &WaitingFlag,
    ) -> Option<Vec<TargetResult>> {
        match self {
            Targets::Inputs(t) if !path => {
                // The ids a whole batch would give (1-based positions).
                for (i, target) in t.iter_mut().enumerate() {
                    target.id.get_or_insert_with(|| (i + 1).to_string());
                }
                let mut out = Vec::with_capacity(t.len());
                for chunk in t.chunks(CHUNK) {
                    if !flag.still_waiting() {
                        return None;
                    }
                    out.extend(solver.solve_targets(chunk, SolveMode::Parallel, options));
                }
                Some(out)
            }
            _ => Some(self.run(solver, options, path)),
        }
    }

    fn run(&self, solver: &IkSolver, options: &SolveOptions, path: bool) -> Vec<TargetResult> {
        match self {
            Targets::Inputs(t) => {
                let mode = if path {
                    SolveMode::Path
                } else if t.len() <= SMALL_SOLVE_MAX {
                    SolveMode::Serial
                } else {
                    SolveMode::Parallel
                };
                solver.solve_targets(t, mode, options)
            }
            Targets::Csv(c) => c.solve(solver, options, path),
        }
    }
}

/// Targets of a large batch solved between two checks that the client
/// still waits (a few hundred milliseconds of one worker).
const CHUNK: usize = 2048;

/// A solve, in domain terms.
#[derive(Debug, Clone)]
pub struct SolveCommand {
    /// The robot to solve for.
    pub robot_id: i64,
    /// The model to solve with.
    pub model: ModelChoice,
    /// Payload mass [kg] instead of the model's.
    pub payload_kg: Option<f64>,
    /// Path-mode joint jump threshold [deg] instead of the default.
    pub jump_deg: Option<f64>,
    /// Joint seed, controller convention [deg]; checked against the robot.
    pub seed_deg: Option<Vec<f64>>,
    /// Frame, branch, position-only and output convention (`seed` is set
    /// from `seed_deg`).
    pub options: SolveOptions,
    /// Path mode: in order, each target seeded by the previous solution, joint jumps reported.
    pub path: bool,
    /// The targets to solve.
    pub targets: Targets,
    /// Production tool on the calibrated flange (`None`: the model's tool).
    pub tool: Option<ItemChoice>,
    /// Work object the targets and false targets are in (`None`: `options.frame`).
    pub work_object: Option<ItemChoice>,
    /// A track value [mm]: the base carried along the robot's stored track
    /// (the solver is then built for the request, not cached).
    pub track_mm: Option<f64>,
    /// A track value per row of a targets CSV (its `e1` column): each row
    /// moved into the base frame at its value along the stored track
    /// (`core::solve::external::place_on_track`; the cached solver serves).
    pub track_rows: Option<Vec<TargetValue>>,
    /// A positioner's tilt and rotate values per row of a targets CSV (its
    /// `e1` and `e2` columns), the targets in its face plate frame: each row
    /// moved into the base frame through the robot's stored positioner
    /// (`super::positioners::place_rows`; the cached solver serves).
    pub positioner_rows: Option<super::positioners::PlateValues>,
    /// A positioner's tilt and rotate values for every target [deg] (a JSON
    /// body's `e1` and `e2`), the targets in its face plate
    /// frame: moved into the base frame through the robot's stored
    /// positioner as a targets CSV's rows at those values are.
    pub positioner_deg: Option<AxisValues>,
    /// What carries the part at those values: the stored positioner, or
    /// the stored turntable (its value the rotate value, the tilt 0).
    pub plate: super::positioners::Plate,
}

/// A tool or work object of a solve: stored by name, or given inline.
#[derive(Debug, Clone)]
pub enum ItemChoice {
    /// The name of one of the robot's stored tools or work objects.
    Stored(String),
    /// A tool or work object given with the request, checked.
    Inline(NewCellItem),
}

/// What a solve produced.
#[derive(Debug)]
pub struct SolveOutcome {
    /// Version number used (`None`: the nominal model).
    pub version: Option<i64>,
    /// Calibration method of that version, or `nominal`.
    pub method: String,
    /// Payload the model was evaluated at [kg].
    pub payload_kg: f64,
    /// The robot's joint count.
    pub dof: usize,
    /// One result per target, in the input order.
    pub results: Vec<TargetResult>,
}

/// The model a solve uses: (version row id, version number, method), `None`
/// for the nominal model.
pub(super) async fn choose_version(
    state: &AppState,
    robot_id: i64,
    choice: ModelChoice,
    active: Option<(i64, i64, String)>,
) -> Result<Option<(i64, i64, String)>, ServiceError> {
    match choice {
        ModelChoice::Active => active.map(Some).ok_or_else(|| {
            ServiceError::Conflict(format!(
                "robot {robot_id} has no active model version: run a calibration (POST /v1/robots/{robot_id}/calibrations), activate a version, name one with \"version\": N, or solve with the nominal model with \"version\": \"nominal\""
            ))
        }),
        ModelChoice::Nominal => Ok(None),
        ModelChoice::Version(v) if v < 1 => Err(ServiceError::Invalid(format!(
            "`version` numbers start at 1, got {v}"
        ))),
        ModelChoice::Version(v) => {
            // A version the robot does not have (yet): a conflict with its
            // state, not a missing URL.
            let row = state.db().version(robot_id, v).await?.ok_or_else(|| {
                ServiceError::Conflict(format!(
                    "robot {robot_id} has no model version {v}; list them with GET /v1/robots/{robot_id}/versions"
                ))
            })?;
            Ok(Some((row.id, row.version, row.method)))
        }
    }
}

/// The compensated model of a chosen version (`None`: the nominal model).
async fn load_model(
    state: &AppState,
    robot_id: i64,
    nominal_json: &str,
    chosen: &Option<(i64, i64, String)>,
) -> Result<CompensatedModel, ServiceError> {
    Ok(match chosen {
        Some((vid, v, _)) => {
            let text = state.db().version_model(*vid).await?.ok_or_else(|| {
                ServiceError::NotFound(format!("robot {robot_id} has no model version {v}"))
            })?;
            CalibratedModelFile::from_json(&text)
                .and_then(|f| f.to_compensated())
                .map_err(|e| ServiceError::Internal(format!("stored model version {v}: {e}")))?
        }
        None => {
            let m = RobotModel::from_json(nominal_json).map_err(|e| {
                ServiceError::Internal(format!("stored model of robot {robot_id}: {e}"))
            })?;
            CompensatedModel::from_nominal(m)
        }
    })
}

/// A model for work other than a solve batch (program filtering): the chosen
/// version's compensated model, its number (`None`: nominal) and its method.
pub struct ChosenModel {
    /// The chosen version's compensated model (or the nominal one).
    pub model: CompensatedModel,
    /// Its version number (`None`: the nominal model).
    pub version: Option<i64>,
    /// Its calibration method, or `nominal`.
    pub method: String,
}

/// The compensated model `choice` names for robot `robot_id`.
pub async fn chosen_model(
    state: &AppState,
    robot_id: i64,
    choice: ModelChoice,
) -> Result<ChosenModel, ServiceError> {
    let ctx = state.robot_context(robot_id).await?;
    let chosen = choose_version(state, robot_id, choice, ctx.active.clone()).await?;
    let model = load_model(state, robot_id, &ctx.model_json, &chosen).await?;
    let (version, method) = match chosen {
        Some((_, v, m)) => (Some(v), m),
        None => (None, "nominal".to_string()),
    };
    Ok(ChosenModel {
        model,
        version,
        method,
    })
}

/// The prepared solver of a command (carrying its production tool when it
/// names one), from the cache when it can be: building one prepares the
/// model, among it the joint maps' tables.
async fn prepare(
    state: &AppState,
    cmd: &SolveCommand,
) -> Result<(Arc<CellSolver>, Option<i64>, String), ServiceError> {
    let robot_id = cmd.robot_id;
    let ctx = state.robot_context(robot_id).await?;
    let chosen = choose_version(state, robot_id, cmd.model, ctx.active.clone()).await?;
    let (version, method) = match &chosen {
        Some((_, v, m)) => (Some(*v), m.clone()),
        None => (None, "nominal".to_string()),
    };
    let tool = match &cmd.tool {
        Some(choice) => Some(resolve(state, robot_id, CellKind::Tool, choice).await?),
        None => None,
    };
    let tcp = tool.as_ref().map(|t| &t.pose);
    let load = tool.as_ref().and_then(|t| t.load.as_ref());
    let key = (
        robot_id,
        chosen.as_ref().map(|c| c.0),
        cmd.payload_kg.map(f64::to_bits),
        tcp.map(|t| std::array::from_fn(|i| if i < 3 { t.p[i] } else { t.r[i - 3] }.to_bits())),
        load.map(|l| [l.mass_kg, l.com.x, l.com.y, l.com.z].map(f64::to_bits)),
    );
    let cacheable = cmd.jump_deg.is_none() && cmd.track_mm.is_none();
    if cacheable {
        if let Some(solver) = state.cached_solver(&key) {
            return Ok((solver, version, method));
        }
    }
    let mut model = load_model(state, robot_id, &ctx.model_json, &chosen).await?;
    if let Some(p) = cmd.payload_kg {
        model.payload_kg = p;
    }
    if let Some(value) = cmd.track_mm {
        model = super::tracks::carry(state, robot_id, model, value).await?;
    }
    let mut settings = IkSettings::default();
    if let Some(j) = cmd.jump_deg {
        settings.jump_threshold_rad = j.to_radians();
    }
    let tool = tool.map(|t| Tool {
        name: t.name,
        number: None,
        tcp: t.pose,
        load: t.load,
    });
    let solver = Arc::new(CellSolver::for_tool(&model, tool.as_ref(), settings));
    if cacheable {
        state.cache_solver(key, solver.clone());
    }
    Ok((solver, version, method))
}

/// The seed in the solver's joint convention, checked against the joint count
/// (a seed for another joint count conflicts with the robot).
pub fn seed_joints(seed_deg: &[f64], solver: &IkSolver) -> Result<Vec<f64>, ServiceError> {
    let dof = solver.model().dof();
    if seed_deg.iter().any(|v| !v.is_finite()) {
        return Err(ServiceError::Invalid(
            "`seed_deg` values must be finite (controller convention, degrees)".into(),
        ));
    }
    if seed_deg.len() != dof {
        return Err(ServiceError::Conflict(format!(
            "`seed_deg` needs one value per joint: the robot has {dof} joints, got {} values (controller convention, degrees)",
            seed_deg.len()
        )));
    }
    let rad: Vec<f64> = seed_deg.iter().map(|d| d.to_radians()).collect();
    Ok(solver.model().nominal.joints_from_controller(&rad))
}

/// Solves a command's targets with the chosen model.
pub async fn solve(state: &AppState, mut cmd: SolveCommand) -> Result<SolveOutcome, ServiceError> {
    let max = state.limits().targets_per_request;
    if cmd.targets.is_empty() {
        return Err(ServiceError::Invalid(
            "no targets: send at least one target".into(),
        ));
    }
    if cmd.targets.len() > max {
        return Err(ServiceError::Invalid(format!(
            "{} targets in one request; at most {max} (`--max-targets`): split the batch",
            cmd.targets.len()
        )));
    }
    let (cell_solver, version, method) = prepare(state, &cmd).await?;
    let work_object = match &cmd.work_object {
        None => None,
        Some(choice) => {
            let item = resolve(state, cmd.robot_id, CellKind::WorkObject, choice).await?;
            Some(item.placed_work_object()?)
        }
    };
    // Rows at their own track values take the work object row by row.
    let placed_rows = place_on_axes(state, &mut cmd, &cell_solver, work_object.as_ref()).await?;
    let in_work_object = match (&work_object, &placed_rows) {
        (_, Some(_)) | (None, None) => None,
        (Some(wobj), None) => {
            let Targets::Inputs(inputs) = &mut cmd.targets else {
                return Err(ServiceError::Invalid(
                    "a work object needs JSON targets (the targets CSV has no work object)".into(),
                ));
            };
            cmd.options.frame = TargetFrame::Base;
            Some(cell_solver.targets_in(wobj, inputs.iter_mut()))
        }
    };
    let solver = cell_solver.solver();
    if let Some(s) = &cmd.seed_deg {
        cmd.options.seed = Some(seed_joints(s, solver)?);
    }
    let payload_kg = solver.model().payload_kg;
    let dof = solver.model().dof();
    let results = if cmd.targets.len() <= SMALL_SOLVE_MAX {
        cmd.targets.run(solver, &cmd.options, cmd.path)
    } else {
        let task_state = state.clone();
        let cell_solver = cell_solver.clone();
        super::heavy::run(state, "solver", move |flag| {
            let out = cmd
                .targets
                .run_large(cell_solver.solver(), &cmd.options, cmd.path, flag);
            if out.is_none() {
                task_state.note_abandoned();
                tracing::info!("a solve batch was stopped: its client went away");
            }
            out
        })
        .await?
        .ok_or_else(|| {
            ServiceError::Unavailable("the solve was stopped before it finished".into())
        })?
    };
    let mut results = results;
    if let Some(w) = &in_work_object {
        w.false_targets_back(&mut results);
    }
    if let Some(placed) = &placed_rows {
        placed.false_targets_back(&mut results);
    }
    Ok(SolveOutcome {
        version,
        method,
        payload_kg,
        dof,
        results,
    })
}

/// Moves the command's targets into the robot's base frame along its
/// external axes: a track value per CSV row, a positioner's values for every
/// target, or per CSV row (module docs); the frame is then the base. Rows
/// at their own track values in `work_object` are placed in it at their
/// values (`W_b(e)·T`), and the rows' placement, which returns their false
/// targets to it, is the answer; a work object beside per-row positioner
/// values is refused (its pose does not follow the plate row by row).
async fn place_on_axes(
    state: &AppState,
    cmd: &mut SolveCommand,
    cell_solver: &CellSolver,
    work_object: Option<&WorkObject>,
) -> Result<Option<PlacedRows>, ServiceError> {
    if work_object.is_some() && cmd.positioner_rows.is_some() {
        return Err(ServiceError::Invalid(
            "a work object beside the targets' own positioner values: give the targets on the face plate, or the values for the whole request".into(),
        ));
    }
    let mut placed_rows = None;
    if let Some(values) = cmd.track_rows.take() {
        let track = super::tracks::stored(state, cmd.robot_id).await?;
        let Targets::Csv(csv) = &mut cmd.targets else {
            return Err(ServiceError::Internal(
                "a track value per row comes with a targets CSV".into(),
            ));
        };
        match cmd.positioner_rows.take() {
            // Beside a positioner: the rows are on its face plate.
            Some(plate) => {
                let positioner =
                    super::positioners::for_rows(state, cmd.robot_id, true, cmd.plate).await?;
                place_on_track_and_positioner(
                    csv,
                    &values,
                    &track,
                    &plate.tilt,
                    &plate.rotate,
                    &positioner,
                );
            }
            None => {
                let placed = place_on_track(csv, &values, &track, cmd.options.frame, work_object);
                placed_rows = work_object.map(|_| placed);
            }
        }
        cmd.options.frame = TargetFrame::Base;
    }
    if let Some(values) = cmd.positioner_deg.take() {
        // Beside the track's `e1`, the solver's model is carried to it.
        let positioner =
            super::positioners::for_predict(state, cmd.robot_id, cmd.track_mm.is_some(), cmd.plate)
                .await?;
        let robot = cell_solver.solver().model();
        match &mut cmd.targets {
            Targets::Csv(csv) => {
                let every = super::positioners::PlateValues::every_row(csv, values);
                super::positioners::place_rows(csv, &every, &positioner, &robot.cell_from_base);
            }
            Targets::Inputs(inputs) => {
                let plate = WorkObject {
                    name: "face_plate".into(),
                    number: None,
                    frame: WorkObjectFrame::Base,
                    pose: base_from_part(robot, &positioner, values, &Pose::identity()),
                };
                // The false targets stay in the base frame, as a CSV's rows'.
                cell_solver.targets_in(&plate, inputs.iter_mut());
            }
        }
        cmd.options.frame = TargetFrame::Base;
    }
    if let Some(values) = cmd.positioner_rows.take() {
        let positioner =
            super::positioners::for_rows(state, cmd.robot_id, false, cmd.plate).await?;
        let Targets::Csv(csv) = &mut cmd.targets else {
            return Err(ServiceError::Internal(
                "a positioner's values per row come with a targets CSV".into(),
            ));
        };
        let robot = &cell_solver.solver().model().cell_from_base;
        super::positioners::place_rows(csv, &values, &positioner, robot);
        cmd.options.frame = TargetFrame::Base;
    }
    Ok(placed_rows)
}

/// A tool or work object of a solve, resolved.
pub(super) struct ResolvedItem {
    pub name: String,
    pub frame: ItemFrame,
    /// SI pose in `frame`.
    pub pose: Pose,
    /// A tool's load, on the flange.
    pub load: Option<Load>,
}

impl ResolvedItem {
    /// The item as a work object a solve or a prediction places in the base
    /// frame; one on the positioner's face plate is refused (409), naming
    /// it: only a program filter given the positioner places it.
    pub(super) fn placed_work_object(self) -> Result<WorkObject, ServiceError> {
        if self.frame == ItemFrame::FacePlate {
            return Err(ServiceError::Conflict(format!(
                "work object `{}` is on the positioner's face plate: it has a pose only at the positioner's values; give the targets in the face plate frame with `e1` and `e2`, or filter a program with `controller_positioner`",
                self.name
            )));
        }
        Ok(WorkObject {
            name: self.name,
            number: None,
            frame: super::cell::work_object_frame(self.frame),
            pose: self.pose,
        })
    }
}

/// A stored or inline tool or work object (`NotFound` for an unknown name).
pub(super) async fn resolve(
    state: &AppState,
    robot_id: i64,
    kind: CellKind,
    choice: &ItemChoice,
) -> Result<ResolvedItem, ServiceError> {
    Ok(match choice {
        ItemChoice::Inline(item) => resolved(
            item.name.clone(),
            item.frame,
            &item.pose,
            item.load.as_ref(),
        )?,
        ItemChoice::Stored(name) => {
            let row = super::cell::get(state, robot_id, kind, name).await?;
            let load = row.load_json.as_ref().map(|j| &j.0);
            resolved(row.name.clone(), row.frame, &row.pose_json.0, load)?
        }
    })
}

/// An item's SI pose and its load on the flange (converted once, `core::cell::load`).
fn resolved(
    name: String,
    frame: ItemFrame,
    pose: &PoseMmDeg,
    load: Option<&LoadDescription>,
) -> Result<ResolvedItem, ServiceError> {
    let pose = pose.pose();
    let load = load
        .map(|l| l.to_load(&pose))
        .transpose()
        .map_err(|e| ServiceError::Invalid(format!("`{name}`: {e}")))?;
    Ok(ResolvedItem {
        name,
        frame,
        pose,
        load,
    })
}
