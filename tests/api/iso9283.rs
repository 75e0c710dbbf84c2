//! `POST /v1/iso9283`: the figures of measured cycles of the test cube equal
//! hand-computed values and `robocal iso9283 --json`; unreadable CSVs are 422
//! naming the test.

use crate::support::*;
use axum::http::StatusCode;
use clap::Parser;
use robocal::cli::iso9283::{figures, make, Iso9283Command};
use serde_json::json;
use std::fmt::Write as _;

/// The cube plan of a UR10 (CSV) and cycles reaching each pose at
/// c + (−1, −1, 0) + (0 | 2 | 4, 0, 0): AP = √2, RP = 4/3 + 3·√(4/3).
fn plan_and_cycles(dir: &std::path::Path) -> (String, String) {
    let plan_path = dir.join("plan.csv");
    let argv = [
        "robocal",
        "iso9283",
        "plan",
        "--model",
        "ur10",
        "--box",
        "300,-400,100,900,400,700",
        "--commands",
        "nominal",
        "--out",
        plan_path.to_str().unwrap(),
    ];
    let robocal::cli::Command::Iso9283(a) =
        robocal::cli::Cli::try_parse_from(argv).unwrap().command
    else {
        panic!("not iso9283")
    };
    let Some(Iso9283Command::Plan(c)) = a.command else {
        panic!("not a plan")
    };
    make(&c).unwrap();
    let plan = std::fs::read_to_string(&plan_path).unwrap();
    let commanded = robocal_core::check::iso9283::csv::read_plan_csv(&plan).unwrap();
    let mut cycles = String::from("pose,cycle,x_mm,y_mm,z_mm\n");
    for c in &commanded {
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
    (plan, cycles)
}

#[tokio::test]
async fn iso9283_figures_over_http_are_the_standards_and_the_clis() {
    let t = setup().await;
    let dir = tempfile::tempdir().unwrap();
    let (plan, cycles) = plan_and_cycles(dir.path());
    let r = t
        .post_json(
            "/v1/iso9283",
            &[],
            json!({ "tests": [{ "label": "nominal", "plan_csv": plan, "measured_csv": cycles }] }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let body = r.json();
    let got = &body["tests"][0];
    assert_eq!(got["label"], "nominal");
    let poses = got["figures"]["poses"].as_array().unwrap();
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
    // The CLI on the same files gives the same figures.
    std::fs::write(dir.path().join("cycles.csv"), &cycles).unwrap();
    let argv = [
        "robocal",
        "iso9283",
        "--plan",
        dir.path().join("plan.csv").to_str().unwrap(),
        "--measured",
        dir.path().join("cycles.csv").to_str().unwrap(),
        "--json",
    ]
    .map(str::to_string);
    let robocal::cli::Command::Iso9283(a) =
        robocal::cli::Cli::try_parse_from(argv).unwrap().command
    else {
        panic!("not iso9283")
    };
    let cli: serde_json::Value = serde_json::from_str(&figures(&a.figures).unwrap()).unwrap();
    assert_eq!(cli[0]["figures"], got["figures"]);

    // A cycles file with one cycle per pose: 422 naming the test.
    let one: String = cycles
        .lines()
        .filter(|l| !l.contains(",2,") && !l.contains(",3,"))
        .map(|l| format!("{l}\n"))
        .collect();
    let r = t
        .post_json(
            "/v1/iso9283",
            &[],
            json!({ "tests": [{ "label": "short", "plan_csv": plan, "measured_csv": one }] }),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
    let why = r.detail();
    assert!(why.contains("`short`") && why.contains("cycle"), "{why}");
}
