//! A one-axis turntable identified from simulated tracker readings: the
//! example positioner's rotate axis with its tilt standing still at true
//! angle 0 (`robocal_core::sim::positioner`, from rotations about true
//! lines, not from the model's code): the axis tilted 0.05° and offset
//! 0.5 mm from nominal, a zero offset of −0.4°, a scale off by −1.5e-4 and a
//! nod of 0.003° once per revolution the model lacks, read with 0.01 mm
//! noise. The axis's line against the truth's, a point 400 mm from the axis
//! predicted at held-out values (not the fitted ones), the nominal model
//! beside it, and the fits the judgement refuses.
//!
//! Figures: `cargo test -p robocal-core --test turntable -- --nocapture`.

use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal_core::calibrate::external::turntable::{
    fit_turntable, held_out_errors_mm, TurntableFit, TurntableFitRequest, TurntableReading,
};
use robocal_core::calibrate::external::RefusalReason;
use robocal_core::model::external::Turntable;
use robocal_core::sim::positioner::TruePositioner;
use robocal_core::sim::turntable_example::{held_out, nominal, sweep, truth, DESIGN_MM};

fn read(t: &TruePositioner, values: &[f64], seed: u64) -> Vec<TurntableReading> {
    let plan: Vec<(usize, [f64; 2])> = (0..2)
        .flat_map(|k| values.iter().map(move |v| (k, [0.0, *v])))
        .collect();
    t.read(&plan, &mut ChaCha8Rng::seed_from_u64(seed))
        .into_iter()
        .map(|r| TurntableReading {
            reflector: r.reflector,
            value_deg: r.values_deg[1],
            xyz_mm: r.xyz_mm,
        })
        .collect()
}

fn request(readings: Vec<TurntableReading>) -> TurntableFitRequest {
    TurntableFitRequest {
        nominal: nominal(),
        reflectors_mm: DESIGN_MM.to_vec(),
        readings,
        tracker_sigma_mm: 0.01,
    }
}

/// Largest distance [mm] of the fitted line from the truth's over ±0.3 m
/// about the face plate, and the angle between them [deg] (the truth's line
/// as its bearing stands, the nod left out).
fn line_error(fit: &TurntableFit, t: &TruePositioner) -> (f64, f64) {
    let line = fit.model.line_in_cell();
    let u = t.cell_from_base.r * t.rotate.direction;
    let through = t.cell_from_base.transform_point(&t.rotate.through);
    let plate = t
        .cell_from_base
        .transform_point(&Vector3::new(0.0, 0.0, 1.1));
    let foot = through + u * u.dot(&(plate - through));
    let d = [-0.3, 0.0, 0.3]
        .iter()
        .map(|s| line.distance_of(&(foot + u * *s)) * 1e3)
        .fold(0.0, f64::max);
    let angle = line
        .direction
        .cross(&u)
        .norm()
        .atan2(line.direction.dot(&u))
        .to_degrees();
    (d, angle)
}

/// Max and RMS [mm] of `model`'s prediction of `point` (face plate frame)
/// against the truth's reflector 0 at the held-out values.
fn prediction_error(model: &Turntable, point: &Vector3<f64>, t: &TruePositioner) -> (f64, f64) {
    let e: Vec<f64> = held_out()
        .iter()
        .map(|v| (model.point_in_cell(*v, point) - t.reflector(0, [0.0, *v])).norm() * 1e3)
        .collect();
    let max = e.iter().copied().fold(0.0, f64::max);
    (
        max,
        (e.iter().map(|x| x * x).sum::<f64>() / e.len() as f64).sqrt(),
    )
}

/// The nominal model's reflector 0 from the same readings (their mean
/// mapped back), as a controller taught the point would have it.
fn nominal_point(readings: &[TurntableReading]) -> Vector3<f64> {
    let n = nominal();
    let mapped: Vec<Vector3<f64>> = readings
        .iter()
        .filter(|r| r.reflector == 0)
        .map(|r| {
            n.cell_from_face_plate(r.value_deg)
                .inverse()
                .transform_point(&(Vector3::from(r.xyz_mm) * 1e-3))
        })
        .collect();
    mapped.iter().sum::<Vector3<f64>>() / mapped.len() as f64
}

/// The acceptance figures of a positioner's axis, for a turntable: its line
/// within 0.02 mm and 0.005°, a point 400 mm from it within 0.03 mm at
/// held-out values, three seeds of the tracker noise, with the nod.
#[test]
fn a_turntables_axis_and_held_out_points_from_tracker_readings() {
    for seed in [1, 2, 3] {
        let t = truth(0.003);
        let readings = read(&t, &sweep(), seed);
        let fit = fit_turntable(&request(readings.clone()))
            .unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        assert!(fit.solver.converged, "{:?}", fit.solver);
        let (d, a) = line_error(&fit, &t);
        let p0 = Vector3::from(fit.reflectors_mm[0]) * 1e-3;
        let (max_fit, rms_fit) = prediction_error(&fit.model, &p0, &t);
        let (max_nom, rms_nom) = prediction_error(&nominal(), &nominal_point(&readings), &t);
        let ds = fit.model.axis.scale - t.rotate.scale;
        // Held-out readings (noisy) through the fit, as `--validate` reports them.
        let held = held_out_errors_mm(&fit, &read(&t, &held_out(), seed + 100));
        let held_max = held.iter().copied().fold(0.0, f64::max);
        println!(
            "seed {seed}: fit rms {:.4} mm max {:.4} mm ({} iterations); axis {d:.4} mm {a:.5}° \
             (σ {:.4} mm {:.5}°); scale off {ds:+.2e} (σ {:.1e}); held-out point 400 mm from the axis: \
             calibrated max {max_fit:.4} mm rms {rms_fit:.4} mm, nominal max {max_nom:.3} mm rms {rms_nom:.3} mm; \
             held-out readings max {held_max:.4} mm",
            fit.rms_mm,
            fit.max_mm,
            fit.solver.iterations,
            fit.sigma.point_mm,
            fit.sigma.direction_deg,
            fit.sigma.scale,
        );
        assert!(d <= 0.02 && a <= 0.005, "seed {seed}: axis {d} mm {a}°");
        assert!(max_fit <= 0.03, "seed {seed}: held-out point {max_fit} mm");
        assert!(
            max_nom > 10.0 * max_fit,
            "seed {seed}: nominal {max_nom} mm"
        );
        assert!(
            ds.abs() <= 4.0 * fit.sigma.scale,
            "seed {seed}: scale {ds:e}"
        );
        let back = Turntable::from_json(&fit.model.to_json()).unwrap();
        let e = (back.point_in_cell(-77.0, &p0) - fit.model.point_in_cell(-77.0, &p0)).norm();
        assert!(e < 1e-9, "{e}");
    }
}

/// Without the nod and the noise the fit gives back the truth's line and
/// scale to rounding, and predicts every reflector at any value exactly.
#[test]
fn exact_readings_give_the_truth_back() {
    let mut t = truth(0.0);
    t.noise_mm = 0.0;
    let mut req = request(read(&t, &sweep(), 1));
    req.tracker_sigma_mm = 1e-6;
    let fit = fit_turntable(&req).unwrap();
    let (d, a) = line_error(&fit, &t);
    assert!(d < 1e-6 && a < 1e-7, "{d} mm {a}°");
    assert!((fit.model.axis.scale - t.rotate.scale).abs() < 1e-9);
    let e = held_out_errors_mm(&fit, &read(&t, &held_out(), 2));
    assert!(e.iter().all(|x| *x < 1e-6), "{e:?}");
}

/// What the readings cannot carry is refused, naming the reason.
#[test]
fn fits_the_readings_cannot_carry_are_refused() {
    let t = truth(0.003);
    let refused = |req: TurntableFitRequest| fit_turntable(&req).unwrap_err();
    // Three values; a 60° span.
    let r = refused(request(read(&t, &[-30.0, 0.0, 30.0], 1)));
    assert_eq!(r.reason, RefusalReason::TooFewAngles, "{r}");
    let r = refused(request(read(&t, &[-30.0, -10.0, 10.0, 30.0], 1)));
    assert_eq!(r.reason, RefusalReason::SpanTooSmall, "{r}");
    // One reading off by 0.15 mm, named.
    let mut readings = read(&t, &sweep(), 1);
    readings[5].xyz_mm[2] += 0.15;
    let r = refused(request(readings));
    assert_eq!(r.reason, RefusalReason::ResidualOutlier, "{r}");
    assert_eq!(r.row, Some(6));
    // A reflector 5 mm from the axis.
    let mut near = t.clone();
    near.reflectors[1] = Vector3::new(0.004, 0.003, 1.12);
    let mut req = request(read(&near, &sweep(), 1));
    req.reflectors_mm[1] = [4.0, 3.0, 20.0];
    assert_eq!(refused(req).reason, RefusalReason::ReflectorNearAxis);
    // A nod of 0.05°: no rigid turntable explains it.
    let r = refused(request(read(&truth(0.05), &sweep(), 1)));
    assert_eq!(r.reason, RefusalReason::ResidualsTooLarge, "{r}");
    assert!(r.fit.is_some());
    // A reading naming a reflector not given; a value not finite.
    let mut readings = read(&t, &sweep(), 1);
    readings[0].reflector = 2;
    assert_eq!(
        refused(request(readings)).reason,
        RefusalReason::UnknownReflector
    );
    let mut readings = read(&t, &sweep(), 1);
    readings[3].value_deg = f64::NAN;
    let r = refused(request(readings));
    assert_eq!((r.reason, r.row), (RefusalReason::NotFinite, Some(4)));
}

/// Standard deviation of `v` about its mean.
fn spread_of(v: &[f64]) -> f64 {
    let m = v.iter().sum::<f64>() / v.len() as f64;
    (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() - 1) as f64).sqrt()
}

/// A turntable's plan (`plan::make_turntable_plan`: one sweep, every
/// reflector at every value, 9 values over −120…150°, not the example's)
/// read from the truth without its nod (noise alone) over 30 seeds and
/// fitted: the fitted zero offset, scale, direction and reference
/// reflector scatter as the plan predicted (within 2×, as the positioner's
/// and the robot's plans are held).
#[test]
fn a_planned_turntable_measurement_scatters_as_predicted() {
    use robocal_core::plan::{make_turntable_plan, plan_csv, TurntablePlanSettings};
    let plan = make_turntable_plan(
        &nominal(),
        &TurntablePlanSettings {
            reflectors_mm: DESIGN_MM.to_vec(),
            travel_deg: [-120.0, 150.0],
            values: 9,
            ..TurntablePlanSettings::default()
        },
    )
    .unwrap();
    let text = plan_csv(&plan.points);
    assert!(text.starts_with("point,e1\nP1,-120\n"), "{text}");
    let t = truth(0.0);
    let (mut zero, mut scale, mut directions) = (Vec::new(), Vec::new(), Vec::new());
    for seed in 1..=30u64 {
        let fit = fit_turntable(&request(read(&t, &plan.values_deg, seed)))
            .unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        zero.push(fit.model.axis.zero_offset.to_degrees());
        scale.push(fit.model.axis.scale);
        directions.push(fit.model.axis.direction);
    }
    let mean = directions.iter().sum::<Vector3<f64>>().normalize();
    let direction_rms = (directions
        .iter()
        .map(|d| d.angle(&mean).powi(2))
        .sum::<f64>()
        / (directions.len() as f64 - 1.0))
        .sqrt();
    let s = plan.sigma;
    for (name, empirical, predicted) in [
        ("zero offset [deg]", spread_of(&zero), s.zero_offset_deg),
        ("scale", spread_of(&scale), s.scale),
        (
            "direction [deg]",
            direction_rms.to_degrees(),
            s.direction_deg,
        ),
    ] {
        let ratio = empirical / predicted;
        println!("turntable {name}: predicted {predicted:.3e}, 30 fits {empirical:.3e}, ratio {ratio:.2}");
        assert!(
            (0.5..=2.0).contains(&ratio),
            "{name}: {empirical} vs {predicted}"
        );
    }
}
