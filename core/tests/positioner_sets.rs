//! The positioner fit reading its readings from measurement CSVs with the
//! axes in external-axis columns: one file per reflector written by the
//! simulated positioner (`robocal_core::sim::positioner_sets`), read back
//! with `measure::csv::parse_set` and turned into readings by the columns'
//! roles. The fit from the files is the fit from the readings themselves,
//! bit for bit, and finds the true axes.

mod common;

use common::positioner::{fit_plan, sweeps};
use nalgebra::{Rotation3, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal_core::calibrate::external::readings::{
    positioner_readings, ColumnsError, PositionerColumns,
};
use robocal_core::calibrate::external::{fit_positioner, PositionerFitRequest};
use robocal_core::measure::csv;
use robocal_core::measure::external::ExternalAxis;
use robocal_core::model::external::{RotaryAxis, TiltRotate};
use robocal_core::model::Pose;
use robocal_core::sim::positioner::{TrueAxis, TruePositioner};
use robocal_core::sim::positioner_sets::positioner_set;

const SIGMA_MM: f64 = 0.01;
const DESIGN_MM: [[f64; 3]; 2] = [[400.0, 0.0, 20.0], [-150.0, 100.0, 20.0]];

fn nominal() -> TiltRotate {
    TiltRotate {
        cell_from_base: Pose::from_translation(Vector3::new(2.5, -0.8, -0.9)),
        tilt: RotaryAxis::new(Vector3::x(), Vector3::new(0.0, 0.0, 0.8), 0.0, 1.0),
        rotate: RotaryAxis::new(Vector3::z(), Vector3::zeros(), 0.0, 1.0),
        face_plate: Pose::from_translation(Vector3::new(0.0, 0.0, 1.1)),
    }
}

/// Each axis tilted 0.05° and offset by tenths of a millimetre, zero
/// offsets and scale errors; no wobble.
fn truth() -> TruePositioner {
    let tilt = |v: Vector3<f64>, about: Vector3<f64>| {
        Rotation3::from_scaled_axis(about.normalize() * 0.05f64.to_radians()) * v
    };
    TruePositioner {
        cell_from_base: nominal().cell_from_base,
        tilt: TrueAxis {
            direction: tilt(Vector3::x(), Vector3::new(0.0, 0.6, 0.8)),
            through: Vector3::new(0.0, 0.0003, 0.8004),
            encoder_offset_rad: 0.3f64.to_radians(),
            scale: 1.0 + 2e-4,
            wobble: None,
        },
        rotate: TrueAxis {
            direction: tilt(Vector3::z(), Vector3::new(1.0, 1.0, 0.0)),
            through: Vector3::new(0.0004, -0.0003, 0.0),
            encoder_offset_rad: -0.4f64.to_radians(),
            scale: 1.0 - 1.5e-4,
            wobble: None,
        },
        reflectors: vec![
            Vector3::new(0.4002, 0.0003, 1.1198),
            Vector3::new(-0.1497, 0.1004, 1.1203),
        ],
        noise_mm: SIGMA_MM,
    }
}

#[test]
fn the_positioner_fit_reads_measurement_sets_by_their_columns() {
    let t = truth();
    // The tilt in e2, the rotate in e1: roles, not column order.
    let columns = PositionerColumns {
        tilt: ExternalAxis::E2,
        rotate: ExternalAxis::E1,
    };
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let files: Vec<String> = (0..2)
        .map(|k| csv::write_set(&positioner_set(&t, k, &sweeps(), columns, &mut rng)))
        .collect();
    assert!(files[0].starts_with("e1,e2,x,y,z\n"), "{}", files[0]);
    let mut from_files = Vec::new();
    for (k, text) in files.iter().enumerate() {
        let set = csv::parse_set(text).unwrap();
        from_files.extend(positioner_readings(&set, columns, k).unwrap());
    }
    // The same readings drawn directly from the same generator.
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let plan = fit_plan();
    let direct: Vec<_> = (0..2)
        .flat_map(|k| {
            let p: Vec<(usize, [f64; 2])> = plan.iter().filter(|(r, _)| *r == k).copied().collect();
            t.read(&p, &mut rng)
        })
        .collect();
    assert_eq!(from_files, direct);
    let request = |readings| PositionerFitRequest {
        nominal: nominal(),
        reflectors_mm: DESIGN_MM.to_vec(),
        readings,
        tracker_sigma_mm: SIGMA_MM,
    };
    let fit = fit_positioner(&request(from_files)).unwrap();
    assert_eq!(fit, fit_positioner(&request(direct)).unwrap());
    // The true axis 1 direction within 0.005°.
    let angle = fit
        .model
        .tilt
        .direction
        .cross(&t.tilt.direction)
        .norm()
        .asin()
        .to_degrees();
    assert!(angle < 0.005, "{angle}");

    // Columns the set does not have, or one column for both roles.
    let set = csv::parse_set(&files[0]).unwrap();
    let e3 = PositionerColumns {
        tilt: ExternalAxis::E3,
        rotate: ExternalAxis::E1,
    };
    assert!(matches!(
        positioner_readings(&set, e3, 0),
        Err(ColumnsError::Missing {
            column: ExternalAxis::E3,
            role: "tilt",
            ..
        })
    ));
    let same = PositionerColumns {
        tilt: ExternalAxis::E1,
        rotate: ExternalAxis::E1,
    };
    assert_eq!(
        positioner_readings(&set, same, 0),
        Err(ColumnsError::SameColumn(ExternalAxis::E1))
    );
    // The robot-only reader refuses the file, naming the column.
    assert!(csv::parse(&files[0])
        .unwrap_err()
        .to_string()
        .contains("`e1`"));
}

/// Standard deviation of `v` about its mean.
fn spread_of(v: &[f64]) -> f64 {
    let m = v.iter().sum::<f64>() / v.len() as f64;
    (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() - 1) as f64).sqrt()
}

/// A positioner's plan (`plan::make_positioner_plan`: the two sweeps, every
/// reflector at every value) through its files: the plan's CSV (`point,e1,e2`,
/// no joints), one tracker export per reflector joined back into a
/// measurement file with its `e1`, `e2` columns, read by the columns' roles
/// and fitted; over 30 seeds of the truth without its nod (noise alone) the
/// fitted zero offsets, scales and axis directions scatter as the plan
/// predicted (within 2×, as the robot's plans are held).
#[test]
fn a_planned_positioner_measurement_scatters_as_predicted() {
    use robocal_core::plan::{
        join, make_positioner_plan, plan_csv, read_plan_csv, JoinOptions, PositionerPlanSettings,
    };
    use robocal_core::sim::positioner_example as example;
    let nominal = example::nominal();
    let plan = make_positioner_plan(
        &nominal,
        &PositionerPlanSettings {
            reflectors_mm: example::DESIGN_MM.to_vec(),
            ..PositionerPlanSettings::default()
        },
    )
    .unwrap();
    let text = plan_csv(&plan.points);
    assert!(text.starts_with("point,e1,e2\nP1,0,-165\n"), "{text}");
    let points = read_plan_csv(&text).unwrap();
    assert_eq!(points, plan.points);
    let truth = example::truth(0.0);
    let columns = PositionerColumns {
        tilt: ExternalAxis::E1,
        rotate: ExternalAxis::E2,
    };
    let u1n = nominal.tilt.direction;
    let mut got: [Vec<f64>; 6] = Default::default();
    let mut directions = Vec::new();
    for seed in 1..=30u64 {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut readings = Vec::new();
        for k in 0..example::DESIGN_MM.len() {
            let at: Vec<(usize, [f64; 2])> = plan.values_deg.iter().map(|v| (k, *v)).collect();
            let read = truth.read(&at, &mut rng);
            let export = common::tracker_export(
                points
                    .iter()
                    .zip(&read)
                    .map(|(p, r)| (p.name.as_str(), r.xyz_mm)),
            );
            let joined = join(&points, &export, &JoinOptions::default()).unwrap();
            let file = csv::write_set(&joined.set());
            assert!(file.starts_with("e1,e2,x,y,z\n"), "{file}");
            readings
                .extend(positioner_readings(&csv::parse_set(&file).unwrap(), columns, k).unwrap());
        }
        let fit = fit_positioner(&PositionerFitRequest {
            nominal,
            reflectors_mm: example::DESIGN_MM.to_vec(),
            readings,
            tracker_sigma_mm: example::TRACKER_SIGMA_MM,
        })
        .unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        let m = &fit.model;
        got[0].push(m.tilt.zero_offset.to_degrees());
        got[1].push(m.rotate.zero_offset.to_degrees());
        got[2].push(m.tilt.scale);
        got[3].push(m.rotate.scale);
        got[5].push(m.rotate.direction.dot(&u1n).asin().to_degrees());
        directions.push(m.tilt.direction);
    }
    let mean = directions.iter().sum::<Vector3<f64>>().normalize();
    let n = directions.len() as f64;
    let tilt_direction_rms = (directions
        .iter()
        .map(|d| d.angle(&mean).powi(2))
        .sum::<f64>()
        / (n - 1.0))
        .sqrt();
    let [t, r] = plan.sigma;
    let rows = [
        (
            "axis 1 zero offset [deg]",
            spread_of(&got[0]),
            t.zero_offset_deg,
        ),
        (
            "axis 2 zero offset [deg]",
            spread_of(&got[1]),
            r.zero_offset_deg,
        ),
        ("axis 1 scale", spread_of(&got[2]), t.scale),
        ("axis 2 scale", spread_of(&got[3]), r.scale),
        (
            "axis 1 direction [deg]",
            tilt_direction_rms.to_degrees(),
            t.direction_deg,
        ),
        (
            "axis 2 direction [deg]",
            spread_of(&got[5]),
            r.direction_deg,
        ),
    ];
    for (name, empirical, predicted) in rows {
        let ratio = empirical / predicted;
        println!("{name}: predicted {predicted:.3e}, 30 fits {empirical:.3e}, ratio {ratio:.2}");
        assert!(
            (0.5..=2.0).contains(&ratio),
            "{name}: {empirical} vs {predicted}"
        );
    }
}
