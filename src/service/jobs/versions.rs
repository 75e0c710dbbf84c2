//! What a successful job stores: one calibrated model file per method (a
//! method whose file does not load back moves to the failed list) and the
//! job's summary.

use crate::calibrate::identify::{
    calibrated_model_file, CalibrationOptions, CalibrationReport, FailedMethod,
};
use crate::db::NewVersion;
use crate::model::RobotModel;
use crate::records::JobSummary;
use serde_json::json;

/// The summary of a report: the best method by validation mean (by
/// identification mean when there are no validation poses), its errors next
/// to the nominal model's on the same poses, every warning and failed method.
pub fn summary_of(r: &CalibrationReport) -> JobSummary {
    let best = r.best_method();
    let validated = best.is_some_and(|m| m.validation.is_some());
    let (set, nominal) = match best {
        Some(m) if validated => (m.validation.as_ref(), r.nominal.validation.as_ref()),
        Some(m) => (Some(&m.identification), Some(&r.nominal.identification)),
        None => (None, None),
    };
    JobSummary {
        best_method: best
            .map(|m| m.method.name().to_string())
            .unwrap_or_default(),
        judged_on: if validated {
            "validation"
        } else {
            "identification"
        }
        .to_string(),
        mean_mm: set.map_or(f64::NAN, |s| s.stats.mean_mm),
        max_mm: set.map_or(f64::NAN, |s| s.stats.max_mm),
        nominal_mean_mm: nominal.map_or(f64::NAN, |s| s.stats.mean_mm),
        warnings: r
            .methods
            .iter()
            .flat_map(|(name, m)| {
                m.warnings
                    .iter()
                    .map(move |w| format!("{name}: {}", w.message))
            })
            .collect(),
        failed_methods: r
            .failed
            .iter()
            .map(|f| format!("{}: {}", f.method.name(), f.reason))
            .collect(),
    }
}

/// One calibrated model file per method, in the order the methods ran. A
/// method whose file does not load back (what solve would use) moves from the
/// report's methods to its failed list; the others are stored.
pub(super) fn versions_of(
    r: &mut CalibrationReport,
    nominal: &RobotModel,
    robot_name: &str,
    opts: &CalibrationOptions,
    payload_kg: f64,
) -> Vec<NewVersion> {
    let mut out = Vec::new();
    for method in &opts.methods {
        let Some(m) = r.methods.get(method) else {
            continue;
        };
        let file = match calibrated_model_file(r, m, nominal, robot_name, payload_kg) {
            Ok(file) => file,
            Err(e) => {
                r.methods.remove(method);
                r.failed.push(FailedMethod {
                    method: *method,
                    reason: format!("the {} model does not load back: {e}", method.name()),
                });
                continue;
            }
        };
        let stats = json!({
            "identification": m.identification.stats,
            "validation": m.validation.as_ref().map(|v| &v.stats),
        });
        out.push(NewVersion {
            method: method.name().to_string(),
            model_json: file.to_json(),
            stats,
        });
    }
    out
}
