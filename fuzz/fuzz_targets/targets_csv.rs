//! The targets CSV parser of `robocal solve`: never panics, and every target
//! it accepts turns into a goal or a per-target error without panicking.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(parsed) = robocal::cli::solve::parse_targets_csv(text) {
        for row in &parsed.rows {
            if let Ok(t) = &row.target {
                let _ = t.to_goal();
            }
        }
    }
});
