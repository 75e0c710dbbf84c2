//! TCP and work-object calibration against a simulated truth (`tcp/truth.rs`:
//! a hand-written DH chain of the calibrated model, tips applied here, 0.01 mm
//! repeatability, seeded).

#[path = "tcp/truth.rs"]
mod truth;

#[path = "tcp/judged.rs"]
mod judged;

use nalgebra::{Matrix3, Vector3};
use robocal_core::cell_fit::tcp::{self, axis, fixed_point, tracker, NotFittedReason, TcpMethod};
use robocal_core::cell_fit::work_object::{self, WorkObjectPoints};
use robocal_core::model::orientation::rotation_angle_between;
use robocal_core::model::Pose;
use robocal_core::sim::random_configurations;
use truth::*;

/// The production tool: tip 250 mm out, off-centre, its z tilted 30° about
/// the flange's y.
fn true_tool() -> Pose {
    Pose::new(
        rot(Vector3::y(), 30f64.to_radians()),
        Vector3::new(0.03, -0.02, 0.25),
    )
}

/// Readings with the tip of `tool` held at `point` (± 0.01 mm) in `n`
/// orientations tilted by `tilt_deg`.
fn fixed_point_readings(
    tool: &Pose,
    point: Vector3<f64>,
    n: usize,
    tilt_deg: f64,
    seed: u64,
) -> Vec<Vec<f64>> {
    let model = calibrated_ur10();
    let mut noise = Noise::new(seed, 1e-5);
    let out: Vec<Vec<f64>> = tilted_orientations(n, tilt_deg)
        .into_iter()
        .filter_map(|r| {
            let target = Pose::new(r, point + noise.vec());
            readings_for(&model, tool, &target)
        })
        .collect();
    assert_eq!(out.len(), n, "the IK must reach every orientation");
    out
}

#[test]
fn fixed_point_recovers_the_tcp_from_4_to_8_orientations() {
    let model = calibrated_ur10();
    let tool = true_tool();
    let point = Vector3::new(0.6, 0.2, 0.3);
    for (n, seed) in [(4, 1), (5, 2), (6, 3), (8, 4)] {
        let q = fixed_point_readings(&tool, point, n, 30.0, seed);
        let flanges = tcp::flange_poses(&model, &q).unwrap();
        let fit = fixed_point::fit(&flanges).unwrap();
        let err_mm = (fit.tcp.p - tool.p).norm() * 1e3;
        eprintln!(
            "fixed point, n = {n}: TCP off by {err_mm:.4} mm, rms {:.4} mm",
            fit.rms_mm
        );
        assert!(err_mm <= 0.05, "n = {n}: TCP off by {err_mm} mm");
        let p = Vector3::from(fit.fixed_point_mm.unwrap()) * 1e-3;
        assert!((p - point).norm() * 1e3 <= 0.05, "n = {n}: point off");
        assert_eq!(fit.method, TcpMethod::FixedPoint);
        assert_eq!(fit.residual_mm.len(), n);
        // 0.01 mm per axis: the tip residuals are of that size, never 0.
        assert!(fit.rms_mm > 1e-4 && fit.rms_mm < 0.03, "rms {}", fit.rms_mm);
        let sigma = fit.sigma_mm.iter().map(|s| s * s).sum::<f64>().sqrt();
        assert!(sigma > 0.0 && sigma < 0.05, "σ {sigma}");
        assert!(err_mm < 5.0 * sigma, "n = {n}: error {err_mm} vs σ {sigma}");
        assert!(fit.orientation_spread_deg.unwrap() > 20.0);
    }
}

#[test]
fn fixed_point_on_the_nominal_model_is_worse_than_on_the_calibrated_one() {
    // The solve uses the calibrated geometry: the same readings on the
    // nominal model miss the TCP by the geometry's error.
    let mut model = calibrated_ur10();
    let tool = true_tool();
    let q = fixed_point_readings(&tool, Vector3::new(0.6, 0.2, 0.3), 6, 30.0, 5);
    let good = fixed_point::fit(&tcp::flange_poses(&model, &q).unwrap()).unwrap();
    model.calibrated = model.nominal.clone();
    let bad = fixed_point::fit(&tcp::flange_poses(&model, &q).unwrap()).unwrap();
    let (eg, eb) = (
        (good.tcp.p - tool.p).norm() * 1e3,
        (bad.tcp.p - tool.p).norm() * 1e3,
    );
    assert!(
        eb > 0.2 && eb > 10.0 * eg,
        "nominal {eb} mm, calibrated {eg} mm"
    );
    assert!(bad.rms_mm > 5.0 * good.rms_mm);
}

#[test]
fn fixed_point_refuses_orientations_about_one_axis_and_too_few_poses() {
    let model = calibrated_ur10();
    let tool = Pose::from_translation(Vector3::new(0.0, 0.0, 0.2));
    let point = Vector3::new(0.6, 0.2, 0.3);
    // Turned about the tool's own axis only: the tip's position along it is
    // unobservable.
    let down = rot(Vector3::x(), std::f64::consts::PI);
    let q: Vec<Vec<f64>> = (0..5)
        .map(|i| {
            let r = down * rot(Vector3::z(), (30.0 * i as f64).to_radians());
            readings_for(&model, &tool, &Pose::new(r, point)).unwrap()
        })
        .collect();
    let flanges = tcp::flange_poses(&model, &q).unwrap();
    match fixed_point::fit(&flanges) {
        Err(e) => {
            assert_eq!(e.reason, NotFittedReason::OrientationsTooSimilar, "{e}");
            let m = &e.message;
            assert!(m.contains("orientations too similar"), "{m}");
            assert!(m.contains("tilt the tool"), "{m}");
            // About the tool's own axis the spread is 0°, of 5° needed.
            assert!(e.measured.unwrap() < 0.01, "{e:?}");
            assert_eq!(e.needed, Some(fixed_point::MIN_SPREAD_DEG));
        }
        other => panic!("expected a refusal, got {other:?}"),
    }
    // Tilts of 2° only.
    let q = fixed_point_readings(&tool, point, 5, 2.0, 6);
    let e = fixed_point::fit(&tcp::flange_poses(&model, &q).unwrap()).unwrap_err();
    assert_eq!(e.reason, NotFittedReason::OrientationsTooSimilar, "{e}");
    let spread = e.measured.unwrap();
    assert!(spread > 1.0 && spread < 5.0, "2° tilts: spread {spread}°");
    // Three orientations.
    let e = fixed_point::fit(&flanges[..3]).unwrap_err();
    assert!(e.to_string().contains("at least 4"), "{e}");
    assert_eq!(e.reason, NotFittedReason::TooFewReadings);
    assert_eq!((e.measured, e.needed), (Some(3.0), Some(4.0)));
    // A row with the wrong joint count.
    let e = tcp::flange_poses(&model, &[vec![0.0; 5]]).unwrap_err();
    assert!(e.to_string().contains("6 joints"), "{e}");
    assert_eq!(e.reason, NotFittedReason::JointCount);
    assert_eq!(
        (e.row, e.measured, e.needed),
        (Some(1), Some(5.0), Some(6.0))
    );
}

/// Random readings and the true flange poses of the calibrated robot.
fn random_readings(n: usize, seed: u64) -> (Vec<Vec<f64>>, Vec<Pose>) {
    let model = calibrated_ur10();
    let mut noise = Noise::new(seed, 0.0);
    let qs = random_configurations(&model.nominal, n, noise.rng());
    let deg = qs
        .iter()
        .map(|q| {
            model
                .nominal
                .joints_to_controller(q)
                .iter()
                .map(|v| v.to_degrees())
                .collect()
        })
        .collect();
    let flanges = qs
        .iter()
        .map(|q| hand_flange(&model.calibrated, q))
        .collect();
    (deg, flanges)
}

#[test]
fn tracker_reflector_and_probe_give_the_tool() {
    let model = calibrated_ur10();
    let tool = true_tool();
    let (q, truth) = random_readings(8, 7);
    let mut noise = Noise::new(8, 1e-5);
    // The reflector at the tip and a 6-D probe frame at the TCP, measured in
    // the tracker frame (0.01 mm, 0.003°).
    let probe: Vec<Pose> = truth
        .iter()
        .map(|f| {
            let mut m = model.cell_from_base.compose(&f.compose(&tool));
            m.p += noise.vec();
            let w = noise.vec() * (0.003f64.to_radians() / 1e-5);
            m.r = rot(w.normalize(), w.norm()) * m.r;
            m
        })
        .collect();
    let flanges = tcp::flange_poses(&model, &q).unwrap();
    let points: Vec<Vector3<f64>> = probe.iter().map(|m| m.p).collect();
    let base = tcp::cell_points_to_base(&model, &points);
    let fit = tracker::fit_points(&flanges, &base).unwrap();
    assert!((fit.tcp.p - tool.p).norm() * 1e3 <= 0.05);
    assert!(fit.rms_mm > 1e-4 && fit.rms_mm < 0.05, "{}", fit.rms_mm);
    let base_frames: Vec<Pose> = probe.iter().map(|m| model.cell_to_base(m)).collect();
    let fit = tracker::fit_frames(&flanges, &base_frames).unwrap();
    assert_eq!(fit.method, TcpMethod::TrackerFrame);
    assert!((fit.tcp.p - tool.p).norm() * 1e3 <= 0.05);
    let ang = rotation_angle_between(&fit.tcp.r, &tool.r).to_degrees();
    eprintln!("6-D probe: frame off by {ang:.5}°");
    assert!(ang <= 0.01, "probe frame off by {ang}°");
    assert!(fit.sigma_deg.unwrap() > 0.0 && fit.sigma_deg.unwrap() < 0.01);
    // Without the registration (tracker points taken as base points) the
    // reflector cannot agree with the flanges.
    let wrong = tracker::fit_points(&flanges, &points).unwrap();
    assert!(wrong.rms_mm > 10.0, "{}", wrong.rms_mm);
    // Counts must match.
    let e = tracker::fit_points(&flanges, &base[..7]).unwrap_err();
    assert!(e.to_string().contains("one measurement per row"), "{e}");
}

#[test]
fn axis_from_a_second_point_gives_the_tool_z() {
    let model = calibrated_ur10();
    let tool = true_tool();
    let point = Vector3::new(0.6, 0.2, 0.3);
    // A mark 150 mm behind the tip on the tool's axis, held at the point too.
    let mark = Pose::new(tool.r, tool.p - tool.r * Vector3::new(0.0, 0.0, 0.15));
    let tip_fit = fixed_point::fit(
        &tcp::flange_poses(&model, &fixed_point_readings(&tool, point, 6, 30.0, 9)).unwrap(),
    )
    .unwrap();
    let mark_fit = fixed_point::fit(
        &tcp::flange_poses(&model, &fixed_point_readings(&mark, point, 6, 30.0, 10)).unwrap(),
    )
    .unwrap();
    let fit = axis::with_axis_point(tip_fit, &mark_fit.tcp.p, &mark_fit.sigma_mm).unwrap();
    let z_err = angle_deg(&fit.tcp.r.column(2).into_owned(), &tool.z_axis());
    let sigma = fit.sigma_deg.unwrap();
    eprintln!("axis point: z off by {z_err:.4}°, σ {sigma:.4}°");
    assert!(
        z_err < 0.03 && z_err < 3.0 * sigma,
        "z off by {z_err}°, σ {sigma}°"
    );
    assert!((fit.axis_length_mm.unwrap() - 150.0).abs() < 0.1);
    assert_eq!(fit.axis, Some(axis::AxisSource::Point));
    // Orthonormal, right-handed.
    assert!((fit.tcp.r.transpose() * fit.tcp.r - Matrix3::identity()).norm() < 1e-12);
    assert!((fit.tcp.r.determinant() - 1.0).abs() < 1e-12);
    // A second point at the tip is refused.
    let e = axis::with_axis_point(fit.clone(), &fit.tcp.p, &[0.0; 3]).unwrap_err();
    assert!(e.to_string().contains("at least 5 mm"), "{e}");
    assert_eq!(e.reason, NotFittedReason::AxisPointTooClose);
    assert_eq!((e.measured, e.needed), (Some(0.0), Some(5.0)));
    // The tip stays reported: only its axis failed.
    assert_eq!(e.tip.as_deref().map(|t| t.tcp.p), Some(fit.tcp.p));
}

#[test]
fn axis_from_a_touched_plane_gives_the_tool_z() {
    let model = calibrated_ur10();
    let tool = true_tool();
    // A plane tilted 20° about x through (0.6, 0, 0.25); the tool flat on it
    // (its z into the plane), touched at five spread points, 0.01 mm.
    let normal = rot(Vector3::x(), 20f64.to_radians()) * Vector3::z();
    let (u, v) = (Vector3::x(), normal.cross(&Vector3::x()));
    let c = Vector3::new(0.6, 0.0, 0.25);
    let mut noise = Noise::new(11, 1e-5);
    let q: Vec<Vec<f64>> = [
        (0.0, 0.0),
        (0.15, 0.0),
        (0.0, 0.15),
        (-0.1, 0.1),
        (0.1, -0.12),
    ]
    .iter()
    .enumerate()
    .map(|(i, (a, b))| {
        let z = -normal;
        let r0 = Matrix3::from_columns(&[u, -v, z]);
        let r = r0 * rot(Vector3::z(), (25.0 * i as f64).to_radians());
        let p = c + u * *a + v * *b + noise.vec();
        readings_for(&model, &tool, &Pose::new(r, p)).unwrap()
    })
    .collect();
    let start = tcp::ToolFit {
        tcp: Pose::from_translation(tool.p),
        ..tracker_fit_stub()
    };
    let fit = axis::with_plane(start, &tcp::flange_poses(&model, &q).unwrap()).unwrap();
    let z_err = angle_deg(&fit.tcp.r.column(2).into_owned(), &tool.z_axis());
    eprintln!("plane axis: z off by {z_err:.5}°");
    assert!(z_err < 0.01, "z off by {z_err}°");
    let flat = fit.plane_residual_mm.as_ref().unwrap();
    assert!(flat.iter().all(|d| *d < 0.05), "{flat:?}");
    assert!(fit.sigma_deg.unwrap() < 0.05);
    // Touches on a line are refused.
    let line: Vec<Pose> = (0..4)
        .map(|i| Pose::from_translation(Vector3::new(0.1 * i as f64, 0.0, 0.0)))
        .collect();
    let e = axis::with_plane(fit, &line).unwrap_err();
    assert!(e.to_string().contains("lie on a line"), "{e}");
    assert_eq!(e.reason, NotFittedReason::PlaneTouchesInLine);
    assert!(e.measured.unwrap() < 1e-9 && e.tip.is_some(), "{e:?}");
}

/// A fit to start an axis from (its TCP is set by the caller).
fn tracker_fit_stub() -> tcp::ToolFit {
    let f: Vec<Pose> = (0..3).map(|_| Pose::identity()).collect();
    tracker::fit_points(&f, &[Vector3::zeros(); 3]).unwrap()
}

/// A work object 400 mm × 300 mm, turned and tilted, in the base frame.
fn true_work_object() -> Pose {
    Pose::new(
        rot(Vector3::z(), 0.7) * rot(Vector3::new(1.0, 1.0, 0.0), 0.15),
        Vector3::new(0.5, -0.3, 0.2),
    )
}

fn wo_points(w: &Pose) -> [Vector3<f64>; 4] {
    [
        w.transform_point(&Vector3::zeros()),
        w.transform_point(&Vector3::new(0.4, 0.0, 0.0)),
        w.transform_point(&Vector3::new(0.1, 0.3, 0.0)),
        w.transform_point(&Vector3::new(0.3, 0.25, 0.0)),
    ]
}

fn check_work_object(fit: &work_object::WorkObjectFit, w: &Pose) {
    let pos = (fit.pose.p - w.p).norm() * 1e3;
    let ang = rotation_angle_between(&fit.pose.r, &w.r).to_degrees();
    eprintln!("work object: origin off by {pos:.4} mm, orientation by {ang:.5}°");
    assert!(pos <= 0.05, "origin off by {pos} mm");
    assert!(ang <= 0.01, "orientation off by {ang}°");
    assert!(fit.sigma_mm.unwrap() > 0.0 && fit.sigma_mm.unwrap() < 0.05);
    assert!(fit.sigma_deg.unwrap() < 0.01);
    assert!(fit.plane_residual_mm.iter().all(|d| *d < 0.06));
    assert!(
        (fit.xy_angle_deg - 71.565).abs() < 0.05,
        "{}",
        fit.xy_angle_deg
    );
}

#[test]
fn work_object_from_tracker_points() {
    let model = calibrated_ur10();
    let w = true_work_object();
    let mut noise = Noise::new(12, 1e-5);
    // Each point measured three times in the tracker frame.
    let mut groups: Vec<Vec<Vector3<f64>>> = wo_points(&w)
        .iter()
        .map(|p| {
            let cell: Vec<Vector3<f64>> = (0..3)
                .map(|_| model.cell_from_base.transform_point(p) + noise.vec())
                .collect();
            tcp::cell_points_to_base(&model, &cell)
        })
        .collect();
    let pts = WorkObjectPoints {
        plane: groups.pop().unwrap(),
        xy: groups.pop().unwrap(),
        x: groups.pop().unwrap(),
        origin: groups.pop().unwrap(),
    };
    let fit = work_object::fit(&pts).unwrap();
    check_work_object(&fit, &w);
    assert!(fit.scatter_mm.iter().all(|s| *s > 0.0 && *s < 0.05));
}

#[test]
fn work_object_touched_with_a_calibrated_tcp() {
    let model = calibrated_ur10();
    let tool = true_tool();
    let w = true_work_object();
    let mut noise = Noise::new(13, 1e-5);
    let down = w.r * rot(Vector3::x(), std::f64::consts::PI);
    let touches = |p: &Vector3<f64>, noise: &mut Noise| -> Vec<Vec<f64>> {
        (0..2)
            .map(|i| {
                let r = down * rot(Vector3::z(), (20.0 * i as f64).to_radians());
                readings_for(&model, &tool, &Pose::new(r, p + noise.vec())).unwrap()
            })
            .collect()
    };
    let [o, x, xy, plane] = wo_points(&w);
    let tips = |q: &[Vec<f64>]| work_object::touched_tips(&model, &tool.p, q).unwrap();
    let pts = WorkObjectPoints {
        origin: tips(&touches(&o, &mut noise)),
        x: tips(&touches(&x, &mut noise)),
        xy: tips(&touches(&xy, &mut noise)),
        plane: tips(&touches(&plane, &mut noise)),
    };
    let fit = work_object::fit(&pts).unwrap();
    check_work_object(&fit, &w);
}

#[test]
fn work_object_refuses_degenerate_points() {
    let p = |x: f64, y: f64| vec![Vector3::new(x, y, 0.0)];
    let fit = |o, x, xy| {
        work_object::fit(&WorkObjectPoints {
            origin: o,
            x,
            xy,
            plane: vec![],
        })
    };
    let e = fit(p(0.0, 0.0), p(0.005, 0.0), p(0.0, 0.2)).unwrap_err();
    assert!(e.to_string().contains("from the origin"), "{e}");
    assert_eq!(e.reason, NotFittedReason::XPointTooClose);
    assert!((e.measured.unwrap() - 5.0).abs() < 1e-9, "{e:?}");
    let e = fit(p(0.0, 0.0), p(0.3, 0.0), p(0.5, 0.02)).unwrap_err();
    assert!(e.to_string().contains("on the x axis"), "{e}");
    assert_eq!(e.reason, NotFittedReason::XyPointOnXAxis);
    // OX along x, OY = (0.5, 0.02): atan(0.02/0.5) = 2.29°.
    let want = (0.02f64 / 0.5).atan().to_degrees();
    assert!((e.measured.unwrap() - want).abs() < 1e-9, "{e:?}");
    let e = fit(p(0.0, 0.0), vec![], p(0.5, 0.2)).unwrap_err();
    assert!(e.to_string().contains("no `x` point"), "{e}");
    assert_eq!(e.reason, NotFittedReason::MissingPoint);
    let e = fit(p(0.0, 0.0), p(0.3, f64::NAN), p(0.0, 0.2)).unwrap_err();
    assert!(e.to_string().contains("finite"), "{e}");
    // Single touches: a frame, but σ unknown.
    let f = fit(p(0.0, 0.0), p(0.3, 0.0), p(0.0, 0.2)).unwrap();
    assert_eq!(f.sigma_mm, None);
    assert!((f.pose.r - Matrix3::identity()).norm() < 1e-12);
}
