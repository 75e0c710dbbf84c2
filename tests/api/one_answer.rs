//! One target, one answer (issue 42): the same unflagged target, in the same
//! tool and work object, through `robocal solve`, `robocal filter`, the HTTP
//! solve and the HTTP filter gets the same configuration, joints and false
//! target — including targets where the filter used to take the nominal
//! controller's first solution and `solve` another.

use super::cell::{calibrated_robot_with_cell, examples, model_file};
use crate::support::*;
use axum::http::StatusCode;
use clap::Parser;
use robocal::cli::filter::{filter_to_string, FilterArgs};
use robocal::cli::solve::{solve_to_string, SolveArgs};
use robocal::model::orientation::{rotation_from, OrientationConvention};
use robocal::model::Pose;
use robocal::program::{parse, Language, ProgramFile};
use robocal::solve::cell::{CellDescription, CellOptions, CellRef, CellSolver};
use robocal::solve::ik::IkSettings;
use robocal_core::model::calibrated::CalibratedModelFile;
use serde_json::{json, Value};
use std::path::Path;

const SOLVE: &str = "/v1/robots/{id}/solve";
const FILTER: &str = "/v1/robots/{id}/programs/filter";

/// Targets in the work object `table`: mm and KUKA A, B, C [deg].
const TARGETS: [([f64; 3], [f64; 3]); 8] = [
    ([0.0, 0.0, 0.0], [0.0, 0.0, 180.0]),
    ([100.0, 150.0, 30.0], [10.0, 5.0, 175.0]),
    ([200.0, 50.0, 0.0], [90.0, 0.0, 180.0]),
    ([-100.0, 200.0, 100.0], [30.0, -10.0, 170.0]),
    ([300.0, -100.0, 50.0], [-45.0, 0.0, 180.0]),
    ([50.0, 300.0, 200.0], [135.0, 10.0, 175.0]),
    ([-200.0, -150.0, 150.0], [-120.0, 20.0, 160.0]),
    ([150.0, 250.0, 80.0], [180.0, -15.0, 170.0]),
];

/// A one-target KRL program in tool 1 (torch), base 2 (table), no flags.
fn program(p: [f64; 3], o: [f64; 3]) -> String {
    format!(
        "DEF one()\n$TOOL = TOOL_DATA[1]\nBAS(#BASE, 2)\nLIN {{X {:.4},Y {:.4},Z {:.4},A {:.4},B {:.4},C {:.4}}}\nEND\n",
        p[0], p[1], p[2], o[0], o[1], o[2]
    )
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap_or_else(|| panic!("not an array: {v}"))
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// The false target a filter wrote (m, rotation).
fn written(text: &str) -> Pose {
    let file = ProgramFile {
        name: "one.src".into(),
        text: text.into(),
    };
    parse(Language::Krl, &[file]).unwrap().sites[0]
        .pose
        .unwrap()
}

/// A false target of a solve answer: `x, y, z` [mm] and the KUKA angles.
fn pose_of(xyz: [f64; 3], abc: &[f64]) -> Pose {
    let r = rotation_from(OrientationConvention::KukaAbc, abc).unwrap();
    Pose::new(r, nalgebra::Vector3::from(xyz) * 1e-3)
}

/// One answer, as each entry point gives it.
#[derive(Debug)]
struct Answer {
    configuration: String,
    joints_deg: Vec<f64>,
    false_target: Pose,
}

fn assert_same(want: &Answer, got: &Answer, what: &str, i: usize, pose_mm: f64) {
    assert_eq!(got.configuration, want.configuration, "{what}, target {i}");
    for (a, b) in got.joints_deg.iter().zip(&want.joints_deg) {
        assert!((a - b).abs() < 1e-6, "{what}, target {i}: {a} vs {b} deg");
    }
    let dp = (got.false_target.p - want.false_target.p).norm() * 1e3;
    let dr = (got.false_target.r - want.false_target.r).norm();
    assert!(
        dp < pose_mm && dr < 1e-5,
        "{what}, target {i}: {dp} mm, {dr}"
    );
}

fn cli_solve(model: &Path, dir: &Path) -> Vec<Answer> {
    let csv = dir.join("targets.csv");
    let mut text = String::from("id,x,y,z,a,b,c\n");
    for (i, (p, o)) in TARGETS.iter().enumerate() {
        text.push_str(&format!(
            "{i},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4}\n",
            p[0], p[1], p[2], o[0], o[1], o[2]
        ));
    }
    std::fs::write(&csv, text).unwrap();
    let cell = examples().join("cell.json");
    let argv = [
        "robocal",
        "solve",
        "--model",
        model.to_str().unwrap(),
        "--targets",
        csv.to_str().unwrap(),
        "--cell",
        cell.to_str().unwrap(),
        "--tool",
        "torch",
        "--work-object",
        "table",
        "--format",
        "json",
    ];
    let args: SolveArgs = match robocal::cli::Cli::try_parse_from(argv).unwrap().command {
        robocal::cli::Command::Solve(a) => a,
        other => panic!("{other:?}"),
    };
    let out: Value = serde_json::from_str(&solve_to_string(&args).unwrap()).unwrap();
    out["targets"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| {
            let f = &t["false_target"];
            let abc = [
                f["a"].as_f64().unwrap(),
                f["b"].as_f64().unwrap(),
                f["c"].as_f64().unwrap(),
            ];
            Answer {
                configuration: t["branch"].as_str().unwrap().to_string(),
                joints_deg: numbers(&t["joints_deg"]),
                false_target: pose_of(crate::common::json_xyz(f).into(), &abc),
            }
        })
        .collect()
}

fn cli_filter(model: &Path, dir: &Path, i: usize) -> Answer {
    let (p, o) = TARGETS[i];
    let src = dir.join(format!("one{i}.src"));
    std::fs::write(&src, program(p, o)).unwrap();
    let out_dir = dir.join(format!("out{i}"));
    let cell = examples().join("cell.json");
    let argv = [
        "robocal",
        "filter",
        "--model",
        model.to_str().unwrap(),
        "--cell",
        cell.to_str().unwrap(),
        "--out-dir",
        out_dir.to_str().unwrap(),
        src.to_str().unwrap(),
    ];
    let args: FilterArgs = match robocal::cli::Cli::try_parse_from(argv).unwrap().command {
        robocal::cli::Command::Filter(a) => a,
        other => panic!("{other:?}"),
    };
    let report: Value = serde_json::from_str(&filter_to_string(&args).unwrap()).unwrap();
    let t = &report["targets"][0];
    assert_eq!(t["status"], "filtered", "{report}");
    let text = std::fs::read_to_string(out_dir.join(format!("one{i}.src"))).unwrap();
    Answer {
        configuration: t["configuration"].as_str().unwrap().to_string(),
        joints_deg: numbers(&t["joints_deg"]),
        false_target: written(&text),
    }
}

async fn http_solve(t: &TestApp, rid: &str) -> Vec<Answer> {
    let targets: Vec<Value> = TARGETS
        .iter()
        .map(|(p, o)| {
            let r = |v: f64| (v * 1e4).round() / 1e4;
            json!({ "x": r(p[0]), "y": r(p[1]), "z": r(p[2]), "orientation": { "values": [r(o[0]), r(o[1]), r(o[2])] } })
        })
        .collect();
    let r = t
        .post_json(
            SOLVE,
            &[rid],
            json!({ "targets": targets, "convention": "kuka_abc", "tool": "torch", "work_object": "table" }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    r.json()["results"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| {
            assert_eq!(x["status"], "ok", "{x}");
            let f = &x["false_target"];
            Answer {
                configuration: x["branch"].as_str().unwrap().to_string(),
                joints_deg: numbers(&x["joints_deg"]),
                false_target: pose_of(crate::common::json_xyz(f).into(), &numbers(&f["values"])),
            }
        })
        .collect()
}

async fn http_filter(t: &TestApp, rid: &str, i: usize) -> Answer {
    let (p, o) = TARGETS[i];
    let r = t
        .post_json(
            FILTER,
            &[rid],
            json!({ "language": "krl", "files": [{ "name": "one.src", "content": program(p, o) }] }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let body = r.json();
    let line = &body["report"]["targets"][0];
    assert_eq!(line["status"], "filtered", "{body}");
    Answer {
        configuration: line["configuration"].as_str().unwrap().to_string(),
        joints_deg: numbers(&line["joints_deg"]),
        false_target: written(body["files"][0]["content"].as_str().unwrap()),
    }
}

#[tokio::test]
async fn a_target_gets_one_answer_from_solve_and_filter_over_http_and_the_cli() {
    let t = setup().await;
    let (_, rid) = calibrated_robot_with_cell(&t).await;
    let dir = tempfile::tempdir().unwrap();
    let model = model_file(&t, &rid, dir.path()).await;
    let solved = cli_solve(&model, dir.path());
    let over_http = http_solve(&t, &rid).await;
    // Where the filter's old choice (the nominal controller's first
    // solution) was not the one `solve` gives.
    let compensated = CalibratedModelFile::from_json(&std::fs::read_to_string(&model).unwrap())
        .unwrap()
        .to_compensated()
        .unwrap();
    let cell =
        CellDescription::from_json(&std::fs::read_to_string(examples().join("cell.json")).unwrap())
            .unwrap()
            .to_cell()
            .unwrap();
    let tool = cell.tool(&CellRef::Name("torch".into())).unwrap();
    let wobj = cell.work_object(&CellRef::Name("table".into())).unwrap();
    let solver = CellSolver::for_tool(&compensated, Some(&tool), IkSettings::default());
    let mut differed = 0;
    for (i, want) in solved.iter().enumerate() {
        let (p, o) = TARGETS[i];
        let pose = pose_of(p, &o);
        let first = solver.nominal_solutions(&wobj, &pose);
        let core = solver.solve(&wobj, &pose, &CellOptions::default());
        assert_eq!(
            core.solution.branch.map(|b| b.to_string()).as_deref(),
            Some(want.configuration.as_str())
        );
        if first.first().and_then(|q| solver.configuration(q)) != core.solution.branch {
            differed += 1;
        }
        assert_same(want, &over_http[i], "HTTP solve", i, 1e-6);
        // The filter writes 4 decimals.
        assert_same(
            want,
            &cli_filter(&model, dir.path(), i),
            "robocal filter",
            i,
            1e-4,
        );
        assert_same(
            want,
            &http_filter(&t, &rid, i).await,
            "HTTP filter",
            i,
            1e-4,
        );
    }
    assert!(differed >= 1, "no target where the old choice differed");
}
