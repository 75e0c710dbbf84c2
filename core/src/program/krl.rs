//! KUKA KRL: `.src` modules and their `.dat` data lists.
//!
//! Targets: `E6POS`, `POS` and `FRAME` aggregates `{X …, Y …, Z …, A …, B …,
//! C …, S …, T …, E1 …}`, declared (`DECL E6POS XP1={…}`, in any file) and
//! used by name in `PTP`/`LIN`/`CIRC` (and `SPTP`/`SLIN`/`SCIRC`/`SPL`), or
//! inline in a motion. Joint aggregates (`A1 … A6`) and points declared
//! `E6AXIS`/`AXIS` are not targets (joint motions); nor are `XHOME` and
//! `XHOME1`..`XHOME5` when the files do not declare them (KUKA's home
//! positions, axis values in `$config.dat`). Every motion's position is
//! reported (`Motion`): a relative motion (`LIN_REL`, `PTP_REL`, …), a
//! system variable (`$POS_ACT`), an array element, an expression, a point
//! declared without a value or assigned in a `.src` is set at run time and
//! skipped; a name no file declares (a `.src` without its `.dat`) fails;
//! an `E6POS` carries its external axes' values `E1..E6` to the filter
//! (`program::axes`: the track's composed, any other in use refused).
//! Tool and base: `$TOOL = TOOL_DATA[n]`, `$BASE = BASE_DATA[n]`, inline
//! frames, `$NULLFRAME`, `BAS(#TOOL, n)`, `BAS(#BASE, n)` and `FDAT_ACT = FP1`
//! with `DECL FDAT FP1={TOOL_NO n, BASE_NO m, …}`; `TOOL_DATA[n]={…}` and
//! `BASE_DATA[n]={…}` in the files define numbers over the cell's. The
//! declared load: `$LOAD = {M m, CM {X, Y, Z, …}, J {X, Y, Z}}` or
//! `$LOAD = LOAD_DATA[n]`, and `BAS(#TOOL, n)` takes `LOAD_DATA[n]` when the
//! files define it (`LOAD_DATA[n]={…}`, as in `$config.dat`); kg, mm in the
//! flange frame, kg·m²; a mass of −1 (the controller's default) or 0 is no
//! declaration. External TCP (`$IPO_MODE = #TCP`, or `IPO_FRAME #TCP` in
//! the active `FDAT`) swaps the roles as the controller does: `$BASE`
//! (`BASE_DATA[n]`) is the stationary tool in the robot base frame, `$TOOL`
//! (`TOOL_DATA[n]`) the work piece the robot carries (flange → work piece),
//! `$LOAD` that work piece's load, and a point the fixed tool's pose in the
//! carried work piece ([`Site::stationary_tool`]); `#BASE` restores the
//! ordinary roles. A declared point takes the tool, base and interpolation
//! mode of the motions that use it (all the same, else it is skipped). Comments (`;` to the end of the line) are ignored;
//! KRL is case-insensitive.
//!
//! Units: mm and degrees, `R = Rz(A)·Ry(B)·Rx(C)`. `S` and `T` are kept.

mod aggregate;

use super::{FrameSpec, JointTarget, Motion, MotionTarget, ParseError, ProgramFile, Site, Targets};
use crate::model::orientation::OrientationConvention;
use crate::model::Pose;
use crate::solve::cell::{CellRef, Load};
#[cfg(test)]
use aggregate::real;
use aggregate::{
    classify, code_of, frame_of, integer, joint_values, lines, load_of, shift, tokens, Kind, Line,
    Tok,
};
use std::collections::{HashMap, HashSet};
use std::ops::Range;

const MOTIONS: [&str; 7] = ["PTP", "LIN", "CIRC", "SPTP", "SLIN", "SCIRC", "SPL"];
const RELATIVE: [&str; 6] = [
    "PTP_REL",
    "LIN_REL",
    "CIRC_REL",
    "SPTP_REL",
    "SLIN_REL",
    "SCIRC_REL",
];
const POSE_TYPES: [&str; 3] = ["E6POS", "POS", "FRAME"];
const AXIS_TYPES: [&str; 2] = ["E6AXIS", "AXIS"];
/// Words that end a motion's position (approximation and spline clauses).
const CLAUSES: [&str; 7] = ["C_DIS", "C_PTP", "C_VEL", "C_ORI", "C_SPL", "WITH", "CA"];

#[derive(Debug, Clone, PartialEq)]
struct Context {
    tool: FrameSpec,
    base: FrameSpec,
    load: Option<Load>,
    /// External TCP (`$IPO_MODE = #TCP`): the tool is fixed, the robot
    /// carries the work piece.
    external: bool,
}

/// What a `DECL FDAT` selects: `TOOL_NO`, `BASE_NO` and `IPO_FRAME`
/// (`Some(true)` for `#TCP`).
#[derive(Clone, Copy)]
struct Fdat {
    tool: Option<u32>,
    base: Option<u32>,
    external: Option<bool>,
}

/// A declared point, the contexts of the motions that use it, and its
/// place in the execution order (at its first use).
struct Declared {
    site: Site,
    uses: Vec<(usize, Context)>,
    at: Option<usize>,
}

struct Parser<'a> {
    files: &'a [ProgramFile],
    declared: Vec<Declared>,
    by_name: HashMap<String, usize>,
    /// Points declared with axis values (`E6AXIS`, `AXIS`).
    axis_names: HashSet<String>,
    /// Points without a Cartesian value in the files, and why.
    runtime: HashMap<String, String>,
    /// Names a `.src` assigns: the first file and line.
    assigned: HashMap<String, (usize, usize)>,
    fdat: HashMap<String, Fdat>,
    tools: HashMap<u32, Pose>,
    bases: HashMap<u32, Pose>,
    loads: HashMap<u32, Load>,
    /// Sites in execution order; `Err(i)` is declared point `i` at its first use.
    order: Vec<Result<Site, usize>>,
    motions: Vec<Motion>,
    joints: Vec<JointTarget>,
}

fn err(file: &ProgramFile, line: &Line, at: usize, message: String) -> ParseError {
    let column = line.text.get(..at).map_or(at, |s| s.chars().count()) + 1;
    ParseError {
        file: file.name.clone(),
        line: line.no,
        column,
        message,
    }
}

fn site_of(
    file: usize,
    line: &Line,
    name: &str,
    kind: Kind,
    ctx: &Context,
    skip: Option<String>,
) -> Option<Site> {
    let Kind::Cartesian {
        pose,
        flags,
        slots,
        axes,
    } = kind
    else {
        return None;
    };
    let (pose, skip) = match pose {
        Ok(p) => (Some(p), skip),
        Err(e) => (None, skip.or(Some(e))),
    };
    // External TCP: the fixed tool is `$BASE`, the carried work piece `$TOOL`.
    let (tool, work_object) = ctx.roles();
    Some(Site {
        file,
        line: line.no,
        name: name.to_string(),
        pose,
        flags,
        tool,
        load: ctx.load,
        work_object,
        slots,
        convention: OrientationConvention::KukaAbc,
        unit_m: 1e-3,
        decimals: [4, 4],
        mark_at: line.end..line.end,
        after_joints: None,
        skip,
        refuse: None,
        axes,
        stationary_tool: ctx.external,
    })
}

impl Context {
    fn unset() -> Context {
        Context {
            tool: FrameSpec::Unset,
            base: FrameSpec::Unset,
            load: None,
            external: false,
        }
    }

    /// The site's (tool, work object): `($TOOL, $BASE)`, or with an external
    /// TCP `($BASE, $TOOL)` (the fixed tool, the carried work piece).
    fn roles(&self) -> (FrameSpec, FrameSpec) {
        if self.external {
            (self.base.clone(), self.tool.clone())
        } else {
            (self.tool.clone(), self.base.clone())
        }
    }
}

impl Parser<'_> {
    fn number_ref(&self, toks: &[(Tok, Range<usize>)], at: usize) -> Option<u32> {
        match (toks.get(at), toks.get(at + 1), toks.get(at + 2)) {
            (Some((Tok::Punct('['), _)), Some((Tok::Number(n), _)), Some((Tok::Punct(']'), _)))
                if n.fract() == 0.0 && *n >= 0.0 && *n < 1e9 =>
            {
                Some(*n as u32)
            }
            _ => None,
        }
    }

    fn frame_spec(&self, number: u32, tool: bool) -> FrameSpec {
        let defined = if tool { &self.tools } else { &self.bases };
        match defined.get(&number) {
            Some(p) => FrameSpec::Inline(*p),
            None => FrameSpec::Ref(CellRef::Number(number)),
        }
    }

    /// Declarations and data definitions (first pass, every file), and the
    /// names a `.src` assigns.
    fn declarations(&mut self, fi: usize) -> Result<(), ParseError> {
        let file = &self.files[fi];
        let src = has_ext(&file.name, "src");
        for line in lines(&file.text) {
            let code = code_of(line.text).map_err(|(at, m)| err(file, &line, at, m))?;
            let toks = tokens(code).map_err(|(at, m)| err(file, &line, at, m))?;
            for (t, _) in &toks {
                if let Tok::Agg(a) = t {
                    if let Some(deg) = joint_values(a, code) {
                        self.joints.push(JointTarget {
                            file: fi,
                            line: line.no,
                            deg,
                        });
                    }
                }
            }
            let words: Vec<&str> = toks
                .iter()
                .map(|(t, _)| match t {
                    Tok::Word(w) => w.as_str(),
                    _ => "",
                })
                .collect();
            let mut k = 0;
            if words.first() == Some(&"DECL") {
                k = 1;
            }
            while matches!(words.get(k), Some(&"GLOBAL") | Some(&"CONST")) {
                k += 1;
            }
            let ty = words.get(k).copied().unwrap_or("");
            if k == 0 && matches!(ty, "LOAD_DATA" | "TOOL_DATA" | "BASE_DATA") {
                self.data_line(ty, &toks, code);
                continue;
            }
            if let (
                Some((Tok::Word(name), _)),
                Some((Tok::Punct('='), _)),
                Some((Tok::Agg(a), _)),
            ) = (toks.get(k + 1), toks.get(k + 2), toks.get(k + 3))
            {
                self.named_aggregate(fi, &line, ty, name, a, code);
                continue;
            }
            let typed = POSE_TYPES.contains(&ty) || AXIS_TYPES.contains(&ty);
            if typed && (k > 0 || words.get(1).is_some_and(|w| !w.is_empty())) {
                self.declared_without_value(ty, &toks[k + 1..]);
            } else if src && k == 0 {
                self.assignment(fi, &line, &toks);
            }
        }
        Ok(())
    }

    /// `LOAD_DATA[n]={M …, CM {…}, J {…}}`, `TOOL_DATA[n]={…}`, `BASE_DATA[n]={…}`.
    fn data_line(&mut self, ty: &str, toks: &[(Tok, Range<usize>)], code: &str) {
        let (Some(n), Some((Tok::Punct('='), _)), Some((Tok::Agg(a), _))) =
            (self.number_ref(toks, 1), toks.get(4), toks.get(5))
        else {
            return;
        };
        if ty == "LOAD_DATA" {
            if let Some(l) = load_of(a, code) {
                self.loads.insert(n, l);
            }
        } else if let Some(p) = frame_of(a, code, 0) {
            let map = if ty == "TOOL_DATA" {
                &mut self.tools
            } else {
                &mut self.bases
            };
            map.insert(n, p);
        }
    }

    /// `DECL ty NAME={…}`: an `FDAT`, a Cartesian point, a point with axis values.
    fn named_aggregate(
        &mut self,
        fi: usize,
        line: &Line,
        ty: &str,
        name: &str,
        a: &aggregate::Agg,
        code: &str,
    ) {
        if ty == "FDAT" {
            let get = |key: &str| {
                a.items
                    .iter()
                    .find(|(k, _)| k == key)
                    .and_then(|(_, r)| integer(&code[r.clone()]))
            };
            let external = a
                .items
                .iter()
                .find(|(k, _)| k == "IPO_FRAME")
                .map(|(_, r)| code[r.clone()].trim().eq_ignore_ascii_case("#TCP"));
            self.fdat.insert(
                name.to_string(),
                Fdat {
                    tool: get("TOOL_NO"),
                    base: get("BASE_NO"),
                    external,
                },
            );
            return;
        }
        if AXIS_TYPES.contains(&ty) {
            self.axis_names.insert(name.to_string());
            return;
        }
        if !POSE_TYPES.contains(&ty) {
            return;
        }
        let a = shift(a, line.start);
        let kind = classify(&a, self.files[fi].text.as_str(), 0);
        match site_of(fi, line, name, kind, &Context::unset(), None) {
            Some(site) => {
                self.by_name
                    .entry(name.to_string())
                    .or_insert(self.declared.len());
                self.declared.push(Declared {
                    site,
                    uses: Vec::new(),
                    at: None,
                });
            }
            None => {
                self.runtime
                    .entry(name.to_string())
                    .or_insert(format!("{name} has no Cartesian value in the files"));
            }
        }
    }

    /// `DECL E6POS XP1, XP2[10]` (no value): set at run time; the same with
    /// `E6AXIS`/`AXIS`: axis values.
    fn declared_without_value(&mut self, ty: &str, rest: &[(Tok, Range<usize>)]) {
        let mut depth = 0i32;
        for (i, (t, _)) in rest.iter().enumerate() {
            match t {
                Tok::Punct('[') => depth += 1,
                Tok::Punct(']') => depth -= 1,
                Tok::Word(w) if depth == 0 => {
                    let array = matches!(rest.get(i + 1), Some((Tok::Punct('['), _)));
                    if AXIS_TYPES.contains(&ty) {
                        self.axis_names.insert(w.clone());
                    } else {
                        let why = if array {
                            format!("{w} is an array whose elements are set at run time")
                        } else {
                            format!("{w} is declared without a value: it is set at run time")
                        };
                        self.runtime.entry(w.clone()).or_insert(why);
                    }
                }
                _ => {}
            }
        }
    }

    /// `NAME = …`, `NAME.X = …`, `NAME[i] = …` in a `.src`: NAME is set at run time.
    fn assignment(&mut self, fi: usize, line: &Line, toks: &[(Tok, Range<usize>)]) {
        let Some((Tok::Word(name), _)) = toks.first() else {
            return;
        };
        if name.starts_with('$') {
            return;
        }
        let mut k = 1;
        let mut depth = 0i32;
        while let Some((t, _)) = toks.get(k) {
            match t {
                Tok::Punct('[') => depth += 1,
                Tok::Punct(']') => depth -= 1,
                Tok::Punct('.') | Tok::Word(_) if depth == 0 => {}
                Tok::Punct('=') if depth == 0 => {
                    if !matches!(toks.get(k + 1), Some((Tok::Punct('='), _))) {
                        self.assigned.entry(name.clone()).or_insert((fi, line.no));
                    }
                    return;
                }
                _ if depth > 0 => {}
                _ => return,
            }
            k += 1;
        }
    }

    /// Motions and frame selections (second pass, `.src` files in order).
    fn statements(&mut self, fi: usize) -> Result<(), ParseError> {
        let file = &self.files[fi];
        let mut ctx = Context::unset();
        for line in lines(&file.text) {
            let code = code_of(line.text).map_err(|(at, m)| err(file, &line, at, m))?;
            let toks = tokens(code).map_err(|(at, m)| err(file, &line, at, m))?;
            let first = match toks.first() {
                Some((Tok::Word(w), _)) => w.as_str(),
                _ => "",
            };
            let is_decl = first == "DECL" || POSE_TYPES.contains(&first) || first == "FDAT";
            if is_decl || matches!(first, "TOOL_DATA" | "BASE_DATA" | "LOAD_DATA") {
                continue; // handled by `declarations`
            }
            if self.context_statement(&toks, code, &mut ctx) {
                continue;
            }
            if MOTIONS.contains(&first) || RELATIVE.contains(&first) {
                self.motion(fi, &line, &toks, code, &ctx);
            }
        }
        Ok(())
    }

    /// The positions of a motion statement: one, or two for a circular
    /// motion (via point, end point), each up to a `,` or a clause.
    fn motion(
        &mut self,
        fi: usize,
        line: &Line,
        toks: &[(Tok, Range<usize>)],
        code: &str,
        ctx: &Context,
    ) {
        let Some((Tok::Word(instr), _)) = toks.first() else {
            return;
        };
        let circular = instr.contains("CIRC");
        let mut at = 1;
        for _ in 0..if circular { 2 } else { 1 } {
            at = at.min(toks.len());
            let mut end = at;
            let mut depth = 0i32;
            while let Some((t, _)) = toks.get(end) {
                match t {
                    Tok::Punct('(' | '[') => depth += 1,
                    Tok::Punct(')' | ']') => depth -= 1,
                    Tok::Punct(',') if depth == 0 => break,
                    Tok::Word(w) if depth == 0 && end > at && CLAUSES.contains(&w.as_str()) => {
                        break
                    }
                    _ => {}
                }
                end += 1;
            }
            let (name, target) = self.position(fi, line, &toks[at..end], code, ctx, instr);
            self.motions.push(Motion {
                file: fi,
                line: line.no,
                instruction: code[toks[0].1.clone()].to_string(),
                name,
                target,
                mark_at: line.end..line.end,
            });
            at = end + 1;
        }
    }

    /// What one position of a motion is, and its name as written.
    fn position(
        &mut self,
        fi: usize,
        line: &Line,
        expr: &[(Tok, Range<usize>)],
        code: &str,
        ctx: &Context,
        instr: &str,
    ) -> (String, MotionTarget) {
        let text = match (expr.first(), expr.last()) {
            (Some(a), Some(b)) => code[a.1.start..b.1.end].to_string(),
            _ => String::new(),
        };
        let name = match expr {
            [(Tok::Agg(_), _)] => "inline".to_string(),
            _ => text.clone(),
        };
        if RELATIVE.contains(&instr) {
            // `PTP_REL {A1 45}` moves axes: a joint motion.
            if let [(Tok::Agg(a), _)] = expr {
                let kind = classify(&shift(a, line.start), &self.files[fi].text, 0);
                if matches!(kind, Kind::Other) {
                    return (name, MotionTarget::Joints { note: None });
                }
            }
            let why = format!("relative motion: {instr} moves from where the robot is");
            return (name, MotionTarget::RunTime(why));
        }
        let target = match expr {
            [] => MotionTarget::RunTime("the motion gives no position".into()),
            [(Tok::Agg(a), _)] => {
                let kind = classify(&shift(a, line.start), &self.files[fi].text, 0);
                match site_of(fi, line, "inline", kind, ctx, None) {
                    Some(site) => {
                        self.order.push(Ok(site));
                        MotionTarget::Site(self.order.len() - 1)
                    }
                    None => MotionTarget::Joints { note: None },
                }
            }
            [(Tok::Word(w), _)] => self.named(w, line.no, ctx),
            _ => MotionTarget::RunTime(format!("`{text}` is computed at run time")),
        };
        (name, target)
    }

    /// What a motion to the point named `name` (upper case) goes to.
    fn named(&mut self, name: &str, line: usize, ctx: &Context) -> MotionTarget {
        if name.starts_with('$') {
            return MotionTarget::RunTime(format!("{name} is a system variable, set at run time"));
        }
        if let Some(&i) = self.by_name.get(name) {
            let d = &mut self.declared[i];
            let at = *d.at.get_or_insert(self.order.len());
            if at == self.order.len() {
                self.order.push(Err(i));
            }
            d.uses.push((line, ctx.clone()));
            return MotionTarget::Site(at);
        }
        if self.axis_names.contains(name) {
            return MotionTarget::Joints { note: None };
        }
        if let Some(why) = self.runtime.get(name) {
            return MotionTarget::RunTime(why.clone());
        }
        if let Some((fi, l)) = self.assigned.get(name) {
            return MotionTarget::RunTime(format!(
                "{name} is assigned at run time ({} line {l})",
                self.files[*fi].name
            ));
        }
        let home = name == "XHOME"
            || name
                .strip_prefix("XHOME")
                .is_some_and(|n| matches!(n, "1" | "2" | "3" | "4" | "5"));
        if home {
            return MotionTarget::Joints {
                note: Some(format!(
                    "{name} is not declared in the files: KUKA's home position, axis values in $config.dat"
                )),
            };
        }
        MotionTarget::Undeclared
    }

    /// A statement that sets the motion context (`$TOOL`, `$BASE`,
    /// `$IPO_MODE`, `$LOAD`, `BAS(#TOOL|#BASE, n)`, `FDAT_ACT`) updates `ctx`;
    /// true when `toks` was one.
    fn context_statement(
        &self,
        toks: &[(Tok, Range<usize>)],
        code: &str,
        ctx: &mut Context,
    ) -> bool {
        let word = |i: usize| match toks.get(i) {
            Some((Tok::Word(w), _)) => w.as_str(),
            _ => "",
        };
        let first = word(0);
        // $TOOL = … / $BASE = …
        if (first == "$TOOL" || first == "$BASE")
            && matches!(toks.get(1), Some((Tok::Punct('='), _)))
        {
            let tool = first == "$TOOL";
            let spec = match toks.get(2) {
                Some((Tok::Word(w), _)) if w == "$NULLFRAME" => FrameSpec::Ref(CellRef::Number(0)),
                Some((Tok::Word(w), _)) if w == "TOOL_DATA" || w == "BASE_DATA" => {
                    match self.number_ref(toks, 3) {
                        Some(n) => self.frame_spec(n, w == "TOOL_DATA"),
                        None => FrameSpec::Unset,
                    }
                }
                Some((Tok::Agg(a), _)) => {
                    frame_of(a, code, 0).map_or(FrameSpec::Unset, FrameSpec::Inline)
                }
                _ => FrameSpec::Unset,
            };
            if tool {
                ctx.tool = spec;
            } else {
                ctx.base = spec;
            }
            return true;
        }
        // $IPO_MODE = #TCP / #BASE
        if first == "$IPO_MODE" && matches!(toks.get(1), Some((Tok::Punct('='), _))) {
            match word(2) {
                "#TCP" => ctx.external = true,
                "#BASE" => ctx.external = false,
                _ => {}
            }
            return true;
        }
        // $LOAD = {…} / $LOAD = LOAD_DATA[n]
        if first == "$LOAD" && matches!(toks.get(1), Some((Tok::Punct('='), _))) {
            ctx.load = match toks.get(2) {
                Some((Tok::Agg(a), _)) => load_of(a, code),
                Some((Tok::Word(w), _)) if w == "LOAD_DATA" => self
                    .number_ref(toks, 3)
                    .and_then(|n| self.loads.get(&n).copied()),
                _ => None,
            };
            return true;
        }
        // BAS(#TOOL, n) / BAS(#BASE, n)
        if first == "BAS" && matches!(word(2), "#TOOL" | "#BASE") {
            if let (Some((Tok::Punct(','), _)), Some((Tok::Number(n), _))) =
                (toks.get(3), toks.get(4))
            {
                if n.fract() == 0.0 && *n >= 0.0 && *n < 1e9 {
                    let tool = word(2) == "#TOOL";
                    let spec = self.frame_spec(*n as u32, tool);
                    if tool {
                        if let Some(l) = self.loads.get(&(*n as u32)) {
                            ctx.load = Some(*l);
                        }
                        ctx.tool = spec;
                    } else {
                        ctx.base = spec;
                    }
                }
            }
            return true;
        }
        // FDAT_ACT = FP1
        if first == "FDAT_ACT" && matches!(toks.get(1), Some((Tok::Punct('='), _))) {
            if let Some(fdat) = self.fdat.get(word(2)).copied() {
                if let Some(t) = fdat.tool {
                    ctx.tool = self.frame_spec(t, true);
                }
                if let Some(b) = fdat.base {
                    ctx.base = self.frame_spec(b, false);
                }
                if let Some(e) = fdat.external {
                    ctx.external = e;
                }
            }
            return true;
        }
        false
    }

    fn finish(mut self) -> Targets {
        for (i, d) in self.declared.iter_mut().enumerate() {
            if d.at.is_none() {
                d.at = Some(self.order.len());
                self.order.push(Err(i));
            }
        }
        let declared = std::mem::take(&mut self.declared);
        let order = std::mem::take(&mut self.order);
        let sites = order
            .into_iter()
            .map(|s| match s {
                Ok(site) => site,
                Err(i) => self.declared_site(&declared[i]),
            })
            .collect();
        Targets {
            sites,
            motions: self.motions,
            joints: self.joints,
        }
    }

    /// A declared point with the context of the motions that use it.
    fn declared_site(&self, d: &Declared) -> Site {
        let mut site = d.site.clone();
        if let Some((fi, l)) = self.assigned.get(&site.name.to_ascii_uppercase()) {
            site.skip.get_or_insert(format!(
                "{} is assigned at run time ({} line {l})",
                site.name, self.files[*fi].name
            ));
        }
        match d.uses.first() {
            None => {
                site.skip
                    .get_or_insert("no motion of the program uses it".into());
            }
            Some((_, ctx)) => {
                (site.tool, site.work_object) = ctx.roles();
                site.load = ctx.load;
                site.stationary_tool = ctx.external;
                let other = d.uses.iter().find(|(_, c)| {
                    c.tool != ctx.tool || c.base != ctx.base || c.external != ctx.external
                });
                if let Some((line, _)) = other {
                    site.skip.get_or_insert(format!(
                        "used with different tools, bases or interpolation modes (lines {} and {line})",
                        d.uses[0].0
                    ));
                }
            }
        }
        site
    }
}

fn has_ext(name: &str, ext: &str) -> bool {
    name.rsplit('.')
        .next()
        .is_some_and(|e| e.eq_ignore_ascii_case(ext))
}

/// Parses a KRL program (`.src` and `.dat` files; other files are read as data lists).
pub(super) fn parse(files: &[ProgramFile]) -> Result<Targets, ParseError> {
    let mut p = Parser {
        files,
        declared: Vec::new(),
        by_name: HashMap::new(),
        axis_names: HashSet::new(),
        runtime: HashMap::new(),
        assigned: HashMap::new(),
        fdat: HashMap::new(),
        tools: HashMap::new(),
        loads: HashMap::new(),
        bases: HashMap::new(),
        order: Vec::new(),
        motions: Vec::new(),
        joints: Vec::new(),
    };
    for fi in 0..files.len() {
        p.declarations(fi)?;
    }
    for (fi, f) in files.iter().enumerate() {
        if has_ext(&f.name, "src") {
            p.statements(fi)?;
        }
    }
    Ok(p.finish())
}

#[cfg(test)]
mod tests;
