//! The body of `POST /v1/robots/{id}/solve`: parsing and every check of the
//! HTTP layer never panic, and an accepted request solves (its first targets,
//! on the nominal YS100) into one result per target without panicking.
#![no_main]
use libfuzzer_sys::fuzz_target;
use robocal::compensate::CompensatedModel;
use robocal::http::input::from_json_object;
use robocal::http::solve::{check_request, seed_joints, solve_inline, SolveRequest};
use robocal::ik::{IkSettings, IkSolver, SolveOptions};
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
    let Ok(checked) = check_request(&req, 100_000) else {
        return;
    };
    let Ok(seed) = seed_joints(&req, solver()) else {
        return;
    };
    let options = SolveOptions {
        frame: checked.frame,
        position_only: req.position_only,
        branch: checked.branch,
        seed,
    };
    let first = &checked.inputs[..checked.inputs.len().min(8)];
    let results = if req.path {
        solver().solve_targets_path(first, &options)
    } else {
        solve_inline(solver(), first, &options, checked.default_conv)
    };
    assert_eq!(results.len(), first.len());
});
