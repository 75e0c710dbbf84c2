//! Identification of a one-axis turntable from tracker readings of
//! reflectors on its face plate at several values of its axis: a circle per
//! reflector gives the axis's line as a start (`super::circle`); one
//! least-squares fit over every reading gives the line, the zero offset, the
//! scale and the reflectors' positions ([`problem`]), with residuals and σ;
//! the fit is judged before it is written as a positioner's is
//! (`super::judge`: enough values, span, radius, residuals against the
//! tracker's noise), and the outcome is typed ([`outcome`]).
//!
//! Frames: readings in the cell (tracker) frame; the nominal model places
//! the turntable's base in it; the axis's line in the base frame
//! (`model::external::turntable`). Units: mm and degrees in the inputs and
//! reports, m and rad inside.

pub mod fit;
pub mod outcome;
pub mod problem;

pub use fit::{fit_turntable, held_out_errors_mm};
pub use outcome::{TurntableFit, TurntableFitRequest, TurntableReading, TurntableRefused};
