//! ABB RAPID modules (`.mod`, `.modx`, `.prg`).
//!
//! Targets: `robtarget` literals `[[x,y,z],[q1,q2,q3,q4],[cf1,cf4,cf6,cfx],
//! [eax_a,…]]`, declared (`CONST|PERS|VAR robtarget p10 := …;`, arrays too)
//! and used by name, or inline, in `MoveL`, `MoveJ`, `MoveC` (and their `DO`
//! and `Trigg` forms). The tool is the motion's `Tool` argument, the work
//! object its `\WObj`; both are read from the module's `tooldata`
//! (`[robhold,[[x,y,z],[q1..q4]],[mass,[cx,cy,cz],…]]`) and `wobjdata`
//! (`[robhold,ufprog,ufmec,uframe,oframe]`, the work object `uframe·oframe`),
//! else looked up in the cell by name; `tool0` is the flange and `wobj0` the
//! base frame. A tooldata's `robhold TRUE` is a tool the robot holds (the
//! ordinary case); `FALSE` a stationary tool, its `tframe` in the world
//! (taken as the base) frame, used with a `wobjdata` of `robhold TRUE` whose
//! `uframe·oframe` is in the flange (wrist) frame: the robot carries the work
//! object past the fixed tool ([`Site::stationary_tool`]). A stationary tool
//! with a fixed work object, or a robot-held tool with a robot-held work
//! object, is reported as not filtered. A tooldata's `tload` (mass [kg],
//! centre of gravity [mm] in the flange frame `tool0`, principal moments
//! [kg·m²]) is the target's declared load (for a stationary tool, the load
//! the robot carries: the gripper and work piece). A declared
//! point takes the tool and work object of the motions that use it (all the
//! same, else it is skipped). Comments: `!` to the end of the line.
//!
//! Units: mm, unit quaternions with the scalar `q1` first. `cf1, cf4, cf6`
//! are the quadrants `⌊A/90°⌋` of axes 1, 4, 6; `cfx = 4·back + 2·down +
//! [A5 < 0]` (wrist centre behind axis 1, behind the lower arm, axis 5
//! negative). All four are kept.

use super::lex::{blank_comments, error, line_end, list, tokens, Fail, Tok, Token, Val};
use super::{Flags, FrameSpec, JointTarget, ParseError, ProgramFile, Site, Targets};
use crate::model::orientation::{rotation_from, OrientationConvention};
use crate::model::Pose;
use crate::solve::cell::{CellRef, Load};
use nalgebra::Vector3;
use std::collections::{HashMap, HashSet};
use std::ops::Range;

const MOTIONS: [&str; 9] = [
    "movel", "movej", "movec", "moveldo", "movejdo", "movecdo", "triggl", "triggj", "triggc",
];

/// A pose or why not, and the ranges of its values.
type Frame = (Result<Pose, String>, Vec<Range<usize>>);

/// A pose from `[[x,y,z],[q1..q4]]` (mm).
fn frame(v: &Val) -> Option<Frame> {
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
fn tload(v: &Val) -> Option<Load> {
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

/// A robtarget literal: pose, flags, value ranges.
struct Target {
    pose: Result<Pose, String>,
    flags: Flags,
    slots: Vec<Range<usize>>,
    start: usize,
}

fn robtarget(v: &Val) -> Result<Target, Fail> {
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
    items[3].list().ok_or_else(bad)?;
    Ok(Target {
        pose,
        flags,
        slots,
        start: v.range().start,
    })
}

/// Splits a statement's tokens at top-level commas.
fn arguments(toks: &[Token]) -> Vec<&[Token]> {
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

/// The part of an argument before its first `\switch`.
fn main_part(arg: &[Token]) -> &[Token] {
    let end = arg
        .iter()
        .position(|(t, _)| *t == Tok::Punct('\\'))
        .unwrap_or(arg.len());
    &arg[..end]
}

fn word(t: Option<&Token>) -> Option<&str> {
    match t {
        Some((Tok::Word(w), _)) => Some(w),
        _ => None,
    }
}

#[derive(Clone, PartialEq)]
struct Context {
    tool: FrameSpec,
    wobj: FrameSpec,
    load: Option<Load>,
    skip: Option<String>,
    stationary: bool,
}

struct Declared {
    site: Site,
    uses: Vec<(usize, Context)>,
}

struct Parser<'a> {
    files: &'a [ProgramFile],
    masked: Vec<String>,
    toks: Vec<Vec<Token>>,
    tools: HashMap<String, Result<Pose, String>>,
    loads: HashMap<String, Load>,
    wobjs: HashMap<String, Result<Pose, String>>,
    /// Tools with `robhold FALSE` and work objects with `robhold TRUE`.
    stationary_tools: HashSet<String>,
    held_wobjs: HashSet<String>,
    declared: Vec<Declared>,
    by_name: HashMap<String, Vec<usize>>,
    order: Vec<Result<Site, usize>>,
    joints: Vec<JointTarget>,
}

fn statements(toks: &[Token]) -> impl Iterator<Item = &[Token]> {
    toks.split(|(t, _)| *t == Tok::Punct(';'))
}

impl Parser<'_> {
    fn site(&self, fi: usize, name: String, t: Target, ctx: &Context) -> Site {
        let text = &self.files[fi].text;
        let (pose, skip) = match t.pose {
            Ok(p) => (Some(p), ctx.skip.clone()),
            Err(e) => (None, Some(e)),
        };
        let end = line_end(text, t.start);
        Site {
            file: fi,
            line: super::lex::position(text, t.start).0,
            name,
            pose,
            flags: t.flags,
            tool: ctx.tool.clone(),
            load: ctx.load,
            work_object: ctx.wobj.clone(),
            slots: t.slots,
            convention: OrientationConvention::AbbQ1q4,
            unit_m: 1e-3,
            decimals: [4, 8],
            mark_at: end..end,
            after_joints: None,
            skip: None,
            stationary_tool: ctx.stationary,
        }
        .with_skip(skip)
    }

    fn declarations(&mut self, fi: usize) -> Result<(), Fail> {
        let toks = std::mem::take(&mut self.toks[fi]);
        for st in statements(&toks) {
            // Statements without `;` (MODULE, PROC headers, ENDPROC, …) come first.
            let Some(k) = st.iter().position(|t| {
                matches!(
                    word(Some(t)).map(str::to_ascii_lowercase).as_deref(),
                    Some("const" | "pers" | "var")
                )
            }) else {
                continue;
            };
            let (Some(ty), Some(name)) = (word(st.get(k + 1)), word(st.get(k + 2))) else {
                continue;
            };
            let ty = ty.to_ascii_lowercase();
            let mut j = k + 3;
            let array = st.get(j).is_some_and(|t| t.0 == Tok::Punct('{'));
            if array {
                while st.get(j).is_some_and(|t| t.0 != Tok::Punct('}')) {
                    j += 1;
                }
                j += 1;
            }
            let assign = st.get(j).is_some_and(|t| t.0 == Tok::Punct(':'))
                && st.get(j + 1).is_some_and(|t| t.0 == Tok::Punct('='));
            if !assign || !st.get(j + 2).is_some_and(|t| t.0 == Tok::Punct('[')) {
                continue;
            }
            let (v, next) = list(st, j + 2)?;
            if let Some((_, r)) = st.get(next) {
                return Err((r.start, "expected `;` after the value".into()));
            }
            let key = name.to_ascii_lowercase();
            match ty.as_str() {
                "robtarget" => self.declare_robtargets(fi, name, key, &v, array)?,
                "jointtarget" => self.joint(fi, &v),
                "tooldata" => self.declare_tool(fi, name, key, &v)?,
                "wobjdata" => self.declare_wobj(fi, name, key, &v)?,
                _ => {}
            }
        }
        self.toks[fi] = toks;
        Ok(())
    }

    /// A `robtarget` declaration (one target, or one per element of an
    /// array, labelled `name{i}`).
    fn declare_robtargets(
        &mut self,
        fi: usize,
        name: &str,
        key: String,
        v: &Val,
        array: bool,
    ) -> Result<(), Fail> {
        let elements: Vec<&Val> = match (v, array) {
            (Val::List(items, _), true) => items.iter().collect(),
            _ => vec![v],
        };
        for (i, e) in elements.into_iter().enumerate() {
            let t = robtarget(e)?;
            let label = if array {
                format!("{name}{{{}}}", i + 1)
            } else {
                name.to_string()
            };
            let unset = Context {
                tool: FrameSpec::Unset,
                wobj: FrameSpec::Unset,
                load: None,
                skip: None,
                stationary: false,
            };
            let site = self.site(fi, label, t, &unset);
            self.by_name
                .entry(key.clone())
                .or_default()
                .push(self.declared.len());
            self.declared.push(Declared {
                site,
                uses: Vec::new(),
            });
        }
        Ok(())
    }

    /// A `tooldata` declaration: its TCP, its load, and whether the robot
    /// holds it (`robhold FALSE`: a stationary tool).
    fn declare_tool(&mut self, fi: usize, name: &str, key: String, v: &Val) -> Result<(), Fail> {
        let tool = v.list().and_then(|i| i.get(1)).and_then(frame);
        let robhold = v
            .list()
            .and_then(|i| i.first())
            .map(|r| self.text_of(fi, r));
        if robhold.is_some_and(|r| r.eq_ignore_ascii_case("false")) {
            self.stationary_tools.insert(key.clone());
        }
        let value = match tool {
            Some((pose, _)) => pose,
            None => {
                return Err((
                    v.range().start,
                    format!("tooldata {name} is not `[robhold,[[x,y,z],[q1,q2,q3,q4]],…]`"),
                ))
            }
        };
        if let Some(load) = v.list().and_then(|i| i.get(2)).and_then(tload) {
            self.loads.insert(key.clone(), load);
        }
        self.tools.insert(key, value);
        Ok(())
    }

    /// A `wobjdata` declaration: user frame · object frame, held by the
    /// robot when `robhold TRUE`, refused when a mechanical unit moves it.
    fn declare_wobj(&mut self, fi: usize, name: &str, key: String, v: &Val) -> Result<(), Fail> {
        let items = v.list().unwrap_or(&[]);
        let frames = (items.get(3).and_then(frame), items.get(4).and_then(frame));
        let (Some((uf, _)), Some((of, _))) = frames else {
            return Err((
                v.range().start,
                format!("wobjdata {name} is not `[robhold,ufprog,ufmec,uframe,oframe]`"),
            ));
        };
        let robhold = items
            .first()
            .map(|r| self.text_of(fi, r))
            .unwrap_or_default();
        let ufmec = items
            .get(2)
            .map(|r| self.text_of(fi, r))
            .unwrap_or_default();
        if robhold.eq_ignore_ascii_case("true") {
            self.held_wobjs.insert(key.clone());
        }
        let value = if ufmec.trim_matches('"').trim() != "" {
            Err(format!("work object {name} moves with {ufmec}"))
        } else {
            uf.and_then(|u| of.map(|o| u.compose(&o)))
        };
        self.wobjs.insert(key, value);
        Ok(())
    }

    /// A jointtarget literal `[[j1..j6],[eax]]` [deg].
    fn joint(&mut self, fi: usize, v: &Val) {
        if let Some((deg, _)) = v.list().and_then(|i| i.first()).and_then(|j| j.numbers(6)) {
            let line = super::lex::position(&self.files[fi].text, v.range().start).0;
            self.joints.push(JointTarget {
                file: fi,
                line,
                deg,
            });
        }
    }

    fn text_of(&self, fi: usize, v: &Val) -> String {
        self.masked[fi][v.range()].trim().to_string()
    }

    fn frame_spec(
        map: &HashMap<String, Result<Pose, String>>,
        name: &str,
        default: &str,
    ) -> (FrameSpec, Option<String>) {
        let key = name.to_ascii_lowercase();
        if key == default {
            return (FrameSpec::Ref(CellRef::Number(0)), None);
        }
        match map.get(&key) {
            Some(Ok(p)) => (FrameSpec::Inline(*p), None),
            Some(Err(e)) => (FrameSpec::Unset, Some(e.clone())),
            None => (FrameSpec::Ref(CellRef::Name(name.to_string())), None),
        }
    }

    fn motions(&mut self, fi: usize) -> Result<(), Fail> {
        let toks = std::mem::take(&mut self.toks[fi]);
        for st in statements(&toks) {
            if let Some(m) = st
                .iter()
                .position(|t| word(Some(t)).is_some_and(|w| w.eq_ignore_ascii_case("moveabsj")))
            {
                if st.get(m + 1).is_some_and(|t| t.0 == Tok::Punct('[')) {
                    let (v, _) = list(st, m + 1)?;
                    self.joint(fi, &v);
                }
                continue;
            }
            // After whatever has no `;` (PROC headers, THEN, DO, …).
            let Some(m) = st.iter().position(|t| {
                word(Some(t)).is_some_and(|w| MOTIONS.contains(&w.to_ascii_lowercase().as_str()))
            }) else {
                continue;
            };
            let st = &st[m..];
            let instr = word(st.first()).unwrap_or_default().to_ascii_lowercase();
            let args = arguments(&st[1..]);
            let positional: Vec<&[Token]> = args
                .iter()
                .filter(|a| a.first().is_some_and(|t| t.0 != Tok::Punct('\\')))
                .map(|a| main_part(a))
                .collect();
            let circular = instr.starts_with("movec") || instr == "triggc";
            let n_points = if circular { 2 } else { 1 };
            let tool_name = positional.get(n_points + 2).and_then(|a| word(a.first()));
            let wobj_name = st.windows(5).find_map(|w| {
                let is_wobj = w[0].0 == Tok::Punct('\\')
                    && word(Some(&w[1])).is_some_and(|x| x.eq_ignore_ascii_case("wobj"))
                    && w[2].0 == Tok::Punct(':')
                    && w[3].0 == Tok::Punct('=');
                is_wobj.then(|| word(Some(&w[4]))).flatten()
            });
            let (tool, tool_err) = match tool_name {
                Some(t) => Self::frame_spec(&self.tools, t, "tool0"),
                None => (FrameSpec::Unset, None),
            };
            let (wobj, wobj_err) =
                Self::frame_spec(&self.wobjs, wobj_name.unwrap_or("wobj0"), "wobj0");
            let load = tool_name.and_then(|t| self.loads.get(&t.to_ascii_lowercase()).copied());
            let tool_key = tool_name.unwrap_or_default().to_ascii_lowercase();
            let wobj_key = wobj_name.unwrap_or_default().to_ascii_lowercase();
            let stationary = self.stationary_tools.contains(&tool_key);
            let roles = match (stationary, self.held_wobjs.contains(&wobj_key)) {
                (true, false) => Some(format!(
                    "tool {tool_key} is stationary (robhold FALSE) but the robot does not hold work object {}",
                    wobj_name.unwrap_or("wobj0")
                )),
                (false, true) => Some(format!(
                    "the robot holds both tool {tool_key} and work object {wobj_key} (robhold TRUE)"
                )),
                _ => None,
            };
            let ctx = Context {
                tool,
                wobj,
                load,
                skip: tool_err.or(wobj_err).or(roles),
                stationary,
            };
            for arg in positional.iter().take(n_points) {
                if arg.first().is_some_and(|t| t.0 == Tok::Punct('[')) {
                    let (v, _) = list(arg, 0)?;
                    let t = robtarget(&v)?;
                    let site = self.site(fi, "inline".into(), t, &ctx);
                    self.order.push(Ok(site));
                } else {
                    for (t, _) in arg.iter() {
                        if let Tok::Word(w) = t {
                            self.use_point(&w.to_ascii_lowercase(), st[0].1.start, fi, &ctx);
                        }
                    }
                }
            }
        }
        self.toks[fi] = toks;
        Ok(())
    }

    fn use_point(&mut self, key: &str, at: usize, fi: usize, ctx: &Context) {
        let Some(ids) = self.by_name.get(key).cloned() else {
            return;
        };
        let line = super::lex::position(&self.files[fi].text, at).0;
        for i in ids {
            if self.declared[i].uses.is_empty() {
                self.order.push(Err(i));
            }
            self.declared[i].uses.push((line, ctx.clone()));
        }
    }

    fn finish(self) -> Targets {
        let declared = self.declared;
        let mut order = self.order;
        for (i, d) in declared.iter().enumerate() {
            if d.uses.is_empty() {
                order.push(Err(i));
            }
        }
        let sites = order
            .into_iter()
            .map(|s| match s {
                Ok(site) => site,
                Err(i) => {
                    let d = &declared[i];
                    let mut site = d.site.clone();
                    match d.uses.first() {
                        None => site.skip = site.skip.or(Some("no motion of the program uses it".into())),
                        Some((first, ctx)) => {
                            site.tool = ctx.tool.clone();
                            site.load = ctx.load;
                            site.work_object = ctx.wobj.clone();
                            site.stationary_tool = ctx.stationary;
                            site.skip = site.skip.or(ctx.skip.clone());
                            if let Some((line, _)) = d.uses.iter().find(|(_, c)| c.tool != ctx.tool || c.wobj != ctx.wobj) {
                                site.skip = site.skip.or(Some(format!(
                                    "used with different tools or work objects (lines {first} and {line})"
                                )));
                            }
                        }
                    }
                    site
                }
            })
            .collect();
        Targets {
            sites,
            joints: self.joints,
        }
    }
}

/// Parses RAPID modules.
pub fn parse(files: &[ProgramFile]) -> Result<Targets, ParseError> {
    let mut masked = Vec::with_capacity(files.len());
    let mut toks = Vec::with_capacity(files.len());
    for f in files {
        let m = blank_comments(&f.text, '!', &['"']).map_err(|e| error(&f.name, &f.text, e))?;
        toks.push(tokens(&m, &['"']).map_err(|e| error(&f.name, &f.text, e))?);
        masked.push(m);
    }
    let mut p = Parser {
        files,
        masked,
        toks,
        tools: HashMap::new(),
        loads: HashMap::new(),
        wobjs: HashMap::new(),
        stationary_tools: HashSet::new(),
        held_wobjs: HashSet::new(),
        declared: Vec::new(),
        by_name: HashMap::new(),
        order: Vec::new(),
        joints: Vec::new(),
    };
    for (fi, f) in files.iter().enumerate() {
        p.declarations(fi).map_err(|e| error(&f.name, &f.text, e))?;
    }
    for (fi, f) in files.iter().enumerate() {
        p.motions(fi).map_err(|e| error(&f.name, &f.text, e))?;
    }
    Ok(p.finish())
}

#[cfg(test)]
mod tests;
