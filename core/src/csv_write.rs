//! CSV text as robocal writes it: the one place where every CSV writer
//! (predict and solve answers, measurement and ISO 9283 plans, measurement
//! files, model exports) turns numbers and texts into cells and comment lines.
//!
//! - A number robocal formats itself ([`Cell::num`], [`Cell::fixed`], …) is
//!   written as it is (`-20`, `1.5e-3`): a program or a spreadsheet reading
//!   the file gets a number. A value that is not finite is an empty cell.
//! - A text ([`Cell::text`]: an id, a name, a message, a header) is neutralised
//!   ([`neutralise`]) and quoted when it holds a `,`, a `"` or a line break
//!   (`"` doubled, RFC 4180).
//! - A `#` comment line ([`comment_line`]) has its control characters replaced
//!   by spaces and is neutralised like a text: a spreadsheet that opens the
//!   file splits the comment at its commas too.
//!
//! Neutralising: a spreadsheet runs a cell whose first character is `=`, `+`,
//! `-` or `@` (after blanks and quotes) as a formula, and it splits a line at
//! `,`, `;` or a tab (by locale). So every part of a text between those
//! separators that would start such a cell (in some split, the first part a
//! cell shows after blank parts, as `-0` in a `,` cell `\t-0\ta`) gets a
//! leading `'` (which spreadsheets show as text), unless that cell is a plain
//! decimal number (`-20`, `+1.5e3`). robocal's
//! readers drop that `'` again ([`read_text`]): `read_text(neutralise(t)) ==
//! t` for every text.

use std::borrow::Cow;
use std::fmt::Display;

/// The characters at which a spreadsheet may split a line into cells.
const SPLITS: [char; 3] = [',', ';', '\t'];
/// Where a cell may start: after a split or a line break (a reader that
/// does not honour quotes starts a row there).
const SEPARATORS: [char; 5] = [',', ';', '\t', '\n', '\r'];

/// Whether a part holds nothing a spreadsheet shows before a cell's first
/// character: only blanks, `'` and `"`.
fn blank(part: &str) -> bool {
    part.chars()
        .all(|c| c.is_whitespace() || c == '\'' || c == '"')
}

/// Whether a part would start a formula: its first character after blanks,
/// `'` and `"` is `=`, `+`, `-` or `@`.
fn formula_like(part: &str) -> bool {
    matches!(
        part.trim_start_matches(|c: char| c.is_whitespace() || c == '\'' || c == '"')
            .chars()
            .next(),
        Some('=' | '+' | '-' | '@')
    )
}

/// `-20`, `+1.5`, `.5`, `2e-3` (surrounding blanks allowed): what every
/// spreadsheet reads as a number, never as a formula.
fn plain_number(part: &str) -> bool {
    let s = part.trim();
    let s = s.strip_prefix(['+', '-']).unwrap_or(s);
    let (mantissa, exponent) = match s.find(['e', 'E']) {
        Some(i) => (&s[..i], Some(&s[i + 1..])),
        None => (s, None),
    };
    let digits = |t: &str| !t.is_empty() && t.bytes().all(|b| b.is_ascii_digit());
    let mantissa_ok = match mantissa.split_once('.') {
        Some((a, b)) => {
            (digits(a) || a.is_empty()) && (digits(b) || b.is_empty()) && a.len() + b.len() > 0
        }
        None => digits(mantissa),
    };
    let exponent_ok = exponent.is_none_or(|e| digits(e.strip_prefix(['+', '-']).unwrap_or(e)));
    mantissa_ok && exponent_ok
}

/// The parts of `text` between separators, each with the separator that
/// ends it (none for the last).
fn parts(text: &str) -> impl Iterator<Item = (&str, Option<char>)> {
    let mut rest = Some(text);
    std::iter::from_fn(move || {
        let s = rest?;
        match s.find(SEPARATORS) {
            Some(i) => {
                let sep = s[i..].chars().next().expect("a separator at i");
                rest = Some(&s[i + sep.len_utf8()..]);
                Some((&s[..i], Some(sep)))
            }
            None => {
                rest = None;
                Some((s, None))
            }
        }
    })
}

/// The text with a leading `'` on every part a spreadsheet would run as a
/// formula (module docs); anything else unchanged.
pub fn neutralise(text: &str) -> Cow<'_, str> {
    let parts: Vec<(&str, Option<char>)> = parts(text).collect();
    let marks = marks(&parts);
    if !marks.iter().any(|m| *m) {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 4);
    for ((p, sep), mark) in parts.iter().zip(&marks) {
        if *mark {
            out.push('\'');
        }
        out.push_str(p);
        if let Some(c) = sep {
            out.push(*c);
        }
    }
    Cow::Owned(out)
}

/// Which parts [`neutralise`] marks. In every split, each cell (from a line
/// start or the split's separator to the next one or a line break) is
/// looked at from its first character a spreadsheet shows: blank parts joined
/// by blank separators (a tab inside a `,` cell) are skipped, and the first
/// part that is not blank is marked when it starts a formula and the whole
/// cell is not a plain number. Every part starts a cell in some split (the
/// one of the separator before it), so every part that starts with `'` and a
/// formula is marked, which is what lets [`read_text`] drop exactly the marks.
fn marks(parts: &[(&str, Option<char>)]) -> Vec<bool> {
    let mut marks = vec![false; parts.len()];
    for split in SPLITS {
        let mut first = 0;
        while first < parts.len() {
            let last = (first..parts.len())
                .find(|&j| {
                    matches!(parts[j].1, None | Some('\n' | '\r')) || parts[j].1 == Some(split)
                })
                .unwrap_or(parts.len() - 1);
            let shown = (first..=last)
                .take_while(|&j| j == first || parts[j - 1].1.is_some_and(char::is_whitespace))
                .find(|&j| !blank(parts[j].0));
            if let Some(k) = shown {
                let mut cell = String::new();
                for (j, (p, sep)) in parts.iter().enumerate().take(last + 1).skip(first) {
                    cell.push_str(p);
                    if j < last {
                        cell.extend(*sep);
                    }
                }
                if formula_like(parts[k].0) && !plain_number(&cell) {
                    marks[k] = true;
                }
            }
            first = last + 1;
        }
    }
    marks
}

/// A part that [`neutralise`] marked: `'` followed by a formula-like part.
fn marked(part: &str) -> bool {
    part.strip_prefix('\'').is_some_and(formula_like)
}

/// A text field as robocal wrote it, with the marks of [`neutralise`]
/// dropped: every reader of a text column (ids, names, sessions) reads it
/// through this, so a text reads back as it was written.
pub fn read_text(field: &str) -> Cow<'_, str> {
    if !parts(field).any(|(p, _)| marked(p)) {
        return Cow::Borrowed(field);
    }
    let mut out = String::with_capacity(field.len());
    for (p, sep) in parts(field) {
        out.push_str(if marked(p) { &p[1..] } else { p });
        if let Some(c) = sep {
            out.push(c);
        }
    }
    Cow::Owned(out)
}

/// A text as a CSV cell: neutralised, and quoted when it holds a `,`, a `"`
/// or a line break.
pub fn text_cell(text: &str) -> Cow<'_, str> {
    let safe = neutralise(text);
    if safe.contains([',', '"', '\n', '\r']) {
        Cow::Owned(format!("\"{}\"", safe.replace('"', "\"\"")))
    } else {
        safe
    }
}

/// A `#` comment line (with its line break): control characters become
/// spaces (a line break would end the comment and start a row), and the
/// text is neutralised.
pub fn comment_line(text: &str) -> String {
    let flat: String = text
        .chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect();
    format!("# {}\n", neutralise(&flat))
}

/// One cell of a CSV row: a number robocal formatted, or a text.
#[derive(Debug, Clone, PartialEq)]
pub enum Cell {
    /// A number as formatted (empty: no value).
    Number(String),
    /// A text as given (neutralised and quoted when written).
    Text(String),
}

impl Cell {
    /// A text cell.
    pub fn text(text: impl Into<String>) -> Cell {
        Cell::Text(text.into())
    }

    /// An empty cell.
    pub fn empty() -> Cell {
        Cell::Number(String::new())
    }

    fn finite(v: f64, format: impl Fn(f64) -> String) -> Cell {
        Cell::Number(if v.is_finite() {
            format(v)
        } else {
            String::new()
        })
    }

    /// The shortest text that reads back as exactly `v` (plain decimal, or
    /// exponent notation when the decimal would be long, e.g. `1e-17`).
    pub fn num(v: f64) -> Cell {
        Cell::finite(v, |v| {
            let s = v.to_string();
            if s.len() > 24 {
                format!("{v:e}")
            } else {
                s
            }
        })
    }

    /// `v` with `decimals` digits after the point.
    pub fn fixed(v: f64, decimals: usize) -> Cell {
        Cell::finite(v, |v| format!("{v:.decimals$}"))
    }

    /// `v` in exponent notation with `decimals` digits after the point.
    pub fn sci(v: f64, decimals: usize) -> Cell {
        Cell::finite(v, |v| format!("{v:.decimals$e}"))
    }

    /// An integer (a count, a joint number, an iteration).
    pub fn int<T: Integer>(v: T) -> Cell {
        Cell::Number(v.to_string())
    }

    /// The value as shown in a text table (no CSV marks).
    pub fn shown(&self) -> &str {
        match self {
            Cell::Number(s) | Cell::Text(s) => s,
        }
    }

    /// The cell as written in a CSV row.
    pub fn csv(&self) -> Cow<'_, str> {
        match self {
            Cell::Number(s) => Cow::Borrowed(s),
            Cell::Text(s) => text_cell(s),
        }
    }
}

/// The integer types [`Cell::int`] takes.
pub trait Integer: Display {}
macro_rules! integers {
    ($($t:ty),*) => { $(impl Integer for $t {})* };
}
integers!(u8, u16, u32, u64, usize, i8, i16, i32, i64, isize);

/// Appends one CSV row (comma-separated, `\n`-terminated).
pub fn push_row<'a>(out: &mut String, cells: impl IntoIterator<Item = &'a Cell>) {
    for (i, c) in cells.into_iter().enumerate() {
        if i > 0 {
            out.push(',');
        }
        out.push_str(&c.csv());
    }
    out.push('\n');
}

/// Appends a header row of text cells.
pub fn push_header<S: AsRef<str>>(out: &mut String, names: impl IntoIterator<Item = S>) {
    let cells: Vec<Cell> = names.into_iter().map(|n| Cell::text(n.as_ref())).collect();
    push_row(out, &cells);
}

#[cfg(test)]
mod tests;
