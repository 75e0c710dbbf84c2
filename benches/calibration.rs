//! Calibration benchmarks (YS100, one core): KM with 50 and 1000 poses, SKCM, and
//! SKCM-C by TLBO (population 50, 100 generations), each through the whole
//! `identify::calibrate` pipeline (checks, registration, identifiability, fit).

use criterion::{criterion_group, criterion_main, Criterion};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal::calibrate::identify::{calibrate, CalibrationOptions, Method};
use robocal::measure::{self, Measurement};
use robocal::model::preset;
use robocal::sim::{perturb_geometry, random_configurations, ErrorMagnitudes, TrueRobot};

fn data(n: usize) -> Vec<Measurement> {
    let nominal = preset("ys100").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(n as u64);
    let mut tm = perturb_geometry(&nominal, &ErrorMagnitudes::from_mm_deg(1.0, 0.1), &mut rng);
    for (k, l) in tm.links.iter_mut().enumerate() {
        l.compliance = if (1..5).contains(&k) { 1e-6 } else { 0.0 };
    }
    let mut truth = TrueRobot::new(tm);
    truth.noise_mm = 0.01;
    let qs = random_configurations(&nominal, n, &mut rng);
    let rows = truth.measure(&qs, Some(110.0), None, &mut rng).unwrap();
    measure::to_measurements(&nominal, &rows, 110.0)
}

fn bench(c: &mut Criterion) {
    let nominal = preset("ys100").unwrap();
    let mut g = c.benchmark_group("calibrate_ys100");
    g.sample_size(10);
    for (label, n, method) in [
        ("km_50_poses", 50, Method::Km),
        ("km_1000_poses", 1000, Method::Km),
        ("skcm_50_poses", 50, Method::Skcm),
        ("skcm_tlbo_30_poses_pop50_gen100", 30, Method::SkcmTlbo),
    ] {
        let d = data(n);
        let opts = CalibrationOptions {
            methods: vec![method],
            ..Default::default()
        };
        g.bench_function(label, |b| {
            b.iter(|| calibrate(&nominal, &d, &[], &opts, &|_| true).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
