//! The targets CSV parser shared by `robocal solve` and the service's
//! `text/csv` solve: never panics, and every target it accepts turns into a
//! goal or a per-target error without panicking.
#![no_main]
use libfuzzer_sys::fuzz_target;
use robocal::measure::csv_text::Dialect;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(parsed) = robocal::solve::ik::parse_targets_csv(text, Dialect::default()) {
        for row in &parsed.rows {
            if let Ok(t) = &row.target {
                let _ = t.to_goal();
            }
        }
    }
});
