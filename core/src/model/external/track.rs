//! A linear track: the robot's base carried along a rail by a carriage.
//!
//! Frames:
//! - the cell frame (the tracker's measurement frame);
//! - the rail frame: its x axis is the rail's unit `direction` in the cell
//!   frame, its z axis the cell's z made perpendicular to it (the rail's
//!   "up"), y = z × x (the rail's side); a rail within
//!   [`MAX_RAIL_INCLINE_DEG`] of the horizontal only;
//! - the robot base frame, carried: at controller value `v` [mm]
//!   `cell_from_base(v)` has the origin
//!   `c + d·(s + e_x(v)) + R_rail·(0, e_y(v), e_z(v))` and the rotation
//!   `R_rail·R(roll, pitch, yaw)(v)·R_mount`, where `s = scale·v + zero` is
//!   the travel along the rail, `c` the rail line's
//!   point closest to the cell origin, `R(roll, pitch, yaw) =
//!   Rz(yaw)·Ry(pitch)·Rx(roll)` about the rail frame's axes, and `R_mount`
//!   the base's orientation in the rail frame.
//!
//! The carriage's pose errors along the rail, its positioning error beyond
//! scale and zero (`e_x`, a rack's pitch error), the straightness across it
//! (`e_y`, lateral) and up (`e_z`, vertical), roll, pitch and yaw, are smooth
//! maps of the controller value over the travel measured
//! ([`super::travel_map`]); the robot base origin is the point they move, so
//! a pitch of the carriage moves it along the rail by the pitch times the
//! base's height above the pivot, and that motion is in `e_x` (the Abbe
//! effect of the carriage on the base is held; the reflector's arm from the
//! base is the robot's, through the rotation). Outside the travel the model
//! refuses ([`OutsideTravel`]).
//!
//! The nominal model (what the controller computes: the rail's direction,
//! scale 1, the zero from the drawing, no maps) and the calibrated one share
//! this type. Units: m and rad inside; the description ([`TrackDescription`],
//! JSON) in mm, degrees and arcseconds, checked on reading.

use super::positioner::{FrameDescription, MAX_FRAME_DISTANCE_MM};
use super::rotary::{check_finite, closest_to_origin, Line, DIRECTION_TOLERANCE};
use super::travel_map::{OutsideTravel, Travel, TravelMap, MAX_MAP_ORDER};
use crate::model::error::ModelError;
use crate::model::pose::rpy_matrix;
use crate::model::Pose;
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// Largest accepted incline of a rail from the cell's horizontal plane [deg]
/// (a rail near the vertical has no "side" to state straightness in).
pub const MAX_RAIL_INCLINE_DEG: f64 = 60.0;
/// Largest accepted `|scale − 1|`: a rack or a gear ratio wrong by more than
/// 1 % is a configuration error, not a calibration.
pub const MAX_TRACK_SCALE_DEVIATION: f64 = 0.01;
/// Largest accepted bound of a straightness map [mm].
pub const MAX_STRAIGHTNESS_MM: f64 = 10.0;
/// Largest accepted bound of an angle map [arcsec] (1°).
pub const MAX_CARRIAGE_ANGLE_ARCSEC: f64 = 3600.0;

const ARCSEC: f64 = std::f64::consts::PI / (180.0 * 3600.0);

/// The carriage's pose errors along the rail (a closed set; maps, reports
/// and descriptions derive from it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CarriageTerm {
    /// Positioning along the rail beyond scale and zero [m].
    Along,
    /// Straightness across the rail, along the rail frame's y [m].
    Lateral,
    /// Straightness up, along the rail frame's z [m].
    Vertical,
    /// About the rail (x) [rad].
    Roll,
    /// About the rail frame's y [rad].
    Pitch,
    /// About the rail frame's z [rad].
    Yaw,
}

impl CarriageTerm {
    /// Every term, in map order.
    pub const ALL: [CarriageTerm; 6] = [
        CarriageTerm::Along,
        CarriageTerm::Lateral,
        CarriageTerm::Vertical,
        CarriageTerm::Roll,
        CarriageTerm::Pitch,
        CarriageTerm::Yaw,
    ];

    /// 0 for `Along` … 5 for `Yaw`.
    pub fn index(self) -> usize {
        self as usize
    }

    /// The term as reports name it.
    pub fn name(self) -> &'static str {
        match self {
            CarriageTerm::Along => "positioning along the rail",
            CarriageTerm::Lateral => "lateral straightness",
            CarriageTerm::Vertical => "vertical straightness",
            CarriageTerm::Roll => "roll",
            CarriageTerm::Pitch => "pitch",
            CarriageTerm::Yaw => "yaw",
        }
    }

    /// Whether the term is an angle (else a length).
    pub fn is_angle(self) -> bool {
        !matches!(
            self,
            CarriageTerm::Along | CarriageTerm::Lateral | CarriageTerm::Vertical
        )
    }

    /// The unit of the stored description: `mm` or `arcsec`.
    pub fn unit(self) -> &'static str {
        if self.is_angle() {
            "arcsec"
        } else {
            "mm"
        }
    }

    /// Stored unit per SI unit (1e3 mm/m, arcsec/rad).
    pub fn per_si(self) -> f64 {
        if self.is_angle() {
            1.0 / ARCSEC
        } else {
            1e3
        }
    }

    /// The largest accepted bound of the map, in the stored unit.
    fn max_bound(self) -> f64 {
        if self.is_angle() {
            MAX_CARRIAGE_ANGLE_ARCSEC
        } else {
            MAX_STRAIGHTNESS_MM
        }
    }
}

/// The carriage's six errors at one value (SI), by [`CarriageTerm`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CarriageErrors(pub [f64; 6]);

impl CarriageErrors {
    /// The error of term `t` (m or rad).
    pub fn get(&self, t: CarriageTerm) -> f64 {
        self.0[t.index()]
    }
}

/// The rail frame's rotation for a rail along the unit `direction` (module
/// docs): x along the rail, z the cell's z made perpendicular to it.
pub fn rail_rotation(direction: &Vector3<f64>) -> Matrix3<f64> {
    let x = direction.normalize();
    let z = (Vector3::z() - x * x.z).normalize();
    let y = z.cross(&x);
    Matrix3::from_columns(&[x, y, z])
}

/// A linear track (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct LinearTrack {
    /// The rail line in the cell frame: unit direction of increasing values
    /// and the point closest to the cell origin [m].
    pub rail: Line,
    /// Controller value → travel (1 nominal).
    pub scale: f64,
    /// Travel at controller value 0, along the rail from `rail.point` [m].
    pub zero: f64,
    /// The robot base's orientation in the rail frame.
    pub mount: Matrix3<f64>,
    /// The controller values the maps hold over [mm].
    pub travel: Travel,
    /// The carriage maps, by [`CarriageTerm`] (m, rad).
    pub maps: [TravelMap; 6],
}

impl LinearTrack {
    /// A track without maps (a nominal model): the rail along `direction`
    /// through `any_point` [m], the base's orientation `mount` in the rail
    /// frame, `zero` [m], scale 1.
    pub fn nominal(
        direction: Vector3<f64>,
        any_point: Vector3<f64>,
        zero: f64,
        mount: Matrix3<f64>,
        travel: Travel,
    ) -> Self {
        let u = direction.normalize();
        LinearTrack {
            rail: Line {
                direction: u,
                point: closest_to_origin(&u, &any_point),
            },
            scale: 1.0,
            zero,
            mount,
            travel,
            maps: Default::default(),
        }
    }

    /// The rail frame's rotation in the cell frame.
    pub fn rail_rotation(&self) -> Matrix3<f64> {
        rail_rotation(&self.rail.direction)
    }

    /// Travel along the rail [m] at controller value `value_mm`.
    pub fn travel_at(&self, value_mm: f64) -> f64 {
        self.scale * value_mm * 1e-3 + self.zero
    }

    /// The carriage's errors at `value_mm` (SI), or the refusal beyond the
    /// travel.
    pub fn errors_at(&self, value_mm: f64) -> Result<CarriageErrors, OutsideTravel> {
        let x = self.travel.normalized(value_mm)?;
        Ok(CarriageErrors(
            CarriageTerm::ALL.map(|t| self.maps[t.index()].at(x)),
        ))
    }

    /// The robot base frame in the cell frame at controller value
    /// `value_mm`, or the refusal beyond the travel.
    pub fn cell_from_base(&self, value_mm: f64) -> Result<Pose, OutsideTravel> {
        let e = self.errors_at(value_mm)?;
        let r_rail = self.rail_rotation();
        let origin = self.rail.point
            + self.rail.direction * (self.travel_at(value_mm) + e.get(CarriageTerm::Along))
            + r_rail
                * Vector3::new(
                    0.0,
                    e.get(CarriageTerm::Lateral),
                    e.get(CarriageTerm::Vertical),
                );
        let turn = rpy_matrix(
            e.get(CarriageTerm::Roll),
            e.get(CarriageTerm::Pitch),
            e.get(CarriageTerm::Yaw),
        );
        Ok(Pose::new(r_rail * turn * self.mount, origin))
    }

    /// The stored description (mm, degrees, arcseconds).
    pub fn describe(&self) -> TrackDescription {
        let map = |t: CarriageTerm| -> Vec<f64> {
            self.maps[t.index()]
                .coefficients
                .iter()
                .map(|c| c * t.per_si())
                .collect()
        };
        TrackDescription {
            direction: self.rail.direction.into(),
            point_mm: (self.rail.point * 1e3).into(),
            scale: self.scale,
            zero_mm: self.zero * 1e3,
            mount_rpy_deg: FrameDescription::of(&Pose::new(self.mount, Vector3::zeros())).rpy_deg,
            travel_mm: [self.travel.lo_mm, self.travel.hi_mm],
            maps: MapsDescription {
                along_mm: map(CarriageTerm::Along),
                lateral_mm: map(CarriageTerm::Lateral),
                vertical_mm: map(CarriageTerm::Vertical),
                roll_arcsec: map(CarriageTerm::Roll),
                pitch_arcsec: map(CarriageTerm::Pitch),
                yaw_arcsec: map(CarriageTerm::Yaw),
            },
        }
    }

    /// Reads and checks a JSON description.
    pub fn from_json(text: &str) -> Result<Self, ModelError> {
        let d: TrackDescription =
            serde_json::from_str(text).map_err(|e| ModelError::Parse(e.to_string()))?;
        d.to_model()
    }

    /// The JSON description.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(&self.describe()).expect("plain numbers serialise")
    }
}

/// The carriage maps as stored: Legendre coefficients `c_0 … c_N` over the
/// travel (N ≤ [`MAX_MAP_ORDER`]), positioning and straightness in mm,
/// angles in arcsec.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MapsDescription {
    /// Positioning along the rail beyond scale and zero [mm].
    pub along_mm: Vec<f64>,
    /// Straightness along the rail frame's y [mm].
    pub lateral_mm: Vec<f64>,
    /// Straightness along the rail frame's z [mm].
    pub vertical_mm: Vec<f64>,
    /// Roll about the rail frame's x [arcsec].
    pub roll_arcsec: Vec<f64>,
    /// Pitch about the rail frame's y [arcsec].
    pub pitch_arcsec: Vec<f64>,
    /// Yaw about the rail frame's z [arcsec].
    pub yaw_arcsec: Vec<f64>,
}

impl MapsDescription {
    fn get(&self, t: CarriageTerm) -> (&'static str, &Vec<f64>) {
        match t {
            CarriageTerm::Along => ("maps.along_mm", &self.along_mm),
            CarriageTerm::Lateral => ("maps.lateral_mm", &self.lateral_mm),
            CarriageTerm::Vertical => ("maps.vertical_mm", &self.vertical_mm),
            CarriageTerm::Roll => ("maps.roll_arcsec", &self.roll_arcsec),
            CarriageTerm::Pitch => ("maps.pitch_arcsec", &self.pitch_arcsec),
            CarriageTerm::Yaw => ("maps.yaw_arcsec", &self.yaw_arcsec),
        }
    }
}

/// A linear track as stored (mm, degrees, arcsec; module docs for frames).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrackDescription {
    /// Unit direction of the rail (increasing values) in the cell frame.
    pub direction: [f64; 3],
    /// The rail line's point closest to the cell origin [mm].
    pub point_mm: [f64; 3],
    /// Controller value → travel (dimensionless).
    pub scale: f64,
    /// Travel at controller value 0 along the rail from `point_mm` [mm].
    pub zero_mm: f64,
    /// The robot base's orientation in the rail frame, fixed-axis
    /// `[rx, ry, rz]` [deg].
    pub mount_rpy_deg: [f64; 3],
    /// The controller values the maps hold over `[lo, hi]` [mm].
    pub travel_mm: [f64; 2],
    /// The carriage maps (left out: zero, the nominal model).
    #[serde(default)]
    pub maps: MapsDescription,
}

fn invalid(field: &str, reason: String) -> ModelError {
    ModelError::InvalidField {
        field: field.to_string(),
        reason,
    }
}

impl TrackDescription {
    /// The model, every bound checked (the field that fails is named).
    pub fn to_model(&self) -> Result<LinearTrack, ModelError> {
        check_finite("direction", &self.direction)?;
        check_finite("point_mm", &self.point_mm)?;
        check_finite("scale", &[self.scale])?;
        check_finite("zero_mm", &[self.zero_mm])?;
        check_finite("travel_mm", &self.travel_mm)?;
        let u = Vector3::from(self.direction);
        if (u.norm() - 1.0).abs() > DIRECTION_TOLERANCE {
            return Err(invalid(
                "direction",
                format!(
                    "length {:.9}, not a unit vector (within {DIRECTION_TOLERANCE}); divide it by its length",
                    u.norm()
                ),
            ));
        }
        let incline = u.z.clamp(-1.0, 1.0).asin().to_degrees();
        if incline.abs() > MAX_RAIL_INCLINE_DEG {
            return Err(invalid(
                "direction",
                format!("the rail rises {incline:.1}° from the cell's horizontal plane, beyond {MAX_RAIL_INCLINE_DEG}°: its side and up are not defined"),
            ));
        }
        let p = Vector3::from(self.point_mm);
        let along = p.dot(&u);
        if along.abs() > 1e-3 {
            let c = closest_to_origin(&u, &p);
            return Err(invalid(
                "point_mm",
                format!(
                    "lies {along:.4} mm along the rail from its point closest to the origin ({:.4}, {:.4}, {:.4}); give that point",
                    c.x, c.y, c.z
                ),
            ));
        }
        for (field, v) in [
            ("point_mm", p.norm()),
            ("zero_mm", self.zero_mm.abs()),
            (
                "travel_mm",
                self.travel_mm[0].abs().max(self.travel_mm[1].abs()),
            ),
        ] {
            if v > MAX_FRAME_DISTANCE_MM {
                return Err(invalid(
                    field,
                    format!(
                        "{v:.0} mm, beyond {MAX_FRAME_DISTANCE_MM:.0} mm; check the units (mm)"
                    ),
                ));
            }
        }
        if (self.scale - 1.0).abs() > MAX_TRACK_SCALE_DEVIATION {
            return Err(invalid(
                "scale",
                format!(
                    "{} is more than {MAX_TRACK_SCALE_DEVIATION} from 1: the rack, the gear ratio or the units are wrong, which a calibration does not correct",
                    self.scale
                ),
            ));
        }
        let [lo, hi] = self.travel_mm;
        if lo >= hi {
            return Err(invalid(
                "travel_mm",
                format!("[{lo}, {hi}] is not an interval: give [lowest, highest] value measured"),
            ));
        }
        let mount = FrameDescription {
            xyz_mm: [0.0; 3],
            rpy_deg: self.mount_rpy_deg,
        }
        .to_pose("mount_rpy_deg")?
        .r;
        let mut maps: [TravelMap; 6] = Default::default();
        for t in CarriageTerm::ALL {
            let (field, c) = self.maps.get(t);
            check_finite(field, c)?;
            if c.len() > MAX_MAP_ORDER + 1 {
                return Err(invalid(
                    field,
                    format!(
                        "{} coefficients, more than the {} of order {MAX_MAP_ORDER}",
                        c.len(),
                        MAX_MAP_ORDER + 1
                    ),
                ));
            }
            let bound: f64 = c.iter().map(|v| v.abs()).sum();
            if bound > t.max_bound() {
                return Err(invalid(
                    field,
                    format!(
                        "the coefficients' magnitudes add up to {bound} {}, beyond {} {}: not a {} a calibration corrects",
                        t.unit(),
                        t.max_bound(),
                        t.unit(),
                        t.name()
                    ),
                ));
            }
            maps[t.index()] = TravelMap {
                coefficients: c.iter().map(|v| v / t.per_si()).collect(),
            };
        }
        Ok(LinearTrack {
            rail: Line {
                direction: u / u.norm(),
                point: p * 1e-3,
            },
            scale: self.scale,
            zero: self.zero_mm * 1e-3,
            mount,
            travel: Travel {
                lo_mm: lo,
                hi_mm: hi,
            },
            maps,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn track() -> LinearTrack {
        let mut t = LinearTrack::nominal(
            Vector3::new(1.0, 1.0, 0.0),
            Vector3::new(1.0, -1.0, 0.5),
            0.25,
            rpy_matrix(0.0, 0.0, std::f64::consts::FRAC_PI_2),
            Travel {
                lo_mm: 0.0,
                hi_mm: 4000.0,
            },
        );
        t.scale = 1.0002;
        t.maps[CarriageTerm::Lateral.index()].coefficients = vec![0.0, 0.0, 1e-4];
        t.maps[CarriageTerm::Yaw.index()].coefficients = vec![0.0, 30.0 * ARCSEC];
        t
    }

    /// Closed forms: the rail frame of a horizontal rail along (1, 1, 0)/√2;
    /// the base at a value moves along it by scale·v + zero, sideways by
    /// the lateral map, and turns by the yaw map about the rail's up.
    #[test]
    fn the_base_follows_closed_forms() {
        let t = track();
        let r = t.rail_rotation();
        let s = std::f64::consts::FRAC_1_SQRT_2;
        assert!((r.column(0) - Vector3::new(s, s, 0.0)).norm() < 1e-15);
        assert!((r.column(2) - Vector3::z()).norm() < 1e-15);
        assert!((r.column(1) - Vector3::new(-s, s, 0.0)).norm() < 1e-15);
        assert!((t.rail.point - Vector3::new(1.0, -1.0, 0.5)).norm() < 1e-15);
        // At v = 4000 (x = 1): along 1.0002·4 + 0.25 m, lateral P2(1)·1e-4 m,
        // yaw 30″ (P1(1) = 1).
        let b = t.cell_from_base(4000.0).unwrap();
        let along = 1.0002 * 4.0 + 0.25;
        let want = Vector3::new(1.0, -1.0, 0.5)
            + Vector3::new(s, s, 0.0) * along
            + Vector3::new(-s, s, 0.0) * 1e-4;
        assert!((b.p - want).norm() < 1e-14, "{}", b.p - want);
        let yaw = (r.transpose() * b.r * t.mount.transpose()).column(0)[1].asin();
        assert!((yaw - 30.0 * ARCSEC).abs() < 1e-12);
        // At the middle (x = 0) P1 and the yaw vanish, P2(0) = −1/2.
        let b = t.cell_from_base(2000.0).unwrap();
        let want = Vector3::new(1.0, -1.0, 0.5) + Vector3::new(s, s, 0.0) * (1.0002 * 2.0 + 0.25)
            - Vector3::new(-s, s, 0.0) * 0.5e-4;
        assert!((b.p - want).norm() < 1e-14);
        assert!((b.r - r * t.mount).norm() < 1e-15);
        // Beyond the travel: refused, not extrapolated.
        assert!(t.cell_from_base(4000.1).is_err());
        assert!(t.cell_from_base(-1.0).is_err());
    }

    #[test]
    fn json_round_trips_and_refuses_out_of_bounds() {
        let t = track();
        let back = LinearTrack::from_json(&t.to_json()).unwrap();
        for v in [0.0, 1234.5, 4000.0] {
            let (a, b) = (
                t.cell_from_base(v).unwrap(),
                back.cell_from_base(v).unwrap(),
            );
            assert!(
                (a.p - b.p).norm() < 1e-12 && (a.r - b.r).norm() < 1e-12,
                "{v}"
            );
        }
        let d = t.describe();
        assert_eq!(d.maps.yaw_arcsec.len(), 2);
        assert!((d.maps.yaw_arcsec[1] - 30.0).abs() < 1e-9);
        let refused = |d: TrackDescription| match d.to_model() {
            Err(ModelError::InvalidField { field, .. }) => field,
            other => panic!("{other:?}"),
        };
        let mut bad = d.clone();
        bad.scale = 1.05;
        assert_eq!(refused(bad), "scale");
        let mut bad = d.clone();
        bad.direction = [0.0, 0.0, 1.0];
        assert_eq!(refused(bad), "direction");
        let mut bad = d.clone();
        bad.point_mm[0] += 10.0;
        assert_eq!(refused(bad), "point_mm");
        let mut bad = d.clone();
        bad.travel_mm = [4000.0, 0.0];
        assert_eq!(refused(bad), "travel_mm");
        let mut bad = d.clone();
        bad.maps.lateral_mm = vec![0.0, 0.0, 12.0];
        assert_eq!(refused(bad), "maps.lateral_mm");
        let mut bad = d.clone();
        bad.maps.roll_arcsec = vec![0.0; MAX_MAP_ORDER + 2];
        assert_eq!(refused(bad), "maps.roll_arcsec");
        let mut bad = d;
        bad.maps.pitch_arcsec = vec![f64::NAN];
        assert_eq!(refused(bad), "maps.pitch_arcsec");
        assert!(matches!(
            LinearTrack::from_json("{\"direction\": [1, 0, 0], \"extra\": 1}"),
            Err(ModelError::Parse(_))
        ));
    }
}
