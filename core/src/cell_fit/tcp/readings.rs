//! The rows a TCP or work-object calibration reads: controller joint
//! readings `q1..qN` [deg], and/or a tracker measurement `x, y, z` [mm]
//! (measurement frame) with optionally `rx, ry, rz` [deg] (fixed-axis,
//! `R = Rz(rz)·Ry(ry)·Rx(rx)`, a 6-D probe), and for a work object a `point`
//! column naming which point the row is ([`WoPoint`]). The CSV form:
//!
//! ```text
//! # the tool's tip held at one point
//! q1,q2,q3,q4,q5,q6
//! 10.5,-80.2,95.0,-105.3,-89.9,12.0
//! # a work object measured by the tracker
//! point,x,y,z
//! origin,1523.2,12.5,980.1
//! ```
//!
//! Delimiter (`,` `;` tab) and decimal comma are detected; `#` starts a comment.

use crate::measure::csv_text::{self, Dialect};
use serde::{Deserialize, Serialize};

/// Which point of a work object a row measures (a closed set).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WoPoint {
    /// The work object's origin.
    Origin,
    /// A point on its +x axis.
    X,
    /// A point in its xy plane, on the +y side.
    Xy,
    /// A further point of the xy plane (checked, not fitted).
    Plane,
}

impl WoPoint {
    /// Every point, in declaration order.
    pub const ALL: [WoPoint; 4] = [WoPoint::Origin, WoPoint::X, WoPoint::Xy, WoPoint::Plane];

    /// The point's name in the `point` column (lower case).
    pub fn as_str(self) -> &'static str {
        match self {
            WoPoint::Origin => "origin",
            WoPoint::X => "x",
            WoPoint::Xy => "xy",
            WoPoint::Plane => "plane",
        }
    }
}

impl std::str::FromStr for WoPoint {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let k = s.trim().to_ascii_lowercase();
        WoPoint::ALL
            .into_iter()
            .find(|p| p.as_str() == k)
            .ok_or_else(|| {
                let all: Vec<&str> = WoPoint::ALL.iter().map(|p| p.as_str()).collect();
                format!("point `{s}`: one of {}", all.join(", "))
            })
    }
}

/// A readings file that cannot be read (the line and what is wrong).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct CsvError(pub String);

/// One row: joint readings and/or a tracker measurement.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Reading {
    /// Work objects: which point.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub point: Option<WoPoint>,
    /// Controller joint readings [deg].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub joints_deg: Option<Vec<f64>>,
    /// Tracker position, measurement frame [mm].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub xyz_mm: Option<[f64; 3]>,
    /// Tracker orientation, fixed-axis `[rx, ry, rz]` [deg] (6-D probe).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rpy_deg: Option<[f64; 3]>,
}

fn column(header: &[String], name: &str) -> Option<usize> {
    header.iter().position(|h| h.eq_ignore_ascii_case(name))
}

/// Joint columns: `q1..qN` or `j1..jN`, consecutive from 1.
fn joint_columns(header: &[String]) -> Vec<usize> {
    for prefix in ["q", "j"] {
        let cols: Vec<usize> = (1..)
            .map_while(|k| column(header, &format!("{prefix}{k}")))
            .collect();
        if !cols.is_empty() {
            return cols;
        }
    }
    Vec::new()
}

fn triple(
    table: &csv_text::Table,
    rec: &csv_text::Record,
    cols: &Option<[usize; 3]>,
) -> Result<Option<[f64; 3]>, CsvError> {
    let Some(cols) = cols else { return Ok(None) };
    let mut out = [0.0; 3];
    for (o, c) in out.iter_mut().zip(cols) {
        let f = rec.fields.get(*c).map(|s| s.trim()).unwrap_or("");
        *o = table
            .number(f)
            .filter(|v| v.is_finite())
            .ok_or_else(|| CsvError(format!("line {}: `{f}` is not a number", rec.line)))?;
    }
    Ok(Some(out))
}

/// Parses the CSV text of readings.
pub fn parse_csv(text: &str) -> Result<Vec<Reading>, CsvError> {
    let table = csv_text::read(text, Dialect::default())
        .map_err(|e| CsvError(e.to_string()))?
        .ok_or_else(|| CsvError("the file has no header line".into()))?;
    let h = &table.header;
    let joints = joint_columns(h);
    let find3 = |n: [&str; 3]| -> Option<[usize; 3]> {
        Some([column(h, n[0])?, column(h, n[1])?, column(h, n[2])?])
    };
    let xyz = find3(["x", "y", "z"]);
    let rpy = find3(["rx", "ry", "rz"]);
    let point = column(h, "point");
    if joints.is_empty() && xyz.is_none() {
        return Err(CsvError(
            "no joint columns (q1..qN, controller degrees) and no x, y, z columns (mm)".into(),
        ));
    }
    let mut rows = Vec::with_capacity(table.records.len());
    for rec in &table.records {
        // A row of another width would be read shifted.
        table
            .check_shape(rec)
            .map_err(|e| CsvError(e.to_string()))?;
        let mut q = Vec::with_capacity(joints.len());
        for c in &joints {
            let f = rec.fields.get(*c).map(|s| s.trim()).unwrap_or("");
            q.push(table.number(f).filter(|v| v.is_finite()).ok_or_else(|| {
                CsvError(format!(
                    "line {}: joint reading `{f}` is not a number",
                    rec.line
                ))
            })?);
        }
        let point = point
            .map(|c| {
                rec.fields
                    .get(c)
                    .map(|s| s.as_str())
                    .unwrap_or("")
                    .parse::<WoPoint>()
                    .map_err(|e| CsvError(format!("line {}: {e}", rec.line)))
            })
            .transpose()?;
        rows.push(Reading {
            point,
            joints_deg: (!q.is_empty()).then_some(q),
            xyz_mm: triple(&table, rec, &xyz)?,
            rpy_deg: triple(&table, rec, &rpy)?,
        });
    }
    if rows.is_empty() {
        return Err(CsvError("the file has no rows".into()));
    }
    Ok(rows)
}
