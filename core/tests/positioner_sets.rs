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
