//! A plan's exports: the joint CSV `point,q1..qN` (controller convention,
//! degrees; read back by [`read_plan_csv`] and by `robocal plan join`) and a
//! joint program in each language that visits every pose and waits there
//! (`program::export::labelled_joint_program`).

use super::MeasurementPlan;
use crate::csv_write::{push_header, push_row, read_text, Cell};
use crate::measure::bounds::{within, EXTERNAL_VALUE, JOINT_DEG};
use crate::measure::csv_text::{self, Dialect, FieldCount};
use crate::measure::external::{ExternalAxis, ExternalValues};
use crate::model::bounds::show;
use crate::program::axes_only::{axes_only_program, AxesOnlyError, AxesStop};
use crate::program::export::{labelled_joint_program, LabelledJoints, TrackValue};
use crate::program::{Language, ProgramFile};
use serde::{Deserialize, Serialize};

/// One planned pose: its point name and controller joints [deg].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlanPoint {
    /// The point's name (`P1`, `P2`, … in a made plan), which the tracker
    /// export joins by.
    pub name: String,
    /// Joint values in the controller convention [deg], `q1..qN`.
    pub q_deg: Vec<f64>,
    /// External-axis values at the pose (a track plan's value [mm]); empty
    /// for a robot on a fixed base. Written as the CSV's `e1`…`e6` columns
    /// and in JSON as `external: {"e1": …}` (left out when empty).
    #[serde(
        skip_deserializing,
        skip_serializing_if = "ExternalValues::is_empty",
        serialize_with = "external_by_column"
    )]
    pub external: ExternalValues,
}

/// `{"e1": value, …}` of the axes `v` carries.
fn external_by_column<S: serde::Serializer>(v: &ExternalValues, s: S) -> Result<S::Ok, S::Error> {
    use serde::ser::SerializeMap;
    let mut m = s.serialize_map(None)?;
    for a in ExternalAxis::ALL {
        if let Some(x) = v.get(a) {
            m.serialize_entry(a.column(), &x)?;
        }
    }
    m.end()
}

/// Why a plan CSV cannot be read or exported.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanCsvError {
    /// The text is not a readable CSV; the reader's message.
    #[error("the plan CSV: {0}")]
    Text(String),
    /// The CSV has no data rows.
    #[error("the plan CSV has no data rows")]
    Empty,
    /// The header lacks `point`, or both `q1` and an `e` column; the header as read.
    #[error("the plan CSV's header needs `point` and `q1`, `q2`, … (or a positioner's `e` columns); got {0}")]
    Header(String),
    /// A joint value is not a finite number.
    #[error("the plan CSV, line {line}: `{field}` is not a number")]
    Number {
        /// 1-based line of the record in the text.
        line: usize,
        /// The field as read (shortened).
        field: String,
    },
    /// A record's field count differs from the header's.
    #[error("the plan CSV, {0}")]
    Fields(#[from] FieldCount),
    /// A joint value is beyond the bound of a controller joint reading.
    #[error("the plan CSV, line {line}, column `{column}`: {} deg is beyond the bound ±{} deg (controller degrees)", show(*value), JOINT_DEG.max)]
    Joint {
        /// 1-based line of the record in the text.
        line: usize,
        /// The joint's column, as the header names it.
        column: String,
        /// The value read [deg].
        value: f64,
    },
    /// An external-axis value is beyond the bound of a controller's value.
    #[error("the plan CSV, line {line}, column `{column}`: {} is beyond the bound ±{} (mm or deg)", show(*value), EXTERNAL_VALUE.max)]
    External {
        /// 1-based line of the record in the text.
        line: usize,
        /// The axis's column.
        column: ExternalAxis,
        /// The value read.
        value: f64,
    },
    /// URScript programs carry no external axes.
    #[error("URScript programs carry no external axes; write the plan's CSV or a KRL, RAPID or Fanuc program")]
    NoExternalAxes,
    /// A point name appears twice; the name.
    #[error("the plan CSV: point `{0}` appears twice")]
    Duplicate(String),
    /// A program needs 6 axes; the plan's number of joints.
    #[error("programs take 6 axes; this plan has {0}")]
    Axes(usize),
    /// A point without joints moves other external axes than the first
    /// does, or none; its 1-based index.
    #[error(
        "point {0} of a plan without joints moves other external axes than the first point does"
    )]
    StopAxes(usize),
}

/// The external-axis columns any of `points` carries, in axis order.
pub fn plan_axes(points: &[PlanPoint]) -> Vec<ExternalAxis> {
    ExternalAxis::ALL
        .into_iter()
        .filter(|a| points.iter().any(|p| p.external.get(*a).is_some()))
        .collect()
}

/// The joint CSV of `points`: `point,q1..qN`, degrees, then the
/// external-axis columns any point carries (`e1`…, mm or degrees; point
/// names as `csv_write` writes every text).
pub fn plan_csv(points: &[PlanPoint]) -> String {
    let n = points.iter().map(|p| p.q_deg.len()).max().unwrap_or(0);
    let axes = plan_axes(points);
    let mut s = String::new();
    let header = std::iter::once("point".to_string())
        .chain((1..=n).map(|i| format!("q{i}")))
        .chain(axes.iter().map(|a| a.column().to_string()));
    push_header(&mut s, header);
    for p in points {
        let mut row = vec![Cell::text(&p.name)];
        row.extend(p.q_deg.iter().map(|v| Cell::num(*v)));
        for a in &axes {
            row.push(match p.external.get(*a) {
                Some(v) => Cell::num(v),
                None => Cell::text(""),
            });
        }
        push_row(&mut s, &row);
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
    let axes: Vec<(ExternalAxis, usize)> = ExternalAxis::ALL
        .into_iter()
        .filter_map(|a| Some((a, names.iter().position(|h| h == a.column())?)))
        .collect();
    // A positioner's plan moves only its axes: no joints, `e` columns.
    let (Some(point), false) = (point, joints.is_empty() && axes.is_empty()) else {
        return Err(PlanCsvError::Header(t.header.join(",")));
    };
    let mut out: Vec<PlanPoint> = Vec::new();
    for r in &t.records {
        t.check_shape(r)?;
        let name = read_text(r.fields[point].trim()).into_owned();
        if out.iter().any(|p| p.name == name) {
            return Err(PlanCsvError::Duplicate(name));
        }
        let number = |c: usize| {
            t.number(r.fields[c].trim())
                .filter(|v| v.is_finite())
                .ok_or_else(|| PlanCsvError::Number {
                    line: r.line,
                    field: csv_text::short_text(&r.fields[c]),
                })
        };
        let q_deg = joints
            .iter()
            .map(|&c| {
                let v = number(c)?;
                if !within(v, &JOINT_DEG) {
                    return Err(PlanCsvError::Joint {
                        line: r.line,
                        column: t.header[c].clone(),
                        value: v,
                    });
                }
                Ok(v)
            })
            .collect::<Result<Vec<f64>, _>>()?;
        let mut external = ExternalValues::default();
        for &(a, c) in &axes {
            let v = number(c)?;
            if !within(v, &EXTERNAL_VALUE) {
                return Err(PlanCsvError::External {
                    line: r.line,
                    column: a,
                    value: v,
                });
            }
            external.0[a.index()] = Some(v);
        }
        out.push(PlanPoint {
            name,
            q_deg,
            external,
        });
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
    points_program(&plan.points, language, name, wait_s)
}

/// `points` as a program in `language` named `name`, waiting `wait_s` at
/// each pose; a point's external-axis value (a track plan's) moves the
/// track with the robot (KRL `E1`…, RAPID `eax_a`…, Fanuc `E1` in `GP1`, mm).
/// Points without joints (a positioner's plan) move the external axes alone
/// (`program::axes_only`: KRL `PTP {E1 …, E2 …}`, RAPID `MoveExtJ`, Fanuc
/// motion group 2).
pub fn points_program(
    points: &[PlanPoint],
    language: Language,
    name: &str,
    wait_s: f64,
) -> Result<Vec<ProgramFile>, PlanCsvError> {
    if !points.is_empty() && points.iter().all(|p| p.q_deg.is_empty()) {
        return axes_program(points, language, name, wait_s);
    }
    let mut targets = Vec::with_capacity(points.len());
    for (i, p) in points.iter().enumerate() {
        let joints_deg = <[f64; 6]>::try_from(p.q_deg.as_slice())
            .map_err(|_| PlanCsvError::Axes(p.q_deg.len()))?;
        let track = ExternalAxis::ALL.into_iter().find_map(|axis| {
            Some(TrackValue {
                axis,
                value_mm: p.external.get(axis)?,
            })
        });
        if track.is_some() && language == Language::UrScript {
            return Err(PlanCsvError::NoExternalAxes);
        }
        targets.push(LabelledJoints {
            label: format!("pose {}", i + 1),
            joints_deg,
            track,
        });
    }
    let head = format!(
        "robocal measurement plan: {} poses, a wait of {wait_s} s at each",
        points.len()
    );
    Ok(labelled_joint_program(
        language, name, &head, &targets, wait_s,
    ))
}

/// Points without joints as a program moving their external axes alone.
fn axes_program(
    points: &[PlanPoint],
    language: Language,
    name: &str,
    wait_s: f64,
) -> Result<Vec<ProgramFile>, PlanCsvError> {
    let stops: Vec<AxesStop> = points
        .iter()
        .map(|p| AxesStop {
            label: p.name.clone(),
            values: ExternalAxis::ALL
                .into_iter()
                .filter_map(|a| Some((a, p.external.get(a)?)))
                .collect(),
        })
        .collect();
    let head = format!(
        "robocal measurement plan: {} stops of the external axes alone, a wait of {wait_s} s at each",
        points.len()
    );
    axes_only_program(language, name, &head, &stops, wait_s).map_err(|e| match e {
        AxesOnlyError::UrScript => PlanCsvError::NoExternalAxes,
        AxesOnlyError::Axes(i) => PlanCsvError::StopAxes(i),
    })
}
