//! The simulator against independent expectations: an error-free truth measures
//! the nominal forward kinematics exactly, compliance sags the TCP along gravity,
//! the tracker frame maps base to tracker coordinates, the noise has the requested
//! spread, and the thesis's §7.4 robot carries Tables 7.1/7.2 (`robocal
//! simulate` writing CSV that parses back is a test of the root crate).

use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal_core::measure::SetRole;
use robocal_core::model::kinematics::fk;
use robocal_core::model::{preset, RobotModel};
use robocal_core::sim::{
    perturb_geometry, random_configurations, tracker_frame, ys100_table_7_1, ErrorMagnitudes,
    TrueRobot,
};

fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

#[test]
fn error_free_noise_free_truth_measures_nominal_fk_exactly() {
    for name in ["ys100", "hh800", "ur5", "ur10"] {
        let nominal = preset(name).unwrap();
        assert!(!nominal.has_compliance());
        let truth = TrueRobot::new(nominal.clone());
        let qs = random_configurations(&nominal, 50, &mut rng(11));
        let rows = truth
            .measure(&qs, Some(20.0), Some(SetRole::Validation), &mut rng(12))
            .unwrap();
        assert_eq!(rows.len(), 50);
        for (q, r) in qs.iter().zip(&rows) {
            let p = fk(&nominal, q).unwrap().p;
            assert_eq!(r.xyz_mm, [p.x * 1e3, p.y * 1e3, p.z * 1e3], "{name}");
            let back: Vec<f64> = r.q_deg.iter().map(|d| d.to_radians()).collect();
            let q_back = nominal.joints_from_controller(&back);
            for (a, b) in q_back.iter().zip(q) {
                assert!((a - b).abs() < 1e-14);
            }
            assert_eq!(r.payload_kg, Some(20.0));
            assert_eq!(r.set, Some(SetRole::Validation));
            assert_eq!(r.rpy_deg, None);
        }
    }
}

/// YS100 nominal geometry with the Table 7.2 compliance.
fn compliant_ys100() -> RobotModel {
    let mut m = preset("ys100").unwrap();
    let c = ys100_table_7_1().compliance();
    for (l, c) in m.links.iter_mut().zip(c) {
        l.compliance = c;
    }
    m
}

#[test]
fn compliance_sags_the_tcp_along_gravity() {
    // Outstretched floor-robot pose: the TCP sinks by millimetres, more with payload.
    let m = compliant_ys100();
    let truth = TrueRobot::new(m.clone());
    let q = [0.0, 1.2, -0.4, 0.0, 0.6, 0.0];
    let p_nom = fk(&m, &q).unwrap().p;
    let sag = |payload: f64| truth.true_position(&q, Some(payload)).unwrap() - p_nom;
    let (empty, loaded) = (sag(0.0), sag(110.0));
    assert!(empty.z < -1e-4, "{empty:?}");
    assert!(loaded.z < empty.z, "{loaded:?} vs {empty:?}");
    assert!(
        loaded.z.abs() > 3.0 * loaded.x.hypot(loaded.y),
        "{loaded:?}"
    );

    // A point payload at the TCP on massless links: to first order the TCP moves
    // by J·C·Jᵀ·(M g), which never has a component against gravity.
    let mut point = m.clone();
    for l in point.links.iter_mut() {
        l.mass = 0.0;
    }
    point.payload.com = Vector3::zeros();
    let truth = TrueRobot::new(point.clone());
    for q in random_configurations(&point, 200, &mut rng(5)) {
        let d = truth.true_position(&q, Some(200.0)).unwrap() - fk(&point, &q).unwrap().p;
        let along_gravity = d.dot(&point.gravity.normalize());
        assert!(along_gravity > -1e-9, "{q:?}: {d:?}");
    }

    // A ceiling-mounted robot (gravity +z in its base frame) sags towards +z.
    let mut ceiling = point.clone();
    ceiling.gravity = -ceiling.gravity;
    let truth = TrueRobot::new(ceiling.clone());
    let q = [0.0, 1.2, -0.4, 0.0, 0.6, 0.0];
    let d = truth.true_position(&q, Some(200.0)).unwrap() - fk(&ceiling, &q).unwrap().p;
    assert!(d.z > 1e-4, "{d:?}");
}

#[test]
fn tracker_frame_maps_base_to_tracker_and_round_trips() {
    let tf = tracker_frame(10.0, -20.0, 30.0, [1000.0, -3240.0, 500.0]);
    // The base origin sits at the offset in tracker coordinates.
    let o = tf.transform_point(&Vector3::zeros());
    assert!((o - Vector3::new(1.0, -3.24, 0.5)).norm() < 1e-15);
    let p = Vector3::new(0.4, -1.1, 0.9);
    let back = tf.inverse().transform_point(&tf.transform_point(&p));
    assert!((back - p).norm() < 1e-14);
    // A pure yaw of 90°: the base x axis is the tracker y axis.
    let yaw = tracker_frame(0.0, 0.0, 90.0, [0.0; 3]);
    let x = yaw.transform_point(&Vector3::x());
    assert!((x - Vector3::y()).norm() < 1e-15);

    // Measurements in the tracker frame are the base-frame ones moved by `tf`.
    let m = ys100_table_7_1();
    let base = TrueRobot::new(m.clone());
    let moved = TrueRobot {
        tracker_from_base: tf,
        ..base.clone()
    };
    let qs = random_configurations(&m, 20, &mut rng(2));
    let rb = base.measure(&qs, None, None, &mut rng(3)).unwrap();
    let rt = moved.measure(&qs, None, None, &mut rng(3)).unwrap();
    for (a, b) in rb.iter().zip(&rt) {
        let pb = Vector3::from(a.xyz_mm) * 1e-3;
        let pt = Vector3::from(b.xyz_mm) * 1e-3;
        assert!((tf.transform_point(&pb) - pt).norm() < 1e-12);
        assert!((tf.inverse().transform_point(&pt) - pb).norm() < 1e-12);
        assert_eq!(a.q_deg, b.q_deg);
    }
}

#[test]
fn noise_has_the_requested_standard_deviation() {
    let m = preset("ur5").unwrap();
    let truth = TrueRobot {
        noise_mm: 0.05,
        ..TrueRobot::new(m.clone())
    };
    let q = vec![0.3, -1.2, 1.4, -0.5, 1.1, 0.2];
    let p = truth.true_position(&q, None).unwrap() * 1e3;
    let n = 20_000;
    let qs = vec![q; n];
    let rows = truth.measure(&qs, None, None, &mut rng(99)).unwrap();
    for axis in 0..3 {
        let e: Vec<f64> = rows.iter().map(|r| r.xyz_mm[axis] - p[axis]).collect();
        let mean = e.iter().sum::<f64>() / n as f64;
        let std = (e.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt();
        // Standard errors: mean 0.05/√n ≈ 3.5e-4 mm, std ≈ 0.05/√(2n) ≈ 2.5e-4 mm.
        assert!(mean.abs() < 2e-3, "axis {axis}: mean {mean}");
        assert!((std - 0.05).abs() < 1.5e-3, "axis {axis}: std {std}");
    }
    // Seeded: the same seed reproduces the draws, another seed does not.
    let again = truth.measure(&qs[..10], None, None, &mut rng(99)).unwrap();
    assert_eq!(again[..], rows[..10]);
    let other = truth.measure(&qs[..10], None, None, &mut rng(100)).unwrap();
    assert_ne!(other[..], rows[..10]);
}

#[test]
fn ys100_table_7_1_carries_tables_7_1_and_7_2() {
    let m = ys100_table_7_1();
    let nominal = preset("ys100").unwrap();
    let deg = f64::to_radians;
    let close = |a: f64, b: f64| (a - b).abs() < 1e-12;
    let l = &m.links;
    // Row 1 (base): α0, β0, θ1, d1 as printed; a0, b0 as mm deviations.
    assert!(close(l[0].alpha, deg(0.1)) && close(l[0].beta, deg(0.1)));
    assert!(close(l[0].theta, deg(0.2)) && close(l[0].d, 0.5));
    assert!(close(l[0].a, -0.5e-3) && close(l[0].b, 0.05e-3));
    // Rows 2..6.
    assert!(close(l[1].alpha, deg(90.2)) && close(l[1].a, 0.33) && close(l[1].theta, deg(0.1)));
    assert!(close(l[2].alpha, deg(-0.1)) && close(l[2].a, 0.86) && close(l[2].d, -0.001));
    assert!(l[2].parallel && close(l[2].beta, deg(0.01)) && close(l[2].theta, deg(-1.0)));
    assert!(close(l[3].alpha, deg(89.9)) && close(l[3].a, 0.21) && close(l[3].d, 1.02));
    assert!(close(l[3].theta, deg(-1.3)));
    assert!(close(l[4].alpha, deg(-90.2)) && close(l[4].a, 0.002) && close(l[4].d, 0.002));
    assert!(close(l[4].theta, deg(-1.2)));
    assert!(close(l[5].alpha, deg(90.1)) && close(l[5].a, 0.003) && close(l[5].d, 0.185));
    assert!(close(l[5].theta, 0.0));
    // Row T as mm deviations from Table 2.1's (200, 50, 500) mm.
    assert!((m.tool.p - Vector3::new(0.1997, 0.05005, 0.50045)).norm() < 1e-12);
    // Table 7.2: 1/c = K2..K5, joints 1 and 6 rigid.
    let c = m.compliance();
    assert_eq!((c[0], c[5]), (0.0, 0.0));
    for (k, stiffness) in [(1, 1.5e6), (2, 1.0e6), (3, 1.2e6), (4, 1.0e6)] {
        assert!(
            (1.0 / c[k] - stiffness).abs() < 1e-6 * stiffness,
            "K{}",
            k + 1
        );
    }
    // Inertia, payload and limits are the preset's.
    for (a, b) in l.iter().zip(&nominal.links) {
        assert_eq!((a.mass, a.com, a.limits), (b.mass, b.com, b.limits));
    }
    assert_eq!(m.payload, nominal.payload);
    assert!(m.assumptions.iter().any(|s| s.contains("Table 7.1")));
    // The reading is stated in the model and survives the JSON round trip.
    let back = RobotModel::from_json(&m.to_json()).unwrap();
    assert_eq!(back.assumptions, m.assumptions);
    assert!(back.links[2].parallel && (back.links[2].beta - deg(0.01)).abs() < 1e-15);
}

#[test]
fn perturbed_truth_stays_within_the_requested_error() {
    let nominal = preset("ur5").unwrap();
    let mag = ErrorMagnitudes::from_mm_deg(0.5, 0.05);
    let truth = perturb_geometry(&nominal, &mag, &mut rng(1));
    let qs = random_configurations(&nominal, 100, &mut rng(2));
    let mut worst: f64 = 0.0;
    for q in &qs {
        let d = (fk(&truth, q).unwrap().p - fk(&nominal, q).unwrap().p).norm();
        worst = worst.max(d);
    }
    // ±0.5 mm / ±0.05° on ~30 parameters of a 1 m arm: millimetres, not centimetres.
    assert!(worst > 1e-4 && worst < 1e-2, "{worst}");
}
