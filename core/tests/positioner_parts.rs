//! A part on a positioner's face plate carried to the cell frame at the
//! axes' values (`solve::external::positioner`), against the simulated
//! positioner's physics (`robocal_core::sim::positioner`: rotations about
//! true lines, with a once-per-revolution nod of the rotate axis the model
//! lacks), through the positioner calibrated from tracker readings and
//! through the nominal one.
//!
//! The part is a frame on the rotate body ~430 mm from axis 2, located on
//! the face plate the way a part is taught: its pose measured in the cell
//! with both axes at 0, mapped back through the model (`part_from_cell`).
//! It is then carried to 56 held-out pairs of values (none fitted) and
//! compared with where the true positioner puts it. The calibrated model
//! must land within the σ-scale the fit is judged by (`3·√3·σ`, the fit's
//! RMS limit, in position; that over the part's arm in orientation); the
//! nominal one misses by the simulated errors (axis offsets of 0.5 mm,
//! tilts of 0.05°, zero offsets of tenths of a degree).
//!
//! Figures: `cargo test -p robocal-core --test positioner_parts -- --nocapture`.

mod common;

use common::positioner::{self, fit_plan, nominal, DESIGN_MM, TRACKER_SIGMA_MM};
use nalgebra::{Matrix3, Rotation3, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal_core::calibrate::external::{fit_positioner, PositionerFitRequest};
use robocal_core::model::calibrated::CompensatedModel;
use robocal_core::model::external::TiltRotate;
use robocal_core::model::pose::rpy_matrix;
use robocal_core::model::{preset, Pose};
use robocal_core::sim::positioner::TruePositioner;
use robocal_core::solve::external::{base_from_part, cell_from_part, part_from_cell, AxisValues};

/// The held-out values as the carrying functions take them.
fn held_out() -> Vec<AxisValues> {
    positioner::held_out()
        .into_iter()
        .map(|[a, b]| AxisValues {
            tilt_deg: a,
            rotate_deg: b,
        })
        .collect()
}

/// The part's true pose in the cell at `v`: its origin and its axes' tips
/// carried by the true positioner's physics (a rigid motion, so the
/// carried axes are orthonormal to rounding).
fn true_part(t: &TruePositioner, body: &Pose, v: AxisValues) -> Pose {
    let arm = 0.1;
    let o = t.point(v.as_array(), &body.p);
    let axis = |k: usize| (t.point(v.as_array(), &(body.p + body.r.column(k) * arm)) - o) / arm;
    Pose::new(Matrix3::from_columns(&[axis(0), axis(1), axis(2)]), o)
}

/// Largest and RMS position error [mm] and largest angle error [deg] of
/// `model` carrying the part located at axes 0, 0 against the truth.
struct Miss {
    max_mm: f64,
    rms_mm: f64,
    max_deg: f64,
}

fn miss(model: &TiltRotate, t: &TruePositioner, body: &Pose) -> Miss {
    let zero = AxisValues {
        tilt_deg: 0.0,
        rotate_deg: 0.0,
    };
    let located = part_from_cell(model, zero, &true_part(t, body, zero));
    let (mut max_mm, mut sum, mut max_deg) = (0.0f64, 0.0, 0.0f64);
    let values = held_out();
    for v in &values {
        let got = cell_from_part(model, *v, &located);
        let want = true_part(t, body, *v);
        let e = (got.p - want.p).norm() * 1e3;
        let r = Rotation3::from_matrix_unchecked(got.r.transpose() * want.r);
        max_mm = max_mm.max(e);
        sum += e * e;
        max_deg = max_deg.max(r.angle().to_degrees());
    }
    Miss {
        max_mm,
        rms_mm: (sum / values.len() as f64).sqrt(),
        max_deg,
    }
}

#[test]
fn a_part_on_the_face_plate_lands_where_the_true_positioner_puts_it() {
    // The part: ~430 mm from axis 2, 60 mm above the plate, turned.
    let body = Pose::new(rpy_matrix(0.3, -0.2, 1.1), Vector3::new(0.35, 0.25, 1.16));
    for seed in [1, 2, 3] {
        let t = positioner::truth(0.003);
        let readings = t.read(&fit_plan(), &mut ChaCha8Rng::seed_from_u64(seed));
        let fit = fit_positioner(&PositionerFitRequest {
            nominal: nominal(),
            reflectors_mm: DESIGN_MM.to_vec(),
            readings,
            tracker_sigma_mm: TRACKER_SIGMA_MM,
        })
        .unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        let cal = miss(&fit.model, &t, &body);
        let nom = miss(&nominal(), &t, &body);
        let arm_mm = 1e3 * (body.p - Vector3::new(0.0, 0.0, body.p.z)).norm();
        let bound_mm = fit.limits.rms_mm;
        let bound_deg = (bound_mm / arm_mm).to_degrees();
        println!(
            "seed {seed}: part {arm_mm:.0} mm from axis 2 at 56 held-out values: calibrated max {:.4} mm \
             (rms {:.4} mm), {:.5}°; nominal max {:.3} mm (rms {:.3} mm), {:.4}°; bounds {bound_mm:.4} mm, {bound_deg:.5}°",
            cal.max_mm, cal.rms_mm, cal.max_deg, nom.max_mm, nom.rms_mm, nom.max_deg
        );
        assert!(cal.max_mm <= bound_mm, "seed {seed}: {} mm", cal.max_mm);
        assert!(cal.max_deg <= bound_deg, "seed {seed}: {}°", cal.max_deg);
        // The nominal model misses by the simulated errors: more than the
        // axes' offsets (0.5 mm) and tilts (0.05°).
        assert!(nom.max_mm > 0.5, "seed {seed}: nominal {} mm", nom.max_mm);
        assert!(nom.max_deg > 0.05, "seed {seed}: nominal {}°", nom.max_deg);
    }
}

/// In a robot's base frame: the same pose as the cell frame's, seen
/// from the robot's registered base (`cell_from_base⁻¹`), computed apart.
#[test]
fn the_base_frame_is_the_cell_frame_seen_from_the_robots_base() {
    let mut robot = CompensatedModel::from_nominal(preset("ys100").unwrap());
    robot.cell_from_base = Pose::new(rpy_matrix(0.0, 0.0, -0.4), Vector3::new(0.7, 1.2, 0.05));
    let p = nominal();
    let part = Pose::new(rpy_matrix(0.1, 0.0, 0.5), Vector3::new(0.2, -0.1, 0.05));
    let v = AxisValues {
        tilt_deg: 35.0,
        rotate_deg: -120.0,
    };
    let in_base = base_from_part(&robot, &p, v, &part);
    // By hand: the cell point through the inverse registration.
    let cell = cell_from_part(&p, v, &part);
    let want_p = robot.cell_from_base.r.transpose() * (cell.p - robot.cell_from_base.p);
    let want_r = robot.cell_from_base.r.transpose() * cell.r;
    assert!((in_base.p - want_p).norm() < 1e-12);
    assert!((in_base.r - want_r).norm() < 1e-12);
}
