//! How much of a calibrated model's learned or mapped correction applies at
//! one configuration (model convention, rad): the worst of its joint maps'
//! coverage and its compensator's support (`support.rs`), with the
//! compensator's expected error there when it gives one.

use super::compensated::CompensatedModel;
use super::compensator::Compensator;
use crate::model::joint_maps::Coverage;
use serde::{Deserialize, Serialize};

/// How much of a model's learned or mapped correction applies at one
/// configuration: the worst of its joint maps' coverage and its
/// compensator's support.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Compensation {
    /// `inside`: applied fully; `faded`: partly; `outside`: not at all.
    pub level: Coverage,
    /// 1-based joints outside a trained range (maps or compensator).
    pub joints_outside: Vec<usize>,
    /// The compensator's nearest training configuration is farther than its
    /// support's radius (`false` without a compensator support).
    pub far_from_training: bool,
    /// The compensator's expected position error at the pose [mm], when it
    /// gives one ([`Compensator::uncertainty`](super::compensator::Compensator::uncertainty)).
    pub expected_error_mm: Option<f64>,
}

impl Compensation {
    /// A warning for the user, or `None` when everything applies.
    pub fn warning(&self) -> Option<String> {
        let joints = self
            .joints_outside
            .iter()
            .map(|j| format!("J{j}"))
            .collect::<Vec<_>>()
            .join(", ");
        let level = match self.level {
            Coverage::Inside => None,
            Coverage::Faded => Some(format!(
                "compensation faded: {joints} outside the trained range"
            )),
            Coverage::Outside => Some(format!(
                "compensation not applied: {joints} beyond the trained range"
            )),
        };
        match (level, self.far_from_training) {
            (None, false) => None,
            (Some(l), false) => Some(l),
            (None, true) => Some("far from the compensator's training poses".into()),
            (Some(l), true) => Some(format!("{l}; far from the compensator's training poses")),
        }
    }

    /// Its level as `solve` writes it: `full`, `faded` or `none`.
    pub fn label(&self) -> &'static str {
        match self.level {
            Coverage::Inside => "full",
            Coverage::Faded => "faded",
            Coverage::Outside => "none",
        }
    }
}

fn worse(a: Coverage, b: Coverage) -> Coverage {
    let rank = |c: Coverage| match c {
        Coverage::Inside => 0,
        Coverage::Faded => 1,
        Coverage::Outside => 2,
    };
    if rank(b) > rank(a) {
        b
    } else {
        a
    }
}

impl CompensatedModel {
    /// The coverage of `q` (model convention, rad) by the calibrated model's
    /// joint maps and its compensator's support; `None` when it has neither.
    pub fn compensation_at(&self, q: &[f64]) -> Option<Compensation> {
        let maps = self.calibrated.joint_maps.as_ref();
        let support = self.compensator.as_ref().and_then(|c| c.support());
        if maps.is_none() && support.is_none() {
            return None;
        }
        let mut out = Compensation {
            level: Coverage::Inside,
            joints_outside: Vec::new(),
            far_from_training: false,
            expected_error_mm: None,
        };
        if let Some(maps) = maps {
            for (i, c) in maps.coverage(q).into_iter().enumerate() {
                if let Some(c) = c {
                    out.level = worse(out.level, c);
                    if c != Coverage::Inside {
                        out.joints_outside.push(i + 1);
                    }
                }
            }
        }
        if let Some(s) = support {
            let c = s.coverage(q);
            out.level = worse(out.level, c.level);
            out.joints_outside.extend(c.joints_outside);
            out.far_from_training = c.far;
        }
        out.expected_error_mm = self
            .compensator
            .as_ref()
            .and_then(|c| c.uncertainty(q))
            .map(|u| u.compensated_m * 1e3);
        out.joints_outside.sort_unstable();
        out.joints_outside.dedup();
        Some(out)
    }
}
