//! The measurement plan's CSV reader and the tracker export join
//! (`robocal plan join`): never panic; a joined set writes a measurement CSV
//! that reads back to the same rows whenever the measurement reader accepts it.
//! Input: the plan CSV, a NUL byte, the tracker export.
#![no_main]
use libfuzzer_sys::fuzz_target;
use robocal::measure::csv;
use robocal::plan::{join, read_plan_csv, JoinBy, JoinOptions, Units};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let (plan, export) = text.split_once('\0').unwrap_or((text, text));
    let Ok(points) = read_plan_csv(plan) else {
        return;
    };
    for units in [Units::Detect, Units::Mm, Units::M] {
        for by in [JoinBy::Detect, JoinBy::Name, JoinBy::Order] {
            if let Ok(joined) = join(&points, export, &JoinOptions { units, by }) {
                assert_eq!(joined.rows.len(), points.len());
                if let Ok(back) = csv::parse(&csv::write(&joined.rows)) {
                    assert_eq!(back, joined.rows);
                }
            }
        }
    }
});
