//! Fixtures of the inverse-kinematics tests: random in-limit joints, joint
//! distances modulo 2π, synthetic calibrated presets and a KUKA-like arm.

use rand::Rng;
use robocal_core::model::calibrated::CompensatedModel;
use robocal_core::model::orientation::rotation_angle_between;
use robocal_core::model::{preset, Pose, RobotModel};
use robocal_core::sim::{synthetic_calibration, SyntheticErrors};
use std::f64::consts::{PI, TAU};

/// Uniform joints within the limits, clamped to ±π.
pub fn random_q(model: &RobotModel, rng: &mut impl Rng) -> Vec<f64> {
    model
        .links
        .iter()
        .map(|l| rng.gen_range(l.limits[0].max(-PI)..l.limits[1].min(PI)))
        .collect()
}

/// Largest joint difference, each wrapped to [−π, π).
pub fn wrapped_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| ((x - y + PI).rem_euclid(TAU) - PI).abs())
        .fold(0.0, f64::max)
}

/// A synthetic calibration of preset `name`. Compliance per preset: ~1e-6
/// rad/N·m, 1e-7 on the HH800 whose gravity torques are ten times larger.
pub fn calibrated(name: &str, seed: u64) -> CompensatedModel {
    let c = if name == "hh800" { 1e-7 } else { 1e-6 };
    let mut e = SyntheticErrors::typical(c);
    if name.starts_with("ur") {
        e.payload_kg = Some(8.0);
    }
    synthetic_calibration(&preset(name).unwrap(), &e, seed)
}

/// A KUKA-like spherical-wrist arm with a tilted, offset base, lateral offsets,
/// θ offsets, controller sign/zero conventions and a 6-D tool.
pub fn kuka_like() -> RobotModel {
    let desc = serde_json::json!({
        "name": "kuka-like",
        "joints": [
            {"d_mm": 675, "a_mm": 40, "b_mm": -25, "alpha_deg": 0.4, "beta_deg": -0.3,
             "theta_offset_deg": 10, "sign": -1, "zero_deg": 5, "limits_deg": [-185, 185]},
            {"alpha_deg": -90, "a_mm": 260, "d_mm": 45, "theta_offset_deg": -90, "limits_deg": [-140, -5]},
            {"alpha_deg": 0, "a_mm": 680, "d_mm": -20, "theta_offset_deg": 90, "limits_deg": [-120, 168]},
            {"alpha_deg": -90, "a_mm": 35, "d_mm": 670, "sign": -1, "limits_deg": [-350, 350]},
            {"alpha_deg": 90, "limits_deg": [-122.5, 122.5]},
            {"alpha_deg": -90, "d_mm": 115, "theta_offset_deg": 180, "limits_deg": [-350, 350]}
        ],
        "tool": {"xyz_mm": [10, 20, 200], "rpy_deg": [5, -10, 30]},
        "payload": {"mass_kg": 16}
    });
    RobotModel::from_json(&desc.to_string()).unwrap()
}

/// Positions within `tol_m` and rotations within `tol_rad` of each other.
pub fn pose_close(a: &Pose, b: &Pose, tol_m: f64, tol_rad: f64) -> bool {
    (a.p - b.p).norm() < tol_m && rotation_angle_between(&a.r, &b.r) < tol_rad
}
