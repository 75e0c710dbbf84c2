//! Identification of a linear track ([`fit::fit_track`]): the robot it
//! carries measured by a tracker at several robot poses at each of several
//! track values (a measurement set with the track's external-axis column),
//! the robot's calibrated model held. Per station the base's pose and its
//! σ ([`station`]); the rail's line, scale and zero; the carriage's maps
//! with their orders cross-validated over the stations ([`series`]); the
//! fit judged before it is stored and the outcome typed ([`outcome`]).
//!
//! Frames and units: `model::external::track` and each file's header.

pub mod fit;
pub mod outcome;
pub mod series;
pub mod station;

pub use fit::{
    fit_track, fit_track_compensated, DEFAULT_MAX_ORDER, MIN_ACROSS_MM, MIN_POSES, MIN_STATIONS,
};
pub use outcome::{
    MapReport, OrderScore, StationReport, TrackFit, TrackFitRequest, TrackRefusalReason,
    TrackRefused, Unseen, UnseenTerm,
};
