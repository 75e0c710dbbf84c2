//! The reach test of the solver (see the parent module's "Reach test"):
//! the margin from the sampled calibrated-vs-nominal deviation and the
//! corrected excess of a target, a fixed-point iteration of the closed form
//! onto the calibrated workspace. Frames: base frame; units: m, rad.

use super::eval::Local;
use super::seeds::halton_joints;
use super::types::IkSolver;
use crate::model::calibrated::CompensatedModel;
use crate::model::pose::rotation_log;
use crate::model::{Pose, RobotModel};

/// Safety factor on the sampled calibrated-vs-nominal deviation of the reach test.
pub(super) const REACH_MARGIN_FACTOR: f64 = 2.0;
/// Floor added to the reach test's margin [m] (unsampled deviations, compensator).
pub(super) const REACH_MARGIN_FLOOR_M: f64 = 0.005;
/// Fixed-point steps of the corrected reach test per branch.
pub(super) const CORRECTED_REACH_STEPS: usize = 4;
/// The corrected reach test's iteration stops when the excess changes less than this [m].
pub(super) const CORRECTED_REACH_CONVERGED_M: f64 = 2e-6;
/// A target whose corrected reach excess is above this [m] is unreachable.
pub(super) const CORRECTED_REACH_TOLERANCE_M: f64 = 0.0001;
/// Joint samples of the deviation estimate of the reach test.
pub(super) const REACH_SAMPLES: usize = 64;

/// Largest deviation [m] of the calibrated prediction's wrist point from the
/// seed model's over `REACH_SAMPLES` Halton points within the limits (capped
/// to ±π): `|Δp| + |ΔR|·(|tool| + |d_N|)` with `|ΔR|` the rotation angle.
pub(super) fn wrist_deviation(
    model: &CompensatedModel,
    seed_model: &RobotModel,
    limits: &[[f64; 2]],
) -> f64 {
    let lever = seed_model.tool.p.norm() + seed_model.links.last().map_or(0.0, |l| l.d.abs());
    let mut worst: f64 = 0.0;
    for i in 1..=REACH_SAMPLES {
        let q = halton_joints(limits, i);
        let (Ok(p), Ok(n)) = (
            model.predict_base(&q),
            crate::model::kinematics::fk(seed_model, &q),
        ) else {
            continue;
        };
        let d = (p.p - n.p).norm() + rotation_log(&(p.r * n.r.transpose())).norm() * lever;
        worst = worst.max(d);
    }
    worst
}

impl IkSolver {
    /// The calibrated model's reach excess [m]: the closed form's branch `q`
    /// (clamped to the workspace boundary when outside, limits ignored) is
    /// moved by the calibrated model's deviation there, as in the seed
    /// corrections — the target becomes `T·P(q)⁻¹·FK_nom(q)` — and the branch
    /// is re-solved for the moved target, up to `CORRECTED_REACH_STEPS` times
    /// or until the excess changes by less than `CORRECTED_REACH_CONVERGED_M`
    /// (a fixed-point iteration onto the calibrated workspace). Branches are
    /// taken nearest the workspace first, only those within the reach margin,
    /// until one reaches the target. Returns the smallest excess (−∞ without
    /// branches) and the evaluations used.
    pub(super) fn corrected_reach_excess(
        &self,
        target: &Pose,
        hint: Option<&[f64]>,
    ) -> (f64, usize) {
        let Some(analytic) = &self.analytic else {
            return (0.0, 0);
        };
        let mut branches = analytic.solve_with_margin(target, hint, f64::INFINITY);
        branches.sort_by(|a, b| a.reach_excess_m.total_cmp(&b.reach_excess_m));
        let mut best = f64::INFINITY;
        let mut evaluations = 0;
        for branch in branches
            .iter()
            .filter(|b| b.reach_excess_m <= self.reach_margin_m)
        {
            let mut q = branch.q;
            let mut excess = branch.reach_excess_m;
            for _ in 0..CORRECTED_REACH_STEPS {
                let Some(moved) = self.moved_target(target, &q, None, None) else {
                    break;
                };
                evaluations += 1;
                let Some(next) =
                    analytic.solve_branch(&moved, branch.configuration, Some(&q), f64::INFINITY)
                else {
                    break;
                };
                let change = (next.reach_excess_m - excess).abs();
                excess = next.reach_excess_m;
                q = next.q;
                if change < CORRECTED_REACH_CONVERGED_M {
                    break;
                }
            }
            best = best.min(excess);
            if best <= 0.0 {
                break;
            }
        }
        (
            if best.is_finite() {
                best
            } else {
                f64::NEG_INFINITY
            },
            evaluations,
        )
    }

    /// The target moved by the calibrated model's deviation from the seed
    /// model at `q`: `T·P(q)⁻¹·FK_nom(q)` (one evaluation of the prediction).
    /// `seed_pose` is `FK_nom(q)` when the caller knows it (a closed-form
    /// solution of `T` itself). With `expansion`, the joint maps and the
    /// compensator are expanded at `q` into it on the way.
    pub(super) fn moved_target(
        &self,
        target: &Pose,
        q: &[f64],
        seed_pose: Option<&Pose>,
        expansion: Option<&mut Local>,
    ) -> Option<Pose> {
        let p = match expansion {
            Some(local) => self.prepared.predict_expanded(q, local)?,
            None => self.prepared.predict_base(q)?,
        };
        let n = match seed_pose {
            Some(n) => *n,
            None => self.prepared.seed_fk(q)?,
        };
        Some(target.compose(&p.inverse()).compose(&n))
    }
}
