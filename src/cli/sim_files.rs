//! What the `simulate` commands (`positioner simulate`, `track simulate`)
//! share: the tracker noise's check, the output directory and its files,
//! and the listing they print.

use anyhow::Context;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Refuses a tracker noise [mm] that is not a non-negative number.
pub(crate) fn check_noise(noise_mm: f64) -> anyhow::Result<()> {
    if !(noise_mm.is_finite() && noise_mm >= 0.0) {
        anyhow::bail!("--noise-mm {noise_mm}: give a non-negative number of mm");
    }
    Ok(())
}

/// The directory the files are written into (created when missing).
pub(crate) struct OutDir(PathBuf);

impl OutDir {
    /// `path`, created with its parents.
    pub(crate) fn create(path: &str) -> anyhow::Result<Self> {
        std::fs::create_dir_all(path).with_context(|| format!("cannot create {path}"))?;
        Ok(OutDir(Path::new(path).to_path_buf()))
    }

    /// Writes `text` to the file `name` in it; the path as printed.
    pub(crate) fn write(&self, name: &str, text: &str) -> anyhow::Result<String> {
        let path = self.0.join(name);
        std::fs::write(&path, text).with_context(|| format!("cannot write {}", path.display()))?;
        Ok(path.display().to_string())
    }
}

/// What a target left out of a simulated program says.
pub(crate) fn left_out_note(target: &str) -> String {
    format!(
        "left out of part.src: {target} (out of the nominal robot's reach with the torch pointing into the part)"
    )
}

/// Appends a `wrote PATH` line per file written, then the notes.
pub(crate) fn list(out: &mut String, written: &[String], notes: &[String]) {
    for w in written {
        let _ = writeln!(out, "wrote {w}");
    }
    for note in notes {
        let _ = writeln!(out, "{note}");
    }
}
