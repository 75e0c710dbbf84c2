//! The `robocal` command line: simulate, calibrate, demo, solve, filter, plan, serve, bench.

use clap::{Parser, Subcommand};

pub mod bench;
pub mod calibrate;
pub mod cell;
pub mod check;
pub mod demo;
pub mod exit;
pub mod export;
pub mod filter;
pub mod iso9283;
pub mod judged_fit;
pub mod keygen;
pub mod model_files;
pub mod orientation_arg;
pub mod plan;
pub mod positioner;
mod positioner_part;
pub mod positioner_sim;
mod positioner_touches;
pub mod predict;
pub mod progress;
pub mod reregister;
pub mod serve;
mod sim_files;
pub mod simulate;
pub mod solve;
pub mod tcp;
pub mod track;
mod track_part;
pub mod track_sim;
pub mod turntable;
mod weld;

pub use model_files::load_model;

/// The parsed command line: one subcommand with its arguments.
#[derive(Debug, Parser)]
#[command(
    name = "robocal",
    version,
    about = "Robot calibration and false targets for offline programming",
    after_help = exit::help_all()
)]
pub struct Cli {
    /// The subcommand to run.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands of `robocal`, each with its arguments.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Simulate a "true" robot and write measurements in the CSV format.
    #[command(after_help = exit::help_for("simulate"))]
    Simulate(simulate::SimulateArgs),
    /// Identify calibrated models from measurement CSVs and compare methods.
    #[command(after_help = exit::help_for("calibrate"))]
    Calibrate(calibrate::CalibrateArgs),
    /// Score check poses against a calibrated model without fitting: the status.
    #[command(after_help = exit::help_for("check"))]
    Check(check::CheckArgs),
    /// Score one check set against several calibrated models (versions compared on the same poses).
    #[command(after_help = exit::help_for("compare"))]
    Compare(check::CompareArgs),
    /// Refit only the measurement frame and tool of a calibrated model on a few poses of a new session.
    #[command(after_help = exit::help_for("reregister"))]
    Reregister(reregister::ReregisterArgs),
    /// Run a built-in end-to-end study.
    #[command(after_help = exit::help_for("demo"))]
    Demo(demo::DemoArgs),
    /// Solve target poses into joint commands and false targets.
    #[command(after_help = exit::help_for("solve"))]
    Solve(solve::SolveArgs),
    /// Predict the pose of the measured point or a tool from joint readings (solve's forward half).
    #[command(after_help = exit::help_for("predict"))]
    Predict(predict::PredictArgs),
    /// Export the (calibrated) geometric model: URDF, standard/modified DH CSV, JSON.
    #[command(after_help = exit::help_for("export"))]
    Export(export::ExportArgs),
    /// Filter robot programs (KRL, RAPID, Fanuc, URScript): targets become false targets.
    #[command(after_help = exit::help_for("filter"))]
    Filter(filter::FilterArgs),
    /// The cell's tool, load and work object data as a controller needs them.
    #[command(after_help = exit::help_for("cell"))]
    Cell(cell::CellArgs),
    /// Plan measurement poses (joint CSV or program) and join tracker exports back.
    #[command(after_help = exit::help_for("plan"))]
    Plan(plan::PlanArgs),
    /// ISO 9283 pose accuracy and repeatability: the test cube plan and the figures.
    #[command(after_help = exit::help_for("iso9283"))]
    Iso9283(iso9283::Iso9283Args),
    /// A production tool's TCP (and axis) fitted on the calibrated model, judged before it is written.
    #[command(after_help = exit::help_for("tcp"))]
    Tcp(tcp::TcpArgs),
    /// A work object from three points (tracker or touched with a calibrated tool), judged before it is written.
    #[command(after_help = exit::help_for("work-object"))]
    WorkObject(tcp::WorkObjectArgs),
    /// A robot on a linear track: fit the track from tracker readings at several track values.
    #[command(after_help = exit::help_for("track"))]
    Track(track::TrackArgs),
    /// A two-axis positioner: fit its axes from tracker readings of reflectors on its face plate.
    #[command(after_help = exit::help_for("positioner"))]
    Positioner(positioner::PositionerArgs),
    /// A one-axis turntable: fit its axis from tracker readings of reflectors on its face plate.
    #[command(after_help = exit::help_for("turntable"))]
    Turntable(turntable::TurntableArgs),
    /// Run the HTTP service.
    #[command(after_help = exit::help_for("serve"))]
    Serve(serve::ServeArgs),
    /// Print a new random API key with its role (`KEY:ROLE`) for ROBOCAL_API_KEYS.
    #[command(after_help = exit::help_for("keygen"))]
    Keygen(keygen::KeygenArgs),
    /// Time robocal's side of the peer benchmark (KM, IK), as JSON.
    #[command(after_help = exit::help_for("bench"))]
    Bench(bench::BenchArgs),
}

/// Runs the parsed command line: how it ended ([`exit::Exit`]), or the
/// error that refused it (exit code 1).
pub fn run(cli: Cli) -> anyhow::Result<exit::Exit> {
    let done = |r: anyhow::Result<()>| r.map(|()| exit::Exit::Success);
    match cli.command {
        Command::Simulate(a) => done(simulate::run(a)),
        Command::Calibrate(a) => done(calibrate::run(a)),
        Command::Check(a) => check::run(a),
        Command::Compare(a) => done(check::compare(a)),
        Command::Reregister(a) => done(reregister::run(a)),
        Command::Demo(a) => done(demo::run(a)),
        Command::Solve(a) => solve::run(a),
        Command::Predict(a) => predict::run(a),
        Command::Export(a) => done(export::run(a)),
        Command::Filter(a) => filter::run(a),
        Command::Cell(a) => done(cell::run(a)),
        Command::Plan(a) => done(plan::run(a)),
        Command::Iso9283(a) => done(iso9283::run(a)),
        Command::Tcp(a) => done(tcp::run_tcp(a)),
        Command::WorkObject(a) => done(tcp::run_work_object(a)),
        Command::Track(a) => done(track::run(a)),
        Command::Positioner(a) => done(positioner::run(a)),
        Command::Turntable(a) => done(turntable::run(a)),
        Command::Serve(a) => done(serve::run(a)),
        Command::Keygen(a) => done(keygen::run(a)),
        Command::Bench(a) => done(bench::run(a)),
    }
}
