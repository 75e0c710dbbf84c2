//! Exit codes a script can gate on (issue 42), asserted on the real binary:
//! `check` ends with its status's code (0 only for `ok`), `filter` and
//! `solve` with 2 when a target failed unless `--allow-failures`, refused
//! input with 1; docs/guide/exit-codes.md states the code's table.

mod common;

use common::{code, robocal, text};
use robocal::check::CheckStatus;
use robocal::cli::exit::Exit;
use robocal::measure::{csv, MeasuredPose};
use robocal::model::preset;
use robocal_core::model::calibrated::CompensatedModel;
use std::path::Path;
use std::process::Output;

fn stdout(out: &Output) -> String {
    text(&out.stdout)
}

/// The rows of every markdown table of the guide's page `name`
/// (docs/guide/), the cells trimmed, in order.
fn guide_tables(name: &str) -> Vec<Vec<Vec<String>>> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("docs/guide")
        .join(name);
    let page = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut tables: Vec<Vec<Vec<String>>> = Vec::new();
    let mut in_table = false;
    for line in page.lines() {
        let line = line.trim();
        if !line.starts_with('|') {
            in_table = false;
            continue;
        }
        if !in_table {
            tables.push(Vec::new());
            in_table = true;
        }
        let cells: Vec<String> = line
            .trim_matches('|')
            .split('|')
            .map(|c| c.trim().to_string())
            .collect();
        if cells
            .iter()
            .all(|c| c.chars().all(|ch| ch == '-' || ch == ':'))
        {
            continue;
        }
        tables.last_mut().unwrap().push(cells);
    }
    tables
}

#[test]
fn the_guide_states_the_exit_codes_and_statuses_of_the_code() {
    let tables = guide_tables("exit-codes.md");
    assert_eq!(tables.len(), 2, "{tables:?}");
    let codes = &tables[0];
    assert_eq!(codes[0], ["code", "name", "commands", "meaning"]);
    let want: Vec<Vec<String>> = Exit::ALL
        .iter()
        .map(|e| {
            vec![
                e.code().to_string(),
                format!("`{}`", e.name()),
                e.scope().label(),
                e.meaning(),
            ]
        })
        .collect();
    assert_eq!(codes[1..], want[..]);
    let statuses = &tables[1];
    assert_eq!(
        statuses[0],
        ["status", "when", "what to do", "`robocal check` exits"]
    );
    let want: Vec<Vec<String>> = CheckStatus::ALL
        .iter()
        .map(|s| {
            vec![
                format!("`{}`", s.name()),
                s.meaning().to_string(),
                s.action().to_string(),
                Exit::of_check(*s).code().to_string(),
            ]
        })
        .collect();
    assert_eq!(statuses[1..], want[..]);
}

/// 20 poses of the UR10 (the model the checks score against), each row's
/// position the model's prediction moved by `error(i, p)` [mm].
fn check_rows(error: &dyn Fn(usize, [f64; 3]) -> [f64; 3]) -> Vec<MeasuredPose> {
    let nominal = preset("ur10").unwrap();
    let model = CompensatedModel::from_nominal(nominal.clone());
    (0..20)
        .map(|i| {
            let t = i as f64;
            let q = vec![
                0.15 * t - 1.5,
                -1.2 + 0.04 * t,
                1.1 - 0.03 * t,
                -1.4 + 0.02 * t,
                1.5 + 0.03 * t,
                0.1 * t,
            ];
            let p = model.predict(&q).unwrap().p * 1e3;
            MeasuredPose {
                q_deg: nominal
                    .joints_to_controller(&q)
                    .into_iter()
                    .map(f64::to_degrees)
                    .collect(),
                xyz_mm: error(i, [p.x, p.y, p.z]),
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
}

/// A rigid transform of the measured points: 0.3° about z through the
/// origin, then (9, −8, 5) mm.
fn rigidly_moved(p: [f64; 3]) -> [f64; 3] {
    let (s, c) = 0.3f64.to_radians().sin_cos();
    [
        c * p[0] - s * p[1] + 9.0,
        s * p[0] + c * p[1] - 8.0,
        p[2] + 5.0,
    ]
}

/// A row's position error: the position for row `i` and the model's `p` [mm].
type RowError = Box<dyn Fn(usize, [f64; 3]) -> [f64; 3]>;

/// Errors that differ from pose to pose (a changed robot, not a moved frame):
/// `size` mm along x, y or z in turn, the sign alternating.
fn scattered(size: f64) -> impl Fn(usize, [f64; 3]) -> [f64; 3] {
    move |i, mut p| {
        p[i % 3] += if i % 2 == 0 { size } else { -size };
        p
    }
}

#[test]
fn check_ends_with_its_status_code() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&str, CheckStatus, RowError); 4] = [
        ("ok.csv", CheckStatus::Ok, Box::new(|_, p| p)),
        (
            "degraded.csv",
            CheckStatus::Degraded,
            Box::new(scattered(0.7)),
        ),
        (
            "recalibrate.csv",
            CheckStatus::Recalibrate,
            Box::new(scattered(3.0)),
        ),
        (
            "shifted.csv",
            CheckStatus::Shifted,
            Box::new(|_, p| rigidly_moved(p)),
        ),
    ];
    for (name, status, error) in &cases {
        std::fs::write(dir.path().join(name), csv::write(&check_rows(error))).unwrap();
        let args = ["check", "--model", "ur10", "--measurements", name];
        let out = robocal(dir.path(), &args);
        let text = stdout(&out);
        assert!(
            text.starts_with(&format!("status: {}", status.name())),
            "{name}: {text}"
        );
        assert_eq!(
            code(&out),
            i32::from(Exit::of_check(*status).code()),
            "{name}"
        );
        assert_eq!(code(&out) == 0, status.is_ok(), "{name}");
        let json = robocal(dir.path(), &[&args[..], &["--json"]].concat());
        assert_eq!(code(&json), code(&out));
        let v: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
        assert_eq!(v["status"], status.name());
    }
    assert_eq!(
        [0, 3, 4, 5],
        cases.map(|c| Exit::of_check(c.1).code()),
        "ok, degraded, recalibrate, shifted"
    );
    // The shift named is the one applied: the mean displacement of the
    // points (the transform's translation at their centre) and 0.3°.
    let rows = check_rows(&|_, p| p);
    let n = rows.len() as f64;
    let mean_shift: Vec<f64> = (0..3)
        .map(|k| {
            rows.iter()
                .map(|r| rigidly_moved(r.xyz_mm)[k] - r.xyz_mm[k])
                .sum::<f64>()
                / n
        })
        .collect();
    let translation = mean_shift.iter().map(|d| d * d).sum::<f64>().sqrt();
    let out = robocal(
        dir.path(),
        &[
            "check",
            "--model",
            "ur10",
            "--measurements",
            "shifted.csv",
            "--json",
        ],
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let f = &v["frame_shift"];
    assert!(
        (f["translation_mm"].as_f64().unwrap() - translation).abs() < 1e-3,
        "{f} vs {translation}"
    );
    assert!(
        (f["rotation_deg"].as_f64().unwrap() - 0.3).abs() < 1e-5,
        "{f}"
    );
    let text = stdout(&robocal(
        dir.path(),
        &["check", "--model", "ur10", "--measurements", "shifted.csv"],
    ));
    assert!(
        text.contains(&format!("frame shift {translation:.3} mm, 0.3000°")),
        "{text}"
    );
}

/// Four `movel` targets of a UR5 program (the tool at the flange), three of
/// them 3–4 m away.
const FOUR_TARGETS: &str = "def prog():
  set_tcp(p[0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
  movel(p[0.4, -0.1, 0.3, 3.14159265, 0.0, 0.0], a=0.5, v=0.1)
  movel(p[3.0, 0.0, 0.3, 3.14159265, 0.0, 0.0], a=0.5, v=0.1)
  movel(p[0.0, 3.0, 0.3, 3.14159265, 0.0, 0.0], a=0.5, v=0.1)
  movel(p[0.0, 0.0, 4.0, 3.14159265, 0.0, 0.0], a=0.5, v=0.1)
end
";

#[test]
fn filter_and_solve_end_with_2_when_targets_fail_unless_allowed() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("prog.script"), FOUR_TARGETS).unwrap();
    let filter = |extra: &[&str]| {
        let mut args = vec![
            "filter",
            "--model",
            "ur5",
            "--out-dir",
            "out",
            "--report",
            "report.json",
        ];
        args.extend_from_slice(extra);
        args.push("prog.script");
        let out = robocal(dir.path(), &args);
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.path().join("report.json")).unwrap())
                .unwrap();
        (out, report)
    };
    let (out, report) = filter(&[]);
    assert_eq!(
        (report["filtered"].as_u64(), report["failed"].as_u64()),
        (Some(1), Some(3)),
        "{report}"
    );
    assert_eq!(code(&out), i32::from(Exit::Failures.code()));
    assert_eq!(code(&out), 2);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("3 of 4 targets failed"), "{err}");
    assert!(dir.path().join("out/prog.script").exists());
    let (out, report) = filter(&["--allow-failures"]);
    assert_eq!(report["failed"].as_u64(), Some(3));
    assert_eq!(code(&out), 0);

    std::fs::write(
        dir.path().join("targets.csv"),
        "id,x,y,z\nnear,400,-100,300\nfar,3000,0,300\n",
    )
    .unwrap();
    let solve = [
        "solve",
        "--model",
        "ur5",
        "--targets",
        "targets.csv",
        "--position-only",
    ];
    let out = robocal(dir.path(), &solve);
    assert_eq!(code(&out), 2, "{}", stdout(&out));
    assert!(
        stdout(&out).contains("1 of 2 targets solved"),
        "{}",
        stdout(&out)
    );
    let out = robocal(dir.path(), &[&solve[..], &["--allow-failures"]].concat());
    assert_eq!(code(&out), 0);
    std::fs::write(dir.path().join("near.csv"), "id,x,y,z\nnear,400,-100,300\n").unwrap();
    let out = robocal(
        dir.path(),
        &[
            "solve",
            "--model",
            "ur5",
            "--targets",
            "near.csv",
            "--position-only",
        ],
    );
    assert_eq!(code(&out), 0, "{}", stdout(&out));
}

#[test]
fn refused_input_ends_with_1_and_names_it() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("bad.script"),
        "def f():\n  movel(p[1, 2, 3], a=1)\nend\n",
    )
    .unwrap();
    let refused = i32::from(Exit::Refused.code());
    let cases: [(&[&str], &str); 4] = [
        (
            &["check", "--model", "ur10", "--measurements", "missing.csv"],
            "missing.csv",
        ),
        (
            &[
                "check",
                "--model",
                "ur10",
                "--measurements",
                "x.csv",
                "--degraded-mm",
                "abc",
            ],
            "--degraded-mm",
        ),
        (
            &["filter", "--model", "ur5", "--out-dir", "out", "bad.script"],
            "bad.script:2:10",
        ),
        (
            &["solve", "--model", "ur5", "--targets", "missing.csv"],
            "missing.csv",
        ),
    ];
    for (args, named) in cases {
        let out = robocal(dir.path(), args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(code(&out), refused, "{args:?}: {err}");
        assert!(err.contains(named), "{args:?}: {err}");
        assert!(out.stdout.is_empty(), "{args:?}");
    }
    // Help is not a refusal, and says the codes.
    let out = robocal(dir.path(), &["check", "--help"]);
    assert_eq!(code(&out), 0);
    assert!(stdout(&out).contains(&robocal::cli::exit::help_for("check")));
}
