//! The URScript program parser and the filter never panic (`common/program.rs`).
#![no_main]
use libfuzzer_sys::fuzz_target;
use robocal::program::Language;

#[path = "../common/program.rs"]
mod program;

fuzz_target!(|data: &[u8]| program::check(Language::UrScript, ["a.script", "b.script"], data));
