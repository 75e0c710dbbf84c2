//! The files `positioner simulate --robot` writes for `robocal filter
//! --positioner`: a KRL weld program on a part on the face plate, its cell
//! file and the controller's own positioner.
//!
//! - `controller.json`: the nominal positioner (the drawing) in the
//!   controller's world, which on a fixed base is the robot's base frame:
//!   where the drawing puts it relative to the robot (`P_nom(v)` of
//!   docs/external-axes/programs.md "Programs on a positioner").
//! - `cell.json`: tool 1, a torch 250 mm from the flange tilted 30° (the
//!   examples' `cell.json`), and base 3, the part on the face plate (frame
//!   `face_plate`, 60 mm above the plate).
//! - `part.src`, `part.dat`: `LIN` to each of the part's points
//!   ([`super::positioner_sim`]'s `part.csv`, mm, stated in base 3) at each
//!   pair of axis values (`super::weld`: the torch into the part, the
//!   nominal controller's flags), `E1` the tilt and `E2` the rotate value
//!   [deg].
//!
//! Frames: the controller composes a target `T` in base 3 at values `v` as
//! `P_nom(v)·W₃·T` in the robot's base frame and solves its nominal model
//! with the torch for it; lengths mm in the files, m inside.

use super::weld::{weld, Station, TORCH_MM, TORCH_RPY_DEG};
use nalgebra::Vector3;
use robocal_core::model::calibrated::CompensatedModel;
use robocal_core::model::external::TiltRotate;
use robocal_core::model::Pose;

/// Base 3, the part, on the face plate [mm].
const PART_BASE_MM: [f64; 3] = [0.0, 0.0, 60.0];

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
    let base3 = Pose::from_translation(Vector3::from(PART_BASE_MM) * 1e-3);
    let stations: Vec<Station> = values
        .iter()
        .map(|v| Station {
            frame: controller_positioner
                .cell_from_face_plate(*v)
                .compose(&base3),
            axes: format!("E1 {},E2 {},E3 0.0,E4 0.0,E5 0.0,E6 0.0", v[0], v[1]),
            label: format!("axes {v:?}°"),
            points: points
                .iter()
                .map(|p| {
                    (
                        Vector3::new(p[0], p[1], p[2] - PART_BASE_MM[2]) * 1e-3,
                        format!("point {p:?} mm"),
                    )
                })
                .collect(),
        })
        .collect();
    let program = weld(
        model,
        "; A weld on the part on the positioner (tool 1: torch, base 3: on the face plate).\n$TOOL = TOOL_DATA[1]\n$BASE = BASE_DATA[3]\n",
        &stations,
    )?;
    let cell = serde_json::json!({
        "tools": [{ "name": "torch", "number": 1, "xyz_mm": TORCH_MM, "rpy_deg": TORCH_RPY_DEG }],
        "work_objects": [{ "name": "part", "number": 3, "frame": "face_plate",
                           "xyz_mm": PART_BASE_MM, "rpy_deg": [0.0, 0.0, 0.0] }]
    });
    Ok(PartProgram {
        controller: controller_positioner.to_json(),
        cell: serde_json::to_string_pretty(&cell).expect("JSON of numbers and strings"),
        src: program.src,
        dat: program.dat,
        left_out: program.left_out,
    })
}
