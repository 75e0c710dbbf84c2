//! A two-axis tilt-rotate positioner identified from simulated tracker
//! readings: a true positioner with axis tilts of 0.05°, axis offsets of
//! 0.5 mm, zero offsets, scale errors and a wobble (a once-per-revolution
//! nod) of the rotate axis the model lacks (`robocal_core::sim::positioner`), read with 0.01 mm noise.
//! Axis lines against the truth, a point 400 mm from axis 2 predicted at
//! held-out axis values (not the fitted ones), the nominal model beside it,
//! and the fits the judgement refuses.
//!
//! Figures: `cargo test -p robocal-core --test positioner -- --nocapture`.

mod common;

use common::positioner::{fit_plan, held_out, nominal, truth, DESIGN_MM, TRACKER_SIGMA_MM};
use nalgebra::{Rotation3, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal_core::calibrate::external::{
    fit_positioner, PositionerFit, PositionerFitRequest, PositionerReading, RefusalReason,
};
use robocal_core::model::external::{Line, TiltRotate};
use robocal_core::sim::positioner::TruePositioner;

fn request(readings: Vec<PositionerReading>) -> PositionerFitRequest {
    PositionerFitRequest {
        nominal: nominal(),
        reflectors_mm: DESIGN_MM.to_vec(),
        readings,
        tracker_sigma_mm: TRACKER_SIGMA_MM,
    }
}

fn read(t: &TruePositioner, plan: &[(usize, [f64; 2])], seed: u64) -> Vec<PositionerReading> {
    t.read(plan, &mut ChaCha8Rng::seed_from_u64(seed))
}

/// Largest distance [mm] of the fitted line from the true one (through
/// `through`, along `u`) over `±half` m about the true line's point nearest
/// `near`, and the angle between them [deg].
fn line_error(
    fit: &Line,
    u: Vector3<f64>,
    through: Vector3<f64>,
    near: Vector3<f64>,
    half: f64,
) -> (f64, f64) {
    let foot = through + u * u.dot(&(near - through));
    let d = [-half, 0.0, half]
        .iter()
        .map(|s| fit.distance_of(&(foot + u * *s)) * 1e3)
        .fold(0.0, f64::max);
    let angle = fit
        .direction
        .cross(&u)
        .norm()
        .atan2(fit.direction.dot(&u))
        .to_degrees();
    (d, angle)
}

/// The true angle [rad] near 0 at which `g` (smooth) is 0 (Newton, central
/// differences).
fn root(g: impl Fn(f64) -> f64) -> f64 {
    let mut x = 0.0;
    for _ in 0..20 {
        let h = 1e-7;
        x -= g(x) / ((g(x + h) - g(x - h)) / (2.0 * h));
    }
    x
}

/// `x` turned by `angle` about the line through `c` along `u`, no wobble.
fn about_line(u: Vector3<f64>, c: Vector3<f64>, angle: f64, x: Vector3<f64>) -> Vector3<f64> {
    Rotation3::from_scaled_axis(u * angle) * (x - c) + c
}

/// The zero offsets the fit's definitions give on the truth
/// (docs/external-axes/positioner.md): axis 1's is the true angle at which axis 2
/// lies in the plane of nominal axes 1 and 2; axis 2's the true angle at
/// which reflector 0 stands on its design azimuth in the face plate frame.
fn expected_zero_offsets(t: &TruePositioner) -> [f64; 2] {
    let n = nominal();
    let plane = n.tilt.direction.cross(&n.rotate.direction).normalize();
    let alpha = root(|a| {
        plane.dot(&(Rotation3::from_scaled_axis(t.tilt.direction * a) * t.rotate.direction))
    });
    let radial = Vector3::new(DESIGN_MM[0][0], DESIGN_MM[0][1], 0.0).normalize();
    let tangent = Vector3::z().cross(&radial);
    let beta = root(|b| {
        let body = about_line(t.rotate.direction, t.rotate.through, b, t.reflectors[0]);
        let tilt_frame = about_line(t.tilt.direction, t.tilt.through, alpha, body);
        n.face_plate
            .inverse()
            .transform_point(&tilt_frame)
            .dot(&tangent)
    });
    [
        t.tilt.encoder_offset_rad - alpha,
        t.rotate.encoder_offset_rad - beta,
    ]
}

/// The nominal model's prediction of reflector 0 with its position taken
/// from the same fit readings through the nominal model (the mean of the
/// readings mapped back), as a controller taught the point would have it.
fn nominal_point(readings: &[PositionerReading]) -> Vector3<f64> {
    let n = nominal();
    let mapped: Vec<Vector3<f64>> = readings
        .iter()
        .filter(|r| r.reflector == 0)
        .map(|r| {
            n.cell_from_face_plate(r.values_deg)
                .inverse()
                .transform_point(&(Vector3::from(r.xyz_mm) * 1e-3))
        })
        .collect();
    mapped.iter().sum::<Vector3<f64>>() / mapped.len() as f64
}

/// Max and RMS [mm] of `model`'s prediction of `point` (face plate frame)
/// against the truth's reflector 0 at the held-out values.
fn prediction_error(model: &TiltRotate, point: &Vector3<f64>, t: &TruePositioner) -> (f64, f64) {
    let e: Vec<f64> = held_out()
        .iter()
        .map(|v| (model.point_in_cell(*v, point) - t.reflector(0, *v)).norm() * 1e3)
        .collect();
    let max = e.iter().copied().fold(0.0, f64::max);
    let rms = (e.iter().map(|x| x * x).sum::<f64>() / e.len() as f64).sqrt();
    (max, rms)
}

fn fitted(seed: u64, wobble_deg: f64) -> (TruePositioner, Vec<PositionerReading>, PositionerFit) {
    let t = truth(wobble_deg);
    let readings = read(&t, &fit_plan(), seed);
    let fit =
        fit_positioner(&request(readings.clone())).unwrap_or_else(|e| panic!("seed {seed}: {e}"));
    (t, readings, fit)
}

/// The acceptance figures: axis lines within 0.02 mm and 0.005°, a point
/// 400 mm from axis 2 within 0.03 mm at held-out values, for three seeds of
/// the tracker noise, with a nod of the rotate axis of 0.003° once per
/// revolution, half of which no rigid model holds.
#[test]
fn positioner_axes_and_held_out_points_from_tracker_readings() {
    for seed in [1, 2, 3] {
        let (t, readings, fit) = fitted(seed, 0.003);
        let m = &fit.model;
        assert!(fit.solver.converged, "{:?}", fit.solver);
        // Axis 1 over ±0.5 m about the face plate; axis 2 at tilt 0 and
        // ±60° over ±0.3 m about the face plate centre.
        let centre = Vector3::new(0.0, 0.0, 1.1);
        let (d1, a1) = line_error(
            &m.tilt_line(),
            t.tilt.direction,
            t.tilt.through,
            centre,
            0.5,
        );
        let mut d2: f64 = 0.0;
        let mut a2: f64 = 0.0;
        for v1 in [-60.0, 0.0, 60.0] {
            let th = t.tilt.angle(v1);
            let u = Rotation3::from_scaled_axis(t.tilt.direction * th) * t.rotate.direction;
            let c = about_line(t.tilt.direction, t.tilt.through, th, t.rotate.through);
            let near = about_line(t.tilt.direction, t.tilt.through, th, centre);
            let (d, a) = line_error(&m.rotate_line(v1), u, c, near, 0.3);
            d2 = d2.max(d);
            a2 = a2.max(a);
        }
        let p0 = Vector3::from(fit.reflectors_mm[0]) * 1e-3;
        let (max_fit, rms_fit) = prediction_error(m, &p0, &t);
        let (max_nom, rms_nom) = prediction_error(&nominal(), &nominal_point(&readings), &t);
        // The same without the nod, for comparison.
        let (t0, _, fit0) = fitted(seed, 0.0);
        let q0 = Vector3::from(fit0.reflectors_mm[0]) * 1e-3;
        let (max_rigid, rms_rigid) = prediction_error(&fit0.model, &q0, &t0);
        let [o1, o2] = expected_zero_offsets(&t);
        let do1 = (m.tilt.zero_offset - o1).to_degrees();
        let do2 = (m.rotate.zero_offset - o2).to_degrees();
        let ds1 = m.tilt.scale - t.tilt.scale;
        let ds2 = m.rotate.scale - t.rotate.scale;
        println!(
            "seed {seed}: fit rms {:.4} mm max {:.4} mm ({} iterations, {:?}); axis 1 {d1:.4} mm {a1:.5}°, \
             axis 2 {d2:.4} mm {a2:.5}°; zero offsets off {do1:+.5}° {do2:+.5}° (σ {:.5}° {:.5}°); \
             scales off {ds1:+.2e} {ds2:+.2e} (σ {:.1e} {:.1e}); held-out point 400 mm from axis 2: \
             calibrated max {max_fit:.4} mm rms {rms_fit:.4} mm, nominal max {max_nom:.3} mm rms {rms_nom:.3} mm; \
             calibrated without the nod max {max_rigid:.4} mm rms {rms_rigid:.4} mm",
            fit.rms_mm,
            fit.max_mm,
            fit.solver.iterations,
            fit.solver.reason,
            fit.sigma[0].zero_offset_deg,
            fit.sigma[1].zero_offset_deg,
            fit.sigma[0].scale,
            fit.sigma[1].scale,
        );
        assert!(
            d1 <= 0.02 && a1 <= 0.005,
            "seed {seed}: axis 1 {d1} mm {a1}°"
        );
        assert!(
            d2 <= 0.02 && a2 <= 0.005,
            "seed {seed}: axis 2 {d2} mm {a2}°"
        );
        assert!(max_fit <= 0.03, "seed {seed}: held-out point {max_fit} mm");
        assert!(
            max_rigid <= 0.03,
            "seed {seed}: held-out point without the nod {max_rigid} mm"
        );
        assert!(
            max_nom > 10.0 * max_fit,
            "seed {seed}: nominal {max_nom} mm"
        );
        assert!(
            do1.abs() <= 0.005 && do2.abs() <= 0.005,
            "seed {seed}: zero offsets {do1}° {do2}°"
        );
        assert!(
            ds1.abs() <= 4.0 * fit.sigma[0].scale,
            "seed {seed}: scale 1 {ds1:e}"
        );
        assert!(
            ds2.abs() <= 4.0 * fit.sigma[1].scale,
            "seed {seed}: scale 2 {ds2:e}"
        );
        // The stored description predicts what the fit does.
        let back = TiltRotate::from_json(&m.to_json()).unwrap();
        let d =
            (back.point_in_cell([33.0, -77.0], &p0) - m.point_in_cell([33.0, -77.0], &p0)).norm();
        assert!(d < 1e-9, "{d}");
    }
}

/// Without the wobble and the noise the fit gives back the truth's lines,
/// scales and the offsets its definitions give, to rounding.
#[test]
fn exact_readings_give_the_truth_back() {
    let mut t = truth(0.0);
    t.noise_mm = 0.0;
    let fit = fit_positioner(&request(read(&t, &fit_plan(), 0))).unwrap();
    let [o1, o2] = expected_zero_offsets(&t);
    let m = &fit.model;
    assert!(
        (m.tilt.zero_offset - o1).abs() < 1e-9,
        "{} {}",
        m.tilt.zero_offset,
        o1
    );
    assert!(
        (m.rotate.zero_offset - o2).abs() < 1e-9,
        "{} {}",
        m.rotate.zero_offset,
        o2
    );
    assert!((m.tilt.scale - t.tilt.scale).abs() < 1e-9);
    assert!((m.rotate.scale - t.rotate.scale).abs() < 1e-9);
    assert!(m.tilt_line().distance_of(&t.tilt.through) < 1e-9);
    assert!(fit.max_mm < 1e-6, "{}", fit.max_mm);
}

/// Zero offsets of several degrees (a positioner re-mastered badly) are
/// found from the circles' start as well: exact readings give them back.
#[test]
fn large_zero_offsets_are_found() {
    let mut t = truth(0.0);
    t.noise_mm = 0.0;
    t.tilt.encoder_offset_rad = 6f64.to_radians();
    t.rotate.encoder_offset_rad = -14f64.to_radians();
    let fit = fit_positioner(&request(read(&t, &fit_plan(), 0))).unwrap();
    let [o1, o2] = expected_zero_offsets(&t);
    println!(
        "large offsets: fitted {:.6}° {:.6}°, expected {:.6}° {:.6}°",
        fit.model.tilt.zero_offset.to_degrees(),
        fit.model.rotate.zero_offset.to_degrees(),
        o1.to_degrees(),
        o2.to_degrees()
    );
    assert!((fit.model.tilt.zero_offset - o1).abs() < 1e-9);
    assert!((fit.model.rotate.zero_offset - o2).abs() < 1e-9);
    assert!(fit.max_mm < 1e-6, "{}", fit.max_mm);
}

fn refused(readings: Vec<PositionerReading>) -> robocal_core::calibrate::external::Refused {
    match fit_positioner(&request(readings)) {
        Ok(f) => panic!("fitted: rms {} mm", f.rms_mm),
        Err(e) => {
            println!("refused ({:?}): {}", e.reason, e.message);
            e
        }
    }
}

/// Too few angles, a span too small to see the scale, a reflector knocked
/// in its nest half way, one wrong reading (0.25 mm), a reflector on an
/// axis, readings that name no reflector or are not finite, and a wobble far
/// beyond the tracker's noise: each refused with its reason.
#[test]
fn fits_the_readings_cannot_carry_are_refused() {
    let t = truth(0.002);
    // Axis 2 at three values only.
    let plan: Vec<_> = fit_plan()
        .into_iter()
        .filter(|(_, v)| v[0] != 0.0 || [-165.0, -15.0, 135.0].contains(&v[1]))
        .collect();
    let e = refused(read(&t, &plan, 4));
    assert_eq!(e.reason, RefusalReason::TooFewAngles);
    assert_eq!((e.measured, e.needed), (Some(3.0), Some(4.0)));
    // Axis 2 over 60° (7 values).
    let mut plan: Vec<_> = fit_plan()
        .into_iter()
        .filter(|(_, v)| v[0] != 0.0 || v[1] == 0.0)
        .collect();
    for k in 0..2 {
        for i in 0..7 {
            plan.push((k, [0.0, -30.0 + 10.0 * i as f64]));
        }
    }
    let e = refused(read(&t, &plan, 5));
    assert_eq!(e.reason, RefusalReason::SpanTooSmall);
    // Reflector 0 knocked by 0.3 mm before the axis 1 sweep.
    let mut readings = read(&t, &fit_plan(), 6);
    for r in readings.iter_mut().take(25).skip(12) {
        r.xyz_mm[2] += 0.3;
    }
    let e = refused(readings);
    assert!(matches!(
        e.reason,
        RefusalReason::ResidualsTooLarge | RefusalReason::ResidualOutlier
    ));
    assert!(e.fit.is_some());
    // One reading off by 0.25 mm: named.
    let mut readings = read(&t, &fit_plan(), 7);
    readings[30].xyz_mm[0] += 0.25;
    let e = refused(readings);
    assert_eq!(e.reason, RefusalReason::ResidualOutlier);
    assert_eq!(e.row, Some(31));
    // Reflector 1 5 mm from axis 2.
    let mut near = truth(0.002);
    near.reflectors[1] = Vector3::new(0.005, 0.0, 1.12);
    let mut req = request(read(&near, &fit_plan(), 9));
    req.reflectors_mm[1] = [5.0, 0.0, 20.0];
    let e = fit_positioner(&req).unwrap_err();
    println!("refused ({:?}): {}", e.reason, e.message);
    assert_eq!(e.reason, RefusalReason::ReflectorNearAxis);
    // A reading naming a reflector not given, a reflector given but not
    // read, and a reading not finite.
    let mut readings = read(&t, &fit_plan(), 10);
    readings[3].reflector = 2;
    assert_eq!(refused(readings).reason, RefusalReason::UnknownReflector);
    let mut req = request(read(&t, &fit_plan(), 10));
    req.reflectors_mm.push([0.0, 300.0, 20.0]);
    let e = fit_positioner(&req).unwrap_err();
    assert_eq!(e.reason, RefusalReason::UnknownReflector);
    assert!(
        e.message
            .contains("reflector 2 is given but has no readings"),
        "{}",
        e.message
    );
    let mut readings = read(&t, &fit_plan(), 10);
    readings[3].xyz_mm[1] = f64::NAN;
    assert_eq!(refused(readings).row, Some(4));
    // A wobble of 0.05°: the positioner is not the rigid model.
    let e = refused(read(&truth(0.05), &fit_plan(), 8));
    assert_eq!(e.reason, RefusalReason::ResidualsTooLarge);
}
