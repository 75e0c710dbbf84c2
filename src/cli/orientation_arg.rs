//! `--orientation`: the convention of a measurement file's orientation
//! columns, one of [`MeasuredOrientation`]'s names (the possible values and
//! their help come from the enum).

use crate::measure::convention::MeasuredOrientation;
use clap::builder::{PossibleValue, TypedValueParser};
use clap::error::ErrorKind;

/// Parses `--orientation` into a [`MeasuredOrientation`].
#[derive(Debug, Clone, Copy)]
pub struct OrientationValues;

impl TypedValueParser for OrientationValues {
    type Value = MeasuredOrientation;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<MeasuredOrientation, clap::Error> {
        let text = value.to_string_lossy();
        MeasuredOrientation::from_name(&text).ok_or_else(|| {
            let arg = arg.map_or_else(|| "--orientation".to_string(), |a| a.to_string());
            clap::Error::raw(
                ErrorKind::InvalidValue,
                format!(
                    "invalid value '{text}' for '{arg}': expected one of {}\n",
                    MeasuredOrientation::names()
                ),
            )
            .with_cmd(cmd)
        })
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        Some(Box::new(
            MeasuredOrientation::ALL
                .into_iter()
                .map(|c| PossibleValue::new(c.name()).help(c.meaning())),
        ))
    }
}

/// Reads a measurement CSV with `orientation` declared (`None`: from the header).
pub fn read_measurements(
    path: &std::path::Path,
    read: crate::measure::csv::ReadOptions,
) -> anyhow::Result<Vec<crate::measure::MeasuredPose>> {
    use anyhow::Context;
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    crate::measure::csv::parse_opts(&text, &read).with_context(|| path.display().to_string())
}

/// Reads a measurement CSV carrying a track's column `track`, each
/// reading in the tracker session of its station
/// (`MeasurementSet::stations_as_sessions`).
pub fn read_stations(
    path: &std::path::Path,
    read: crate::measure::csv::ReadOptions,
    track: crate::measure::external::ExternalAxis,
) -> anyhow::Result<Vec<crate::measure::MeasuredPose>> {
    use anyhow::Context;
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    let set = crate::measure::csv::parse_set_opts(&text, &read)
        .with_context(|| path.display().to_string())?;
    set.stations_as_sessions(track)
        .with_context(|| format!("{} (--track-column {track})", path.display()))
}
