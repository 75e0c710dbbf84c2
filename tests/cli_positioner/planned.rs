//! A positioner's measurement planned, read and fitted on the command line:
//! `robocal plan --positioner` writes the two sweeps (`point,e1,e2`, the
//! library's plan byte for byte), the simulated tracker reads each reflector
//! at every value (one export per reflector, naming the points), `plan
//! join` turns each export into a measurement file with the axes' columns
//! and `positioner calibrate` fits them: accepted, its axes on the truth's.

use super::{code, robocal, text, truth};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal::model::external::TiltRotate;
use robocal::plan::{make_positioner_plan, plan_csv, PositionerPlanSettings};
use robocal::sim::positioner_example as example;

#[test]
fn a_planned_positioner_measurement_is_joined_and_fitted() {
    let d = tempfile::tempdir().unwrap();
    let nominal = example::nominal();
    std::fs::write(d.path().join("stn.json"), nominal.to_json()).unwrap();
    let plan_args = [
        "plan",
        "--positioner",
        "stn.json",
        "--reflector",
        "400,0,20",
        "--reflector",
        "-150,100,20",
        "--tilt",
        "-80,80",
        "--tilt-values",
        "9",
    ];
    let with =
        |extra: &[&'static str]| -> Vec<&str> { plan_args.iter().chain(extra).copied().collect() };
    let out = robocal(d.path(), &with(&["--out", "plan.csv"]));
    assert_eq!(code(&out), 0, "{}", text(&out.stderr));
    let table = text(&out.stdout);
    assert!(
        table.starts_with("# 21 values of the positioner's two axes"),
        "{table}"
    );
    let plan = make_positioner_plan(
        &nominal,
        &PositionerPlanSettings {
            reflectors_mm: example::DESIGN_MM.to_vec(),
            tilt_deg: [-80.0, 80.0],
            tilt_values: 9,
            ..PositionerPlanSettings::default()
        },
    )
    .unwrap();
    let written = std::fs::read_to_string(d.path().join("plan.csv")).unwrap();
    assert_eq!(written, plan_csv(&plan.points));
    // The tracker reads each reflector at every value; its exports joined back.
    let truth = truth();
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for k in 0..2 {
        let at: Vec<(usize, [f64; 2])> = plan.values_deg.iter().map(|v| (k, *v)).collect();
        let read = truth.read(&at, &mut rng);
        let export = crate::core_common::tracker_export(
            plan.points
                .iter()
                .zip(&read)
                .map(|(p, r)| (p.name.as_str(), r.xyz_mm)),
        );
        std::fs::write(d.path().join(format!("nest{k}.csv")), export).unwrap();
        let (nest, set) = (format!("nest{k}.csv"), format!("r{k}.csv"));
        let out = robocal(
            d.path(),
            &[
                "plan",
                "join",
                "--plan",
                "plan.csv",
                "--tracker-export",
                &nest,
                "--out",
                &set,
            ],
        );
        assert_eq!(code(&out), 0, "{}", text(&out.stderr));
    }
    let out = robocal(
        d.path(),
        &[
            "positioner",
            "calibrate",
            "r0.csv",
            "r1.csv",
            "--nominal",
            "stn.json",
            "--reflector",
            "400,0,20",
            "--reflector",
            "-150,100,20",
            "--out",
            "fitted.json",
        ],
    );
    assert_eq!(code(&out), 0, "{}{}", text(&out.stdout), text(&out.stderr));
    let fitted =
        TiltRotate::from_json(&std::fs::read_to_string(d.path().join("fitted.json")).unwrap())
            .unwrap();
    let angle = fitted
        .tilt
        .direction
        .angle(&truth.tilt.direction)
        .to_degrees();
    println!("planned positioner fit: axis 1 {angle:.5} deg from the truth's");
    assert!(angle < 0.005, "{angle}");
    // Programs move the positioner alone through the plan's values, in
    // its order: KRL `PTP {E1 …,E2 …}`, RAPID `MoveExtJ`, Fanuc group 2.
    for (format, line) in [
        (
            "krl",
            (|p: &[f64; 2], name: &str| {
                format!("PTP {{E1 {:.4},E2 {:.4}}} ; {name}\r\n", p[0], p[1])
            }) as fn(&[f64; 2], &str) -> String,
        ),
        ("rapid", |p, name| {
            format!(
                "MoveExtJ [[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09],[{:.4},{:.4},9E+09,9E+09,9E+09,9E+09]], vrot10, fine; ! {name}\r\n",
                p[0], p[1]
            )
        }),
        ("fanuc", |p, _| {
            format!("\tJ1= {:.4} deg,\tJ2= {:.4} deg\r\n", p[0], p[1])
        }),
    ] {
        let out = robocal(d.path(), &with(&["--format", format, "--out", "stn.txt"]));
        assert_eq!(code(&out), 0, "{format}: {}", text(&out.stderr));
        let program = std::fs::read_to_string(d.path().join("stn.txt")).unwrap();
        let mut at = 0;
        for (p, v) in plan.points.iter().zip(&plan.values_deg) {
            let want = line(v, &p.name);
            let found = program[at..].find(&want);
            assert!(
                found.is_some(),
                "{format}: {want:?} after byte {at} in\n{program}"
            );
            at += found.unwrap() + want.len();
        }
    }
    // URScript has no external axes; Fanuc writes group 2 in column order,
    // so a tilt after the rotate is refused.
    let out = robocal(d.path(), &with(&["--format", "urscript"]));
    assert_eq!(code(&out), 1);
    assert!(text(&out.stderr).contains("URScript programs carry no external axes"));
    let swapped = [
        "--format",
        "fanuc",
        "--tilt-column",
        "e2",
        "--rotate-column",
        "e1",
    ];
    let out = robocal(d.path(), &with(&swapped));
    assert_eq!(code(&out), 1);
    assert!(text(&out.stderr).contains("give the tilt a column before the rotate's"));
}
