//! `robocal demo ys100-simulation`: runs the thesis's simulation study of §7.4
//! (`crate::sim::study::ys100_simulation`, whose doc states its set-up) and prints
//! the Table 7.5 comparison of KM, SKCM and SKCM-C and the identified
//! stiffness next to the truth.

use super::progress::ProgressPrinter;
use crate::calibrate::identify::Method;
use crate::sim::study::ys100_simulation;
use anyhow::bail;
use clap::Args;

/// Arguments of `robocal demo`.
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

/// Runs the study named (only `ys100-simulation`) and prints its comparison (text, or the
/// report as JSON with `--json`).
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
        "YS100 simulation study (thesis §7.4): truth = Table 7.1 geometry + Table 7.2 stiffness,"
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
    for method in Method::THESIS {
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
