//! A calibrated positioner or track as a KUKA controller holds it: an
//! external kinematic system, a chain of frames in which each axis moves its
//! frame about (rotary) or along (linear) that frame's z axis, and the
//! chain's root in the world.
//!
//! `world_from_flange(E1, E2) = ROOT·TA1KR·J1(E1)·TA2A1·J2(E2)·TA3A2·TFLA3`,
//! `J` a turn `Rz(E)` [deg] or a shift `Tz(E)` [mm] (`$machine.dat`:
//! `$ET1_TA1KR` root → axis 1, `$ET1_TA2A1` axis 1 → axis 2, `$ET1_TA3A2`
//! axis 2 → axis 3, identity here, `$ET1_TFLA3` the last axis → flange).
//!
//! - A two-axis positioner is a base kinematic system (`#EASYS`, `E1` the
//!   tilt, `E2` the rotate): its root is `MACHINE_DEF[2].ROOT` of
//!   `$config.dat` in the world, which is the robot's base frame (the frame
//!   the filter's controller positioner is stated in; `$ROBROOT` the null
//!   frame); the flange is the face plate frame, so a base on the plate
//!   (`BASE_DATA[n]`, coupled by `EK(MACHINE_DEF[2].ROOT, …)`) is the work
//!   object's pose on the face plate. The root is the positioner's base
//!   frame; axis k's frame has its origin at the calibrated line's point
//!   closest to its parent's origin and z along the line; a zero offset `δ`
//!   is the next link turned by `Rz(δ)` (exact).
//! - A one-axis turntable is a base kinematic system with one axis
//!   (`#EASYS`, `E1` its axis, `TR_A2 #NONE`): the positioner's root and
//!   flange; `$ET1_TA1KR` the axis frame, `$ET1_TA2A1` and `$ET1_TA3A2`
//!   identities, `$ET1_TFLA3` the face plate from the axis (its zero offset
//!   `Rz(δ)` first).
//! - A track is a robot-root kinematic system (`#ERSYS`, `E1`): its root
//!   `$ERSYSROOT` sits on the rail at value 0 with z along the rail (the
//!   cell frame is the world, as for the filter's controller track), the
//!   flange is the robot's base frame.
//! - A track with a positioner or a turntable beside it: the track is ET1
//!   (`E1`), the positioner or turntable ET2 (`$ET2_…`, its axes `E2`, `E3`,
//!   as the filter numbers them) with its root `MACHINE_DEF[2].ROOT` in the
//!   world, which is then the cell frame (`world_from_cell` the identity).
//!
//! Not held: a rotary axis's, the turntable's or the track's scale (the controller turns or
//! moves its frame by the value; the gear ratio is the drive's) and the
//! carriage's maps along the rail. [`KukaKinematics::held`] is what the
//! controller then computes: given to the filter as its controller
//! positioner or track, the filter corrects only what is not held.
//! Units: m and rad inside, the text in mm and degrees with
//! `R = Rz(A)·Ry(B)·Rx(C)`.

use crate::model::external::{CarriageTerm, LinearTrack, TiltRotate, TravelMap, Turntable};
use crate::model::pose::rpy_matrix;
use crate::model::Pose;
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};
use std::f64::consts::FRAC_PI_2;

/// Distance from an axis at which a rotary scale's miss is stated [mm].
pub const SCALE_RADIUS_MM: f64 = 500.0;
/// Turn over which a rotary scale's miss is stated [deg].
pub const SCALE_TURN_DEG: f64 = 180.0;
/// Distance from the robot base at which a carriage angle's miss is stated
/// [mm].
pub const ANGLE_ARM_MM: f64 = 1000.0;

/// A calibrated positioner or track whose axes a cell's export writes.
#[derive(Debug, Clone, PartialEq)]
pub enum ExternalAxes {
    /// A positioner in the cell frame the robot's model is registered in.
    Positioner(TiltRotate),
    /// A track in the cell frame, the controller's world.
    Track(LinearTrack),
    /// A one-axis turntable in the cell frame the robot's model is
    /// registered in.
    Turntable(Turntable),
    /// A track and, beside it, a positioner, both in the track's cell frame
    /// (the controller's world).
    TrackAndPositioner(LinearTrack, TiltRotate),
    /// A track and, beside it, a one-axis turntable, both in the track's
    /// cell frame (the controller's world).
    TrackAndTurntable(LinearTrack, Turntable),
}

impl ExternalAxes {
    /// Which axes these are.
    pub fn kind(&self) -> AxesKind {
        match self {
            Self::Positioner(_) => AxesKind::Positioner,
            Self::Track(_) => AxesKind::Track,
            Self::Turntable(_) => AxesKind::Turntable,
            Self::TrackAndPositioner(..) => AxesKind::TrackAndPositioner,
            Self::TrackAndTurntable(..) => AxesKind::TrackAndTurntable,
        }
    }
}

/// The external axes a cell export writes (the HTTP export's `axes`): one
/// kinematic system, or a track with a positioner or a turntable beside it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AxesKind {
    /// A tilt-rotate positioner (ET1).
    Positioner,
    /// A linear track carrying the robot (ET1).
    Track,
    /// A one-axis turntable (ET1).
    Turntable,
    /// A track (ET1) and a positioner beside it (ET2).
    TrackAndPositioner,
    /// A track (ET1) and a turntable beside it (ET2).
    TrackAndTurntable,
}

impl AxesKind {
    /// Every kind, in the order the API lists them.
    pub const ALL: [AxesKind; 5] = [
        AxesKind::Positioner,
        AxesKind::Track,
        AxesKind::Turntable,
        AxesKind::TrackAndPositioner,
        AxesKind::TrackAndTurntable,
    ];

    /// The kind's name as the API spells it (its serde name).
    pub fn name(self) -> &'static str {
        match self {
            Self::Positioner => "positioner",
            Self::Track => "track",
            Self::Turntable => "turntable",
            Self::TrackAndPositioner => "track_and_positioner",
            Self::TrackAndTurntable => "track_and_turntable",
        }
    }

    /// The kinematic systems written, in their order (ET1, ET2).
    pub fn systems(self) -> &'static [KinematicKind] {
        match self {
            Self::Positioner => &[KinematicKind::Positioner],
            Self::Track => &[KinematicKind::Track],
            Self::Turntable => &[KinematicKind::Turntable],
            Self::TrackAndPositioner => &[KinematicKind::Track, KinematicKind::Positioner],
            Self::TrackAndTurntable => &[KinematicKind::Track, KinematicKind::Turntable],
        }
    }
}

impl KinematicKind {
    /// The kind's name as the API spells it (`positioner`, `track`,
    /// `turntable`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Positioner => "positioner",
            Self::Track => "track",
            Self::Turntable => "turntable",
        }
    }
}

/// The kinds of external kinematic system written (the HTTP export's
/// `axes`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum KinematicKind {
    /// A tilt-rotate positioner: a base kinematic system, `#EASYS`.
    Positioner,
    /// A linear track carrying the robot: a robot-root kinematic system,
    /// `#ERSYS`.
    Track,
    /// A one-axis turntable: a base kinematic system with one axis,
    /// `#EASYS`.
    Turntable,
}

/// The axes as the controller holds them.
#[derive(Debug, Clone, PartialEq)]
pub enum HeldAxes {
    /// The positioner the chain computes, stated in the world: the robot's
    /// base frame, or beside a track the cell frame.
    Positioner(TiltRotate),
    /// The track the chain computes, in the cell frame.
    Track(LinearTrack),
    /// The turntable the chain computes, stated in the world: the robot's
    /// base frame, or beside a track the cell frame.
    Turntable(Turntable),
}

/// One calibrated term the controller's chain cannot hold.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NotHeld {
    /// The term, e.g. `tilt scale` or `yaw`.
    pub term: String,
    /// Its calibrated value (a scale, or a map's largest magnitude over the
    /// travel, on a grid of 201 values) in `unit`.
    pub value: f64,
    /// The value's unit (`""` for a scale).
    pub unit: &'static str,
    /// What it moves a point by [mm]: a rotary scale at [`SCALE_RADIUS_MM`]
    /// over [`SCALE_TURN_DEG`], the track's scale at the travel's farther
    /// end, a carriage position map its own largest value, an angle map at
    /// [`ANGLE_ARM_MM`] from the base.
    pub miss_mm: f64,
}

/// A KUKA external kinematic system for a calibrated positioner or track.
#[derive(Debug, Clone, PartialEq)]
pub struct KukaKinematics {
    /// Positioner or track.
    pub kind: KinematicKind,
    /// Its number `n` (`$ETn_…`): 1, or 2 for a positioner or turntable
    /// beside a track (ET1). Its first axis is `En`.
    pub system: u8,
    /// The root in the world (`MACHINE_DEF[2].ROOT` or `$ERSYSROOT`).
    pub root: Pose,
    /// `$ET1_TA1KR`, `$ET1_TA2A1`, `$ET1_TA3A2`, `$ET1_TFLA3`.
    pub links: [Pose; 4],
    /// What the chain computes, as a model the filter takes.
    pub held: HeldAxes,
    /// The calibrated terms the chain cannot hold.
    pub not_held: Vec<NotHeld>,
}

/// A frame with its origin at `origin` and z along the unit `z` (x: the
/// parent's x, else y, made perpendicular to z).
fn axis_frame(z: &Vector3<f64>, origin: Vector3<f64>) -> Pose {
    let pick = if z.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let x = (pick - z * z.dot(&pick)).normalize();
    let y = z.cross(&x);
    Pose::new(Matrix3::from_columns(&[x, y, *z]), origin)
}

fn rz(angle: f64) -> Pose {
    Pose::new(rpy_matrix(0.0, 0.0, angle), Vector3::zeros())
}

/// The rotary axes' scales other than 1, each with what it moves a point
/// [`SCALE_RADIUS_MM`] from its axis over [`SCALE_TURN_DEG`] by: what a
/// chain of frames cannot hold.
fn rotary_scales(scales: &[(&str, f64)]) -> Vec<NotHeld> {
    scales
        .iter()
        .filter(|(_, s)| *s != 1.0)
        .map(|&(term, s)| NotHeld {
            term: term.into(),
            value: s,
            unit: "",
            miss_mm: (s - 1.0).abs() * SCALE_TURN_DEG.to_radians() * SCALE_RADIUS_MM,
        })
        .collect()
}

/// The calibrated positioner `p` (in the cell frame) as a base kinematic
/// system in the robot's base frame, `world_from_cell` the calibrated
/// model's base-from-cell.
pub fn kuka_positioner(p: &TiltRotate, world_from_cell: &Pose) -> KukaKinematics {
    let root = world_from_cell.compose(&p.cell_from_base);
    let f1 = axis_frame(&p.tilt.direction, p.tilt.point);
    let f2 = axis_frame(&p.rotate.direction, p.rotate.point);
    let links = [
        f1,
        rz(p.tilt.zero_offset).compose(&f1.inverse().compose(&f2)),
        Pose::identity(),
        rz(p.rotate.zero_offset).compose(&f2.inverse().compose(&p.face_plate)),
    ];
    let mut held = *p;
    held.cell_from_base = root;
    held.tilt.scale = 1.0;
    held.rotate.scale = 1.0;
    let not_held = rotary_scales(&[
        ("tilt scale", p.tilt.scale),
        ("rotate scale", p.rotate.scale),
    ]);
    KukaKinematics {
        kind: KinematicKind::Positioner,
        system: 1,
        root,
        links,
        held: HeldAxes::Positioner(held),
        not_held,
    }
}

/// The calibrated turntable `t` (in the cell frame) as a one-axis base
/// kinematic system in the robot's base frame, `world_from_cell` the
/// calibrated model's base-from-cell.
pub fn kuka_turntable(t: &Turntable, world_from_cell: &Pose) -> KukaKinematics {
    let root = world_from_cell.compose(&t.cell_from_base);
    let f1 = axis_frame(&t.axis.direction, t.axis.point);
    let links = [
        f1,
        Pose::identity(),
        Pose::identity(),
        rz(t.axis.zero_offset).compose(&f1.inverse().compose(&t.face_plate)),
    ];
    let mut held = *t;
    held.cell_from_base = root;
    held.axis.scale = 1.0;
    let not_held = rotary_scales(&[("turntable scale", t.axis.scale)]);
    KukaKinematics {
        kind: KinematicKind::Turntable,
        system: 1,
        root,
        links,
        held: HeldAxes::Turntable(held),
        not_held,
    }
}

/// The calibrated track `t` (in the cell frame, the controller's world) as a
/// robot-root kinematic system.
pub fn kuka_track(t: &LinearTrack) -> KukaKinematics {
    let r_rail = t.rail_rotation();
    // z along the rail: the rail frame turned by +90° about its y.
    let turn = rpy_matrix(0.0, FRAC_PI_2, 0.0);
    let root = Pose::new(r_rail * turn, t.rail.point + t.rail.direction * t.zero);
    let links = [
        Pose::identity(),
        Pose::identity(),
        Pose::identity(),
        Pose::new(turn.transpose() * t.mount, Vector3::zeros()),
    ];
    let mut held = t.clone();
    held.scale = 1.0;
    held.maps = Default::default();
    let mut not_held = Vec::new();
    if t.scale != 1.0 {
        let far = t.travel.lo_mm.abs().max(t.travel.hi_mm.abs());
        not_held.push(NotHeld {
            term: "track scale".into(),
            value: t.scale,
            unit: "",
            miss_mm: (t.scale - 1.0).abs() * far,
        });
    }
    for term in CarriageTerm::ALL {
        let map: &TravelMap = &t.maps[term.index()];
        if map.coefficients.is_empty() {
            continue;
        }
        // The largest magnitude over the travel, on a grid of 201 values.
        let largest = (0..=200)
            .map(|i| map.at(f64::from(i) / 100.0 - 1.0).abs())
            .fold(0.0, f64::max);
        let miss_mm = if term.is_angle() {
            largest * ANGLE_ARM_MM
        } else {
            largest * 1e3
        };
        not_held.push(NotHeld {
            term: term.name().into(),
            value: largest * term.per_si(),
            unit: term.unit(),
            miss_mm,
        });
    }
    KukaKinematics {
        kind: KinematicKind::Track,
        system: 1,
        root,
        links,
        held: HeldAxes::Track(held),
        not_held,
    }
}

impl KukaKinematics {
    /// The held positioner's or track's description JSON (what `--held`
    /// writes).
    pub fn held_json(&self) -> String {
        match &self.held {
            HeldAxes::Positioner(p) => p.to_json(),
            HeldAxes::Track(t) => t.to_json(),
            HeldAxes::Turntable(t) => t.to_json(),
        }
    }
    /// This system as ET2 beside a track's ET1: its axes from `E2`, its
    /// root in the cell frame.
    pub fn beside_track(self) -> Self {
        Self { system: 2, ..self }
    }
}
