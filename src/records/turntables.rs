//! A one-axis turntable beside a robot, as stored: the calibrated
//! turntable's JSON description and what its fit was made on (tracker
//! readings of reflectors on its face plate) and judged against.

use sqlx::FromRow;

/// A fitted turntable to store for a robot (replacing the one it has).
#[derive(Debug, Clone, PartialEq)]
pub struct NewTurntable {
    /// The measurement files' column of the axis's value, `e1` … `e6`.
    pub value_column: String,
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
    /// `Turntable::to_json`: mm, degrees.
    pub turntable_json: String,
    /// The calibrate request that fitted it, as JSON (`GET …/fit-request`).
    pub fit_request: String,
}

/// A robot's stored turntable.
#[derive(Debug, Clone, FromRow)]
pub struct TurntableRow {
    /// The robot whose cell holds the turntable.
    pub robot_id: i64,
    /// The measurement files' column of the axis's value, `e1` … `e6`.
    pub value_column: String,
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
    /// `Turntable::to_json`: mm, degrees.
    pub turntable_json: String,
    /// When it was stored (UTC, RFC 3339).
    pub created_at: String,
}
