//! External-axis values per row of a targets file, each target moved into
//! the robot's base frame at its own values: a track's `e1` column, the
//! robot's base carried along a calibrated [`LinearTrack`]
//! ([`place_on_track`]); or a positioner's `e1` (tilt) and `e2` (rotate)
//! columns, the target given in its face plate frame
//! ([`place_on_positioner`]: `robot_cell_from_base⁻¹·F(v)·T`,
//! `solve::external::positioner`); or both, the robot on a track beside a
//! positioner, `e1` the track and `e2`, `e3` the positioner's axes
//! ([`place_on_track_and_positioner`]: `B(e)⁻¹·F(v)·T`).
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
//! Units: track values in mm, positioner values in degrees, as the
//! controller shows them; positions in mm and orientations in each row's
//! convention at the boundary, SI inside.
//!
//! A row fails alone (`invalid_target`, naming its line and the column) when
//! its value is empty, not a finite number, or beyond the travel the track
//! was measured over ([`RowError::OutsideTravel`]): never extrapolated, never
//! skipped.

use super::positioner::AxisValues;
use super::rows::{column_index, TrackColumnError, TRACK_COLUMN};
use crate::measure::csv_text::{self, short_text, Dialect};
use crate::model::external::{LinearTrack, TiltRotate};
use crate::model::orientation::{rotation_from, rotation_to};
use crate::model::Pose;
use crate::solve::cell::{WorkObject, WorkObjectFrame};
use crate::solve::ik::{FalseTarget, RowError, TargetFrame, TargetInput, TargetResult, TargetsCsv};
use nalgebra::Vector3;

/// One targets-file row's value of an external axis (a track's [mm], a
/// positioner axis's [deg]), or why the row has none.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetValue {
    /// 1-based line of the row in the text.
    pub line: usize,
    /// The value, or the row's error (the row fails alone).
    pub value: Result<f64, RowError>,
}

impl TargetValue {
    /// A turntable's axis 1, standing at 0, on every row of `values` (a
    /// turntable is the positioner whose axis 1 stands at 0).
    pub fn held_at_zero(values: &[TargetValue]) -> Vec<TargetValue> {
        values
            .iter()
            .map(|t| TargetValue {
                line: t.line,
                value: Ok(0.0),
            })
            .collect()
    }
}

/// The `e1` value of every row of a targets file `text`, or `None` when its
/// header has no `e1` column (any ASCII case) or it has no header
/// ([`target_column_values`]).
pub fn target_track_values(
    text: &str,
    dialect: Dialect,
) -> Result<Option<Vec<TargetValue>>, TrackColumnError> {
    target_column_values(text, dialect, TRACK_COLUMN)
}

/// The values of column `column` (any ASCII case) of every row of a
/// targets file `text`, or `None` when its header has no such column or it
/// has no header. A row whose field count is not the header's, or whose
/// value is not a finite number, carries its error (it fails alone, as
/// every malformed targets row); a header naming the column twice refuses
/// the file.
pub fn target_column_values(
    text: &str,
    dialect: Dialect,
    column: &str,
) -> Result<Option<Vec<TargetValue>>, TrackColumnError> {
    let Some(table) = csv_text::read(text, dialect)? else {
        return Ok(None);
    };
    let Some(col) = column_index(&table.header, table.header_line, column)? else {
        return Ok(None);
    };
    let column = table.header[col].clone();
    let values = table
        .records
        .iter()
        .map(|r| {
            let value = table.check_shape(r).map_err(RowError::from).and_then(|()| {
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
            TargetValue {
                line: r.line,
                value,
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
    values: &[TargetValue],
    track: &LinearTrack,
    frame: TargetFrame,
    work_object: Option<&WorkObject>,
) -> PlacedRows {
    place(csv, |line| {
        let b = base_at(track, values, line)?;
        Ok(match (work_object, frame) {
            (Some(w), _) => {
                let wb = match w.frame {
                    // `Cell::work_object` gives no face-plate work object.
                    WorkObjectFrame::Base | WorkObjectFrame::FacePlate => w.pose,
                    WorkObjectFrame::Measurement => b.inverse().compose(&w.pose),
                };
                (wb, Some(wb))
            }
            (None, TargetFrame::Cell) => (b.inverse(), None),
            (None, TargetFrame::Base) => (Pose::identity(), None),
        })
    })
}

/// Moves every valid row of `csv`, a target `T` given in a positioner's
/// face plate frame, into the robot's base frame at its row's axis values
/// (`tilt` and `rotate` [deg], matched by line):
/// `robot_cell_from_base⁻¹·F(v)·T` (`solve::external::positioner`; the
/// robot and the positioner registered in the same cell frame). The
/// targets are then solved with `TargetFrame::Base`; their false targets
/// stay in the controller's base frame. A row without a number in either
/// column becomes invalid (it fails alone, naming its line and column).
pub fn place_on_positioner(
    csv: &mut TargetsCsv,
    tilt: &[TargetValue],
    rotate: &[TargetValue],
    positioner: &TiltRotate,
    robot_cell_from_base: &Pose,
) -> PlacedRows {
    let base_from_cell = robot_cell_from_base.inverse();
    place(csv, |line| {
        let values = AxisValues {
            tilt_deg: value_at(tilt, line, TILT_COLUMN)?,
            rotate_deg: value_at(rotate, line, ROTATE_COLUMN)?,
        };
        let w = base_from_cell.compose(&positioner.cell_from_face_plate(values.as_array()));
        Ok((w, None))
    })
}

/// Moves every valid row of `csv`, a target `T` given in a positioner's
/// face plate frame, into the base frame of a robot carried by a track, at
/// the row's track value (`track_values` [mm]) and axis values (`tilt`,
/// `rotate` [deg]), all matched by line: `B(e)⁻¹·F(v)·T`, the track and the
/// positioner registered in the same cell frame (the controller's world).
/// The columns are the programs' numbering beside a track
/// ([`positioner_columns`]`(true)`: `e1` the track, `e2` the tilt, `e3` the
/// rotate). The targets are then solved with `TargetFrame::Base`; their
/// false targets stay in the controller's base frame at the row's track
/// value. A row without a number in a column, or beyond the travel the
/// track was measured over, becomes invalid (it fails alone, naming its
/// line and column).
pub fn place_on_track_and_positioner(
    csv: &mut TargetsCsv,
    track_values: &[TargetValue],
    track: &LinearTrack,
    tilt: &[TargetValue],
    rotate: &[TargetValue],
    positioner: &TiltRotate,
) -> PlacedRows {
    let [tilt_column, rotate_column] = positioner_columns(true);
    place(csv, |line| {
        let b = base_at(track, track_values, line)?;
        let values = AxisValues {
            tilt_deg: value_at(tilt, line, tilt_column)?,
            rotate_deg: value_at(rotate, line, rotate_column)?,
        };
        let w = b
            .inverse()
            .compose(&positioner.cell_from_face_plate(values.as_array()));
        Ok((w, None))
    })
}

/// The columns of a positioner's axes in a targets file: axis 1 (tilt).
pub const TILT_COLUMN: &str = "e1";
/// The columns of a positioner's axes in a targets file: axis 2 (rotate).
pub const ROTATE_COLUMN: &str = "e2";

/// The targets-file columns of a positioner's tilt and rotate axes: `e1`,
/// `e2` ([`TILT_COLUMN`], [`ROTATE_COLUMN`]) with the robot on a fixed
/// base; `e2`, `e3` beside a track (`on_track`), whose value is `e1`, as
/// the programs number them (`program::axes::FilterAxes::positioner_numbers`).
pub const fn positioner_columns(on_track: bool) -> [&'static str; 2] {
    if on_track {
        ["e2", "e3"]
    } else {
        [TILT_COLUMN, ROTATE_COLUMN]
    }
}

/// The robot's base `B(e)` in the cell frame at row `line`'s track value
/// in `values`, or the row's error (no number, or beyond the travel).
fn base_at(track: &LinearTrack, values: &[TargetValue], line: usize) -> Result<Pose, RowError> {
    let e = value_at(values, line, TRACK_COLUMN)?;
    track
        .cell_from_base(e)
        .map_err(|travel| RowError::OutsideTravel {
            line,
            column: TRACK_COLUMN.into(),
            travel,
        })
}

/// Row `line`'s value in `values`, or its error (no value read: empty).
fn value_at(values: &[TargetValue], line: usize, column: &str) -> Result<f64, RowError> {
    values.iter().find(|v| v.line == line).map_or_else(
        || {
            Err(RowError::NotNumber {
                line,
                column: column.into(),
                value: String::new(),
            })
        },
        |v| v.value.clone(),
    )
}

/// Moves each valid row's target by the pose `frame_of(line)` gives (`W`,
/// and the work object its false target is returned in), or makes the row
/// invalid with its error.
fn place(
    csv: &mut TargetsCsv,
    mut frame_of: impl FnMut(usize) -> Result<(Pose, Option<Pose>), RowError>,
) -> PlacedRows {
    let mut work_objects = Vec::with_capacity(csv.rows.len());
    for row in &mut csv.rows {
        let mut back = None;
        if let Ok(target) = &mut row.target {
            match frame_of(row.line) {
                Err(e) => row.target = Err(e),
                Ok((w, b)) => {
                    *target = moved(&w, target);
                    back = b;
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

    /// A turntable at the cell's origin, its plate 0.5 m up: axis 1 (tilt)
    /// about x, axis 2 (rotate) about z, no offsets.
    fn turntable() -> TiltRotate {
        use crate::model::external::RotaryAxis;
        TiltRotate {
            cell_from_base: Pose::identity(),
            tilt: RotaryAxis::new(Vector3::x(), Vector3::zeros(), 0.0, 1.0),
            rotate: RotaryAxis::new(Vector3::z(), Vector3::zeros(), 0.0, 1.0),
            face_plate: Pose::from_translation(Vector3::new(0.0, 0.0, 0.5)),
        }
    }

    /// Closed form: a turntable (axis 1 at 0) at a quarter turn carries a
    /// target at (1, 0, 0) on the plate, 0.5 m above the base, to (0, 1,
    /// 0.5) in a robot base standing at the cell's origin; a row without its
    /// rotate value fails alone.
    #[test]
    fn a_target_on_the_face_plate_is_moved_by_its_rows_axis_values() {
        let p = turntable();
        let text = "x,y,z,e1,e2\n1000,0,0,0,90\n1000,0,0,0,\n";
        let d = Dialect::default();
        let tilt = target_column_values(text, d, TILT_COLUMN).unwrap().unwrap();
        let rotate = target_column_values(text, d, ROTATE_COLUMN)
            .unwrap()
            .unwrap();
        let mut csv = parse_targets_csv_beside(text, d, &["e1", "e2"]).unwrap();
        place_on_positioner(&mut csv, &tilt, &rotate, &p, &Pose::identity());
        let at = csv.rows[0].target.as_ref().unwrap().xyz_mm;
        assert!(
            (Vector3::from(at) - Vector3::new(0.0, 1000.0, 500.0)).norm() < 1e-9,
            "{at:?}"
        );
        let e = csv.rows[1].target.as_ref().unwrap_err().to_string();
        assert_eq!(e, "line 3: column `e2`: `` is not a number");
    }

    /// Closed form: the same turntable beside a straight track along cell
    /// x; with the base carried to 200 mm, the quarter-turned target at
    /// (0, 1, 0.5) in the cell is at (−0.2, 1, 0.5) in the base. A row
    /// beyond the travel, or without its rotate value (`e3` there), fails
    /// alone, naming the column.
    #[test]
    fn beside_a_track_a_plate_target_is_moved_by_its_rows_track_and_axis_values() {
        let p = turntable();
        let text = "x,y,z,e1,e2,e3\n1000,0,0,200,0,90\n1000,0,0,1200,0,90\n1000,0,0,200,0,\n";
        let d = Dialect::default();
        let [tilt_column, rotate_column] = positioner_columns(true);
        let read = |c: &str| target_column_values(text, d, c).unwrap().unwrap();
        let mut csv = parse_targets_csv_beside(text, d, &["e1", "e2", "e3"]).unwrap();
        let placed = place_on_track_and_positioner(
            &mut csv,
            &read(TRACK_COLUMN),
            &straight(),
            &read(tilt_column),
            &read(rotate_column),
            &p,
        );
        let at = csv.rows[0].target.as_ref().unwrap().xyz_mm;
        assert!(
            (Vector3::from(at) - Vector3::new(-200.0, 1000.0, 500.0)).norm() < 1e-9,
            "{at:?}"
        );
        let msg = |i: usize| csv.rows[i].target.as_ref().unwrap_err().to_string();
        assert!(
            msg(1).starts_with("line 3: column `e1`: value 1200 mm is outside"),
            "{}",
            msg(1)
        );
        assert_eq!(msg(2), "line 4: column `e3`: `` is not a number");
        assert_eq!(placed.work_objects, vec![None; 3]);
        assert_eq!(positioner_columns(false), [TILT_COLUMN, ROTATE_COLUMN]);
    }
}
