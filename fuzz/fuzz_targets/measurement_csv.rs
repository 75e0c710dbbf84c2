//! The measurement CSV parser: never panics; what it accepts is finite and
//! survives a write/parse round trip unchanged, with its external-axis
//! columns too.
#![no_main]
use libfuzzer_sys::fuzz_target;
use robocal::measure::csv;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(rows) = csv::parse(text) {
        for r in &rows {
            assert!(r.q_deg.iter().chain(&r.xyz_mm).all(|v| v.is_finite()));
        }
        let again = csv::parse(&csv::write(&rows)).expect("written CSV parses");
        assert_eq!(again, rows, "round trip changed the rows");
    }
    if let Ok(set) = csv::parse_set(text) {
        assert!(set.external.iter().all(|e| e.0.iter().flatten().all(|v| v.is_finite())));
        let again = csv::parse_set(&csv::write_set(&set)).expect("written set parses");
        assert_eq!(again, set, "round trip changed the set");
    }
});
