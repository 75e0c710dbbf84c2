//! What the controller must hold for a filtered program: tool data (TCP in
//! the flange frame), load data (mass, centre of mass in the flange frame,
//! principal inertia) and work objects in the controller's base frame, in
//! each language's own form.
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
//! - Fanuc: a TP program setting position registers and `UTOOL[n]`,
//!   `UFRAME[n]` from them (`PR[i,j]`: X, Y, Z mm, W, P, R deg), and the
//!   payload schedule `$PLST_GRP1[n]` (kg; centre of gravity in cm; inertia
//!   in kgf·cm·s²).
//! - URScript: `set_tcp(p[…])`, `set_payload(kg, [cx, cy, cz])` (m, the
//!   rotation vector in rad) and a feature variable `name = p[…]`.

use super::{Cell, Load, Tool};
use crate::calibrate::compensate::CompensatedModel;
use crate::model::orientation::{rotation_to, OrientationConvention};
use crate::model::Pose;
use crate::solve::program::Language;
use std::fmt::Write as _;

/// One tool as the controller holds it.
#[derive(Debug, Clone, PartialEq)]
pub struct ControllerTool {
    pub name: String,
    /// The controller's number (the cell's, else its place in the cell, 1-based).
    pub number: u32,
    /// Flange → TCP [m].
    pub tcp: Pose,
    pub load: Load,
}

/// One work object in the controller's base frame.
#[derive(Debug, Clone, PartialEq)]
pub struct ControllerFrame {
    pub name: String,
    pub number: u32,
    /// Base → work object [m].
    pub pose: Pose,
}

/// The cell's tools and work objects as the controller holds them, for the
/// calibrated `model`: work objects in its base frame, loads on the flange.
pub fn controller_data(
    cell: &Cell,
    model: &CompensatedModel,
) -> (Vec<ControllerTool>, Vec<ControllerFrame>) {
    let model_load = Load {
        mass_kg: model.payload_kg,
        ..Load::of_model(&model.calibrated)
    };
    let tools = cell
        .tools
        .iter()
        .enumerate()
        .map(|(i, t): (usize, &Tool)| ControllerTool {
            name: t.name.clone(),
            number: t.number.unwrap_or(i as u32 + 1),
            tcp: t.tcp,
            load: t.load.unwrap_or(model_load),
        })
        .collect();
    let frames = cell
        .work_objects
        .iter()
        .enumerate()
        .map(|(i, w)| ControllerFrame {
            name: w.name.clone(),
            number: w.number.unwrap_or(i as u32 + 1),
            pose: w.in_base(model),
        })
        .collect();
    (tools, frames)
}

/// A name the language accepts as an identifier (letters, digits, `_`,
/// starting with a letter).
fn ident(name: &str, fallback: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    if s.starts_with(|c: char| c.is_ascii_alphabetic()) {
        s
    } else {
        format!("{fallback}{s}")
    }
}

fn kuka_frame(p: &Pose) -> String {
    let abc = rotation_to(OrientationConvention::KukaAbc, &p.r);
    format!(
        "{{X {:.6},Y {:.6},Z {:.6},A {:.9},B {:.9},C {:.9}}}",
        p.p.x * 1e3,
        p.p.y * 1e3,
        p.p.z * 1e3,
        abc[0],
        abc[1],
        abc[2]
    )
}

fn abb_frame(p: &Pose) -> String {
    let q = rotation_to(OrientationConvention::AbbQ1q4, &p.r);
    format!(
        "[[{:.6},{:.6},{:.6}],[{:.12},{:.12},{:.12},{:.12}]]",
        p.p.x * 1e3,
        p.p.y * 1e3,
        p.p.z * 1e3,
        q[0],
        q[1],
        q[2],
        q[3]
    )
}

fn ur_pose(p: &Pose) -> String {
    let r = rotation_to(OrientationConvention::UrRotvec, &p.r);
    format!(
        "p[{:.9}, {:.9}, {:.9}, {:.12}, {:.12}, {:.12}]",
        p.p.x, p.p.y, p.p.z, r[0], r[1], r[2]
    )
}

/// Fanuc's inertia unit: 1 kgf·cm·s² = 9.80665 N · 0.01 m · s² =
/// 0.0980665 kg·m².
const KGM2_TO_KGF_CM_S2: f64 = 100.0 / 9.80665;

/// The controller's tool, load and work object data in `language`.
pub fn controller_text(
    language: Language,
    tools: &[ControllerTool],
    frames: &[ControllerFrame],
) -> String {
    let mut s = String::new();
    let inertia = |l: &Load| l.inertia_kgm2.unwrap_or([0.0; 3]);
    match language {
        Language::Krl => {
            s.push_str(
                "; robocal: tool, load and base data for $config.dat (mm, deg, kg, kg m2)\r\n",
            );
            for t in tools {
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
                    name = t.name,
                );
            }
            for f in frames {
                let _ = write!(
                    s,
                    "BASE_DATA[{}]={} ; {}\r\n",
                    f.number,
                    kuka_frame(&f.pose),
                    f.name
                );
            }
        }
        Language::Rapid => {
            s.push_str("  ! robocal: tool and work object data (mm, quaternions, kg, kg m2)\r\n");
            for t in tools {
                let j = inertia(&t.load);
                let c = t.load.com * 1e3;
                let _ = write!(
                    s,
                    "  PERS tooldata {}:=[TRUE,{},[{:.6},[{:.6},{:.6},{:.6}],[1,0,0,0],{:.6},{:.6},{:.6}]];\r\n",
                    ident(&t.name, "tool"),
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
            for f in frames {
                let _ = write!(
                    s,
                    "  TASK PERS wobjdata {}:=[FALSE,TRUE,\"\",{},[[0,0,0],[1,0,0,0]]];\r\n",
                    ident(&f.name, "wobj"),
                    abb_frame(&f.pose)
                );
            }
        }
        Language::Fanuc => fanuc_text(&mut s, tools, frames),
        Language::UrScript => {
            s.push_str("# robocal: tool, payload and feature data (m, rad, kg)\n");
            for t in tools {
                let c = t.load.com;
                let _ = write!(
                    s,
                    "# tool {}\nset_tcp({})\nset_payload({:.6}, [{:.9}, {:.9}, {:.9}])\n",
                    t.name,
                    ur_pose(&t.tcp),
                    t.load.mass_kg,
                    c.x,
                    c.y,
                    c.z
                );
            }
            for f in frames {
                let _ = writeln!(
                    s,
                    "global {} = {}",
                    ident(&f.name, "feature"),
                    ur_pose(&f.pose)
                );
            }
        }
    }
    s
}

/// A TP program: `PR[…]` set element by element, `UTOOL`/`UFRAME` from them,
/// the payload schedules.
fn fanuc_text(s: &mut String, tools: &[ControllerTool], frames: &[ControllerFrame]) {
    let mut lines: Vec<String> = Vec::new();
    let mut pr = 90;
    let mut set = |lines: &mut Vec<String>, p: &Pose, what: &str| {
        pr += 1;
        let wpr = rotation_to(OrientationConvention::FanucWpr, &p.r);
        let v = [
            p.p.x * 1e3,
            p.p.y * 1e3,
            p.p.z * 1e3,
            wpr[0],
            wpr[1],
            wpr[2],
        ];
        lines.push(format!("PR[{pr}]=LPOS ;"));
        for (j, x) in v.iter().enumerate() {
            let decimals = if j < 3 { 6 } else { 9 };
            lines.push(format!("PR[{pr},{}]={x:.decimals$} ;", j + 1));
        }
        lines.push(format!("{what}=PR[{pr}] ;"));
    };
    for t in tools {
        lines.push(format!("! tool {} ;", t.name));
        set(&mut lines, &t.tcp, &format!("UTOOL[{}]", t.number));
    }
    for f in frames {
        lines.push(format!("! frame {} ;", f.name));
        set(&mut lines, &f.pose, &format!("UFRAME[{}]", f.number));
    }
    for t in tools {
        let c = t.load.com * 1e2;
        let j = t.load.inertia_kgm2.unwrap_or([0.0; 3]);
        let n = t.number;
        lines.push(format!("! payload of tool {} ;", t.name));
        lines.push(format!("$PLST_GRP1[{n}].$PAYLOAD={:.6} ;", t.load.mass_kg));
        for (k, axis) in ["X", "Y", "Z"].iter().enumerate() {
            lines.push(format!("$PLST_GRP1[{n}].$PAYLOAD_{axis}={:.6} ;", c[k]));
        }
        for (k, axis) in ["X", "Y", "Z"].iter().enumerate() {
            lines.push(format!(
                "$PLST_GRP1[{n}].$PAYLOAD_I{axis}={:.6} ;",
                j[k] * KGM2_TO_KGF_CM_S2
            ));
        }
    }
    let _ = write!(
        s,
        "/PROG  ROBOCAL_FRAMES\n/ATTR\nCOMMENT = \"robocal frames\";\n/MN\n"
    );
    for (i, l) in lines.iter().enumerate() {
        let _ = writeln!(s, "{:4}:  {l}", i + 1);
    }
    s.push_str("/POS\n/END\n");
}
