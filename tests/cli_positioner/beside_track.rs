//! `solve` and `predict` with `--track` beside `--positioner`: `e1` the
//! track's value, `e2`, `e3` the positioner's tilt and rotate, as the
//! programs number them. A straight track along the cell's x whose
//! carriage puts the robot's base at the cell frame's origin at 500 mm (as
//! the robot file's base is) adds nothing there: the targets at `e1` 500
//! with the positioner's values moved to `e2`, `e3` give the fixed base's
//! joints, and the poses predicted at them the fixed base's poses; at
//! `e1` 0 the base stands 0.5 m back and the joints differ.

use super::*;
use common::json_numbers as numbers;
use robocal::model::external::{LinearTrack, Travel};

/// The track's value at which the base stands at the cell frame's origin [mm].
const AT_ORIGIN_MM: f64 = 500.0;

fn rail() -> LinearTrack {
    LinearTrack::nominal(
        Vector3::x(),
        Vector3::zeros(),
        -0.5,
        nalgebra::Matrix3::identity(),
        Travel {
            lo_mm: -100.0,
            hi_mm: 2000.0,
        },
    )
}

fn run_json(d: &Path, args: &[&str]) -> serde_json::Value {
    let out = robocal(d, args);
    assert_eq!(code(&out), 0, "{args:?}: {}", text(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn beside_a_track_at_its_origin_solve_and_predict_give_the_fixed_bases() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fitted_near(d);
    std::fs::write(d.join("rail.json"), rail().to_json()).unwrap();

    let points = [[400.0, 150.0, 60.0], [-250.0, 280.0, 40.0]];
    let values = [[-30.0, 40.0], [15.0, -120.0], [35.0, 160.0]];
    let (mut fixed, mut beside, mut flag) = (
        vec!["id,x,y,z,e1,e2".to_string()],
        vec!["id,x,y,z,e1,e2,e3".to_string()],
        vec!["id,x,y,z,e2,e3".to_string()],
    );
    for (i, p) in points.iter().enumerate() {
        for (k, v) in values.iter().enumerate() {
            let at = format!("p{i}v{k},{},{},{}", p[0], p[1], p[2]);
            fixed.push(format!("{at},{},{}", v[0], v[1]));
            beside.push(format!("{at},{AT_ORIGIN_MM},{},{}", v[0], v[1]));
            flag.push(format!("{at},{},{}", v[0], v[1]));
        }
    }
    for (name, rows) in [
        ("fixed.csv", &fixed),
        ("beside.csv", &beside),
        ("flag.csv", &flag),
    ] {
        std::fs::write(d.join(name), rows.join("\n") + "\n").unwrap();
    }
    let solve = |file: &str, extra: &[&str]| {
        let mut args = vec!["solve", "--model", "robot.json", "--targets", file];
        args.extend_from_slice(extra);
        args.extend_from_slice(&["--positioner", "p.json", "--position-only", "--json"]);
        run_json(d, &args)
    };
    let on_fixed = solve("fixed.csv", &[]);
    let on_rail = solve("beside.csv", &["--track", "rail.json"]);
    let at_flag = solve("flag.csv", &["--track", "rail.json", "--e1", "500"]);
    let back = solve("flag.csv", &["--track", "rail.json", "--e1", "0"]);
    assert_eq!(
        on_rail["frame"],
        "face plate of positioner p.json at each row's e2 (tilt), e3 (rotate) (track rail.json at each row's e1)"
    );
    assert_eq!(
        at_flag["frame"],
        "face plate of positioner p.json at each row's e2 (tilt), e3 (rotate) (track rail.json at e1 = 500 mm)"
    );
    let n = points.len() * values.len();
    let mut worst = 0.0f64;
    for k in 0..n {
        let a = numbers(&on_fixed["targets"][k]["joints_deg"]);
        assert_eq!(on_fixed["targets"][k]["status"], "ok");
        for doc in [&on_rail, &at_flag] {
            for (x, y) in a.iter().zip(numbers(&doc["targets"][k]["joints_deg"])) {
                worst = worst.max((x - y).abs());
            }
        }
    }
    let moved = numbers(&on_fixed["targets"][0]["joints_deg"])
        .iter()
        .zip(numbers(&back["targets"][0]["joints_deg"]))
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    println!("solve beside a track with the base at the origin at 500 mm: {n} targets, joints of the fixed base within {worst:.1e} deg; at 0 mm the first target's joints {moved:.2} deg apart");
    assert!(worst < 1e-9, "{worst}");
    assert!(moved > 1.0, "{moved}");

    // Predicted at the fixed base's joints of one pair of values: the same
    // poses on the face plate.
    let mut joints = vec!["id,q1,q2,q3,q4,q5,q6".to_string()];
    for (k, r) in on_fixed["targets"].as_array().unwrap().iter().enumerate() {
        let q: Vec<String> = numbers(&r["joints_deg"])
            .iter()
            .map(|x| format!("{x:.10}"))
            .collect();
        joints.push(format!("r{k},{}", q.join(",")));
    }
    std::fs::write(d.join("joints.csv"), joints.join("\n") + "\n").unwrap();
    let predict = |extra: &[&str]| {
        let mut args = vec![
            "predict",
            "--model",
            "robot.json",
            "--joints",
            "joints.csv",
            "--json",
        ];
        args.extend_from_slice(extra);
        run_json(d, &args)
    };
    let v = values[1].map(|x| x.to_string());
    let on_fixed = predict(&["--positioner", "p.json", "--e1", &v[0], "--e2", &v[1]]);
    let on_rail = predict(&[
        "--track",
        "rail.json",
        "--e1",
        "500",
        "--positioner",
        "p.json",
        "--e2",
        &v[0],
        "--e3",
        &v[1],
    ]);
    for k in 0..n {
        for c in ["x", "y", "z", "rx", "ry", "rz"] {
            let (a, b) = (
                on_fixed["results"][k][c].as_f64().unwrap(),
                on_rail["results"][k][c].as_f64().unwrap(),
            );
            assert!(
                (a - b).abs() < 1e-9,
                "row {k} {c}: fixed {a}, on the rail {b}"
            );
        }
    }

    // Beside the track, a file without its `e3` column is refused, naming it.
    let out = robocal(
        d,
        &[
            "solve",
            "--model",
            "robot.json",
            "--targets",
            "fixed.csv",
            "--track",
            "rail.json",
            "--positioner",
            "p.json",
            "--position-only",
        ],
    );
    assert_refused(&out, "an `e3` column");
}
