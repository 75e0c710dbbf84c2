//! The cell around a calibrated robot: production tools on the calibrated
//! flange, work objects (user frames), and solving a target taught in a work
//! object for a tool (docs/design.md "Tools, work objects and programs").
//!
//! Frames: a [`Tool`] is the TCP pose in the flange frame (the last link's
//! frame of the model, before the model's own tool). A [`WorkObject`] is a
//! frame given in the robot base frame (the controller's base frame, taken as
//! the calibrated model's registered base frame) or in the measurement
//! (tracker) frame; the controller knows it in its base frame,
//! [`WorkObject::in_base`]. A program target `T` in a work object `W` means the
//! TCP pose `W·T` in the base frame. The false target is the nominal model's
//! pose of the calibrated solution, with the same tool, expressed in `W`:
//! `W⁻¹·FK_nom(q)·tool`.
//!
//! What a tracker measurement of one reflector cannot separate: the reflector
//! offset absorbs the errors of `d` and of the θ offset of the last joint
//! (identifiability keeps the tool's z over d6 and its x, y over θ6), so the
//! calibrated flange carries the nominal d6 and θ6. A production tool on it is
//! off by the true Δd6 along the last axis and by Δθ6 times the TCP's distance
//! from that axis. The compensator's residual (a position at the reflector) is
//! applied unchanged at the production TCP.
//!
//! Units: SI (m, rad) inside; the programs' units are converted by the parsers.

pub mod accuracy;
pub mod file;
pub mod joints_csv;
pub(crate) mod numbering;
pub use crate::model::load;
pub mod predict;

pub use file::{CellDescription, CellFileError};
pub use load::{Load, LoadDescription, LoadFrame};
pub use numbering::{AssignedNumber, ItemKind};
pub use predict::{Forward, PoseOut, PredictError, PredictFrame, Predicted};

use crate::model::calibrated::CompensatedModel;
use crate::model::Pose;
use crate::solve::ik::{
    Configuration, Goal, IkSettings, IkSolution, IkSolver, SolveOptions, TargetFrame, TcpTool,
};
use serde::{Deserialize, Serialize};

/// A production tool: TCP pose in the flange frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Tool {
    /// The tool's name (a reference matches it ignoring ASCII case).
    pub name: String,
    /// The controller's number (KUKA `TOOL_DATA[n]`, Fanuc `UT`), if any.
    #[serde(default)]
    pub number: Option<u32>,
    /// Flange → TCP [m].
    pub tcp: Pose,
    /// The load the tool carries (centre of mass in the flange frame), if
    /// stated; else a solve takes the model's payload at its flange point.
    #[serde(default)]
    pub load: Option<Load>,
}

/// In which frame a work object's pose is given.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WorkObjectFrame {
    /// The robot (controller) base frame.
    #[default]
    Base,
    /// The measurement (tracker) frame of the calibration.
    Measurement,
    /// The face plate of the cell's positioner (`model::external::positioner`):
    /// the work object turns with it (KRL a base coupled to the positioner,
    /// RAPID `ufprog FALSE`, Fanuc a user frame of coordinated motion) and
    /// has a pose in the base frame only at the positioner's values, which
    /// the program filter composes (`program::axes`); [`Cell::work_object`]
    /// refuses it elsewhere.
    FacePlate,
}

/// A work object / user frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WorkObject {
    /// The work object's name (a reference matches it ignoring ASCII case).
    pub name: String,
    /// The controller's number (KUKA `BASE_DATA[n]`, Fanuc `UF`), if any.
    #[serde(default)]
    pub number: Option<u32>,
    /// The frame `pose` is given in (the base frame by default).
    #[serde(default)]
    pub frame: WorkObjectFrame,
    /// Frame → work object [m].
    pub pose: Pose,
}

impl WorkObject {
    /// The robot base frame itself.
    pub fn base() -> Self {
        WorkObject {
            name: "base".into(),
            number: Some(0),
            frame: WorkObjectFrame::Base,
            pose: Pose::identity(),
        }
    }

    /// The work object in the robot base frame: `base_from_cell·pose` for a
    /// measurement-frame work object. A face-plate work object has none
    /// (it turns with the positioner): its pose on the plate, as the
    /// controller holds it ([`Cell::work_object`] does not give one out).
    pub fn in_base(&self, model: &CompensatedModel) -> Pose {
        self.in_base_at(&model.cell_from_base)
    }

    /// [`Self::in_base`] with the robot's base at `cell_from_base` (a base
    /// a track carries): `cell_from_base⁻¹·pose` for a measurement-frame
    /// work object.
    pub fn in_base_at(&self, cell_from_base: &Pose) -> Pose {
        match self.frame {
            WorkObjectFrame::Base | WorkObjectFrame::FacePlate => self.pose,
            WorkObjectFrame::Measurement => cell_from_base.inverse().compose(&self.pose),
        }
    }
}

/// A name or a controller number of a tool or work object.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum CellRef {
    /// A controller number (shown as `#n`).
    Number(u32),
    /// A name, matched ignoring ASCII case.
    Name(String),
}

impl std::fmt::Display for CellRef {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CellRef::Number(n) => write!(f, "#{n}"),
            CellRef::Name(s) => f.write_str(s),
        }
    }
}

/// The tools and work objects of one robot.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Cell {
    /// The production tools, in the order given.
    #[serde(default)]
    pub tools: Vec<Tool>,
    /// The work objects (user frames), in the order given.
    #[serde(default)]
    pub work_objects: Vec<WorkObject>,
}

/// Why a tool or work object cannot be found.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum CellError {
    /// No tool answers the reference (number 0, the bare flange, always does).
    #[error("no tool {0} in the cell")]
    UnknownTool(CellRef),
    /// No work object answers the reference (number 0, the base frame, always does).
    #[error("no work object {0} in the cell")]
    UnknownWorkObject(CellRef),
    /// The work object turns with the positioner; only a program filter
    /// with the positioner's values places it.
    #[error("work object {0} is on the positioner's face plate: it has a pose only at the positioner's axis values, which the program filter composes given the positioner (robocal filter --positioner, --nominal-positioner)")]
    OnFacePlate(String),
    /// Two items answer one reference (a number held twice, or one name
    /// in two ASCII cases).
    #[error("{} {reference} is ambiguous: both `{first}` and `{second}` answer it; give each its own name and number", .kind.label())]
    Ambiguous {
        /// Whether tools or work objects were searched.
        kind: ItemKind,
        /// The reference given.
        reference: CellRef,
        /// Name of the first item answering it.
        first: String,
        /// Name of the second item answering it.
        second: String,
    },
}

/// The index of the one item answering `r` among items named `names` and
/// numbered `numbers` (`numbering::numbers`).
fn find(
    kind: ItemKind,
    names: &[&str],
    numbers: &[u32],
    r: &CellRef,
) -> Result<Option<usize>, CellError> {
    let hits: Vec<usize> = (0..names.len())
        .filter(|i| match r {
            CellRef::Number(n) => numbers[*i] == *n,
            CellRef::Name(s) => names[*i].eq_ignore_ascii_case(s),
        })
        .collect();
    match hits.as_slice() {
        [] => Ok(None),
        [one] => Ok(Some(*one)),
        [a, b, ..] => Err(CellError::Ambiguous {
            kind,
            reference: r.clone(),
            first: names[*a].to_string(),
            second: names[*b].to_string(),
        }),
    }
}

impl Cell {
    /// The controller numbers of the tools, in their order: their own, else
    /// the lowest free ones (`numbering`).
    pub fn tool_numbers(&self) -> Vec<u32> {
        let d: Vec<(&str, Option<u32>)> = self
            .tools
            .iter()
            .map(|t| (t.name.as_str(), t.number))
            .collect();
        numbering::numbers(&d)
    }

    /// The controller numbers of the work objects (`numbering`).
    pub fn work_object_numbers(&self) -> Vec<u32> {
        let d: Vec<(&str, Option<u32>)> = self
            .work_objects
            .iter()
            .map(|w| (w.name.as_str(), w.number))
            .collect();
        numbering::numbers(&d)
    }

    /// The tool named or numbered `r`, carrying its controller number (its
    /// own or the one `numbering` gives it); number 0 is the bare flange
    /// when the cell does not define it.
    pub fn tool(&self, r: &CellRef) -> Result<Tool, CellError> {
        let numbers = self.tool_numbers();
        let names: Vec<&str> = self.tools.iter().map(|t| t.name.as_str()).collect();
        match find(ItemKind::Tool, &names, &numbers, r)? {
            Some(i) => Ok(Tool {
                number: Some(numbers[i]),
                ..self.tools[i].clone()
            }),
            None if *r == CellRef::Number(0) => Ok(Tool {
                name: "flange".into(),
                number: Some(0),
                tcp: Pose::identity(),
                load: None,
            }),
            None => Err(CellError::UnknownTool(r.clone())),
        }
    }

    /// The work object named or numbered `r`, carrying its controller number
    /// (`numbering`); number 0 is the base frame when the cell does not
    /// define it. One on the positioner's face plate is refused
    /// ([`CellError::OnFacePlate`]; [`Cell::any_work_object`] gives it).
    pub fn work_object(&self, r: &CellRef) -> Result<WorkObject, CellError> {
        let w = self.any_work_object(r)?;
        match w.frame {
            WorkObjectFrame::FacePlate => Err(CellError::OnFacePlate(w.name)),
            _ => Ok(w),
        }
    }

    /// [`Cell::work_object`], a work object on the positioner's face plate
    /// included.
    pub fn any_work_object(&self, r: &CellRef) -> Result<WorkObject, CellError> {
        let numbers = self.work_object_numbers();
        let names: Vec<&str> = self.work_objects.iter().map(|w| w.name.as_str()).collect();
        match find(ItemKind::WorkObject, &names, &numbers, r)? {
            Some(i) => Ok(WorkObject {
                number: Some(numbers[i]),
                ..self.work_objects[i].clone()
            }),
            None if *r == CellRef::Number(0) => Ok(WorkObject::base()),
            None => Err(CellError::UnknownWorkObject(r.clone())),
        }
    }

    /// Whether the cell itself holds the tool `r` (not the bare flange).
    pub fn defines_tool(&self, r: &CellRef) -> bool {
        let numbers = self.tool_numbers();
        let names: Vec<&str> = self.tools.iter().map(|t| t.name.as_str()).collect();
        !matches!(find(ItemKind::Tool, &names, &numbers, r), Ok(None))
    }

    /// Whether the cell itself holds the work object `r` (not the base frame).
    pub fn defines_work_object(&self, r: &CellRef) -> bool {
        let numbers = self.work_object_numbers();
        let names: Vec<&str> = self.work_objects.iter().map(|w| w.name.as_str()).collect();
        !matches!(find(ItemKind::WorkObject, &names, &numbers, r), Ok(None))
    }
}

/// `model` with the production tool `tcp` on its calibrated flange and on its
/// nominal flange (the controller's tool data), the payload kept where it
/// hangs on the flange (`load::on_tool`; never moved with the TCP).
pub fn with_tool(model: &CompensatedModel, tcp: &Pose) -> CompensatedModel {
    with_tool_load(model, tcp, None)
}

/// [`with_tool`] carrying `load` (flange frame) instead of the model's
/// payload; `None` keeps each model's payload at its flange point. For the
/// forward predictions; a solve takes the tool as an input
/// ([`IkSolver::with_tool`]), which applies it the same way.
pub fn with_tool_load(
    model: &CompensatedModel,
    tcp: &Pose,
    load: Option<&Load>,
) -> CompensatedModel {
    crate::solve::ik::tool::carrying(model, tcp, load)
}

/// Options of one cell solve.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CellOptions {
    /// Required configuration branch.
    pub branch: Option<Configuration>,
    /// Joint seed (model convention, rad).
    pub seed: Option<Vec<f64>>,
}

/// The calibrated solution of a cell target and its false target.
#[derive(Debug, Clone, PartialEq)]
pub struct CellSolution {
    /// The calibrated model's IK solution for the TCP at `W·T` (base frame).
    pub solution: IkSolution,
    /// `W⁻¹·FK_nom(q)·tool` when converged: what to write in the program.
    pub false_target: Option<Pose>,
}

/// A calibrated IK solver for one production tool.
#[derive(Debug, Clone)]
pub struct CellSolver {
    solver: IkSolver,
    /// The closed form of the nominal model with the tool (the controller's IK).
    nominal_ik: Option<crate::solve::ik::AnalyticIk>,
}

impl CellSolver {
    /// A solver of `model` carrying the tool `tcp` (flange → TCP) and the
    /// model's payload at its flange point.
    pub fn new(model: &CompensatedModel, tcp: &Pose, settings: IkSettings) -> Self {
        Self::with_load(model, tcp, None, settings)
    }

    /// A solver of `model` carrying the tool `tcp` and `load` (flange frame;
    /// `None`: the model's payload at its flange point).
    pub fn with_load(
        model: &CompensatedModel,
        tcp: &Pose,
        load: Option<&Load>,
        settings: IkSettings,
    ) -> Self {
        let tool = TcpTool {
            tcp: *tcp,
            load: load.copied(),
        };
        Self::prepared(IkSolver::with_tool(model, Some(&tool), settings))
    }

    /// The one way a production tool enters a solve (the HTTP solve, the CLI
    /// and the program filter): a solver of `model` carrying `tool` with its
    /// load (the tool's own, else the model's payload at its flange point);
    /// `None` keeps the model's own (measurement) tool.
    pub fn for_tool(model: &CompensatedModel, tool: Option<&Tool>, settings: IkSettings) -> Self {
        match tool {
            Some(t) => Self::with_load(model, &t.tcp, t.load.as_ref(), settings),
            None => Self::prepared(IkSolver::with_tool(model, None, settings)),
        }
    }

    /// A cell solver around an IK solver built for its tool, with the
    /// closed form of the nominal model carrying that tool.
    fn prepared(solver: IkSolver) -> Self {
        CellSolver {
            nominal_ik: crate::solve::ik::AnalyticIk::new(&solver.model().nominal).ok(),
            solver,
        }
    }

    /// Boundary targets given in `wobj`, converted in place to the base
    /// frame (`W·T`; an invalid target is left as it is and fails alone), for a
    /// batch solved with `frame = Base`. The answer converts the batch's
    /// false targets back into `wobj`.
    pub fn targets_in<'a>(
        &self,
        wobj: &WorkObject,
        targets: impl IntoIterator<Item = &'a mut crate::solve::ik::TargetInput>,
    ) -> InWorkObject {
        let w = wobj.in_base(self.solver.model());
        for t in targets {
            *t = target_in_base(&w, t);
        }
        InWorkObject { w }
    }

    /// The underlying solver (model with the tool).
    pub fn solver(&self) -> &IkSolver {
        &self.solver
    }

    /// Solves `target` (pose of the TCP in `wobj`) on the calibrated model.
    pub fn solve(&self, wobj: &WorkObject, target: &Pose, options: &CellOptions) -> CellSolution {
        let model = self.solver.model();
        let w = wobj.in_base(model);
        let goal = Goal::from(&w.compose(target));
        let solution = self.solver.solve_goal(
            &goal,
            &SolveOptions {
                frame: TargetFrame::Base,
                branch: options.branch,
                seed: options.seed.clone(),
                ..SolveOptions::default()
            },
        );
        let false_target = if solution.converged {
            model
                .false_target(&solution.q)
                .ok()
                .map(|p| w.inverse().compose(&p))
        } else {
            None
        };
        CellSolution {
            solution,
            false_target,
        }
    }

    /// The nominal controller: closed-form solutions of the nominal model for
    /// `target` in `wobj` (model convention), every branch and every 2π
    /// representative of a joint within the limits; empty without a closed form.
    pub fn nominal_solutions(&self, wobj: &WorkObject, target: &Pose) -> Vec<Vec<f64>> {
        let Some(ik) = &self.nominal_ik else {
            return Vec::new();
        };
        let model = self.solver.model();
        let tcp = wobj.in_base(model).compose(target);
        let limits = self.solver.limits();
        let mut out: Vec<Vec<f64>> = Vec::new();
        for s in ik.solve(&tcp, None) {
            let mut set: Vec<Vec<f64>> = vec![Vec::new()];
            for (k, q) in s.q.iter().enumerate() {
                let [lo, hi] = limits[k];
                let reps: Vec<f64> = [-2.0, -1.0, 0.0, 1.0, 2.0]
                    .iter()
                    .map(|t| q + t * std::f64::consts::TAU)
                    .filter(|v| *v >= lo - 1e-9 && *v <= hi + 1e-9)
                    .collect();
                set = set
                    .into_iter()
                    .flat_map(|head| {
                        reps.iter().map(move |v| {
                            let mut h = head.clone();
                            h.push(*v);
                            h
                        })
                    })
                    .collect();
            }
            out.extend(set);
        }
        out
    }

    /// Configuration flags of model-convention joints `q`.
    pub fn configuration(&self, q: &[f64]) -> Option<Configuration> {
        self.solver.configuration(q)
    }
}

/// A batch's work object, `W` in the base frame: its false targets are
/// returned in `W` ([`CellSolver::targets_in`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InWorkObject {
    w: Pose,
}

impl InWorkObject {
    /// Each converged result's false target `F` (base frame) as `W⁻¹·F`.
    pub fn false_targets_back(&self, results: &mut [crate::solve::ik::TargetResult]) {
        for r in results.iter_mut() {
            if let Some(f) = &r.false_target {
                r.false_target = Some(false_target_in(&self.w, f));
            }
        }
    }
}

/// A boundary target given in work object `w` (its pose in the base frame)
/// as a base-frame target, `W·T`, in the same convention; an invalid target
/// is returned as it is (it fails alone).
fn target_in_base(w: &Pose, t: &crate::solve::ik::TargetInput) -> crate::solve::ik::TargetInput {
    let mut out = t.clone();
    if let Ok((goal, conv)) = t.to_goal() {
        let p = w.r * goal.position + w.p;
        out.xyz_mm = [p.x * 1e3, p.y * 1e3, p.z * 1e3];
        if let (Some(r), Some(conv)) = (goal.rotation, conv) {
            out.orientation = crate::model::orientation::rotation_to(conv, &(w.r * r));
        }
    }
    out
}

/// A base-frame false target expressed in work object `w`: `W⁻¹·F`.
fn false_target_in(w: &Pose, f: &crate::solve::ik::FalseTarget) -> crate::solve::ik::FalseTarget {
    use crate::model::orientation::{rotation_from, rotation_to};
    let mut out = f.clone();
    if let Ok(r) = rotation_from(f.convention, &f.orientation) {
        let p = w
            .inverse()
            .compose(&Pose::new(r, nalgebra::Vector3::from(f.xyz_mm) * 1e-3));
        out.xyz_mm = [p.p.x * 1e3, p.p.y * 1e3, p.p.z * 1e3];
        out.orientation = rotation_to(f.convention, &p.r);
    }
    out
}

impl std::str::FromStr for CellRef {
    type Err = std::convert::Infallible;
    /// A number when the text is one, else a name.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Ok(match s.trim().parse::<u32>() {
            Ok(n) => CellRef::Number(n),
            Err(_) => CellRef::Name(s.trim().to_string()),
        })
    }
}

#[cfg(test)]
mod tests;
