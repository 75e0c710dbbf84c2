//! A track value per row of a targets file: the `e1` column beside a
//! target's `x, y, z` and orientation, each target solved with the robot's
//! base carried to its own value along a calibrated [`LinearTrack`].
//!
//! Frames: a target `T` in the track's cell frame (the tracker frame the
//! track was measured in) is the base-frame target `B(e)⁻¹·T`, with
//! `B(e) = track.cell_from_base(e)` (`solve::external::track`); a target in
//! the robot's base frame stays as given (the track does not move it); a
//! target in a work object `W` is `W_b(e)·T`, with `W_b(e) = W` for a
//! base-frame work object and `B(e)⁻¹·W` for one stated in the measurement
//! (cell) frame, and its false target is returned in `W_b(e)` (`W_b(e)⁻¹·F`).
//! Every target is then solved in the base frame by one solver, so a path
//! (each target seeded by the one before) runs across track values.
//!
//! Units: track values in mm as the controller shows them; positions in mm
//! and orientations in each row's convention at the boundary, SI inside.
//!
//! A row fails alone (`invalid_target`, naming its line and the column) when
//! its value is empty, not a finite number, or beyond the travel the track
//! was measured over ([`RowError::OutsideTravel`]): never extrapolated, never
//! skipped.

use super::rows::{TrackColumnError, TRACK_COLUMN};
use crate::measure::csv_text::{self, short_text, Dialect};
use crate::model::external::LinearTrack;
use crate::model::orientation::{rotation_from, rotation_to};
use crate::model::Pose;
use crate::solve::cell::{WorkObject, WorkObjectFrame};
use crate::solve::ik::{FalseTarget, RowError, TargetFrame, TargetInput, TargetResult, TargetsCsv};
use nalgebra::Vector3;

/// One targets-file row's track value, or why the row has none.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetTrackValue {
    /// 1-based line of the row in the text.
    pub line: usize,
    /// The value [mm], or the row's error (the row fails alone).
    pub value_mm: Result<f64, RowError>,
}

/// The `e1` value of every row of a targets file `text`, or `None` when its
/// header has no `e1` column (any ASCII case) or it has no header. A row
/// whose field count is not the header's, or whose value is not a finite
/// number, carries its error (it fails alone, as every malformed targets
/// row); a header naming `e1` twice refuses the file.
pub fn target_track_values(
    text: &str,
    dialect: Dialect,
) -> Result<Option<Vec<TargetTrackValue>>, TrackColumnError> {
    let Some(table) = csv_text::read(text, dialect)? else {
        return Ok(None);
    };
    let mut at = table
        .header
        .iter()
        .enumerate()
        .filter(|(_, h)| h.eq_ignore_ascii_case(TRACK_COLUMN))
        .map(|(i, _)| i);
    let Some(col) = at.next() else {
        return Ok(None);
    };
    if at.next().is_some() {
        return Err(TrackColumnError::Duplicate {
            line: table.header_line,
        });
    }
    let column = table.header[col].clone();
    let values = table
        .records
        .iter()
        .map(|r| {
            let value_mm = table.check_shape(r).map_err(RowError::from).and_then(|()| {
                let field = &r.fields[col];
                table
                    .number(field)
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| RowError::NotNumber {
                        line: r.line,
                        column: column.clone(),
                        value: short_text(field),
                    })
            });
            TargetTrackValue {
                line: r.line,
                value_mm,
            }
        })
        .collect();
    Ok(Some(values))
}

/// Where a targets file's rows were placed: per row, the work object its
/// false target is returned in (`W_b(e)` in the base frame), when the
/// targets are in one.
#[derive(Debug, Clone, PartialEq)]
pub struct PlacedRows {
    /// Per row of the file, in order.
    work_objects: Vec<Option<Pose>>,
}

impl PlacedRows {
    /// Each converged result's false target `F` (base frame) as
    /// `W_b(e)⁻¹·F` in its row's work object; unchanged without one.
    /// `results` are the file's, one per row in order.
    pub fn false_targets_back(&self, results: &mut [TargetResult]) {
        for (r, w) in results.iter_mut().zip(&self.work_objects) {
            if let (Some(w), Some(f)) = (w, &r.false_target) {
                r.false_target = Some(false_target_in(w, f));
            }
        }
    }
}

/// Moves every valid row of `csv` into the robot's base frame at its own
/// track value (`values`, matched by line; module docs): the targets are
/// then solved with `TargetFrame::Base`. `frame` is the frame the targets
/// are given in without a work object; with `work_object` they are in it. A
/// row without a value, or beyond the travel, becomes invalid (it fails
/// alone, naming its line and column `column`).
pub fn place_on_track(
    csv: &mut TargetsCsv,
    values: &[TargetTrackValue],
    track: &LinearTrack,
    frame: TargetFrame,
    work_object: Option<&WorkObject>,
) -> PlacedRows {
    let mut work_objects = Vec::with_capacity(csv.rows.len());
    for row in &mut csv.rows {
        let value = values.iter().find(|v| v.line == row.line).map_or_else(
            || {
                Err(RowError::NotNumber {
                    line: row.line,
                    column: TRACK_COLUMN.into(),
                    value: String::new(),
                })
            },
            |v| v.value_mm.clone(),
        );
        let base = value.and_then(|v| {
            track
                .cell_from_base(v)
                .map_err(|travel| RowError::OutsideTravel {
                    line: row.line,
                    column: TRACK_COLUMN.into(),
                    travel,
                })
        });
        let mut back = None;
        if let Ok(target) = &mut row.target {
            match base {
                Err(e) => row.target = Err(e),
                Ok(b) => {
                    let w = match (work_object, frame) {
                        (Some(w), _) => {
                            let wb = match w.frame {
                                WorkObjectFrame::Base => w.pose,
                                WorkObjectFrame::Measurement => b.inverse().compose(&w.pose),
                            };
                            back = Some(wb);
                            wb
                        }
                        (None, TargetFrame::Cell) => b.inverse(),
                        (None, TargetFrame::Base) => Pose::identity(),
                    };
                    *target = moved(&w, target);
                }
            }
        }
        work_objects.push(back);
    }
    PlacedRows { work_objects }
}

/// A boundary target `T` as `W·T`, in the same convention; a target that is
/// not valid is returned as it is (it fails alone when solved).
fn moved(w: &Pose, t: &TargetInput) -> TargetInput {
    let mut out = t.clone();
    if let Ok((goal, conv)) = t.to_goal() {
        let p = w.r * goal.position + w.p;
        out.xyz_mm = [p.x * 1e3, p.y * 1e3, p.z * 1e3];
        if let (Some(r), Some(conv)) = (goal.rotation, conv) {
            out.orientation = rotation_to(conv, &(w.r * r));
        }
    }
    out
}

/// A base-frame false target in work object `w`: `W⁻¹·F`.
fn false_target_in(w: &Pose, f: &FalseTarget) -> FalseTarget {
    let mut out = f.clone();
    if let Ok(r) = rotation_from(f.convention, &f.orientation) {
        let p = w
            .inverse()
            .compose(&Pose::new(r, Vector3::from(f.xyz_mm) * 1e-3));
        out.xyz_mm = [p.p.x * 1e3, p.p.y * 1e3, p.p.z * 1e3];
        out.orientation = rotation_to(f.convention, &p.r);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::external::TrackDescription;
    use crate::solve::ik::parse_targets_csv;
    use crate::solve::ik::targets_csv::parse_targets_csv_beside;

    /// A straight track along cell x from the origin, travel 0…1000 mm.
    fn straight() -> LinearTrack {
        let d = TrackDescription {
            direction: [1.0, 0.0, 0.0],
            point_mm: [0.0, 0.0, 0.0],
            scale: 1.0,
            zero_mm: 0.0,
            mount_rpy_deg: [0.0, 0.0, 0.0],
            travel_mm: [0.0, 1000.0],
            maps: Default::default(),
        };
        d.to_model().unwrap()
    }

    #[test]
    fn each_row_is_moved_to_its_own_value_and_a_bad_value_fails_its_row() {
        let text = "id;x;y;z;E1\na;1500;0;0;200\nb;1500;0;0;1200\nc;1500;0;0;x\nd;1500;0\ne;1500;0;0;1000,5\n";
        let d = Dialect::default();
        let values = target_track_values(text, d).unwrap().unwrap();
        assert_eq!(values.len(), 5);
        assert!(parse_targets_csv(text, d).is_err(), "e1 is unknown there");
        let mut csv = parse_targets_csv_beside(text, d, &["e1"]).unwrap();
        let placed = place_on_track(&mut csv, &values, &straight(), TargetFrame::Cell, None);
        // a: the base stands at x = 200 mm, so the target is 1300 mm ahead.
        assert_eq!(
            csv.rows[0].target.as_ref().unwrap().xyz_mm,
            [1300.0, 0.0, 0.0]
        );
        let msg = |i: usize| csv.rows[i].target.as_ref().unwrap_err().to_string();
        assert!(
            msg(1).starts_with(
                "line 3: column `e1`: value 1200 mm is outside the travel measured, [0, 1000] mm"
            ),
            "{}",
            msg(1)
        );
        assert_eq!(msg(2), "line 4: column `E1`: `x` is not a number");
        assert!(msg(3).starts_with("line 5:"), "{}", msg(3));
        assert!(msg(4).contains("outside the travel"), "{}", msg(4));
        assert_eq!(placed.work_objects, vec![None; 5]);
        // Base-frame targets stay; a measurement-frame work object is
        // carried back by the base's value.
        let mut csv = parse_targets_csv_beside(text, d, &["e1"]).unwrap();
        place_on_track(&mut csv, &values, &straight(), TargetFrame::Base, None);
        assert_eq!(
            csv.rows[0].target.as_ref().unwrap().xyz_mm,
            [1500.0, 0.0, 0.0]
        );
        let w = WorkObject {
            name: "table".into(),
            number: None,
            frame: WorkObjectFrame::Measurement,
            pose: Pose::from_translation(Vector3::new(0.5, 0.0, 0.0)),
        };
        let mut csv = parse_targets_csv_beside(text, d, &["e1"]).unwrap();
        let placed = place_on_track(&mut csv, &values, &straight(), TargetFrame::Cell, Some(&w));
        let x = csv.rows[0].target.as_ref().unwrap().xyz_mm[0];
        assert!((x - 1800.0).abs() < 1e-9, "{x}");
        let wb = placed.work_objects[0].unwrap();
        assert!((wb.p - Vector3::new(0.3, 0.0, 0.0)).norm() < 1e-12);
        assert_eq!(target_track_values("x,y,z\n1,2,3\n", d).unwrap(), None);
    }
}
