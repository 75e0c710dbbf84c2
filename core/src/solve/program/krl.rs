//! KUKA KRL: `.src` modules and their `.dat` data lists.
//!
//! Targets: `E6POS`, `POS` and `FRAME` aggregates `{X …, Y …, Z …, A …, B …,
//! C …, S …, T …, E1 …}`, declared (`DECL E6POS XP1={…}`, in any file) and
//! used by name in `PTP`/`LIN`/`CIRC` (and `SPTP`/`SLIN`/`SCIRC`), or inline
//! in a motion or an assignment. Joint aggregates (`A1 … A6`) are not targets.
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

use super::{Flags, FrameSpec, JointTarget, ParseError, ProgramFile, Site, Targets};
use crate::model::orientation::{rotation_from, OrientationConvention};
use crate::model::Pose;
use crate::solve::cell::{CellRef, Load};
use nalgebra::Vector3;
use std::collections::HashMap;
use std::ops::Range;

const MOTIONS: [&str; 6] = ["PTP", "LIN", "CIRC", "SPTP", "SLIN", "SCIRC"];
const RELATIVE: [&str; 6] = [
    "PTP_REL",
    "LIN_REL",
    "CIRC_REL",
    "SPTP_REL",
    "SLIN_REL",
    "SCIRC_REL",
];
const POSE_TYPES: [&str; 3] = ["E6POS", "POS", "FRAME"];

/// A token of a line's code (comments removed); ranges are file byte offsets.
#[derive(Debug, Clone, PartialEq)]
enum Tok {
    /// Identifier, upper-cased (`$TOOL`, `#BASE`, `XP1`).
    Word(String),
    Number(f64),
    Text,
    Punct(char),
    Agg(Agg),
}

/// An aggregate `{KEY value, …}`: upper-cased keys and value ranges.
#[derive(Debug, Clone, PartialEq)]
struct Agg {
    items: Vec<(String, Range<usize>)>,
}

type Fail = (usize, String);

struct Line<'a> {
    text: &'a str,
    /// Byte offset of the line in the file.
    start: usize,
    /// Byte offset of the end of the line's content (before `\r\n`).
    end: usize,
    /// 1-based.
    no: usize,
}

fn lines(text: &str) -> Vec<Line<'_>> {
    let mut out = Vec::new();
    let mut start = 0;
    for (i, raw) in text.split('\n').enumerate() {
        let content = raw.strip_suffix('\r').unwrap_or(raw);
        out.push(Line {
            text: content,
            start,
            end: start + content.len(),
            no: i + 1,
        });
        start += raw.len() + 1;
    }
    out
}

/// Code part of a line: up to a `;` outside quotes.
fn code_of(line: &str) -> Result<&str, Fail> {
    let mut quote: Option<(char, usize)> = None;
    for (i, c) in line.char_indices() {
        match (quote, c) {
            (None, ';') => return Ok(&line[..i]),
            (None, '"' | '\'') => quote = Some((c, i)),
            (Some((q, _)), c) if c == q => quote = None,
            _ => {}
        }
    }
    match quote {
        Some((_, i)) => Err((i, "unterminated string".into())),
        None => Ok(line),
    }
}

fn is_word_start(c: char) -> bool {
    c.is_ascii_alphabetic() || c == '_' || c == '$' || c == '#'
}

fn is_word(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_' || c == '$'
}

/// Tokenises a line's code (offsets relative to the line).
fn tokens(code: &str) -> Result<Vec<(Tok, Range<usize>)>, Fail> {
    let b = code.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let c = code[i..].chars().next().unwrap_or(' ');
        let start = i;
        if c.is_whitespace() {
            i += c.len_utf8();
        } else if is_word_start(c) {
            i += 1;
            while i < b.len() && is_word(b[i] as char) {
                i += 1;
            }
            out.push((Tok::Word(code[start..i].to_ascii_uppercase()), start..i));
        } else if c.is_ascii_digit() || (c == '.' && b.get(i + 1).is_some_and(u8::is_ascii_digit)) {
            i = number_end(b, i);
            let v = code[start..i]
                .parse()
                .map_err(|_| (start, "bad number".to_string()))?;
            out.push((Tok::Number(v), start..i));
        } else if c == '"' || c == '\'' {
            let close = code[i + 1..]
                .find(c)
                .ok_or((i, "unterminated string".to_string()))?;
            i += close + 2;
            out.push((Tok::Text, start..i));
        } else if c == '{' {
            let (agg, end) = aggregate(code, i)?;
            i = end;
            out.push((Tok::Agg(agg), start..i));
        } else {
            i += c.len_utf8();
            out.push((Tok::Punct(c), start..i));
        }
    }
    Ok(out)
}

fn number_end(b: &[u8], mut i: usize) -> usize {
    while i < b.len() && (b[i].is_ascii_digit() || b[i] == b'.') {
        i += 1;
    }
    if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
        let mut j = i + 1;
        if j < b.len() && (b[j] == b'+' || b[j] == b'-') {
            j += 1;
        }
        if j < b.len() && b[j].is_ascii_digit() {
            i = j;
            while i < b.len() && b[i].is_ascii_digit() {
                i += 1;
            }
        }
    }
    i
}

/// Parses the aggregate opening at `open`; returns it and the offset after `}`.
fn aggregate(code: &str, open: usize) -> Result<(Agg, usize), Fail> {
    let b = code.as_bytes();
    let skip_ws = |mut i: usize| {
        while i < b.len() && (b[i] as char).is_ascii_whitespace() {
            i += 1;
        }
        i
    };
    let word_end = |mut i: usize| {
        while i < b.len() && is_word(b[i] as char) {
            i += 1;
        }
        i
    };
    let mut items = Vec::new();
    let mut i = skip_ws(open + 1);
    if b.get(i) == Some(&b'}') {
        return Ok((Agg { items }, i + 1));
    }
    // A typed aggregate `{E6POS: X 1, …}`.
    let w = word_end(i);
    if w > i && b.get(skip_ws(w)) == Some(&b':') {
        i = skip_ws(w) + 1;
    }
    loop {
        i = skip_ws(i);
        let key_start = i;
        let key_end = word_end(i);
        if key_end == key_start {
            return Err((i, "expected a component name in the aggregate".into()));
        }
        let key = code[key_start..key_end].to_ascii_uppercase();
        i = key_end;
        if code[i..].starts_with("[]") {
            i += 2;
        }
        let mut depth = 0usize;
        let value_start = i;
        let mut quote: Option<u8> = None;
        loop {
            let Some(&c) = b.get(i) else {
                return Err((open, "aggregate not closed on its line".into()));
            };
            match (quote, c) {
                (Some(q), c) if c == q => quote = None,
                (Some(_), _) => {}
                (None, b'"' | b'\'') => quote = Some(c),
                (None, b'{') => depth += 1,
                (None, b'}') if depth > 0 => depth -= 1,
                (None, b',' | b'}') if depth == 0 => break,
                _ => {}
            }
            i += 1;
        }
        let raw = &code[value_start..i];
        let lead = raw.len() - raw.trim_start().len();
        let value = value_start + lead..value_start + raw.trim_end().len();
        if value.is_empty() {
            return Err((key_start, format!("component {key} has no value")));
        }
        items.push((key, value));
        if b[i] == b'}' {
            return Ok((Agg { items }, i + 1));
        }
        i += 1;
    }
}

/// A real literal (digits, sign, point, exponent; no `inf`/`nan`).
fn real(s: &str) -> Option<f64> {
    if s.is_empty() || !s.chars().all(|c| c.is_ascii_digit() || "+-.eE".contains(c)) {
        return None;
    }
    s.parse().ok()
}

/// An integer literal: decimal, `'B0101'` or `'H1F'`.
fn integer(s: &str) -> Option<u32> {
    let upper = s.to_ascii_uppercase();
    if let Some(bits) = upper.strip_prefix("'B").and_then(|r| r.strip_suffix('\'')) {
        return u32::from_str_radix(bits, 2).ok();
    }
    if let Some(hex) = upper.strip_prefix("'H").and_then(|r| r.strip_suffix('\'')) {
        return u32::from_str_radix(hex, 16).ok();
    }
    s.parse().ok()
}

const POSE_KEYS: [&str; 6] = ["X", "Y", "Z", "A", "B", "C"];

/// What an aggregate is.
enum Kind {
    /// A Cartesian target: its pose (or why not), flags and value ranges.
    Cartesian {
        pose: Result<Pose, String>,
        flags: Flags,
        slots: Vec<Range<usize>>,
    },
    Other,
}

fn classify(agg: &Agg, text: &str, offset: usize) -> Kind {
    let get = |k: &str| agg.items.iter().find(|(key, _)| key == k);
    let joint = agg
        .items
        .iter()
        .any(|(k, _)| matches!(k.as_str(), "A1" | "A2" | "A3" | "A4" | "A5" | "A6"));
    if joint || !POSE_KEYS.iter().any(|k| get(k).is_some()) {
        return Kind::Other;
    }
    let value = |r: &Range<usize>| &text[r.start - offset..r.end - offset];
    let mut v = [0.0; 6];
    let mut slots = Vec::with_capacity(6);
    let mut missing = Vec::new();
    let mut pose_err = None;
    for (i, k) in POSE_KEYS.iter().enumerate() {
        match get(k) {
            Some((_, r)) => {
                slots.push(r.clone());
                match real(value(r)) {
                    Some(x) => v[i] = x,
                    None => pose_err = Some(format!("{k} is not a number: `{}`", value(r))),
                }
            }
            None => missing.push(*k),
        }
    }
    let flag = |k: &str| get(k).and_then(|(_, r)| integer(value(r)));
    let flags = if get("S").is_some() || get("T").is_some() {
        Flags::Kuka {
            s: flag("S"),
            t: flag("T"),
        }
    } else {
        Flags::Nearest
    };
    let pose = if !missing.is_empty() {
        Err(format!("incomplete pose: no {}", missing.join(", ")))
    } else if let Some(e) = pose_err {
        Err(e)
    } else {
        rotation_from(OrientationConvention::KukaAbc, &v[3..])
            .map(|r| Pose::new(r, Vector3::new(v[0], v[1], v[2]) * 1e-3))
            .map_err(|e| e.to_string())
    };
    Kind::Cartesian { pose, flags, slots }
}

/// The axis values `A1..A6` of a joint aggregate [deg] (ranges relative to `code`).
fn joint_values(agg: &Agg, code: &str) -> Option<Vec<f64>> {
    ["A1", "A2", "A3", "A4", "A5", "A6"]
        .iter()
        .map(|k| {
            let (_, r) = agg.items.iter().find(|(key, _)| key == k)?;
            real(code.get(r.clone())?)
        })
        .collect()
}

/// A frame aggregate `{X, Y, Z, A, B, C}` as a pose [m].
/// A load aggregate `{M m, CM {X x, Y y, Z z, A …}, J {X jx, Y jy, Z jz}}`
/// (kg, mm in the flange frame, kg·m²); `None` when M is missing or not
/// positive (KUKA's −1: no load data).
fn load_of(agg: &Agg, code: &str) -> Option<Load> {
    let get = |a: &Agg, key: &str| {
        a.items
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, r)| r.clone())
    };
    let xyz = |r: Range<usize>| -> Option<[f64; 3]> {
        let (inner, _) = aggregate(code, r.start).ok()?;
        let v = |k: &str| get(&inner, k).and_then(|r| real(&code[r]));
        Some([
            v("X").unwrap_or(0.0),
            v("Y").unwrap_or(0.0),
            v("Z").unwrap_or(0.0),
        ])
    };
    let mass = real(&code[get(agg, "M")?])?;
    if !(mass > 0.0 && mass.is_finite()) {
        return None;
    }
    let com = get(agg, "CM").and_then(xyz).unwrap_or([0.0; 3]);
    let inertia_kgm2 = get(agg, "J")
        .and_then(xyz)
        .filter(|j| j.iter().any(|v| *v != 0.0));
    Some(Load {
        mass_kg: mass,
        com: Vector3::from(com) * 1e-3,
        inertia_kgm2,
    })
}

fn frame_of(agg: &Agg, text: &str, offset: usize) -> Option<Pose> {
    match classify(agg, text, offset) {
        Kind::Cartesian { pose: Ok(p), .. } => Some(p),
        _ => None,
    }
}

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

/// A declared point and the contexts of the motions that use it.
struct Declared {
    site: Site,
    uses: Vec<(usize, Context)>,
}

struct Parser<'a> {
    files: &'a [ProgramFile],
    declared: Vec<Declared>,
    by_name: HashMap<String, usize>,
    fdat: HashMap<String, Fdat>,
    tools: HashMap<u32, Pose>,
    bases: HashMap<u32, Pose>,
    loads: HashMap<u32, Load>,
    /// Sites in execution order; `Err(i)` is declared point `i` at its first use.
    order: Vec<Result<Site, usize>>,
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
    let Kind::Cartesian { pose, flags, slots } = kind else {
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

    /// Declarations and data definitions (first pass, every file).
    fn declarations(&mut self, fi: usize) -> Result<(), ParseError> {
        let file = &self.files[fi];
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
            // LOAD_DATA[n]={M …, CM {…}, J {…}}
            if ty == "LOAD_DATA" && k == 0 {
                if let (Some(n), Some((Tok::Punct('='), _)), Some((Tok::Agg(a), _))) =
                    (self.number_ref(&toks, 1), toks.get(4), toks.get(5))
                {
                    if let Some(l) = load_of(a, code) {
                        self.loads.insert(n, l);
                    }
                }
                continue;
            }
            // TOOL_DATA[n]={…} / BASE_DATA[n]={…}
            if (ty == "TOOL_DATA" || ty == "BASE_DATA") && k == 0 {
                if let (Some(n), Some((Tok::Punct('='), _)), Some((Tok::Agg(a), _))) =
                    (self.number_ref(&toks, 1), toks.get(4), toks.get(5))
                {
                    if let Some(p) = frame_of(a, code, 0) {
                        let map = if ty == "TOOL_DATA" {
                            &mut self.tools
                        } else {
                            &mut self.bases
                        };
                        map.insert(n, p);
                    }
                }
                continue;
            }
            let (Some((Tok::Word(name), _)), Some((Tok::Punct('='), _)), Some((Tok::Agg(a), _))) =
                (toks.get(k + 1), toks.get(k + 2), toks.get(k + 3))
            else {
                continue;
            };
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
                    name.clone(),
                    Fdat {
                        tool: get("TOOL_NO"),
                        base: get("BASE_NO"),
                        external,
                    },
                );
                continue;
            }
            if !POSE_TYPES.contains(&ty) {
                continue;
            }
            let a = shift(a, line.start);
            let unset = Context::unset();
            let kind = classify(&a, file.text.as_str(), 0);
            if let Some(site) = site_of(fi, &line, name, kind, &unset, None) {
                self.by_name
                    .entry(name.clone())
                    .or_insert(self.declared.len());
                self.declared.push(Declared {
                    site,
                    uses: Vec::new(),
                });
            }
        }
        Ok(())
    }

    /// Motions and frame selections (second pass, `.src` files in order).
    fn statements(&mut self, fi: usize) -> Result<(), ParseError> {
        let file = &self.files[fi];
        let mut ctx = Context::unset();
        for line in lines(&file.text) {
            let code = code_of(line.text).map_err(|(at, m)| err(file, &line, at, m))?;
            let toks = tokens(code).map_err(|(at, m)| err(file, &line, at, m))?;
            let word = |i: usize| match toks.get(i) {
                Some((Tok::Word(w), _)) => w.as_str(),
                _ => "",
            };
            let first = word(0);
            let is_decl = first == "DECL" || POSE_TYPES.contains(&first) || first == "FDAT";
            if is_decl || matches!(first, "TOOL_DATA" | "BASE_DATA" | "LOAD_DATA") {
                continue; // handled by `declarations`
            }
            if self.context_statement(&toks, code, &mut ctx) {
                continue;
            }
            let relative = RELATIVE.contains(&first);
            let motion = MOTIONS.contains(&first);
            if motion {
                // Targets by name: PTP XP1 / CIRC XAUX, XEND
                let mut i = 1;
                loop {
                    if let Some((Tok::Word(w), _)) = toks.get(i) {
                        if !matches!(toks.get(i + 1), Some((Tok::Punct('[' | '.'), _))) {
                            self.use_point(w, line.no, &ctx);
                        }
                    }
                    if first.ends_with("CIRC")
                        && i == 1
                        && matches!(toks.get(2), Some((Tok::Punct(','), _)))
                    {
                        i = 3;
                        continue;
                    }
                    break;
                }
            }
            for (t, _) in &toks {
                let Tok::Agg(a) = t else { continue };
                let a = shift(a, line.start);
                let kind = classify(&a, &file.text, 0);
                let skip = relative.then(|| "relative motion".to_string());
                if let Some(site) = site_of(fi, &line, "inline", kind, &ctx, skip) {
                    self.order.push(Ok(site));
                }
            }
        }
        Ok(())
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

    fn use_point(&mut self, name: &str, line: usize, ctx: &Context) {
        let Some(&i) = self.by_name.get(name) else {
            return;
        };
        if self.declared[i].uses.is_empty() {
            self.order.push(Err(i));
        }
        self.declared[i].uses.push((line, ctx.clone()));
    }

    fn finish(mut self) -> Targets {
        for (i, d) in self.declared.iter().enumerate() {
            if d.uses.is_empty() {
                self.order.push(Err(i));
            }
        }
        let declared = std::mem::take(&mut self.declared);
        let order = std::mem::take(&mut self.order);
        let sites = order
            .into_iter()
            .map(|s| match s {
                Ok(site) => site,
                Err(i) => {
                    let d = &declared[i];
                    let mut site = d.site.clone();
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
            })
            .collect();
        Targets {
            sites,
            joints: self.joints,
        }
    }
}

/// `agg` with its ranges moved by `by` bytes.
fn shift(agg: &Agg, by: usize) -> Agg {
    Agg {
        items: agg
            .items
            .iter()
            .map(|(k, r)| (k.clone(), r.start + by..r.end + by))
            .collect(),
    }
}

fn has_ext(name: &str, ext: &str) -> bool {
    name.rsplit('.')
        .next()
        .is_some_and(|e| e.eq_ignore_ascii_case(ext))
}

/// Parses a KRL program (`.src` and `.dat` files; other files are read as data lists).
pub fn parse(files: &[ProgramFile]) -> Result<Targets, ParseError> {
    let mut p = Parser {
        files,
        declared: Vec::new(),
        by_name: HashMap::new(),
        fdat: HashMap::new(),
        tools: HashMap::new(),
        loads: HashMap::new(),
        bases: HashMap::new(),
        order: Vec::new(),
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
