//! The sample programs of examples/programs filter completely on a calibrated
//! model (synthetic errors), and only their target values change.

use super::*;
use robocal_core::program::{filter, TargetStatus};
use robocal_core::sim::{synthetic_calibration, SyntheticErrors};
use robocal_core::solve::cell::CellDescription;
use std::path::Path;

pub fn read(rel: &str) -> ProgramFile {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/programs")
        .join(rel);
    ProgramFile {
        name: rel.rsplit('/').next().unwrap().to_string(),
        text: std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display())),
    }
}

pub fn cell(rel: &str) -> Cell {
    CellDescription::from_json(&read(rel).text)
        .unwrap()
        .to_cell()
        .unwrap()
}

#[test]
fn sample_programs_filter() {
    let ys100 = synthetic_calibration(
        &preset("ys100").unwrap(),
        &SyntheticErrors::typical(1e-6),
        3,
    );
    let ur5 = synthetic_calibration(&preset("ur5").unwrap(), &SyntheticErrors::typical(1e-6), 3);
    let cases = [
        (
            Language::Krl,
            vec![read("krl/seam.src"), read("krl/seam.dat")],
            cell("cell.json"),
            &ys100,
            6,
            1,
        ),
        (
            Language::Rapid,
            vec![read("rapid/Seam.mod")],
            Cell::default(),
            &ys100,
            5,
            0,
        ),
        (
            Language::Fanuc,
            vec![read("fanuc/SEAM.LS")],
            cell("cell.json"),
            &ys100,
            5,
            0,
        ),
        (
            Language::UrScript,
            vec![read("urscript/seam.script")],
            Cell::default(),
            &ur5,
            5,
            0,
        ),
    ];
    for (language, files, cell, model, filtered, skipped) in cases {
        let out = filter(language, &files, &cell, model, &settings()).unwrap();
        let r = &out.report;
        assert_eq!(
            (r.filtered, r.failed, r.skipped),
            (filtered, 0, skipped),
            "{language:?}: {:?}",
            r.targets
        );
        for t in &r.targets {
            if t.status == TargetStatus::Filtered {
                let shift = t.shift_mm.unwrap();
                assert!(
                    shift > 0.1 && shift < 20.0,
                    "{language:?} {}: {shift} mm",
                    t.name
                );
            }
        }
        assert_only_targets_changed(language, &files, &out.files);
    }
}
