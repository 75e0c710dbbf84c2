//! The join of the tracker's export of an ISO 9283 run back to the plan: a
//! CSV of points (a name column, optional; `x`, `y`, `z` in mm or m, read as
//! `robocal plan join` reads a tracker export) turned into the cycles CSV
//! `pose,cycle,x_mm,y_mm,z_mm` that `robocal iso9283` reads.
//!
//! By name, each point names its pose and cycle as the cycle program's
//! comments do: `P3 cycle 12`, and also `P3_C12`, `p3-c12`, `P3.12`
//! (`P<i>`, separators, an optional `cycle` or `c`, `<k>`). By order (no name
//! column), the points come in the program's order: cycle 1's P1 … P5, then
//! cycle 2's, …; their count must be a whole number of cycles. A (pose,
//! cycle) the export lacks is listed, not refused (the figures take the
//! cycles measured; `outcome` says what that leaves undetermined).
//!
//! Positions: millimetres in the frame the tracker measures in (the plan's
//! commanded positions are in the calibrated model's measurement frame).

use super::csv::Commanded;
use super::outcome::{CYCLES_MAX, XYZ_MAX_MM};
use crate::csv_write::{push_header, push_row, Cell};
use crate::model::bounds::show;
use crate::plan::join::{detect_units, read, JoinError};
use crate::plan::{JoinBy, JoinOptions, Units};

/// One attained position of the run.
#[derive(Debug, Clone, PartialEq)]
pub struct CycleRow {
    /// The plan's pose name (`P1` …).
    pub pose: String,
    /// 1-based cycle.
    pub cycle: u32,
    /// [mm]
    pub xyz_mm: [f64; 3],
}

/// The joined run and how it was joined.
#[derive(Debug, Clone, PartialEq)]
pub struct JoinedCycles {
    /// In cycle order, and in the plan's order within a cycle.
    pub rows: Vec<CycleRow>,
    /// The units the export was read in.
    pub units: Units,
    /// How the points were matched.
    pub by: JoinBy,
    /// The highest cycle number joined.
    pub cycles: u32,
    /// `P<i> cycle <k>` of every pose and cycle up to [`Self::cycles`] the
    /// export lacks.
    pub missing: Vec<String>,
}

/// Why a tracker export of the cycles does not join.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CycleJoinError {
    /// The export cannot be read (see [`JoinError`]).
    #[error(transparent)]
    Export(#[from] JoinError),
    /// A point name is not `P<i> cycle <k>`; the name.
    #[error("tracker point `{0}` does not name a pose and a cycle (write `P<i> cycle <k>`, as the cycle program's comments do)")]
    Name(String),
    /// A point names a pose the plan does not have.
    #[error("tracker point `{point}`: the plan has no pose {pose} (it has {plan})")]
    NotInPlan {
        /// The point's name.
        point: String,
        /// The pose it names.
        pose: String,
        /// The plan's poses, for the message.
        plan: String,
    },
    /// A cycle number is not from 1 to [`CYCLES_MAX`].
    #[error("tracker point `{point}`: cycle {cycle} is not from 1 to {CYCLES_MAX}")]
    Cycle {
        /// The point's name.
        point: String,
        /// The cycle number it names.
        cycle: u64,
    },
    /// A pose and cycle appears twice; which.
    #[error("the tracker export has {0} twice")]
    Duplicate(String),
    /// Joining by order, the points are not a whole number of cycles of the plan.
    #[error("joining by order: {points} tracker points are not a whole number of cycles of the plan's {poses} poses")]
    Count {
        /// Points in the export.
        points: usize,
        /// Poses in the plan.
        poses: usize,
    },
    /// Joining by order, the points are more than [`CYCLES_MAX`] cycles of the plan.
    #[error("joining by order: {points} tracker points are more than {CYCLES_MAX} cycles of the plan's {poses} poses")]
    TooManyCycles {
        /// Points in the export.
        points: usize,
        /// Poses in the plan.
        poses: usize,
    },
    /// A coordinate, in millimetres, is beyond ±[`XYZ_MAX_MM`].
    #[error("tracker point {point}: {} mm (in millimetres) is beyond the bound ±{XYZ_MAX_MM} mm", show(*value))]
    OutOfRange {
        /// 1-based index of the point in the export.
        point: usize,
        /// The coordinate [mm].
        value: f64,
    },
}

/// `(pose, cycle)` of a point name `P<i>[sep][cycle|c][sep]<k>`.
pub fn pose_cycle(name: &str) -> Option<(u64, u64)> {
    let lower = name.trim().to_ascii_lowercase();
    let s = lower.strip_prefix('p')?;
    let digits = s.chars().take_while(char::is_ascii_digit).count();
    if digits == 0 {
        return None;
    }
    let pose = s[..digits].parse().ok()?;
    let separators = |t: &str| {
        t.trim_start_matches(|c: char| !c.is_ascii_alphanumeric())
            .to_string()
    };
    let rest = separators(&s[digits..]);
    let rest = rest
        .strip_prefix("cycle")
        .or_else(|| rest.strip_prefix('c'))
        .unwrap_or(&rest);
    let rest = separators(rest);
    if rest.is_empty() || !rest.chars().all(|c| c.is_ascii_digit()) {
        return None;
    }
    Some((pose, rest.parse().ok()?))
}

/// Joins the tracker export `text` of a run of `plan` into cycle rows.
pub fn join_cycles(
    plan: &[Commanded],
    text: &str,
    opts: &JoinOptions,
) -> Result<JoinedCycles, CycleJoinError> {
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
        (JoinBy::Name, None) => return Err(JoinError::NoNames.into()),
        (b, _) => b,
    };
    let n = plan.len();
    // (plan index, cycle) of each point, in the export's order.
    let mut keys: Vec<(usize, u32)> = Vec::with_capacity(e.xyz.len());
    if by == JoinBy::Order {
        let points = e.xyz.len();
        if n == 0 || points % n != 0 {
            return Err(CycleJoinError::Count { points, poses: n });
        }
        if points / n > CYCLES_MAX {
            return Err(CycleJoinError::TooManyCycles { points, poses: n });
        }
        keys.extend((0..points).map(|i| (i % n, (i / n) as u32 + 1)));
    } else {
        let names = e.names.as_deref().unwrap_or_default();
        let plan_names = || {
            plan.iter()
                .map(|c| c.name.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        };
        for name in names {
            let (pose, cycle) =
                pose_cycle(name).ok_or_else(|| CycleJoinError::Name(name.clone()))?;
            let pose_name = format!("P{pose}");
            let i = plan
                .iter()
                .position(|c| c.name == pose_name)
                .ok_or_else(|| CycleJoinError::NotInPlan {
                    point: name.clone(),
                    pose: pose_name.clone(),
                    plan: plan_names(),
                })?;
            if !(1..=CYCLES_MAX as u64).contains(&cycle) {
                return Err(CycleJoinError::Cycle {
                    point: name.clone(),
                    cycle,
                });
            }
            let key = (i, cycle as u32);
            if keys.contains(&key) {
                return Err(CycleJoinError::Duplicate(format!(
                    "{pose_name} cycle {cycle}"
                )));
            }
            keys.push(key);
        }
    }
    let mut rows: Vec<(usize, CycleRow)> = Vec::with_capacity(keys.len());
    for (k, ((i, cycle), xyz)) in keys.iter().zip(&e.xyz).enumerate() {
        let xyz_mm = xyz.map(|v| v * scale);
        if let Some(v) = xyz_mm
            .iter()
            .find(|v| !(v.is_finite() && v.abs() <= XYZ_MAX_MM))
        {
            return Err(CycleJoinError::OutOfRange {
                point: k + 1,
                value: *v,
            });
        }
        rows.push((
            *i,
            CycleRow {
                pose: plan[*i].name.clone(),
                cycle: *cycle,
                xyz_mm,
            },
        ));
    }
    rows.sort_by_key(|(i, r)| (r.cycle, *i));
    let cycles = rows.iter().map(|(_, r)| r.cycle).max().unwrap_or(0);
    let mut missing = Vec::new();
    for k in 1..=cycles {
        for (i, c) in plan.iter().enumerate() {
            if !keys.contains(&(i, k)) {
                missing.push(format!("{} cycle {k}", c.name));
            }
        }
    }
    Ok(JoinedCycles {
        rows: rows.into_iter().map(|(_, r)| r).collect(),
        units,
        by,
        cycles,
        missing,
    })
}

/// The cycles CSV `pose,cycle,x_mm,y_mm,z_mm` of `rows` (what
/// `robocal iso9283 --measured` reads; positions to 1 nm).
pub fn cycles_csv(rows: &[CycleRow]) -> String {
    let mut s = String::new();
    push_header(&mut s, ["pose", "cycle", "x_mm", "y_mm", "z_mm"]);
    for r in rows {
        let mut row = vec![Cell::text(&r.pose), Cell::int(r.cycle)];
        row.extend(r.xyz_mm.iter().map(|v| Cell::fixed(*v, 6)));
        push_row(&mut s, &row);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn point_names_give_pose_and_cycle() {
        for (name, want) in [
            ("P3 cycle 12", Some((3, 12))),
            ("p3_c12", Some((3, 12))),
            ("P3-12", Some((3, 12))),
            ("P3.C12", Some((3, 12))),
            (" P1 Cycle 1 ", Some((1, 1))),
            ("P13", None),
            ("P3 cycle", None),
            ("cycle 3", None),
            ("P3 cycle 1x", None),
        ] {
            assert_eq!(pose_cycle(name), want, "{name}");
        }
    }
}
