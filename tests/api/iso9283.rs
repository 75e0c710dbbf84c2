//! `POST /v1/iso9283` (JSON) and `POST /v1/iso9283/csv`: figures of a tiny
//! plan and cycle set equal hand-computed values (ISO 9283: AP the distance
//! of the barycentre from the command, RP = l̄ + 3·S_l, APa/b/c, ±3·S,
//! AD = D̄ − D_c, RD = 3·S_D, S with n − 1); each reason a figure is not
//! computed, as a 200; form errors as 422; the CSV form equals
//! `robocal iso9283 --json`; the spec's enums and bounds are the code's.

use crate::support::*;
use axum::http::StatusCode;
use clap::Parser;
use robocal::cli::iso9283::{figures, make, Iso9283Command};
use robocal::http::iso9283::{PoseName, LABEL_MAX};
use robocal_core::check::iso9283::outcome::{ABC_MAX_DEG, CYCLES_MAX, XYZ_MAX_MM};
use robocal_core::check::iso9283::NotComputedReason;
use serde_json::{json, Value};
use std::fmt::Write as _;

fn close(got: &Value, want: f64) {
    let g = got
        .as_f64()
        .unwrap_or_else(|| panic!("{got} is not a number"));
    assert!((g - want).abs() < 1e-9, "{g} vs {want}");
}

fn close3(got: &Value, want: [f64; 3]) {
    for (k, w) in want.iter().enumerate() {
        close(&got[k], *w);
    }
}

/// P1 commanded at (600, 0, 400), (180, 0, 90) deg; its barycentre
/// b = (600, 3, 404) and cycles b ± (3, 4, 0), b ± (0, 0, 1): AP = |(0, 3, 4)|
/// = 5; l = 5, 5, 1, 1, l̄ = 3, S_l = √(16/3), RP = 3 + 3·√(16/3) = 3 + 4·√3.
/// a = 179, −179, 180, 178 against 180: deviations −1, 1, 0, −2, APa = −0.5,
/// S_a = √(5/3), RPa = √15; b = 0 throughout; c = 90, 91, 89, 90: APc = 0,
/// RPc = 3·√(2/3) = √6.
/// P2 commanded at (630, 40, 400) (D_c = 50 from P1), no orientation; cycle
/// j at P1's cycle j + (0.6, 0.8, 0)·D_j with D_j = 51, 53, 52, 52: D̄ = 52,
/// AD = 2, S_D = √(2/3), RD = √6; barycentre (631.2, 44.6, 404),
/// AP = |(1.2, 4.6, 4)| = √38.6; l = 4, 4, 1, 1, l̄ = 2.5, S_l = √3,
/// RP = 2.5 + 3·√3. A fifth entry of P2 is `null` (not measured).
fn hand_test() -> Value {
    let p1 = [
        [603.0, 7.0, 404.0],
        [597.0, -1.0, 404.0],
        [600.0, 3.0, 405.0],
        [600.0, 3.0, 403.0],
    ];
    let abc = [
        [179.0, 0.0, 90.0],
        [-179.0, 0.0, 91.0],
        [180.0, 0.0, 89.0],
        [178.0, 0.0, 90.0],
    ];
    let d = [51.0, 53.0, 52.0, 52.0];
    let m1: Vec<Value> = p1
        .iter()
        .zip(&abc)
        .map(|(x, a)| json!({ "xyz_mm": x, "abc_deg": a }))
        .collect();
    let mut m2: Vec<Value> = p1
        .iter()
        .zip(&d)
        .map(|(x, d)| json!({ "xyz_mm": [x[0] + 0.6 * d, x[1] + 0.8 * d, x[2]] }))
        .collect();
    m2.push(Value::Null);
    json!({
        "label": "hand",
        "plan": {
            "P1": { "xyz_mm": [600, 0, 400], "abc_deg": [180, 0, 90] },
            "P2": { "xyz_mm": [630, 40, 400] }
        },
        "measured": { "P1": m1, "P2": m2 }
    })
}

#[tokio::test]
async fn iso9283_json_figures_are_the_hand_computed_ones() {
    let t = setup().await;
    let r = t
        .post_json("/v1/iso9283", &[], json!({ "tests": [hand_test()] }))
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let body = r.json();
    let got = &body["tests"][0];
    assert_eq!(got["label"], "hand");
    let p1 = &got["poses"][0];
    assert_eq!((&p1["pose"], &p1["cycles"]), (&json!("P1"), &json!(4)));
    assert_eq!(p1["ap"]["outcome"], "computed");
    close(&p1["ap"]["ap_mm"], 5.0);
    close3(&p1["ap"]["ap_xyz_mm"], [0.0, 3.0, 4.0]);
    close3(&p1["ap"]["barycentre_mm"], [600.0, 3.0, 404.0]);
    close(&p1["rp"]["l_mean_mm"], 3.0);
    close(&p1["rp"]["s_l_mm"], (16.0f64 / 3.0).sqrt());
    close(&p1["rp"]["rp_mm"], 3.0 + 4.0 * 3f64.sqrt());
    close3(&p1["ap_abc"]["ap_abc_deg"], [-0.5, 0.0, 0.0]);
    close3(
        &p1["rp_abc"]["rp_abc_deg"],
        [15f64.sqrt(), 0.0, 6f64.sqrt()],
    );

    let p2 = &got["poses"][1];
    assert_eq!((&p2["pose"], &p2["cycles"]), (&json!("P2"), &json!(4)));
    close(&p2["ap"]["ap_mm"], 38.6f64.sqrt());
    close3(&p2["ap"]["barycentre_mm"], [631.2, 44.6, 404.0]);
    close(&p2["rp"]["l_mean_mm"], 2.5);
    close(&p2["rp"]["rp_mm"], 2.5 + 3.0 * 3f64.sqrt());
    assert_eq!(p2["ap_abc"]["reason"], "no_orientation_measured");
    assert_eq!(p2["rp_abc"]["reason"], "no_orientation_measured");

    let d = &got["distances"][0];
    assert_eq!(
        (&d["from"], &d["to"], &d["cycles"]),
        (&json!("P1"), &json!("P2"), &json!(4))
    );
    close(&d["ad"]["commanded_mm"], 50.0);
    close(&d["ad"]["mean_mm"], 52.0);
    close(&d["ad"]["ad_mm"], 2.0);
    close(&d["rd"]["s_d_mm"], (2.0f64 / 3.0).sqrt());
    close(&d["rd"]["rd_mm"], 6f64.sqrt());
    assert_eq!(got["distances"].as_array().unwrap().len(), 1);
}

/// One request per reason a figure is not computed: the test, the figure
/// (pose or distance index, field) and the reason it must give, as a 200.
#[tokio::test]
async fn each_reason_a_figure_is_not_computed_is_a_200() {
    let t = setup().await;
    let base = hand_test();
    let with = |f: &dyn Fn(&mut Value)| {
        let mut v = base.clone();
        f(&mut v);
        v
    };
    let cycle = |x: f64| json!({ "xyz_mm": [x, 0, 0] });
    let cases: Vec<(NotComputedReason, Value, &str, usize, &str)> = vec![
        // P3 commanded, not measured: its figures and distances.
        (
            NotComputedReason::PoseNotMeasured,
            with(&|v| v["plan"]["P3"] = json!({ "xyz_mm": [0, 0, 0] })),
            "poses",
            2,
            "rp",
        ),
        (
            NotComputedReason::PoseNotMeasured,
            with(&|v| v["plan"]["P3"] = json!({ "xyz_mm": [0, 0, 0] })),
            "distances",
            1,
            "rd",
        ),
        // P4 measured, not commanded: AP not, RP yes (below).
        (
            NotComputedReason::PoseNotInPlan,
            with(&|v| v["measured"]["P4"] = json!([cycle(1.0), cycle(2.0)])),
            "poses",
            2,
            "ap",
        ),
        // P1 with one cycle measured (the others `null`).
        (
            NotComputedReason::TooFewCycles,
            with(&|v| {
                for k in 1..4 {
                    v["measured"]["P1"][k] = Value::Null;
                }
            }),
            "poses",
            0,
            "rp",
        ),
        // P2 measured in cycles 1–4, P1 in 5 and 6 only.
        (
            NotComputedReason::TooFewSharedCycles,
            with(&|v| {
                v["measured"]["P1"] = json!([null, null, null, null, cycle(1.0), cycle(2.0)])
            }),
            "distances",
            0,
            "rd",
        ),
        (
            NotComputedReason::NoOrientationMeasured,
            base.clone(),
            "poses",
            1,
            "rp_abc",
        ),
        (
            NotComputedReason::OrientationIncomplete,
            with(&|v| {
                v["measured"]["P1"][2]
                    .as_object_mut()
                    .unwrap()
                    .remove("abc_deg");
            }),
            "poses",
            0,
            "ap_abc",
        ),
        (
            NotComputedReason::NoCommandedOrientation,
            with(&|v| {
                v["plan"]["P1"].as_object_mut().unwrap().remove("abc_deg");
            }),
            "poses",
            0,
            "ap_abc",
        ),
    ];
    for reason in NotComputedReason::ALL {
        assert!(
            cases.iter().any(|c| c.0 == reason),
            "no case for {reason:?}"
        );
    }
    for (reason, test, list, i, figure) in &cases {
        let r = t
            .post_json("/v1/iso9283", &[], json!({ "tests": [test] }))
            .await;
        assert_eq!(r.status, StatusCode::OK, "{reason:?}: {}", r.text());
        let got = &r.json()["tests"][0][*list][*i][*figure];
        assert_eq!(got["outcome"], "not_computed", "{reason:?}: {got}");
        assert_eq!(got["reason"], reason.code(), "{got}");
        assert!(!got["message"].as_str().unwrap().is_empty());
    }
    // Without a command, P4's repeatability is still computed: cycles at
    // x = 1 and 2: barycentre 1.5, l = 0.5, 0.5, S_l = 0, RP = 0.5.
    let r = t
        .post_json("/v1/iso9283", &[], json!({ "tests": [&cases[2].1] }))
        .await;
    let p4 = &r.json()["tests"][0]["poses"][2];
    assert_eq!(
        (&p4["pose"], &p4["commanded"]),
        (&json!("P4"), &json!(false))
    );
    close(&p4["rp"]["rp_mm"], 0.5);
    // P1's orientation without a command: RPa/b/c as before.
    let r = t
        .post_json("/v1/iso9283", &[], json!({ "tests": [&cases[7].1] }))
        .await;
    let p1 = &r.json()["tests"][0]["poses"][0];
    close3(
        &p1["rp_abc"]["rp_abc_deg"],
        [15f64.sqrt(), 0.0, 6f64.sqrt()],
    );
}

#[tokio::test]
async fn iso9283_form_errors_are_422_naming_the_field() {
    let t = setup().await;
    let base = hand_test();
    let with = |f: &dyn Fn(&mut Value)| {
        let mut v = base.clone();
        f(&mut v);
        json!({ "tests": [v] })
    };
    for (body, part) in [
        (
            with(&|v| v["measured"]["P1"][1]["xyz_mm"][0] = json!(2e5)),
            "cycle 2",
        ),
        (
            with(&|v| v["plan"]["P1"]["abc_deg"][2] = json!(400)),
            "commanded",
        ),
        (with(&|v| v["plan"] = json!({})), "no pose"),
        (
            with(&|v| v["plan"]["P6"] = json!({ "xyz_mm": [0, 0, 0] })),
            "P6",
        ),
        (with(&|v| v["plan"]["P1"] = Value::Null), "null"),
        (
            with(&|v| v["measured"]["P2"][0]["xyz_mm"] = json!([1, 2])),
            "measured.P2[0].xyz_mm",
        ),
        (
            with(&|v| v["measured"]["P2"][0]["abc_deg"] = Value::Null),
            "abc_deg",
        ),
        (
            with(&|v| v["label"] = json!("x".repeat(LABEL_MAX + 1))),
            "label",
        ),
        (
            with(&|v| v["measured"]["P2"] = json!(vec![Value::Null; CYCLES_MAX + 1])),
            "at most 1000",
        ),
        (json!({ "tests": [] }), "1 to 8 tests"),
    ] {
        let r = t.post_json("/v1/iso9283", &[], body.clone()).await;
        assert_eq!(
            r.status,
            StatusCode::UNPROCESSABLE_ENTITY,
            "{body}: {}",
            r.text()
        );
        assert!(r.detail().contains(part), "`{}` lacks `{part}`", r.detail());
        assert!(
            !t.spec.accepts(
                &t.spec
                    .request_schema("POST", "/v1/iso9283", "application/json"),
                &body
            ),
            "{body}"
        );
    }
    // The bounds themselves are accepted.
    let body = with(&|v| {
        v["measured"]["P1"][0]["xyz_mm"] = json!([XYZ_MAX_MM, -XYZ_MAX_MM, 0]);
        v["measured"]["P1"][0]["abc_deg"] = json!([ABC_MAX_DEG, -ABC_MAX_DEG, 0]);
    });
    let r = t.post_json("/v1/iso9283", &[], body).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
}

/// The spec's reason enum, pose names and bounds are the code's.
#[test]
fn the_spec_states_the_reasons_poses_and_bounds_of_the_code() {
    let yaml: serde_yaml::Value = serde_yaml::from_str(robocal::http::OPENAPI_YAML).unwrap();
    let doc = serde_json::to_value(yaml).unwrap();
    let s = &doc["components"]["schemas"];
    let codes: Vec<&str> = NotComputedReason::ALL.iter().map(|r| r.code()).collect();
    assert_eq!(s["Iso9283Reason"]["enum"], json!(codes));
    let names: Vec<&str> = PoseName::ALL.iter().map(|p| p.name()).collect();
    for field in ["plan", "measured"] {
        let keys: Vec<&String> = s["Iso9283Test"]["properties"][field]["properties"]
            .as_object()
            .unwrap()
            .keys()
            .collect();
        assert_eq!(keys, names, "{field}");
    }
    let xyz = &s["Iso9283Xyz"]["items"];
    assert_eq!(
        (xyz["minimum"].as_f64(), xyz["maximum"].as_f64()),
        (Some(-XYZ_MAX_MM), Some(XYZ_MAX_MM))
    );
    let abc = &s["Iso9283Abc"]["items"];
    assert_eq!(
        (abc["minimum"].as_f64(), abc["maximum"].as_f64()),
        (Some(-ABC_MAX_DEG), Some(ABC_MAX_DEG))
    );
    assert_eq!(s["Iso9283Cycles"]["maxItems"], json!(CYCLES_MAX));
    assert_eq!(
        s["Iso9283Test"]["properties"]["label"]["maxLength"],
        json!(LABEL_MAX)
    );
    let tests = &s["Iso9283Request"]["properties"]["tests"]["maxItems"];
    assert_eq!(tests, &json!(robocal::service::iso9283::TESTS_MAX));
}

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
async fn iso9283_csv_figures_are_the_standards_and_the_clis() {
    let t = setup().await;
    let dir = tempfile::tempdir().unwrap();
    let (plan, cycles) = plan_and_cycles(dir.path());
    let r = t
        .post_json(
            "/v1/iso9283/csv",
            &[],
            json!({ "tests": [{ "label": "nominal", "plan_csv": plan, "measured_csv": cycles }] }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let body = r.json();
    let got = &body["tests"][0];
    assert_eq!(got["label"], "nominal");
    let poses = got["poses"].as_array().unwrap();
    assert_eq!(poses.len(), 5);
    for f in poses {
        close(&f["ap"]["ap_mm"], 2f64.sqrt());
        close(&f["rp"]["rp_mm"], 4.0 / 3.0 + 3.0 * (4.0f64 / 3.0).sqrt());
        // The plan commands orientations; the cycles carry none.
        assert_eq!(f["ap_abc"]["reason"], "no_orientation_measured");
    }
    // The CLI on the same files gives the same values.
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
    let cli: Value = serde_json::from_str(&figures(&a.figures).unwrap()).unwrap();
    let cli = &cli[0]["figures"];
    for (c, h) in cli["poses"].as_array().unwrap().iter().zip(poses) {
        assert_eq!(c["pose"], h["pose"]);
        for (field, figure) in [
            ("ap_mm", "ap"),
            ("ap_xyz_mm", "ap"),
            ("barycentre_mm", "ap"),
            ("l_mean_mm", "rp"),
            ("s_l_mm", "rp"),
            ("rp_mm", "rp"),
        ] {
            assert_eq!(c[field], h[figure][field], "{field}");
        }
    }
    let distances = got["distances"].as_array().unwrap();
    assert_eq!(distances.len(), 10);
    for (c, h) in cli["distances"].as_array().unwrap().iter().zip(distances) {
        assert_eq!((&c["from"], &c["to"]), (&h["from"], &h["to"]));
        assert_eq!(c["ad_mm"], h["ad"]["ad_mm"]);
        assert_eq!(c["rd_mm"], h["rd"]["rd_mm"]);
    }

    // One cycle per pose: a 200 saying so for every figure.
    let one: String = cycles
        .lines()
        .filter(|l| !l.contains(",2,") && !l.contains(",3,"))
        .map(|l| format!("{l}\n"))
        .collect();
    let r = t
        .post_json(
            "/v1/iso9283/csv",
            &[],
            json!({ "tests": [{ "label": "short", "plan_csv": plan, "measured_csv": one }] }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    assert_eq!(
        r.json()["tests"][0]["poses"][0]["rp"]["reason"],
        "too_few_cycles"
    );
    // A cycles file without its z column: 422 naming the test and the file.
    let r = t
        .post_json(
            "/v1/iso9283/csv",
            &[],
            json!({ "tests": [{ "label": "broken", "plan_csv": plan, "measured_csv": "pose,cycle,x_mm,y_mm\nP1,1,0,0\n" }] }),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
    let why = r.detail();
    assert!(
        why.contains("`broken`") && why.contains("measured_csv") && why.contains("z_mm"),
        "{why}"
    );
    // One attained position with a decimal comma in the comma-separated
    // cycles (read shifted, it was answered 200 with AP 194 mm), and a plan
    // row one field short: 422 naming the file, the line and the column.
    let mut lines: Vec<String> = cycles.lines().map(str::to_string).collect();
    let row = lines.iter().position(|l| l.starts_with("P1,2,")).unwrap();
    let fields: Vec<String> = lines[row].split(',').map(str::to_string).collect();
    let x: f64 = fields[2].parse().unwrap();
    lines[row] = format!(
        "P1,2,{},{},{}",
        format!("{x:.2}").replace('.', ","),
        fields[3],
        fields[4]
    );
    let comma = lines.join("\n") + "\n";
    let short: String = plan
        .lines()
        .enumerate()
        .map(|(i, l)| if i == 2 { l.rsplit_once(',').unwrap().0.to_string() } else { l.to_string() } + "\n")
        .collect();
    for (plan, measured, file, want) in [
        (
            plan.clone(),
            comma,
            "measured_csv",
            format!("line {}: 6 fields, the header has 5: field 6", row + 1),
        ),
        (short, cycles.clone(), "plan_csv", "line 3: ".to_string()),
    ] {
        let r = t
            .post_json(
                "/v1/iso9283/csv",
                &[],
                json!({ "tests": [{ "label": "qa", "plan_csv": plan, "measured_csv": measured }] }),
            )
            .await;
        assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
        let why = r.detail();
        assert!(why.contains(file) && why.contains(&want), "{why}");
        assert!(why.contains("column"), "{why}");
    }
}
