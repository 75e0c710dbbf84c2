//! `robocal filter` on the sample programs: filtered files and a JSON report
//! written, only target values changed, a parse error names file, line and column.

use clap::Parser;
use robocal::cli::filter::{filter_to_string, FilterArgs};
use robocal::cli::model_files::save_model_file;
use robocal::model::preset;
use robocal::program::{parse, Language, ProgramFile};
use robocal::sim::{synthetic_calibration, SyntheticErrors};
use robocal_core::model::calibrated::CalibratedModelFile;
use std::path::{Path, PathBuf};

fn examples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/programs")
}

fn args(argv: &[&str]) -> FilterArgs {
    let mut v = vec!["robocal", "filter"];
    v.extend_from_slice(argv);
    match robocal::cli::Cli::try_parse_from(v).unwrap().command {
        robocal::cli::Command::Filter(a) => a,
        other => panic!("{other:?}"),
    }
}

fn file(path: &Path) -> ProgramFile {
    ProgramFile {
        name: path.file_name().unwrap().to_str().unwrap().into(),
        text: std::fs::read_to_string(path).unwrap(),
    }
}

#[test]
fn filter_cli_writes_programs_and_a_report() {
    let dir = tempfile::tempdir().unwrap();
    let model = synthetic_calibration(
        &preset("ys100").unwrap(),
        &SyntheticErrors::typical(1e-6),
        3,
    );
    let model_path = dir.path().join("cal.json");
    save_model_file(
        &CalibratedModelFile::from_compensated(&model, "ys100", "km"),
        &model_path,
    )
    .unwrap();
    let out_dir = dir.path().join("out");
    let (src, dat) = (
        examples().join("krl/seam.src"),
        examples().join("krl/seam.dat"),
    );
    let cell = examples().join("cell.json");
    let report = filter_to_string(&args(&[
        "--model",
        model_path.to_str().unwrap(),
        "--cell",
        cell.to_str().unwrap(),
        "--out-dir",
        out_dir.to_str().unwrap(),
        src.to_str().unwrap(),
        dat.to_str().unwrap(),
    ]))
    .unwrap();
    let report: serde_json::Value = serde_json::from_str(&report).unwrap();
    assert_eq!(report["language"], "krl");
    assert_eq!(
        (report["filtered"].as_u64(), report["failed"].as_u64()),
        (Some(6), Some(0))
    );
    let t = &report["targets"][0];
    assert_eq!(
        (t["file"].as_str(), t["line"].as_u64()),
        (Some("seam.dat"), Some(6))
    );
    assert!(t["shift_mm"].as_f64().unwrap() > 0.1);
    // Same names; only the values of the targets differ.
    let before = [file(&src), file(&dat)];
    let after = [
        file(&out_dir.join("seam.src")),
        file(&out_dir.join("seam.dat")),
    ];
    let (a, b) = (
        parse(Language::Krl, &before).unwrap(),
        parse(Language::Krl, &after).unwrap(),
    );
    for (i, (x, y)) in before.iter().zip(&after).enumerate() {
        let mask = |f: &ProgramFile, sites: &[robocal::program::Site]| {
            let mut text = f.text.clone();
            let mut ranges: Vec<_> = sites
                .iter()
                .filter(|s| s.file == i)
                .flat_map(|s| s.slots.clone())
                .collect();
            ranges.sort_by_key(|r| std::cmp::Reverse(r.start));
            for r in ranges {
                text.replace_range(r, "#");
            }
            text
        };
        assert_ne!(x.text, y.text);
        assert_eq!(mask(x, &a.sites), mask(y, &b.sites));
    }
}

#[test]
fn filter_cli_reports_parse_errors_and_guesses_the_language() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.script");
    std::fs::write(&bad, "def f():\n  movel(p[1, 2, 3], a=1)\nend\n").unwrap();
    let out = dir.path().join("out");
    let err = filter_to_string(&args(&[
        "--model",
        "ur5",
        "--out-dir",
        out.to_str().unwrap(),
        bad.to_str().unwrap(),
    ]))
    .unwrap_err();
    assert_eq!(
        err.to_string(),
        "bad.script:2:10: a pose literal needs six numbers"
    );
    let mixed = dir.path().join("x.txt");
    std::fs::write(&mixed, "").unwrap();
    let err = filter_to_string(&args(&[
        "--model",
        "ur5",
        "--out-dir",
        out.to_str().unwrap(),
        mixed.to_str().unwrap(),
    ]))
    .unwrap_err();
    assert!(err.to_string().contains("--language"), "{err}");
    // --correct-axes without a track or a positioner has nothing to correct.
    let err = filter_to_string(&args(&[
        "--model",
        "ur5",
        "--correct-axes",
        "--out-dir",
        out.to_str().unwrap(),
        bad.to_str().unwrap(),
    ]))
    .unwrap_err();
    assert!(err.to_string().contains("--correct-axes"), "{err}");
}

/// `--positioner FILE --nominal-positioner FILE`: a KRL program whose base 3
/// sits on the positioner's face plate (cell file `frame: face_plate`), each
/// target at its own `E1`, `E2`; the report names the axes and each
/// target's values, and equals the core's filter through the same
/// positioners. The CLI refuses one of the pair alone; beside a track the
/// positioner's axes are E2 and E3, so these targets fail naming E3; without
/// the positioner every target fails naming its axis.
/// (How close the filtered targets bring a true tool to the true part is
/// the core's test, `core/tests/programs/positioner.rs`.)
#[test]
fn filter_cli_composes_a_positioner_with_its_values() {
    use nalgebra::Vector3;
    use robocal::model::external::{RotaryAxis, TiltRotate};
    use robocal::model::Pose;
    use robocal::program::{filter_with, kuka_status, kuka_turn, FilterAxes, FilterControl};
    use robocal::solve::ik::{AnalyticIk, IkSettings};
    let dir = tempfile::tempdir().unwrap();
    let nominal = preset("ys100").unwrap();
    let model = synthetic_calibration(&nominal, &SyntheticErrors::typical(1e-6), 4);
    let model_path = dir.path().join("cal.json");
    save_model_file(
        &CalibratedModelFile::from_compensated(&model, "ys100", "km"),
        &model_path,
    )
    .unwrap();
    // The controller's positioner 1.6 m in front of the robot; the cell's
    // with its rotate axis 0.3° round and its tilt axis 0.5 mm higher.
    let drawing = TiltRotate {
        cell_from_base: Pose::from_translation(Vector3::new(1.6, 0.0, -0.9)),
        tilt: RotaryAxis::new(Vector3::x(), Vector3::new(0.0, 0.0, 0.8), 0.0, 1.0),
        rotate: RotaryAxis::new(Vector3::z(), Vector3::zeros(), 0.0, 1.0),
        face_plate: Pose::from_translation(Vector3::new(0.0, 0.0, 1.1)),
    };
    let mut cell_positioner = drawing;
    cell_positioner.cell_from_base = model.cell_from_base.compose(&drawing.cell_from_base);
    cell_positioner.rotate =
        RotaryAxis::new(Vector3::z(), Vector3::zeros(), 0.3f64.to_radians(), 1.0);
    cell_positioner.tilt = RotaryAxis::new(Vector3::x(), Vector3::new(0.0, 0.0, 0.8005), 0.0, 1.0);
    let (positioner_path, drawing_path) =
        (dir.path().join("stn.json"), dir.path().join("drawing.json"));
    std::fs::write(&positioner_path, cell_positioner.to_json()).unwrap();
    std::fs::write(&drawing_path, drawing.to_json()).unwrap();
    let part = Pose::from_translation(Vector3::new(0.1, 0.05, 0.06));
    let cell_path = dir.path().join("cell.json");
    std::fs::write(
        &cell_path,
        r#"{"tools": [{"name": "torch", "number": 1, "xyz_mm": [125.0, 0.0, 216.50635], "rpy_deg": [0.0, 30.0, 0.0]}],
            "work_objects": [{"name": "part", "number": 3, "frame": "face_plate", "xyz_mm": [100.0, 50.0, 60.0], "rpy_deg": [0.0, 0.0, 0.0]}]}"#,
    )
    .unwrap();
    // Targets the controller reaches: where its nominal robot puts the
    // torch at joints `q`, in the part as it computes it at values `v`.
    let mut controller = nominal.clone();
    controller.tool = robocal::model::Tool {
        p: Vector3::new(0.125, 0.0, 0.21650635),
        rpy: [0.0, 30f64.to_radians(), 0.0],
    };
    let ik = AnalyticIk::new(&controller).unwrap();
    let (mut src, mut dat) = (
        String::from("DEF turn()\r\nBAS(#TOOL, 1)\r\nBAS(#BASE, 3)\r\n"),
        String::from("DEFDAT turn\r\n"),
    );
    let values = [[10.0, -30.0], [-20.0, 75.0], [35.0, 160.0], [0.0, 0.0]];
    for (i, v) in values.iter().enumerate() {
        let q = [0.1 * i as f64, 1.4, -0.2, 0.3, 0.8, -0.5];
        // The controller's model carries the torch as its tool.
        let tcp = robocal::model::kinematics::fk(&controller, &q).unwrap();
        let t = drawing
            .cell_from_face_plate(*v)
            .compose(&part)
            .inverse()
            .compose(&tcp);
        let abc = robocal::model::orientation::rotation_to(
            robocal::model::orientation::OrientationConvention::KukaAbc,
            &t.r,
        );
        let deg: Vec<f64> = controller
            .joints_to_controller(&q)
            .iter()
            .map(|x| x.to_degrees())
            .collect();
        let conf = ik.configuration(&q).unwrap();
        src.push_str(&format!("LIN XP{i}\r\n"));
        dat.push_str(&format!(
            "DECL E6POS XP{i}={{X {:.4},Y {:.4},Z {:.4},A {:.4},B {:.4},C {:.4},S {},T {},E1 {},E2 {},E3 0.0,E4 0.0,E5 0.0,E6 0.0}}\r\n",
            t.p.x * 1e3, t.p.y * 1e3, t.p.z * 1e3, abc[0], abc[1], abc[2],
            kuka_status(&deg, conf), kuka_turn(&deg), v[0], v[1]
        ));
    }
    src.push_str("END\r\n");
    dat.push_str("ENDDAT\r\n");
    let (src_path, dat_path) = (dir.path().join("turn.src"), dir.path().join("turn.dat"));
    std::fs::write(&src_path, &src).unwrap();
    std::fs::write(&dat_path, &dat).unwrap();
    let out_dir = dir.path().join("out");
    let p = |x: &PathBuf| x.to_str().unwrap().to_string();
    let base = [
        "--model".to_string(),
        p(&model_path),
        "--cell".into(),
        p(&cell_path),
        "--out-dir".into(),
        p(&out_dir),
        p(&src_path),
        p(&dat_path),
    ];
    let with = |extra: &[String]| {
        let mut v: Vec<String> = base.to_vec();
        v.extend_from_slice(extra);
        v
    };
    let axes = [
        "--positioner".to_string(),
        p(&positioner_path),
        "--nominal-positioner".into(),
        p(&drawing_path),
    ];
    let argv = with(&axes);
    let report =
        filter_to_string(&args(&argv.iter().map(String::as_str).collect::<Vec<_>>())).unwrap();
    let report: serde_json::Value = serde_json::from_str(&report).unwrap();
    assert_eq!(report["positioner_axes"], serde_json::json!(["E1", "E2"]));
    assert_eq!(
        (report["filtered"].as_u64(), report["failed"].as_u64()),
        (Some(4), Some(0)),
        "{report:#}"
    );
    for (t, v) in report["targets"].as_array().unwrap().iter().zip(&values) {
        assert_eq!(t["positioner_deg"], serde_json::json!(v));
        // 0.3° about axis 2 and 0.5 mm: millimetres at the part.
        assert!(t["shift_mm"].as_f64().unwrap() > 0.1, "{t}");
    }
    // The core's filter through the same positioners gives the same report.
    let files = [file(&src_path), file(&dat_path)];
    // The cell as the command line reads it (mm and degrees converted once).
    let cell = robocal::cli::model_files::load_cell(Some(&p(&cell_path))).unwrap();
    let read = |x: &PathBuf| TiltRotate::from_json(&std::fs::read_to_string(x).unwrap()).unwrap();
    let pair = (read(&positioner_path), read(&drawing_path));
    let loaded = robocal::cli::model_files::load_compensated(&p(&model_path)).unwrap();
    let core = filter_with(
        Language::Krl,
        &files,
        &cell,
        &loaded,
        &IkSettings::default(),
        &FilterAxes::of_cell(None, Some(&pair)),
        &FilterControl::default(),
    )
    .unwrap();
    assert_eq!(serde_json::to_value(&core.report).unwrap(), report);
    // Beside a track: the track is E1 and the positioner E2, E3. A track
    // that is where the controller believes it (nominal = calibrated, the
    // base at the cell frame's origin at 0) adds nothing: the program with
    // E1 0 and the values moved to E2, E3, and the positioner stated in
    // that frame (the robot's base frame), gives the fixed base's joints
    // and shifts.
    let rail = robocal::model::external::LinearTrack::nominal(
        Vector3::x(),
        Vector3::zeros(),
        0.0,
        nalgebra::Matrix3::identity(),
        robocal::model::external::Travel {
            lo_mm: -100.0,
            hi_mm: 2000.0,
        },
    );
    let mut in_base = cell_positioner;
    in_base.cell_from_base = drawing.cell_from_base;
    let (rail_path, in_base_path) = (dir.path().join("rail.json"), dir.path().join("stn0.json"));
    std::fs::write(&rail_path, rail.to_json()).unwrap();
    std::fs::write(&in_base_path, in_base.to_json()).unwrap();
    let mut moved = String::from("DEFDAT turn\r\n");
    for line in dat.lines().filter(|l| l.starts_with("DECL")) {
        let (head, tail) = line.split_at(line.find(",E1 ").unwrap());
        let v: Vec<&str> = tail.split(',').collect();
        // ",E1 a,E2 b,E3 0.0,…" → ",E1 0.0,E2 a,E3 b,…"
        let (a, b) = (&v[1][3..], &v[2][3..]);
        moved.push_str(&format!(
            "{head},E1 0.0,E2 {a},E3 {b},E4 0.0,E5 0.0,E6 0.0}}\r\n"
        ));
    }
    moved.push_str("ENDDAT\r\n");
    let moved_dir = dir.path().join("on_track");
    std::fs::create_dir_all(&moved_dir).unwrap();
    let (src2, dat2) = (moved_dir.join("turn.src"), moved_dir.join("turn.dat"));
    std::fs::write(&src2, &src).unwrap();
    std::fs::write(&dat2, &moved).unwrap();
    let both = [
        "--model".to_string(),
        p(&model_path),
        "--cell".into(),
        p(&cell_path),
        "--out-dir".into(),
        p(&moved_dir.join("out")),
        p(&src2),
        p(&dat2),
        "--positioner".into(),
        p(&in_base_path),
        "--nominal-positioner".into(),
        p(&drawing_path),
        "--track".into(),
        p(&rail_path),
        "--nominal-track".into(),
        p(&rail_path),
    ];
    let on_track =
        filter_to_string(&args(&both.iter().map(String::as_str).collect::<Vec<_>>())).unwrap();
    let on_track: serde_json::Value = serde_json::from_str(&on_track).unwrap();
    assert_eq!(on_track["positioner_axes"], serde_json::json!(["E2", "E3"]));
    assert_eq!(on_track["track_axis"], "E1");
    assert_eq!(on_track["filtered"].as_u64(), Some(4), "{on_track:#}");
    for (t, fixed) in on_track["targets"]
        .as_array()
        .unwrap()
        .iter()
        .zip(report["targets"].as_array().unwrap())
    {
        assert_eq!(t["track_mm"], 0.0);
        assert_eq!(t["positioner_deg"], fixed["positioner_deg"]);
        let shift = |x: &serde_json::Value| x["shift_mm"].as_f64().unwrap();
        assert!((shift(t) - shift(fixed)).abs() < 1e-9, "{t} {fixed}");
        let joints = |x: &serde_json::Value| -> Vec<f64> {
            serde_json::from_value(x["joints_deg"].clone()).unwrap()
        };
        for (a, b) in joints(t).iter().zip(joints(fixed)) {
            assert!((a - b).abs() < 1e-9, "{t} {fixed}");
        }
    }
    let alone = with(&axes[..2]);
    let mut v = vec!["robocal", "filter"];
    v.extend(alone.iter().map(String::as_str));
    assert!(robocal::cli::Cli::try_parse_from(v).is_err());
    // Without the positioner every target fails naming its axis.
    let report =
        filter_to_string(&args(&base.iter().map(String::as_str).collect::<Vec<_>>())).unwrap();
    let report: serde_json::Value = serde_json::from_str(&report).unwrap();
    assert_eq!(report["failed"].as_u64(), Some(4));
    assert!(report["targets"][0]["reason"]
        .as_str()
        .unwrap()
        .contains("external axis E1"));
    assert!(report["targets"][3]["reason"]
        .as_str()
        .unwrap()
        .contains("work object part is on the positioner's face plate"));
}

/// `robocal filter --turntable --nominal-turntable`: a part on a one-axis
/// turntable's face plate (base 3), each target at its own `E1`; the report
/// names the one axis and each target's values `[0, v]`, and equals the
/// core's filter through the same turntables (as positioners whose axis 1
/// stands at 0, `FilterAxes::turntable`). A target that also moves `E2`
/// fails naming it; `--correct-axes` writes each value corrected. (How
/// close the filtered targets bring a true tool to the true part is the
/// core's test, `core/tests/programs/turntable.rs`.)
#[test]
fn filter_cli_composes_a_turntable_with_its_value() {
    use nalgebra::Vector3;
    use robocal::model::external::{RotaryAxis, Turntable};
    use robocal::model::Pose;
    use robocal::program::{filter_with, kuka_status, kuka_turn, FilterAxes, FilterControl};
    use robocal::solve::ik::{AnalyticIk, IkSettings};
    let dir = tempfile::tempdir().unwrap();
    let nominal = preset("ys100").unwrap();
    let model = synthetic_calibration(&nominal, &SyntheticErrors::typical(1e-6), 4);
    let model_path = dir.path().join("cal.json");
    save_model_file(
        &CalibratedModelFile::from_compensated(&model, "ys100", "km"),
        &model_path,
    )
    .unwrap();
    // The controller's turntable 1.6 m in front of the robot; the cell's
    // turned 0.3° further and its axis 0.5 mm off.
    let drawing = Turntable {
        cell_from_base: Pose::from_translation(Vector3::new(1.6, 0.0, -0.9)),
        axis: RotaryAxis::new(Vector3::z(), Vector3::zeros(), 0.0, 1.0),
        face_plate: Pose::from_translation(Vector3::new(0.0, 0.0, 1.1)),
    };
    let mut cell_turntable = drawing;
    cell_turntable.cell_from_base = model.cell_from_base.compose(&drawing.cell_from_base);
    cell_turntable.axis = RotaryAxis::new(
        Vector3::z(),
        Vector3::new(0.0005, 0.0, 0.0),
        0.3f64.to_radians(),
        1.0,
    );
    let p = |x: &Path| x.to_str().unwrap().to_string();
    let (turntable_path, drawing_path) =
        (dir.path().join("tt.json"), dir.path().join("drawing.json"));
    std::fs::write(&turntable_path, cell_turntable.to_json()).unwrap();
    std::fs::write(&drawing_path, drawing.to_json()).unwrap();
    let part = Pose::from_translation(Vector3::new(0.1, 0.05, 0.06));
    let cell_path = dir.path().join("cell.json");
    std::fs::write(
        &cell_path,
        r#"{"tools": [{"name": "torch", "number": 1, "xyz_mm": [125.0, 0.0, 216.50635], "rpy_deg": [0.0, 30.0, 0.0]}],
            "work_objects": [{"name": "part", "number": 3, "frame": "face_plate", "xyz_mm": [100.0, 50.0, 60.0], "rpy_deg": [0.0, 0.0, 0.0]}]}"#,
    )
    .unwrap();
    let mut controller = nominal.clone();
    controller.tool = robocal::model::Tool {
        p: Vector3::new(0.125, 0.0, 0.21650635),
        rpy: [0.0, 30f64.to_radians(), 0.0],
    };
    let ik = AnalyticIk::new(&controller).unwrap();
    let values = [-30.0, 75.0, 160.0, 0.0];
    // The program with `E2` at `second` beside each target's `E1`.
    let program = |second: f64| {
        let (mut src, mut dat) = (
            String::from("DEF turn()\r\nBAS(#TOOL, 1)\r\nBAS(#BASE, 3)\r\n"),
            String::from("DEFDAT turn\r\n"),
        );
        for (i, v) in values.iter().enumerate() {
            let q = [0.1 * i as f64, 1.4, -0.2, 0.3, 0.8, -0.5];
            let tcp = robocal::model::kinematics::fk(&controller, &q).unwrap();
            let t = drawing
                .cell_from_face_plate(*v)
                .compose(&part)
                .inverse()
                .compose(&tcp);
            let abc = robocal::model::orientation::rotation_to(
                robocal::model::orientation::OrientationConvention::KukaAbc,
                &t.r,
            );
            let deg: Vec<f64> = controller
                .joints_to_controller(&q)
                .iter()
                .map(|x| x.to_degrees())
                .collect();
            let conf = ik.configuration(&q).unwrap();
            src.push_str(&format!("LIN XP{i}\r\n"));
            dat.push_str(&format!(
                "DECL E6POS XP{i}={{X {:.4},Y {:.4},Z {:.4},A {:.4},B {:.4},C {:.4},S {},T {},E1 {v},E2 {second},E3 0.0,E4 0.0,E5 0.0,E6 0.0}}\r\n",
                t.p.x * 1e3, t.p.y * 1e3, t.p.z * 1e3, abc[0], abc[1], abc[2],
                kuka_status(&deg, conf), kuka_turn(&deg)
            ));
        }
        src.push_str("END\r\n");
        dat.push_str("ENDDAT\r\n");
        let (src_path, dat_path) = (dir.path().join("turn.src"), dir.path().join("turn.dat"));
        std::fs::write(&src_path, &src).unwrap();
        std::fs::write(&dat_path, &dat).unwrap();
        (src_path, dat_path)
    };
    let run = |second: f64, extra: &[&str]| {
        let (src, dat) = program(second);
        let (m, c, o) = (p(&model_path), p(&cell_path), p(&dir.path().join("out")));
        let (t, n) = (p(&turntable_path), p(&drawing_path));
        let mut argv = vec![
            "--model",
            &m,
            "--cell",
            &c,
            "--out-dir",
            &o,
            "--turntable",
            &t,
            "--nominal-turntable",
            &n,
        ];
        argv.extend_from_slice(extra);
        let (s, d) = (p(&src), p(&dat));
        argv.extend([s.as_str(), d.as_str()]);
        let mut v = vec!["robocal", "filter"];
        v.extend_from_slice(&argv);
        robocal::cli::Cli::try_parse_from(v).map(|cli| match cli.command {
            robocal::cli::Command::Filter(a) => filter_to_string(&a).unwrap(),
            other => panic!("{other:?}"),
        })
    };
    let report: serde_json::Value = serde_json::from_str(&run(0.0, &[]).unwrap()).unwrap();
    assert_eq!(report["positioner_axes"], serde_json::json!(["E1"]));
    assert_eq!(
        (report["filtered"].as_u64(), report["failed"].as_u64()),
        (Some(4), Some(0)),
        "{report:#}"
    );
    for (t, v) in report["targets"].as_array().unwrap().iter().zip(&values) {
        assert_eq!(t["positioner_deg"], serde_json::json!([0.0, v]));
        // 0.3° about the axis and 0.5 mm: millimetres at the part.
        assert!(t["shift_mm"].as_f64().unwrap() > 0.1, "{t}");
    }
    // The core's filter through the same turntables gives the same report.
    let (src, dat) = program(0.0);
    let files = [file(&src), file(&dat)];
    let cell = robocal::cli::model_files::load_cell(Some(&p(&cell_path))).unwrap();
    let read = |x: &Path| {
        Turntable::from_json(&std::fs::read_to_string(x).unwrap())
            .unwrap()
            .as_tilt_rotate()
    };
    let pair = (read(&turntable_path), read(&drawing_path));
    let loaded = robocal::cli::model_files::load_compensated(&p(&model_path)).unwrap();
    let core = filter_with(
        Language::Krl,
        &files,
        &cell,
        &loaded,
        &IkSettings::default(),
        &FilterAxes::of_cell(None, Some(&pair)).turntable(),
        &FilterControl::default(),
    )
    .unwrap();
    assert_eq!(serde_json::to_value(&core.report).unwrap(), report);
    // `E2` in use: an axis the turntable does not have.
    let report: serde_json::Value = serde_json::from_str(&run(12.5, &[]).unwrap()).unwrap();
    assert_eq!(report["failed"].as_u64(), Some(4), "{report:#}");
    let why = report["targets"][0]["reason"].as_str().unwrap();
    assert!(
        why.contains("E2") && why.contains("does not model"),
        "{why}"
    );
    // Corrected on request: the cell's turntable stands 0.3° further round
    // on the drawing's line (the frames coincide), so each value is written
    // 0.3° less.
    let report: serde_json::Value =
        serde_json::from_str(&run(0.0, &["--correct-axes"]).unwrap()).unwrap();
    assert_eq!(report["axis_values"], "corrected");
    assert_eq!(report["filtered"].as_u64(), Some(4), "{report:#}");
    for (t, v) in report["targets"].as_array().unwrap().iter().zip(&values) {
        let written = t["positioner_written_deg"][1].as_f64().unwrap();
        assert!((written - (v - 0.3)).abs() < 1e-3, "{t}");
    }
}
