//! What the controller must hold for a filtered program: tool data (TCP in
//! the flange frame), load data (mass, centre of mass in the flange frame,
//! principal inertia) and work objects in the controller's base frame, in
//! each language's own form, as a controller loads it.
//!
//! Frames: a work object measured in the tracker frame is given to the
//! controller as `base_from_cell·W` (`WorkObject::in_base`) of the calibrated
//! version used; a tool without a stated load carries the model's payload
//! kept at its flange point (`Load::of_model`).
//!
//! Units and forms (values written with 6 decimals in mm and 9 in degrees,
//! so a pose reads back to better than 1e-6 mm):
//! - KRL, lines for `$config.dat`: `TOOL_DATA[n]={X,Y,Z,A,B,C}`,
//!   `LOAD_DATA[n]={M kg,CM {X,Y,Z mm,A,B,C},J {X,Y,Z kg·m²}}`,
//!   `BASE_DATA[n]={…}`; `R = Rz(A)·Ry(B)·Rx(C)`.
//! - RAPID: `PERS tooldata name:=[TRUE,[[x,y,z],[q1..q4]],[kg,[cx,cy,cz],
//!   [1,0,0,0],ix,iy,iz]]`, `PERS wobjdata name:=[FALSE,TRUE,"",[uframe],
//!   [[0,0,0],[1,0,0,0]]]` (mm, quaternion scalar first, kg·m²).
//! - Fanuc: a TP program with the payload schedules `$PLST_GRP1[n]` (kg;
//!   centre of gravity in cm; inertia in kgf·cm·s²) and, with the position
//!   registers the user gives, `UTOOL[n]`, `UFRAME[n]` set from them
//!   (`PR[i,j]`: X, Y, Z mm, W, P, R deg) — `fanuc.rs`.
//! - URScript: `set_tcp(p[…])`, `set_payload(kg, [cx, cy, cz])` (m, the
//!   rotation vector in rad) and a feature variable `name = p[…]`.
//!
//! What a controller loads (the checks, each refusing with the item named):
//! one number per item (`solve::cell::numbering`: the cell's own, else the
//! lowest free, reported in the header comment and [`ControllerExport`]),
//! within the controller's range and never 0 where 0 is the flange or the
//! base (`numbers.rs`); identifiers valid and distinct (`names.rs`), every
//! renaming reported; registers only those the user names.

mod data;
mod fanuc;
mod frames;
mod kinematics;
mod kinematics_text;
mod names;
mod numbers;

pub(crate) use data::comment;
pub use data::{
    ControllerData, ControllerExport, ControllerFrame, ControllerTool, ExportError, ExportOptions,
};
use frames::{abb_frame, kuka_frame, ur_pose};
pub use kinematics::{
    kuka_positioner, kuka_track, kuka_turntable, AxesKind, ExternalAxes, HeldAxes, KinematicKind,
    KukaKinematics, NotHeld, ANGLE_ARM_MM, SCALE_RADIUS_MM, SCALE_TURN_DEG,
};
pub use kinematics_text::kuka_text;
pub use names::{RenameReason, Renamed};
pub use numbers::{NumberRange, RegisterRange, UsedRegister};

use crate::model::calibrated::CompensatedModel;
use crate::model::Pose;
use crate::program::Language;
use crate::solve::cell::numbering::{self, ItemKind};
use crate::solve::cell::{Cell, Load, Tool};
use std::fmt::Write as _;

/// The cell's tools and work objects as the controller holds them, for the
/// calibrated `model`: work objects in its base frame, loads on the flange,
/// numbers by [`numbering`].
pub fn controller_data(cell: &Cell, model: &CompensatedModel) -> ControllerData {
    let model_load = Load {
        mass_kg: model.payload_kg,
        ..Load::of_model(&model.calibrated)
    };
    let tools = cell
        .tools
        .iter()
        .zip(cell.tool_numbers())
        .map(|(t, number): (&Tool, u32)| ControllerTool {
            name: t.name.clone(),
            number,
            tcp: t.tcp,
            load: t.load.unwrap_or(model_load),
        })
        .collect();
    let frames = cell
        .work_objects
        .iter()
        .zip(cell.work_object_numbers())
        .map(|(w, number)| ControllerFrame {
            name: w.name.clone(),
            number,
            pose: w.in_base(model),
        })
        .collect();
    let declared = |v: Vec<(&str, Option<u32>)>, kind| numbering::assigned(kind, &v);
    let mut assigned = declared(
        cell.tools
            .iter()
            .map(|t| (t.name.as_str(), t.number))
            .collect(),
        ItemKind::Tool,
    );
    assigned.extend(declared(
        cell.work_objects
            .iter()
            .map(|w| (w.name.as_str(), w.number))
            .collect(),
        ItemKind::WorkObject,
    ));
    ControllerData {
        tools,
        frames,
        assigned,
    }
}

/// The cell exported for `language` on the calibrated `model`; with
/// `options.axes`, the positioner's, turntable's or track's kinematic
/// systems too (KRL only): work objects on the face plate are then bases
/// coupled to the positioner, and on a track every work object is held in
/// the world (the cell frame).
pub fn export_cell(
    language: Language,
    cell: &Cell,
    model: &CompensatedModel,
    options: &ExportOptions,
) -> Result<ControllerExport, ExportError> {
    use crate::solve::cell::WorkObjectFrame;
    let on = |frame: WorkObjectFrame| cell.work_objects.iter().find(|w| w.frame == frame);
    let mut data = controller_data(cell, model);
    if options.axes.is_some() && language != Language::Krl {
        return Err(ExportError::AxesNotWritten(language));
    }
    let world_from_cell = model.cell_to_base(&Pose::identity());
    let systems = options
        .axes
        .as_ref()
        .map_or(&[][..], |a| a.kind().systems());
    let on_a_track = systems.contains(&KinematicKind::Track);
    let with_a_plate = systems.iter().any(|k| *k != KinematicKind::Track);
    if !with_a_plate {
        if let Some(w) = on(WorkObjectFrame::FacePlate) {
            return Err(ExportError::OnFacePlate(w.name.clone()));
        }
    }
    if on_a_track {
        if let Some(w) = on(WorkObjectFrame::Base) {
            return Err(ExportError::RidesTheCarriage(w.name.clone()));
        }
        // The world is the cell frame: a measured work object as it is, one
        // on the face plate as its pose on the plate.
        for (f, w) in data.frames.iter_mut().zip(&cell.work_objects) {
            f.pose = w.pose;
        }
    }
    let kinematics = match &options.axes {
        None => vec![],
        Some(ExternalAxes::Positioner(p)) => vec![kuka_positioner(p, &world_from_cell)],
        Some(ExternalAxes::Turntable(t)) => vec![kuka_turntable(t, &world_from_cell)],
        Some(ExternalAxes::Track(t)) => vec![kuka_track(t)],
        Some(ExternalAxes::TrackAndPositioner(t, p)) => vec![
            kuka_track(t),
            kuka_positioner(p, &Pose::identity()).beside_track(),
        ],
        Some(ExternalAxes::TrackAndTurntable(t, tt)) => vec![
            kuka_track(t),
            kuka_turntable(tt, &Pose::identity()).beside_track(),
        ],
    };
    let mut out = controller_text(language, &data, options)?;
    if !kinematics.is_empty() {
        out.text.push_str(&kuka_text(&kinematics));
        for (f, w) in data.frames.iter().zip(&cell.work_objects) {
            if w.frame == WorkObjectFrame::FacePlate {
                out.text.push_str(&coupled_base_line(f));
            }
        }
    }
    out.kinematics = kinematics;
    Ok(out)
}

/// The KRL comment saying that base `f` (its pose on the face plate) is
/// coupled to the positioner's or turntable's kinematic system, `MACHINE_DEF[2]`.
pub(crate) fn coupled_base_line(f: &ControllerFrame) -> String {
    format!(
        "; BASE_DATA[{n}] {} is on the face plate: $BASE=EK(MACHINE_DEF[2].ROOT,MACHINE_DEF[2].MECH_TYPE,BASE_DATA[{n}])\r\n",
        comment(&f.name, Language::Krl),
        n = f.number
    )
}

/// Refuses numbers the controller does not take, or one held twice.
fn check_numbers(language: Language, data: &ControllerData) -> Result<(), ExportError> {
    let items: [(ItemKind, Vec<(&str, u32)>); 2] = [
        (
            ItemKind::Tool,
            data.tools
                .iter()
                .map(|t| (t.name.as_str(), t.number))
                .collect(),
        ),
        (
            ItemKind::WorkObject,
            data.frames
                .iter()
                .map(|f| (f.name.as_str(), f.number))
                .collect(),
        ),
    ];
    for (kind, list) in items {
        let Some(range) = numbers::range(language, kind) else {
            continue;
        };
        let names: Vec<&str> = list.iter().map(|(n, _)| *n).collect();
        let nums: Vec<u32> = list.iter().map(|(_, n)| *n).collect();
        if let Some(d) = numbering::duplicate(kind, &names, &nums) {
            return Err(d.into());
        }
        for (name, number) in list {
            let assigned = data
                .assigned
                .iter()
                .any(|a| a.kind == kind && a.name == name && a.number == number);
            if number == 0 {
                return Err(ExportError::NumberZero {
                    kind,
                    name: name.to_string(),
                    range,
                });
            }
            if number < range.first || number > range.last {
                return Err(ExportError::NumberOutOfRange {
                    kind,
                    name: name.to_string(),
                    number,
                    assigned,
                    range,
                });
            }
        }
    }
    Ok(())
}

/// The header comment lines of the numbers given by the export.
fn assigned_lines(language: Language, data: &ControllerData) -> Vec<String> {
    data.assigned
        .iter()
        .filter_map(|a| {
            let range = numbers::range(language, a.kind)?;
            Some(format!(
                "{} `{}` has no number: {}[{}], the lowest free",
                a.kind.label(),
                comment(&a.name, language),
                range.data,
                a.number
            ))
        })
        .collect()
}

fn inertia(l: &Load) -> [f64; 3] {
    l.inertia_kgm2.unwrap_or([0.0; 3])
}

/// The controller's tool, load and work object data in `language`, or why
/// the controller could not load them.
pub fn controller_text(
    language: Language,
    data: &ControllerData,
    options: &ExportOptions,
) -> Result<ControllerExport, ExportError> {
    check_numbers(language, data)?;
    let sorted = in_order(language, data);
    let data = &sorted;
    let mut out = ControllerExport {
        text: String::new(),
        assigned: data
            .assigned
            .iter()
            .filter(|a| numbers::range(language, a.kind).is_some())
            .cloned()
            .collect(),
        renamed: Vec::new(),
        registers: Vec::new(),
        kinematics: Vec::new(),
    };
    let notes = assigned_lines(language, data);
    match language {
        Language::Krl => out.text = krl_text(data, &notes),
        Language::Rapid => {
            let ids = identifiers(&names::RAPID, data, true);
            out.text = rapid_text(data, &ids);
            out.renamed = ids.renamed;
        }
        Language::Fanuc => {
            let (text, registers) = fanuc::program(data, &notes, options.registers)?;
            out.text = text;
            out.registers = registers;
        }
        Language::UrScript => {
            let ids = identifiers(&names::URSCRIPT, data, false);
            out.text = ur_text(data, &ids);
            out.renamed = ids.renamed;
        }
    }
    Ok(out)
}

/// `data`'s items in the order they are written, whatever the cell's order:
/// by number where the language numbers them, else by name (ASCII case
/// folded, then as written).
fn in_order(language: Language, data: &ControllerData) -> ControllerData {
    let numbered = numbers::range(language, ItemKind::Tool).is_some();
    let key = |number: u32, name: &str| {
        (
            if numbered { number } else { 0 },
            name.to_ascii_lowercase(),
            name.to_string(),
        )
    };
    let mut out = data.clone();
    out.tools.sort_by_cached_key(|t| key(t.number, &t.name));
    out.frames.sort_by_cached_key(|f| key(f.number, &f.name));
    out
}

/// The identifiers of `data`'s items (tools only when the language
/// declares them).
fn identifiers(rules: &names::Rules, data: &ControllerData, tools: bool) -> names::Identifiers {
    let t: Vec<&str> = if tools {
        data.tools.iter().map(|t| t.name.as_str()).collect()
    } else {
        Vec::new()
    };
    let f: Vec<&str> = data.frames.iter().map(|f| f.name.as_str()).collect();
    names::identifiers(rules, &t, &f)
}

fn krl_text(data: &ControllerData, notes: &[String]) -> String {
    let mut s = String::from(
        "; robocal: tool, load and base data for $config.dat (mm, deg, kg, kg m2)\r\n",
    );
    for n in notes {
        let _ = write!(s, "; robocal: {n}\r\n");
    }
    for t in &data.tools {
        let j = inertia(&t.load);
        let c = t.load.com * 1e3;
        let _ = write!(
            s,
            "TOOL_DATA[{n}]={} ; {name}\r\nLOAD_DATA[{n}]={{M {:.6},CM {{X {:.6},Y {:.6},Z {:.6},A 0.0,B 0.0,C 0.0}},J {{X {:.6},Y {:.6},Z {:.6}}}}}\r\n",
            kuka_frame(&t.tcp),
            t.load.mass_kg,
            c.x,
            c.y,
            c.z,
            j[0],
            j[1],
            j[2],
            n = t.number,
            name = comment(&t.name, Language::Krl),
        );
    }
    for f in &data.frames {
        let _ = write!(
            s,
            "BASE_DATA[{}]={} ; {}\r\n",
            f.number,
            kuka_frame(&f.pose),
            comment(&f.name, Language::Krl)
        );
    }
    s
}

fn rapid_text(data: &ControllerData, ids: &names::Identifiers) -> String {
    let mut s =
        String::from("  ! robocal: tool and work object data (mm, quaternions, kg, kg m2)\r\n");
    for r in &ids.renamed {
        let _ = write!(
            s,
            "  ! robocal: {}\r\n",
            comment(&r.describe(), Language::Rapid)
        );
    }
    for (t, id) in data.tools.iter().zip(&ids.tools) {
        let j = inertia(&t.load);
        let c = t.load.com * 1e3;
        let _ = write!(
            s,
            "  PERS tooldata {id}:=[TRUE,{},[{:.6},[{:.6},{:.6},{:.6}],[1,0,0,0],{:.6},{:.6},{:.6}]];\r\n",
            abb_frame(&t.tcp),
            t.load.mass_kg,
            c.x,
            c.y,
            c.z,
            j[0],
            j[1],
            j[2]
        );
    }
    for (f, id) in data.frames.iter().zip(&ids.frames) {
        let _ = write!(
            s,
            "  TASK PERS wobjdata {id}:=[FALSE,TRUE,\"\",{},[[0,0,0],[1,0,0,0]]];\r\n",
            abb_frame(&f.pose)
        );
    }
    s
}

fn ur_text(data: &ControllerData, ids: &names::Identifiers) -> String {
    let mut s = String::from("# robocal: tool, payload and feature data (m, rad, kg)\n");
    for r in &ids.renamed {
        let _ = writeln!(
            s,
            "# robocal: {}",
            comment(&r.describe(), Language::UrScript)
        );
    }
    for t in &data.tools {
        let c = t.load.com;
        let _ = write!(
            s,
            "# tool {}\nset_tcp({})\nset_payload({:.6}, [{:.9}, {:.9}, {:.9}])\n",
            comment(&t.name, Language::UrScript),
            ur_pose(&t.tcp),
            t.load.mass_kg,
            c.x,
            c.y,
            c.z
        );
    }
    for (f, id) in data.frames.iter().zip(&ids.frames) {
        let _ = writeln!(s, "global {id} = {}", ur_pose(&f.pose));
    }
    s
}

#[cfg(test)]
mod tests;
