//! Inverse kinematics on the calibrated, compensated model, and false targets
//! (docs/design.md "Compensated model and false targets").
//!
//! - [`analytic`]: closed-form IK of the nominal model (spherical wrist and
//!   UR-style three parallel axes), all branches with configuration flags: the seed.
//! - `solver`: damped Newton on `CompensatedModel::predict = target` from that
//!   seed (branch, joint seed, limits, per-target result and failure reason).
//! - `batch`: parallel batches and path mode.
//! - [`choice`]: the one rule by which a target that names no configuration
//!   gets one (solve, filter, HTTP).
//! - `targets`: boundary targets (mm, degrees, orientation conventions), joint
//!   commands in the controller convention and false targets `FK_nominal(q_cmd)`;
//!   [`targets_csv`]: the same as a targets file; `invalid`: why a target fails
//!   alone.
//!
//! Units: SI inside (m, rad); mm and degrees at the boundary (`targets`).

pub mod analytic;
mod batch;
pub mod choice;
mod config;
mod invalid;
mod solver;
mod targets;
pub mod targets_csv;
pub mod tool;

pub use analytic::{AnalyticError, AnalyticIk, AnalyticSolution, Structure};
pub use config::{BranchError, Configuration, Elbow, Shoulder, Wrist};
pub use invalid::{RowError, TargetError};
pub use solver::{
    FailureReason, Goal, IkSettings, IkSolution, IkSolver, Refined, SolveOptions, UnknownFrame,
};
pub use targets::{FalseTarget, JointJump, SolveMode, TargetFrame, TargetInput, TargetResult};
pub use targets_csv::{parse_targets_csv, results_csv, TargetRow, TargetsCsv, TargetsCsvError};
pub use tool::TcpTool;
