//! The join of a tracker export back to the plan: a CSV of points (a name or
//! 1-based index column, optional; `x`, `y`, `z` in mm or m) matched to the
//! plan's points by name or by order, written as the measurement CSV the
//! calibration reads (controller joints [deg], positions [mm] in the tracker
//! frame).

use super::PlanPoint;
use crate::csv_write::read_text;
use crate::measure::bounds::{within, POSITION_MM};
use crate::measure::csv_text::{self, Dialect, FieldCount};
use crate::measure::external::{ExternalAxis, ExternalValues, MeasurementSet};
use crate::measure::MeasuredPose;
use crate::model::bounds::show;
use serde::{Deserialize, Serialize};

/// Position units of a tracker export.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Units {
    /// Millimetres.
    Mm,
    /// Metres (scaled by 1000 into the measurement CSV).
    M,
    /// From the header (`x_mm`, `x [m]`, …), else from the points' spread.
    Detect,
}

/// How tracker points find their plan points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum JoinBy {
    /// By name (or 1-based index) when the export has a name column, else by order.
    Detect,
    /// By the name column (a plan point's name, case-insensitive, or its 1-based index).
    Name,
    /// By order: the n-th tracker point is the n-th plan point.
    Order,
}

/// Join options.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct JoinOptions {
    /// The export's position units (`Detect`: from the header, else the points' spread).
    pub units: Units,
    /// How tracker points find their plan points.
    pub by: JoinBy,
}

impl Default for JoinOptions {
    fn default() -> Self {
        JoinOptions {
            units: Units::Detect,
            by: JoinBy::Detect,
        }
    }
}

/// The joined measurement set and how it was joined.
#[derive(Debug, Clone, PartialEq)]
pub struct Joined {
    /// The measurement rows, in plan order: controller joints [deg] and tracker
    /// positions [mm].
    pub rows: Vec<MeasuredPose>,
    /// The units the export was read in (never `Detect`).
    pub units: Units,
    /// How the points were matched (never `Detect`).
    pub by: JoinBy,
    /// The plan's external-axis columns (a track plan's `e1`), carried to
    /// every row.
    pub axes: Vec<ExternalAxis>,
    /// Each row's external-axis values, in the order of `rows`.
    pub external: Vec<ExternalValues>,
}

impl Joined {
    /// The rows as a measurement set with the plan's external-axis columns
    /// (what `measure::csv::write_set` writes and the track fit reads).
    pub fn set(&self) -> MeasurementSet {
        MeasurementSet {
            poses: self.rows.clone(),
            external: self.external.clone(),
            axes: self.axes.clone(),
        }
    }
}

/// Spread of the points [in their own unit] below which they are read as
/// metres, and above which as millimetres; in between the units are unclear.
const METRES_BELOW: f64 = 5.0;
const MM_ABOVE: f64 = 50.0;

/// Why a tracker export does not join.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum JoinError {
    /// The text is not a readable CSV; the reader's message.
    #[error("the tracker export: {0}")]
    Text(String),
    /// The export has no points.
    #[error("the tracker export has no points")]
    Empty,
    /// The header lacks an x, y or z column; the header as read.
    #[error("the tracker export's header needs x, y and z columns (and optionally point/name/id/index); got {0}")]
    Header(String),
    /// A coordinate is not a finite number.
    #[error("the tracker export, line {line}: `{field}` is not a number")]
    Number {
        /// 1-based line of the record in the text.
        line: usize,
        /// The field as read (shortened).
        field: String,
    },
    /// A record's field count differs from the header's.
    #[error("the tracker export, {0}")]
    Fields(#[from] FieldCount),
    /// Joining by name was asked, but the export has no name column.
    #[error("the tracker export has no point name column, so it can only join by order")]
    NoNames,
    /// A point name appears twice in the export; the name.
    #[error("the tracker export has point `{0}` twice")]
    Duplicate(String),
    /// Plan points the export does not have, by name.
    #[error("plan points missing from the tracker export: {}", .0.join(", "))]
    Missing(Vec<String>),
    /// Export points that name no plan point.
    #[error("tracker points that are not in the plan: {}", .0.join(", "))]
    Extra(Vec<String>),
    /// Joining by order, the export has not as many points as the plan.
    #[error("joining by order: the plan has {plan} points, the tracker export {tracker}")]
    Count {
        /// Points in the plan.
        plan: usize,
        /// Points in the tracker export.
        tracker: usize,
    },
    /// A coordinate, in millimetres, is beyond the bound of a measured position.
    #[error("tracker point {point}: {} mm (in millimetres) is beyond the bound ±{} mm of a measured position", show(*value), POSITION_MM.max)]
    OutOfRange {
        /// 1-based index of the point in plan order.
        point: usize,
        /// The coordinate [mm].
        value: f64,
    },
    /// The units were to be detected, but the points' spread fits neither
    /// metres nor millimetres.
    #[error("units unclear: the points spread over {spread} (neither clearly metres, below {METRES_BELOW}, nor millimetres, above {MM_ABOVE}); give the units (mm or m)")]
    UnitsUnclear {
        /// Largest extent of the points along an axis, in their own unit.
        spread: f64,
    },
}

/// A tracker export as read: point names (when it has a name column), the
/// positions in the export's own unit, and the unit its header names.
pub(crate) struct Export {
    pub(crate) names: Option<Vec<String>>,
    pub(crate) xyz: Vec<[f64; 3]>,
    pub(crate) header_units: Option<Units>,
}

/// The tracker export's points (also read by the ISO 9283 cycles' join).
pub(crate) fn read(text: &str) -> Result<Export, JoinError> {
    let t = csv_text::read(text, Dialect::default())
        .map_err(|e| JoinError::Text(e.to_string()))?
        .ok_or(JoinError::Empty)?;
    let keys: Vec<String> = t
        .header
        .iter()
        .map(|h| {
            h.chars()
                .filter(char::is_ascii_alphanumeric)
                .collect::<String>()
                .to_ascii_lowercase()
        })
        .collect();
    let find = |axis: &str| -> Option<(usize, Option<Units>)> {
        keys.iter()
            .enumerate()
            .find_map(|(i, k)| match k.strip_prefix(axis)? {
                "" => Some((i, None)),
                "mm" => Some((i, Some(Units::Mm))),
                "m" => Some((i, Some(Units::M))),
                _ => None,
            })
    };
    let (Some(x), Some(y), Some(z)) = (find("x"), find("y"), find("z")) else {
        return Err(JoinError::Header(t.header.join(",")));
    };
    let name = keys
        .iter()
        .position(|k| ["point", "name", "id", "index", "pointname", "label"].contains(&k.as_str()));
    let mut names = Vec::new();
    let mut xyz = Vec::new();
    for r in &t.records {
        t.check_shape(r)?;
        let mut p = [0.0; 3];
        for (v, c) in p.iter_mut().zip([x.0, y.0, z.0]) {
            *v = t
                .number(r.fields[c].trim())
                .filter(|v| v.is_finite())
                .ok_or_else(|| JoinError::Number {
                    line: r.line,
                    field: csv_text::short_text(&r.fields[c]),
                })?;
        }
        xyz.push(p);
        if let Some(n) = name {
            names.push(read_text(r.fields[n].trim()).into_owned());
        }
    }
    if xyz.is_empty() {
        return Err(JoinError::Empty);
    }
    Ok(Export {
        names: name.map(|_| names),
        xyz,
        header_units: x.1.or(y.1).or(z.1),
    })
}

/// Metres or millimetres from the points' largest extent along an axis.
pub(crate) fn detect_units(xyz: &[[f64; 3]]) -> Result<Units, JoinError> {
    let spread = (0..3)
        .map(|k| {
            let (lo, hi) = xyz
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
                    (a.min(p[k]), b.max(p[k]))
                });
            hi - lo
        })
        .fold(0.0, f64::max);
    if spread < METRES_BELOW {
        Ok(Units::M)
    } else if spread > MM_ABOVE {
        Ok(Units::Mm)
    } else {
        Err(JoinError::UnitsUnclear { spread })
    }
}

/// Index of the plan point a tracker point `name` refers to: its name
/// (case-insensitive), else a 1-based index.
fn plan_index(plan: &[PlanPoint], name: &str) -> Option<usize> {
    plan.iter()
        .position(|p| p.name.eq_ignore_ascii_case(name))
        .or_else(|| {
            let k: usize = name.parse().ok()?;
            (1..=plan.len()).contains(&k).then(|| k - 1)
        })
}

/// Joins the tracker export `text` to `plan` into measurement rows.
pub fn join(plan: &[PlanPoint], text: &str, opts: &JoinOptions) -> Result<Joined, JoinError> {
    let e = read(text)?;
    let units = match opts.units {
        Units::Detect => match e.header_units {
            Some(u) => u,
            None => detect_units(&e.xyz)?,
        },
        u => u,
    };
    let scale = if units == Units::M { 1e3 } else { 1.0 };
    let by = match (opts.by, &e.names) {
        (JoinBy::Detect, Some(_)) => JoinBy::Name,
        (JoinBy::Detect, None) => JoinBy::Order,
        (JoinBy::Name, None) => return Err(JoinError::NoNames),
        (b, _) => b,
    };
    let mut slot: Vec<Option<[f64; 3]>> = vec![None; plan.len()];
    if by == JoinBy::Order {
        if e.xyz.len() != plan.len() {
            return Err(JoinError::Count {
                plan: plan.len(),
                tracker: e.xyz.len(),
            });
        }
        for (s, p) in slot.iter_mut().zip(&e.xyz) {
            *s = Some(*p);
        }
    } else {
        let names = e.names.as_deref().unwrap_or_default();
        let mut extra = Vec::new();
        for (n, p) in names.iter().zip(&e.xyz) {
            match plan_index(plan, n) {
                Some(i) if slot[i].is_some() => return Err(JoinError::Duplicate(n.clone())),
                Some(i) => slot[i] = Some(*p),
                None => extra.push(n.clone()),
            }
        }
        if !extra.is_empty() {
            return Err(JoinError::Extra(extra));
        }
    }
    let missing: Vec<String> = plan
        .iter()
        .zip(&slot)
        .filter(|(_, s)| s.is_none())
        .map(|(p, _)| p.name.clone())
        .collect();
    if !missing.is_empty() {
        return Err(JoinError::Missing(missing));
    }
    let rows = plan
        .iter()
        .zip(slot.into_iter().flatten())
        .enumerate()
        .map(|(i, (p, xyz))| {
            let xyz_mm = xyz.map(|v| v * scale);
            if let Some(v) = xyz_mm.iter().find(|v| !within(**v, &POSITION_MM)) {
                return Err(JoinError::OutOfRange {
                    point: i + 1,
                    value: *v,
                });
            }
            Ok(MeasuredPose::position_only(p.q_deg.clone(), xyz_mm))
        })
        .collect::<Result<_, _>>()?;
    Ok(Joined {
        rows,
        units,
        by,
        axes: super::export::plan_axes(plan),
        external: plan.iter().map(|p| p.external).collect(),
    })
}
