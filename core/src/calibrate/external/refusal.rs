//! A fit of an external axis refused before it is stored: the shape the
//! positioner's and the track's refusals share. Each fit names its own
//! reasons (a closed set per fit: `outcome::RefusalReason`,
//! `track::outcome::TrackRefusalReason`) and its own fit; the message, the
//! figures (in the unit the reason names), the reading and, for a track, the
//! station are carried alike.

use serde::Serialize;

/// A fit's closed set of refusal reasons.
pub trait Reason {
    /// Whether a refusal of this fit can name a station (a track value): the
    /// `station_mm` field is written only for fits that have stations.
    const NAMES_STATIONS: bool;
}

/// A fit refused before it is stored: why, in words a user can act on, the
/// figures, the station or reading it names, and the fit itself when one
/// was made.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(bound(serialize = "R: Serialize + Reason, F: Serialize"))]
pub struct Refusal<R, F> {
    /// Why, from the fit's closed set.
    pub reason: R,
    /// What is wrong and what to do, in words.
    pub message: String,
    /// The figure measured, in the unit the reason names.
    pub measured: Option<f64>,
    /// The bound it failed, in the same unit.
    pub needed: Option<f64>,
    /// The station's value [mm] the refusal names (fits with stations only).
    #[serde(skip_serializing_if = "without_stations::<R>")]
    pub station_mm: Option<f64>,
    /// The reading (1-based, in the request or set) the refusal names.
    pub row: Option<usize>,
    /// The fit, when one was made before it was judged.
    pub fit: Option<Box<F>>,
}

fn without_stations<R: Reason>(_: &Option<f64>) -> bool {
    !R::NAMES_STATIONS
}

impl<R, F> Refusal<R, F> {
    /// A refusal for `reason`, saying `message`.
    pub fn new(reason: R, message: String) -> Self {
        Refusal {
            reason,
            message,
            measured: None,
            needed: None,
            station_mm: None,
            row: None,
            fit: None,
        }
    }

    /// With the figure measured and the bound it failed.
    pub fn figures(mut self, measured: f64, needed: f64) -> Self {
        self.measured = Some(measured);
        self.needed = Some(needed);
        self
    }

    /// Naming the reading (1-based).
    pub fn at_row(mut self, row: usize) -> Self {
        self.row = Some(row);
        self
    }

    /// With the fit that was judged.
    pub fn with_fit(mut self, fit: F) -> Self {
        self.fit = Some(Box::new(fit));
        self
    }
}

impl<R: Reason, F> Refusal<R, F> {
    /// Names the station (track value, mm) the refusal is about.
    pub fn at_station(mut self, value_mm: f64) -> Self {
        debug_assert!(R::NAMES_STATIONS, "this fit has no stations");
        self.station_mm = Some(value_mm);
        self
    }
}

impl<R, F> std::fmt::Display for Refusal<R, F> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl<R: std::fmt::Debug, F: std::fmt::Debug> std::error::Error for Refusal<R, F> {}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Serialize)]
    enum WithStations {
        A,
    }
    impl Reason for WithStations {
        const NAMES_STATIONS: bool = true;
    }
    #[derive(Debug, Serialize)]
    enum WithoutStations {
        B,
    }
    impl Reason for WithoutStations {
        const NAMES_STATIONS: bool = false;
    }

    /// The station field is written (null when unset) only for fits with
    /// stations, so each fit's refusal keeps its own shape.
    #[test]
    fn the_station_is_written_only_for_fits_with_stations() {
        let t = Refusal::<_, ()>::new(WithStations::A, "m".into()).figures(1.0, 2.0);
        let j = serde_json::to_value(&t).unwrap();
        assert_eq!(j["station_mm"], serde_json::Value::Null);
        assert!(j.as_object().unwrap().contains_key("station_mm"));
        let p = Refusal::<_, ()>::new(WithoutStations::B, "m".into()).at_row(3);
        let j = serde_json::to_value(&p).unwrap();
        assert!(!j.as_object().unwrap().contains_key("station_mm"));
        assert_eq!(j["row"], 3);
        assert_eq!(p.to_string(), "m");
    }
}
