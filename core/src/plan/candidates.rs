//! Candidate configurations: uniform within the joint limits (model
//! convention, rad), filtered by reachability, the workspace box (TCP
//! position, base frame, mm) and the tracker's line of sight.

use super::settings::{FilterCounts, PlanError, PlanSettings, TrackerSight, WorkspaceBox};
use crate::model::kinematics::fk;
use crate::model::pose::Pose;
use crate::model::RobotModel;
use nalgebra::Vector3;
use rand::Rng;

/// Whether the TCP position `p` [m] is inside `b`.
pub(super) fn inside_box(b: &WorkspaceBox, p: &Vector3<f64>) -> bool {
    (0..3).all(|k| {
        let v = p[k] * 1e3;
        v >= b.min_mm[k] && v <= b.max_mm[k]
    })
}

/// Angle [deg] between the reflector's axis at `tcp` and the line to the tracker.
pub(super) fn sight_angle_deg(t: &TrackerSight, tcp: &Pose) -> f64 {
    let axis = tcp.r * Vector3::from(t.axis).normalize();
    let to = Vector3::from(t.position_mm) * 1e-3 - tcp.p;
    axis.angle(&to).to_degrees()
}

/// Draws `s.candidates` configurations and keeps those that pass.
pub(super) fn draw(
    model: &RobotModel,
    s: &PlanSettings,
    rng: &mut impl Rng,
) -> Result<(Vec<Vec<f64>>, FilterCounts), PlanError> {
    if let Some(b) = &s.workspace {
        let ordered = |k: usize| {
            b.min_mm[k] < b.max_mm[k] && b.min_mm[k].is_finite() && b.max_mm[k].is_finite()
        };
        if !(0..3).all(ordered) {
            return Err(PlanError::Setting(format!(
                "the box's minimum must be below its maximum on every axis: {:?} .. {:?}",
                b.min_mm, b.max_mm
            )));
        }
    }
    if let Some(t) = &s.tracker {
        let a = Vector3::from(t.axis);
        if !(a.norm() > 0.0 && a.norm().is_finite() && t.max_angle_deg.is_finite()) {
            return Err(PlanError::Setting(
                "the reflector axis must be a non-zero vector and the angle a number".into(),
            ));
        }
    }
    let margin = s.margin_deg.to_radians();
    let ranges: Vec<(f64, f64)> = model
        .links
        .iter()
        .map(|l| {
            let (lo, hi) = (l.limits[0] + margin, l.limits[1] - margin);
            if lo < hi {
                (lo, hi)
            } else {
                let m = 0.5 * (l.limits[0] + l.limits[1]);
                (m, m)
            }
        })
        .collect();
    let mut counts = FilterCounts::default();
    let mut pool = Vec::new();
    for _ in 0..s.candidates {
        counts.drawn += 1;
        let q: Vec<f64> = ranges
            .iter()
            .map(|&(lo, hi)| if lo < hi { rng.gen_range(lo..hi) } else { lo })
            .collect();
        let Ok(tcp) = fk(model, &q) else { continue };
        if !(tcp.p.iter().all(|v| v.is_finite()) && tcp.r.iter().all(|v| v.is_finite())) {
            continue;
        }
        counts.reachable += 1;
        if s.workspace.as_ref().is_some_and(|b| !inside_box(b, &tcp.p)) {
            continue;
        }
        counts.in_box += 1;
        if s.tracker
            .as_ref()
            .is_some_and(|t| sight_angle_deg(t, &tcp) > t.max_angle_deg)
        {
            continue;
        }
        counts.in_sight += 1;
        pool.push(q);
    }
    Ok((pool, counts))
}
