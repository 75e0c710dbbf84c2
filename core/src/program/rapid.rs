//! ABB RAPID modules (`.mod`, `.modx`, `.prg`).
//!
//! Targets: `robtarget` literals `[[x,y,z],[q1,q2,q3,q4],[cf1,cf4,cf6,cfx],
//! [eax_a,…]]`, declared (`CONST|PERS|VAR robtarget p10 := …;`, arrays too)
//! and used by name, or inline, in `MoveL`, `MoveJ`, `MoveC` (and their `DO`
//! and `Trigg` forms). The tool is the motion's `Tool` argument, the work
//! object its `\WObj`; both are read from the module's `tooldata`
//! (`[robhold,[[x,y,z],[q1..q4]],[mass,[cx,cy,cz],…]]`) and `wobjdata`
//! (`[robhold,ufprog,ufmec,uframe,oframe]`, the work object `uframe·oframe`;
//! with `ufprog FALSE` a work object the mechanical unit `ufmec` moves,
//! whose user frame the controller computes from the unit: `oframe` on the
//! positioner's face plate, [`FrameSpec::FacePlate`]), else looked up in the
//! cell by name; `tool0` is the flange and `wobj0` the base frame. A tooldata's `robhold TRUE` is a tool the robot holds (the
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
//! Every position of a motion is reported (`Motion`): `MoveAbsJ` is a joint
//! motion; `Offs(…)`, `RelTool(…)`, `CRobT()`, an array element chosen at
//! run time, a routine's parameter, a robtarget declared without a value or
//! assigned in a routine (`p10 := …`, `p10.trans.z := …`) are set at run
//! time and skipped; a name no module declares fails; a robtarget's
//! external axes other than 9E9 go with the site to the filter
//! (`program::axes`: the track's, `eax_a`, composed, any other refused).
//!
//! Units: mm, unit quaternions with the scalar `q1` first. `cf1, cf4, cf6`
//! are the quadrants `⌊A/90°⌋` of axes 1, 4, 6; `cfx = 4·back + 2·down +
//! [A5 < 0]` (wrist centre behind axis 1, behind the lower arm, axis 5
//! negative). All four are kept.

mod literals;

use super::lex::{blank_comments, error, line_end, list, tokens, Fail, Tok, Token, Val};
use super::{FrameSpec, JointTarget, Motion, MotionTarget, ParseError, ProgramFile, Site, Targets};
use crate::model::orientation::OrientationConvention;
use crate::model::Pose;
use crate::solve::cell::{CellRef, Load};
use literals::{
    arguments, assigned_root, frame, main_part, robtarget, tload, word, Instruction, Target,
    ToolArg, INSTRUCTIONS,
};
use std::collections::{HashMap, HashSet};

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
    /// Its place in the execution order (at its first use).
    at: Option<usize>,
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
    /// Work objects a mechanical unit moves (`ufprog FALSE`).
    moved_wobjs: HashSet<String>,
    declared: Vec<Declared>,
    /// Declared robtargets by lower-case name (one per element of an array).
    by_name: HashMap<String, Vec<usize>>,
    /// Declared jointtargets (lower case).
    joint_names: HashSet<String>,
    /// Robtargets without a value in the modules (declared without one,
    /// routine parameters), and why.
    runtime: HashMap<String, String>,
    /// Robtargets a routine assigns (lower case): the line.
    assigned: HashMap<String, usize>,
    order: Vec<Result<Site, usize>>,
    motions: Vec<Motion>,
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
            refuse: None,
            axes: t.axes,
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
            let key = name.to_ascii_lowercase();
            if ty == "jointtarget" {
                self.joint_names.insert(key.clone());
            }
            if !assign && ty == "robtarget" {
                self.runtime.entry(key).or_insert(format!(
                    "{name} is declared without a value: it is set at run time"
                ));
                continue;
            }
            if !assign || !st.get(j + 2).is_some_and(|t| t.0 == Tok::Punct('[')) {
                continue;
            }
            let (v, next) = list(st, j + 2)?;
            if let Some((_, r)) = st.get(next) {
                return Err((r.start, "expected `;` after the value".into()));
            }
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
                at: None,
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
    /// robot when `robhold TRUE`; the object frame on the face plate of the
    /// positioner when a mechanical unit moves it (`ufprog FALSE`).
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
        let ufprog = items
            .get(1)
            .map(|r| self.text_of(fi, r))
            .unwrap_or_default();
        let ufmec = items
            .get(2)
            .map(|r| self.text_of(fi, r))
            .unwrap_or_default();
        let held = robhold.eq_ignore_ascii_case("true");
        if held {
            self.held_wobjs.insert(key.clone());
        }
        let unit = ufmec.trim_matches('"').trim();
        let value = if !ufprog.eq_ignore_ascii_case("false") {
            uf.and_then(|u| of.map(|o| u.compose(&o)))
        } else if unit.is_empty() {
            Err(format!(
                "work object {name} is moved (ufprog FALSE) by no mechanical unit (ufmec empty)"
            ))
        } else if held {
            Err(format!(
                "work object {name} is held by the robot and moved by {ufmec}, which is not modelled"
            ))
        } else {
            self.moved_wobjs.insert(key.clone());
            of
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
            if let Some(m) = st.iter().position(|t| {
                word(Some(t)).is_some_and(|w| {
                    w.eq_ignore_ascii_case("moveabsj") || w.eq_ignore_ascii_case("moveextj")
                })
            }) {
                self.joint_motion(fi, st, m)?;
                continue;
            }
            // After whatever has no `;` (PROC headers, THEN, DO, …).
            let found = st.iter().enumerate().find_map(|(i, t)| {
                let w = word(Some(t))?;
                let ins = INSTRUCTIONS
                    .iter()
                    .find(|x| w.eq_ignore_ascii_case(x.name))?;
                Some((i, ins))
            });
            if let Some((m, ins)) = found {
                self.motion(fi, &st[m..], ins)?;
            }
        }
        self.toks[fi] = toks;
        Ok(())
    }

    /// `MoveAbsJ` (or `MoveExtJ`) at token `m` of a statement: axis values.
    fn joint_motion(&mut self, fi: usize, st: &[Token], m: usize) -> Result<(), Fail> {
        if st.get(m + 1).is_some_and(|t| t.0 == Tok::Punct('[')) {
            let (v, _) = list(st, m + 1)?;
            self.joint(fi, &v);
        }
        let args = arguments(&st[m + 1..]);
        let first = args
            .iter()
            .find(|a| a.first().is_some_and(|t| t.0 != Tok::Punct('\\')))
            .map(|a| main_part(a));
        let name = match first {
            Some([(Tok::Punct('['), _), ..]) | None => "inline".to_string(),
            Some(a) => self.text_of_tokens(fi, a),
        };
        let text = &self.files[fi].text;
        let at = st[m].1.start;
        let end = line_end(text, at);
        self.motions.push(Motion {
            file: fi,
            line: super::lex::position(text, at).0,
            instruction: text[st[m].1.clone()].to_string(),
            name,
            target: MotionTarget::Joints { note: None },
            mark_at: end..end,
        });
        Ok(())
    }

    /// The text of tokens `a` (comments blanked out).
    fn text_of_tokens(&self, fi: usize, a: &[Token]) -> String {
        match (a.first(), a.last()) {
            (Some(x), Some(y)) => self.masked[fi][x.1.start..y.1.end].trim().to_string(),
            _ => String::new(),
        }
    }

    /// A Cartesian motion (the statement from its instruction on): its tool,
    /// work object and load, and its positions.
    fn motion(&mut self, fi: usize, st: &[Token], ins: &Instruction) -> Result<(), Fail> {
        let args = arguments(&st[1..]);
        let positional: Vec<&[Token]> = args
            .iter()
            .filter(|a| a.first().is_some_and(|t| t.0 != Tok::Punct('\\')))
            .map(|a| main_part(a))
            .collect();
        let tool_arg = match ins.tool {
            ToolArg::Last => positional.len().checked_sub(1),
            ToolArg::At(k) => Some(k),
        }
        .filter(|k| *k >= ins.first + ins.points);
        let tool_name = tool_arg
            .and_then(|k| positional.get(k))
            .and_then(|a| word(a.first()));
        let ctx = self.context_of(st, tool_name);
        let text = &self.files[fi].text;
        let line = super::lex::position(text, st[0].1.start).0;
        let instruction = text[st[0].1.clone()].to_string();
        for arg in positional.iter().skip(ins.first).take(ins.points) {
            let (name, target) = self.position(fi, arg, line, &ctx)?;
            let text = &self.files[fi].text;
            let end = line_end(text, arg.first().map_or(st[0].1.start, |t| t.1.start));
            self.motions.push(Motion {
                file: fi,
                line,
                instruction: instruction.clone(),
                name,
                target,
                mark_at: end..end,
            });
        }
        Ok(())
    }

    /// The tool, work object and load of a motion statement.
    fn context_of(&self, st: &[Token], tool_name: Option<&str>) -> Context {
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
        let (wobj, wobj_err) = Self::frame_spec(&self.wobjs, wobj_name.unwrap_or("wobj0"), "wobj0");
        let moved = self
            .moved_wobjs
            .contains(&wobj_name.unwrap_or_default().to_ascii_lowercase());
        let wobj = match wobj {
            FrameSpec::Inline(p) if moved => FrameSpec::FacePlate(p),
            other => other,
        };
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
        Context {
            tool,
            wobj,
            load,
            skip: tool_err.or(wobj_err).or(roles),
            stationary,
        }
    }

    /// What one position argument of a motion at `line` is, and its name as written.
    fn position(
        &mut self,
        fi: usize,
        arg: &[Token],
        line: usize,
        ctx: &Context,
    ) -> Result<(String, MotionTarget), Fail> {
        let text = self.text_of_tokens(fi, arg);
        let target = match arg {
            [] => MotionTarget::RunTime("the motion gives no position".into()),
            [(Tok::Punct('['), _), ..] => {
                let (v, _) = list(arg, 0)?;
                let t = robtarget(&v)?;
                let site = self.site(fi, "inline".into(), t, ctx);
                self.order.push(Ok(site));
                return Ok(("inline".into(), MotionTarget::Site(self.order.len() - 1)));
            }
            [(Tok::Word(w), _)] => self.named(w, None, line, ctx),
            [(Tok::Word(w), _), (Tok::Punct('{'), _), (Tok::Number(n), _), (Tok::Punct('}'), _)]
                if n.fract() == 0.0 && *n >= 1.0 && *n < 1e9 =>
            {
                self.named(w, Some(*n as usize), line, ctx)
            }
            [(Tok::Word(_), _), (Tok::Punct('{'), _), ..] => {
                MotionTarget::RunTime(format!("`{text}` is an element chosen at run time"))
            }
            _ => MotionTarget::RunTime(format!("`{text}` is computed at run time")),
        };
        Ok((text, target))
    }

    /// What a motion to the robtarget `name` (element `index` of an array,
    /// 1-based) goes to.
    fn named(
        &mut self,
        name: &str,
        index: Option<usize>,
        line: usize,
        ctx: &Context,
    ) -> MotionTarget {
        let key = name.to_ascii_lowercase();
        if let Some(ids) = self.by_name.get(&key) {
            let array = self.declared[ids[0]].site.name.ends_with('}');
            let id = match (array, index) {
                (false, None) => Some(ids[0]),
                (true, Some(k)) => ids.get(k - 1).copied(),
                (true, None) => {
                    return MotionTarget::RunTime(format!(
                        "{name} is an array: the motion takes a whole array"
                    ))
                }
                (false, Some(_)) => None,
            };
            return match id {
                Some(i) => MotionTarget::Site(self.use_declared(i, line, ctx)),
                None => MotionTarget::Undeclared,
            };
        }
        if let Some(why) = self.runtime.get(&key) {
            return MotionTarget::RunTime(why.clone());
        }
        if self.joint_names.contains(&key) {
            return MotionTarget::Joints { note: None };
        }
        MotionTarget::Undeclared
    }

    /// Declared point `i` used by a motion at `line`: its place in the execution order.
    fn use_declared(&mut self, i: usize, line: usize, ctx: &Context) -> usize {
        let d = &mut self.declared[i];
        let at = *d.at.get_or_insert(self.order.len());
        if at == self.order.len() {
            self.order.push(Err(i));
        }
        d.uses.push((line, ctx.clone()));
        at
    }

    /// Routine parameters of type robtarget (set by the caller) and the
    /// robtargets a routine assigns (`p10 := …`, `p10.trans.z := …`).
    fn routines(&mut self, fi: usize) {
        let toks = std::mem::take(&mut self.toks[fi]);
        for st in statements(&toks) {
            let lower = |t: &Token| word(Some(t)).map(str::to_ascii_lowercase);
            for (j, t) in st.iter().enumerate() {
                if !matches!(lower(t).as_deref(), Some("proc" | "func" | "trap")) {
                    continue;
                }
                let routine = word(st.get(j + 1)).unwrap_or_default().to_string();
                let params = st[j..].iter().take_while(|t| t.0 != Tok::Punct(')'));
                let params: Vec<&Token> = params.collect();
                for w in params.windows(2) {
                    if lower(w[0]).as_deref() == Some("robtarget") {
                        if let Some(p) = word(Some(w[1])) {
                            self.runtime
                                .entry(p.to_ascii_lowercase())
                                .or_insert(format!(
                                    "{p} is a parameter of {routine}: set at run time"
                                ));
                        }
                    }
                }
            }
            let declaration = st
                .iter()
                .any(|t| matches!(lower(t).as_deref(), Some("const" | "pers" | "var")));
            if declaration {
                continue;
            }
            for k in 0..st.len().saturating_sub(1) {
                if st[k].0 == Tok::Punct(':') && st[k + 1].0 == Tok::Punct('=') {
                    if let Some(root) = assigned_root(st, k) {
                        let line = super::lex::position(&self.files[fi].text, st[k].1.start).0;
                        self.assigned
                            .entry(root.to_ascii_lowercase())
                            .or_insert(line);
                    }
                }
            }
        }
        self.toks[fi] = toks;
    }

    fn finish(self) -> Targets {
        let mut declared = self.declared;
        let mut order = self.order;
        for (i, d) in declared.iter_mut().enumerate() {
            if d.at.is_none() {
                d.at = Some(order.len());
                order.push(Err(i));
            }
        }
        let assigned = &self.assigned;
        let sites = order
            .into_iter()
            .map(|s| match s {
                Ok(site) => site,
                Err(i) => declared_site(&declared[i], assigned),
            })
            .collect();
        Targets {
            sites,
            motions: self.motions,
            joints: self.joints,
        }
    }
}

/// A declared point with the context of the motions that use it; skipped
/// when a routine assigns it.
fn declared_site(d: &Declared, assigned: &HashMap<String, usize>) -> Site {
    let mut site = d.site.clone();
    let key = site
        .name
        .split('{')
        .next()
        .unwrap_or_default()
        .to_ascii_lowercase();
    if let Some(line) = assigned.get(&key) {
        site.skip
            .get_or_insert(format!("{key} is assigned at run time (line {line})"));
    }
    match d.uses.first() {
        None => {
            site.skip
                .get_or_insert("no motion of the program uses it".into());
        }
        Some((first, ctx)) => {
            site.tool = ctx.tool.clone();
            site.load = ctx.load;
            site.work_object = ctx.wobj.clone();
            site.stationary_tool = ctx.stationary;
            site.skip = site.skip.take().or(ctx.skip.clone());
            let other = d
                .uses
                .iter()
                .find(|(_, c)| c.tool != ctx.tool || c.wobj != ctx.wobj);
            if let Some((line, _)) = other {
                site.skip.get_or_insert(format!(
                    "used with different tools or work objects (lines {first} and {line})"
                ));
            }
        }
    }
    site
}

/// Parses RAPID modules.
pub(super) fn parse(files: &[ProgramFile]) -> Result<Targets, ParseError> {
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
        moved_wobjs: HashSet::new(),
        declared: Vec::new(),
        by_name: HashMap::new(),
        joint_names: HashSet::new(),
        runtime: HashMap::new(),
        assigned: HashMap::new(),
        order: Vec::new(),
        motions: Vec::new(),
        joints: Vec::new(),
    };
    for (fi, f) in files.iter().enumerate() {
        p.declarations(fi).map_err(|e| error(&f.name, &f.text, e))?;
        p.routines(fi);
    }
    for (fi, f) in files.iter().enumerate() {
        p.motions(fi).map_err(|e| error(&f.name, &f.text, e))?;
    }
    Ok(p.finish())
}

#[cfg(test)]
mod tests;
