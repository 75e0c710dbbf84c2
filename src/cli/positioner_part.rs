//! The files `positioner simulate --robot` writes for `robocal filter
//! --positioner`: a KRL weld program on a part on the face plate, its cell
//! file and the controller's own positioner.
//!
//! - `controller.json`: the nominal positioner (the drawing) in the
//!   controller's world, which on a fixed base is the robot's base frame:
//!   where the drawing puts it relative to the robot (`P_nom(v)` of
//!   docs/external-axes.md "Programs on a positioner").
//! - `cell.json`: tool 1, a torch 250 mm from the flange tilted 30° (the
//!   examples' `cell.json`), and base 3, the part on the face plate (frame
//!   `face_plate`, 60 mm above the plate).
//! - `part.src`, `part.dat`: `LIN` to each of the part's points
//!   ([`super::positioner_sim`]'s `part.csv`, mm, stated in base 3) at each
//!   pair of axis values, the torch pointing into the part (`C 180`) and
//!   spun about its axis in 15° steps until every joint the controller
//!   computes is 2° clear of the sign its flags record; `S` and `T` are
//!   the nominal controller's own (its closed form, elbow up in front where
//!   a spin allows it, else any branch within the limits; the solution
//!   nearest the previous target's), `E1` the tilt and `E2` the rotate
//!   value [deg].
//!
//! Frames: the controller composes a target `T` in base 3 at values `v` as
//! `P_nom(v)·W₃·T` in the robot's base frame and solves its nominal model
//! with the torch for it; lengths mm in the files, m inside.

use nalgebra::Vector3;
use robocal_core::model::calibrated::CompensatedModel;
use robocal_core::model::external::TiltRotate;
use robocal_core::model::orientation::{rotation_to, OrientationConvention};
use robocal_core::model::pose::rpy_matrix;
use robocal_core::model::{Pose, Tool};
use robocal_core::program::{kuka_status, kuka_turn};
use robocal_core::solve::ik::{AnalyticIk, Elbow, Shoulder};
use std::fmt::Write as _;

/// The torch: TCP in the flange frame [mm] and its `rpy_deg`.
const TORCH_MM: [f64; 3] = [125.0, 0.0, 216.50635];
const TORCH_RPY_DEG: [f64; 3] = [0.0, 30.0, 0.0];
/// Base 3, the part, on the face plate [mm].
const PART_BASE_MM: [f64; 3] = [0.0, 0.0, 60.0];
/// How far every controller joint stays from the sign its flags record [deg].
const FLAG_MARGIN_DEG: f64 = 2.0;

/// The program's files.
pub(crate) struct PartProgram {
    /// `controller.json`.
    pub(crate) controller: String,
    /// `cell.json`.
    pub(crate) cell: String,
    /// `part.src`.
    pub(crate) src: String,
    /// `part.dat`.
    pub(crate) dat: String,
    /// The points and values left out of the program: out of the nominal
    /// robot's reach with the torch pointing into the part.
    pub(crate) left_out: Vec<String>,
}

/// The files for `points` (face plate frame, mm) at `values` (tilt, rotate,
/// deg) on `nominal` placed at `in_base` (the drawing's placement in the
/// robot's base frame), for `model`'s nominal robot. A point the controller
/// cannot reach with clear flags at a pair of values is left out and named;
/// `Err` when none is left.
pub(crate) fn part_program(
    model: &CompensatedModel,
    nominal: &TiltRotate,
    in_base: Pose,
    points: &[[f64; 3]],
    values: &[[f64; 2]],
) -> Result<PartProgram, String> {
    let controller_positioner = TiltRotate {
        cell_from_base: in_base,
        ..*nominal
    };
    let mut controller = model.nominal.clone();
    controller.tool = Tool {
        p: Vector3::from(TORCH_MM) * 1e-3,
        rpy: TORCH_RPY_DEG.map(f64::to_radians),
    };
    let ik = AnalyticIk::new(&controller)
        .map_err(|e| format!("the robot's nominal model has no closed form: {e}"))?;
    let base3 = Pose::new(
        nalgebra::Matrix3::identity(),
        Vector3::from(PART_BASE_MM) * 1e-3,
    );
    let mut src = String::from(
        "DEF part()\n; A weld on the part on the positioner (tool 1: torch, base 3: on the face plate).\n$TOOL = TOOL_DATA[1]\n$BASE = BASE_DATA[3]\n",
    );
    let mut dat = String::from("DEFDAT part\n");
    let mut previous: Option<Vec<f64>> = None;
    let mut n = 0;
    let mut left_out = Vec::new();
    for v in values {
        let plate = controller_positioner
            .cell_from_face_plate(*v)
            .compose(&base3);
        for p in points {
            let at = Vector3::new(p[0], p[1], p[2] - PART_BASE_MM[2]) * 1e-3;
            // Elbow up in front where the part allows, else any branch.
            let Some((target, q_deg, configuration, q)) =
                [true, false].into_iter().find_map(|upright| {
                    (0..24).find_map(|k| {
                        let spin = (15.0 * f64::from(k)).to_radians();
                        let target = Pose::new(rpy_matrix(std::f64::consts::PI, 0.0, spin), at);
                        let tcp = plate.compose(&target);
                        ik.solve(&tcp, previous.as_deref())
                            .into_iter()
                            .filter(|s| {
                                s.within_limits
                                    && !s.singular
                                    && (!upright
                                        || s.configuration.elbow == Elbow::Up
                                            && s.configuration.shoulder == Shoulder::Front)
                            })
                            .map(|s| {
                                let q_deg: Vec<f64> = controller
                                    .joints_to_controller(&s.q)
                                    .iter()
                                    .map(|q| q.to_degrees())
                                    .collect();
                                (target, q_deg, s.configuration, s.q)
                            })
                            .filter(|c| c.1.iter().all(|q| q.abs() >= FLAG_MARGIN_DEG))
                            .min_by(|a, b| {
                                distance(&a.3, previous.as_deref())
                                    .total_cmp(&distance(&b.3, previous.as_deref()))
                            })
                    })
                })
            else {
                left_out.push(format!("point {p:?} mm at axes {v:?}°"));
                continue;
            };
            n += 1;
            previous = Some(q.to_vec());
            let s = kuka_status(&q_deg, configuration);
            let abc = rotation_to(OrientationConvention::KukaAbc, &target.r);
            writeln!(src, "LIN XP{n}").expect("a String takes writes");
            writeln!(
                dat,
                "DECL E6POS XP{n}={{X {:.3},Y {:.3},Z {:.3},A {:.3},B {:.3},C {:.3},S {s},T {},E1 {},E2 {},E3 0.0,E4 0.0,E5 0.0,E6 0.0}}",
                target.p.x * 1e3,
                target.p.y * 1e3,
                target.p.z * 1e3,
                abc[0],
                abc[1],
                abc[2],
                kuka_turn(&q_deg),
                v[0],
                v[1]
            )
            .expect("a String takes writes");
        }
    }
    if n == 0 {
        return Err(format!(
            "none of the part's points is within the nominal robot's reach (every branch within \
             the limits, joints {FLAG_MARGIN_DEG}° clear of 0)"
        ));
    }
    src.push_str("END\n");
    dat.push_str("ENDDAT\n");
    let cell = serde_json::json!({
        "tools": [{ "name": "torch", "number": 1, "xyz_mm": TORCH_MM, "rpy_deg": TORCH_RPY_DEG }],
        "work_objects": [{ "name": "part", "number": 3, "frame": "face_plate",
                           "xyz_mm": PART_BASE_MM, "rpy_deg": [0.0, 0.0, 0.0] }]
    });
    Ok(PartProgram {
        controller: controller_positioner.to_json(),
        cell: serde_json::to_string_pretty(&cell).expect("JSON of numbers and strings"),
        src,
        dat,
        left_out,
    })
}

/// Sum of absolute joint differences [rad]; 0 without a previous solution.
fn distance(q: &[f64], previous: Option<&[f64]>) -> f64 {
    previous.map_or(0.0, |p| q.iter().zip(p).map(|(a, b)| (a - b).abs()).sum())
}
