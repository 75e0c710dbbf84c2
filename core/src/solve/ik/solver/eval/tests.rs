//! Tests of the prepared model's evaluation: its prediction against the
//! compensated model's own (networks, joint maps, both), the local
//! expansion's order and the seeds' use and check of it.

use super::*;
use crate::model::calibrated::mlp::{Features, Mlp, Normalisation, Shape};
use crate::model::calibrated::StoredCompensator;
use crate::model::kinematics::fk;
use crate::model::{preset, JointMaps};
use crate::sim::{synthetic_calibration, SyntheticErrors};
use nalgebra::Dyn;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn net(dof: usize, sin_cos: bool) -> Mlp {
    let features = Features {
        sin_cos,
        payload: false,
    };
    let shape = Shape {
        inputs: features.count(dof),
        hidden: 20,
        outputs: 3,
    };
    Mlp {
        dof,
        hidden: 20,
        features,
        weights: (0..shape.n_weights())
            .map(|k| ((k as f64) * 0.37).sin())
            .collect(),
        input_norm: Normalisation {
            centre: vec![0.1; shape.inputs],
            scale: vec![0.6; shape.inputs],
        },
        output_norm: Normalisation {
            centre: vec![1e-4, 0.0, -1e-4],
            scale: vec![3e3; 3],
        },
    }
}

/// Rigid and compliant, with and without a compensator, on YS100, UR10 and
/// the HH800 loop (calibrated: Hayati β, base and tool errors).
fn models() -> Vec<(String, CompensatedModel)> {
    let mut out = Vec::new();
    for name in ["ys100", "ur10", "hh800"] {
        let nominal = preset(name).unwrap();
        let cm = synthetic_calibration(&nominal, &SyntheticErrors::typical(1e-6), 7);
        out.push((
            format!("{name} nominal"),
            CompensatedModel::from_nominal(nominal),
        ));
        out.push((format!("{name} calibrated"), cm.clone()));
        for sin_cos in [false, true] {
            let mut c = cm.clone();
            c.compensator =
                Some(StoredCompensator::from(net(6, sin_cos)).into_arc_oriented(None, None));
            out.push((format!("{name} compensated {sin_cos}"), c));
        }
        let mut c = cm.clone();
        c.calibrated.joint_maps = Some(maps(c.calibrated.dof()));
        out.push((format!("{name} with joint maps"), c.clone()));
        c.compensator = Some(StoredCompensator::from(net(6, true)).into_arc_oriented(None, None));
        out.push((format!("{name} with joint maps and compensator"), c));
    }
    out
}

/// Joint maps of 40 harmonics of up to 20″ over [−1, 1.5] rad, faded over 0.1 rad.
fn maps(dof: usize) -> JointMaps {
    let arcsec = 1f64.to_radians() / 3600.0;
    let coefficient =
        |i: usize, k: usize, phase: f64| 20.0 * arcsec * ((i * 40 + k) as f64 * 0.71 + phase).sin();
    JointMaps {
        joints: (0..dof)
            .map(|i| {
                Some(crate::model::JointMap {
                    cos: (0..40).map(|k| coefficient(i, k, 0.0)).collect(),
                    sin: (0..40).map(|k| coefficient(i, k, 1.3)).collect(),
                    range: [-1.0, 1.5],
                    fade: 0.1,
                })
            })
            .collect(),
    }
}

/// To 1e-12 plus, with joint maps, what their tables' bounds allow: the
/// bound on `f` through a lever of at most 4 m for the pose, on `f'`
/// times a Jacobian entry of at most 4 m for the Jacobian (the tables
/// are tested against the series in `model/joint_map_table.rs`).
#[test]
fn prepared_prediction_equals_the_compensated_model() {
    let mut rng = ChaCha8Rng::seed_from_u64(23);
    for (name, m) in models() {
        let p = PreparedModel::new(&m, &m.nominal);
        let [bf, bs] = p.maps_bound();
        assert!(bf <= 1e-13 && bs <= 1e-12, "{name}: {bf:e} {bs:e}");
        let tol = 1e-12 + 4.0 * bf;
        let tol_j = 1e-12 + 4.0 * (bs + bf);
        let mut local = Local::new();
        for _ in 0..40 {
            let q: Vec<f64> = m
                .nominal
                .links
                .iter()
                .map(|l| rng.gen_range(l.limits[0]..l.limits[1]))
                .collect();
            let Ok((pose, jac)) = m.predict_base_with_jacobian(&q) else {
                assert!(p.predict_base(&q).is_none(), "{name}");
                continue;
            };
            let base = p.predict_base(&q).unwrap();
            let expect = m.predict_base(&q).unwrap();
            assert!((base.p - expect.p).amax() <= tol, "{name}");
            assert!((base.r - expect.r).amax() <= tol, "{name}");
            let mut j = OMatrix::<f64, U6, Dyn>::zeros(6);
            let pj = p
                .predict_with_jacobian(&q, &mut j, &mut Local::new())
                .unwrap();
            assert!((pj.p - pose.p).amax() <= tol, "{name}");
            assert!((pj.r - pose.r).amax() <= tol, "{name}");
            assert!((j - &jac).amax() <= tol_j, "{name}");
            let mut j6 = nalgebra::Matrix6::zeros();
            // One expansion reused from point to point, as the IK does.
            p.predict_with_jacobian(&q, &mut j6, &mut local).unwrap();
            // The chord with the derivative of the same point is the same Jacobian.
            let mut jc = nalgebra::Matrix6::zeros();
            let pc = p
                .predict_with_chord(&q, &mut jc, &local.derivative)
                .unwrap();
            assert!((pc.p - pose.p).amax() <= tol, "{name}");
            assert!((jc - &jac).amax() <= tol_j, "{name}");
            // So is the expansion at its own point.
            let mut jl = nalgebra::Matrix6::zeros();
            let pl = p.predict_local(&q, &mut jl, &mut local).unwrap();
            assert!((pl.p - pose.p).amax() <= tol, "{name}");
            assert!((pl.r - pose.r).amax() <= tol, "{name}");
            assert!((jl - &jac).amax() <= tol_j, "{name}");
            assert!((j6 - &jac).amax() <= tol_j, "{name}");
            let n = p.seed_fk(&q).unwrap();
            let e = fk(&m.nominal, &q).unwrap();
            assert!((n.p - e.p).amax() <= 1e-12 && (n.r - e.r).amax() <= 1e-12);
        }
    }
}

/// Away from its point, the expanded prediction differs from the exact
/// one by the expansion's remainder: halving the distance divides the gap
/// by 8 with joint maps only (third order), by 4 with a compensator
/// (second order).
#[test]
fn the_expansion_has_the_stated_order() {
    let mut rng = ChaCha8Rng::seed_from_u64(29);
    let mut checked = 0;
    for (name, m) in models() {
        let (has_maps, has_nn) = (m.calibrated.joint_maps.is_some(), m.compensator.is_some());
        let expected = match (has_maps, has_nn) {
            (true, false) => 7.0..9.0,
            (false, true) => 3.5..4.5,
            _ => continue,
        };
        let p = PreparedModel::new(&m, &m.nominal);
        for _ in 0..10 {
            // Inside the maps' range and away from its fade.
            let q: Vec<f64> = (0..6).map(|_| rng.gen_range(-0.8..1.3)).collect();
            let dir: Vec<f64> = (0..6).map(|_| rng.gen_range(-1.0..1.0)).collect();
            let mut local = Local::new();
            let mut jac = nalgebra::Matrix6::zeros();
            if p.predict_with_jacobian(&q, &mut jac, &mut local).is_none() {
                continue;
            }
            let mut gap = |h: f64| {
                let qh: Vec<f64> = q.iter().zip(&dir).map(|(q, d)| q + h * d).collect();
                let exact = p.predict_base(&qh)?;
                let expanded = p.predict_local(&qh, &mut jac, &mut local)?;
                Some((exact.p - expanded.p).norm())
            };
            let (Some(a), Some(b)) = (gap(2e-3), gap(1e-3)) else {
                continue;
            };
            assert!(a > 1e-12, "{name}: gap {a:e} m");
            let ratio = a / b;
            assert!(expected.contains(&ratio), "{name}: ratio {ratio}");
            checked += 1;
        }
    }
    assert!(checked >= 80, "{checked} points checked");
}

/// The thesis's correction expands the compensator on its exact prediction
/// (`predict_expanded` is `predict_base`), and a run that starts nearby on
/// that expansion (`predict_start` with `CompensatorAt::Kept`) has the exact chain and joint maps
/// and the compensator's first-order expansion: at the seed it equals
/// `predict_with_jacobian` (pose and Jacobian); away from it the gap to
/// the exact prediction is second order (halving the distance divides it
/// by 4) with and without joint maps; the check there is exact.
#[test]
fn a_run_starts_on_the_seeds_expansion_of_the_compensator() {
    let mut rng = ChaCha8Rng::seed_from_u64(37);
    let mut checked = 0;
    for (name, m) in models() {
        let p = PreparedModel::new(&m, &m.nominal);
        if !p.has_compensator() {
            continue;
        }
        for _ in 0..10 {
            let q1: Vec<f64> = (0..6).map(|_| rng.gen_range(-0.8..1.3)).collect();
            let dir: Vec<f64> = (0..6).map(|_| rng.gen_range(-1.0..1.0)).collect();
            let mut seed = Local::new();
            let (Some(pose), Some(exact)) =
                (p.predict_expanded(&q1, &mut seed), p.predict_base(&q1))
            else {
                continue;
            };
            assert!((pose.p - exact.p).amax() <= 1e-12, "{name}");
            assert!((pose.r - exact.r).amax() <= 1e-12, "{name}");
            let (mut ja, mut jb) = (nalgebra::Matrix6::zeros(), nalgebra::Matrix6::zeros());
            let mut fresh = Local::new();
            let a = p.predict_with_jacobian(&q1, &mut ja, &mut fresh).unwrap();
            let mut local = seed.clone();
            let b = p
                .predict_start(&q1, &mut jb, CompensatorAt::Kept, &mut local)
                .unwrap();
            assert!(local.is_exact_at(&q1), "{name}");
            assert!(
                (a.p - b.p).amax() <= 1e-12 && (a.r - b.r).amax() <= 1e-12,
                "{name}"
            );
            assert!((ja - jb).amax() <= 1e-12, "{name}");
            let gap = |h: f64| {
                let qh: Vec<f64> = q1.iter().zip(&dir).map(|(q, d)| q + h * d).collect();
                let mut local = seed.clone();
                let mut jac = nalgebra::Matrix6::zeros();
                let restarted = p.predict_start(&qh, &mut jac, CompensatorAt::Kept, &mut local)?;
                assert!(!local.is_exact_at(&qh), "{name}");
                let exact = p.predict_base(&qh)?;
                let checked = p.predict_checked(&qh, &restarted, &mut local)?;
                assert!((checked.p - exact.p).amax() <= 1e-12, "{name}");
                assert!((checked.r - exact.r).amax() <= 1e-12, "{name}");
                Some((exact.p - restarted.p).norm())
            };
            let (Some(a), Some(b)) = (gap(2e-3), gap(1e-3)) else {
                continue;
            };
            assert!(a > 1e-12, "{name}: gap {a:e} m");
            let ratio = a / b;
            assert!((3.5..4.5).contains(&ratio), "{name}: ratio {ratio}");
            checked += 1;
        }
    }
    assert!(checked >= 80, "{checked} points checked");
}

/// With a compensator whose seed expansion is rough (a GP's, single
/// precision): the expansion is within the rough prediction's bound of
/// the exact one but not taken as exact at its own point, so a run
/// starting there checks; the check is the exact prediction. A start too
/// far from the seed (in the GP's length scales) does not hold the
/// expansion, one next to it does.
#[test]
fn a_rough_seed_expansion_is_checked() {
    let gp = crate::model::calibrated::gp::predict::tests::random_gp(60, 3);
    let scale = gp.signal_variance * gp.alpha.iter().map(|a| a.abs()).sum::<f64>();
    let nominal = preset("ys100").unwrap();
    let mut m = synthetic_calibration(&nominal, &SyntheticErrors::typical(1e-6), 7);
    m.compensator = Some(StoredCompensator::Gp(gp).into_arc_oriented(None, None));
    for with_maps in [false, true] {
        if with_maps {
            m.calibrated.joint_maps = Some(maps(6));
        }
        let p = PreparedModel::new(&m, &m.nominal);
        let mut rng = ChaCha8Rng::seed_from_u64(41);
        let mut differs = false;
        for _ in 0..20 {
            let q1: Vec<f64> = (0..6).map(|_| rng.gen_range(-0.8..1.3)).collect();
            let mut seed = Local::new();
            let pose = p.predict_expanded(&q1, &mut seed).unwrap();
            let exact = p.predict_base(&q1).unwrap();
            let gap = (pose.p - exact.p).norm();
            assert!(gap <= 1e-7 * scale, "{gap:e} m");
            assert!((pose.r - exact.r).amax() <= 1e-12);
            differs |= gap > 0.0;
            let mut local = seed.clone();
            let mut jac = nalgebra::Matrix6::zeros();
            let restarted = p
                .predict_start(&q1, &mut jac, CompensatorAt::Kept, &mut local)
                .unwrap();
            assert!(!local.is_exact_at(&q1));
            let checked = p.predict_checked(&q1, &restarted, &mut local).unwrap();
            assert!((checked.p - exact.p).amax() <= 1e-12);
            assert!((checked.r - exact.r).amax() <= 1e-12);
            assert!(p.expansion_holds(&seed, &q1, 1e-7));
            let far: Vec<f64> = q1.iter().map(|q| q + 0.5).collect();
            assert!(!p.expansion_holds(&seed, &far, 1e-7));
        }
        assert!(differs, "the rough prediction is its own computation");
    }
}

/// The check at an accepted trial step is the exact prediction there
/// (with and without joint maps), and shifts the expansion onto it.
#[test]
fn the_check_is_the_exact_prediction_and_shifts_the_expansion() {
    let mut rng = ChaCha8Rng::seed_from_u64(31);
    let mut checked = 0;
    for (name, m) in models() {
        let p = PreparedModel::new(&m, &m.nominal);
        if !p.has_local_terms() {
            continue;
        }
        let mut local = Local::new();
        let mut jac = nalgebra::Matrix6::zeros();
        for _ in 0..10 {
            let q0: Vec<f64> = (0..6).map(|_| rng.gen_range(-0.8..1.3)).collect();
            let q1: Vec<f64> = q0.iter().map(|q| q + rng.gen_range(-0.01..0.01)).collect();
            if p.predict_with_jacobian(&q0, &mut jac, &mut local).is_none() {
                continue;
            }
            let (Some(expanded), Some(exact)) = (
                p.predict_local(&q1, &mut jac, &mut local),
                p.predict_base(&q1),
            ) else {
                continue;
            };
            local.accept();
            let checked_pose = p.predict_checked(&q1, &expanded, &mut local).unwrap();
            assert!((checked_pose.p - exact.p).amax() <= 1e-12, "{name}");
            assert!((checked_pose.r - exact.r).amax() <= 1e-12, "{name}");
            let shifted = p.predict_local(&q1, &mut jac, &mut local).unwrap();
            assert!((shifted.p - exact.p).amax() <= 1e-12, "{name}");
            assert!((shifted.r - exact.r).amax() <= 1e-12, "{name}");
            checked += 1;
        }
    }
    assert!(checked >= 100, "{checked} points checked");
}
