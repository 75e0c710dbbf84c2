//! Program filtering per target, a KRL program of 40 targets on a YS100 with
//! a synthetic calibrated model (`SyntheticErrors::typical(1e-6)`): targets
//! the robot reaches (from the nominal model's forward kinematics of random
//! joints, with their `S`/`T` flags) against the same targets moved 3 m out
//! of the workspace. The cost of an unreachable target is quoted as a ratio
//! to a reached one (docs/guide/api.md, "The service: storage, routes and limits").
//!
//! Run: `cargo bench -p robocal-core --bench filter` (about 15 s).

use criterion::{criterion_group, criterion_main, Criterion};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use robocal_core::model::orientation::{rotation_to, OrientationConvention};
use robocal_core::model::preset;
use robocal_core::program::{filter, kuka_status, kuka_turn, Language, ProgramFile};
use robocal_core::sim::{synthetic_calibration, SyntheticErrors};
use robocal_core::solve::cell::Cell;
use robocal_core::solve::ik::{AnalyticIk, IkSettings};
use std::hint::black_box;
use std::time::Duration;

/// A KRL program of 40 targets, each `shift_mm` further along x than where
/// the nominal robot puts its flange at random joints.
fn program(shift_mm: f64) -> Vec<ProgramFile> {
    let nominal = preset("ys100").unwrap();
    let mut bare = nominal.clone();
    bare.tool = Default::default();
    let ik = AnalyticIk::new(&bare).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let mut src = String::from("DEF bench()\r\n$TOOL = $NULLFRAME\r\n$BASE = $NULLFRAME\r\n");
    let mut n = 0;
    while n < 40 {
        let q: Vec<f64> = bare
            .links
            .iter()
            .map(|l| rng.gen_range(l.limits[0] * 0.8..l.limits[1] * 0.8))
            .collect();
        let (Ok(p), Some(c)) = (
            robocal_core::model::kinematics::fk(&bare, &q),
            ik.configuration(&q),
        ) else {
            continue;
        };
        let deg: Vec<f64> = bare
            .joints_to_controller(&q)
            .iter()
            .map(|v| v.to_degrees())
            .collect();
        let abc = rotation_to(OrientationConvention::KukaAbc, &p.r);
        src.push_str(&format!(
            "LIN {{X {:.4},Y {:.4},Z {:.4},A {:.4},B {:.4},C {:.4},S {},T {}}}\r\n",
            p.p.x * 1e3 + shift_mm,
            p.p.y * 1e3,
            p.p.z * 1e3,
            abc[0],
            abc[1],
            abc[2],
            kuka_status(&deg, c),
            kuka_turn(&deg)
        ));
        n += 1;
    }
    src.push_str("END\r\n");
    vec![ProgramFile {
        name: "bench.src".into(),
        text: src,
    }]
}

fn bench(c: &mut Criterion) {
    let nominal = preset("ys100").unwrap();
    let model = synthetic_calibration(&nominal, &SyntheticErrors::typical(1e-6), 3);
    let cell = Cell::default();
    let settings = IkSettings::default();
    let mut g = c.benchmark_group("filter_krl_40");
    g.sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(5));
    for (name, shift) in [("reached", 0.0), ("unreachable", 3000.0)] {
        let files = program(shift);
        let out = filter(Language::Krl, &files, &cell, &model, &settings).unwrap();
        let r = &out.report;
        eprintln!("{name}: {} filtered, {} failed", r.filtered, r.failed);
        if shift == 0.0 {
            assert!(r.filtered >= 30, "{name}: {r:?}");
        } else {
            assert_eq!(r.failed, 40, "{name}");
        }
        g.bench_function(name, |b| {
            b.iter(|| filter(Language::Krl, black_box(&files), &cell, &model, &settings))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
