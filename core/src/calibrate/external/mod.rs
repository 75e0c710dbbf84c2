//! Identification of external axes from tracker data: a linear track
//! carrying the robot ([`track`]), its readings a measurement set with the
//! track's column; and a two-axis tilt-rotate
//! positioner ([`fit::fit_positioner`]): reflectors on its face plate read by
//! a tracker at several values of each axis with the other held; a circle per
//! sweep gives each axis's line as a start ([`circle`]); one least-squares fit
//! over every reading gives both lines, zero offsets and scales and the
//! reflectors' positions ([`problem`]), with residuals and σ; the fit is
//! judged before it is stored ([`judge`]) and the outcome is typed
//! ([`outcome`], its refusal's shape shared with the track's:
//! [`refusal`]); its readings can come from measurement sets with the axes'
//! columns ([`readings`]).
//!
//! Frames: readings in the cell (tracker) frame; the nominal model places the
//! positioner base in it; lines of axis 1 in the base frame, of axis 2 in the
//! tilt frame (docs/external-axes/positioner.md). Units: mm and degrees in the inputs
//! and reports, m and rad inside.

pub mod circle;
pub mod fit;
pub mod judge;
pub mod outcome;
pub mod problem;
pub mod readings;
pub mod refusal;
pub mod track;
pub mod turntable;

pub use fit::fit_positioner;
pub use outcome::{
    Axis, AxisSigma, CircleReport, FitLimits, PositionerFit, PositionerFitRequest,
    PositionerReading, RefusalReason, Refused, SolverOutcome,
};
pub use refusal::Refusal;
