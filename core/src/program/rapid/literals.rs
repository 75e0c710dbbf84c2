//! RAPID's literals and statements: robtargets `[[x,y,z],[q1..q4],[cf1,
//! cf4,cf6,cfx],[eax_a..eax_f]]`, frames and `tload`s of tooldata, the
//! motion instructions and where their positions and tool are, a
//! statement's arguments, and the variable an assignment sets. Units: mm in
//! the text, SI (m) in the poses; unit quaternions, scalar `q1` first.

use super::super::lex::{Fail, Tok, Token, Val};
use super::super::{AxisValue, Flags};
use crate::model::orientation::{rotation_from, OrientationConvention};
use crate::model::Pose;
use crate::solve::cell::Load;
use nalgebra::Vector3;
use std::ops::Range;

/// Where a motion instruction's tool argument is.
#[derive(Clone, Copy)]
pub(super) enum ToolArg {
    /// The last positional argument.
    Last,
    /// The positional argument at this index (0-based).
    At(usize),
}

/// A motion instruction (lower case): the positional argument of its first
/// position, how many positions it takes, and where its tool is.
pub(super) struct Instruction {
    pub(super) name: &'static str,
    pub(super) first: usize,
    pub(super) points: usize,
    pub(super) tool: ToolArg,
}

pub(super) const fn instr(
    name: &'static str,
    first: usize,
    points: usize,
    tool: ToolArg,
) -> Instruction {
    Instruction {
        name,
        first,
        points,
        tool,
    }
}

pub(super) const INSTRUCTIONS: [Instruction; 27] = [
    instr("movel", 0, 1, ToolArg::Last),
    instr("movej", 0, 1, ToolArg::Last),
    instr("movec", 0, 2, ToolArg::Last),
    instr("movelsync", 0, 1, ToolArg::Last),
    instr("movejsync", 0, 1, ToolArg::Last),
    instr("movecsync", 0, 2, ToolArg::Last),
    instr("moveldo", 0, 1, ToolArg::At(3)),
    instr("movejdo", 0, 1, ToolArg::At(3)),
    instr("movecdo", 0, 2, ToolArg::At(4)),
    instr("movelao", 0, 1, ToolArg::At(3)),
    instr("movejao", 0, 1, ToolArg::At(3)),
    instr("movecao", 0, 2, ToolArg::At(4)),
    instr("movelgo", 0, 1, ToolArg::At(3)),
    instr("movejgo", 0, 1, ToolArg::At(3)),
    instr("movecgo", 0, 2, ToolArg::At(4)),
    instr("triggl", 0, 1, ToolArg::Last),
    instr("triggj", 0, 1, ToolArg::Last),
    instr("triggc", 0, 2, ToolArg::Last),
    // SearchL Signal, SearchPoint (where the search stopped: an output), ToPoint, …
    instr("searchl", 2, 1, ToolArg::Last),
    instr("searchc", 2, 2, ToolArg::Last),
    instr("arcl", 0, 1, ToolArg::Last),
    instr("arclstart", 0, 1, ToolArg::Last),
    instr("arclend", 0, 1, ToolArg::Last),
    instr("arcc", 0, 2, ToolArg::Last),
    instr("arccstart", 0, 2, ToolArg::Last),
    instr("arccend", 0, 2, ToolArg::Last),
    instr("spotl", 0, 1, ToolArg::Last),
];

/// The names of a robtarget's external axes, in order.
pub(super) const EXTERNAL_AXES: [&str; 6] = ["eax_a", "eax_b", "eax_c", "eax_d", "eax_e", "eax_f"];

/// A pose or why not, and the ranges of its values.
pub(super) type Frame = (Result<Pose, String>, Vec<Range<usize>>);

/// A pose from `[[x,y,z],[q1..q4]]` (mm).
pub(super) fn frame(v: &Val) -> Option<Frame> {
    let items = v.list()?;
    let (p, mut ranges) = items.first()?.numbers(3)?;
    let (q, qr) = items.get(1)?.numbers(4)?;
    ranges.extend(qr);
    let pose = rotation_from(OrientationConvention::AbbQ1q4, &q)
        .map(|r| Pose::new(r, Vector3::new(p[0], p[1], p[2]) * 1e-3))
        .map_err(|e| e.to_string());
    Some((pose, ranges))
}

/// A tooldata's `tload` `[mass,[cx,cy,cz],[q1..q4],ix,iy,iz]` (kg, mm in the
/// flange frame, kg·m²); `None` when it is not one or the mass is not positive.
pub(super) fn tload(v: &Val) -> Option<Load> {
    let num = |v: &Val| match v {
        Val::Num(x, _) => Some(*x),
        _ => None,
    };
    let items = v.list()?;
    let mass = num(items.first()?)?;
    let (c, _) = items.get(1)?.numbers(3)?;
    let moments: Option<Vec<f64>> = items.get(3..6).map(|m| m.iter().filter_map(num).collect());
    let inertia_kgm2 = moments
        .filter(|m| m.len() == 3 && m.iter().any(|x| *x != 0.0))
        .map(|m| [m[0], m[1], m[2]]);
    (mass > 0.0 && mass.is_finite()).then(|| Load {
        mass_kg: mass,
        com: Vector3::new(c[0], c[1], c[2]) * 1e-3,
        inertia_kgm2,
    })
}

/// A robtarget literal: pose, flags, value ranges, the external axes in
/// use (not 9E9).
pub(super) struct Target {
    pub(super) pose: Result<Pose, String>,
    pub(super) flags: Flags,
    pub(super) slots: Vec<Range<usize>>,
    pub(super) start: usize,
    pub(super) axes: Vec<AxisValue>,
}

pub(super) fn robtarget(v: &Val) -> Result<Target, Fail> {
    let bad = || {
        (
            v.range().start,
            "not a robtarget `[[x,y,z],[q1,q2,q3,q4],[cf1,cf4,cf6,cfx],[eax]]`".to_string(),
        )
    };
    let items = v.list().ok_or_else(bad)?;
    if items.len() != 4 {
        return Err(bad());
    }
    let (pose, slots) = frame(v).ok_or_else(bad)?;
    let (cf, _) = items[2].numbers(4).ok_or_else(bad)?;
    let flags = if cf.iter().all(|c| c.fract() == 0.0 && c.abs() < 1e6) {
        Flags::Abb {
            cf: [cf[0] as i32, cf[1] as i32, cf[2] as i32, cf[3] as i32],
        }
    } else {
        return Err(bad());
    };
    let extax = items[3].list().ok_or_else(bad)?;
    // 9E9 is an axis not in use.
    let axes = extax
        .iter()
        .zip(EXTERNAL_AXES)
        .enumerate()
        .filter_map(|(i, (e, axis))| {
            let (value, text, slot) = match e {
                Val::Num(x, _) if *x >= 8.99e9 => return None,
                Val::Num(x, r) => (Some(*x), format!("{x}"), Some(r.clone())),
                _ => (None, "a value computed at run time".to_string(), None),
            };
            Some(AxisValue {
                group: 1,
                number: i + 1,
                name: axis.to_string(),
                value,
                text,
                slot,
            })
        })
        .collect();
    Ok(Target {
        pose,
        flags,
        slots,
        start: v.range().start,
        axes,
    })
}

/// Splits a statement's tokens at top-level commas.
pub(super) fn arguments(toks: &[Token]) -> Vec<&[Token]> {
    let mut out = Vec::new();
    let mut depth = 0i32;
    let mut start = 0;
    for (i, (t, _)) in toks.iter().enumerate() {
        match t {
            Tok::Punct('[' | '(' | '{') => depth += 1,
            Tok::Punct(']' | ')' | '}') => depth -= 1,
            Tok::Punct(',') if depth == 0 => {
                out.push(&toks[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    out.push(&toks[start..]);
    out
}

/// The part of an argument before its first `\switch` outside brackets.
pub(super) fn main_part(arg: &[Token]) -> &[Token] {
    let mut depth = 0i32;
    let end = arg
        .iter()
        .position(|(t, _)| {
            match t {
                Tok::Punct('[' | '(' | '{') => depth += 1,
                Tok::Punct(']' | ')' | '}') => depth -= 1,
                _ => {}
            }
            depth == 0 && *t == Tok::Punct('\\')
        })
        .unwrap_or(arg.len());
    &arg[..end]
}

pub(super) fn word(t: Option<&Token>) -> Option<&str> {
    match t {
        Some((Tok::Word(w), _)) => Some(w),
        _ => None,
    }
}

/// The variable a `:=` at token `colon` assigns: the root of `a`, `a.b.c`,
/// `a{i}` or `a{i}.b`; `None` for an optional argument (`\WObj:=…`).
pub(super) fn assigned_root(st: &[Token], colon: usize) -> Option<&str> {
    let mut j = colon.checked_sub(1)?;
    loop {
        if st[j].0 == Tok::Punct('}') {
            let mut depth = 0;
            loop {
                match st[j].0 {
                    Tok::Punct('}') => depth += 1,
                    Tok::Punct('{') => depth -= 1,
                    _ => {}
                }
                if depth == 0 {
                    break;
                }
                j = j.checked_sub(1)?;
            }
            j = j.checked_sub(1)?;
        }
        let root = word(st.get(j))?;
        if j >= 2 && st[j - 1].0 == Tok::Punct('.') {
            j -= 2;
            continue;
        }
        if j >= 1 && st[j - 1].0 == Tok::Punct('\\') {
            return None;
        }
        return Some(root);
    }
}
