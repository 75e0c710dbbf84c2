//! `robocal simulate`: measure a simulated "true" robot and write the measurement
//! CSV (docs/design.md "Measurement CSV"; the thesis's §7.4 simulation study).
//!
//! ```text
//! robocal simulate --preset ys100 --poses 30 --noise-mm 0.01 --seed 1 --out q1.csv \
//!     [--truth truth.json] [--payload-kg M] [--set identification] \
//!     [--truth-from table-7-1|random|model.json] [--error-mm 0.5 --error-deg 0.05] \
//!     [--tracker "rx,ry,rz,x,y,z"]
//! ```
//!
//! - The truth defaults to `table-7-1` (`sim::ys100_table_7_1`, thesis Tables 7.1/7.2)
//!   for the `ys100` preset and to `random` otherwise (`sim::perturb_geometry`:
//!   uniform errors of ±error-mm / ±error-deg on every geometric parameter; the
//!   compliance of the nominal model is kept unless `--stiffness` is given). A
//!   model JSON path (e.g. a file written earlier with `--truth`) reuses a truth.
//! - Randomness: `--seed` drives the poses and the noise (separate ChaCha8
//!   streams); `--truth-seed` (default 0) drives the random truth, so sets measured
//!   with different `--seed` values see the same random robot.
//! - `--tracker "rx,ry,rz,x,y,z"` (deg, mm) is the pose of the robot base in the
//!   tracker frame: `x_tracker = Rz(rz)·Ry(ry)·Rx(rx)·x_base + (x, y, z)`.
//!   Positions in the CSV are in the tracker frame; joints are controller
//!   readings in degrees.
//! - The payload column is always written (default: the truth's payload mass).

use crate::measure::{csv, SetRole};
use crate::model::kinematics::fk;
use crate::model::RobotModel;
use crate::sim::{
    perturb_geometry, tracker_frame, try_random_configurations, ys100_table_7_1, ErrorMagnitudes,
    PoseFilter, TrueRobot, UnmodelledEffects,
};
use anyhow::{bail, Context};
use clap::Args;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal_core::csv_write::comment_line;

/// Arguments of `robocal simulate`.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// Nominal robot: a preset name (ys100, hh800, ur5, ur10) or a model JSON file.
    #[arg(long, default_value = "ys100")]
    pub preset: String,
    /// Number of measured poses.
    #[arg(long, default_value_t = 30)]
    pub poses: usize,
    /// Tracker noise, standard deviation per axis [mm].
    #[arg(long, default_value_t = 0.01)]
    pub noise_mm: f64,
    /// Seed of the poses and the noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Output measurement CSV (`-` for standard output).
    #[arg(long)]
    pub out: String,
    /// Also write the truth model (model JSON, loadable by `calibrate --model`).
    #[arg(long)]
    pub truth: Option<String>,
    /// Payload mass [kg] (default: the truth's payload).
    #[arg(long)]
    pub payload_kg: Option<f64>,
    /// Set role written in every row: identification, training, validation or check.
    #[arg(long)]
    pub set: Option<String>,
    /// Truth: table-7-1 (ys100 only), random, or a model JSON file.
    /// Default: table-7-1 for the ys100 preset, random otherwise.
    #[arg(long)]
    pub truth_from: Option<String>,
    /// Seed of the random truth (kept apart from --seed so several sets share a truth).
    #[arg(long, default_value_t = 0)]
    pub truth_seed: u64,
    /// Random truth: length error bound [mm].
    #[arg(long, default_value_t = 0.5)]
    pub error_mm: f64,
    /// Random truth: angle error bound [deg].
    #[arg(long, default_value_t = 0.05)]
    pub error_deg: f64,
    /// Pose of the robot base in the tracker frame: "rx,ry,rz,x,y,z" [deg, mm].
    #[arg(long, allow_hyphen_values = true)]
    pub tracker: Option<String>,
    /// Truth joint stiffness [N·m/rad], one per joint, 0 = rigid
    /// (e.g. "0,1.5e6,1e6,1.2e6,1e6,0"); replaces the truth's compliance.
    #[arg(long)]
    pub stiffness: Option<String>,
    /// Unmodelled: cubic spring term k2 [N·m/rad³] per joint (thesis eq. 7.3).
    #[arg(long)]
    pub nonlinear_k2: Option<String>,
    /// Unmodelled: gear transmission error "amplitude_deg,harmonic".
    #[arg(long)]
    pub gear_error: Option<String>,
    /// Unmodelled: backlash [deg], on the side of the gravity torque.
    #[arg(long, default_value_t = 0.0)]
    pub backlash_deg: f64,
    /// Unmodelled: link bending compliance [rad/(N·m²)] (see sim::UnmodelledEffects).
    #[arg(long, default_value_t = 0.0)]
    pub link_bending: f64,
    /// Transmission errors with fine structure, "amplitude_arcsec,harmonics": per
    /// joint harmonics 1..=harmonics of its own angle (amplitude/√k) and a
    /// motor-side term at k = 101 (sim::fine_transmission_errors), drawn from
    /// --truth-seed.
    #[arg(long)]
    pub transmission: Option<String>,
}

fn numbers(what: &str, s: &str) -> anyhow::Result<Vec<f64>> {
    s.split(',')
        .map(|x| {
            let v: f64 = x
                .trim()
                .parse()
                .with_context(|| format!("{what}: `{}` is not a number", x.trim()))?;
            if !v.is_finite() {
                bail!("{what}: `{}` is not finite", x.trim());
            }
            Ok(v)
        })
        .collect()
}

fn non_negative(what: &str, v: f64) -> anyhow::Result<()> {
    if !(v.is_finite() && v >= 0.0) {
        bail!("{what} must be a non-negative number, got {v}");
    }
    Ok(())
}

/// Builds the truth model and a label for the summary.
fn truth_model(a: &SimulateArgs, nominal: &RobotModel) -> anyhow::Result<(RobotModel, String)> {
    let is_ys100 = a.preset.eq_ignore_ascii_case("ys100");
    let from = a
        .truth_from
        .clone()
        .unwrap_or_else(|| if is_ys100 { "table-7-1" } else { "random" }.into());
    let (mut truth, label) = match from.to_ascii_lowercase().as_str() {
        "table-7-1" | "table_7_1" | "table7.1" => {
            if !is_ys100 {
                bail!(
                    "--truth-from table-7-1 is the thesis's simulated YS100 and needs --preset ys100 (got {})",
                    a.preset
                );
            }
            (ys100_table_7_1(), "table-7-1".to_string())
        }
        "random" => {
            non_negative("--error-mm", a.error_mm)?;
            non_negative("--error-deg", a.error_deg)?;
            let mag = ErrorMagnitudes::from_mm_deg(a.error_mm, a.error_deg);
            let mut rng = ChaCha8Rng::seed_from_u64(a.truth_seed);
            (
                perturb_geometry(nominal, &mag, &mut rng),
                format!(
                    "random ±{} mm/±{} deg, truth seed {}",
                    a.error_mm, a.error_deg, a.truth_seed
                ),
            )
        }
        _ => {
            let m = super::model_files::load_model(&from).with_context(|| {
                format!("--truth-from {from}: expected table-7-1, random or a model JSON file")
            })?;
            if m.dof() != nominal.dof() {
                bail!(
                    "--truth-from {from}: {} joints, the nominal model has {}",
                    m.dof(),
                    nominal.dof()
                );
            }
            (m, from.clone())
        }
    };
    if let Some(s) = &a.stiffness {
        let k = numbers("--stiffness", s)?;
        if k.len() != truth.dof() {
            bail!("--stiffness: {} values for {} joints", k.len(), truth.dof());
        }
        for (l, k) in truth.links.iter_mut().zip(&k) {
            non_negative("--stiffness", *k)?;
            l.compliance = if *k == 0.0 { 0.0 } else { 1.0 / k };
        }
        truth.assumptions.push(format!(
            "simulated truth: joint stiffness set to [{s}] N·m/rad (0 = rigid)"
        ));
    }
    Ok((truth, label))
}

fn effects(a: &SimulateArgs, dof: usize) -> anyhow::Result<UnmodelledEffects> {
    let nonlinear_k2 = match &a.nonlinear_k2 {
        Some(s) => {
            let k = numbers("--nonlinear-k2", s)?;
            if k.len() != dof {
                bail!("--nonlinear-k2: {} values for {dof} joints", k.len());
            }
            Some(k)
        }
        None => None,
    };
    let gear_error = match &a.gear_error {
        Some(s) => {
            let v = numbers("--gear-error", s)?;
            if v.len() != 2 || v[1] < 0.0 || v[1].fract() != 0.0 || v[1] > f64::from(u32::MAX) {
                bail!(
                    "--gear-error must be \"amplitude_deg,harmonic\" with an integer harmonic >= 0"
                );
            }
            Some((v[0].to_radians(), v[1] as u32))
        }
        None => None,
    };
    non_negative("--backlash-deg", a.backlash_deg)?;
    non_negative("--link-bending", a.link_bending)?;
    let transmission = match &a.transmission {
        Some(s) => {
            let v = numbers("--transmission", s)?;
            if v.len() != 2 || v[0] < 0.0 || v[1] < 1.0 || v[1] > 1000.0 || v[1].fract() != 0.0 {
                bail!("--transmission must be \"amplitude_arcsec,harmonics\" with amplitude >= 0 and an integer 1..1000 harmonics");
            }
            let mut rng = ChaCha8Rng::seed_from_u64(a.truth_seed.wrapping_add(7));
            crate::sim::fine_transmission_errors(dof, v[1] as u32, v[0], &mut rng)
        }
        None => Vec::new(),
    };
    Ok(UnmodelledEffects {
        nonlinear_k2,
        gear_error,
        hysteresis_rad: a.backlash_deg.to_radians(),
        link_bending: a.link_bending,
        transmission,
    })
}

/// Measures the simulated robot and writes the CSV to `--out` (`-`: standard output), and
/// the truth's model JSON to `--truth` when given.
pub fn run(a: SimulateArgs) -> anyhow::Result<()> {
    let nominal = super::model_files::load_model(&a.preset)?;
    if a.poses == 0 {
        bail!("--poses must be at least 1");
    }
    non_negative("--noise-mm", a.noise_mm)?;
    if let Some(p) = a.payload_kg {
        non_negative("--payload-kg", p)?;
    }
    let set = match &a.set {
        Some(s) => Some(
            SetRole::parse(s)
                .with_context(|| format!("--set must be {}, got {s}", SetRole::names()))?,
        ),
        None => None,
    };
    let tracker = match &a.tracker {
        Some(s) => {
            let v = numbers("--tracker", s)?;
            if v.len() != 6 {
                bail!(
                    "--tracker must be \"rx,ry,rz,x,y,z\" (deg, mm), got {} values",
                    v.len()
                );
            }
            tracker_frame(v[0], v[1], v[2], [v[3], v[4], v[5]])
        }
        None => crate::model::Pose::identity(),
    };
    let (truth_model, truth_label) = truth_model(&a, &nominal)?;
    let truth = TrueRobot {
        effects: effects(&a, truth_model.dof())?,
        model: truth_model,
        tracker_from_base: tracker,
        noise_mm: a.noise_mm,
    };
    let payload = a.payload_kg.unwrap_or(truth.model.payload.mass);

    // Poses are planned on the nominal model and must be reachable by the truth.
    let mut pose_rng = ChaCha8Rng::seed_from_u64(a.seed);
    pose_rng.set_stream(1);
    let qs = try_random_configurations(
        &nominal,
        a.poses,
        &PoseFilter::default(),
        &mut pose_rng,
        |q| truth.true_position(q, Some(payload)).is_ok(),
    )?;
    let mut noise_rng = ChaCha8Rng::seed_from_u64(a.seed);
    noise_rng.set_stream(2);
    let rows = truth.measure(&qs, Some(payload), set, &mut noise_rng)?;

    // Error of the nominal model against the measurements (tracker frame known here).
    let errs: Vec<f64> = qs
        .iter()
        .zip(&rows)
        .map(|(q, r)| {
            let p = tracker.transform_point(&fk(&nominal, q)?.p) * 1e3;
            Ok(((p.x - r.xyz_mm[0]).powi(2)
                + (p.y - r.xyz_mm[1]).powi(2)
                + (p.z - r.xyz_mm[2]).powi(2))
            .sqrt())
        })
        .collect::<Result<_, crate::model::kinematics::KinematicsError>>()?;
    let mean = errs.iter().sum::<f64>() / errs.len() as f64;
    let max = errs.iter().fold(0.0_f64, |m, e| m.max(*e));

    let t = a.tracker.as_deref().unwrap_or("0,0,0,0,0,0");
    let mut text = comment_line(&format!(
        "robocal simulate: nominal {}, truth {}, {} poses, noise {} mm, seed {}, payload {} kg",
        nominal.name, truth_label, a.poses, a.noise_mm, a.seed, payload
    ));
    text.push_str(&comment_line(&format!(
        "positions in mm in the tracker frame (base pose in tracker rx,ry,rz,x,y,z = {t}); joints are controller readings in deg"
    )));
    text.push_str(&csv::write(&rows));
    if a.out == "-" {
        print!("{text}");
    } else {
        std::fs::write(&a.out, &text).with_context(|| format!("cannot write {}", a.out))?;
    }
    if let Some(path) = &a.truth {
        std::fs::write(path, truth.model.to_json())
            .with_context(|| format!("cannot write {path}"))?;
    }
    eprintln!(
        "simulate: {} poses of {} (truth {}, noise {} mm, payload {} kg, seed {}) -> {}{}; nominal model error mean {:.4} mm, max {:.4} mm",
        a.poses,
        nominal.name,
        truth_label,
        a.noise_mm,
        payload,
        a.seed,
        a.out,
        a.truth
            .as_deref()
            .map(|p| format!(", truth -> {p}"))
            .unwrap_or_default(),
        mean,
        max
    );
    Ok(())
}
