//! The command line end to end: simulate → calibrate (table and JSON), and errors.

use std::process::Command;

fn robocal(args: &[&str], dir: &std::path::Path) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_robocal"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

#[test]
fn simulate_then_calibrate_json_is_scriptable() {
    let dir = std::env::temp_dir().join(format!("robocal-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let a = robocal(
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
        &dir,
    );
    assert!(a.status.success(), "{}", String::from_utf8_lossy(&a.stderr));
    let b = robocal(
        &[
            "simulate", "--preset", "ys100", "--poses", "20", "--seed", "2", "--out", "q2.csv",
        ],
        &dir,
    );
    assert!(b.status.success());
    let out = robocal(
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
        &dir,
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
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
        &[
            "calibrate",
            "--model",
            "truth.json",
            "--identify",
            "q1.csv",
            "--method",
            "km",
        ],
        &dir,
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
        &["calibrate", "--model", "ys100", "--identify", "bad.csv"],
        &dir,
    );
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("line 2"), "{err}");
    let out = robocal(
        &["calibrate", "--model", "kr16", "--identify", "bad.csv"],
        &dir,
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("unknown robot preset"));
    let out = robocal(
        &[
            "calibrate",
            "--model",
            "ys100",
            "--identify",
            "bad.csv",
            "--method",
            "fancy",
        ],
        &dir,
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("unknown method `fancy`"));
    let out = robocal(&["demo", "nothing"], &dir);
    assert!(String::from_utf8_lossy(&out.stderr).contains("unknown demo"));
    std::fs::remove_dir_all(&dir).ok();
}
