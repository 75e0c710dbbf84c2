//! TLBO vs IWO vs LM backpropagation over 20 seeds (issue 9): the YS100 study
//! truth of `compensate::unmodelled_truth` (unmodelled effects on), 1000
//! training poses identified by SKCM, 200 validation poses; each trainer runs
//! with seeds 0–19 on the same residuals. Prints per trainer the validation
//! mean error [mm] after compensation (mean, min, max over seeds) and the wall
//! time per training run [s].
//!
//! Run: `cargo run --release -p robocal-core --example compare_trainers [seeds]`
//! (release: the population trainers of the 18-40-3 network take minutes per
//! seed in the dev profile). `COMPARE_TRAINERS=iwo,tlbo` runs only the
//! trainers whose name contains one of the comma-separated words
//! (case-insensitive); `COMPARE_PER_SEED=1` also prints, per seed, the
//! validation mean, its gain against SKCM and the training run's stop reason.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal_core::calibrate::compensate::{
    samples_of, train, CompensatorSpec, IwoSettings, LmTrainSettings, MlpSettings, MlpSpec,
    OutputLayer, TlboTrainSettings, Trainer,
};
use robocal_core::calibrate::identify::{calibrate, CalibrationOptions, Method};
use robocal_core::measure::{self, Measurement};
use robocal_core::model::calibrated::CompensatedModel;
use robocal_core::model::preset;
use robocal_core::sim::random_configurations;
use robocal_core::sim::unmodelled_truth;
use std::time::Instant;

fn main() {
    let seeds: u64 = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(20);
    let filter: Vec<String> = std::env::var("COMPARE_TRAINERS")
        .unwrap_or_default()
        .split(',')
        .map(|w| w.trim().to_lowercase())
        .filter(|w| !w.is_empty())
        .collect();
    let selected = |name: &str| {
        let name = name.to_lowercase();
        filter.is_empty() || filter.iter().any(|w| name.contains(w.as_str()))
    };
    let per_seed = std::env::var("COMPARE_PER_SEED").is_ok_and(|v| v == "1");
    let nominal = preset("ys100").unwrap();
    let truth = unmodelled_truth(&nominal, true, 1);
    let mut rng = ChaCha8Rng::seed_from_u64(101);
    let payload = nominal.payload.mass;
    let mut draw = |n| -> Vec<Measurement> {
        let qs = random_configurations(&nominal, n, &mut rng);
        let rows = truth.measure(&qs, Some(payload), None, &mut rng).unwrap();
        measure::to_measurements(&nominal, &rows, payload)
    };
    let train_set = draw(1000);
    let valid = draw(200);
    let opts = CalibrationOptions {
        methods: vec![Method::Skcm],
        ..Default::default()
    };
    let r = calibrate(&nominal, &train_set, &valid, &opts, &|_| true).unwrap();
    let base = CompensatedModel {
        calibrated: r.methods["skcm"].calibrated.clone(),
        nominal: nominal.clone(),
        cell_from_base: r.tracker_to_base.inverse(),
        payload_kg: payload,
        compensator: None,
    };
    let samples = samples_of(&base, &train_set).unwrap();
    let vsamples = samples_of(&base, &valid).unwrap();
    let base_mean =
        vsamples.iter().map(|s| s.residual.norm()).sum::<f64>() / vsamples.len() as f64 * 1e3;
    println!("SKCM validation mean {base_mean:.4} mm (1000 training poses, 200 validation poses, {seeds} seeds)");
    println!("| trainer | network | validation mean [mm] (mean / min / max over seeds) | wall time per run [s] |");
    println!("|---|---|---|---|");
    for (name, net, spec) in trainers() {
        if !selected(name) {
            continue;
        }
        let mut errs = Vec::new();
        let mut secs = 0.0;
        for seed in 0..seeds {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let t0 = Instant::now();
            let (c, rep) = train(&spec, &samples, &mut rng, &mut |_, _| true).unwrap();
            secs += t0.elapsed().as_secs_f64();
            let c = c.into_arc();
            let e = vsamples
                .iter()
                .map(|s| (s.residual - c.residual_at(&s.q, &s.tau, s.payload_kg)).norm())
                .sum::<f64>()
                / vsamples.len() as f64
                * 1e3;
            if per_seed {
                println!(
                    "  seed {seed}: {e:.4} mm, gain {:.1} %, loss {:.4e}, {} evaluations, {}",
                    (1.0 - e / base_mean) * 100.0,
                    rep.loss,
                    rep.evaluations,
                    rep.stop
                );
            }
            errs.push(e);
        }
        let mean = errs.iter().sum::<f64>() / errs.len() as f64;
        let min = errs.iter().cloned().fold(f64::INFINITY, f64::min);
        let max = errs.iter().cloned().fold(0.0, f64::max);
        println!(
            "| {name} | {net} | {mean:.4} / {min:.4} / {max:.4} | {:.3} |",
            secs / seeds as f64
        );
    }
}

/// The trainers compared: a name, the network they train and its settings.
fn trainers() -> Vec<(&'static str, &'static str, CompensatorSpec)> {
    let lm_small = CompensatorSpec::Mlp(MlpSettings {
        spec: MlpSpec::SMALL,
        trainer: Trainer::Lm(LmTrainSettings::default()),
    });
    let searched = |trainer| {
        CompensatorSpec::Mlp(MlpSettings {
            spec: MlpSpec::SMALL,
            trainer,
        })
    };
    let iwo_mean_only = CompensatorSpec::Mlp(MlpSettings {
        spec: MlpSpec::POPULATION,
        trainer: Trainer::Iwo(IwoSettings {
            max_weight: 0.0,
            ..Default::default()
        }),
    });
    vec![
        (
            "LM backprop (SKCM-NN)",
            "18-20-3 (q, sin q, cos q)",
            CompensatorSpec::skcm_nn(),
        ),
        ("LM backprop", "6-5-3", lm_small),
        (
            "IWO (SKCM-IWONN)",
            "18-40-3, output layer by least squares",
            CompensatorSpec::skcm_iwonn(),
        ),
        (
            "TLBO (SKCM-TLBONN)",
            "18-40-3, output layer by least squares",
            CompensatorSpec::skcm_tlbonn(),
        ),
        (
            "IWO, loss mean(E) instead of eq. 5.7",
            "18-40-3, output layer by least squares",
            iwo_mean_only,
        ),
        (
            "IWO, every weight searched",
            "6-5-3 (the thesis's)",
            searched(Trainer::Iwo(IwoSettings {
                output_layer: OutputLayer::Searched,
                ..Default::default()
            })),
        ),
        (
            "TLBO, every weight searched",
            "6-5-3 (the thesis's)",
            searched(Trainer::Tlbo(TlboTrainSettings {
                output_layer: OutputLayer::Searched,
                ..Default::default()
            })),
        ),
    ]
}
