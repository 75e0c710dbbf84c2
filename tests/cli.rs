//! The command line end to end: simulate → calibrate (table and JSON), and errors.

mod common;

use common::{robocal, robocal_json};

#[test]
fn simulate_then_calibrate_json_is_scriptable() {
    let dir = std::env::temp_dir().join(format!("robocal-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let a = robocal(
        &dir,
        &[
            "simulate",
            "--preset",
            "ys100",
            "--poses",
            "30",
            "--seed",
            "1",
            "--out",
            "q1.csv",
            "--truth",
            "truth.json",
        ],
    );
    assert!(a.status.success(), "{}", String::from_utf8_lossy(&a.stderr));
    let b = robocal(
        &dir,
        &[
            "simulate", "--preset", "ys100", "--poses", "20", "--seed", "2", "--out", "q2.csv",
        ],
    );
    assert!(b.status.success());
    let v = robocal_json(
        &dir,
        &[
            "calibrate",
            "--model",
            "ys100",
            "--identify",
            "q1.csv",
            "--validate",
            "q2.csv",
            "--method",
            "km,skcm",
            "--json",
            "--save",
            "cal.json",
        ],
    );
    let km = v["methods"]["km"]["validation"]["mean_mm"]
        .as_f64()
        .unwrap();
    let skcm = v["methods"]["skcm"]["validation"]["mean_mm"]
        .as_f64()
        .unwrap();
    assert!(skcm < 0.05 && km > 10.0 * skcm, "km {km} skcm {skcm}");
    assert_eq!(v["identifiability"]["kept"].as_array().unwrap().len(), 31);
    assert!(v["methods"]["skcm"]["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .any(|p| p["name"] == "d3" && p["unit"] == "mm"));
    let saved: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("cal.json")).unwrap()).unwrap();
    assert_eq!(saved["method"], "skcm");
    // The saved model is a valid model description; the truth model loads as a model file.
    robocal::model::RobotModel::from_json(&saved["model"].to_string()).unwrap();
    let t = robocal(
        &dir,
        &[
            "calibrate",
            "--model",
            "truth.json",
            "--identify",
            "q1.csv",
            "--method",
            "km",
        ],
    );
    assert!(t.status.success(), "{}", String::from_utf8_lossy(&t.stderr));
    let text = String::from_utf8_lossy(&t.stdout);
    assert!(
        text.contains("Nominal robot model") && text.contains("Identifiability"),
        "{text}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn errors_are_reported_not_panicked() {
    let dir = std::env::temp_dir().join(format!("robocal-cli-err-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("bad.csv"),
        "q1,q2,q3,q4,q5,q6,x,y,z\n1,2,3,4,5,6,7,8\n",
    )
    .unwrap();
    let out = robocal(
        &dir,
        &["calibrate", "--model", "ys100", "--identify", "bad.csv"],
    );
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("line 2"), "{err}");
    let out = robocal(
        &dir,
        &["calibrate", "--model", "kr16", "--identify", "bad.csv"],
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("unknown robot preset"));
    let out = robocal(
        &dir,
        &[
            "calibrate",
            "--model",
            "ys100",
            "--identify",
            "bad.csv",
            "--method",
            "fancy",
        ],
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("unknown method `fancy`"));
    let out = robocal(&dir, &["demo", "nothing"]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("unknown demo"));
    std::fs::remove_dir_all(&dir).ok();
}

/// A compensator method from the command line: `--train` is the training pool,
/// the comparison table has its column, `--save` writes the compensator
/// (format 2) and `solve --model` uses it: each solution lands on its target
/// through the compensated prediction of the saved file.
#[test]
fn compensator_method_saves_and_solves() {
    let dir = std::env::temp_dir().join(format!("robocal-cli-comp-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (set, n, seed) in [("identification", "40", "1"), ("training", "80", "2")] {
        let a = robocal(
            &dir,
            &[
                "simulate",
                "--poses",
                n,
                "--seed",
                seed,
                "--set",
                set,
                "--gear-error",
                "0.01,1",
                "--out",
                &format!("{set}.csv"),
            ],
        );
        assert!(a.status.success(), "{}", String::from_utf8_lossy(&a.stderr));
    }
    let out = robocal(
        &dir,
        &[
            "calibrate",
            "--model",
            "ys100",
            "--identify",
            "identification.csv",
            "--train",
            "training.csv",
            "--method",
            "skcm,skcm-nn",
            "--cv-folds",
            "0",
            "--save",
            "cal.json",
            "--save-method",
            "skcm-nn",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("training (Q2)") && text.contains("Compensators"),
        "{text}"
    );
    assert!(text.contains("on 80 training poses"), "{text}");
    let file = std::fs::read_to_string(dir.join("cal.json")).unwrap();
    let model = robocal_core::model::calibrated::parse_compensated(&file).unwrap();
    assert!(model.compensator.is_some());
    let nominal = robocal::model::preset("ys100").unwrap();
    let mut rng = <rand_chacha::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(9);
    let qs = robocal::sim::random_configurations(&nominal, 5, &mut rng);
    let mut targets = String::from("id,x,y,z\n");
    let mut want = Vec::new();
    for (i, q) in qs.iter().enumerate() {
        let p = model.predict(q).unwrap().p * 1e3;
        targets.push_str(&format!("t{i},{},{},{}\n", p.x, p.y, p.z));
        want.push(p);
    }
    std::fs::write(dir.join("targets.csv"), targets).unwrap();
    let v = robocal_json(
        &dir,
        &[
            "solve",
            "--model",
            "cal.json",
            "--targets",
            "targets.csv",
            "--position-only",
            "--json",
        ],
    );
    let results = v["targets"].as_array().unwrap_or_else(|| panic!("{v}"));
    assert_eq!(results.len(), 5);
    assert!(v["solved"].as_u64() >= Some(4), "{v}");
    for (r, p) in results.iter().zip(&want) {
        if r["status"] != "ok" {
            continue;
        }
        let deg: Vec<f64> = serde_json::from_value(r["joints_deg"].clone()).unwrap();
        let q =
            nominal.joints_from_controller(&deg.iter().map(|d| d.to_radians()).collect::<Vec<_>>());
        let reached = model.predict(&q).unwrap().p * 1e3;
        assert!((reached - p).norm() < 1e-3, "{} mm", (reached - p).norm());
    }
    // The same file with one network weight out of its bound: refused,
    // naming the field, its value and the bound.
    let mut hostile: serde_json::Value = serde_json::from_str(&file).unwrap();
    hostile["compensator"]["weights"][3] = 1e308.into();
    std::fs::write(dir.join("hostile.json"), hostile.to_string()).unwrap();
    let out = robocal(
        &dir,
        &[
            "solve",
            "--model",
            "hostile.json",
            "--targets",
            "targets.csv",
        ],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(
        err.contains("`compensator.weights[3]`")
            && err.contains("1e308")
            && err.contains("[-1e12, 1e12]"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
