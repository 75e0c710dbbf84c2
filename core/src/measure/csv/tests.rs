use super::*;
use crate::measure::SetRole;

fn row(q: &[f64], xyz: [f64; 3]) -> MeasuredPose {
    MeasuredPose::position_only(q.to_vec(), xyz)
}

#[test]
fn round_trip_is_exact() {
    let mut rows = vec![
        row(
            &[
                0.1,
                -45.123456789012345,
                1e-17,
                179.99999999999997,
                -0.0,
                3e-300,
            ],
            [1523.2000000000003, -1.0 / 3.0, 980.0],
        ),
        row(
            &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0],
            [std::f64::consts::PI * 100.0, 2.5e-9, -1e3],
        ),
        row(&[-719.0, 0.5, 0.25, 0.125, 7.0, 8.0], [10.0, 20.0, 30.0]),
    ];
    rows[0].rpy_deg = Some([0.1, 89.99999999999999, -179.5]);
    rows[0].payload_kg = Some(110.0);
    rows[1].temperature_c = Some(21.123456789);
    rows[0].set = Some(SetRole::Identification);
    rows[2].set = Some(SetRole::Validation);
    let text = write(&rows);
    assert!(text.starts_with("q1,q2,q3,q4,q5,q6,x,y,z,rx,ry,rz,payload_kg,temperature_c,set\n"));
    let back = parse(&text).unwrap();
    assert_eq!(back, rows);
    for (a, b) in back.iter().zip(&rows) {
        for (x, y) in a.q_deg.iter().zip(&b.q_deg) {
            assert_eq!(x.to_bits(), y.to_bits());
        }
    }
    // Minimal layout: no optional columns.
    let plain = vec![row(&[1.0, 2.0], [100.0, 0.0, 0.0])];
    let text = write(&plain);
    assert_eq!(text, "q1,q2,x,y,z\n1,2,100,0,0\n");
    assert_eq!(parse(&text).unwrap(), plain);
}

#[test]
fn orientation_columns_may_say_degrees() {
    let plain = parse("q1,q2,x,y,z,rx,ry,rz\n1,2,100,0,0,10,20,30\n").unwrap();
    let named = parse("q1,q2,x,y,z,rx_deg,ry_deg,rz_deg\n1,2,100,0,0,10,20,30\n").unwrap();
    assert_eq!(plain, named);
    assert_eq!(named[0].rpy_deg, Some([10.0, 20.0, 30.0]));
    assert!(parse("q1,q2,x,y,z,rx,ry_deg,rx_deg\n1,2,100,0,0,10,20,30\n").is_err());
}

#[test]
fn comments_blank_lines_case_and_order() {
    let text = "\u{feff}# exported by a tracker\n\n  # another comment\n\
                SET, Z ,y,X,Q2,q1,Payload_KG\r\n\
                # comment between rows\n\
                q2, 3.5, 2, 1, 20, 10, 5\r\n\
                \n\
                Training,6,5,4,40,30,\n";
    let rows = parse(text).unwrap();
    assert_eq!(rows.len(), 2);
    assert_eq!(rows[0].q_deg, vec![10.0, 20.0]);
    assert_eq!(rows[0].xyz_mm, [1.0, 2.0, 3.5]);
    assert_eq!(rows[0].set, Some(SetRole::Training));
    assert_eq!(rows[0].payload_kg, Some(5.0));
    assert_eq!(rows[1].q_deg, vec![30.0, 40.0]);
    assert_eq!(rows[1].xyz_mm, [4.0, 5.0, 6.0]);
    assert_eq!(rows[1].payload_kg, None);
    assert_eq!(rows[1].set, Some(SetRole::Training));
}

#[test]
fn real_data_layout_and_dif_sign() {
    let text = "step_order,x_t,y_t,z_t,x_dif,y_dif,z_dif,joint_1,joint_2,joint_3\n\
                0,100,200,300,1,-2,0.5,10,20,30\n";
    let plus = parse(text).unwrap();
    assert_eq!(plus[0].xyz_mm, [101.0, 198.0, 300.5]);
    assert_eq!(plus[0].q_deg, vec![10.0, 20.0, 30.0]);
    let minus = parse_with(text, DifSign::Minus).unwrap();
    assert_eq!(minus[0].xyz_mm, [99.0, 202.0, 299.5]);
}

fn err(text: &str) -> CsvError {
    parse(text).unwrap_err()
}

#[test]
fn errors_name_line_and_column() {
    assert_eq!(err(""), CsvError::Empty);
    assert_eq!(err("# only a comment\n\n"), CsvError::Empty);
    assert_eq!(
        err("# c\nq1,q2,x,y,z\n# nothing\n"),
        CsvError::NoDataRows { header_line: 2 }
    );
    assert_eq!(
        err("q1,q2,x,y\n1,2,100,0\n"),
        CsvError::MissingColumn {
            line: 1,
            column: "z".into()
        }
    );
    assert_eq!(
        err("q1,q3,x,y,z\n1,2,100,0,0\n"),
        CsvError::MissingColumn {
            line: 1,
            column: "q2".into()
        }
    );
    assert_eq!(
        err("x,y,z\n100,0,0\n"),
        CsvError::MissingColumn {
            line: 1,
            column: "q1".into()
        }
    );
    assert!(matches!(
        err("q1,x,y,z\n1,100,0,0\n"),
        CsvError::JointColumns { line: 1, .. }
    ));
    assert!(matches!(
        err("q1,q2,q3,q4,q5,q6,q7,q8,x,y,z\n1,2,3,4,5,6,7,8,100,0,0\n"),
        CsvError::JointColumns { line: 1, .. }
    ));
    let e = err("q1,q2,x,y,z,speed\n1,2,100,0,0,3\n");
    assert!(
        matches!(&e, CsvError::UnknownColumn { line: 1, column, .. } if column == "speed"),
        "{e}"
    );
    assert!(e.to_string().contains("payload_kg"), "{e}");
    assert!(matches!(
        err("q1,q2,x,y,z,X\n1,2,100,0,0,1\n"),
        CsvError::DuplicateColumn { line: 1, .. }
    ));
    let e = err("q1,q2,joint_1,x,y,z\n1,2,1,100,0,0\n");
    assert!(
        matches!(e, CsvError::DuplicateColumn { line: 1, .. }),
        "{e}"
    );
    assert!(e.to_string().contains("joint_1"), "{e}");
    assert!(matches!(
        err("q1,q2,x,y,z,x_t\n1,2,100,0,0,1\n"),
        CsvError::ConflictingColumns { line: 1, .. }
    ));
    assert_eq!(
        err("q1,q2,x_t,y_t,z_t,x_dif,y_dif\n1,2,100,0,0,1,1\n"),
        CsvError::MissingColumn {
            line: 1,
            column: "z_dif".into()
        }
    );
    assert_eq!(
        err("q1,q2,x,y,z,rx,ry\n1,2,100,0,0,1,1\n"),
        CsvError::MissingColumn {
            line: 1,
            column: "rz".into()
        }
    );
}

#[test]
fn row_errors_name_line_and_column() {
    assert_eq!(
        err("q1,q2,x,y,z\n1,2,100,0,0\n\n1,2,100,0\n"),
        CsvError::FieldCount(csv_text::FieldCount {
            line: 4,
            expected: 5,
            got: 4,
            misfit: csv_text::Misfit::Missing {
                index: 5,
                column: "z".into()
            }
        })
    );
    assert_eq!(
        err("q1,q2,x,y,z\n1,2,100,0,0\n1,abc,100,0,0\n"),
        CsvError::NotNumeric {
            line: 3,
            column: "q2".into(),
            value: "abc".into()
        }
    );
    assert_eq!(
        err("q1,q2,x,y,z\n1,2,,0,0\n"),
        CsvError::NotNumeric {
            line: 2,
            column: "x".into(),
            value: "".into()
        }
    );
    for bad in ["NaN", "inf", "-infinity"] {
        assert_eq!(
            err(&format!("q1,q2,x,y,z\n1,2,100,{bad},0\n")),
            CsvError::NotFinite {
                line: 2,
                column: "y".into(),
                value: bad.into()
            }
        );
    }
    assert_eq!(
        err("q1,q2,x,y,z,set\n1,2,100,0,0,calibration\n"),
        CsvError::UnknownSet {
            line: 2,
            value: "calibration".into()
        }
    );
    assert_eq!(
        err("q1,q2,x,y,z,rx,ry,rz\n1,2,100,0,0,1,,3\n"),
        CsvError::PartialOrientation { line: 2 }
    );
    assert_eq!(
        err("q1,q2,x,y,z\n1,2,100,0,0\n1,36000,100,0,0\n"),
        CsvError::JointUnits {
            line: 3,
            column: "q2".into(),
            value: 36000.0
        }
    );
    assert_eq!(
        err("q1,q2,x,y,z\n1,2,1.2,0.3,0.9\n3,4,-1.1,2.5,0.2\n"),
        CsvError::PositionUnits
    );
    // One millimetre-sized row is enough to pass the metres check.
    assert!(parse("q1,q2,x,y,z\n1,2,1.2,0.3,0.9\n3,4,-1.1,250,0.2\n").is_ok());
}

#[test]
fn joint_count_check() {
    let rows = vec![
        row(&[1.0; 6], [100.0, 0.0, 0.0]),
        row(&[1.0; 7], [100.0, 0.0, 0.0]),
    ];
    assert_eq!(check_joint_count(&rows[..1], 6), Ok(()));
    assert_eq!(
        check_joint_count(&rows, 6),
        Err(CsvError::JointCount {
            row: 2,
            expected: 6,
            got: 7
        })
    );
}

/// The real UR5/WAM laser-tracker files (data/ur5-wam-laser-tracker in the repository, or
/// `ROBOCAL_DATA_DIR`).
#[test]
fn real_ur5_wam_files_parse() {
    let dir = std::env::var("ROBOCAL_DATA_DIR")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|_| {
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/ur5-wam-laser-tracker")
        });
    assert!(
        dir.exists(),
        "real data not found at {} (set ROBOCAL_DATA_DIR)",
        dir.display()
    );
    for (file, n, dof) in [
        ("UR5/3D_UR5_uncalibrated_grid_cleaned.csv", 1000, 6),
        ("UR5/3D_UR5_uncalibrated_random_cleaned.csv", 20, 6),
        ("WAM/3D_WAM_uncalibrated_grid_cleaned.csv", 216, 7),
        ("WAM/3D_WAM_uncalibrated_random_cleaned.csv", 20, 7),
    ] {
        let text = std::fs::read_to_string(dir.join(file)).unwrap();
        let rows = parse(&text).unwrap_or_else(|e| panic!("{file}: {e}"));
        assert_eq!(rows.len(), n, "{file}");
        check_joint_count(&rows, dof).unwrap();
        let minus = parse_with(&text, DifSign::Minus).unwrap();
        // The two readings differ by exactly 2·dif.
        let d = (rows[0].xyz_mm[2] - minus[0].xyz_mm[2]).abs();
        assert!(d > 0.0, "{file}");
        assert!(rows.iter().all(|r| r.set.is_none() && r.rpy_deg.is_none()));
        // Round trip through the canonical layout.
        assert_eq!(parse(&write(&rows)).unwrap(), rows, "{file}");
    }
    // First UR5 grid row: measured = x_t + x_dif.
    let text =
        std::fs::read_to_string(dir.join("UR5/3D_UR5_uncalibrated_grid_cleaned.csv")).unwrap();
    let r = &parse(&text).unwrap()[0];
    assert_eq!(r.xyz_mm[0], -430.32784075885013 + -2.144122241149887);
    assert_eq!(r.q_deg[0], -22.933297010882566);
}

mod bounds_tests {
    use super::*;

    fn err(text: &str) -> String {
        parse(text).unwrap_err().to_string()
    }

    /// Positions beyond ±100 m, payloads outside 0..10,000 kg and absurd joint
    /// values are rejected with a short message naming line and column.
    #[test]
    fn out_of_range_values_give_short_messages() {
        let head = "q1,q2,q3,q4,q5,q6,x,y,z,payload_kg\n";
        let ok = "0,0,0,0,0,0,1000,200,300,5\n";
        let e = err(&format!("{head}{ok}0,0,0,0,0,0,1e300,200,300,5\n"));
        assert!(
            e.starts_with(
                "line 3, column `x`: 1.000e300 mm is outside [-100000, 100000] mm (positions are in millimetres)"
            ),
            "{e}"
        );
        assert!(e.len() < 120, "{e}");
        let e = err(&format!("{head}{ok}0,0,0,0,0,0,1000,-100001,300,5\n"));
        assert!(e.contains("line 3, column `y`"), "{e}");
        for bad in ["-1", "10000.5", "1e308"] {
            let e = err(&format!("{head}0,0,0,0,0,0,1000,200,300,{bad}\n"));
            assert!(
                e.starts_with("line 2, column `payload_kg`") && e.contains("[0, 10000] kg"),
                "{e}"
            );
            assert!(e.len() < 120, "{e}");
        }
        assert!(parse(&format!("{head}0,0,0,0,0,0,1000,200,300,10000\n")).is_ok());
        let e = err(&format!("{head}1e300,0,0,0,0,0,1000,200,300,5\n"));
        assert!(
            e.contains("column `q1`: 1.000e300 deg") && e.len() < 160,
            "{e}"
        );
        let long = "9".repeat(400) + "x";
        let e = err(&format!("{head}0,0,0,0,0,0,{long},200,300,5\n"));
        assert!(e.len() < 160, "{e}");
        // The real-data layout names the target column.
        let e = err("x_t,y_t,z_t,x_dif,y_dif,z_dif,joint_1,joint_2\n2e5,0,0,0,0,0,0,0\n");
        assert!(e.contains("column `x_t`"), "{e}");
    }

    #[test]
    fn metres_radians_semicolons_and_decimal_commas_read_like_the_canonical_file() {
        let canonical = parse("q1,q2,x,y,z,rx,ry,rz\n90,-45,1250,-500,2000,0,0,180\n").unwrap();
        let opts = ReadOptions {
            metres: true,
            radians: true,
            ..ReadOptions::default()
        };
        let text = format!(
            "# tracker export\nq1;q2;x;y;z;rx;ry;rz\n{};{};1,25;-0,5;2;0;0;{}\n",
            std::f64::consts::FRAC_PI_2.to_string().replace('.', ","),
            (-std::f64::consts::FRAC_PI_4).to_string().replace('.', ","),
            std::f64::consts::PI.to_string().replace('.', ",")
        );
        let rows = parse_opts(&text, &opts).unwrap();
        assert_eq!(rows.len(), 1);
        for (a, b) in rows[0].q_deg.iter().zip(&canonical[0].q_deg) {
            assert!((a - b).abs() < 1e-12, "{a} vs {b}");
        }
        assert_eq!(rows[0].xyz_mm, canonical[0].xyz_mm);
        let r = rows[0].rpy_deg.unwrap();
        assert!((r[2] - 180.0).abs() < 1e-12);
        // A decimal comma in a comma-separated file is a field count error,
        // never a silently different number.
        assert!(matches!(
            parse("q1,q2,x,y,z\n1,5,2,3,4,5\n"),
            Err(CsvError::FieldCount(_))
        ));
    }

    /// Standard deviations, temperatures and angles are bounded as stored,
    /// after the unit conversion: a σ of 1e306 m (1e309 mm, infinite) is
    /// refused naming line, column, value and bound, as is one that a
    /// declared unit takes beyond the bound; at the bounds the rows read
    /// and write back exactly.
    #[test]
    fn every_numeric_column_is_bounded_as_stored() {
        let metres = ReadOptions {
            metres: true,
            ..ReadOptions::default()
        };
        let head = "q1,q2,x,y,z,std_x,std_y,std_z\n";
        let e = parse_opts(&format!("{head}1,2,1.5,0,0,1e306,0.001,0.001\n"), &metres)
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "line 2, column `std_x`: inf mm is outside [1e-5, 1000] mm"
        );
        // 2 m is 2000 mm: beyond a metre although 2 is a small number.
        let e = parse_opts(&format!("{head}1,2,1.5,0,0,0.001,2,0.001\n"), &metres).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("line 2, column `std_y`: 2000 mm is outside"),
            "{e}"
        );
        let e = parse(&format!("{head}1,2,150,0,0,1e-6,1,1\n")).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("line 2, column `std_x`: 1.000e-6 mm"),
            "{e}"
        );
        let e =
            parse("q1,q2,x,y,z,temperature_c\n1,2,150,0,0,21\n1,2,150,0,0,1e300\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "line 3, column `temperature_c`: 1.000e300 °C is outside [-100, 200] °C"
        );
        let e = parse("q1,q2,x,y,z,rx,ry,rz\n1,2,150,0,0,0,400,0\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "line 2, column `ry`: 400 deg is outside [-360, 360] deg"
        );
        let std_deg = "q1,q2,x,y,z,rx,ry,rz,std_x,std_y,std_z,std_rx,std_ry,std_rz\n\
                       1,2,150,0,0,0,0,0,1,1,1,1,1,4\n";
        let radians = ReadOptions {
            radians: true,
            ..ReadOptions::default()
        };
        let e = parse_opts(std_deg, &radians).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("line 2, column `std_rz`: 229.183118 deg"),
            "{e}"
        );
        // At every bound: accepted, and written back exactly.
        let edge = "q1,q2,x,y,z,rx,ry,rz,std_x,std_y,std_z,std_rx,std_ry,std_rz,payload_kg,temperature_c\n\
                    720,-720,100000,-100000,5,360,-360,0,1e-5,1000,1,1e-6,180,1,10000,-100\n\
                    0,0,100,0,0,0,0,0,1,1,1,1,1,1,0,200\n";
        let rows = parse(edge).unwrap();
        assert_eq!(rows[0].std_mm, Some([1e-5, 1000.0, 1.0]));
        assert_eq!(rows[1].temperature_c, Some(200.0));
        assert_eq!(parse(&write(&rows)).unwrap(), rows);
        for r in &rows {
            assert_eq!(r.check_bounds(), Ok(()));
        }
    }

    #[test]
    fn dif_sign_minus_subtracts_the_deviation() {
        let text = "joint_1,joint_2,x_t,y_t,z_t,x_dif,y_dif,z_dif\n1,2,100,200,300,0.5,-0.25,1\n";
        let plus = parse_with(text, DifSign::Plus).unwrap();
        let minus = parse_with(text, DifSign::Minus).unwrap();
        assert_eq!(plus[0].xyz_mm, [100.5, 199.75, 301.0]);
        assert_eq!(minus[0].xyz_mm, [99.5, 200.25, 299.0]);
    }
}
