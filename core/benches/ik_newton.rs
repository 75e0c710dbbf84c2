//! The IK's damped Newton run by its fixed-size iteration
//! (`IkSolver::refine_with`: 6×6 stack matrices) against the same iteration on
//! the generic LM driver (`IkSolver::refine_on_driver`: `optim::lm`, dynamic
//! matrices), YS100 with a synthetic calibrated model
//! (`SyntheticErrors::typical(1e-6)`), 200 full-pose targets each started
//! 0.05 rad per joint off a known solution; one refinement per iteration.
//!
//! Run: `cargo bench -p robocal-core --bench ik_newton` (about 10 s).

use criterion::{criterion_group, criterion_main, Criterion};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use robocal_core::model::preset;
use robocal_core::sim::{synthetic_calibration, SyntheticErrors};
use robocal_core::solve::ik::{Goal, IkSettings, IkSolver};
use std::hint::black_box;
use std::time::Duration;

/// Targets and their starting joints.
struct Case {
    goal: Goal,
    q0: Vec<f64>,
}

fn setup() -> (IkSolver, Vec<Case>) {
    let nominal = preset("ys100").unwrap();
    let cm = synthetic_calibration(&nominal, &SyntheticErrors::typical(1e-6), 3);
    let mut rng = ChaCha8Rng::seed_from_u64(17);
    let mut cases = Vec::new();
    while cases.len() < 200 {
        let q: Vec<f64> = nominal
            .links
            .iter()
            .map(|l| rng.gen_range(l.limits[0]..l.limits[1]))
            .collect();
        if let Ok(p) = cm.predict_base(&q) {
            let q0 = q.iter().map(|v| v + rng.gen_range(-0.05..0.05)).collect();
            cases.push(Case {
                goal: Goal::from(&p),
                q0,
            });
        }
    }
    (IkSolver::new(cm, IkSettings::default()), cases)
}

fn bench(c: &mut Criterion) {
    let (solver, cases) = setup();
    let mut g = c.benchmark_group("ik_newton_ys100");
    g.sample_size(20)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3));
    let mut i = 0;
    g.bench_function("fixed_size", |b| {
        b.iter(|| {
            i = (i + 1) % cases.len();
            let c = &cases[i];
            black_box(solver.refine_with(black_box(&c.goal), &c.q0, false, 60))
        })
    });
    let mut i = 0;
    g.bench_function("generic_driver", |b| {
        b.iter(|| {
            i = (i + 1) % cases.len();
            let c = &cases[i];
            black_box(solver.refine_on_driver(black_box(&c.goal), &c.q0, false, 60))
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
