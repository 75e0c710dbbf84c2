//! The check every program fuzz target runs: the input is one file, or two
//! split at the first NUL byte (named `names`); parsing never panics, every
//! target's value ranges and every motion's mark lie inside its file, and a
//! program that parses filters (on the nominal model, no tool or work object
//! in the cell) without panicking.
use robocal::solve::cell::Cell;
use robocal::model::calibrated::CompensatedModel;
use robocal::solve::ik::IkSettings;
use robocal::program::{filter, parse, Language, ProgramFile};

pub fn check(language: Language, names: [&str; 2], data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let mut parts = text.splitn(2, '\0');
    let files: Vec<ProgramFile> = names
        .iter()
        .zip(&mut parts)
        .map(|(name, text)| ProgramFile {
            name: name.to_string(),
            text: text.to_string(),
        })
        .collect();
    let Ok(program) = parse(language, &files) else {
        return;
    };
    for s in &program.sites {
        let t = &files[s.file].text;
        for r in s.slots.iter().chain([&s.mark_at]) {
            assert!(r.start <= r.end && t.is_char_boundary(r.start) && t.is_char_boundary(r.end));
        }
    }
    for m in &program.motions {
        let (t, r) = (&files[m.file].text, &m.mark_at);
        assert!(r.start <= r.end && t.is_char_boundary(r.start) && t.is_char_boundary(r.end));
    }
    if program.sites.len() <= 8 {
        let model = CompensatedModel::from_nominal(robocal::model::preset("ur5").unwrap());
        let _ = filter(language, &files, &Cell::default(), &model, &IkSettings::default());
    }
}
