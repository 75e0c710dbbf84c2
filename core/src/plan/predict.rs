//! Predicted standard deviations of a plan: the calibration's identifiability
//! analysis (same candidates, same settings) on the plan's poses at the
//! nominal model, then `Σ = σ²·(JᵀJ)⁻¹` over the kept parameters, J the
//! stacked position Jacobian [m per parameter unit], σ the tracker noise [m].
//!
//! The calibration first registers the tracker frame onto the nominal model's
//! TCP positions (a rigid fit), and the base parameters absorb what the noise
//! moved that fit; so the prediction is `Σ = σ²·M⁻¹·(JᵀPJ)·M⁻¹`, `M = JᵀJ`,
//! `P = I − G(GᵀG)⁻¹Gᵀ` removing the rigid motions `G_i = [I, −[p_i]×]` of
//! the points. It equals `σ²·(JᵀJ)⁻¹` for parameters a rigid motion of the
//! measurement frame does not alias (all but the base's, in practice).

use super::PlanError;
use crate::calibrate::identify::checks::{
    fixed_params, gravity_problem, stacked_factor, stacked_jacobian,
};
use crate::calibrate::identify::identifiability::{analyse_factor, IdentifiabilitySettings};
use crate::measure::Measurement;
use crate::model::kinematics::fk;
use crate::model::{ParamId, ParamKind, ParamLayout, RobotModel};
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

/// One parameter's predicted standard deviation, in `unit`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParamPrediction {
    /// The parameter's name in the thesis's tables (`a1`, `theta2`, `c3`, …).
    pub name: String,
    /// mm, deg or rad/(N·m).
    pub unit: String,
    /// Predicted standard deviation from `σ²·(JᵀJ)⁻¹`, in `unit`.
    pub std: f64,
}

/// A method's predicted standard deviations.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PredictedStd {
    /// `km` (geometry) or `skcm` (geometry and joint compliance).
    pub method: String,
    /// Predicted standard deviation of each parameter the calibration identifies.
    pub params: Vec<ParamPrediction>,
    /// Parameters the calibration would not identify from these poses.
    pub not_identified: Vec<String>,
}

fn measurements(model: &RobotModel, q: &[Vec<f64>], payload_kg: f64) -> Vec<Measurement> {
    q.iter()
        .filter_map(|q| {
            Some(Measurement {
                q: q.clone(),
                position: fk(model, q).ok()?.p,
                orientation: None,
                payload_mass: payload_kg,
                session: 0,
                std: None,
            })
        })
        .collect()
}

/// Whether gravity puts torque on some joint in these poses.
pub(super) fn gravity_loads(model: &RobotModel, q: &[Vec<f64>], payload_kg: f64) -> bool {
    gravity_problem(model, &measurements(model, q, payload_kg)).is_none()
}

/// KM's prediction, and SKCM's when `gravity` loads a joint.
pub(super) fn predict(
    model: &RobotModel,
    q: &[Vec<f64>],
    payload_kg: f64,
    noise_mm: f64,
    gravity: bool,
) -> Result<Vec<PredictedStd>, PlanError> {
    let data = measurements(model, q, payload_kg);
    let mut out = vec![one(model, &data, noise_mm, false, "km")?];
    if gravity {
        out.push(one(model, &data, noise_mm, true, "skcm")?);
    }
    Ok(out)
}

/// `G`: the position rows' derivatives by a small rigid motion `(t, ω)` of
/// the points, `δp_i = t + ω × p_i`.
fn rigid_motions(data: &[Measurement]) -> DMatrix<f64> {
    let mut g = DMatrix::zeros(3 * data.len(), 6);
    for (i, m) in data.iter().enumerate() {
        let p = m.position;
        let skew = [[0.0, p.z, -p.y], [-p.z, 0.0, p.x], [p.y, -p.x, 0.0]];
        for r in 0..3 {
            g[(3 * i + r, r)] = 1.0;
            for c in 0..3 {
                g[(3 * i + r, 3 + c)] = skew[r][c];
            }
        }
    }
    g
}

fn one(
    model: &RobotModel,
    data: &[Measurement],
    noise_mm: f64,
    compliance: bool,
    method: &str,
) -> Result<PredictedStd, PlanError> {
    let fixed = fixed_params(model);
    let mut candidates: Vec<ParamId> = ParamLayout::geometric(model)
        .ids
        .into_iter()
        .filter(|id| !fixed.iter().any(|(f, _)| f == id))
        .collect();
    if compliance {
        candidates.extend((0..model.dof()).map(|k| ParamId::new(ParamKind::Compliance, k)));
    }
    let (r, rows) = stacked_factor(model, &candidates, data, None);
    if r.iter().any(|v| !v.is_finite())
        || data
            .iter()
            .any(|m| !m.position.iter().all(|v| v.is_finite()))
    {
        return Err(PlanError::Unidentifiable(
            "the model's positions or Jacobian overflow at the chosen poses (check its lengths and masses)".into(),
        ));
    }
    let analysis = analyse_factor(
        model,
        &r,
        rows,
        &candidates,
        &fixed,
        data.len(),
        &IdentifiabilitySettings::default(),
    );
    let kept = analysis.kept;
    if rows <= kept.len() {
        return Err(PlanError::Unidentifiable(format!(
            "{rows} equations for {} parameters",
            kept.len()
        )));
    }
    // Column scaling D for the inverse: Σ = D·Σ_s·D with Js = J·D.
    let mut js = stacked_jacobian(model, &kept, data);
    let d: Vec<f64> = js.column_iter().map(|c| 1.0 / c.norm()).collect();
    for (c, s) in d.iter().enumerate() {
        js.column_mut(c).scale_mut(*s);
    }
    let singular = || PlanError::Unidentifiable("the kept parameters' Jacobian is singular".into());
    let m_inv: DMatrix<f64> = (js.transpose() * &js).try_inverse().ok_or_else(singular)?;
    let g = rigid_motions(data);
    let gtg_inv = (g.transpose() * &g).try_inverse().ok_or_else(singular)?;
    let pj = &js - &g * (gtg_inv * (g.transpose() * &js));
    let inv = &m_inv * (pj.transpose() * &pj) * &m_inv;
    let sigma = noise_mm * 1e-3;
    let params = kept
        .iter()
        .enumerate()
        .map(|(i, id)| ParamPrediction {
            name: id.name(),
            unit: id.unit_name().to_string(),
            std: id.to_display(sigma * d[i] * inv[(i, i)].max(0.0).sqrt()),
        })
        .collect();
    Ok(PredictedStd {
        method: method.to_string(),
        params,
        not_identified: analysis
            .report
            .dropped
            .into_iter()
            .map(|d| d.name)
            .collect(),
    })
}
