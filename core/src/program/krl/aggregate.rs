//! KRL's lexical level: a line's code (comments removed), its tokens with
//! byte ranges, aggregates `{KEY value, …}`, literals, and what an aggregate
//! is (a Cartesian target, axis values, a frame, a load). Units: mm and
//! degrees in the text, SI (m) in the poses, `R = Rz(A)·Ry(B)·Rx(C)`.

use super::super::{AxisValue, Flags};
use crate::model::orientation::{rotation_from, OrientationConvention};
use crate::model::Pose;
use crate::solve::cell::Load;
use nalgebra::Vector3;
use std::ops::Range;

/// A token of a line's code (comments removed); ranges are file byte offsets.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Tok {
    /// Identifier, upper-cased (`$TOOL`, `#BASE`, `XP1`).
    Word(String),
    Number(f64),
    Text,
    Punct(char),
    Agg(Agg),
}

/// An aggregate `{KEY value, …}`: upper-cased keys and value ranges.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Agg {
    pub(super) items: Vec<(String, Range<usize>)>,
}

pub(super) type Fail = (usize, String);

pub(super) struct Line<'a> {
    pub(super) text: &'a str,
    /// Byte offset of the line in the file.
    pub(super) start: usize,
    /// Byte offset of the end of the line's content (before `\r\n`).
    pub(super) end: usize,
    /// 1-based.
    pub(super) no: usize,
}

pub(super) fn lines(text: &str) -> Vec<Line<'_>> {
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
pub(super) fn code_of(line: &str) -> Result<&str, Fail> {
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

pub(super) fn is_word_start(c: char) -> bool {
    c.is_ascii_alphabetic() || c == '_' || c == '$' || c == '#'
}

pub(super) fn is_word(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_' || c == '$'
}

/// Tokenises a line's code (offsets relative to the line).
pub(super) fn tokens(code: &str) -> Result<Vec<(Tok, Range<usize>)>, Fail> {
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

pub(super) fn number_end(b: &[u8], mut i: usize) -> usize {
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
pub(super) fn aggregate(code: &str, open: usize) -> Result<(Agg, usize), Fail> {
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
pub(super) fn real(s: &str) -> Option<f64> {
    if s.is_empty() || !s.chars().all(|c| c.is_ascii_digit() || "+-.eE".contains(c)) {
        return None;
    }
    s.parse().ok()
}

/// An integer literal: decimal, `'B0101'` or `'H1F'`.
pub(super) fn integer(s: &str) -> Option<u32> {
    let upper = s.to_ascii_uppercase();
    if let Some(bits) = upper.strip_prefix("'B").and_then(|r| r.strip_suffix('\'')) {
        return u32::from_str_radix(bits, 2).ok();
    }
    if let Some(hex) = upper.strip_prefix("'H").and_then(|r| r.strip_suffix('\'')) {
        return u32::from_str_radix(hex, 16).ok();
    }
    s.parse().ok()
}

pub(super) const POSE_KEYS: [&str; 6] = ["X", "Y", "Z", "A", "B", "C"];

/// What an aggregate is.
pub(super) enum Kind {
    /// A Cartesian target: its pose (or why not), flags, value ranges, and
    /// its external axes' values (`E1..E6` as given).
    Cartesian {
        pose: Result<Pose, String>,
        flags: Flags,
        slots: Vec<Range<usize>>,
        axes: Vec<AxisValue>,
    },
    /// Anything else (axis values `A1..A6`, `E1..E6` alone, a load).
    Other,
}

pub(super) fn classify(agg: &Agg, text: &str, offset: usize) -> Kind {
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
    // E6POS carries the external axes E1..E6 (0 for an axis the robot does
    // not have); a value that is not a number is one computed at run time.
    let axes = ["E1", "E2", "E3", "E4", "E5", "E6"]
        .iter()
        .enumerate()
        .filter_map(|(i, k)| {
            let (_, r) = get(k)?;
            Some(AxisValue {
                group: 1,
                number: i + 1,
                name: (*k).to_string(),
                value: real(value(r)),
                text: value(r).to_string(),
                slot: Some(r.clone()),
            })
        })
        .collect();
    Kind::Cartesian {
        pose,
        flags,
        slots,
        axes,
    }
}

/// The axis values `A1..A6` of a joint aggregate [deg] (ranges relative to `code`).
pub(super) fn joint_values(agg: &Agg, code: &str) -> Option<Vec<f64>> {
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
pub(super) fn load_of(agg: &Agg, code: &str) -> Option<Load> {
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

pub(super) fn frame_of(agg: &Agg, text: &str, offset: usize) -> Option<Pose> {
    match classify(agg, text, offset) {
        Kind::Cartesian { pose: Ok(p), .. } => Some(p),
        _ => None,
    }
}

/// `agg` with its ranges moved by `by` bytes.
pub(super) fn shift(agg: &Agg, by: usize) -> Agg {
    Agg {
        items: agg
            .items
            .iter()
            .map(|(k, r)| (k.clone(), r.start + by..r.end + by))
            .collect(),
    }
}
