//! robocal-core: the numerical core of robocal, one folder per step of the flow; the floors
//! and what each may import are docs/architecture.md.
//!
//! - `measure`: read measurement and target CSV texts (`csv_text`), the tracker's conventions.
//! - `model`: the robot model (`robot`, DH/MDH parameters, joint maps), its kinematics
//!   (`kinematics`: chain, Jacobian, gravity), its stored description and its exports, and
//!   the calibrated model as solves use it (`calibrated`: the compensated model, the learned
//!   compensators' stored forms and prediction, the calibrated model file and its loader).
//! - `calibrate`: identify the model from measurements (`identify`) and train the learned
//!   compensator (`compensate`); `identify::model_file` assembles and checks the calibrated
//!   model file the service stores.
//! - `solve`: inverse kinematics on a calibrated model (`ik`), tools, loads and work objects in
//!   the cell (`cell`).
//! - `cell_fit`: a tool's TCP and a work object fitted from readings on the calibrated model.
//! - `program`: robot programs (KRL, RAPID, Fanuc, URScript) parsed and filtered, joint programs
//!   written, and what the controller must hold of the cell (`program::controller`).
//! - `plan`: measurement plans (`plan::pose_selection`: D-optimal poses); `check`: accuracy
//!   checks, re-registration, ISO 9283.
//! - `sim`: simulated true robots, the thesis's §7.4 study and synthetic calibrations, for
//!   `robocal simulate`, `robocal demo`, tests and benches.
//! - `optim` (Levenberg–Marquardt, TLBO) and `stats`: numerics shared by the steps.
//!
//! Every function takes the model and the joint values as arguments; there is no hidden
//! mutable chain state, and nothing here touches HTTP, a database, the async runtime or the
//! file system.

#![warn(unreachable_pub)]
#![warn(missing_docs)]

pub mod calibrate;
pub mod cell_fit;
pub mod check;
pub mod csv_write;
pub mod measure;
pub mod model;
pub mod optim;
pub mod plan;
pub mod program;
pub mod sim;
pub mod solve;
pub mod stats;
