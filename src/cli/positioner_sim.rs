//! `robocal positioner simulate`: the example positioner
//! (`sim::positioner_example`) measured by a simulated tracker, written as
//! the files `positioner calibrate` reads, so a positioner cell can be tried
//! without one at hand.
//!
//! `positioner simulate --out-dir DIR [--robot MODEL] [--seed S]
//! [--noise-mm σ] [--wobble-deg W]` writes, in `DIR`:
//!
//! - `nominal.json`: the nominal positioner (`model::external::TiltRotate`'s
//!   JSON, what the controller computes from the drawing);
//! - `r0.csv`, `r1.csv`: each reflector's readings over both axes' sweeps
//!   (axis 2 over 330° at axis 1 = 0, axis 1 over 180° at axis 2 = 0), `e1`
//!   the tilt and `e2` the rotate value [deg], `x, y, z` [mm] in the tracker
//!   frame;
//! - `v0.csv`, `v1.csv`: held-out readings with both axes moved together;
//! - `part.csv`: points of a part on the face plate (mm, face plate frame)
//!   at four pairs of axis values, a targets file for `solve --positioner`;
//! - with `--robot`, a program on the part for `filter --positioner`
//!   (`super::positioner_part`): `controller.json` (the nominal positioner
//!   where the controller holds it, in the robot's base frame), `cell.json`
//!   (the torch and base 3 on the face plate), `part.src` and `part.dat`
//!   (those points at those values, the flags the nominal controller's); a
//!   target out of the robot's reach is left out, named in the output, and
//!   a robot that reaches none gets no program, the output saying why.
//!
//! The truth has what the nominal model lacks: each axis tilted by 0.05° and
//! offset by ~0.5 mm, zero offsets of 0.3° and −0.4°, scale errors, the
//! reflectors 0.2–0.4 mm off their design positions, and the rotate axis
//! nodding by `--wobble-deg` once per revolution (a wobble the fitted model
//! cannot hold). With `--robot` (a calibrated model file, a model JSON or a
//! preset) the positioner stands 1.7 m in front of that robot's registered
//! base (turned 30°, its base 0.9 m below the robot's), in the cell frame the
//! robot is registered in; without it, where the example puts it. Randomness:
//! the tracker's noise from `ChaCha8Rng(seed)`, a stream per file.

use super::model_files::load_compensated;
use super::positioner_part::part_program;
use super::sim_files::{check_noise, left_out_note, list, OutDir};
use anyhow::Context;
use clap::Args;
use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal_core::calibrate::external::readings::PositionerColumns;
use robocal_core::measure::csv::write_set;
use robocal_core::measure::external::ExternalAxis;
use robocal_core::model::calibrated::CompensatedModel;
use robocal_core::model::external::TiltRotate;
use robocal_core::model::pose::rpy_matrix;
use robocal_core::model::Pose;
use robocal_core::sim::positioner::TruePositioner;
use robocal_core::sim::positioner_example::{held_out, nominal, sweeps, truth, DESIGN_MM};
use robocal_core::sim::positioner_sets::positioner_set;
use std::fmt::Write as _;

/// Arguments of `robocal positioner simulate`.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// Directory to write the files into (created when missing).
    #[arg(long)]
    pub out_dir: String,
    /// Place the positioner in front of this robot (a calibrated model file,
    /// a model JSON or a preset), in the cell frame it is registered in.
    #[arg(long)]
    pub robot: Option<String>,
    /// Seed of the tracker's noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// The tracker's noise per coordinate, 1σ [mm].
    #[arg(long, default_value_t = 0.01)]
    pub noise_mm: f64,
    /// The rotate axis's nod once per revolution [deg], an error the fitted
    /// model does not have.
    #[arg(long, default_value_t = 0.003)]
    pub wobble_deg: f64,
}

/// Points of a part on the face plate [mm, face plate frame] and the axis
/// values `[tilt, rotate]` [deg] `part.csv` asks for them at.
const PART_MM: [[f64; 3]; 3] = [
    [300.0, 200.0, 60.0],
    [-250.0, 280.0, 60.0],
    [50.0, -350.0, 80.0],
];
const PART_VALUES_DEG: [[f64; 2]; 4] =
    [[-30.0, 40.0], [15.0, -120.0], [35.0, 160.0], [-10.0, -45.0]];

/// The positioner's base in the cell frame: 1.7 m in front of `robot`'s
/// base, turned 30° about its vertical, 0.9 m below it.
fn in_front_of(robot: &Pose) -> Pose {
    robot.compose(&Pose::new(
        rpy_matrix(0.0, 0.0, 30f64.to_radians()),
        Vector3::new(1.7, 0.3, -0.9),
    ))
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
    let mut nominal: TiltRotate = nominal();
    let mut truth: TruePositioner = TruePositioner {
        noise_mm: a.noise_mm,
        ..truth(a.wobble_deg)
    };
    let mut model = None;
    if let Some(robot) = &a.robot {
        let m = load_compensated(robot).with_context(|| format!("--robot {robot}"))?;
        let base = in_front_of(&m.cell_from_base);
        nominal.cell_from_base = base;
        truth.cell_from_base = base;
        model = Some(m);
    }
    let dir = OutDir::create(&a.out_dir)?;
    let write = |name: &str, text: &str| dir.write(name, text);
    let columns = PositionerColumns {
        tilt: ExternalAxis::E1,
        rotate: ExternalAxis::E2,
    };
    let mut written = vec![write("nominal.json", &nominal.to_json())?];
    let mut stream = 0u64;
    let mut set = |k: usize, values: &[[f64; 2]]| {
        let mut rng = ChaCha8Rng::seed_from_u64(a.seed);
        rng.set_stream(stream);
        stream += 1;
        write_set(&positioner_set(&truth, k, values, columns, &mut rng))
    };
    let fits: Vec<String> = (0..DESIGN_MM.len())
        .map(|k| write(&format!("r{k}.csv"), &set(k, &sweeps())))
        .collect::<anyhow::Result<_>>()?;
    let held = held_out();
    let validations: Vec<String> = (0..DESIGN_MM.len())
        .map(|k| write(&format!("v{k}.csv"), &set(k, &held)))
        .collect::<anyhow::Result<_>>()?;
    let mut part = String::from("id,x,y,z,e1,e2\n");
    for (i, p) in PART_MM.iter().enumerate() {
        for (k, v) in PART_VALUES_DEG.iter().enumerate() {
            writeln!(
                part,
                "p{i}v{k},{},{},{},{},{}",
                p[0], p[1], p[2], v[0], v[1]
            )?;
        }
    }
    written.extend(fits.iter().cloned());
    written.extend(validations.iter().cloned());
    written.push(write("part.csv", &part)?);
    let (program, notes) = program_files(model.as_ref(), &nominal);
    for (name, text) in &program {
        written.push(write(name, text)?);
    }
    let mut out = String::new();
    writeln!(
        out,
        "simulated positioner: {} readings per reflector over both sweeps, {} held out; tracker noise {} mm, rotate axis nod {}°",
        sweeps().len(),
        held.len(),
        a.noise_mm,
        a.wobble_deg
    )?;
    list(&mut out, &written, &notes);
    let reflectors: Vec<String> = DESIGN_MM
        .iter()
        .map(|p| format!("--reflector {},{},{}", p[0], p[1], p[2]))
        .collect();
    let validate: Vec<String> = validations
        .iter()
        .map(|v| format!("--validate {v}"))
        .collect();
    writeln!(
        out,
        "fit it with: robocal positioner calibrate {} --nominal {} {} {} --out positioner.json",
        fits.join(" "),
        written[0],
        reflectors.join(" "),
        validate.join(" ")
    )?;
    Ok(out)
}

/// The program on the part for the controller in front of `model` (none
/// without `--robot`): the files to write (name, text) and what to say of
/// the targets left out or of no program at all.
fn program_files(
    model: Option<&CompensatedModel>,
    nominal: &TiltRotate,
) -> (Vec<(&'static str, String)>, Vec<String>) {
    let Some(model) = model else {
        return (Vec::new(), Vec::new());
    };
    match part_program(
        model,
        nominal,
        in_front_of(&Pose::identity()),
        &PART_MM,
        &PART_VALUES_DEG,
    ) {
        Ok(files) => {
            let notes = files.left_out.iter().map(|t| left_out_note(t)).collect();
            (
                vec![
                    ("controller.json", files.controller),
                    ("cell.json", files.cell),
                    ("part.src", files.src),
                    ("part.dat", files.dat),
                ],
                notes,
            )
        }
        Err(why) => (
            Vec::new(),
            vec![format!(
                "no program on the part (controller.json, cell.json, part.src, part.dat): {why}"
            )],
        ),
    }
}
