//! The files `track simulate` writes for `robocal filter --track`: a KRL
//! weld along a part beside the rail and its cell file.
//!
//! - `cell.json`: tool 1, the torch of `super::weld`; base 2, the part,
//!   measured in the cell (tracker) frame (frame `measurement`): in the
//!   drawing's rail frame 2 m along the rail, 1.3 m beside it and 0.2 m below
//!   the rail's line, turned 10° about the vertical.
//! - `part.src`, `part.dat`: `LIN` to nine points along the part's seam (its
//!   x axis, −1.6 … 1.6 m), each at the track value `E1` that puts the
//!   robot's base beside it on the drawing's rail (clamped to the travel),
//!   the torch into the part, the nominal controller's flags
//!   (`super::weld`); a point out of reach is left out and named.
//!
//! Frames: the controller's world is the cell frame; it composes a target
//! `T` in base 2 at value `e` as `N(e)⁻¹·W₂·T` in the robot's base frame,
//! `N` the drawing's track (`TrueTrack::drawing_4m`); lengths mm in the
//! files, m inside.

use super::weld::{weld, Station, TORCH_MM, TORCH_RPY_DEG};
use nalgebra::Vector3;
use robocal_core::model::calibrated::CompensatedModel;
use robocal_core::model::external::LinearTrack;
use robocal_core::model::orientation::fixed_xyz_angles;
use robocal_core::model::Pose;
use robocal_core::sim::track::TrueTrack;

/// The seam's points along the part's x [m].
const SEAM_M: [f64; 9] = [-1.6, -1.2, -0.8, -0.4, 0.0, 0.4, 0.8, 1.2, 1.6];

/// The program's files.
pub(crate) struct TrackProgram {
    /// `cell.json`.
    pub(crate) cell: String,
    /// `part.src`.
    pub(crate) src: String,
    /// `part.dat`.
    pub(crate) dat: String,
    /// The points left out: out of the nominal robot's reach.
    pub(crate) left_out: Vec<String>,
}

/// The part in the cell frame, placed in the drawing's rail frame
/// (`TrueTrack::drawing_rail_4m`).
fn part_in_cell() -> Pose {
    let mut on_rail = Pose::from_translation(Vector3::new(2.0, 1.3, -0.2));
    on_rail.rot_z(10f64.to_radians());
    TrueTrack::drawing_rail_4m().compose(&on_rail)
}

/// The files for `model`'s nominal robot on the controller's `drawing`
/// track; `Err` when no point is within reach.
pub(crate) fn track_program(
    model: &CompensatedModel,
    drawing: &LinearTrack,
) -> Result<TrackProgram, String> {
    let part = part_in_cell();
    let travel = drawing.travel;
    // The robot's base at the travel's start: the values count from it.
    let start = drawing
        .cell_from_base(travel.lo_mm)
        .map_err(|e| e.to_string())?
        .p;
    let stations = SEAM_M
        .iter()
        .map(|x| {
            let at = Vector3::new(*x, 0.0, 0.0);
            let in_cell = part.transform_point(&at);
            let e = (travel.lo_mm + (in_cell - start).dot(&drawing.rail.direction) * 1e3)
                .round()
                .clamp(travel.lo_mm, travel.hi_mm);
            let base = drawing.cell_from_base(e).map_err(|e| e.to_string())?;
            Ok(Station {
                frame: base.inverse().compose(&part),
                axes: format!("E1 {e},E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0"),
                label: format!("E1 {e} mm"),
                points: vec![(at, format!("point [{:.0}, 0, 0] mm", x * 1e3))],
            })
        })
        .collect::<Result<Vec<Station>, String>>()?;
    let program = weld(
        model,
        "; A weld along the part beside the rail (tool 1: torch, base 2: measured in the cell).\n$TOOL = TOOL_DATA[1]\n$BASE = BASE_DATA[2]\n",
        &stations,
    )?;
    let rpy = fixed_xyz_angles(&part.r).map(f64::to_degrees);
    let cell = serde_json::json!({
        "tools": [{ "name": "torch", "number": 1, "xyz_mm": TORCH_MM, "rpy_deg": TORCH_RPY_DEG }],
        "work_objects": [{ "name": "part", "number": 2, "frame": "measurement",
                           "xyz_mm": (part.p * 1e3).as_slice(), "rpy_deg": rpy }]
    });
    Ok(TrackProgram {
        cell: serde_json::to_string_pretty(&cell).expect("JSON of numbers and strings"),
        src: program.src,
        dat: program.dat,
        left_out: program.left_out,
    })
}
