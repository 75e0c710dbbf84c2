//! `robocal demo ys100-simulation`: the seed's simulation study of §7.4 end to
//! end. The true robot is seed Table 7.1 with the stiffness of Table 7.2
//! (`sim::ys100_table_7_1`, whose doc states how the table is read), measured
//! with σ = 0.01 mm tracker noise at 30 identification poses (chosen D-optimally
//! among 500 random in-limit poses) and 45 random validation poses
//! with the 110 kg payload; KM, SKCM and SKCM-C by TLBO are compared as in
//! Table 7.5 and the identified stiffness is printed next to the truth.

use super::progress::ProgressPrinter;
use crate::identify::pose_selection::choose_d_optimal;
use crate::identify::{calibrate, CalibrationOptions, CalibrationReport, Method};
use crate::measure;
use crate::model::{preset, RobotModel};
use crate::sim::{random_configurations, ys100_table_7_1, TrueRobot};
use anyhow::bail;
use clap::Args;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

#[derive(Debug, Args)]
pub struct DemoArgs {
    /// The study to run: ys100-simulation.
    pub name: String,
    /// Random seed of poses, noise and TLBO.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Print the full report as JSON.
    #[arg(long)]
    pub json: bool,
}

/// The §7.4 study's inputs and result.
pub struct Ys100Study {
    pub nominal: RobotModel,
    pub truth: RobotModel,
    pub report: CalibrationReport,
}

/// Runs the seed's §7.4 simulation study with the given seed.
pub fn ys100_simulation(
    seed: u64,
    progress: &dyn Fn(&crate::identify::Progress) -> bool,
) -> anyhow::Result<Ys100Study> {
    let nominal = preset("ys100")?;
    let truth_model = ys100_table_7_1();
    let mut truth = TrueRobot::new(truth_model.clone());
    truth.noise_mm = 0.01;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let payload = nominal.payload.mass;
    // 30 identification poses chosen for D-optimality among 500 random ones that
    // cover the workspace; 45 validation poses drawn at random.
    let candidates = random_configurations(&nominal, 500, &mut rng);
    let q_id = choose_d_optimal(&nominal, &candidates, 30, payload, true);
    let q_va = random_configurations(&nominal, 45, &mut rng);
    let rows_id = truth.measure(&q_id, Some(payload), None, &mut rng)?;
    let rows_va = truth.measure(&q_va, Some(payload), None, &mut rng)?;
    let ident = measure::to_measurements(&nominal, &rows_id, payload);
    let valid = measure::to_measurements(&nominal, &rows_va, payload);
    let mut opts = CalibrationOptions {
        methods: Method::MODEL_BASED.to_vec(),
        ..Default::default()
    };
    opts.tlbo.seed = seed;
    let report = calibrate(&nominal, &ident, &valid, &opts, progress)?;
    Ok(Ys100Study {
        nominal,
        truth: truth_model,
        report,
    })
}

pub fn run(a: DemoArgs) -> anyhow::Result<()> {
    if a.name != "ys100-simulation" {
        bail!("unknown demo `{}` (available: ys100-simulation)", a.name);
    }
    let progress = ProgressPrinter::stderr(!a.json);
    let study = ys100_simulation(a.seed, &|p| {
        progress.update(p);
        true
    });
    progress.finish();
    let study = study?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&study.report)?);
        return Ok(());
    }
    let r = &study.report;
    println!(
        "YS100 simulation study (seed §7.4): truth = Table 7.1 geometry + Table 7.2 stiffness,"
    );
    println!("payload 110 kg, tracker noise 0.01 mm per axis, 30 identification poses (D-optimal among 500 random) / 45 random validation poses.\n");
    println!("Table 7.5 equivalent: absolute position accuracy on the validation poses (mm)");
    println!("{:<22} {:>9} {:>9} {:>9}", "", "Mean", "Max.", "Std.");
    let row = |label: &str, s: &crate::stats::ErrorStats| {
        println!(
            "{:<22} {:>9.4} {:>9.4} {:>9.4}",
            label, s.mean_mm, s.max_mm, s.std_mm
        );
    };
    if let Some(v) = &r.nominal.validation {
        row("Nominal robot model", &v.stats);
    }
    for method in Method::SEED {
        if let Some(v) = r.methods.get(&method).and_then(|m| m.validation.as_ref()) {
            row(method.label(), &v.stats);
        }
    }
    println!("\nStiffness (N·m/rad), Table 7.4 equivalent");
    println!(
        "{:<16} {:>12} {:>12} {:>12} {:>12}",
        "", "K2", "K3", "K4", "K5"
    );
    let truth_k: Vec<f64> = (1..5)
        .map(|k| 1.0 / study.truth.links[k].compliance)
        .collect();
    println!(
        "{:<16} {:>12.4e} {:>12.4e} {:>12.4e} {:>12.4e}",
        "truth", truth_k[0], truth_k[1], truth_k[2], truth_k[3]
    );
    for method in [Method::Skcm, Method::SkcmTlbo] {
        let label = method.label();
        if let Some(m) = r.methods.get(&method) {
            let ks: Vec<String> = (1..5)
                .map(|k| match m.stiffness_nm_per_rad[k] {
                    Some(v) => format!("{:>12.4e}", v),
                    None => format!("{:>12}", "-"),
                })
                .collect();
            println!("{:<16} {}", label, ks.join(" "));
            let acc: Vec<String> = (1..5)
                .map(|k| match m.stiffness_nm_per_rad[k] {
                    Some(v) => format!(
                        "{:>11.2}%",
                        100.0 * (1.0 - ((v - truth_k[k - 1]) / truth_k[k - 1]).abs())
                    ),
                    None => format!("{:>12}", "-"),
                })
                .collect();
            println!("{:<16} {}", "  precision", acc.join(" "));
        }
    }
    println!();
    print!("{}", crate::cli::calibrate::render_report(r));
    Ok(())
}
