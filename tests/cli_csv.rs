//! What the command line writes as CSV parses as what it claims: every
//! numeric cell of `robocal predict --format csv` is a number (a negative one
//! too, not the text `'-20`) equal to the JSON answer's, and an id a
//! spreadsheet would run is text that robocal's readers read back as sent.

use clap::Parser;
use robocal::cli::predict::predict_to_string;
use robocal::measure::csv_text::{read, Dialect};
use robocal_core::csv_write::read_text;
use serde_json::Value;

fn predict(args: &[&str]) -> String {
    let mut argv = vec!["robocal", "predict"];
    argv.extend_from_slice(args);
    match robocal::cli::Cli::parse_from(argv).command {
        robocal::cli::Command::Predict(p) => predict_to_string(&p).unwrap(),
        _ => unreachable!(),
    }
}

#[test]
fn predict_csv_cells_are_numbers_and_ids_read_back_as_sent() {
    let dir = tempfile::tempdir().unwrap();
    let joints = dir.path().join("joints.csv");
    let ids = ["=cmd|' /C calc'!A0", "-2", "+SUM(1;2)", "p,4"];
    std::fs::write(
        &joints,
        "id,q1,q2,q3,q4,q5,q6\n\
         '=cmd|' /C calc'!A0,10,-80,95,0,45,0\n\
         -2,-30,-60,80,-100,-50,-170\n\
         '+SUM(1;2),170,-20,10,20,-30,40\n\
         \"p,4\",-5,-90,100,5,60,-5\n",
    )
    .unwrap();
    let path = joints.to_str().unwrap();
    let csv = predict(&[
        "--model",
        "ys100",
        "--joints",
        path,
        "--format",
        "csv",
        "--convention",
        "kuka_abc",
    ]);
    let json: Value = serde_json::from_str(&predict(&[
        "--model",
        "ys100",
        "--joints",
        path,
        "--json",
        "--convention",
        "kuka_abc",
    ]))
    .unwrap();
    let t = read(&csv, Dialect::default()).unwrap().unwrap();
    assert_eq!(t.records.len(), ids.len(), "{csv}");
    let col = |name: &str| t.header.iter().position(|h| h == name).unwrap();
    let mut negative = 0;
    for (k, (r, id)) in t.records.iter().zip(ids).enumerate() {
        assert_eq!(t.check_shape(r), Ok(()), "{csv}");
        assert_eq!(read_text(&r.fields[col("id")]), id);
        let want = &json["results"][k];
        let mut cells: Vec<(String, f64)> = (1..=6)
            .map(|j| {
                (
                    format!("j{j}_deg"),
                    want["joints_deg"][j - 1].as_f64().unwrap(),
                )
            })
            .collect();
        for (c, key) in [
            ("x_mm", "x"),
            ("y_mm", "y"),
            ("z_mm", "z"),
            ("rx_deg", "rx"),
            ("ry_deg", "ry"),
            ("rz_deg", "rz"),
        ] {
            cells.push((c.to_string(), want[key].as_f64().unwrap()));
        }
        for (i, name) in ["a", "b", "c"].iter().enumerate() {
            let v = want["orientation"]["values"][i].as_f64().unwrap();
            cells.push((name.to_string(), v));
        }
        for (name, v) in cells {
            let cell = &r.fields[col(&name)];
            let got = t
                .number(cell)
                .unwrap_or_else(|| panic!("{name} `{cell}` is not a number: {csv}"));
            assert!((got - v).abs() < 1e-5, "{name}: {got} vs {v}");
            negative += usize::from(cell.starts_with('-'));
        }
    }
    assert!(negative > 10, "negative numbers written as numbers: {csv}");
}

/// The readers the command line takes files through refuse a row of another
/// width than its header, naming line and column, rather than read it
/// shifted: the TCP fit's readings here (the others in their own tests).
#[test]
fn tcp_readings_of_another_width_are_refused() {
    let e = robocal::cell_fit::tcp::readings::parse_csv(
        "q1,q2,q3,q4,q5,q6\n10,-80,95,0,45,0\n10,-80,95,0,45,0,7\n",
    )
    .unwrap_err();
    assert!(
        e.to_string().contains(
            "line 3: 7 fields, the header has 6: field 7 `7` is beyond the last column `q6`"
        ),
        "{e}"
    );
}
