//! The `robocal` command line: simulate, calibrate, demo, solve, filter, plan, serve, bench.

use clap::{Parser, Subcommand};

pub mod bench;
pub mod calibrate;
pub mod cell;
pub mod demo;
pub mod export;
pub mod filter;
pub mod model_files;
pub mod plan;
pub mod progress;
pub mod serve;
pub mod simulate;
pub mod solve;

#[derive(Debug, Parser)]
#[command(
    name = "robocal",
    version,
    about = "Robot calibration and false targets for offline programming"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Simulate a "true" robot and write measurements in the CSV format.
    Simulate(simulate::SimulateArgs),
    /// Identify calibrated models from measurement CSVs and compare methods.
    Calibrate(calibrate::CalibrateArgs),
    /// Run a built-in end-to-end study.
    Demo(demo::DemoArgs),
    /// Solve target poses into joint commands and false targets.
    Solve(solve::SolveArgs),
    /// Export the (calibrated) geometric model: URDF, standard/modified DH CSV, JSON.
    Export(export::ExportArgs),
    /// Filter robot programs (KRL, RAPID, Fanuc, URScript): targets become false targets.
    Filter(filter::FilterArgs),
    /// The cell's tool, load and work object data as a controller needs them.
    Cell(cell::CellArgs),
    /// Plan measurement poses (joint CSV or program) and join tracker exports back.
    Plan(plan::PlanArgs),
    /// Run the HTTP service.
    Serve(serve::ServeArgs),
    /// Time robocal's side of the peer benchmark (KM, IK), as JSON.
    Bench(bench::BenchArgs),
}

/// Runs the parsed command line.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Simulate(a) => simulate::run(a),
        Command::Calibrate(a) => calibrate::run(a),
        Command::Demo(a) => demo::run(a),
        Command::Solve(a) => solve::run(a),
        Command::Export(a) => export::run(a),
        Command::Filter(a) => filter::run(a),
        Command::Cell(a) => cell::run(a),
        Command::Plan(a) => plan::run(a),
        Command::Serve(a) => serve::run(a),
        Command::Bench(a) => bench::run(a),
    }
}

/// Loads a model from a preset name or a model JSON file path.
pub fn load_model(arg: &str) -> anyhow::Result<crate::model::RobotModel> {
    let path = std::path::Path::new(arg);
    if path.exists() {
        let text = std::fs::read_to_string(path)
            .map_err(|e| anyhow::anyhow!("cannot read model file {arg}: {e}"))?;
        crate::model::RobotModel::from_json(&text)
            .map_err(|e| anyhow::anyhow!("model file {arg}: {e}"))
    } else if arg.ends_with(".json") {
        anyhow::bail!("model file {arg} does not exist")
    } else {
        crate::model::preset(arg).map_err(|e| anyhow::anyhow!("{e}"))
    }
}
