//! What a turntable fit takes and gives: the tracker readings and the
//! request (mm and degrees as measured), the fit with its residuals and σ,
//! and the refusal (the positioner's closed set of reasons) when the fit is
//! not one to write.
//!
//! Frames: readings in the cell (tracker) frame, in which the nominal
//! model's `cell_from_base` places the turntable's base; reflector positions
//! in the face plate frame.

use super::super::outcome::{AxisSigma, CircleReport, FitLimits, RefusalReason, SolverOutcome};
use super::super::refusal::Refusal;
use crate::model::external::{Turntable, TurntableDescription};
use serde::Serialize;

/// One tracker reading of a reflector on the face plate.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TurntableReading {
    /// Which reflector (index into [`TurntableFitRequest::reflectors_mm`]).
    pub reflector: usize,
    /// The axis's controller value [deg].
    pub value_deg: f64,
    /// Measured position in the cell frame [mm].
    pub xyz_mm: [f64; 3],
}

/// A turntable fit's inputs.
#[derive(Debug, Clone, PartialEq)]
pub struct TurntableFitRequest {
    /// The nominal model: the start, the base frame in the cell frame and the
    /// face plate frame the reflectors are stated in.
    pub nominal: Turntable,
    /// The reflectors' design positions in the face plate frame [mm]; the
    /// first is the reference, whose azimuth about the axis defines its zero.
    pub reflectors_mm: Vec<[f64; 3]>,
    /// The tracker readings.
    pub readings: Vec<TurntableReading>,
    /// The tracker's noise per coordinate, 1σ [mm]: the residuals are judged
    /// against it.
    pub tracker_sigma_mm: f64,
}

/// A fitted turntable.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TurntableFit {
    /// The calibrated model.
    #[serde(skip)]
    pub model: Turntable,
    /// The calibrated model as stored.
    pub description: TurntableDescription,
    /// The reflectors' fitted positions in the face plate frame [mm].
    pub reflectors_mm: Vec<[f64; 3]>,
    /// 1σ of each reflector's position (3-D) [mm].
    pub reflector_sigma_mm: Vec<f64>,
    /// 1σ of the axis's parameters (`axis`: `rotate`, the one axis turned).
    pub sigma: AxisSigma,
    /// Each reading's 3-D residual [mm].
    pub residual_mm: Vec<f64>,
    /// RMS of the 3-D residuals [mm].
    pub rms_mm: f64,
    /// Largest 3-D residual [mm].
    pub max_mm: f64,
    /// Each reflector's circle (the start of the fit; `held_deg` 0).
    pub circles: Vec<CircleReport>,
    /// How the least-squares run ended.
    pub solver: SolverOutcome,
    /// The bounds the fit was judged against.
    pub limits: FitLimits,
}

/// A turntable fit refused before it is written.
pub type TurntableRefused = Refusal<RefusalReason, TurntableFit>;
