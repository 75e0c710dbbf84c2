//! A program for a robot on its stored track, filtered over HTTP with the
//! controller's own track (`controller_track`) and by `robocal filter
//! --track --nominal-track` with the stored track's file: the same files and
//! the same report, byte for byte. The program is KRL, every target an
//! `E6POS` at its own track value, the poses the true robot on the
//! simulated rail reached there (`track::Rail`); the controller's track is
//! the rail's drawing (horizontal, 25° off the cell's x, scale 1). How close
//! filtered programs bring a true tool to its part is the core's test
//! (`core/tests/programs/track.rs`); here the plumbing is.

use super::track::Rail;
use crate::support::*;
use axum::http::StatusCode;
use clap::Parser;
use rand_chacha::ChaCha8Rng;
use robocal::model::external::LinearTrack;
use robocal::model::kinematics::chain::tool_pose;
use robocal::model::orientation::{rotation_to, OrientationConvention};
use robocal::model::preset;
use robocal::program::{kuka_status, kuka_turn};
use robocal::sim::random_configurations;
use robocal::solve::ik::{AnalyticIk, Configuration, Elbow};
use serde_json::{json, Value};
use std::path::Path;

const FILTER: &str = "/v1/robots/{id}/programs/filter";

/// The controller's track: the rail of the drawing, the base 350 mm above
/// the carriage and 120 mm beside it, turned 90° about the vertical.
pub(crate) fn drawing() -> LinearTrack {
    robocal::sim::track::TrueTrack::drawing_4m()
}

pub(crate) fn controller_track() -> Value {
    serde_json::from_str(&drawing().to_json()).unwrap()
}

/// A KRL program (the nominal reflector as its tool, the world as its base)
/// to the reflector poses the true robot reached at `values` [mm], with the
/// nominal model's flags (joints away from the flags' boundaries, elbow up).
/// The head of a KRL `.src` named `name` with the nominal YS100's
/// reflector as its `$TOOL` and `base` (a `$BASE` or `BAS` line) after it.
pub(crate) fn krl_head(name: &str, base: &str) -> String {
    let tool = tool_pose(&preset("ys100").unwrap());
    let t = rotation_to(OrientationConvention::KukaAbc, &tool.r);
    format!(
        "DEF {name}()\n$TOOL = {{X {:.4},Y {:.4},Z {:.4},A {:.4},B {:.4},C {:.4}}}\n{base}\n",
        tool.p.x * 1e3,
        tool.p.y * 1e3,
        tool.p.z * 1e3,
        t[0],
        t[1],
        t[2]
    )
}

/// Random joints of the nominal YS100 (model convention), drawn until their
/// flags are clear of the flags' boundaries (every joint 5° from 0, A5 10°)
/// and `accept` takes their configuration; with their controller degrees.
pub(crate) fn flagged_joints(
    ik: &AnalyticIk,
    rng: &mut ChaCha8Rng,
    accept: impl Fn(Configuration) -> bool,
) -> (Vec<f64>, Vec<f64>, Configuration) {
    let nominal = preset("ys100").unwrap();
    loop {
        let q = random_configurations(&nominal, 1, rng).remove(0);
        let deg: Vec<f64> = nominal
            .joints_to_controller(&q)
            .iter()
            .map(|v| v.to_degrees())
            .collect();
        let Some(conf) = ik.configuration(&q) else {
            continue;
        };
        if deg.iter().any(|v| v.abs() < 5.0) || deg[4].abs() < 10.0 || !accept(conf) {
            continue;
        }
        return (q, deg, conf);
    }
}

fn program(rail: &Rail, values: &[f64], rng: &mut ChaCha8Rng) -> (String, String) {
    let ik = AnalyticIk::new(&preset("ys100").unwrap()).unwrap();
    let mut src = krl_head("rail", "$BASE = $NULLFRAME");
    let mut dat = String::from("DEFDAT rail\n");
    for (i, &e) in values.iter().enumerate() {
        // Elbow down is near the YS100's limits: a target the true robot
        // reached there may have no solution on its flags within them.
        let (q, deg, conf) = flagged_joints(&ik, rng, |c| c.elbow == Elbow::Up);
        let p = rail.true_pose(&q, e);
        let abc = rotation_to(OrientationConvention::KukaAbc, &p.r);
        let s = kuka_status(&deg, conf);
        src.push_str(&format!("PTP XP{i}\n"));
        dat.push_str(&format!(
            "DECL E6POS XP{i}={{X {:.4},Y {:.4},Z {:.4},A {:.4},B {:.4},C {:.4},S {s},T {},E1 {e:.3},E2 0.0}}\n",
            p.p.x * 1e3,
            p.p.y * 1e3,
            p.p.z * 1e3,
            abc[0],
            abc[1],
            abc[2],
            kuka_turn(&deg)
        ));
    }
    (src + "END\n", dat + "ENDDAT\n")
}

fn request(src: &str, dat: &str) -> Value {
    json!({
        "language": "krl",
        "files": [
            { "name": "rail.src", "content": src },
            { "name": "rail.dat", "content": dat }
        ],
        "controller_track": controller_track(),
    })
}

/// Before the robot has a track: `controller_track` is a 409 naming what to
/// fit; a controller track the model refuses is a 422 naming its field.
pub(crate) async fn refused_without_a_track(t: &TestApp, rid: &str) {
    let src = "DEF a()\nPTP XP1\nEND\n";
    let dat = "DEFDAT a\nDECL E6POS XP1={X 1500,Y 0,Z 1200,A 0,B 90,C 0,E1 100}\nENDDAT\n";
    let r = t.post_json(FILTER, &[rid], request(src, dat)).await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    assert!(
        r.detail().contains("`controller_track`: robot") && r.detail().contains("has no track"),
        "{}",
        r.detail()
    );
    let mut body = request(src, dat);
    body["controller_track"]["scale"] = json!(1.5);
    let r = t.post_json(FILTER, &[rid], body).await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
    assert!(
        r.detail().contains("`controller_track`") && r.detail().contains("scale"),
        "{}",
        r.detail()
    );
}

/// `robocal filter` run in-process with `argv` (writing into `out`) gives
/// the HTTP answer `http`'s report and files, byte for byte, every target
/// filtered.
pub(crate) fn assert_cli_gives(http: &Value, argv: impl IntoIterator<Item = String>, out: &Path) {
    let robocal::cli::Command::Filter(a) = robocal::cli::Cli::try_parse_from(argv).unwrap().command
    else {
        unreachable!("a filter command line")
    };
    let by_cli = robocal::cli::filter::filter_report(&a).unwrap();
    assert_eq!(by_cli.not_done, 0);
    let cli_report: Value = serde_json::from_str(&by_cli.text).unwrap();
    assert_eq!(http["report"], cli_report, "the report");
    for f in http["files"].as_array().unwrap() {
        let name = f["name"].as_str().unwrap();
        let written = std::fs::read_to_string(out.join(name)).unwrap();
        assert_eq!(f["content"].as_str().unwrap(), written, "{name}");
    }
}

/// After the fit: the program filtered over HTTP and by the command line
/// with the stored track's file `rail_json` and the model file `model`.
pub(crate) async fn filters_as_the_command_line(
    t: &TestApp,
    rid: &str,
    rail: &Rail,
    model: &Path,
    rail_json: &Path,
    dir: &Path,
    rng: &mut ChaCha8Rng,
) {
    let values: Vec<f64> = (0..12).map(|i| 150.0 + 310.0 * f64::from(i)).collect();
    let (src, dat) = program(rail, &values, rng);
    let r = t.post_json(FILTER, &[rid], request(&src, &dat)).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let http = r.json();
    let report = &http["report"];
    assert_eq!(report["filtered"], 12, "{report}");
    assert_eq!(report["track_axis"], "E1");
    for (line, e) in report["targets"].as_array().unwrap().iter().zip(&values) {
        assert_eq!(line["track_mm"].as_f64(), Some(*e));
    }

    std::fs::write(dir.join("rail.src"), &src).unwrap();
    std::fs::write(dir.join("rail.dat"), &dat).unwrap();
    std::fs::write(dir.join("drawing.json"), drawing().to_json()).unwrap();
    let out = dir.join("filtered");
    let p = |p: &Path| p.to_str().unwrap().to_string();
    let argv = [
        "robocal".to_string(),
        "filter".into(),
        "--model".into(),
        p(model),
        "--track".into(),
        p(rail_json),
        "--nominal-track".into(),
        p(&dir.join("drawing.json")),
        "--out-dir".into(),
        p(&out),
        p(&dir.join("rail.src")),
        p(&dir.join("rail.dat")),
    ];
    assert_cli_gives(&http, argv, &out);
    std::fs::write(dir.join("cell.json"), "{}").unwrap();
    let axes = super::positioner_filter::Axes {
        kind: "track",
        file: rail_json,
        cell: &dir.join("cell.json"),
    };
    super::positioner_filter::exports_as_the_command_line(t, rid, model, &axes, dir).await;
    // The values stay as programmed.
    let filtered = http["files"][1]["content"].as_str().unwrap();
    for e in &values {
        assert!(filtered.contains(&format!("E1 {e:.3}")), "{e}");
    }
    // The command line needs both tracks.
    let half = robocal::cli::Cli::try_parse_from([
        "robocal",
        "filter",
        "--model",
        "ys100",
        "--track",
        "rail.json",
        "--out-dir",
        "x",
        "a.src",
    ]);
    assert!(half.is_err());
}
