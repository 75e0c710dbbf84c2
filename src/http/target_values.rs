//! A JSON solve's targets that each carry their own `e1`, `e2`, `e3`, as a
//! targets CSV's rows carry columns. Each target's values are read as the
//! body's would be (`solve_columns::axis_values`, a refusal naming the
//! target); every target gives the same fields and the body none; a work
//! object beside them is refused (the targets are in the cell frame, the
//! base frame or on the face plate). The targets then become rows numbered
//! by their 1-based position, so the service places each at its values as
//! it places a CSV's rows, one beyond the track's travel failing alone; a
//! failed row's words are given back in the JSON's terms
//! (`targets[i].e1`).

use super::solve_columns::{axis_values, AxisColumns, AxisSettings};
use super::ApiError;
use crate::service::positioners::{Plate, PlateValues};
use crate::solve::ik::{TargetInput, TargetRow, TargetsCsv};
use robocal_core::solve::external::TargetValue;

/// What the targets' own values carry, and what carries the part.
pub struct OwnValues {
    /// The values per target, as a targets CSV's columns.
    pub columns: AxisColumns,
    /// The stored positioner or turntable.
    pub plate: Plate,
}

impl OwnValues {
    /// The targets are on the face plate (a positioner's or a turntable's
    /// values), not in the cell or base frame along a track alone.
    pub fn on_plate(&self) -> bool {
        !matches!(self.columns, AxisColumns::None | AxisColumns::Track(_))
    }
}

fn given(t: &[Option<f64>; 3]) -> [bool; 3] {
    t.map(|v| v.is_some())
}

fn names(g: [bool; 3]) -> String {
    let listed: Vec<&str> = ["`e1`", "`e2`", "`e3`"]
        .into_iter()
        .zip(g)
        .filter_map(|(n, on)| on.then_some(n))
        .collect();
    if listed.is_empty() {
        "none".into()
    } else {
        listed.join(", ")
    }
}

/// The items of a body that carry their own values: `readings` of a
/// prediction, `targets` of a solve.
#[derive(Debug, Clone, Copy)]
pub struct Items {
    /// The body's field, e.g. `readings`.
    pub field: &'static str,
    /// One of them, e.g. `reading`.
    pub one: &'static str,
}

/// A prediction's readings.
pub const READINGS: Items = Items {
    field: "readings",
    one: "reading",
};

/// A solve's targets.
pub const TARGETS: Items = Items {
    field: "targets",
    one: "target",
};

/// Each item's own `e1`, `e2`, `e3` (`values`, one per item) read as the
/// body's would be (`axis_values` with `frame_given` and `plate`, a refusal
/// naming the item), when any item gives one: every item the same fields,
/// none beside the body's own `body`. `None` when no item gives one.
pub fn each_own(
    values: &[[Option<f64>; 3]],
    items: Items,
    body: [Option<f64>; 3],
    frame_given: bool,
    plate: Plate,
) -> Result<Option<Vec<AxisSettings>>, ApiError> {
    let Items { field, one } = items;
    let Some(first) = values.iter().position(|t| given(t) != [false; 3]) else {
        return Ok(None);
    };
    let want = given(&values[first]);
    if given(&body) != [false; 3] {
        return Err(ApiError::invalid(format!(
            "`{field}[{first}]` has its own {} and the body gives `e1`, `e2` or `e3` for every {one}: which holds is ambiguous; give the values per {one} or in the body",
            names(want)
        )));
    }
    let mut out = Vec::with_capacity(values.len());
    for (i, t) in values.iter().enumerate() {
        if given(t) != want {
            return Err(ApiError::invalid(format!(
                "`{field}[{i}]` gives {} and `{field}[{first}]` {}: give every {one} the same axes' values",
                names(given(t)),
                names(want)
            )));
        }
        out.push(
            axis_values(t[0], t[1], t[2], frame_given, plate).map_err(|e| match e {
                ApiError::Unprocessable(m) => {
                    ApiError::Unprocessable(format!("`{field}[{i}]`: {m}"))
                }
                other => other,
            })?,
        );
    }
    Ok(Some(out))
}

/// The targets' own values (`targets`, each target's `e1`, `e2`, `e3`),
/// when they carry them ([`each_own`]), beside the body's `body` values,
/// its work object (`work_object` whether it names one; with a track's
/// values alone), `plate` (its `turntable`) and `frame_given` (whether it
/// names a frame).
pub fn own_values(
    targets: &[[Option<f64>; 3]],
    body: [Option<f64>; 3],
    work_object: bool,
    plate: Plate,
    frame_given: bool,
) -> Result<Option<OwnValues>, ApiError> {
    let Some(each) = each_own(targets, TARGETS, body, frame_given, plate)? else {
        return Ok(None);
    };
    // A work object beside a track's values alone holds at each target's
    // value (as a targets CSV's `e1` with `robocal solve --work-object`);
    // a target at its own positioner values is on the face plate.
    if work_object && each.iter().any(|at| at.positioner_deg.is_some()) {
        return Err(ApiError::invalid(format!(
            "`work_object` beside the targets' own {}: a target at its own positioner values is on the face plate; give the targets in the face plate frame, or the values in the body to solve in a work object",
            names(given(&targets[0]))
        )));
    }
    let (mut track, mut tilt, mut rotate) = (Vec::new(), Vec::new(), Vec::new());
    for (i, at) in each.iter().enumerate() {
        let line = i + 1;
        if let Some(v) = at.track_mm {
            track.push(TargetValue { line, value: Ok(v) });
        }
        if let Some(v) = at.positioner_deg {
            tilt.push(TargetValue {
                line,
                value: Ok(v.tilt_deg),
            });
            rotate.push(TargetValue {
                line,
                value: Ok(v.rotate_deg),
            });
        }
    }
    let columns = match (track.is_empty(), tilt.is_empty()) {
        (false, true) => AxisColumns::Track(track),
        (true, false) => AxisColumns::Positioner(PlateValues { tilt, rotate }),
        (false, false) => AxisColumns::TrackAndPositioner {
            track,
            plate: PlateValues { tilt, rotate },
        },
        (true, true) => AxisColumns::None,
    };
    Ok(Some(OwnValues {
        columns,
        plate: each[0].plate,
    }))
}

/// The targets as rows numbered by their 1-based position (the lines the
/// values name).
pub fn as_rows(inputs: Vec<TargetInput>) -> TargetsCsv {
    TargetsCsv {
        convention: None,
        rows: inputs
            .into_iter()
            .enumerate()
            .map(|(i, t)| TargetRow {
                id: t.id.clone().unwrap_or_else(|| (i + 1).to_string()),
                line: i + 1,
                target: Ok(t),
            })
            .collect(),
    }
}

/// A failed row's words in the JSON's terms: ``line N: column `eK`: …``
/// in target `i`'s (row `i + 1`) `message` becomes `` `targets[i].eK`: … ``.
pub fn in_json_terms(i: usize, message: &mut String) {
    let row = format!("line {}: column `", i + 1);
    let Some(at) = message.find(&row) else {
        return;
    };
    let rest = &message[at + row.len()..];
    if let Some((column, words)) = rest.split_once("`: ") {
        *message = format!("{}`targets[{i}].{column}`: {words}", &message[..at]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rows_words_name_the_target() {
        let mut m = "invalid target: line 4: column `e1`: value 9000 mm is outside".to_string();
        in_json_terms(3, &mut m);
        assert_eq!(
            m,
            "invalid target: `targets[3].e1`: value 9000 mm is outside"
        );
        // Another row's line, or no line, is left as it is.
        let mut other = "invalid target: line 2: column `e1`: x".to_string();
        in_json_terms(3, &mut other);
        assert_eq!(other, "invalid target: line 2: column `e1`: x");
    }
}
