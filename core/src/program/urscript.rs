//! URScript (`.script`, `.urscript`).
//!
//! Targets: pose literals `p[x, y, z, rx, ry, rz]` that a motion goes to —
//! the first argument of `movel`, `movej`, `movep` (the first two of
//! `movec`), directly, through a variable assigned a literal (`name =
//! p[…]`), or as the second argument of `pose_trans(frame, …)`, the work
//! object `frame` (a variable assigned a literal, else looked up in the cell
//! by name). Other pose literals are not targets; joint targets
//! (`movej([…])`) are not either, but the controller starts the next target
//! from them. The tool is the last `set_tcp(p[…])` before the motion, its
//! declared load the last `set_payload(m, [cx, cy, cz])` (or
//! `set_target_payload`; kg, centre of gravity in metres in the flange
//! frame). A
//! variable takes the tool and frame of the motions that use it (all the
//! same, else it is skipped). Comments: `#` to the end of the line.
//!
//! Every position of a motion is reported (`Motion`): a joint list (or a
//! variable holding one) is a joint motion; a variable assigned anything but
//! a literal (`get_actual_tcp_pose()`, `pose_add(…)`), a routine's
//! parameter, any other expression (nested `pose_trans`, `pose_add`) is
//! computed at run time and skipped; a name the script never assigns fails.
//! `get_inverse_kin(x, qnear=q)` (as Polyscope writes a joint move to a
//! waypoint) goes to the pose `x`, from the joints `q`.
//!
//! Units: metres and the rotation vector `rx, ry, rz` in radians. There are
//! no configuration flags: the controller takes the solution nearest its
//! current joints.

use super::lex::{blank_comments, error, line_end, list, position, tokens, Fail, Tok, Token};
use super::{
    Flags, FrameSpec, JointTarget, Motion, MotionTarget, ParseError, ProgramFile, Site, Targets,
};
use crate::model::orientation::{rotation_from, OrientationConvention};
use crate::model::Pose;
use crate::solve::cell::{CellRef, Load};
use nalgebra::Vector3;
use std::collections::HashMap;
use std::ops::Range;

const MOTIONS: [&str; 4] = ["movel", "movej", "movep", "movec"];

fn word(t: Option<&Token>) -> Option<&str> {
    match t {
        Some((Tok::Word(w), _)) => Some(w),
        _ => None,
    }
}

fn punct(t: Option<&Token>, c: char) -> bool {
    matches!(t, Some((Tok::Punct(p), _)) if *p == c)
}

/// A pose literal at token `i` (`p` `[`): pose or why not, slots, the token after.
type Literal = (Result<Pose, String>, Vec<Range<usize>>, usize);

fn literal(toks: &[Token], i: usize) -> Result<Option<Literal>, Fail> {
    if !(word(toks.get(i)) == Some("p") && punct(toks.get(i + 1), '[')) {
        return Ok(None);
    }
    let (v, next) = list(toks, i + 1)?;
    let Some((x, slots)) = v.numbers(6) else {
        return Err((v.range().start, "a pose literal needs six numbers".into()));
    };
    let pose = rotation_from(OrientationConvention::UrRotvec, &x[3..])
        .map(|r| Pose::new(r, Vector3::new(x[0], x[1], x[2])))
        .map_err(|e| e.to_string());
    Ok(Some((pose, slots, next)))
}

/// The end of the argument starting at token `i` (a `,` or `)` at depth 0).
fn argument_end(toks: &[Token], mut i: usize) -> usize {
    let mut depth = 0i32;
    while let Some((t, _)) = toks.get(i) {
        match t {
            Tok::Punct('(' | '[') => depth += 1,
            Tok::Punct(')' | ']') if depth == 0 => return i,
            Tok::Punct(')' | ']') => depth -= 1,
            Tok::Punct(',') if depth == 0 => return i,
            _ => {}
        }
        i += 1;
    }
    i
}

#[derive(Clone, PartialEq)]
struct Context {
    tool: FrameSpec,
    frame: FrameSpec,
    load: Option<Load>,
}

struct Declared {
    site: Site,
    uses: Vec<(usize, Context)>,
    /// Its place in the execution order (at its first use).
    at: Option<usize>,
}

/// What a variable holds where a motion reads it.
#[derive(Clone)]
enum Var {
    /// A pose literal: its pose (a frame for `pose_trans`) and declared point.
    Pose(Option<Pose>, usize),
    /// Joint values [rad], when literal numbers.
    Joints(Option<Vec<f64>>),
    /// Anything computed at run time, and why.
    RunTime(String),
}

struct Parser<'a> {
    file: usize,
    text: &'a str,
    toks: Vec<Token>,
    tool: FrameSpec,
    /// The last `set_payload`/`set_target_payload` (flange frame).
    load: Option<Load>,
    /// Variables by name, as last assigned.
    vars: HashMap<String, Var>,
    declared: Vec<Declared>,
    order: Vec<Result<Site, usize>>,
    motions: Vec<Motion>,
    joints: Option<Vec<f64>>,
    joint_targets: Vec<JointTarget>,
}

/// The arguments of `set_payload(m, [cx, cy, cz])` at token `i` (kg, m in
/// the flange frame); `None` when the call is not literal numbers.
fn payload(toks: &[Token], i: usize) -> Result<Option<Load>, Fail> {
    let mass = match toks.get(i) {
        Some((Tok::Number(m), _)) => *m,
        _ => return Ok(None),
    };
    if !punct(toks.get(i + 1), ',') || !punct(toks.get(i + 2), '[') {
        return Ok(None);
    }
    let (v, _) = list(toks, i + 2)?;
    Ok(v.numbers(3).and_then(|(c, _)| {
        (mass > 0.0 && mass.is_finite()).then(|| Load {
            mass_kg: mass,
            com: Vector3::new(c[0], c[1], c[2]),
            inertia_kgm2: None,
        })
    }))
}

impl Parser<'_> {
    fn site(
        &self,
        name: String,
        pose: Result<Pose, String>,
        slots: Vec<Range<usize>>,
        ctx: &Context,
    ) -> Site {
        let start = slots.first().map_or(0, |r| r.start);
        let end = line_end(self.text, start);
        let (pose, skip) = match pose {
            Ok(p) => (Some(p), None),
            Err(e) => (None, Some(e)),
        };
        Site {
            file: self.file,
            line: position(self.text, start).0,
            name,
            pose,
            flags: Flags::Nearest,
            tool: ctx.tool.clone(),
            load: ctx.load,
            work_object: ctx.frame.clone(),
            slots,
            convention: OrientationConvention::UrRotvec,
            unit_m: 1.0,
            decimals: [7, 7],
            mark_at: end..end,
            after_joints: None,
            skip,
            refuse: None,
            axes: Vec::new(),
            stationary_tool: false,
        }
    }

    /// A site reached next in the program (after the pending joint move, if
    /// any): its place in the execution order.
    fn push(&mut self, site: Result<Site, usize>) -> usize {
        let joints = self.joints.take();
        match site {
            Ok(mut s) => {
                s.after_joints = joints;
                self.order.push(Ok(s));
                self.order.len() - 1
            }
            Err(i) => {
                let d = &mut self.declared[i];
                if let Some(j) = joints {
                    d.site.after_joints.get_or_insert(j);
                }
                *d.at.get_or_insert_with(|| {
                    self.order.push(Err(i));
                    self.order.len() - 1
                })
            }
        }
    }

    /// The text of tokens `i..end`.
    fn text_of(&self, i: usize, end: usize) -> String {
        match (
            self.toks.get(i),
            end.checked_sub(1).and_then(|e| self.toks.get(e)),
        ) {
            (Some(a), Some(b)) if b.1.end >= a.1.start => self.text[a.1.start..b.1.end].to_string(),
            _ => String::new(),
        }
    }

    /// The position argument at token `i` of a motion at `line`, in frame
    /// `frame`: its name as written and what it is.
    fn target(
        &mut self,
        i: usize,
        frame: FrameSpec,
        line: usize,
    ) -> Result<(String, MotionTarget), Fail> {
        let ctx = Context {
            tool: self.tool.clone(),
            frame,
            load: self.load,
        };
        let end = argument_end(&self.toks, i);
        let text = self.text_of(i, end);
        if let Some((pose, slots, next)) = literal(&self.toks, i)? {
            if next == end {
                let site = self.site("inline".into(), pose, slots, &ctx);
                let at = self.push(Ok(site));
                return Ok(("inline".into(), MotionTarget::Site(at)));
            }
        }
        if word(self.toks.get(i)) == Some("pose_trans") && punct(self.toks.get(i + 1), '(') {
            return self.pose_trans(i, line, text);
        }
        if word(self.toks.get(i)) == Some("get_inverse_kin") && punct(self.toks.get(i + 1), '(') {
            return self.inverse_kin(i, ctx.frame, line, text);
        }
        if let (Some(name), true) = (word(self.toks.get(i)).map(str::to_string), end == i + 1) {
            let name = name.as_str();
            let target = match self.vars.get(name).cloned() {
                Some(Var::Pose(_, d)) => {
                    self.declared[d].uses.push((line, ctx));
                    MotionTarget::Site(self.push(Err(d)))
                }
                Some(Var::Joints(q)) => {
                    if let Some(q) = q {
                        self.joints = Some(q.iter().map(|r| r.to_degrees()).collect());
                    }
                    MotionTarget::Joints { note: None }
                }
                Some(Var::RunTime(why)) => MotionTarget::RunTime(why),
                None => MotionTarget::Undeclared,
            };
            return Ok((name.to_string(), target));
        }
        if punct(self.toks.get(i), '[') {
            // A joint target: where the controller starts the next target from.
            let (v, _) = list(&self.toks, i)?;
            if let Some((q, _)) = v.numbers(6) {
                let deg: Vec<f64> = q.iter().map(|r| r.to_degrees()).collect();
                self.joint_targets.push(JointTarget {
                    file: self.file,
                    line: position(self.text, v.range().start).0,
                    deg: deg.clone(),
                });
                self.joints = Some(deg);
            }
            return Ok(("inline".into(), MotionTarget::Joints { note: None }));
        }
        let why = format!("`{text}` is computed at run time");
        Ok((text, MotionTarget::RunTime(why)))
    }

    /// `pose_trans(frame, point)` at token `i`: the point in the frame (a
    /// pose variable or literal; another name is the cell's work object).
    fn pose_trans(
        &mut self,
        i: usize,
        line: usize,
        text: String,
    ) -> Result<(String, MotionTarget), Fail> {
        let run_time = |text: String| {
            let why = format!("`{text}` is computed at run time");
            Ok((text, MotionTarget::RunTime(why)))
        };
        let frame_end = argument_end(&self.toks, i + 2);
        let frame = match (self.toks.get(i + 2), frame_end - (i + 2)) {
            (Some((Tok::Word(f), _)), 1) => match self.vars.get(f) {
                Some(Var::Pose(Some(p), _)) => FrameSpec::Inline(*p),
                Some(_) => return run_time(text),
                None => FrameSpec::Ref(CellRef::Name(f.to_string())),
            },
            _ => match literal(&self.toks, i + 2)? {
                Some((Ok(p), _, next)) if next == frame_end => FrameSpec::Inline(p),
                _ => return run_time(text),
            },
        };
        let point = frame_end + 1;
        let closes = punct(self.toks.get(argument_end(&self.toks, point)), ')');
        let simple = literal(&self.toks, point)?.is_some()
            || (word(self.toks.get(point)).is_some()
                && argument_end(&self.toks, point) == point + 1);
        if !punct(self.toks.get(frame_end), ',') || !closes || !simple {
            return run_time(text);
        }
        self.target(point, frame, line)
    }

    /// `get_inverse_kin(x)` or `get_inverse_kin(x, qnear)` (`qnear=` named
    /// or not) at token `i`: the controller's own inverse kinematics of the
    /// pose `x` (a literal, a pose variable, `pose_trans`), nearest the
    /// joints `qnear` when given — the position is `x`, and the solution
    /// starts from `qnear`. Other arguments (tolerances, another TCP) make it
    /// a position computed at run time.
    fn inverse_kin(
        &mut self,
        i: usize,
        frame: FrameSpec,
        line: usize,
        text: String,
    ) -> Result<(String, MotionTarget), Fail> {
        let run_time = |text: String| {
            let why = format!("`{text}` is computed at run time");
            Ok((text, MotionTarget::RunTime(why)))
        };
        let x = i + 2;
        let mut close = argument_end(&self.toks, x);
        let mut near: Option<Vec<f64>> = None;
        if punct(self.toks.get(close), ',') {
            let mut a = close + 1;
            if word(self.toks.get(a)) == Some("qnear") && punct(self.toks.get(a + 1), '=') {
                a += 2;
            }
            close = argument_end(&self.toks, a);
            near = match (self.toks.get(a), close - a) {
                (Some((Tok::Word(v), _)), 1) => match self.vars.get(v) {
                    Some(Var::Joints(Some(q))) => Some(q.clone()),
                    _ => return run_time(text),
                },
                (Some((Tok::Punct('['), _)), _) => match list(&self.toks, a)? {
                    (v, next) if next == close => v.numbers(6).map(|(q, _)| q),
                    _ => None,
                },
                _ => None,
            };
            if near.is_none() {
                return run_time(text);
            }
        }
        if !punct(self.toks.get(close), ')') {
            return run_time(text);
        }
        if let Some(q) = near {
            self.joints = Some(q.iter().map(|r| r.to_degrees()).collect());
        }
        self.target(x, frame, line)
    }

    /// A motion call at token `i` (its name): its position arguments (two
    /// for `movec`: via point and end point).
    fn motion(&mut self, i: usize, instruction: &str) -> Result<(), Fail> {
        let at = self.toks[i].1.start;
        let line = position(self.text, at).0;
        let end = line_end(self.text, at);
        let mut arg = i + 2;
        for k in 0..if instruction == "movec" { 2 } else { 1 } {
            if k > 0 {
                let e = argument_end(&self.toks, arg);
                if !punct(self.toks.get(e), ',') {
                    break;
                }
                arg = e + 1;
            }
            let (name, target) = self.target(arg, FrameSpec::Unset, line)?;
            if matches!(target, MotionTarget::RunTime(_) | MotionTarget::Undeclared) {
                // The robot went elsewhere: a joint move before no longer
                // says where the next target starts from.
                self.joints = None;
            }
            self.motions.push(Motion {
                file: self.file,
                line,
                instruction: instruction.to_string(),
                name,
                target,
                mark_at: end..end,
            });
        }
        Ok(())
    }

    /// Whether token `i` starts a statement (the first on its line, or
    /// after `global`/`local`).
    fn statement_start(&self, i: usize) -> bool {
        let after_keyword = i
            .checked_sub(1)
            .is_some_and(|j| matches!(word(self.toks.get(j)), Some("global" | "local")));
        after_keyword || self.line_break_before(i)
    }

    /// Whether token `k` starts a new line (or is past the last token).
    fn line_break_before(&self, k: usize) -> bool {
        match (
            k.checked_sub(1).and_then(|j| self.toks.get(j)),
            self.toks.get(k),
        ) {
            (Some(a), Some(b)) => self.text[a.1.end..b.1.start].contains('\n'),
            _ => true,
        }
    }

    /// `name = value` at token `i` (the name): what the variable holds (a
    /// literal only when it is the whole statement).
    fn assignment(&mut self, i: usize, name: &str) -> Result<(), Fail> {
        let value = i + 2;
        if let Some((pose, slots, next)) = literal(&self.toks, value)? {
            if self.line_break_before(next) {
                let unset = Context {
                    tool: FrameSpec::Unset,
                    frame: FrameSpec::Unset,
                    load: None,
                };
                let frame = pose.as_ref().ok().copied();
                let site = self.site(name.to_string(), pose, slots, &unset);
                self.vars
                    .insert(name.to_string(), Var::Pose(frame, self.declared.len()));
                self.declared.push(Declared {
                    site,
                    uses: Vec::new(),
                    at: None,
                });
                return Ok(());
            }
        }
        let joints = if punct(self.toks.get(value), '[') {
            let (v, next) = list(&self.toks, value)?;
            self.line_break_before(next)
                .then(|| v.numbers(6).map(|(q, _)| q))
        } else {
            None
        };
        let var = if let Some(q) = joints {
            Var::Joints(q)
        } else {
            let line = position(self.text, self.toks[i].1.start).0;
            Var::RunTime(format!("{name} is computed at run time (line {line})"))
        };
        self.vars.insert(name.to_string(), var);
        Ok(())
    }

    /// `def name(a, b):`: the parameters, set by the caller.
    fn parameters(&mut self, i: usize) {
        let routine = word(self.toks.get(i + 1)).unwrap_or_default().to_string();
        let mut k = i + 3;
        while let Some((t, _)) = self.toks.get(k) {
            match t {
                Tok::Punct(')') => break,
                Tok::Word(p) => {
                    let why = format!("{p} is a parameter of {routine}: set at run time");
                    self.vars.insert(p.clone(), Var::RunTime(why));
                }
                _ => {}
            }
            k += 1;
        }
    }

    fn run(&mut self) -> Result<(), Fail> {
        let mut i = 0;
        while i < self.toks.len() {
            let w = word(self.toks.get(i)).map(str::to_string);
            match w.as_deref() {
                Some("set_tcp") if punct(self.toks.get(i + 1), '(') => {
                    self.tool = match literal(&self.toks, i + 2)? {
                        Some((Ok(p), _, _)) => FrameSpec::Inline(p),
                        _ => FrameSpec::Unset,
                    };
                }
                Some("set_payload" | "set_target_payload") if punct(self.toks.get(i + 1), '(') => {
                    self.load = payload(&self.toks, i + 2)?;
                }
                Some("def") if punct(self.toks.get(i + 2), '(') => self.parameters(i),
                Some(m) if MOTIONS.contains(&m) && punct(self.toks.get(i + 1), '(') => {
                    self.motion(i, m)?;
                }
                Some(name)
                    if punct(self.toks.get(i + 1), '=')
                        && !punct(self.toks.get(i + 2), '=')
                        && self.statement_start(i) =>
                {
                    self.assignment(i, name)?;
                }
                _ => {}
            }
            i += 1;
        }
        Ok(())
    }

    fn finish(self) -> Targets {
        // A variable no motion uses is not known to be a target (a frame, an
        // offset): it is not a site.
        let declared = self.declared;
        let sites = self
            .order
            .into_iter()
            .map(|s| match s {
                Ok(site) => site,
                Err(i) => {
                    let d = &declared[i];
                    let mut site = d.site.clone();
                    // In the order at its first use: it has one.
                    if let Some((first, ctx)) = d.uses.first() {
                        site.tool = ctx.tool.clone();
                        site.load = ctx.load;
                        site.work_object = ctx.frame.clone();
                        if let Some((line, _)) = d.uses.iter().find(|(_, c)| c != ctx) {
                            site.skip = site.skip.or(Some(format!(
                                "used with different tools or frames (lines {first} and {line})"
                            )));
                        }
                    }
                    site
                }
            })
            .collect();
        Targets {
            sites,
            motions: self.motions,
            joints: self.joint_targets,
        }
    }
}

/// Parses URScript files.
pub(super) fn parse(files: &[ProgramFile]) -> Result<Targets, ParseError> {
    let mut found = Targets::default();
    for (fi, f) in files.iter().enumerate() {
        let fail = |e: Fail| error(&f.name, &f.text, e);
        let masked = blank_comments(&f.text, '#', &['"', '\'']).map_err(fail)?;
        let mut p = Parser {
            file: fi,
            text: &f.text,
            toks: tokens(&masked, &['"', '\'']).map_err(fail)?,
            tool: FrameSpec::Unset,
            load: None,
            vars: HashMap::new(),
            declared: Vec::new(),
            order: Vec::new(),
            motions: Vec::new(),
            joints: None,
            joint_targets: Vec::new(),
        };
        p.run().map_err(fail)?;
        let t = p.finish();
        let offset = found.sites.len();
        found.sites.extend(t.sites);
        found.motions.extend(t.motions.into_iter().map(|mut m| {
            if let MotionTarget::Site(i) = &mut m.target {
                *i += offset;
            }
            m
        }));
        found.joints.extend(t.joints);
    }
    Ok(found)
}

#[cfg(test)]
mod tests;
