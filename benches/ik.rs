//! IK benchmarks (YS100; synthetic calibrated model with 1 mm / 0.05° errors,
//! compliance 1e-6 rad/(N·m) on joints 2–5 and the 110 kg payload):
//!
//! - `nominal_analytic_all_branches`: closed-form IK of the nominal model, all
//!   branches, one target per iteration (cycling through 1000 targets);
//! - `calibrated_solve_from_analytic_seed`: one calibrated solve (closed-form
//!   seed, seed corrections, damped Newton), one core;
//! - `batch_1000_targets_{1,2}_threads`: 1000 calibrated solves on a 1- and a
//!   2-thread pool.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use robocal::model::kinematics::fk;
use robocal::model::{preset, Pose};
use robocal::sim::{synthetic_calibration, SyntheticErrors};
use robocal::solve::ik::{AnalyticIk, Goal, IkSettings, IkSolver, SolveOptions};
use std::hint::black_box;

fn setup() -> (IkSolver, Vec<Goal>, Vec<Pose>) {
    let nominal = preset("ys100").unwrap();
    let cm = synthetic_calibration(&nominal, &SyntheticErrors::typical(1e-6), 3);
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let mut goals = Vec::new();
    let mut nominal_targets = Vec::new();
    while goals.len() < 1000 {
        let q: Vec<f64> = nominal
            .links
            .iter()
            .map(|l| rng.gen_range(l.limits[0]..l.limits[1]))
            .collect();
        if let (Ok(p), Ok(n)) = (cm.predict(&q), fk(&nominal, &q)) {
            goals.push(Goal::from(&p));
            nominal_targets.push(n);
        }
    }
    (
        IkSolver::new(cm, IkSettings::default()),
        goals,
        nominal_targets,
    )
}

fn bench(c: &mut Criterion) {
    let (solver, goals, nominal_targets) = setup();
    let analytic = AnalyticIk::new(&preset("ys100").unwrap()).unwrap();
    let options = SolveOptions::default();

    let mut g = c.benchmark_group("ik_ys100");
    let mut i = 0;
    g.bench_function("nominal_analytic_all_branches", |b| {
        b.iter(|| {
            i = (i + 1) % nominal_targets.len();
            black_box(analytic.solve(black_box(&nominal_targets[i]), None))
        })
    });
    let mut i = 0;
    g.bench_function("calibrated_solve_from_analytic_seed", |b| {
        b.iter(|| {
            i = (i + 1) % goals.len();
            black_box(solver.solve_goal(black_box(&goals[i]), &options))
        })
    });
    g.finish();

    let mut g = c.benchmark_group("ik_ys100_batch");
    g.sample_size(20);
    g.throughput(Throughput::Elements(goals.len() as u64));
    for threads in [1, 2] {
        let pool = IkSolver::new(
            solver.model().clone(),
            IkSettings {
                threads,
                ..IkSettings::default()
            },
        );
        g.bench_function(format!("batch_1000_targets_{threads}_threads"), |b| {
            b.iter(|| black_box(pool.solve_batch(black_box(&goals), &options)))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
