//! The body of `POST /v1/robots/{id}/solve`: parsing and every check of the
//! HTTP layer never panic, and an accepted request solves (its first targets,
//! on the nominal YS100) into one result per target without panicking.
#![no_main]
use libfuzzer_sys::fuzz_target;
use robocal::model::calibrated::CompensatedModel;
use robocal::http::input::from_json_object;
use robocal::http::solve::{json_command, CsvSolveQuery, SolveRequest};
use robocal::solve::ik::{IkSettings, IkSolver, SolveMode};
use robocal::service::solve::{seed_joints, Targets};
use std::sync::OnceLock;

fn solver() -> &'static IkSolver {
    static SOLVER: OnceLock<IkSolver> = OnceLock::new();
    SOLVER.get_or_init(|| {
        let model = CompensatedModel::from_nominal(robocal::model::preset("ys100").unwrap());
        IkSolver::new(model, IkSettings::default())
    })
}

fuzz_target!(|data: &[u8]| {
    let Ok(req) = from_json_object::<SolveRequest>(data) else {
        return;
    };
    let Ok(mut cmd) = json_command(1, &req, &CsvSolveQuery::default()) else {
        return;
    };
    if let Some(s) = &cmd.seed_deg {
        let Ok(seed) = seed_joints(s, solver()) else {
            return;
        };
        cmd.options.seed = Some(seed);
    }
    let Targets::Inputs(inputs) = &cmd.targets else {
        panic!("a JSON request gives checked inputs");
    };
    let first = &inputs[..inputs.len().min(8)];
    let mode = if cmd.path {
        SolveMode::Path
    } else {
        SolveMode::Serial
    };
    let results = solver().solve_targets(first, mode, &cmd.options);
    assert_eq!(results.len(), first.len());
});
