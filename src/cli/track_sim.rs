//! `robocal track simulate`: a robot on the example 4 m track
//! (`sim::track::TrueTrack::rail_4m`) measured by a simulated tracker,
//! written as the files `track calibrate` reads, so a track cell can be
//! tried without one at hand.
//!
//! `track simulate --out-dir DIR --robot MODEL [--seed S] [--noise-mm σ]
//! [--poses N]` writes, in `DIR`:
//!
//! - `stations.csv`: the reflector at `N` random poses at each of the 11
//!   stations 0, 400, …, 4000 mm (`q1..qN` controller degrees, `e1` the
//!   track's value [mm], `x, y, z` [mm] in the tracker frame);
//! - `validate.csv`: 8 poses at each of five values between the stations
//!   (200, 1000, 1800, 2600, 3400 mm), held out of the fit;
//! - `drawing.json`: the track the controller computes from its drawing
//!   (`TrueTrack::drawing_4m`: scale 1, straight, no carriage angles), the
//!   filter's `--nominal-track`;
//! - a program for `filter --track` (`super::track_part`): `cell.json` (the
//!   torch and base 2, a part beside the rail measured in the cell frame),
//!   `part.src` and `part.dat` (a weld along it, each target at the track
//!   value that puts the robot beside it); a target out of the robot's
//!   reach is left out, named in the output, and a robot that reaches none
//!   gets no program, the output saying why;
//!
//! and prints the `track calibrate` command that fits them.
//!
//! The robot on the carriage is `MODEL`'s calibrated geometry, exactly (its
//! own errors are the robot calibration's business); what is simulated is
//! the track, from its physics and with what the fitted model lacks: rails
//! bent by sines no polynomial map holds exactly, a carriage on bearing
//! blocks 0.6 m apart yawing and pitching with them, a rail rising 0.1°,
//! the rack's scale off by 0.2 mm/m. Randomness: the poses and the
//! tracker's noise from `ChaCha8Rng(seed)`, one stream per file.

use super::model_files::load_compensated;
use super::sim_files::{check_noise, left_out_note, list, OutDir};
use super::track_part::track_program;
use anyhow::Context;
use clap::Args;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal_core::measure::csv::write_set;
use robocal_core::measure::external::ExternalAxis;
use robocal_core::sim::track::TrueTrack;
use robocal_core::sim::{random_configurations, TrueRobot};
use std::fmt::Write as _;

/// The fitted stations [mm]: every 400 mm over the 4 m.
const STATIONS_MM: [f64; 11] = [
    0.0, 400.0, 800.0, 1200.0, 1600.0, 2000.0, 2400.0, 2800.0, 3200.0, 3600.0, 4000.0,
];
/// Held-out values [mm], between the stations.
const HELD_OUT_MM: [f64; 5] = [200.0, 1000.0, 1800.0, 2600.0, 3400.0];
/// Poses at each held-out value.
const HELD_OUT_POSES: usize = 8;

/// Arguments of `robocal track simulate`.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// Directory to write the files into (created when missing).
    #[arg(long)]
    pub out_dir: String,
    /// The robot on the carriage: a calibrated model file, a model JSON or a
    /// preset (the same `--model` the printed `track calibrate` takes).
    #[arg(long)]
    pub robot: String,
    /// Seed of the poses and the tracker's noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// The tracker's noise per coordinate, 1σ [mm].
    #[arg(long, default_value_t = 0.01)]
    pub noise_mm: f64,
    /// Robot poses at each station (at least 3).
    #[arg(long, default_value_t = 15)]
    pub poses: usize,
}

/// Writes the files; what the command prints (the files and how to fit them).
pub fn simulate_to_string(a: &SimulateArgs) -> anyhow::Result<String> {
    check_noise(a.noise_mm)?;
    if !(3..=1000).contains(&a.poses) {
        anyhow::bail!(
            "--poses {}: give 3 to 1000 poses per station (the fit needs 3 not on a line at each)",
            a.poses
        );
    }
    let model = load_compensated(&a.robot).with_context(|| format!("--robot {}", a.robot))?;
    let mut robot = TrueRobot::new(model.calibrated.clone());
    robot.noise_mm = a.noise_mm;
    let track = TrueTrack::rail_4m();
    let dir = OutDir::create(&a.out_dir)?;
    let write = |name: &str, text: &str| dir.write(name, text);
    let set = |stream: u64, values: &[f64], n: usize| -> anyhow::Result<String> {
        let mut rng = ChaCha8Rng::seed_from_u64(a.seed);
        rng.set_stream(stream);
        let stations: Vec<(f64, Vec<Vec<f64>>)> = values
            .iter()
            .map(|v| (*v, random_configurations(&model.nominal, n, &mut rng)))
            .collect();
        let set = track
            .measure(
                &robot,
                ExternalAxis::E1,
                &stations,
                Some(model.payload_kg),
                &mut rng,
            )
            .context("the simulated tracker")?;
        Ok(write_set(&set))
    };
    let stations = write("stations.csv", &set(0, &STATIONS_MM, a.poses)?)?;
    let validate = write("validate.csv", &set(1, &HELD_OUT_MM, HELD_OUT_POSES)?)?;
    let drawing = write("drawing.json", &TrueTrack::drawing_4m().to_json())?;
    let mut written = vec![stations.clone(), validate.clone(), drawing];
    let mut notes = Vec::new();
    match track_program(&model, &TrueTrack::drawing_4m()) {
        Ok(program) => {
            for (name, text) in [
                ("cell.json", &program.cell),
                ("part.src", &program.src),
                ("part.dat", &program.dat),
            ] {
                written.push(write(name, text)?);
            }
            notes.extend(program.left_out.iter().map(|t| left_out_note(t)));
        }
        Err(why) => notes.push(format!(
            "no program beside the rail (cell.json, part.src, part.dat): {why}"
        )),
    }
    let mut out = String::new();
    writeln!(
        out,
        "simulated track: 4 m, {} poses at each of {} stations, {HELD_OUT_POSES} at each of {} held-out values; tracker noise {} mm",
        a.poses,
        STATIONS_MM.len(),
        HELD_OUT_MM.len(),
        a.noise_mm
    )?;
    list(&mut out, &written, &notes);
    writeln!(
        out,
        "fit it with: robocal track calibrate {stations} --model {} --validate {validate} --out track.json",
        a.robot
    )?;
    Ok(out)
}
