//! Configuration flags from the user's side: a KRL target whose `S`/`T` no
//! solution carries fails in `robocal filter`'s report, listing the
//! configurations that do reach it with their flags; each is then solved
//! on its own with `robocal solve --branch` and its flags recomputed here
//! from the joints by the rules of `docs/configurations.md` (S = back +
//! 2·down + 4·[A5 < 0], T bit i when A(i+1) < 0). `solve --help` sets the
//! rules out.

use clap::{CommandFactory, Parser};
use robocal::cli::{Cli, Command};
use serde_json::Value;

const CELL: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/programs/cell.json");

/// A one-target KRL program in tool 1 (torch), base 2 (table).
fn program(flags: &str) -> String {
    format!(
        "DEF one()\n$TOOL = TOOL_DATA[1]\nBAS(#BASE, 2)\nPTP {{X 100.0,Y 150.0,Z 30.0,A 0.0,B 0.0,C 180.0{flags}}}\nEND\n"
    )
}

fn filter_report(dir: &std::path::Path, flags: &str) -> Value {
    let src = dir.join("one.src");
    std::fs::write(&src, program(flags)).unwrap();
    let out = dir.join("out");
    let argv = [
        "robocal",
        "filter",
        "--model",
        "ys100",
        "--cell",
        CELL,
        "--out-dir",
        out.to_str().unwrap(),
        src.to_str().unwrap(),
    ];
    let Command::Filter(a) = Cli::try_parse_from(argv).unwrap().command else {
        panic!("not filter")
    };
    serde_json::from_str(&robocal::cli::filter::filter_to_string(&a).unwrap()).unwrap()
}

/// The KUKA status and turn of controller joints in a branch, by the rules
/// the documentation states.
fn kuka_flags(branch: &str, joints_deg: &[f64]) -> String {
    let parts: Vec<&str> = branch.split([',', '-']).collect();
    let s = u32::from(parts[0] == "back")
        + 2 * u32::from(parts[1] == "down")
        + 4 * u32::from(joints_deg[4] < 0.0);
    let t: u32 = joints_deg
        .iter()
        .enumerate()
        .map(|(i, a)| u32::from(*a < 0.0) << i)
        .sum();
    format!("S {s} T {t}")
}

#[test]
fn a_failed_krl_flag_lists_the_configurations_that_reach_the_target_each_solved_alone() {
    let dir = tempfile::tempdir().unwrap();
    // The flags of the target as the filter chooses them without any.
    let free = filter_report(dir.path(), "");
    let line = &free["targets"][0];
    assert_eq!(line["status"], "filtered", "{line}");
    // Flags that fail: the first status whose report fails with reachable
    // configurations listed.
    let (flags, line) = (0..8)
        .flat_map(|s| [0, 8, 16, 32].map(move |t| format!(",S {s},T {t}")))
        .find_map(|f| {
            let r = filter_report(dir.path(), &f);
            let line = r["targets"][0].clone();
            (line["status"] == "failed").then_some((f, line))
        })
        .expect("some S, T fails");
    let reachable = line["reachable"].as_array().unwrap();
    assert!(reachable.len() >= 2, "{line}");
    let reason = line["reason"].as_str().unwrap();
    assert!(reason.contains("reachable with S "), "{reason}");

    // Each configuration listed, solved alone in its branch: it reaches the
    // target, and its joints carry the flags listed beside it.
    let targets = dir.path().join("t.csv");
    std::fs::write(&targets, "id,x,y,z,a,b,c\n1,100,150,30,0,0,180\n").unwrap();
    let mut seen = Vec::new();
    for r in reachable {
        let branch = r["configuration"].as_str().unwrap();
        let listed = r["flags"].as_str().unwrap();
        let argv = [
            "robocal",
            "solve",
            "--model",
            "ys100",
            "--cell",
            CELL,
            "--tool",
            "torch",
            "--work-object",
            "table",
            "--targets",
            targets.to_str().unwrap(),
            "--branch",
            branch,
            "--format",
            "json",
        ];
        let Command::Solve(a) = Cli::try_parse_from(argv).unwrap().command else {
            panic!("not solve")
        };
        let out: Value =
            serde_json::from_str(&robocal::cli::solve::solve_to_string(&a).unwrap()).unwrap();
        let t = &out["targets"][0];
        assert_eq!(t["status"], "ok", "{branch}: {t}");
        assert_eq!(t["branch"], branch, "{t}");
        assert!(t["position_residual_mm"].as_f64().unwrap() < 1e-3, "{t}");
        let joints: Vec<f64> = t["joints_deg"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        assert_eq!(kuka_flags(branch, &joints), listed, "{branch}: {joints:?}");
        seen.push(listed.to_string());
    }
    // The failed flags are none of them; the free target's are one of them.
    let failed = flags.trim_start_matches(',').replace(',', " ");
    assert!(!seen.contains(&failed), "{failed} in {seen:?}");
    let free_flags = kuka_flags(
        line_branch(&free["targets"][0]).as_str(),
        &joints_of(&free["targets"][0]),
    );
    assert!(seen.contains(&free_flags), "{free_flags} not in {seen:?}");

    // `solve --help` explains the flags of each controller.
    let help = Cli::command()
        .find_subcommand_mut("solve")
        .unwrap()
        .render_long_help()
        .to_string();
    for needle in [
        "KRL",
        "S = ",
        "cf1",
        "cfx",
        "CONFIG",
        "docs/configurations.md",
    ] {
        assert!(help.contains(needle), "no {needle} in {help}");
    }
}

fn line_branch(line: &Value) -> String {
    line["configuration"].as_str().unwrap().to_string()
}

fn joints_of(line: &Value) -> Vec<f64> {
    line["joints_deg"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect()
}
