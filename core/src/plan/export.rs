//! A plan's exports: the joint CSV `point,q1..qN` (controller convention,
//! degrees; read back by [`read_plan_csv`] and by `robocal plan join`) and a
//! joint program in each language that visits every pose and waits there
//! (`program::export::joint_program`).

use super::MeasurementPlan;
use crate::measure::csv_text::{self, Dialect};
use crate::solve::program::export::joint_program;
use crate::solve::program::{Language, ProgramFile};
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;

/// One planned pose: its point name and controller joints [deg].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlanPoint {
    pub name: String,
    pub q_deg: Vec<f64>,
}

/// Why a plan CSV cannot be read or exported.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanCsvError {
    #[error("the plan CSV: {0}")]
    Text(String),
    #[error("the plan CSV has no data rows")]
    Empty,
    #[error("the plan CSV's header needs `point` and `q1`, `q2`, …; got {0}")]
    Header(String),
    #[error("the plan CSV, line {line}: `{field}` is not a number")]
    Number { line: usize, field: String },
    #[error("the plan CSV, line {line}: {got} fields, the header has {expected}")]
    Fields {
        line: usize,
        expected: usize,
        got: usize,
    },
    #[error("the plan CSV: point `{0}` appears twice")]
    Duplicate(String),
    #[error("programs take 6 axes; this plan has {0}")]
    Axes(usize),
}

/// The joint CSV of `points`: `point,q1..qN`, degrees.
pub fn plan_csv(points: &[PlanPoint]) -> String {
    let n = points.iter().map(|p| p.q_deg.len()).max().unwrap_or(0);
    let mut s = String::from("point");
    for i in 1..=n {
        let _ = write!(s, ",q{i}");
    }
    s.push('\n');
    for p in points {
        s.push_str(&p.name);
        for v in &p.q_deg {
            let _ = write!(s, ",{v}");
        }
        s.push('\n');
    }
    s
}

/// Reads a plan CSV written by [`plan_csv`] (`,`, `;` or tab delimited).
pub fn read_plan_csv(text: &str) -> Result<Vec<PlanPoint>, PlanCsvError> {
    let t = csv_text::read(text, Dialect::default())
        .map_err(|e| PlanCsvError::Text(e.to_string()))?
        .ok_or(PlanCsvError::Empty)?;
    let names: Vec<String> = t.header.iter().map(|h| h.to_ascii_lowercase()).collect();
    let point = names.iter().position(|h| h == "point");
    let joints: Vec<usize> = (1..)
        .map_while(|i| names.iter().position(|h| *h == format!("q{i}")))
        .collect();
    let (Some(point), false) = (point, joints.is_empty()) else {
        return Err(PlanCsvError::Header(t.header.join(",")));
    };
    let mut out: Vec<PlanPoint> = Vec::new();
    for r in &t.records {
        if r.fields.len() != t.header.len() {
            return Err(PlanCsvError::Fields {
                line: r.line,
                expected: t.header.len(),
                got: r.fields.len(),
            });
        }
        let name = r.fields[point].trim().to_string();
        if out.iter().any(|p| p.name == name) {
            return Err(PlanCsvError::Duplicate(name));
        }
        let q_deg = joints
            .iter()
            .map(|&c| {
                t.number(r.fields[c].trim())
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| PlanCsvError::Number {
                        line: r.line,
                        field: csv_text::short_text(&r.fields[c]),
                    })
            })
            .collect::<Result<Vec<f64>, _>>()?;
        out.push(PlanPoint { name, q_deg });
    }
    if out.is_empty() {
        return Err(PlanCsvError::Empty);
    }
    Ok(out)
}

/// The plan as a program in `language` named `name`, waiting `wait_s` at each pose.
pub fn plan_program(
    plan: &MeasurementPlan,
    language: Language,
    name: &str,
    wait_s: f64,
) -> Result<Vec<ProgramFile>, PlanCsvError> {
    let joints = plan
        .points
        .iter()
        .map(|p| {
            <[f64; 6]>::try_from(p.q_deg.as_slice()).map_err(|_| PlanCsvError::Axes(p.q_deg.len()))
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(joint_program(language, name, &joints, wait_s))
}
