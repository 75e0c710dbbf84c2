//! Synthetic calibrated models for tests, benchmarks and demonstrations: the
//! nominal model with small random geometric errors, joint compliance, a payload
//! and a measurement frame, as a calibration would return them.
//!
//! Every geometric parameter of `ParamLayout::geometric` (base, links, 6-D tool,
//! loop lengths except the scale-fixing `l3`) gets a uniform error in
//! `[−length, length]` [m] or `[−angle, angle]` [rad]. Units SI.

use crate::model::calibrated::CompensatedModel;
use crate::model::params::ParamUnit;
use crate::model::{ParamKind, ParamLayout, Pose, RobotModel};
use crate::sim::{
    perturb_geometry, tracker_frame, ErrorMagnitudes, TrueRobot, UnmodelledEffects,
    TABLE_7_2_STIFFNESS,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Sizes of the synthetic errors and the operating conditions.
#[derive(Debug, Clone, PartialEq)]
pub struct SyntheticErrors {
    /// Length error bound [m].
    pub length_m: f64,
    /// Angle error bound [rad].
    pub angle_rad: f64,
    /// Compliance [rad/(N·m)] per joint (0-based index, value); others rigid.
    pub compliance: Vec<(usize, f64)>,
    /// Payload mass [kg]; `None` keeps the model's default payload.
    pub payload_kg: Option<f64>,
    /// Registered base frame → measurement frame.
    pub cell_from_base: Pose,
}

impl SyntheticErrors {
    /// ~1 mm / 0.05° geometric errors, compliance `c` on joints 2–5, the model's
    /// payload and a tracker frame 3.24 m away, turned by 30° about z.
    pub fn typical(c: f64) -> Self {
        let mut frame = Pose::identity();
        frame.tr_x(0.4);
        frame.tr_y(-3.24);
        frame.tr_z(0.15);
        frame.rot_z(30f64.to_radians());
        frame.rot_x(0.2f64.to_radians());
        SyntheticErrors {
            length_m: 1e-3,
            angle_rad: 0.05f64.to_radians(),
            compliance: (1..5).map(|k| (k, c)).collect(),
            payload_kg: None,
            cell_from_base: frame,
        }
    }
}

/// A calibrated model derived from `nominal` by the errors of `errors`,
/// reproducible from `seed`.
pub fn synthetic_calibration(
    nominal: &RobotModel,
    errors: &SyntheticErrors,
    seed: u64,
) -> CompensatedModel {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut cal = nominal.clone();
    let layout = ParamLayout::geometric(&cal);
    let mut v = layout.values(&cal);
    for (x, id) in v.iter_mut().zip(&layout.ids) {
        if id.kind == ParamKind::LoopL3 {
            continue;
        }
        *x += match id.unit() {
            ParamUnit::Angle => rng.gen_range(-1.0..=1.0) * errors.angle_rad,
            _ => rng.gen_range(-1.0..=1.0) * errors.length_m,
        };
    }
    layout.apply(&mut cal, &v);
    for l in cal.links.iter_mut() {
        l.compliance = 0.0;
    }
    for &(k, c) in &errors.compliance {
        if let Some(l) = cal.links.get_mut(k) {
            l.compliance = c;
        }
    }
    CompensatedModel {
        payload_kg: errors.payload_kg.unwrap_or(nominal.payload.mass),
        calibrated: cal,
        nominal: nominal.clone(),
        cell_from_base: errors.cell_from_base,
        compensator: None,
    }
}

/// The simulated truth of the compensator study (tests/compensate.rs, the
/// compensator benchmark `core/benches/compensate.rs` and
/// `core/examples/compare_trainers.rs`): `nominal` with
/// uniform 1 mm / 0.1° geometric errors, the joint stiffness of the thesis's
/// Table 7.2 on joints 2–5, 0.01 mm tracker noise and a tracker frame 3.4 m
/// from the base, turned by 30°. With `effects`, also what no model-based
/// method here captures: link masses 25 % above the model's, centres of mass
/// moved by (+60, 0, −30) mm in their link frames, a first-harmonic gear
/// transmission error of 4e-5 rad and 2e-5 rad backlash on every joint.
pub fn unmodelled_truth(nominal: &RobotModel, effects: bool, seed: u64) -> TrueRobot {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut m = perturb_geometry(nominal, &ErrorMagnitudes::from_mm_deg(1.0, 0.1), &mut rng);
    for (k, stiffness) in TABLE_7_2_STIFFNESS {
        if let Some(l) = m.links.get_mut(k) {
            l.compliance = 1.0 / stiffness;
        }
    }
    let mut t = TrueRobot::new(m);
    t.tracker_from_base = tracker_frame(0.4, -0.3, 30.0, [1200.0, -3240.0, 150.0]);
    t.noise_mm = 0.01;
    if effects {
        for l in t.model.links.iter_mut() {
            l.mass *= 1.25;
            l.com.x += 0.06;
            l.com.z -= 0.03;
        }
        t.effects = UnmodelledEffects {
            gear_error: Some((4e-5, 1)),
            hysteresis_rad: 2e-5,
            ..Default::default()
        };
    }
    t
}
