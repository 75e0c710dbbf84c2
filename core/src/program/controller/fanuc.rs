//! The Fanuc export: a TP program (`.ls`). A TP program can set a tool or
//! user frame only from a position register (`UTOOL[n]=PR[i]`), which it
//! overwrites; so the registers are the user's choice, never the export's:
//!
//! - with a register range (`--registers 91..99`, JSON `registers`), each
//!   tool and then each work object takes the next register of the range:
//!   `PR[i]=LPOS` (a Cartesian register), its six elements `PR[i,1..6]` =
//!   X, Y, Z [mm], W, P, R [deg], then `UTOOL[n]=PR[i]` / `UFRAME[n]=PR[i]`;
//!   the header remark names the registers overwritten, and a range shorter
//!   than the items is refused;
//! - without one, no register is written: each frame's values are remark
//!   lines, for entry on the controller's frame setup screen, and the
//!   header remark says so and how to have them set.
//!
//! The payload schedules `$PLST_GRP1[n]` (system variables, kg, cm,
//! kgf·cm·s²) are set in both forms, `n` the tool's number.

use super::data::{comment, ControllerData, ExportError};
use super::numbers::{RegisterRange, UsedRegister};
use crate::model::orientation::{rotation_to, OrientationConvention};
use crate::model::Pose;
use crate::program::Language;
use crate::solve::cell::numbering::ItemKind;
use std::fmt::Write as _;

/// Fanuc's inertia unit: 1 kgf·cm·s² = 9.80665 N · 0.01 m · s² =
/// 0.0980665 kg·m².
const KGM2_TO_KGF_CM_S2: f64 = 100.0 / 9.80665;

/// X, Y, Z [mm], W, P, R [deg] of a pose.
fn xyzwpr(p: &Pose) -> [f64; 6] {
    let wpr = rotation_to(OrientationConvention::FanucWpr, &p.r);
    [
        p.p.x * 1e3,
        p.p.y * 1e3,
        p.p.z * 1e3,
        wpr[0],
        wpr[1],
        wpr[2],
    ]
}

/// `v` with 6 decimals for the lengths and 9 for the angles.
fn value(j: usize, x: f64) -> String {
    let decimals = if j < 3 { 6 } else { 9 };
    format!("{x:.decimals$}")
}

/// The program and the registers it overwrites.
pub(super) fn program(
    data: &ControllerData,
    notes: &[String],
    registers: Option<RegisterRange>,
) -> Result<(String, Vec<UsedRegister>), ExportError> {
    let items: Vec<(ItemKind, &str, u32, &Pose)> = data
        .tools
        .iter()
        .map(|t| (ItemKind::Tool, t.name.as_str(), t.number, &t.tcp))
        .chain(
            data.frames
                .iter()
                .map(|f| (ItemKind::WorkObject, f.name.as_str(), f.number, &f.pose)),
        )
        .collect();
    let mut lines: Vec<String> = Vec::new();
    let mut used = Vec::new();
    match registers {
        Some(range) => {
            if range.count() < items.len() {
                return Err(ExportError::TooFewRegisters {
                    needed: items.len(),
                    given: range.count(),
                    range,
                });
            }
            if !items.is_empty() {
                lines.push(format!(
                    "! robocal overwrites PR[{}..{}] ;",
                    range.first,
                    range.first as usize + items.len() - 1
                ));
            }
        }
        None => {
            lines.push("! robocal: no position register written ;".into());
            lines.push("! enter the frames below by hand ;".into());
            lines.push("! or export with registers FIRST..LAST ;".into());
        }
    }
    for n in notes {
        lines.push(format!("! {} ;", comment(n, Language::Fanuc)));
    }
    for (k, (kind, name, number, pose)) in items.iter().enumerate() {
        let data = match kind {
            ItemKind::Tool => "UTOOL",
            ItemKind::WorkObject => "UFRAME",
        };
        let v = xyzwpr(pose);
        lines.push(format!(
            "! {} {} ;",
            if *kind == ItemKind::Tool {
                "tool"
            } else {
                "frame"
            },
            comment(name, Language::Fanuc)
        ));
        match registers {
            Some(range) => {
                let pr = range.first + k as u32;
                lines.push(format!("PR[{pr}]=LPOS ;"));
                for (j, x) in v.iter().enumerate() {
                    lines.push(format!("PR[{pr},{}]={} ;", j + 1, value(j, *x)));
                }
                lines.push(format!("{data}[{number}]=PR[{pr}] ;"));
                used.push(UsedRegister {
                    register: pr,
                    kind: *kind,
                    name: name.to_string(),
                });
            }
            None => {
                lines.push(format!(
                    "! {data}[{number}] X {} Y {} Z {} ;",
                    value(0, v[0]),
                    value(1, v[1]),
                    value(2, v[2])
                ));
                lines.push(format!(
                    "! {data}[{number}] W {} P {} R {} ;",
                    value(3, v[3]),
                    value(4, v[4]),
                    value(5, v[5])
                ));
            }
        }
    }
    for t in &data.tools {
        let c = t.load.com * 1e2;
        let j = t.load.inertia_kgm2.unwrap_or([0.0; 3]);
        let n = t.number;
        lines.push(format!(
            "! payload of tool {} ;",
            comment(&t.name, Language::Fanuc)
        ));
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
    let mut s = String::from("/PROG  ROBOCAL_FRAMES\n/ATTR\nCOMMENT = \"robocal frames\";\n/MN\n");
    for (i, l) in lines.iter().enumerate() {
        let _ = writeln!(s, "{:4}:  {l}", i + 1);
    }
    s.push_str("/POS\n/END\n");
    Ok((s, used))
}
