//! The external-axis columns `e1…e6`: read per reading, written beside the
//! joints, refused by the robot-only reader and when a value is missing,
//! not finite or out of bounds, each refusal naming line and column.

use super::*;
use crate::measure::external::{ExternalAxis, MeasurementSet};

const TRACK: &str = "q1,q2,q3,q4,q5,q6,e1,x,y,z,set\n\
    10,95,-20,0,30,0,0,1523.2,12.5,980.1,identification\n\
    10,95,-20,0,30,0,1999.75,3522.9,12.6,980.0,identification\n\
    -5,80,10,0,45,90,3999.5,5480.3,-40.2,1100.4,validation\n";

#[test]
fn a_track_set_carries_each_readings_value() {
    let set = parse_set(TRACK).unwrap();
    assert_eq!(set.axes, vec![ExternalAxis::E1]);
    assert_eq!(set.poses.len(), 3);
    let e1: Vec<Option<f64>> = set
        .readings()
        .map(|r| r.external.get(ExternalAxis::E1))
        .collect();
    assert_eq!(e1, vec![Some(0.0), Some(1999.75), Some(3999.5)]);
    assert!(set
        .readings()
        .all(|r| r.external.get(ExternalAxis::E2).is_none()));
    assert_eq!(set.poses[1].xyz_mm, [3522.9, 12.6, 980.0]);
    assert_eq!(set.poses[2].q_deg[5], 90.0);
    // Written beside the joints, read back bit for bit.
    let text = write_set(&set);
    assert!(
        text.starts_with("q1,q2,q3,q4,q5,q6,e1,x,y,z,set\n"),
        "{text}"
    );
    assert_eq!(parse_set(&text).unwrap(), set);
}

#[test]
fn the_robot_only_reader_refuses_external_axes_naming_the_column() {
    let e = parse(TRACK).unwrap_err();
    assert_eq!(
        e,
        CsvError::ExternalNotComposed {
            line: 1,
            column: "e1".into()
        }
    );
    assert!(e.to_string().contains("column `e1`"), "{e}");
}

#[test]
fn a_set_without_external_axes_reads_and_writes_as_before() {
    let text = "q1,q2,q3,x,y,z,payload_kg\n1,2,3,100,200,300,5\n4,5,6,-100,0,7.5,\n";
    let set = parse_set(text).unwrap();
    assert!(set.axes.is_empty());
    assert!(set.external.iter().all(|e| e.is_empty()));
    assert_eq!(set.poses, parse(text).unwrap());
    assert_eq!(write_set(&set), write(&set.poses));
    assert_eq!(set, MeasurementSet::without_axes(set.poses.clone()));
}

#[test]
fn external_values_missing_not_finite_or_out_of_bounds_are_refused() {
    let missing = "q1,q2,e1,e2,x,y,z\n1,2,0,10,100,0,0\n1,2,500,,100,0,0\n";
    assert_eq!(
        parse_set(missing).unwrap_err(),
        CsvError::MissingExternal {
            line: 3,
            column: "e2".into()
        }
    );
    let infinite = "q1,q2,e1,e2,x,y,z\n1,2,0,1e400,100,0,0\n";
    assert!(matches!(
        parse_set(infinite).unwrap_err(),
        CsvError::NotFinite { line: 2, column, .. } if column == "e2"
    ));
    let text = "q1,q2,e3,x,y,z\n1,2,x,100,0,0\n";
    assert!(matches!(
        parse_set(text).unwrap_err(),
        CsvError::NotNumeric { line: 2, column, .. } if column == "e3"
    ));
    let far = "q1,q2,e1,x,y,z\n1,2,250000,100,0,0\n";
    assert!(matches!(
        parse_set(far).unwrap_err(),
        CsvError::OutOfRange { line: 2, column, .. } if column == "e1"
    ));
    for name in ["e7", "e0", "e01", "e"] {
        let text = format!("q1,q2,{name},x,y,z\n1,2,0,100,0,0\n");
        assert!(matches!(
            parse_set(&text).unwrap_err(),
            CsvError::UnknownColumn { column, .. } if column == name
        ));
    }
    let dup = "q1,q2,e1,E1,x,y,z\n1,2,0,0,100,0,0\n";
    assert!(matches!(
        parse_set(dup).unwrap_err(),
        CsvError::DuplicateColumn { .. }
    ));
    let metres = ReadOptions {
        metres: true,
        ..ReadOptions::default()
    };
    assert_eq!(
        parse_set_opts("q1,q2,e2,x,y,z\n1,2,0,1,0,0\n", &metres).unwrap_err(),
        CsvError::ExternalUnits {
            line: 1,
            column: "e2".into()
        }
    );
}

/// A positioner's readings carry no robot joints: allowed only beside
/// external-axis columns.
#[test]
fn readings_without_joints_need_external_axes() {
    let text = "e1,e2,x,y,z\n-30,90,2400.5,-1.25,900\n";
    let set = parse_set(text).unwrap();
    assert!(set.poses[0].q_deg.is_empty());
    assert_eq!(set.external[0].get(ExternalAxis::E2), Some(90.0));
    assert_eq!(parse_set(&write_set(&set)).unwrap(), set);
    assert_eq!(
        parse_set("x,y,z\n2400,0,900\n").unwrap_err(),
        CsvError::MissingColumn {
            line: 1,
            column: "q1".into()
        }
    );
}
