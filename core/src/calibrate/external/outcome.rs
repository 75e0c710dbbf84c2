//! What a positioner fit takes and gives: the tracker readings and the
//! request (inputs, mm and degrees as measured), the fit with its residuals
//! and σ, and the refusal with its reason (a closed set) when the fit is not
//! one to store.
//!
//! Frames: readings are in the cell (tracker) frame, in which the nominal
//! model's `cell_from_base` places the positioner base; reflector positions
//! are in the face plate frame.

use super::refusal::{Reason, Refusal};
use crate::model::external::{TiltRotate, TiltRotateDescription};
use crate::optim::lm::StopReason;
use serde::Serialize;

/// The positioner's axes (a closed set; reports and σ derive from it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Axis {
    /// Axis 1.
    Tilt,
    /// Axis 2, carried by axis 1.
    Rotate,
}

impl Axis {
    /// Both axes, axis 1 first.
    pub const ALL: [Axis; 2] = [Axis::Tilt, Axis::Rotate];

    /// 0 for the tilt, 1 for the rotate axis (the column of the values).
    pub fn index(self) -> usize {
        match self {
            Axis::Tilt => 0,
            Axis::Rotate => 1,
        }
    }

    /// The axis as reports name it.
    pub fn name(self) -> &'static str {
        match self {
            Axis::Tilt => "axis 1 (tilt)",
            Axis::Rotate => "axis 2 (rotate)",
        }
    }
}

/// One tracker reading of a reflector on the face plate.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PositionerReading {
    /// Which reflector (index into [`PositionerFitRequest::reflectors_mm`]).
    pub reflector: usize,
    /// Controller values of axis 1 and axis 2 [deg].
    pub values_deg: [f64; 2],
    /// Measured position in the cell frame [mm].
    pub xyz_mm: [f64; 3],
}

/// A positioner fit's inputs.
#[derive(Debug, Clone, PartialEq)]
pub struct PositionerFitRequest {
    /// The nominal model: the start, the base frame in the cell frame and the
    /// face plate frame the reflectors are stated in.
    pub nominal: TiltRotate,
    /// The reflectors' design positions in the face plate frame [mm]. The
    /// first is the reference: its azimuth about axis 2 is held at the design
    /// one, which defines axis 2's zero (docs/external-axes/positioner.md).
    pub reflectors_mm: Vec<[f64; 3]>,
    /// The tracker readings, every reflector at every pair of values.
    pub readings: Vec<PositionerReading>,
    /// The tracker's noise per coordinate, 1σ [mm]: the residuals are judged
    /// against it.
    pub tracker_sigma_mm: f64,
}

/// 1σ of one axis's parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct AxisSigma {
    /// The axis these σ are of.
    pub axis: Axis,
    /// Of the direction [deg]: axis 1's two tilts combined; axis 2's tilt
    /// toward axis 1 (its turn about axis 1 is axis 1's zero offset).
    pub direction_deg: f64,
    /// Of the line's position across it (both directions combined) [mm].
    pub point_mm: f64,
    /// Of the zero offset [deg].
    pub zero_offset_deg: f64,
    /// Of the scale (dimensionless).
    pub scale: f64,
}

/// One circle of a reflector while one axis turned and the other was held.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CircleReport {
    /// The axis that turned.
    pub axis: Axis,
    /// The reflector read (index into the request's reflectors).
    pub reflector: usize,
    /// The other axis's value [deg].
    pub held_deg: f64,
    /// Distinct values of the turning axis.
    pub angles: usize,
    /// Their span [deg].
    pub span_deg: f64,
    /// The circle's radius [mm].
    pub radius_mm: f64,
    /// RMS distance of the readings from the circle [mm].
    pub rms_mm: f64,
}

/// How the least-squares run ended.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SolverOutcome {
    /// Whether a convergence test passed.
    pub converged: bool,
    /// Iterations run.
    pub iterations: usize,
    /// Why the run stopped.
    pub reason: StopReason,
    /// The stop in words.
    pub detail: String,
    /// RMS of the 3-D residuals at the start (circle fits) [mm].
    pub start_rms_mm: f64,
}

/// The bounds the fit was judged against.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FitLimits {
    /// Tracker noise per coordinate [mm].
    pub sigma_mm: f64,
    /// Largest RMS of the 3-D residuals [mm].
    pub rms_mm: f64,
    /// Largest single 3-D residual [mm].
    pub max_mm: f64,
}

/// A fitted positioner.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PositionerFit {
    /// The calibrated model.
    #[serde(skip)]
    pub model: TiltRotate,
    /// The calibrated model as stored.
    pub description: TiltRotateDescription,
    /// The reflectors' fitted positions in the face plate frame [mm].
    pub reflectors_mm: Vec<[f64; 3]>,
    /// 1σ of each reflector's position (3-D) [mm].
    pub reflector_sigma_mm: Vec<f64>,
    /// 1σ of each axis's parameters, axis 1 first.
    pub sigma: [AxisSigma; 2],
    /// Each reading's 3-D residual [mm].
    pub residual_mm: Vec<f64>,
    /// RMS of the 3-D residuals [mm].
    pub rms_mm: f64,
    /// Largest 3-D residual [mm].
    pub max_mm: f64,
    /// Each sweep's circle (the start of the fit).
    pub circles: Vec<CircleReport>,
    /// How the least-squares run ended.
    pub solver: SolverOutcome,
    /// The bounds the fit was judged against.
    pub limits: FitLimits,
}

/// Why a positioner was not fitted (a closed set). `measured` and `needed`
/// of a [`Refused`] carry the figure each names, in the unit given here.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RefusalReason {
    /// A value is not finite, or the tracker σ is not positive.
    NotFinite,
    /// No reflectors, or a reading names one that is not given.
    UnknownReflector,
    /// An axis turned through too few distinct values with the other held (values).
    TooFewAngles,
    /// An axis's sweep spans too little to see its scale (deg).
    SpanTooSmall,
    /// A reflector is too near the axis it turned about (mm).
    ReflectorNearAxis,
    /// The readings do not determine every parameter (condition number).
    Singular,
    /// The least-squares run did not pass a convergence test.
    NotConverged,
    /// The residuals' RMS is beyond the tracker's noise (mm).
    ResidualsTooLarge,
    /// One reading's residual is beyond the tracker's noise (mm).
    ResidualOutlier,
}

/// A positioner fit refused before it is stored (the shape every external
/// axis fit's refusal shares, [`Refusal`]).
pub type Refused = Refusal<RefusalReason, PositionerFit>;

impl Reason for RefusalReason {
    const NAMES_STATIONS: bool = false;
}
