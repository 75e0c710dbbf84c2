//! `robocal iso9283 plan`, `robocal iso9283` and `robocal check` in process:
//! the cube's joint CSV and a program cycling it, figures from a cycles CSV
//! against hand-computed values, and a check of a shifted frame.

use clap::Parser;
use robocal::cli::check::check_file;
use robocal::cli::iso9283::{figures, join_files, make, FiguresArgs, Iso9283Args, Iso9283Command};
use robocal::measure::{csv, MeasuredPose};
use robocal::model::preset;
use robocal::program::{parse, Language, ProgramFile};
use robocal_core::check::iso9283::csv::read_plan_csv;
use robocal_core::model::calibrated::CompensatedModel;
use std::fmt::Write as _;

#[path = "common/html_table.rs"]
mod html_table;
use html_table::{cell, table_rows};

fn iso_args(argv: &[&str]) -> Iso9283Args {
    let mut v = vec!["robocal", "iso9283"];
    v.extend_from_slice(argv);
    match robocal::cli::Cli::try_parse_from(v).unwrap().command {
        robocal::cli::Command::Iso9283(a) => a,
        other => panic!("{other:?}"),
    }
}

fn cube(argv: &[&str]) -> String {
    match iso_args(argv).command {
        Some(Iso9283Command::Plan(c)) => make(&c).unwrap(),
        _ => panic!("not a plan"),
    }
}

fn figures_of(argv: &[&str]) -> FiguresArgs {
    let a = iso_args(argv);
    assert!(a.command.is_none());
    a.figures
}

#[test]
fn the_cube_plan_cycles_in_a_program_and_the_figures_match_hand_values() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let common = [
        "plan",
        "--model",
        "ur10",
        "--box",
        "300,-400,100,900,400,700",
        "--commands",
        "nominal",
    ];
    let summary = cube(&[&common[..], &["--out", &p("plan.csv")]].concat());
    assert!(summary.contains("edge 600.0 mm"), "{summary}");
    let plan = read_plan_csv(&std::fs::read_to_string(p("plan.csv")).unwrap()).unwrap();
    assert_eq!(plan.len(), 5);
    // P1 is the box's centre; P2 10 % of the diagonal from C1 (300, -300, 100).
    assert_eq!(plan[0].xyz_mm, [600.0, 0.0, 400.0]);
    assert_eq!(plan[1].xyz_mm, [360.0, -240.0, 160.0]);
    assert_eq!(plan[0].abc_deg, Some([180.0, 0.0, 0.0]));

    // A KRL program of 3 cycles visits the five poses' joints in order, 3 times.
    cube(
        &[
            &common[..],
            &["--format", "krl", "--cycles", "3", "--out", &p("iso.src")],
        ]
        .concat(),
    );
    let text = std::fs::read_to_string(p("iso.src")).unwrap();
    let program = parse(
        Language::Krl,
        &[ProgramFile {
            name: "iso.src".into(),
            text,
        }],
    )
    .unwrap();
    assert_eq!(program.joints.len(), 15);
    // The Fanuc program, with a comment line per motion, parses back the same.
    cube(
        &[
            &common[..],
            &["--format", "fanuc", "--cycles", "3", "--out", &p("ISO.LS")],
        ]
        .concat(),
    );
    let fanuc = std::fs::read_to_string(p("ISO.LS")).unwrap();
    assert!(fanuc.contains("  ! P5 cycle 3 ;"), "{fanuc}");
    let fanuc = parse(
        Language::Fanuc,
        &[ProgramFile {
            name: "ISO.LS".into(),
            text: fanuc,
        }],
    )
    .unwrap();
    assert_eq!(fanuc.joints.len(), 15);
    for (a, b) in fanuc.joints.iter().zip(&program.joints) {
        for (x, y) in a.deg.iter().zip(&b.deg) {
            assert!((x - y).abs() < 1e-9, "{x} vs {y}");
        }
    }
    let plan_text = std::fs::read_to_string(p("plan.csv")).unwrap();
    let joints: Vec<Vec<f64>> = plan_text
        .lines()
        .skip(1)
        .map(|l| l.split(',').skip(7).map(|v| v.parse().unwrap()).collect())
        .collect();
    for (i, j) in program.joints.iter().enumerate() {
        for (a, b) in j.deg.iter().zip(&joints[i % 5]) {
            assert!((a - b).abs() < 1e-4, "move {i}: {a} vs {b}");
        }
    }

    // Cycles: each pose reached at c + (-1, -1, 0) + (0 | 2 | 4, 0, 0):
    // barycentre c + (1, -1, 0), AP = √2; l = 2, 0, 2, RP = 4/3 + 3·√(4/3);
    // the distances between poses differ from the commanded ones.
    let mut cycles = String::from("pose,cycle,x_mm,y_mm,z_mm\n");
    for c in &plan {
        for (k, dx) in [0.0, 2.0, 4.0].iter().enumerate() {
            let _ = writeln!(
                cycles,
                "{},{},{},{},{}",
                c.name,
                k + 1,
                c.xyz_mm[0] - 1.0 + dx,
                c.xyz_mm[1] - 1.0,
                c.xyz_mm[2]
            );
        }
    }
    std::fs::write(p("cycles.csv"), cycles).unwrap();
    let args = figures_of(&[
        "--plan",
        &p("plan.csv"),
        "--measured",
        &p("cycles.csv"),
        "--json",
    ]);
    let out: serde_json::Value = serde_json::from_str(&figures(&args).unwrap()).unwrap();
    let poses = out[0]["figures"]["poses"].as_array().unwrap();
    assert_eq!(poses.len(), 5);
    for f in poses {
        let ap = f["ap_mm"].as_f64().unwrap();
        let rp = f["rp_mm"].as_f64().unwrap();
        assert!((ap - 2f64.sqrt()).abs() < 1e-9, "{f}");
        assert!(
            (rp - (4.0 / 3.0 + 3.0 * (4.0f64 / 3.0).sqrt())).abs() < 1e-9,
            "{f}"
        );
    }
    // Every pose moved the same way in each cycle: the distances are exact.
    for d in out[0]["figures"]["distances"].as_array().unwrap() {
        assert!(d["ad_mm"].as_f64().unwrap().abs() < 1e-9, "{d}");
        assert!(d["rd_mm"].as_f64().unwrap().abs() < 1e-9, "{d}");
    }
    let table = figures(&figures_of(&[
        "--plan",
        &p("plan.csv"),
        "--measured",
        &p("cycles.csv"),
        "--report",
        &p("iso.html"),
    ]))
    .unwrap();
    assert!(table.contains("P5"), "{table}");
    // The HTML report: a row per pose and characteristic with the hand
    // values of AP and RP (four decimals, as the table prints them) and rows
    // per pair of poses.
    let html = std::fs::read_to_string(p("iso.html")).unwrap();
    let rows = table_rows(&html, "iso9283-figures");
    let (ap, rp) = (
        format!("{:.4}", 2f64.sqrt()),
        format!("{:.4}", 4.0 / 3.0 + 3.0 * (4.0f64 / 3.0).sqrt()),
    );
    assert_eq!((ap.as_str(), rp.as_str()), ("1.4142", "4.7974"));
    assert_eq!(
        rows[0],
        ["pose", "characteristic", "unit", p("cycles.csv").as_str()]
    );
    for k in 1..=5 {
        let pose = format!("P{k}");
        assert_eq!(cell(&rows, &pose, "n"), ["3"]);
        assert_eq!(cell(&rows, &pose, "AP"), [ap.as_str()]);
        assert_eq!(cell(&rows, &pose, "RP"), [rp.as_str()]);
        assert_eq!(cell(&rows, &pose, "APa"), ["— (no_orientation_measured)"]);
    }
    assert_eq!(cell(&rows, "P4–P5", "n"), ["3"]);
    // D_c is the commanded distance of P1 and P2.
    let dc: f64 = cell(&rows, "P1–P2", "D_c")[0].parse().unwrap();
    let d: f64 = (0..3)
        .map(|k| (plan[0].xyz_mm[k] - plan[1].xyz_mm[k]).powi(2))
        .sum::<f64>()
        .sqrt();
    assert!((dc - d).abs() < 1e-4, "{dc} vs {d}");
    // A plan without its cycles file is refused.
    assert!(figures(&figures_of(&["--plan", &p("plan.csv")])).is_err());
}

#[test]
fn check_names_a_moved_tracker_and_a_changed_robot() {
    let dir = tempfile::tempdir().unwrap();
    let model = CompensatedModel::from_nominal(preset("ur10").unwrap());
    let nominal = preset("ur10").unwrap();
    let qs: Vec<Vec<f64>> = (0..12)
        .map(|i| {
            let t = i as f64;
            vec![
                0.3 * t - 1.5,
                -1.2 + 0.07 * t,
                1.1 - 0.05 * t,
                -1.4,
                1.5 + 0.04 * t,
                0.1 * t,
            ]
        })
        .collect();
    let rows = |shift: &dyn Fn(usize, [f64; 3]) -> [f64; 3]| -> Vec<MeasuredPose> {
        qs.iter()
            .enumerate()
            .map(|(i, q)| {
                let p = model.predict(q).unwrap().p * 1e3;
                MeasuredPose {
                    q_deg: nominal
                        .joints_to_controller(q)
                        .into_iter()
                        .map(f64::to_degrees)
                        .collect(),
                    xyz_mm: shift(i, [p.x, p.y, p.z]),
                    rpy_deg: None,
                    std_mm: None,
                    std_deg: None,
                    payload_kg: None,
                    temperature_c: None,
                    set: None,
                    session: None,
                }
            })
            .collect()
    };
    let run_with_model = |name: &str, model: &str| {
        let path = dir.path().join(name);
        let args = match robocal::cli::Cli::try_parse_from([
            "robocal",
            "check",
            "--model",
            model,
            "--measurements",
            path.to_str().unwrap(),
        ])
        .unwrap()
        .command
        {
            robocal::cli::Command::Check(a) => a,
            other => panic!("{other:?}"),
        };
        check_file(&args).unwrap()
    };
    let run = |name: &str, rows: Vec<MeasuredPose>| {
        std::fs::write(dir.path().join(name), csv::write(&rows)).unwrap();
        run_with_model(name, "ur10")
    };
    // The model's own positions (CSV rounding only): ok.
    let same = run("same.csv", rows(&|_, p| p));
    assert_eq!(same.status.name(), "ok");
    assert!(same.position.max_mm < 1e-3, "{:?}", same.position);
    // The tracker moved 4 mm: every point shifted alike; named a frame shift.
    let moved = run("moved.csv", rows(&|_, p| [p[0] + 4.0, p[1], p[2] - 1.0]));
    assert!(moved.position.mean_mm > 4.0);
    assert!(
        moved.frame_shift.as_ref().unwrap().explains,
        "{}",
        moved.summary
    );
    assert_eq!(moved.status.name(), "shifted");
    // Errors that differ from pose to pose (±3 mm): not a frame shift.
    let changed = run(
        "changed.csv",
        rows(&|i, p| [p[0] + if i % 2 == 0 { 3.0 } else { -3.0 }, p[1], p[2]]),
    );
    assert_eq!(changed.status.name(), "recalibrate", "{}", changed.summary);
    assert!(!changed.frame_shift.as_ref().unwrap().explains);

    // `compare`: the same poses against the UR10 they come from and a UR5:
    // the UR10 as `check` scored it, the UR5 centimetres off.
    let path = dir.path().join("same.csv");
    let args = match robocal::cli::Cli::try_parse_from([
        "robocal",
        "compare",
        "--model",
        "ur10",
        "--model",
        "ur5",
        "--measurements",
        path.to_str().unwrap(),
    ])
    .unwrap()
    .command
    {
        robocal::cli::Command::Compare(a) => a,
        other => panic!("{other:?}"),
    };
    let scores = robocal::cli::check::compare_files(&args).unwrap();
    assert_eq!(scores.len(), 2);
    assert_eq!(scores[0].model, "ur10");
    assert_eq!(scores[0].result.position, same.position);
    assert!(
        scores[1].result.position.mean_mm > 10.0,
        "{:?}",
        scores[1].result.position
    );
    let table = robocal::cli::check::compare_text(&scores);
    assert_eq!(table.lines().count(), 3, "{table}");
    assert!(
        table
            .lines()
            .nth(2)
            .unwrap()
            .starts_with("ur5 | recalibrate"),
        "{table}"
    );
    // One model is not a comparison.
    let one = robocal::cli::Cli::try_parse_from([
        "robocal",
        "compare",
        "--model",
        "ur10",
        "--measurements",
        path.to_str().unwrap(),
    ])
    .unwrap();
    let robocal::cli::Command::Compare(a) = one.command else {
        panic!()
    };
    let e = robocal::cli::check::compare_files(&a).unwrap_err();
    assert!(e.to_string().contains("at least two"), "{e}");

    // `reregister`: the tracker moved 4 mm; the refitted model scores the
    // moved poses to rounding, and the file it saves loads back as a model.
    let moved = dir.path().join("moved.csv");
    let saved = dir.path().join("moved-model.json");
    let argv = [
        "robocal",
        "reregister",
        "--model",
        "ur10",
        "--measurements",
        moved.to_str().unwrap(),
        "--save",
        saved.to_str().unwrap(),
    ];
    let robocal::cli::Command::Reregister(a) =
        robocal::cli::Cli::try_parse_from(argv).unwrap().command
    else {
        panic!("not reregister")
    };
    let report = robocal::cli::reregister::reregister_file(&a).unwrap();
    assert!(report.before.mean_mm > 4.0, "{:?}", report.before);
    assert!(report.after.max_mm < 1e-3, "{:?}", report.after);
    assert!(
        report.frame_translation_mm > 4.0 && report.tool_shift_mm < 1e-3,
        "{report:?}"
    );
    let text = robocal::cli::reregister::report_text(&report);
    assert!(
        text.contains("refitted measurement frame, tool position"),
        "{text}"
    );
    let rescored = run_with_model("moved.csv", saved.to_str().unwrap());
    assert!(rescored.position.max_mm < 1e-3, "{:?}", rescored.position);
}

/// The attained positions of a run: each pose reached at its command plus
/// `s`·((−1, −1, 0) + (0 | 2 | 4, 0, 0)) in cycles 1, 2, 3, so that
/// AP = s·√2 and RP = s·(4/3 + 3·√(4/3)) at every pose.
fn run_positions(
    plan: &[robocal_core::check::iso9283::csv::Commanded],
    s: f64,
) -> Vec<(String, u32, [f64; 3])> {
    let mut out = Vec::new();
    for k in 0..3u32 {
        for c in plan {
            let dx = 2.0 * f64::from(k);
            out.push((
                c.name.clone(),
                k + 1,
                [c.xyz_mm[0] + s * (dx - 1.0), c.xyz_mm[1] - s, c.xyz_mm[2]],
            ));
        }
    }
    out
}

#[test]
fn a_before_after_report_is_one_table_under_its_conditions_and_the_tracker_export_joins() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let common = [
        "plan",
        "--model",
        "ur10",
        "--box",
        "300,-400,100,900,400,700",
        "--commands",
        "nominal",
    ];
    cube(&[&common[..], &["--out", &p("plan.csv")]].concat());
    let plan = read_plan_csv(&std::fs::read_to_string(p("plan.csv")).unwrap()).unwrap();

    // The cycle program labels each motion by pose and cycle, in order.
    cube(
        &[
            &common[..],
            &["--format", "rapid", "--cycles", "3", "--out", &p("iso.mod")],
        ]
        .concat(),
    );
    let text = std::fs::read_to_string(p("iso.mod")).unwrap();
    let labels: Vec<&str> = text
        .lines()
        .filter(|l| l.contains("MoveAbsJ"))
        .map(|l| l.rsplit("! ").next().unwrap())
        .collect();
    let want: Vec<String> = (1..=3)
        .flat_map(|k| (1..=5).map(move |i| format!("P{i} cycle {k}")))
        .collect();
    assert_eq!(labels, want);

    // The tracker's export by name, in metres, in reverse order: joined, it
    // is the run's positions in millimetres, cycle by cycle.
    let run = run_positions(&plan, 1.0);
    let mut export = String::from("Point,X [m],Y [m],Z [m]\n");
    for (pose, k, x) in run.iter().rev() {
        let _ = writeln!(
            export,
            "{pose} cycle {k},{},{},{}",
            x[0] / 1e3,
            x[1] / 1e3,
            x[2] / 1e3
        );
    }
    std::fs::write(p("export.csv"), &export).unwrap();
    let join = |export: &str, out: &str| {
        let a = iso_args(&[
            "join",
            "--plan",
            &p("plan.csv"),
            "--tracker-export",
            &p(export),
            "--out",
            &p(out),
        ]);
        match a.command {
            Some(Iso9283Command::Join(j)) => join_files(&j),
            _ => panic!("not a join"),
        }
    };
    let summary = join("export.csv", "before.csv").unwrap();
    assert!(
        summary.starts_with("15 positions of 5 poses over 3 cycles joined by name (read in m)"),
        "{summary}"
    );
    let joined = std::fs::read_to_string(p("before.csv")).unwrap();
    let lines: Vec<&str> = joined.lines().collect();
    assert_eq!(lines[0], "pose,cycle,x_mm,y_mm,z_mm");
    assert_eq!(lines.len(), 16);
    for (line, (pose, k, x)) in lines[1..].iter().zip(&run) {
        let f: Vec<&str> = line.split(',').collect();
        assert_eq!(
            (f[0], f[1]),
            (pose.as_str(), k.to_string().as_str()),
            "{line}"
        );
        for (got, want) in f[2..].iter().zip(x) {
            assert!(
                (got.parse::<f64>().unwrap() - want).abs() < 1e-6,
                "{line} vs {x:?}"
            );
        }
    }
    // Without names, in the program's order: the same cycles CSV.
    let mut ordered = String::from("x,y,z\n");
    for (_, _, x) in &run {
        let _ = writeln!(ordered, "{},{},{}", x[0], x[1], x[2]);
    }
    std::fs::write(p("ordered.csv"), ordered).unwrap();
    join("ordered.csv", "ordered_cycles.csv").unwrap();
    assert_eq!(
        std::fs::read_to_string(p("ordered_cycles.csv")).unwrap(),
        joined
    );
    // A point the export lacks is listed; a name that is no pose and cycle,
    // or a pose the plan lacks, is refused naming it.
    let lacking: String = export
        .lines()
        .filter(|l| !l.starts_with("P4 cycle 2,"))
        .map(|l| format!("{l}\n"))
        .collect();
    std::fs::write(p("lacking.csv"), lacking).unwrap();
    let summary = join("lacking.csv", "lacking_cycles.csv").unwrap();
    assert!(
        summary.contains("not in the export (1): P4 cycle 2"),
        "{summary}"
    );
    std::fs::write(
        p("bad.csv"),
        "point,x,y,z\nP1 cycle 1,600,0,400\nP9 cycle 1,1,2,3\n",
    )
    .unwrap();
    let e = format!("{:#}", join("bad.csv", "x.csv").unwrap_err());
    assert!(
        e.contains("`P9 cycle 1`") && e.contains("no pose P9"),
        "{e}"
    );

    // The filtered run: a tenth of the errors.
    let mut after = String::from("pose,cycle,x_mm,y_mm,z_mm\n");
    for (pose, k, x) in run_positions(&plan, 0.1) {
        let _ = writeln!(after, "{pose},{k},{},{},{}", x[0], x[1], x[2]);
    }
    std::fs::write(p("after.csv"), after).unwrap();
    // The model file's SHA-256: the FIPS 180 example of "abc".
    std::fs::write(p("model.json"), "abc").unwrap();
    let args = figures_of(&[
        "--plan",
        &p("plan.csv"),
        "--measured",
        &p("before.csv"),
        "--plan",
        &p("plan.csv"),
        "--measured",
        &p("after.csv"),
        "--report",
        &p("report.html"),
        "--robot",
        "YS100 #4711",
        "--model",
        &p("model.json"),
        "--model-version",
        "3",
        "--date",
        "2026-11-02",
        "--load-kg",
        "12.5",
        "--speed-percent",
        "100",
        "--measurement",
        "AT960, 1.5 in. SMR",
    ]);
    assert!(robocal::cli::iso9283::unstated(&args).is_empty());
    figures(&args).unwrap();
    let html = std::fs::read_to_string(p("report.html")).unwrap();
    let conditions: Vec<(String, String)> = table_rows(&html, "iso9283-conditions")
        .into_iter()
        .map(|r| (r[0].clone(), r[1].clone()))
        .collect();
    let stated = |name: &str| -> Vec<&str> {
        conditions
            .iter()
            .filter(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
            .collect()
    };
    assert_eq!(stated("Robot"), ["YS100 #4711"]);
    assert_eq!(stated("Model version"), ["3"]);
    assert_eq!(
        stated("Model SHA-256"),
        ["ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"]
    );
    assert_eq!(stated("Test date"), ["2026-11-02"]);
    assert_eq!(stated("Load"), ["12.5 kg"]);
    assert_eq!(stated("Speed"), ["100 % of rated"]);
    assert_eq!(stated("Measurement"), ["AT960, 1.5 in. SMR"]);
    assert_eq!(
        stated("Cycles"),
        [format!("{}: 3; {}: 3", p("before.csv"), p("after.csv"))]
    );
    let sets = stated("Measurement set");
    assert_eq!(sets.len(), 2);
    assert!(sets[0].starts_with(&p("before.csv")), "{sets:?}");
    // One table of figures, the two runs side by side and the change.
    assert_eq!(html.matches("<table").count(), 2, "conditions and figures");
    let rows = table_rows(&html, "iso9283-figures");
    assert_eq!(
        rows[0],
        [
            "pose",
            "characteristic",
            "unit",
            p("before.csv").as_str(),
            p("after.csv").as_str(),
            "change"
        ]
    );
    let rp = 4.0 / 3.0 + 3.0 * (4.0f64 / 3.0).sqrt();
    for k in 1..=5 {
        let pose = format!("P{k}");
        assert_eq!(
            cell(&rows, &pose, "AP"),
            [
                format!("{:.4}", 2f64.sqrt()),
                format!("{:.4}", 0.1 * 2f64.sqrt()),
                format!("{:+.4}", -0.9 * 2f64.sqrt())
            ]
        );
        assert_eq!(
            cell(&rows, &pose, "RP"),
            [
                format!("{rp:.4}"),
                format!("{:.4}", 0.1 * rp),
                format!("{:+.4}", -0.9 * rp)
            ]
        );
        assert_eq!(cell(&rows, &pose, "n"), ["3", "3", "+0"]);
    }
    // A date that is not one is refused.
    let mut bad = figures_of(&["--plan", &p("plan.csv"), "--measured", &p("after.csv")]);
    bad.report = Some(dir.path().join("r.html"));
    bad.date = Some("2026-02-30".into());
    assert!(figures(&bad).is_err());
}
