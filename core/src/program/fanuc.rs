//! Fanuc TP programs in their ASCII form (`.ls`).
//!
//! Targets: the `/POS` section's positions `P[n]` or `P[n:"comment"]`, group
//! `GP1`, in Cartesian form `UF : u, UT : t, CONFIG : 'N U T, 0, 0, 0',
//! X = … mm, Y = … mm, Z = … mm, W = … deg, P = … deg, R = … deg`; joint
//! positions (`J1 = …`) are not targets, nor are other groups. The user frame
//! `UF` and tool `UT` are looked up in the cell by number (`UF : 0` is the
//! base frame). An extended axis of `GP1` (`E1 = …`) and the joints of
//! another group (`GP2: … J1 = 30.000 deg`, a positioner) go with the site
//! to the filter (`program::axes`: a track's `E1` and a positioner's `GP2`
//! `J1`, `J2` composed, any other refused naming it); another group in
//! Cartesian form (a second robot) is refused, naming it.
//!
//! Motions: the `/MN` section's `J`, `L`, `C` and `A` instructions
//! (`fanuc/motions.rs`) name the positions; a position in joint form is a
//! joint motion, a position register `PR[n]` or `P[R[n]]` is set at run
//! time, as is an incremental (`INC`) or offset (`Offset`, `Tool_Offset`,
//! `VOFFSET`) motion: skipped; a `P[n]` that `/POS` lacks fails. A file
//! without `/MN` is a list of positions, each its own motion (`/POS`).
//!
//! Units: mm and degrees, `W, P, R` fixed-axis XYZ (`R = Rz(R)·Ry(P)·Rx(W)`).
//! `CONFIG`: `F`/`N` (axis 5 < 0 or not), `U`/`D` (elbow), `T`/`B` (wrist
//! centre in front of or behind axis 1), then the turn numbers of axes 1, 4
//! and 6, `⌊(A + 180°)/360°⌋`; all kept. An unsolved position is marked by its
//! comment, `P[n:"robocal: failed"]`.

mod motions;

use super::lex::{error, position, tokens, Fail, Tok, Token};
use super::{
    AxisValue, Flags, FrameSpec, JointTarget, Motion, MotionTarget, ParseError, ProgramFile, Site,
    Targets,
};
use crate::model::orientation::{rotation_from, OrientationConvention};
use crate::model::Pose;
use crate::solve::cell::CellRef;
use motions::{MotionLine, Reference};
use nalgebra::Vector3;
use std::collections::HashMap;
use std::ops::Range;

/// The mark of an unsolved position (Fanuc comments hold 16 characters).
pub(super) const MARK: &str = ":\"robocal: failed\"";

fn punct(t: Option<&Token>, c: char) -> bool {
    matches!(t, Some((Tok::Punct(p), _)) if *p == c)
}

fn word(t: Option<&Token>) -> Option<&str> {
    match t {
        Some((Tok::Word(w), _)) => Some(w),
        _ => None,
    }
}

/// Parses `'N U T, 0, 0, 0'`.
fn config(text: &str) -> Option<Flags> {
    let inner = text.trim_matches('\'');
    let mut parts = inner.split(',');
    let letters: Vec<char> = parts
        .next()?
        .chars()
        .filter(|c| !c.is_whitespace())
        .map(|c| c.to_ascii_uppercase())
        .collect();
    let turns: Vec<i32> = parts
        .map(|p| p.trim().parse().ok())
        .collect::<Option<Vec<i32>>>()?;
    let flag = |a: char, b: char| {
        letters
            .iter()
            .find(|c| **c == a || **c == b)
            .map(|c| *c == a)
    };
    Some(Flags::Fanuc {
        flip: flag('F', 'N')?,
        up: flag('U', 'D')?,
        front: flag('T', 'B')?,
        turns: [
            turns.first().copied().unwrap_or(0),
            turns.get(1).copied().unwrap_or(0),
            turns.get(2).copied().unwrap_or(0),
        ],
    })
}

/// What one `P[n]` block holds for group 1.
enum Position {
    Cartesian(Box<Site>),
    Joint(JointTarget),
    Neither,
}

/// Offset of token `k` in the section (the end of the text past the last).
fn at(text: &str, toks: &[Token], k: usize) -> usize {
    toks.get(k).map_or(text.len(), |t| t.1.start)
}

/// The head `P[n]{` or `P[n:"comment"]{` at token `i`: the position number,
/// where an unsolved mark goes (the comment's span, or empty after the
/// number) and the token after `{`.
fn head(text: &str, toks: &[Token], i: usize) -> Result<(f64, Range<usize>, usize), Fail> {
    if !(word(toks.get(i)) == Some("P") && punct(toks.get(i + 1), '[')) {
        return Err((at(text, toks, i), "expected `P[n]{`".into()));
    }
    let Some((Tok::Number(n), _)) = toks.get(i + 2) else {
        return Err((at(text, toks, i + 2), "expected the position number".into()));
    };
    let mut k = i + 3;
    let mark_at = if punct(toks.get(k), ':') {
        let Some((Tok::Str, r)) = toks.get(k + 1) else {
            return Err((at(text, toks, k + 1), "expected a comment string".into()));
        };
        let span = toks[k].1.start..r.end;
        k += 2;
        span
    } else {
        at(text, toks, k)..at(text, toks, k)
    };
    if !punct(toks.get(k), ']') || !punct(toks.get(k + 1), '{') {
        return Err((at(text, toks, k), "expected `]{`".into()));
    }
    Ok((*n, mark_at, k + 2))
}

/// The fields of a block read so far; only group 1's are kept.
#[derive(Default)]
struct Fields {
    group: u32,
    /// Groups other than 1 the position gives in Cartesian form.
    other_groups: Vec<u32>,
    /// The extended axes of group 1 (`E1 = 100 mm`) and the joints of other
    /// groups (`J1 = 30 deg` of `GP2`), in the block's order.
    extended: Vec<AxisValue>,
    uf: Option<u32>,
    ut: Option<u32>,
    flags: Option<Flags>,
    /// X, Y, Z, W, P, R with the span each value occupies.
    values: [Option<(f64, Range<usize>)>; 6],
    joint: [Option<f64>; 6],
    any_joint: bool,
}

impl Fields {
    /// `UF : u`, `UT : t` or `CONFIG : '…'` at token `k` (the word); returns
    /// the token after it and its comma.
    fn colon(&mut self, text: &str, toks: &[Token], k: usize) -> Result<usize, Fail> {
        let (Tok::Word(w), r) = &toks[k] else {
            unreachable!("called at a word")
        };
        let key = w.to_ascii_uppercase();
        match (key.as_str(), toks.get(k + 2)) {
            ("UF" | "UT", Some((Tok::Number(v), _)))
                if v.fract() == 0.0 && *v >= 0.0 && *v < 1e6 =>
            {
                if self.group == 1 {
                    *(if key == "UF" {
                        &mut self.uf
                    } else {
                        &mut self.ut
                    }) = Some(*v as u32);
                }
            }
            ("CONFIG", Some((Tok::Str, s))) => {
                let c =
                    config(&text[s.clone()]).ok_or((s.start, "bad CONFIG string".to_string()))?;
                if self.group == 1 {
                    self.flags = Some(c);
                }
            }
            _ => return Err((r.start, format!("unexpected value of {w}"))),
        }
        let k = k + 3;
        Ok(if punct(toks.get(k), ',') { k + 1 } else { k })
    }

    /// `X = 1.5 mm,` (or `Jn = …`) at token `k` (the word); returns the
    /// token after the value, its unit and its comma.
    fn equals(&mut self, text: &str, toks: &[Token], k: usize) -> Result<usize, Fail> {
        let (Tok::Word(w), r) = &toks[k] else {
            unreachable!("called at a word")
        };
        let key = w.to_ascii_uppercase();
        let mut j = k + 2;
        let sign = if punct(toks.get(j), '-') {
            j += 1;
            -1.0
        } else {
            if punct(toks.get(j), '+') {
                j += 1;
            }
            1.0
        };
        let Some((Tok::Number(v), vr)) = toks.get(j) else {
            return Err((at(text, toks, j), format!("{w} is not a number")));
        };
        let slot = toks[k + 2].1.start..vr.end;
        j += 1;
        let unit = word(toks.get(j))
            .filter(|u| u.eq_ignore_ascii_case("mm") || u.eq_ignore_ascii_case("deg"));
        if unit.is_some() {
            j += 1;
        }
        if punct(toks.get(j), ',') {
            j += 1;
        }
        let written = || {
            format!("{} {}", &text[slot.clone()], unit.unwrap_or(""))
                .trim_end()
                .to_string()
        };
        if self.group != 1 {
            match key.strip_prefix('J').and_then(|n| n.parse::<usize>().ok()) {
                Some(number) => self.extended.push(AxisValue {
                    group: self.group,
                    number,
                    name: format!("{key} of motion group GP{}", self.group),
                    value: Some(sign * v),
                    text: written(),
                    slot: Some(slot.clone()),
                }),
                None if !self.other_groups.contains(&self.group) => {
                    self.other_groups.push(self.group)
                }
                None => {}
            }
        } else {
            match "XYZWPR".find(key.as_str()).filter(|_| key.len() == 1) {
                Some(idx) => self.values[idx] = Some((sign * v, slot)),
                None if key.starts_with('J') || key.starts_with('E') => {
                    let extended = key.strip_prefix('E').and_then(|n| n.parse::<usize>().ok());
                    if let Some(number) = extended {
                        self.extended.push(AxisValue {
                            group: 1,
                            number,
                            name: key.clone(),
                            value: Some(sign * v),
                            text: written(),
                            slot: Some(slot.clone()),
                        });
                    }
                    let axis = key.strip_prefix('J').and_then(|n| n.parse::<usize>().ok());
                    if let Some(n) = axis {
                        self.any_joint = true;
                        if (1..=6).contains(&n) {
                            self.joint[n - 1] = Some(sign * v);
                        }
                    }
                }
                None => return Err((r.start, format!("unknown component {w}"))),
            }
        }
        Ok(j)
    }
}

/// One `P[n]{…};` block from token `i` (at `P`); returns its group-1
/// position and the token after the block.
fn block(fi: usize, text: &str, toks: &[Token], i: usize) -> Result<(u32, Position, usize), Fail> {
    let (n, mark_at, mut k) = head(text, toks, i)?;
    let name = format!("P[{n}]");
    let mut fields = Fields::default();
    loop {
        let Some((t, r)) = toks.get(k) else {
            return Err((at(text, toks, i), format!("{name} is not closed by `}};`")));
        };
        k = match t {
            Tok::Punct('}') => {
                if !punct(toks.get(k + 1), ';') {
                    return Err((at(text, toks, k + 1), "expected `;` after `}`".into()));
                }
                k += 2;
                break;
            }
            Tok::Word(w) if w.starts_with("GP") && punct(toks.get(k + 1), ':') => {
                fields.group = w[2..].parse().unwrap_or(0);
                k + 2
            }
            Tok::Word(_) if punct(toks.get(k + 1), ':') => fields.colon(text, toks, k)?,
            Tok::Word(_) if punct(toks.get(k + 1), '=') => fields.equals(text, toks, k)?,
            _ => return Err((r.start, "unexpected text in the position".into())),
        };
    }
    let line = position(text, toks[i].1.start).0;
    Ok((n as u32, found(fi, line, name, mark_at, fields), k))
}

/// The target a block's group-1 fields make: joint values, a Cartesian site
/// (skipped with its reason when incomplete or not a rotation), or nothing.
fn found(fi: usize, line: usize, name: String, mark_at: Range<usize>, f: Fields) -> Position {
    if f.any_joint {
        let deg: Option<Vec<f64>> = f.joint.iter().copied().collect();
        return deg.map_or(Position::Neither, |deg| {
            Position::Joint(JointTarget {
                file: fi,
                line,
                deg,
            })
        });
    }
    if f.values.iter().all(Option::is_none) {
        return Position::Neither;
    }
    let complete: Option<Vec<(f64, Range<usize>)>> = f.values.iter().cloned().collect();
    let (pose, slots, skip) = match complete {
        Some(v) => {
            let x: Vec<f64> = v.iter().map(|p| p.0).collect();
            let pose = rotation_from(OrientationConvention::FanucWpr, &x[3..])
                .map(|r| Pose::new(r, Vector3::new(x[0], x[1], x[2]) * 1e-3));
            let slots = v.into_iter().map(|p| p.1).collect();
            match pose {
                Ok(p) => (Some(p), slots, None),
                Err(e) => (None, slots, Some(e.to_string())),
            }
        }
        None => (
            None,
            Vec::new(),
            Some("incomplete position: X..R not all given".into()),
        ),
    };
    let spec = |v: Option<u32>| v.map_or(FrameSpec::Unset, |n| FrameSpec::Ref(CellRef::Number(n)));
    let refuse = f.other_groups.first().map(|g| format!(
        "the position also moves motion group GP{g} in Cartesian form (another robot), which the cell does not model: not filtered"
    ));
    Position::Cartesian(Box::new(Site {
        file: fi,
        line,
        name,
        pose,
        flags: f.flags.unwrap_or(Flags::Nearest),
        tool: spec(f.ut),
        load: None,
        work_object: spec(f.uf),
        slots,
        convention: OrientationConvention::FanucWpr,
        unit_m: 1e-3,
        decimals: [3, 3],
        mark_at,
        after_joints: None,
        skip,
        refuse,
        axes: f.extended,
        stationary_tool: false,
    }))
}

/// What `/POS` holds for a position number.
#[derive(Clone, Copy)]
enum Held {
    /// A Cartesian position: its index among the file's.
    Cartesian(usize),
    Joint,
    /// No group-1 values.
    Neither,
}

/// Parses `.ls` files: the Cartesian positions of their `/POS` sections and
/// the motions of their `/MN` sections.
pub(super) fn parse(files: &[ProgramFile]) -> Result<Targets, ParseError> {
    let mut found = Targets::default();
    for (fi, f) in files.iter().enumerate() {
        let text = f.text.as_str();
        let positions = match section(text, "/POS") {
            Some(pos) => positions(fi, f, pos)?,
            None => Vec::new(),
        };
        let mn = section(text, "/MN").map(|m| {
            let body = m + "/MN".len();
            let end = ["/POS", "/END"]
                .iter()
                .filter_map(|h| section(&text[body..], h))
                .min()
                .map_or(text.len(), |e| body + e);
            motions::motions(text, body..end)
        });
        file_targets(fi, positions, mn, &mut found);
    }
    Ok(found)
}

/// The blocks of the `/POS` section at byte `pos`: number and position.
fn positions(fi: usize, f: &ProgramFile, pos: usize) -> Result<Vec<(u32, Position)>, ParseError> {
    let text = f.text.as_str();
    let end = section(&text[pos..], "/END").map_or(text.len(), |e| pos + e);
    let body = pos + "/POS".len();
    let fail = |(at, m): Fail| error(&f.name, text, (at + body, m));
    let toks: Vec<Token> = tokens(&text[body..end], &['"', '\''])
        .map_err(fail)?
        .into_iter()
        .map(|(t, r)| (t, r.start + body..r.end + body))
        .collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < toks.len() {
        let (number, position, next) =
            block(fi, text, &toks, i).map_err(|(at, m)| error(&f.name, text, (at, m)))?;
        out.push((number, position));
        i = next;
    }
    Ok(out)
}

/// One file's sites (in the order its motions first use them, unused ones
/// last), motions and joint targets, into `found`.
fn file_targets(
    fi: usize,
    positions: Vec<(u32, Position)>,
    mn: Option<Vec<MotionLine>>,
    found: &mut Targets,
) {
    let mut held: HashMap<u32, Held> = HashMap::new();
    let mut cartesian: Vec<Option<Site>> = Vec::new();
    for (n, p) in positions {
        let h = match p {
            Position::Cartesian(s) => {
                cartesian.push(Some(*s));
                Held::Cartesian(cartesian.len() - 1)
            }
            Position::Joint(j) => {
                found.joints.push(j);
                Held::Joint
            }
            Position::Neither => Held::Neither,
        };
        held.entry(n).or_insert(h);
    }
    let count = cartesian.len();
    let mut at: Vec<Option<usize>> = vec![None; count];
    let mut visit = |k: usize, found: &mut Targets| {
        *at[k].get_or_insert_with(|| {
            found.sites.extend(cartesian[k].take());
            found.sites.len() - 1
        })
    };
    let Some(mn) = mn else {
        // A list of positions: each its own motion.
        for k in 0..count {
            let i = visit(k, found);
            let s = &found.sites[i];
            found.motions.push(Motion {
                file: fi,
                line: s.line,
                instruction: "/POS".into(),
                name: s.name.clone(),
                target: MotionTarget::Site(i),
                mark_at: s.mark_at.clone(),
            });
        }
        return;
    };
    for m in mn {
        for (name, r) in m.positions {
            let (target, mark_at) = match (&m.run_time, r) {
                (Some(why), _) => (MotionTarget::RunTime(why.clone()), 0..0),
                (None, Reference::RunTime(why)) => (MotionTarget::RunTime(why), 0..0),
                (None, Reference::Position { number, mark_at }) => {
                    let target = match held.get(&number) {
                        Some(Held::Cartesian(k)) => MotionTarget::Site(visit(*k, found)),
                        Some(Held::Joint) => MotionTarget::Joints { note: None },
                        Some(Held::Neither) | None => MotionTarget::Undeclared,
                    };
                    (target, mark_at)
                }
            };
            found.motions.push(Motion {
                file: fi,
                line: m.line,
                instruction: m.instruction.clone(),
                name,
                target,
                mark_at,
            });
        }
    }
    for s in cartesian.into_iter().flatten() {
        found
            .sites
            .push(s.with_skip(Some("no motion of the program uses it".into())));
    }
}

/// Byte offset of a line that starts with `name` (a section header).
fn section(text: &str, name: &str) -> Option<usize> {
    let mut start = 0;
    for line in text.split('\n') {
        if line.trim_start().starts_with(name) {
            return Some(start + (line.len() - line.trim_start().len()));
        }
        start += line.len() + 1;
    }
    None
}

#[cfg(test)]
mod tests;
