//! A linear track carrying a robot, as stored: the calibrated track's JSON
//! description and what its fit was made on and judged against.

use sqlx::FromRow;

/// A fitted track to store for a robot (replacing the one it has).
#[derive(Debug, Clone, PartialEq)]
pub struct NewTrack {
    /// The model version the fit held (its number).
    pub version: i64,
    /// The measurement file's column of the track's value, `e1` … `e6`.
    pub axis_column: String,
    /// The tracker's σ per coordinate the fit was judged against [mm].
    pub sigma_mm: f64,
    /// The highest carriage-map order tried.
    pub max_order: i64,
    /// The readings the fit used.
    pub readings: i64,
    /// The track positions (stations) the readings were taken at.
    pub stations: i64,
    /// RMS of the fit's residuals [mm].
    pub rms_mm: f64,
    /// Largest residual of the fit [mm].
    pub max_mm: f64,
    /// `LinearTrack::to_json`: mm, degrees, arcsec.
    pub track_json: String,
    /// The station sets it was fitted from, a JSON array of ids (`None`: a
    /// posted file).
    pub set_ids: Option<String>,
    /// The calibrate request that fitted it, as JSON (`GET …/fit-request`).
    pub fit_request: String,
}

/// A robot's stored track.
#[derive(Debug, Clone, FromRow)]
pub struct TrackRow {
    /// The robot the track carries.
    pub robot_id: i64,
    /// The model version the fit held (its number).
    pub version: i64,
    /// The measurement file's column of the track's value, `e1` … `e6`.
    pub axis_column: String,
    /// The tracker's σ per coordinate the fit was judged against [mm].
    pub sigma_mm: f64,
    /// The highest carriage-map order tried.
    pub max_order: i64,
    /// The readings the fit used.
    pub readings: i64,
    /// The track positions (stations) the readings were taken at.
    pub stations: i64,
    /// RMS of the fit's residuals [mm].
    pub rms_mm: f64,
    /// Largest residual of the fit [mm].
    pub max_mm: f64,
    /// `LinearTrack::to_json`: mm, degrees, arcsec.
    pub track_json: String,
    /// When it was stored (UTC, RFC 3339).
    pub created_at: String,
    /// The station sets it was fitted from, a JSON array of ids (`None`: a
    /// posted file).
    pub set_ids: Option<String>,
}

impl TrackRow {
    /// The station sets it was fitted from (`None`: a posted file), read
    /// from their stored JSON array.
    pub fn fitted_from_sets(&self) -> Result<Option<Vec<i64>>, serde_json::Error> {
        self.set_ids
            .as_deref()
            .map(serde_json::from_str)
            .transpose()
    }
}
