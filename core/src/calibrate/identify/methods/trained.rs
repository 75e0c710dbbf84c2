//! A trained compensator ([`Trained`]: its stored form, orientation part,
//! support, training report and cross-validation) and the compensator a
//! method applies on top of its base's fit ([`AppliedCompensator`]).
//! Supports are in joint space [rad] and fade over [`SUPPORT_FADE_RAD`].

use super::{Base, Method};
use crate::calibrate::compensate::{CvStats, Sample, TrainReport};
use crate::calibrate::identify::report::OrientationPart;
use crate::model::calibrated::{StoredCompensator, StoredOrientation, Support};

/// A trained compensator with its training report and cross-validation.
#[derive(Clone)]
pub(crate) struct Trained {
    pub stored: StoredCompensator,
    /// Its orientation part, where the pool measured orientations.
    pub orientation: Option<StoredOrientation>,
    /// Why it has an orientation part or not, and its cross-validation.
    pub orientation_part: OrientationPart,
    /// Where it was trained: its correction fades to zero beyond it.
    pub support: Support,
    pub report: TrainReport,
    pub cv: Option<CvStats>,
}

/// A trained compensator on top of the fit of its base.
pub(crate) struct AppliedCompensator {
    pub method: Method,
    pub base: Base,
    pub trained: Trained,
}

/// The support of training samples, with the joint maps' fade width.
pub(crate) fn support_of(samples: &[Sample]) -> Support {
    let qs: Vec<&[f64]> = samples.iter().map(|s| s.q.as_slice()).collect();
    Support::of(&qs, SUPPORT_FADE_RAD)
}

/// Width of a compensator's fade beyond its trained joint ranges [rad] (5°).
pub(crate) const SUPPORT_FADE_RAD: f64 = 5.0 * std::f64::consts::PI / 180.0;
