//! `robocal plan` and `robocal plan join`: the joint CSV and a program of the
//! same poses, the σ table, and a simulated tracker export joined back into a
//! measurement CSV that calibrates back to the simulated robot.

use clap::Parser;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal::calibrate::identify::{calibrate, CalibrationOptions, Method};
use robocal::cli::plan::{join_files, make, JoinArgs, MakeArgs, PlanCommand};
use robocal::measure::{csv, to_measurements};
use robocal::model::preset;
use robocal::plan::read_plan_csv;
use robocal::program::{parse, Language, ProgramFile};
use robocal::sim::{perturb_geometry, tracker_frame, ErrorMagnitudes, TrueRobot};
use std::fmt::Write as _;

fn parsed(argv: &[&str]) -> robocal::cli::plan::PlanArgs {
    let mut v = vec!["robocal", "plan"];
    v.extend_from_slice(argv);
    match robocal::cli::Cli::try_parse_from(v).unwrap().command {
        robocal::cli::Command::Plan(a) => a,
        other => panic!("{other:?}"),
    }
}

fn make_args(argv: &[&str]) -> MakeArgs {
    let a = parsed(argv);
    assert!(a.command.is_none());
    a.make
}

fn join_args(argv: &[&str]) -> JoinArgs {
    match parsed(argv).command {
        Some(PlanCommand::Join(j)) => j,
        other => panic!("{other:?}"),
    }
}

#[test]
fn plan_cli_writes_csv_and_programs_and_joins_an_export() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let common = [
        "--model",
        "ur5",
        "--poses",
        "40",
        "--candidates",
        "400",
        "--box",
        "-900,-900,-100,900,900,1000",
        "--tracker",
        "2500,0,500",
        "--max-angle-deg",
        "70",
        "--noise-mm",
        "0.02",
        "--seed",
        "4",
    ];
    let mut csv_argv = common.to_vec();
    let plan_path = p("plan.csv");
    csv_argv.extend(["--out", &plan_path]);
    let table = make(&make_args(&csv_argv)).unwrap();
    assert!(
        table.contains("km:") && table.contains("tool_z") && table.contains("mm"),
        "{table}"
    );
    assert!(table.contains("400 candidates drawn"), "{table}");
    let plan = read_plan_csv(&std::fs::read_to_string(&plan_path).unwrap()).unwrap();
    assert_eq!(plan.len(), 40);

    // The same seed as a RAPID module: the same joints.
    let mut rapid_argv = common.to_vec();
    let mod_path = p("plan.mod");
    let csv2 = p("plan2.csv");
    rapid_argv.extend(["--format", "rapid", "--out", &mod_path, "--csv", &csv2]);
    make(&make_args(&rapid_argv)).unwrap();
    assert_eq!(
        std::fs::read_to_string(&csv2).unwrap(),
        std::fs::read_to_string(&plan_path).unwrap()
    );
    let module = ProgramFile {
        name: "plan.mod".into(),
        text: std::fs::read_to_string(&mod_path).unwrap(),
    };
    let program = parse(Language::Rapid, &[module]).unwrap();
    assert_eq!(program.joints.len(), 40);
    for (j, pt) in program.joints.iter().zip(&plan) {
        for (a, b) in j.deg.iter().zip(&pt.q_deg) {
            assert!((a - b).abs() < 1e-4);
        }
    }

    // A simulated tracker export (names, metres, reversed) joined back.
    let nominal = preset("ur5").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let mut truth = TrueRobot::new(perturb_geometry(
        &nominal,
        &ErrorMagnitudes::from_mm_deg(0.5, 0.05),
        &mut rng,
    ));
    truth.tracker_from_base = tracker_frame(0.0, 0.0, 25.0, [2500.0, 0.0, 500.0]);
    truth.noise_mm = 0.02;
    let q: Vec<Vec<f64>> = plan
        .iter()
        .map(|pt| {
            let c: Vec<f64> = pt.q_deg.iter().map(|d| d.to_radians()).collect();
            nominal.joints_from_controller(&c)
        })
        .collect();
    let rows = truth.measure(&q, None, None, &mut rng).unwrap();
    let mut export = String::from("Name,X_m,Y_m,Z_m\n");
    for (pt, r) in plan.iter().zip(&rows).rev() {
        let x = r.xyz_mm.map(|v| v / 1e3);
        let _ = writeln!(export, "{},{},{},{}", pt.name, x[0], x[1], x[2]);
    }
    let export_path = p("export.csv");
    std::fs::write(&export_path, &export).unwrap();
    let out = p("measurements.csv");
    let summary = join_files(&join_args(&[
        "join",
        "--plan",
        &plan_path,
        "--tracker-export",
        &export_path,
        "--out",
        &out,
    ]))
    .unwrap();
    assert!(
        summary.contains("40 measurements joined by name (positions read in m)"),
        "{summary}"
    );
    let joined = csv::parse(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let data = to_measurements(&nominal, &joined, nominal.payload.mass);
    let opts = CalibrationOptions {
        methods: vec![Method::Km],
        ..Default::default()
    };
    let report = calibrate(&nominal, &data, &[], &opts, &|_| true).unwrap();
    let km = &report.methods[&Method::Km];
    // Noise of 0.02 mm per axis: an RMS of about √3·0.02 mm less the fitted share.
    assert!(
        km.identification.stats.rms_mm < 0.05,
        "{}",
        km.identification.stats.rms_mm
    );

    // An export missing a point, in order: a clear error.
    let short: String = export.lines().take(40).map(|l| format!("{l}\n")).collect();
    std::fs::write(&export_path, short).unwrap();
    let e = join_files(&join_args(&[
        "join",
        "--plan",
        &plan_path,
        "--tracker-export",
        &export_path,
        "--out",
        &out,
    ]))
    .unwrap_err();
    assert!(
        format!("{e:#}").contains("plan points missing from the tracker export: P1"),
        "{e:#}"
    );
}
