//! `robocal turntable`: a one-axis turntable (or headstock) carrying the
//! part, its own type (`model::external::Turntable`).
//!
//! `turntable calibrate SET… --nominal NOMINAL.json --reflector X,Y,Z…
//! --out TURNTABLE.json` reads one measurement file per reflector on the
//! face plate (the axis's value in degrees in one `e` column, `--column`,
//! default `e1`; `x, y, z` mm in the tracker frame; no joints), fits the
//! axis's line, zero offset and scale and the reflectors' positions
//! (`calibrate::external::turntable`), judges the fit before writing it
//! (`--sigma-mm`, the tracker's noise, default 0.01) and, with `--validate`
//! (the k-th file reflector k's), predicts held-out readings through it. A
//! refused fit writes nothing and exits 1 naming its reason (`--json`: the
//! refusal as JSON on stdout).
//!
//! `turntable simulate --out-dir DIR` writes the example turntable
//! (`sim::turntable_example`) measured by a simulated tracker: the nominal
//! JSON, `r0.csv`, `r1.csv` (the fit's readings) and `v0.csv`, `v1.csv`
//! (held out), and prints the command that fits them. Randomness: the
//! tracker's noise from `ChaCha8Rng(seed)`, a stream per file.

use super::judged_fit;
use super::positioner::{parse_axis, reflectors_of};
use super::sim_files::{check_noise, list, OutDir};
use crate::service::positioners::ReadingsFrom;
use crate::service::turntables::{held_out, HeldOut};
use anyhow::Context;
use clap::{Args, Subcommand};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal_core::calibrate::external::readings::turntable_readings;
use robocal_core::calibrate::external::turntable::{
    fit_turntable, TurntableFit, TurntableFitRequest, TurntableReading, TurntableRefused,
};
use robocal_core::measure::csv::{parse_set, write_set};
use robocal_core::measure::external::ExternalAxis;
use robocal_core::model::external::Turntable;
use robocal_core::sim::turntable_example as example;
use serde::Serialize;
use std::fmt::Write as _;

/// Arguments of `robocal turntable`.
#[derive(Debug, Args)]
pub struct TurntableArgs {
    /// The turntable subcommand to run.
    #[command(subcommand)]
    pub command: TurntableCommand,
}

/// The subcommands of `robocal turntable`.
#[derive(Debug, Subcommand)]
pub enum TurntableCommand {
    /// Fit a one-axis turntable from tracker readings of reflectors on its face plate.
    Calibrate(CalibrateArgs),
    /// Write an example turntable's nominal model and simulated tracker readings (the files `calibrate` reads).
    Simulate(SimulateArgs),
}

/// Arguments of `robocal turntable calibrate`.
#[derive(Debug, Args)]
pub struct CalibrateArgs {
    /// Measurement CSVs, one per reflector in the order of --reflector: the
    /// axis's value (degrees) in its column and `x,y,z` (mm, tracker
    /// frame); the axis turned over ≥ 90° at ≥ 4 values.
    #[arg(required = true)]
    pub sets: Vec<String>,
    /// The nominal turntable (JSON, mm and degrees, the description this
    /// command writes): the start and the frames the fit is stated in.
    #[arg(long)]
    pub nominal: String,
    /// A reflector's design position on the face plate, `x,y,z` [mm, face
    /// plate frame], once per file; the first is the reference.
    #[arg(long, required = true, allow_hyphen_values = true)]
    pub reflector: Vec<String>,
    /// Where to write the calibrated turntable (JSON, mm, degrees).
    #[arg(long)]
    pub out: String,
    /// The axis's column, e1 … e6.
    #[arg(long, default_value = "e1", value_parser = parse_axis)]
    pub column: ExternalAxis,
    /// The tracker's noise per coordinate, 1σ [mm]: the fit is judged against it.
    #[arg(long, default_value_t = 0.01)]
    pub sigma_mm: f64,
    /// Held-out readings (same column), the k-th file of reflector k,
    /// predicted through the fitted turntable.
    #[arg(long)]
    pub validate: Vec<String>,
    /// Print the outcome as JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

/// A fit the readings cannot carry: its reason and message (nothing is written).
#[derive(Debug, thiserror::Error)]
#[error("not fitted ({}): {}", judged_fit::code(&.0.reason), .0.message)]
pub struct TurntableNotFitted(pub Box<TurntableRefused>);

/// Held-out readings predicted through the fitted turntable [mm]: the
/// files and the figures the service gives for the same readings.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Validation {
    /// The held-out files, the k-th of reflector k.
    pub files: Vec<String>,
    /// Their readings' figures through the fitted turntable.
    #[serde(flatten)]
    pub held_out: HeldOut,
}

/// Every file's rows as readings of its reflector (the file's index).
fn read_readings(files: &[String], column: ExternalAxis) -> anyhow::Result<Vec<TurntableReading>> {
    let mut out = Vec::new();
    for (k, path) in files.iter().enumerate() {
        let text = std::fs::read_to_string(path).with_context(|| format!("cannot read {path}"))?;
        let set = parse_set(&text).with_context(|| path.clone())?;
        out.extend(turntable_readings(&set, column, k).with_context(|| path.clone())?);
    }
    Ok(out)
}

fn validate(
    files: &[String],
    column: ExternalAxis,
    fit: &TurntableFit,
) -> anyhow::Result<Validation> {
    let readings = read_readings(files, column)?;
    let held_out = held_out(&readings, fit).context("--validate: no readings")?;
    Ok(Validation {
        files: files.to_vec(),
        held_out,
    })
}

/// Fits, judges, validates and writes the turntable; what the command prints.
pub fn calibrate_to_string(a: &CalibrateArgs) -> anyhow::Result<String> {
    let reflectors_mm = reflectors_of(&a.sets, &a.reflector, &a.validate)?;
    let text = std::fs::read_to_string(&a.nominal)
        .with_context(|| format!("cannot read nominal turntable {}", a.nominal))?;
    let nominal =
        Turntable::from_json(&text).with_context(|| format!("nominal turntable {}", a.nominal))?;
    let request = TurntableFitRequest {
        nominal,
        reflectors_mm,
        readings: read_readings(&a.sets, a.column)?,
        tracker_sigma_mm: a.sigma_mm,
    };
    let fit = match fit_turntable(&request) {
        Ok(f) => f,
        Err(refused) => {
            judged_fit::print_refusal(a.json, &judged_fit::code(&refused.reason), &refused)?;
            return Err(TurntableNotFitted(Box::new(refused)).into());
        }
    };
    let validation = if a.validate.is_empty() {
        None
    } else {
        Some(validate(&a.validate, a.column, &fit)?)
    };
    let written = judged_fit::write_fitted(
        "turntable",
        &a.out,
        fit.model.to_json(),
        Some(&ReadingsFrom::Tracker),
        &fit,
        validation.as_ref(),
        a.json,
    )?;
    if let Some(json) = written {
        return Ok(json);
    }
    Ok(report(a, &request, &fit, validation.as_ref()))
}

fn report(
    a: &CalibrateArgs,
    request: &TurntableFitRequest,
    fit: &TurntableFit,
    v: Option<&Validation>,
) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "turntable fitted: {} readings of {} reflectors (column {}), nominal {}",
        request.readings.len(),
        request.reflectors_mm.len(),
        a.column,
        a.nominal
    );
    let (d, sigma) = (&fit.description.axis, &fit.sigma);
    let [ux, uy, uz] = d.direction;
    let [px, py, pz] = d.point_mm;
    let _ = writeln!(
        s,
        "axis: direction [{ux:.6}, {uy:.6}, {uz:.6}] (σ {:.5} deg), point [{px:.4}, {py:.4}, {pz:.4}] mm (σ {:.4} mm); \
         zero offset {:.5} deg (σ {:.5}); scale {:.6} (σ {:.1e})",
        sigma.direction_deg, sigma.point_mm, d.zero_offset_deg, sigma.zero_offset_deg, d.scale, sigma.scale
    );
    let l = &fit.limits;
    let _ = writeln!(
        s,
        "residuals: rms {:.4} mm, max {:.4} mm (limits: rms ≤ {:.4} mm, each ≤ {:.4} mm; σ {} mm per axis)",
        fit.rms_mm, fit.max_mm, l.rms_mm, l.max_mm, l.sigma_mm
    );
    let _ = writeln!(
        s,
        "solver: converged {}, {} iterations, start rms {:.4} mm",
        fit.solver.converged, fit.solver.iterations, fit.solver.start_rms_mm
    );
    let _ = writeln!(
        s,
        "circles (reflector, values, span deg, radius mm, rms mm):"
    );
    for c in &fit.circles {
        let _ = writeln!(
            s,
            "  {}  {:>3}  {:>7.2}  {:>9.3}  {:.4}",
            c.reflector + 1,
            c.angles,
            c.span_deg,
            c.radius_mm,
            c.rms_mm
        );
    }
    let _ = writeln!(
        s,
        "reflectors on the face plate (design → fitted mm, σ mm):"
    );
    for (k, (p, q)) in request
        .reflectors_mm
        .iter()
        .zip(&fit.reflectors_mm)
        .enumerate()
    {
        let _ = writeln!(
            s,
            "  {}: [{:.3}, {:.3}, {:.3}] → [{:.4}, {:.4}, {:.4}], σ {:.4}",
            k + 1,
            p[0],
            p[1],
            p[2],
            q[0],
            q[1],
            q[2],
            fit.reflector_sigma_mm[k]
        );
    }
    if let Some(v) = v {
        let _ = writeln!(
            s,
            "held out: {} readings at {} values ({}): rms {:.4} mm, max {:.4} mm",
            v.held_out.readings,
            v.held_out.values,
            v.files.join(", "),
            v.held_out.rms_mm,
            v.held_out.max_mm
        );
    }
    let _ = writeln!(s, "written: {}", a.out);
    s
}

/// Arguments of `robocal turntable simulate`.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// Directory to write the files into (created when missing).
    #[arg(long)]
    pub out_dir: String,
    /// Seed of the tracker's noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// The tracker's noise per coordinate, 1σ [mm].
    #[arg(long, default_value_t = 0.01)]
    pub noise_mm: f64,
    /// The axis's nod once per revolution [deg], an error the fitted model
    /// does not have.
    #[arg(long, default_value_t = 0.003)]
    pub wobble_deg: f64,
}

/// Writes the files; what the command prints (the files and how to fit them).
pub fn simulate_to_string(a: &SimulateArgs) -> anyhow::Result<String> {
    check_noise(a.noise_mm)?;
    if !(a.wobble_deg.is_finite() && a.wobble_deg.abs() <= 1.0) {
        anyhow::bail!(
            "--wobble-deg {}: give a nod of at most 1° (a finite number)",
            a.wobble_deg
        );
    }
    let mut truth = example::truth(a.wobble_deg);
    truth.noise_mm = a.noise_mm;
    let dir = OutDir::create(&a.out_dir)?;
    let mut written = vec![dir.write("nominal.json", &example::nominal().to_json())?];
    let mut stream = 0u64;
    let mut set = |name: String, k: usize, values: &[f64]| {
        let mut rng = ChaCha8Rng::seed_from_u64(a.seed);
        rng.set_stream(stream);
        stream += 1;
        let s = example::turntable_set(&truth, k, values, ExternalAxis::E1, &mut rng);
        dir.write(&name, &write_set(&s))
    };
    let k_all = 0..example::DESIGN_MM.len();
    let fits: Vec<String> = k_all
        .clone()
        .map(|k| set(format!("r{k}.csv"), k, &example::sweep()))
        .collect::<anyhow::Result<_>>()?;
    let held: Vec<String> = k_all
        .map(|k| set(format!("v{k}.csv"), k, &example::held_out()))
        .collect::<anyhow::Result<_>>()?;
    written.extend(fits.iter().cloned());
    written.extend(held.iter().cloned());
    let mut out = String::new();
    writeln!(
        out,
        "simulated turntable: {} readings per reflector over 330°, {} held out; tracker noise {} mm, axis nod {}°",
        example::sweep().len(),
        example::held_out().len(),
        a.noise_mm,
        a.wobble_deg
    )?;
    list(&mut out, &written, &[]);
    let reflectors: Vec<String> = example::DESIGN_MM
        .iter()
        .map(|p| format!("--reflector {},{},{}", p[0], p[1], p[2]))
        .collect();
    let validate: Vec<String> = held.iter().map(|v| format!("--validate {v}")).collect();
    writeln!(
        out,
        "fit it with: robocal turntable calibrate {} --nominal {} {} {} --out turntable.json",
        fits.join(" "),
        written[0],
        reflectors.join(" "),
        validate.join(" ")
    )?;
    Ok(out)
}

/// The turntable file `path` (`turntable calibrate --out`).
pub fn read_turntable(path: &str) -> anyhow::Result<Turntable> {
    let json = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read turntable file {path}"))?;
    Turntable::from_json(&json).with_context(|| format!("turntable file {path}"))
}

/// Runs `robocal turntable`.
pub fn run(a: TurntableArgs) -> anyhow::Result<()> {
    let out = match a.command {
        TurntableCommand::Calibrate(c) => calibrate_to_string(&c)?,
        TurntableCommand::Simulate(s) => simulate_to_string(&s)?,
    };
    print!("{out}");
    Ok(())
}
