//! A simulated linear track from its physics, carrying a simulated robot,
//! read by a simulated tracker: for tests of the track fit that are not
//! circular (the model's maps are polynomials over the travel; the truth's
//! rails bend as sums of sines of incommensurate wavelengths, which no
//! polynomial holds exactly, and its carriage's angles come from its bearing
//! blocks riding those rails).
//!
//! The carriage rides two pairs of bearing blocks a `wheelbase_m` apart on
//! rails whose side and height deviate from the straight line by `y(s)` and
//! `z(s)` (the rail frame's y and z, [`Wave`] sums). At travel
//! `s = (1 + scale_error)·v` (v the controller value; a rack whose pitch is
//! off by `scale_error`), the carriage's reference point is the mid point of
//! its blocks, `(s, (y(s+L/2) + y(s−L/2))/2, (z(s+L/2) + z(s−L/2))/2)` in the
//! rail frame, it yaws by `(y(s+L/2) − y(s−L/2))/L` and pitches by
//! `−(z(s+L/2) − z(s−L/2))/L` (front up tips it about −y), plus the
//! `yaw_extra`, `pitch_extra` and `roll` waves (blocks preloaded unevenly, a
//! twisted bed), applied as one rotation vector in the rail frame
//! (`Rotation3::from_scaled_axis`). The robot base sits on the carriage at
//! `base_on_carriage` (an arm above and beside the carriage's reference, so
//! the carriage's angles move the base: the Abbe effect).
//!
//! Frames: the rail frame in the cell (tracker) frame is `cell_from_rail`
//! (x along increasing values); the robot base in the cell frame at value
//! `v` is `cell_from_rail · rail_from_carriage(v) · base_on_carriage`.
//! Tracker noise is the robot's (`TrueRobot::noise_mm`), from the injected,
//! seeded generator. Units: m and rad inside; values in mm, readings in mm
//! and degrees.

use super::{SimError, TrueRobot};
use crate::measure::external::{ExternalAxis, ExternalValues, MeasurementSet};
use crate::model::external::{LinearTrack, Travel};
use crate::model::pose::rpy_matrix;
use crate::model::Pose;
use nalgebra::{Rotation3, Vector3};
use rand::Rng;

/// One sine of a rail's deviation or a carriage angle: `A·sin(2π·s/λ + φ)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Wave {
    /// `A` [m or rad].
    pub amplitude: f64,
    /// `λ` [m].
    pub wavelength_m: f64,
    /// `φ` [rad].
    pub phase_rad: f64,
}

/// The sum of `waves` at travel `s` [m].
pub fn waves_at(waves: &[Wave], s: f64) -> f64 {
    waves
        .iter()
        .map(|w| w.amplitude * (std::f64::consts::TAU * s / w.wavelength_m + w.phase_rad).sin())
        .sum()
}

/// A true linear track (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct TrueTrack {
    /// The rail frame in the cell frame (x along increasing values).
    pub cell_from_rail: Pose,
    /// Travel per controller value, less 1 (2e-4: 0.2 mm/m).
    pub scale_error: f64,
    /// The rails' deviation sideways, `y(s)` [m].
    pub lateral: Vec<Wave>,
    /// The rails' deviation up, `z(s)` [m].
    pub vertical: Vec<Wave>,
    /// Distance of the carriage's front and rear blocks [m].
    pub wheelbase_m: f64,
    /// Yaw added to the blocks' (about the rail frame's z) over the travel [rad].
    pub yaw_extra: Vec<Wave>,
    /// Pitch added to the blocks' (about the rail frame's y) over the travel [rad].
    pub pitch_extra: Vec<Wave>,
    /// The carriage's roll (about the rail frame's x) over the travel [rad].
    pub roll: Vec<Wave>,
    /// The robot base frame in the carriage frame.
    pub base_on_carriage: Pose,
}

/// The carriage's angles at a value [rad]: rotation vector components about
/// the rail frame's x, y, z.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CarriageAngles {
    /// About the rail frame's x [rad].
    pub roll: f64,
    /// About the rail frame's y, positive with the front down [rad].
    pub pitch: f64,
    /// About the rail frame's z, positive with the front to +y [rad].
    pub yaw: f64,
}

impl TrueTrack {
    /// The acceptance truth: a 4 m rail along a cell direction 25° off the
    /// tracker's x and rising 0.1°, its scale off by 0.2 mm/m, its rails
    /// bent sideways by three sines (60, 40, 15 µm at 7.3, 4.1, 2.9 m) and up
    /// by two (50, 25 µm at 5.7, 3.3 m), blocks 0.6 m apart, extra yaw 5″ at
    /// 3.7 m, extra pitch 3″ at 4.9 m, roll 8″ at 4.3 m and 3″ at 2.7 m; the
    /// base 350 mm above the carriage's reference and 120 mm beside it,
    /// turned 90° about the vertical.
    pub fn rail_4m() -> Self {
        let arcsec = std::f64::consts::PI / (180.0 * 3600.0);
        let wave = |amplitude: f64, wavelength_m: f64, phase_rad: f64| Wave {
            amplitude,
            wavelength_m,
            phase_rad,
        };
        let r = Rotation3::from_scaled_axis(Vector3::z() * 25f64.to_radians())
            * Rotation3::from_scaled_axis(Vector3::y() * (-0.1f64).to_radians());
        TrueTrack {
            cell_from_rail: Pose::new(r.into_inner(), Vector3::new(0.6, -3.1, -0.4)),
            scale_error: 2e-4,
            lateral: vec![
                wave(60e-6, 7.3, 0.5),
                wave(40e-6, 4.1, 0.0),
                wave(15e-6, 2.9, 4.1),
            ],
            vertical: vec![wave(50e-6, 5.7, 1.1), wave(25e-6, 3.3, 0.3)],
            wheelbase_m: 0.6,
            yaw_extra: vec![wave(5.0 * arcsec, 3.7, 0.9)],
            pitch_extra: vec![wave(3.0 * arcsec, 4.9, 2.2)],
            roll: vec![wave(8.0 * arcsec, 4.3, 1.3), wave(3.0 * arcsec, 2.7, 0.2)],
            base_on_carriage: Pose::new(
                Rotation3::from_scaled_axis(Vector3::z() * std::f64::consts::FRAC_PI_2)
                    .into_inner(),
                Vector3::new(0.0, 0.12, 0.35),
            ),
        }
    }

    /// What a controller computes from [`TrueTrack::rail_4m`]'s drawing: the
    /// rail 25° off the cell's x, horizontal, through the true rail's start;
    /// the base 350 mm above the carriage's reference and 120 mm beside it,
    /// turned 90° about the vertical; scale 1, no maps, travel 0–4000 mm.
    pub fn drawing_4m() -> LinearTrack {
        let rail = TrueTrack::drawing_rail_4m();
        let start = rail.transform_point(&Vector3::new(0.0, 0.12, 0.35));
        let along = rail.r.column(0).into_owned();
        // `zero`: the base's travel at value 0 from the line's point closest
        // to the cell origin.
        LinearTrack::nominal(
            along,
            start,
            start.dot(&along),
            rpy_matrix(0.0, 0.0, std::f64::consts::FRAC_PI_2),
            Travel {
                lo_mm: 0.0,
                hi_mm: 4000.0,
            },
        )
    }

    /// The rail frame of [`TrueTrack::drawing_4m`] in the cell frame: x
    /// along the rail (25° off the cell's x, horizontal), z up, the origin
    /// the rail's start (the robot's base 350 mm above it and 120 mm beside
    /// it at value 0).
    pub fn drawing_rail_4m() -> Pose {
        Pose::new(
            rpy_matrix(0.0, 0.0, 25f64.to_radians()),
            Vector3::new(0.6, -3.1, -0.4),
        )
    }

    /// Travel [m] at controller value `value_mm`.
    pub fn travel(&self, value_mm: f64) -> f64 {
        (1.0 + self.scale_error) * value_mm * 1e-3
    }

    /// The carriage's angles at controller value `value_mm`.
    pub fn angles(&self, value_mm: f64) -> CarriageAngles {
        let s = self.travel(value_mm);
        let h = 0.5 * self.wheelbase_m;
        let (front, rear) = (s + h, s - h);
        let yaw = (waves_at(&self.lateral, front) - waves_at(&self.lateral, rear))
            / self.wheelbase_m
            + waves_at(&self.yaw_extra, s);
        let pitch = -(waves_at(&self.vertical, front) - waves_at(&self.vertical, rear))
            / self.wheelbase_m
            + waves_at(&self.pitch_extra, s);
        CarriageAngles {
            roll: waves_at(&self.roll, s),
            pitch,
            yaw,
        }
    }

    /// The carriage frame in the rail frame at controller value `value_mm`.
    pub fn rail_from_carriage(&self, value_mm: f64) -> Pose {
        let s = self.travel(value_mm);
        let h = 0.5 * self.wheelbase_m;
        let mid = |w: &[Wave]| 0.5 * (waves_at(w, s + h) + waves_at(w, s - h));
        let a = self.angles(value_mm);
        let turn = Rotation3::from_scaled_axis(Vector3::new(a.roll, a.pitch, a.yaw));
        Pose::new(
            turn.into_inner(),
            Vector3::new(s, mid(&self.lateral), mid(&self.vertical)),
        )
    }

    /// The robot base frame in the cell frame at controller value `value_mm`.
    pub fn cell_from_base(&self, value_mm: f64) -> Pose {
        self.cell_from_rail
            .compose(&self.rail_from_carriage(value_mm))
            .compose(&self.base_on_carriage)
    }

    /// `robot` measured at each station: per `(value_mm, configurations)`
    /// (model convention, rad), the robot's tracker readings with its base
    /// carried to the value, `e{axis}` the value. One set, stations in
    /// order; rows with `payload_kg`.
    pub fn measure(
        &self,
        robot: &TrueRobot,
        axis: ExternalAxis,
        stations: &[(f64, Vec<Vec<f64>>)],
        payload_kg: Option<f64>,
        rng: &mut impl Rng,
    ) -> Result<MeasurementSet, SimError> {
        let mut set = MeasurementSet {
            axes: vec![axis],
            ..MeasurementSet::default()
        };
        for (value_mm, qs) in stations {
            let mut carried = robot.clone();
            carried.tracker_from_base = self.cell_from_base(*value_mm);
            let rows = carried.measure(qs, payload_kg, None, rng)?;
            let mut e = ExternalValues::default();
            e.0[axis.index()] = Some(*value_mm);
            set.external.resize(set.external.len() + rows.len(), e);
            set.poses.extend(rows);
        }
        Ok(set)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed forms: a rail bent by one long sine seen by blocks a
    /// wheelbase apart: the carriage's yaw is the chord's slope, its point
    /// the chord's middle; the scale error stretches the travel.
    #[test]
    fn the_carriage_rides_its_rails() {
        let mut t = TrueTrack::rail_4m();
        t.lateral = vec![Wave {
            amplitude: 1e-4,
            wavelength_m: 4.0,
            phase_rad: 0.0,
        }];
        t.vertical.clear();
        t.yaw_extra.clear();
        t.pitch_extra.clear();
        t.roll.clear();
        t.cell_from_rail = Pose::identity();
        t.base_on_carriage = Pose::identity();
        // At s = 1 m (v = 1/(1 + ε) m) the sine peaks: chord of the blocks
        // at 0.7 and 1.3 m is flat, its middle 1e-4·cos(2π·0.3/4) below the peak.
        let v = 1000.0 / (1.0 + t.scale_error);
        let b = t.cell_from_base(v);
        assert!((b.p.x - 1.0).abs() < 1e-12);
        let mid = 1e-4 * (std::f64::consts::TAU * 0.3 / 4.0).cos();
        assert!((b.p.y - mid).abs() < 1e-12, "{}", b.p.y);
        assert!(t.angles(v).yaw.abs() < 1e-12);
        // At s = 0 the slope is 2π·1e-4/4; the chord's slope is
        // 2·1e-4·sin(2π·0.3/4)/0.6.
        let yaw = t.angles(0.0).yaw;
        let chord = 2.0 * 1e-4 * (std::f64::consts::TAU * 0.3 / 4.0).sin() / 0.6;
        assert!((yaw - chord).abs() < 1e-15, "{yaw} {chord}");
        assert!((t.travel(4000.0) - 4.0008).abs() < 1e-12);
    }

    /// The drawing is the truth without its errors: at every value the
    /// drawing's base is where the truth's would be with scale 1, straight
    /// rails, no carriage angles and the rail not rising; the rise alone
    /// (0.1° over 4 m: 7 mm) and the scale (0.8 mm) separate them.
    #[test]
    fn the_drawing_is_the_truth_without_its_errors() {
        let mut ideal = TrueTrack::rail_4m();
        ideal.scale_error = 0.0;
        ideal.lateral.clear();
        ideal.vertical.clear();
        ideal.yaw_extra.clear();
        ideal.pitch_extra.clear();
        ideal.roll.clear();
        let mut r = Pose::from_translation(ideal.cell_from_rail.p);
        r.rot_z(25f64.to_radians());
        ideal.cell_from_rail = r;
        let drawing = TrueTrack::drawing_4m();
        for i in 0..=40 {
            let v = 100.0 * f64::from(i);
            let (a, b) = (drawing.cell_from_base(v).unwrap(), ideal.cell_from_base(v));
            assert!((a.p - b.p).norm() < 1e-12, "{v}: {:?} {:?}", a.p, b.p);
            assert!((a.r - b.r).norm() < 1e-12, "{v}");
        }
        let off = (drawing.cell_from_base(4000.0).unwrap().p
            - TrueTrack::rail_4m().cell_from_base(4000.0).p)
            .norm();
        assert!(off > 6e-3 && off < 9e-3, "{off}");
    }

    /// The acceptance truth has the sizes it is said to have: lateral
    /// straightness reaching ±0.1 mm (0.098), yaw about 30″ (30.5).
    #[test]
    fn the_acceptance_rail_has_its_stated_sizes() {
        let t = TrueTrack::rail_4m();
        let arcsec = std::f64::consts::PI / (180.0 * 3600.0);
        let (mut lat, mut yaw) = (0.0f64, 0.0f64);
        for i in 0..=400 {
            let v = 10.0 * f64::from(i);
            lat = lat.max(t.rail_from_carriage(v).p.y.abs());
            yaw = yaw.max(t.angles(v).yaw.abs() / arcsec);
        }
        assert!(lat > 0.09e-3 && lat <= 0.1e-3, "{lat}");
        assert!(yaw > 25.0 && yaw < 35.0, "{yaw}″");
    }
}
