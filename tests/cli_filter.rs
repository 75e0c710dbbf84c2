//! `robocal filter` on the sample programs: filtered files and a JSON report
//! written, only target values changed, a parse error names file, line and column.

use clap::Parser;
use robocal::cli::filter::{filter_to_string, FilterArgs};
use robocal::cli::model_files::save_model_file;
use robocal::model::preset;
use robocal::program::{parse, Language, ProgramFile};
use robocal::sim::{synthetic_calibration, SyntheticErrors};
use robocal_core::model::calibrated::CalibratedModelFile;
use std::path::{Path, PathBuf};

fn examples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/programs")
}

fn args(argv: &[&str]) -> FilterArgs {
    let mut v = vec!["robocal", "filter"];
    v.extend_from_slice(argv);
    match robocal::cli::Cli::try_parse_from(v).unwrap().command {
        robocal::cli::Command::Filter(a) => a,
        other => panic!("{other:?}"),
    }
}

fn file(path: &Path) -> ProgramFile {
    ProgramFile {
        name: path.file_name().unwrap().to_str().unwrap().into(),
        text: std::fs::read_to_string(path).unwrap(),
    }
}

#[test]
fn filter_cli_writes_programs_and_a_report() {
    let dir = tempfile::tempdir().unwrap();
    let model = synthetic_calibration(
        &preset("ys100").unwrap(),
        &SyntheticErrors::typical(1e-6),
        3,
    );
    let model_path = dir.path().join("cal.json");
    save_model_file(
        &CalibratedModelFile::from_compensated(&model, "ys100", "km"),
        &model_path,
    )
    .unwrap();
    let out_dir = dir.path().join("out");
    let (src, dat) = (
        examples().join("krl/seam.src"),
        examples().join("krl/seam.dat"),
    );
    let cell = examples().join("cell.json");
    let report = filter_to_string(&args(&[
        "--model",
        model_path.to_str().unwrap(),
        "--cell",
        cell.to_str().unwrap(),
        "--out-dir",
        out_dir.to_str().unwrap(),
        src.to_str().unwrap(),
        dat.to_str().unwrap(),
    ]))
    .unwrap();
    let report: serde_json::Value = serde_json::from_str(&report).unwrap();
    assert_eq!(report["language"], "krl");
    assert_eq!(
        (report["filtered"].as_u64(), report["failed"].as_u64()),
        (Some(6), Some(0))
    );
    let t = &report["targets"][0];
    assert_eq!(
        (t["file"].as_str(), t["line"].as_u64()),
        (Some("seam.dat"), Some(6))
    );
    assert!(t["shift_mm"].as_f64().unwrap() > 0.1);
    // Same names; only the values of the targets differ.
    let before = [file(&src), file(&dat)];
    let after = [
        file(&out_dir.join("seam.src")),
        file(&out_dir.join("seam.dat")),
    ];
    let (a, b) = (
        parse(Language::Krl, &before).unwrap(),
        parse(Language::Krl, &after).unwrap(),
    );
    for (i, (x, y)) in before.iter().zip(&after).enumerate() {
        let mask = |f: &ProgramFile, sites: &[robocal::program::Site]| {
            let mut text = f.text.clone();
            let mut ranges: Vec<_> = sites
                .iter()
                .filter(|s| s.file == i)
                .flat_map(|s| s.slots.clone())
                .collect();
            ranges.sort_by_key(|r| std::cmp::Reverse(r.start));
            for r in ranges {
                text.replace_range(r, "#");
            }
            text
        };
        assert_ne!(x.text, y.text);
        assert_eq!(mask(x, &a.sites), mask(y, &b.sites));
    }
}

#[test]
fn filter_cli_reports_parse_errors_and_guesses_the_language() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.script");
    std::fs::write(&bad, "def f():\n  movel(p[1, 2, 3], a=1)\nend\n").unwrap();
    let out = dir.path().join("out");
    let err = filter_to_string(&args(&[
        "--model",
        "ur5",
        "--out-dir",
        out.to_str().unwrap(),
        bad.to_str().unwrap(),
    ]))
    .unwrap_err();
    assert_eq!(
        err.to_string(),
        "bad.script:2:10: a pose literal needs six numbers"
    );
    let mixed = dir.path().join("x.txt");
    std::fs::write(&mixed, "").unwrap();
    let err = filter_to_string(&args(&[
        "--model",
        "ur5",
        "--out-dir",
        out.to_str().unwrap(),
        mixed.to_str().unwrap(),
    ]))
    .unwrap_err();
    assert!(err.to_string().contains("--language"), "{err}");
}
