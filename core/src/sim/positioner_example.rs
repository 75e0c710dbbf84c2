//! An example two-axis tilt-rotate positioner (`super::positioner`), the
//! one the positioner tests share and `robocal positioner simulate` measures:
//! its nominal model, the truth with axis
//! tilts of 0.05°, offsets of ~0.5 mm, zero offsets, scale errors and a nod of
//! the rotate axis the model lacks, the reflectors' design positions and the
//! axis values read for a fit and held out from it. Frames: the cell (tracker)
//! frame, SI units inside the models; design positions and axis values in
//! millimetres and degrees.

use super::positioner::{TrueAxis, TruePositioner, Wobble};
use crate::model::external::{RotaryAxis, TiltRotate};
use crate::model::pose::rpy_matrix;
use crate::model::Pose;
use nalgebra::{Rotation3, Vector3};

/// The tracker's noise per coordinate, 1σ [mm].
pub const TRACKER_SIGMA_MM: f64 = 0.01;

/// Design positions of the reflectors on the face plate [mm]; the first is
/// the reference, 400 mm from axis 2.
pub const DESIGN_MM: [[f64; 3]; 2] = [[400.0, 0.0, 20.0], [-150.0, 100.0, 20.0]];

/// Tilt axis along base x at 800 mm, rotate axis along the tilt frame's z,
/// face plate 300 mm above the tilt axis; the base 2.5 m from the tracker,
/// turned 30° about the vertical.
pub fn nominal() -> TiltRotate {
    TiltRotate {
        cell_from_base: Pose::new(
            rpy_matrix(0.0, 0.0, 30f64.to_radians()),
            Vector3::new(2.5, -0.8, -0.9),
        ),
        tilt: RotaryAxis::new(Vector3::x(), Vector3::new(0.0, 0.0, 0.8), 0.0, 1.0),
        rotate: RotaryAxis::new(Vector3::z(), Vector3::zeros(), 0.0, 1.0),
        face_plate: Pose::from_translation(Vector3::new(0.0, 0.0, 1.1)),
    }
}

/// `v` turned by `deg` about the unit `about`.
pub fn turned(v: Vector3<f64>, about: Vector3<f64>, deg: f64) -> Vector3<f64> {
    Rotation3::from_scaled_axis(about.normalize() * deg.to_radians()) * v
}

/// The truth: each axis tilted 0.05° and offset 0.5 mm from nominal, zero
/// offsets of 0.3° and −0.4°, scales off by 2e-4 and −1.5e-4, the rotate
/// axis nodding by `wobble_deg` once per revolution; the reflectors placed
/// 0.2–0.4 mm off their design positions, read with [`TRACKER_SIGMA_MM`].
pub fn truth(wobble_deg: f64) -> TruePositioner {
    TruePositioner {
        cell_from_base: nominal().cell_from_base,
        tilt: TrueAxis {
            direction: turned(Vector3::x(), Vector3::new(0.0, 0.6, 0.8), 0.05),
            through: Vector3::new(0.0, 0.0003, 0.8004),
            encoder_offset_rad: 0.3f64.to_radians(),
            scale: 1.0 + 2e-4,
            wobble: None,
        },
        rotate: TrueAxis {
            direction: turned(Vector3::z(), Vector3::new(1.0, 1.0, 0.0), 0.05),
            through: Vector3::new(0.0004, -0.0003, 0.0),
            encoder_offset_rad: -0.4f64.to_radians(),
            scale: 1.0 - 1.5e-4,
            wobble: Some(Wobble {
                amplitude_rad: wobble_deg.to_radians(),
                phase_rad: 0.7,
                pivot_along_m: 0.95,
            }),
        },
        reflectors: vec![
            Vector3::new(0.4002, 0.0003, 1.1198),
            Vector3::new(-0.1497, 0.1004, 1.1203),
        ],
        noise_mm: TRACKER_SIGMA_MM,
    }
}

/// Axis values `[tilt, rotate]` [deg] of one reflector's sweeps: axis 2 over
/// 330° at axis 1 = 0 (12 values), axis 1 over 180° at axis 2 = 0 (13 values).
pub fn sweeps() -> Vec<[f64; 2]> {
    let mut v: Vec<[f64; 2]> = (0..12)
        .map(|i| [0.0, -165.0 + 30.0 * f64::from(i)])
        .collect();
    v.extend((0..13).map(|i| [-90.0 + 15.0 * f64::from(i), 0.0]));
    v
}

/// The sweeps of both reflectors, as (reflector, values) pairs.
pub fn fit_plan() -> Vec<(usize, [f64; 2])> {
    (0..2)
        .flat_map(|k| sweeps().into_iter().map(move |v| (k, v)))
        .collect()
}

/// Held-out values over both axes' travel (7 × 8), none of them a fitted pair.
pub fn held_out() -> Vec<[f64; 2]> {
    let mut v = Vec::new();
    for a in [-80.0, -52.0, -23.0, 8.0, 37.0, 61.0, 84.0] {
        for b in [-172.0, -118.0, -71.0, -26.0, 19.0, 66.0, 107.0, 151.0] {
            v.push([a, b]);
        }
    }
    v
}
