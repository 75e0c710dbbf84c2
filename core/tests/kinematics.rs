//! Kinematics checked against independent expectations: golden forward
//! kinematics from roboticstoolbox-python (cross-checked with pybotics, see
//! scripts/golden), and every analytic Jacobian against central finite differences.

use nalgebra::{Matrix3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use robocal_core::model::kinematics::{
    chain, deflected_joints, fk, geometric_jacobian, gravity_torques, identification_jacobian,
};
use robocal_core::model::pose::rotation_log;
use robocal_core::model::presets::{preset, PRESETS};
use robocal_core::model::{ParamLayout, RobotModel};

fn golden(name: &str) -> serde_json::Value {
    let path = format!("{}/tests/golden/fk_{name}.json", env!("CARGO_MANIFEST_DIR"));
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn golden_model(g: &serde_json::Value) -> RobotModel {
    let standard = g["convention"].as_str().unwrap().starts_with("standard");
    let joints: Vec<serde_json::Value> = g["dh"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            serde_json::json!({
                "a_mm": r["a_mm"], "alpha_deg": r["alpha_deg"], "d_mm": r["d_mm"],
                "theta_offset_deg": r["theta_offset_deg"], "limits_deg": [-360.0, 360.0]
            })
        })
        .collect();
    let desc = serde_json::json!({
        "name": "golden",
        "convention": if standard { "standard" } else { "modified" },
        "joints": joints,
        "tool": { "xyz_mm": g["tool"]["xyz_mm"], "rpy_deg": g["tool"]["rpy_deg"] }
    });
    RobotModel::from_json(&desc.to_string()).unwrap()
}

#[test]
fn forward_kinematics_matches_golden_values() {
    for name in ["ur5", "ur10", "wam7", "ys100_mdh"] {
        let g = golden(name);
        let model = golden_model(&g);
        let samples = g["samples"].as_array().unwrap();
        assert!(samples.len() >= 30);
        for s in samples {
            let q: Vec<f64> = s["q_deg"]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap().to_radians())
                .collect();
            let t = s["T"].as_array().unwrap();
            let at = |i: usize, j: usize| t[i][j].as_f64().unwrap();
            let pose = fk(&model, &q).unwrap();
            let p_mm = pose.p * 1e3;
            for i in 0..3 {
                assert!(
                    (p_mm[i] - at(i, 3)).abs() < 1e-9,
                    "{name} q={q:?}: position {i}: {} vs {}",
                    p_mm[i],
                    at(i, 3)
                );
                for j in 0..3 {
                    assert!((pose.r[(i, j)] - at(i, j)).abs() < 1e-12, "{name} rotation");
                }
            }
        }
    }
}

fn random_q(model: &RobotModel, rng: &mut ChaCha8Rng) -> Vec<f64> {
    model
        .links
        .iter()
        .map(|l| {
            let (lo, hi) = (l.limits[0].max(-3.0), l.limits[1].min(3.0));
            rng.gen_range(lo..hi)
        })
        .collect()
}

/// A model perturbed away from nominal so no Jacobian entry is zero by symmetry.
fn perturbed(name: &str, rng: &mut ChaCha8Rng) -> RobotModel {
    let mut m = preset(name).unwrap();
    let layout = ParamLayout::geometric(&m);
    let mut v = layout.values(&m);
    for (x, id) in v.iter_mut().zip(&layout.ids) {
        *x += match id.unit() {
            robocal_core::model::params::ParamUnit::Angle => rng.gen_range(-0.01..0.01),
            _ => rng.gen_range(-0.005..0.005),
        };
    }
    layout.apply(&mut m, &v);
    for l in m.links.iter_mut() {
        l.compliance = 1e-6;
    }
    m
}

fn rel_err(an: &[f64], fd: &[f64]) -> f64 {
    let diff: f64 = an
        .iter()
        .zip(fd)
        .map(|(a, b)| (a - b).powi(2))
        .sum::<f64>()
        .sqrt();
    let norm: f64 = an.iter().map(|a| a * a).sum::<f64>().sqrt();
    diff / norm.max(1.0)
}

fn pose_diff(m: &RobotModel, qp: &[f64], qm: &[f64], h: f64) -> [f64; 6] {
    let (a, b) = (fk(m, qp).unwrap(), fk(m, qm).unwrap());
    let v = (a.p - b.p) / (2.0 * h);
    let w = rotation_log(&(a.r * b.r.transpose())) / (2.0 * h);
    [v.x, v.y, v.z, w.x, w.y, w.z]
}

#[test]
fn geometric_jacobian_matches_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for name in PRESETS {
        let m = perturbed(name, &mut rng);
        for _ in 0..5 {
            let q = random_q(&m, &mut rng);
            let j = geometric_jacobian(&m, &chain(&m, &q).unwrap());
            for k in 0..m.dof() {
                let h = 1e-6;
                let (mut qp, mut qm) = (q.clone(), q.clone());
                qp[k] += h;
                qm[k] -= h;
                let fd = pose_diff(&m, &qp, &qm, h);
                let an: Vec<f64> = j.column(k).iter().copied().collect();
                assert!(
                    rel_err(&an, &fd) < 1e-6,
                    "{name} joint {k}: {an:?} vs {fd:?}"
                );
            }
        }
    }
}

#[test]
fn identification_jacobian_matches_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for name in PRESETS {
        let m = perturbed(name, &mut rng);
        let layout = ParamLayout::full(&m);
        for _ in 0..4 {
            let q = random_q(&m, &mut rng);
            let tau = gravity_torques(&m, &q, m.payload.mass).unwrap();
            // Geometry acts at the deflected joints; compliance columns through the deflection.
            let qd = deflected_joints(&m, &q, m.payload.mass).unwrap();
            let c = chain(&m, &qd).unwrap();
            let j = identification_jacobian(&m, &c, &layout.ids, &tau, m.payload.mass, true);
            let v0 = layout.values(&m);
            for (col, id) in layout.ids.iter().enumerate() {
                // Compliance steps move the joint by about 1e-6 rad.
                let h = if id.is_geometric() {
                    1e-6
                } else {
                    1e-6 / tau[id.link].abs().max(1e-3)
                };
                let eval = |delta: f64| {
                    let mut mm = m.clone();
                    let mut v = v0.clone();
                    v[col] += delta;
                    layout.apply(&mut mm, &v);
                    if id.is_geometric() {
                        fk(&mm, &qd).unwrap()
                    } else {
                        // Torque held at the commanded configuration (eq. 2.8).
                        let qq: Vec<f64> = q
                            .iter()
                            .zip(&tau)
                            .zip(&mm.links)
                            .map(|((q, t), l)| q + l.compliance * t)
                            .collect();
                        fk(&mm, &qq).unwrap()
                    }
                };
                let (a, b) = (eval(h), eval(-h));
                let v = (a.p - b.p) / (2.0 * h);
                let w = rotation_log(&(a.r * b.r.transpose())) / (2.0 * h);
                let fd = [v.x, v.y, v.z, w.x, w.y, w.z];
                let an: Vec<f64> = j.column(col).iter().copied().collect();
                let an_scaled: Vec<f64>;
                let fd_scaled: Vec<f64>;
                let (an_ref, fd_ref) = if id.is_geometric() {
                    (&an[..], &fd[..])
                } else {
                    // Compliance columns are O(τ) ~ 1e3: compare relative to their size.
                    let s = an.iter().map(|x| x * x).sum::<f64>().sqrt().max(1e-9);
                    an_scaled = an.iter().map(|x| x / s).collect();
                    fd_scaled = fd.iter().map(|x| x / s).collect();
                    (&an_scaled[..], &fd_scaled[..])
                };
                assert!(
                    rel_err(an_ref, fd_ref) < 1e-6,
                    "{name} {}: {an:?} vs {fd:?}",
                    id.name()
                );
            }
        }
    }
}

/// Gravity torques equal the derivative of the gravitational potential
/// `Σ M_j g·c_j` with respect to each active joint (virtual work), which checks
/// eqs. 3.7–3.9 and the loop's torque mapping independently.
#[test]
fn gravity_torques_are_the_gradient_of_the_potential() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for name in PRESETS {
        let m = perturbed(name, &mut rng);
        let potential = |q: &[f64]| -> f64 {
            let c = chain(&m, q).unwrap();
            let mut w = m.payload.mass * m.gravity.dot(&c.tcp.transform_point(&m.payload.com));
            for (lf, l) in c.links.iter().zip(&m.links) {
                w += l.mass * m.gravity.dot(&lf.frame.transform_point(&l.com));
            }
            w
        };
        for _ in 0..5 {
            let q = random_q(&m, &mut rng);
            let tau = gravity_torques(&m, &q, m.payload.mass).unwrap();
            let scale = tau.iter().fold(1.0_f64, |a, t| a.max(t.abs()));
            for k in 0..m.dof() {
                let h = 1e-6;
                let (mut qp, mut qm) = (q.clone(), q.clone());
                qp[k] += h;
                qm[k] -= h;
                let fd = (potential(&qp) - potential(&qm)) / (2.0 * h);
                assert!(
                    (fd - tau[k]).abs() < 1e-6 * scale,
                    "{name} joint {k}: fd {fd} vs {}",
                    tau[k]
                );
            }
        }
    }
}

#[test]
fn floor_robot_has_no_torque_on_vertical_axis() {
    let m = preset("ys100").unwrap();
    let q = [0.4, 1.2, -0.3, 0.5, 0.6, 0.7];
    let tau = gravity_torques(&m, &q, 110.0).unwrap();
    assert!(tau[0].abs() < 1e-9);
    // Shoulder carries the arm: thousands of N·m for a 110 kg payload.
    assert!(tau[1].abs() > 1000.0, "{tau:?}");
    // Ceiling-mounted: gravity flips, torques flip.
    let mut ceiling = m.clone();
    ceiling.gravity = -m.gravity;
    let t2 = gravity_torques(&ceiling, &q, 110.0).unwrap();
    for (a, b) in tau.iter().zip(&t2) {
        assert!((a + b).abs() < 1e-9);
    }
}

#[test]
fn standard_dh_import_is_exact() {
    // UR5 at zero: flange at x = a2 + a3, y = -(d4 + d6), z = d1 - d5.
    let m = preset("ur5").unwrap();
    let p = fk(&m, &[0.0; 6]).unwrap();
    let expect = Vector3::new(-0.425 - 0.39225, -(0.10915 + 0.0823), 0.089159 - 0.09465);
    assert!((p.p - expect).norm() < 1e-12, "{:?}", p.p);
    let _ = Matrix3::<f64>::identity();
}
