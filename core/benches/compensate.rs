//! Compensator benchmarks (YS100; synthetic calibrated model of
//! `SyntheticErrors::typical(1e-6)`, residuals a smooth joint-space function of
//! a few tenths of a millimetre, the model's gravity torques):
//!
//! - `train_{50,1000}/{lm_18-20-3,iwo_18-40-3,tlbo_18-40-3,rbf}`: one training
//!   run of each method's compensator with the default settings (SKCM-NN,
//!   SKCM-IWONN, SKCM-TLBONN, KM-RBF);
//! - `predict/mlp_18-20-3_residual`: one residual of the trained SKCM-NN
//!   network (18-20-3: q, sin q, cos q);
//! - `predict/mlp_18-20-3_residual_and_dq`: residual plus its 3×6 derivative;
//! - `predict/gp_residual`, `predict/gp_residual_and_dq`: residual alone and
//!   residual plus derivative of the Gaussian process (300 inducing
//!   configurations) trained on the same 1000 samples;
//!   `predict/gp_residual_and_dq_rough`: the same in single precision (the
//!   IK's expansion at its seed);
//! - `train_{1500,10000}/gp`: one training of the Gaussian process;
//! - `ik/solve_{plain,compensated,gp,maps}`: one calibrated IK solve without
//!   a compensator, with the 18-20-3 network, with the Gaussian process, and
//!   with joint angle error maps of 80 harmonics on every joint and no
//!   compensator (cycling through 1000 targets);
//! - `ik_unmodelled/solve_{skcm,skcm-nn,skcm-gp,skcm-maps,skcm-maps-gp}`: the
//!   same on the models the pipeline delivers for a simulated YS100 with
//!   effects the calibration does not model (`compensate::unmodelled_truth`
//!   with its effects, as in `tests/compensate.rs`: 100 identification and
//!   1000 training poses, each method with its support and fade), cycling
//!   through the calibrated model's predictions at 1000 random
//!   configurations.
//!
//! Trainer comparison over 20 seeds (final validation error and wall time):
//! `cargo run --release -p robocal-core --example compare_trainers`.

#[path = "../tests/common/mod.rs"]
mod common;

use common::measure_truth;
use criterion::measurement::WallTime;
use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use robocal_core::calibrate::compensate::{train, CompensatorSpec, Sample};
use robocal_core::calibrate::identify::{
    calibrate_with_training, CalibrationOptions, CompensatorOptions, Method,
};
use robocal_core::model::calibrated::{CompensatedModel, Compensator, StoredCompensator};
use robocal_core::model::{preset, JointMap, JointMaps};
use robocal_core::sim::random_configurations;
use robocal_core::sim::{synthetic_calibration, unmodelled_truth, SyntheticErrors};
use robocal_core::solve::ik::{Goal, IkSettings, IkSolver, SolveOptions};
use std::hint::black_box;
use std::sync::Arc;

fn samples(cm: &CompensatedModel, n: usize, seed: u64) -> Vec<Sample> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    random_configurations(&cm.nominal, n, &mut rng)
        .into_iter()
        .map(|q| Sample {
            tau: cm.torques(&q).unwrap(),
            residual: Vector3::new(
                2e-4 * (0.8 * q[1]).sin() + 5e-5 * q[2],
                1e-4 * (q[1] + 0.5 * q[2]).cos() * q[0].cos(),
                -1.5e-4 * (0.6 * q[2]).sin() * (0.5 * q[3]).cos(),
            ),
            q,
            payload_kg: cm.payload_kg,
        })
        .collect()
}

fn fit(spec: &CompensatorSpec, s: &[Sample]) -> StoredCompensator {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    train(spec, s, &mut rng, &mut |_, _| true).unwrap().0
}

/// One calibrated IK solve per iteration, cycling through `goals`.
fn bench_ik(
    g: &mut criterion::BenchmarkGroup<'_, WallTime>,
    name: &str,
    m: &CompensatedModel,
    qs: &[Vec<f64>],
) {
    let solver = IkSolver::new(
        m.clone(),
        IkSettings {
            threads: 1,
            ..IkSettings::default()
        },
    );
    let goals: Vec<Goal> = qs
        .iter()
        .map(|q| Goal::from(&m.predict(q).unwrap()))
        .collect();
    let options = SolveOptions::default();
    let mut i = 0;
    g.bench_function(name, |b| {
        b.iter(|| {
            i = (i + 1) % goals.len();
            black_box(solver.solve_goal(black_box(&goals[i]), &options))
        })
    });
}

/// The IK on the models of the unmodelled-effects study (module docs).
fn bench_unmodelled(c: &mut Criterion) {
    let nominal = preset("ys100").unwrap();
    let truth = unmodelled_truth(&nominal, true, 1);
    let mut rng = ChaCha8Rng::seed_from_u64(101);
    let ident = measure_truth(&truth, &nominal, 100, &mut rng);
    let train = measure_truth(&truth, &nominal, 1000, &mut rng);
    let valid = measure_truth(&truth, &nominal, 200, &mut rng);
    let methods = [
        Method::Skcm,
        Method::SkcmNn,
        Method::SkcmGp,
        Method::SkcmMaps,
        Method::SkcmMapsGp,
    ];
    let options = CalibrationOptions {
        methods: methods.to_vec(),
        compensator: CompensatorOptions {
            seed: 1,
            cv_folds: 0,
            ..Default::default()
        },
        ..Default::default()
    };
    let report =
        calibrate_with_training(&nominal, &ident, &train, &valid, &options, &|_| true).unwrap();
    let qs = random_configurations(&nominal, 1000, &mut ChaCha8Rng::seed_from_u64(5));
    let mut g = c.benchmark_group("ik_unmodelled");
    for method in methods {
        let r = &report.methods[method.name()];
        let m = CompensatedModel {
            calibrated: r.calibrated.clone(),
            nominal: nominal.clone(),
            cell_from_base: report.tracker_to_base.inverse(),
            payload_kg: nominal.payload.mass,
            compensator: r.compensator_arc(),
        };
        bench_ik(&mut g, &format!("solve_{}", method.name()), &m, &qs);
    }
    g.finish();
}

fn bench(c: &mut Criterion) {
    let cm = synthetic_calibration(
        &preset("ys100").unwrap(),
        &SyntheticErrors::typical(1e-6),
        3,
    );
    let specs = [
        ("lm_18-20-3", CompensatorSpec::skcm_nn()),
        ("iwo_18-40-3", CompensatorSpec::skcm_iwonn()),
        ("tlbo_18-40-3", CompensatorSpec::skcm_tlbonn()),
        ("rbf", CompensatorSpec::km_rbf()),
    ];
    for n in [50, 1000] {
        let s = samples(&cm, n, 2);
        let mut g = c.benchmark_group(format!("train_{n}"));
        g.sample_size(10);
        for (name, spec) in &specs {
            g.bench_function(*name, |b| b.iter(|| black_box(fit(spec, black_box(&s)))));
        }
        g.finish();
    }

    for n in [1500, 10_000] {
        let s = samples(&cm, n, 2);
        let mut g = c.benchmark_group(format!("train_{n}"));
        g.sample_size(10);
        let gp = CompensatorSpec::Gp(Default::default());
        g.bench_function("gp", |b| b.iter(|| black_box(fit(&gp, black_box(&s)))));
        g.finish();
    }

    let s = samples(&cm, 1000, 2);
    let net = fit(&CompensatorSpec::skcm_nn(), &s).into_arc_oriented(None, None);
    let gp = fit(&CompensatorSpec::Gp(Default::default()), &s).into_arc_oriented(None, None);
    let qs: Vec<Vec<f64>> = s.iter().map(|s| s.q.clone()).collect();
    let tau = vec![0.0; 6];
    let mut g = c.benchmark_group("predict");
    let mut i = 0;
    g.bench_function("mlp_18-20-3_residual", |b| {
        b.iter(|| {
            i = (i + 1) % qs.len();
            black_box(net.residual(black_box(&qs[i]), &tau))
        })
    });
    let mut i = 0;
    g.bench_function("mlp_18-20-3_residual_and_dq", |b| {
        b.iter(|| {
            i = (i + 1) % qs.len();
            let q = black_box(&qs[i]);
            black_box((net.residual(q, &tau), net.jacobian_q(q, &tau, 110.0)))
        })
    });
    let mut i = 0;
    g.bench_function("gp_residual", |b| {
        b.iter(|| {
            i = (i + 1) % qs.len();
            black_box(gp.residual(black_box(&qs[i]), &tau))
        })
    });
    let mut i = 0;
    let mut dq = vec![Vector3::zeros(); 6];
    g.bench_function("gp_residual_and_dq", |b| {
        b.iter(|| {
            i = (i + 1) % qs.len();
            let q = black_box(&qs[i]);
            black_box(gp.residual_and_jacobian(q, &tau, 110.0, &mut dq))
        })
    });
    let mut i = 0;
    g.bench_function("gp_residual_and_dq_rough", |b| {
        b.iter(|| {
            i = (i + 1) % qs.len();
            let q = black_box(&qs[i]);
            black_box(gp.residual_and_jacobian_rough(q, &tau, 110.0, &mut dq))
        })
    });
    g.finish();

    let compensated = CompensatedModel {
        compensator: Some(Arc::clone(&net)),
        ..cm.clone()
    };
    let with_gp = CompensatedModel {
        compensator: Some(Arc::clone(&gp)),
        ..cm.clone()
    };
    let mut with_maps = cm.clone();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let arcsec = 1f64.to_radians() / 3600.0;
    with_maps.calibrated.joint_maps = Some(JointMaps {
        joints: (0..6)
            .map(|_| {
                Some(JointMap {
                    cos: (0..80)
                        .map(|_| rng.gen_range(-10.0..10.0) * arcsec)
                        .collect(),
                    sin: (0..80)
                        .map(|_| rng.gen_range(-10.0..10.0) * arcsec)
                        .collect(),
                    range: [-3.2, 3.2],
                    fade: 0.087,
                })
            })
            .collect(),
    });
    let mut g = c.benchmark_group("ik");
    for (name, m) in [
        ("solve_plain", &cm),
        ("solve_compensated", &compensated),
        ("solve_gp", &with_gp),
        ("solve_maps", &with_maps),
    ] {
        bench_ik(&mut g, name, m, &qs);
    }
    g.finish();
}

criterion_group!(benches, bench, bench_unmodelled);
criterion_main!(benches);
