//! The validation evidence of a calibrated model ([`ValidationEvidence`],
//! kept in its model file): each validation pose predicted by the
//! compensated model at its payload in its session's fitted frame, the
//! position error [mm] and, where the pose measured an orientation,
//! `R_measured − R_predicted` (`model/calibrated/evidence.rs`).

use crate::measure::Measurement;
use crate::model::calibrated::{CompensatedModel, TipTerm, ValidationEvidence};
use crate::model::Pose;
use crate::stats::ErrorStats;

impl ValidationEvidence {
    /// The evidence of `model` (its `cell_from_base` unused: `valid` is in
    /// the registered base frame of each pose's session, `frames` the fitted
    /// session frames); `None` without validation poses.
    pub fn of(model: &CompensatedModel, frames: &[Pose], valid: &[Measurement]) -> Option<Self> {
        let mut norms = Vec::with_capacity(valid.len());
        let mut tip_terms = Vec::new();
        for m in valid {
            let Ok(p) = model.predict_detailed_at(&m.q, m.payload_mass) else {
                continue;
            };
            let frame = frames.get(m.session).copied().unwrap_or_default();
            let pred = frame.compose(&p.pose);
            let e = m.position - pred.p;
            norms.push(e.norm() * 1e3);
            if let Some(r) = &m.orientation {
                let d = r - pred.r;
                // Rounded to 1 nm and 1e-12 (a 1 m lever arm: 1 nm): short files.
                let round = |v: f64, s: f64| (v * s).round() / s;
                tip_terms.push(TipTerm {
                    error_mm: std::array::from_fn(|k| round(e[k] * 1e3, 1e6)),
                    rotation_difference: std::array::from_fn(|k| round(d[(k / 3, k % 3)], 1e12)),
                });
            }
        }
        if norms.is_empty() {
            return None;
        }
        let stats = ErrorStats::from_errors_mm(&norms);
        Some(ValidationEvidence {
            poses: norms.len(),
            position_mean_mm: stats.mean_mm,
            position_max_mm: stats.max_mm,
            tip_terms,
        })
    }
}
