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
//! Units: metres and the rotation vector `rx, ry, rz` in radians. There are
//! no configuration flags: the controller takes the solution nearest its
//! current joints.

use super::lex::{blank_comments, error, line_end, list, position, tokens, Fail, Tok, Token};
use super::{Flags, FrameSpec, JointTarget, ParseError, ProgramFile, Site, Targets};
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
}

struct Parser<'a> {
    file: usize,
    text: &'a str,
    toks: Vec<Token>,
    tool: FrameSpec,
    /// The last `set_payload`/`set_target_payload` (flange frame).
    load: Option<Load>,
    /// Pose variables: name → literal pose (frames) and declared site index.
    vars: HashMap<String, (Option<Pose>, usize)>,
    declared: Vec<Declared>,
    order: Vec<Result<Site, usize>>,
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
            stationary_tool: false,
        }
    }

    fn push(&mut self, site: Result<Site, usize>) {
        let joints = self.joints.take();
        match site {
            Ok(mut s) => {
                s.after_joints = joints;
                self.order.push(Ok(s));
            }
            Err(i) => {
                if let Some(j) = joints {
                    self.declared[i].site.after_joints.get_or_insert(j);
                }
                self.order.push(Err(i));
            }
        }
    }

    /// A motion target at token `i` in frame `frame`; returns the token after it.
    fn target(&mut self, i: usize, frame: FrameSpec) -> Result<(), Fail> {
        let ctx = Context {
            tool: self.tool.clone(),
            frame,
            load: self.load,
        };
        if let Some((pose, slots, _)) = literal(&self.toks, i)? {
            let site = self.site("inline".into(), pose, slots, &ctx);
            self.push(Ok(site));
            return Ok(());
        }
        if word(self.toks.get(i)) == Some("pose_trans") && punct(self.toks.get(i + 1), '(') {
            let Some(f) = word(self.toks.get(i + 2)) else {
                return Ok(());
            };
            if !punct(self.toks.get(i + 3), ',') {
                return Ok(());
            }
            let frame = match self.vars.get(f) {
                Some((Some(p), _)) => FrameSpec::Inline(*p),
                _ => FrameSpec::Ref(CellRef::Name(f.to_string())),
            };
            return self.target(i + 4, frame);
        }
        if let Some(name) = word(self.toks.get(i)) {
            let end = argument_end(&self.toks, i);
            if end == i + 1 {
                if let Some(&(_, d)) = self.vars.get(name) {
                    let line = position(self.text, self.toks[i].1.start).0;
                    if self.declared[d].uses.is_empty() {
                        self.push(Err(d));
                    }
                    self.declared[d].uses.push((line, ctx));
                }
            }
        } else if punct(self.toks.get(i), '[') {
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
        }
        Ok(())
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
                Some(m) if MOTIONS.contains(&m) && punct(self.toks.get(i + 1), '(') => {
                    self.target(i + 2, FrameSpec::Unset)?;
                    if m == "movec" {
                        let end = argument_end(&self.toks, i + 2);
                        if punct(self.toks.get(end), ',') {
                            self.target(end + 1, FrameSpec::Unset)?;
                        }
                    }
                }
                Some(name)
                    if punct(self.toks.get(i + 1), '=') && !punct(self.toks.get(i + 2), '=') =>
                {
                    if let Some((pose, slots, _)) = literal(&self.toks, i + 2)? {
                        let unset = Context {
                            tool: FrameSpec::Unset,
                            frame: FrameSpec::Unset,
                            load: None,
                        };
                        let frame = pose.as_ref().ok().copied();
                        let site = self.site(name.to_string(), pose, slots, &unset);
                        self.vars
                            .insert(name.to_string(), (frame, self.declared.len()));
                        self.declared.push(Declared {
                            site,
                            uses: Vec::new(),
                        });
                    }
                }
                _ => {}
            }
            i += 1;
        }
        Ok(())
    }

    fn finish(self) -> Targets {
        let declared = self.declared;
        let sites = self
            .order
            .into_iter()
            .map(|s| match s {
                Ok(site) => site,
                Err(i) => {
                    let d = &declared[i];
                    let mut site = d.site.clone();
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
            joints: self.joint_targets,
        }
    }
}

/// Parses URScript files.
pub fn parse(files: &[ProgramFile]) -> Result<Targets, ParseError> {
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
            joints: None,
            joint_targets: Vec::new(),
        };
        p.run().map_err(fail)?;
        let t = p.finish();
        found.sites.extend(t.sites);
        found.joints.extend(t.joints);
    }
    Ok(found)
}

#[cfg(test)]
mod tests;
