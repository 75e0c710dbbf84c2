//! A two-axis positioner beside a robot, as stored: the calibrated
//! positioner's JSON description and what its fit was made on (tracker
//! readings, or touches placed by a model version carrying a tool) and judged
//! against.

use sqlx::FromRow;

/// A fitted positioner to store for a robot (replacing the one it has).
#[derive(Debug, Clone, PartialEq)]
pub struct NewPositioner {
    /// The measurement files' column of axis 1 (tilt), `e1` … `e6`.
    pub tilt_column: String,
    /// The measurement files' column of axis 2 (rotate), `e1` … `e6`.
    pub rotate_column: String,
    /// The tracker's σ per coordinate the fit was judged against [mm].
    pub sigma_mm: f64,
    /// The reflectors on the face plate (one measurement file each).
    pub reflectors: i64,
    /// The readings the fit used.
    pub readings: i64,
    /// RMS of the fit's 3-D residuals [mm].
    pub rms_mm: f64,
    /// Largest 3-D residual of the fit [mm].
    pub max_mm: f64,
    /// `TiltRotate::to_json`: mm, degrees.
    pub positioner_json: String,
    /// The model version whose robot placed the touches the fit read
    /// (`None`: tracker readings).
    pub touched_version: Option<i64>,
    /// The cell tool that touched (`None`: tracker readings).
    pub touched_tool: Option<String>,
    /// The calibrate request that fitted it, as JSON (`GET …/fit-request`).
    pub fit_request: String,
}

/// A robot's stored positioner.
#[derive(Debug, Clone, FromRow)]
pub struct PositionerRow {
    /// The robot whose cell holds the positioner.
    pub robot_id: i64,
    /// The measurement files' column of axis 1 (tilt), `e1` … `e6`.
    pub tilt_column: String,
    /// The measurement files' column of axis 2 (rotate), `e1` … `e6`.
    pub rotate_column: String,
    /// The tracker's σ per coordinate the fit was judged against [mm].
    pub sigma_mm: f64,
    /// The reflectors on the face plate (one measurement file each).
    pub reflectors: i64,
    /// The readings the fit used.
    pub readings: i64,
    /// RMS of the fit's 3-D residuals [mm].
    pub rms_mm: f64,
    /// Largest 3-D residual of the fit [mm].
    pub max_mm: f64,
    /// `TiltRotate::to_json`: mm, degrees.
    pub positioner_json: String,
    /// When it was stored (UTC, RFC 3339).
    pub created_at: String,
    /// The model version whose robot placed the touches the fit read
    /// (`None`: tracker readings).
    pub touched_version: Option<i64>,
    /// The cell tool that touched (`None`: tracker readings).
    pub touched_tool: Option<String>,
}
