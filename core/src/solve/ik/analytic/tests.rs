//! Tests of the closed forms: structure detection, angle wrapping, and every
//! branch mapping back to its target on the presets.

use super::*;
use crate::model::kinematics::fk;
use crate::model::preset;

#[test]
fn structures_are_detected() {
    assert_eq!(
        AnalyticIk::new(&preset("ys100").unwrap())
            .unwrap()
            .structure(),
        Structure::SphericalWrist
    );
    assert_eq!(
        AnalyticIk::new(&preset("hh800").unwrap())
            .unwrap()
            .structure(),
        Structure::SphericalWrist
    );
    assert_eq!(
        AnalyticIk::new(&preset("ur5").unwrap())
            .unwrap()
            .structure(),
        Structure::ThreeParallel
    );
    let mut m = preset("ys100").unwrap();
    m.links[4].a = 0.01;
    assert!(AnalyticIk::new(&m).is_err());
}

#[test]
fn wrap_and_round_turns_match_the_library_functions() {
    let reference = |x: f64| {
        let y = x.rem_euclid(TAU);
        if y > PI {
            y - TAU
        } else {
            y
        }
    };
    let mut xs = vec![
        0.0,
        -0.0,
        PI,
        -PI,
        TAU,
        -TAU,
        3.0 * PI,
        -3.0 * PI,
        0.5,
        -0.5,
        1.5,
        -2.5,
    ];
    xs.extend((0..20_000).map(|k| (k as f64 - 10_000.0) * 0.0123));
    xs.extend([1e3, -1e3 - 0.25, 4.4e15 + 0.5, 1e17, -1e17]);
    for x in xs {
        let (a, b) = (wrap(x), reference(x));
        assert!(a > -PI && a <= PI, "wrap({x}) = {a}");
        // The same angle up to rounding, and the same representative.
        assert!(
            (a - b).abs() <= 1e-12 * x.abs().max(1.0),
            "wrap({x}) = {a}, fmod gives {b}"
        );
        assert_eq!(round_turns(x), x.round(), "round_turns({x})");
    }
    assert!(wrap(f64::INFINITY).is_nan() && wrap(f64::NAN).is_nan());
    assert!(round_turns(f64::NAN).is_nan());
    assert_eq!(round_turns(0.49999999999999994), 0.0);
    assert_eq!(round_turns(-0.5), -1.0);
    assert_eq!(round_turns(2.5), 3.0);
}

#[test]
fn wrap_into_prefers_limits_then_reference() {
    assert_eq!(wrap_into(3.0, [-PI, PI], 0.0), (3.0, true));
    let (v, ok) = wrap_into(3.0, [-2.0 * TAU, 2.0 * TAU], -3.0);
    assert!(ok && (v - (3.0 - TAU)).abs() < 1e-12);
    let (_, ok) = wrap_into(3.0, [-1.0, 1.0], 0.0);
    assert!(!ok);
}

#[test]
fn every_branch_maps_back_on_the_presets() {
    for name in ["ys100", "hh800", "ur10"] {
        let m = preset(name).unwrap();
        let ik = AnalyticIk::new(&m).unwrap();
        let q = [0.3, 1.45, 0.2, 0.4, 0.7, -0.6];
        let t = fk(&m, &q).unwrap();
        let sols = ik.solve(&t, None);
        assert!(sols.len() >= 2, "{name}: {}", sols.len());
        let mut found = false;
        for s in &sols {
            let p = fk(&m, &s.q).unwrap();
            assert!((p.p - t.p).norm() < 1e-9, "{name} {:?}", s.configuration);
            assert!((p.r - t.r).norm() < 1e-9, "{name}");
            assert_eq!(ik.configuration(&s.q), Some(s.configuration), "{name}");
            if s.q.iter().zip(&q).all(|(a, b)| wrap(a - b).abs() < 1e-7) {
                found = true;
            }
        }
        assert!(found, "{name}: original branch missing");
    }
}
