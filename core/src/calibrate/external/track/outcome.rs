//! What a track fit takes and gives: the request (the robot's calibrated
//! model held, a measurement set with the track's column), the fit with its
//! stations, maps, residuals and the terms the data cannot see, and the
//! refusal with its reason (a closed set) when the fit is not one to store.
//!
//! Frames: readings and stations in the cell (tracker) frame; the rail frame
//! of `model::external::track`. Units: mm, arcsec and degrees in reports, as
//! stated per field.

use crate::calibrate::external::outcome::FitLimits;
use crate::calibrate::external::refusal::{Reason, Refusal};
use crate::measure::external::{ExternalAxis, MeasurementSet};
use crate::model::external::track::{CarriageTerm, LinearTrack, TrackDescription};
use crate::model::RobotModel;
use serde::Serialize;

/// A track fit's inputs.
#[derive(Debug, Clone, Copy)]
pub struct TrackFitRequest<'a> {
    /// The robot's calibrated model, held: it maps joints to the robot base
    /// frame the track carries.
    pub robot: &'a RobotModel,
    /// Payload [kg] of rows that give none.
    pub payload_kg: f64,
    /// Readings: the reflector at several robot poses at each of several
    /// values of the track's column.
    pub set: &'a MeasurementSet,
    /// The track's column.
    pub column: ExternalAxis,
    /// The tracker's noise per coordinate, 1σ [mm].
    pub tracker_sigma_mm: f64,
    /// Highest map order tried (at most `travel_map::MAX_MAP_ORDER`).
    pub max_order: usize,
}

/// How well one station (one track value) fixes the robot base's pose.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StationReport {
    /// The track's value [mm].
    pub value_mm: f64,
    /// Readings at the value.
    pub poses: usize,
    /// RMS spread of the reflector's positions along their three principal
    /// directions, largest first [mm]: rotations about the first are seen
    /// only through the other two.
    pub spread_mm: [f64; 3],
    /// 1σ of the base's position per coordinate [mm] (σ/√n).
    pub sigma_position_mm: f64,
    /// 1σ of the base's roll, pitch, yaw about the rail frame's axes [arcsec].
    pub sigma_angles_arcsec: [f64; 3],
    /// RMS of the station's own rigid fit (Kabsch) [mm].
    pub rms_mm: f64,
    /// The fitted track's base pose less the station's: along, lateral,
    /// vertical [mm], roll, pitch, yaw [arcsec].
    pub misfit: [f64; 6],
}

/// One candidate order of a map and its leave-one-station-out RMS.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct OrderScore {
    /// The series' highest order.
    pub order: usize,
    /// In the map's stored unit (mm or arcsec).
    pub cv_rms: f64,
}

/// One carriage map as fitted.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MapReport {
    /// The carriage error the map holds.
    pub term: CarriageTerm,
    /// `mm` or `arcsec`.
    pub unit: &'static str,
    /// The order cross-validation chose.
    pub order: usize,
    /// Every order tried.
    pub candidates: Vec<OrderScore>,
    /// Largest |map| at the stations, in the unit.
    pub amplitude: f64,
    /// RMS of the stations about the map, in the unit.
    pub rms: f64,
    /// The median station's 1σ of this term, in the unit.
    pub station_sigma: f64,
}

/// What tracker readings of a carried robot cannot tell apart (a closed set;
/// a fit names each with its figure where it has one).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum UnseenTerm {
    /// A straightness map's mean and slope are the rail line's position and
    /// direction; the positioning map's are zero and scale.
    StraightnessMeanAndSlope,
    /// The mean roll, pitch and yaw are the base's mount on the carriage.
    AngleMeans,
    /// Bends shorter than two station spacings are not sampled.
    ShortBends,
    /// Where the carriage pivots: an angle about another point moves the
    /// base along, across or up, which the positioning and straightness maps
    /// hold; a bent rail and the carriage's arm are not told apart.
    CarriagePivot,
}

impl UnseenTerm {
    /// Every term, in report order.
    pub const ALL: [UnseenTerm; 4] = [
        UnseenTerm::StraightnessMeanAndSlope,
        UnseenTerm::AngleMeans,
        UnseenTerm::ShortBends,
        UnseenTerm::CarriagePivot,
    ];
}

/// One term the data cannot see, and its figure.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Unseen {
    /// Which term.
    pub term: UnseenTerm,
    /// Why, with the figure (a length, for short bends).
    pub note: String,
}

/// A fitted track.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TrackFit {
    /// The calibrated model.
    #[serde(skip)]
    pub model: LinearTrack,
    /// The calibrated model as stored.
    pub description: TrackDescription,
    /// Each station, by increasing value.
    pub stations: Vec<StationReport>,
    /// Each carriage map, by [`CarriageTerm::ALL`].
    pub maps: Vec<MapReport>,
    /// Each reading's 3-D residual through the fitted track and the held
    /// robot [mm], in the set's order.
    pub residual_mm: Vec<f64>,
    /// RMS of the residuals [mm].
    pub rms_mm: f64,
    /// Largest residual [mm].
    pub max_mm: f64,
    /// The terms the readings cannot see.
    pub unseen: Vec<Unseen>,
    /// The bounds the fit was judged against.
    pub limits: FitLimits,
}

/// Why a track was not fitted (a closed set). `measured` and `needed` of a
/// [`TrackRefused`] carry the figure each names, in the unit given here.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TrackRefusalReason {
    /// A value is not finite, the tracker σ is not positive, or the robot's
    /// model cannot place a reading.
    NotFinite,
    /// The set has no column for the track.
    MissingColumn,
    /// A reading's joint count is not the robot's.
    JointCount,
    /// Too few distinct track values (stations).
    TooFewStations,
    /// A station has too few readings to fix the base's angles (readings).
    TooFewPoses,
    /// A station's readings lie (nearly) on a line: the angle about it is
    /// unseen (mm, the spread across the line).
    Collinear,
    /// A station's readings do not fit one rigid pose of the held robot (mm).
    StationResiduals,
    /// The residuals' RMS through the fitted track is beyond the noise (mm).
    ResidualsTooLarge,
    /// One reading's residual is beyond the noise (mm).
    ResidualOutlier,
}

/// A track fit refused before it is stored: the refusal names the station
/// or reading (the shape every external axis fit's refusal shares,
/// [`Refusal`]).
pub type TrackRefused = Refusal<TrackRefusalReason, TrackFit>;

impl Reason for TrackRefusalReason {
    const NAMES_STATIONS: bool = true;
}
