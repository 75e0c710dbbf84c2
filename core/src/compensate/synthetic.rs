//! Synthetic calibrated models for tests, benchmarks and demonstrations: the
//! nominal model with small random geometric errors, joint compliance, a payload
//! and a measurement frame, as a calibration would return them.
//!
//! Every geometric parameter of `ParamLayout::geometric` (base, links, 6-D tool,
//! loop lengths except the scale-fixing `l3`) gets a uniform error in
//! `[−length, length]` [m] or `[−angle, angle]` [rad]. Units SI.

use super::CompensatedModel;
use crate::model::params::ParamUnit;
use crate::model::{ParamKind, ParamLayout, Pose, RobotModel};
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
