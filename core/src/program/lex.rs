//! A small lexer shared by the RAPID and URScript parsers: comments blanked
//! out (offsets kept), tokens with byte ranges, and bracket literals
//! `[a, [b, c], …]` as trees.

use super::ParseError;
use std::ops::Range;

/// An error at a byte offset of a file.
pub(super) type Fail = (usize, String);

/// `(line, column)` (1-based, column in characters) of byte offset `at`.
pub(super) fn position(text: &str, at: usize) -> (usize, usize) {
    let at = at.min(text.len());
    let mut at = at;
    while !text.is_char_boundary(at) {
        at -= 1;
    }
    let before = &text[..at];
    let line = before.matches('\n').count() + 1;
    let start = before.rfind('\n').map_or(0, |i| i + 1);
    (line, before[start..].chars().count() + 1)
}

pub(super) fn error(file: &str, text: &str, (at, message): Fail) -> ParseError {
    let (line, column) = position(text, at);
    ParseError {
        file: file.to_string(),
        line,
        column,
        message,
    }
}

/// Byte offset of the end of the line holding `at` (before `\r\n` or `\n`).
pub(super) fn line_end(text: &str, at: usize) -> usize {
    let end = text[at..].find('\n').map_or(text.len(), |i| at + i);
    if end > 0 && text.as_bytes()[end - 1] == b'\r' {
        end - 1
    } else {
        end
    }
}

/// `text` with every comment (from `comment` to the end of the line, outside
/// strings in `quotes`) replaced by spaces, byte for byte.
pub(super) fn blank_comments(text: &str, comment: char, quotes: &[char]) -> Result<String, Fail> {
    let mut out = String::with_capacity(text.len());
    let mut quote: Option<(char, usize)> = None;
    let mut in_comment = false;
    for (i, c) in text.char_indices() {
        if c == '\n' {
            if let Some((_, at)) = quote {
                return Err((at, "unterminated string".into()));
            }
            in_comment = false;
            out.push('\n');
            continue;
        }
        if in_comment {
            out.extend(std::iter::repeat_n(' ', c.len_utf8()));
            continue;
        }
        match quote {
            Some((q, _)) if c == q => quote = None,
            Some(_) => {}
            None if c == comment => {
                in_comment = true;
                out.extend(std::iter::repeat_n(' ', c.len_utf8()));
                continue;
            }
            None if quotes.contains(&c) => quote = Some((c, i)),
            None => {}
        }
        out.push(c);
    }
    if let Some((_, at)) = quote {
        return Err((at, "unterminated string".into()));
    }
    Ok(out)
}

#[derive(Debug, Clone, PartialEq)]
pub(super) enum Tok {
    /// Identifier as written.
    Word(String),
    Number(f64),
    Str,
    Punct(char),
}

pub(super) type Token = (Tok, Range<usize>);

/// Tokens of comment-free `code` (strings in `quotes`).
pub(super) fn tokens(code: &str, quotes: &[char]) -> Result<Vec<Token>, Fail> {
    let b = code.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let c = code[i..].chars().next().unwrap_or(' ');
        let start = i;
        if c.is_whitespace() {
            i += c.len_utf8();
        } else if c.is_ascii_alphabetic() || c == '_' {
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                i += 1;
            }
            out.push((Tok::Word(code[start..i].to_string()), start..i));
        } else if c.is_ascii_digit() || (c == '.' && b.get(i + 1).is_some_and(u8::is_ascii_digit)) {
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
            let v = code[start..i]
                .parse()
                .map_err(|_| (start, format!("bad number `{}`", &code[start..i])))?;
            out.push((Tok::Number(v), start..i));
        } else if quotes.contains(&c) {
            let close = code[i + 1..]
                .find(c)
                .ok_or((i, "unterminated string".to_string()))?;
            i += close + 2;
            out.push((Tok::Str, start..i));
        } else {
            i += c.len_utf8();
            out.push((Tok::Punct(c), start..i));
        }
    }
    Ok(out)
}

/// A bracket literal.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Val {
    /// `[…]`: elements and the range from `[` to `]`.
    List(Vec<Val>, Range<usize>),
    /// A (signed) number and the range of its text.
    Num(f64, Range<usize>),
    /// Anything else (a name, an expression): its range.
    Other(Range<usize>),
}

impl Val {
    pub(super) fn range(&self) -> Range<usize> {
        match self {
            Val::List(_, r) | Val::Num(_, r) | Val::Other(r) => r.clone(),
        }
    }

    pub(super) fn list(&self) -> Option<&[Val]> {
        match self {
            Val::List(v, _) => Some(v),
            _ => None,
        }
    }

    /// `n` numbers: their values and ranges.
    pub(super) fn numbers(&self, n: usize) -> Option<(Vec<f64>, Vec<Range<usize>>)> {
        let items = self.list()?;
        if items.len() != n {
            return None;
        }
        items
            .iter()
            .map(|v| match v {
                Val::Num(x, r) => Some((*x, r.clone())),
                _ => None,
            })
            .collect::<Option<Vec<_>>>()
            .map(|v| v.into_iter().unzip())
    }
}

fn is(t: Option<&Token>, c: char) -> bool {
    matches!(t, Some((Tok::Punct(p), _)) if *p == c)
}

/// Deepest nesting of bracket literals read (deeper input is an error, not a stack overflow).
const MAX_DEPTH: usize = 32;

/// The element starting at token `i`: a list, a signed number, or anything
/// up to the next `,` or closing bracket at this depth; `open`: where the
/// enclosing bracket opens (for the error of a missing close).
fn value_at_depth(
    toks: &[Token],
    i: usize,
    close: char,
    depth: usize,
    open: usize,
) -> Result<(Val, usize), Fail> {
    let end_of = |j: usize| toks.get(j).map_or(open, |t| t.1.start);
    if is(toks.get(i), '[') {
        return list_at_depth(toks, i, depth + 1);
    }
    let sign = match toks.get(i) {
        Some((Tok::Punct('-'), _)) => Some(-1.0),
        Some((Tok::Punct('+'), _)) => Some(1.0),
        _ => None,
    };
    let j = i + usize::from(sign.is_some());
    if let Some((Tok::Number(x), r)) = toks.get(j) {
        if is(toks.get(j + 1), ',') || is(toks.get(j + 1), close) {
            let start = toks[i].1.start;
            return Ok((Val::Num(sign.unwrap_or(1.0) * x, start..r.end), j + 1));
        }
    }
    // Anything else: up to `,` or the closing bracket at depth 0.
    let mut depth = 0i32;
    let mut k = i;
    loop {
        match toks.get(k) {
            None => return Err((open, "`[` not closed".into())),
            Some((Tok::Punct('[' | '('), _)) => depth += 1,
            Some((Tok::Punct(']' | ')'), _)) if depth > 0 => depth -= 1,
            Some((Tok::Punct(c), _)) if depth == 0 && (*c == ',' || *c == close) => break,
            _ => {}
        }
        k += 1;
    }
    if k == i {
        return Err((end_of(i), "empty element".into()));
    }
    Ok((Val::Other(toks[i].1.start..toks[k - 1].1.end), k))
}

/// The list opening at token `i` (`[`); returns it and the token after `]`.
pub(super) fn list(toks: &[Token], i: usize) -> Result<(Val, usize), Fail> {
    list_at_depth(toks, i, 0)
}

fn list_at_depth(toks: &[Token], i: usize, depth: usize) -> Result<(Val, usize), Fail> {
    let open = toks[i].1.start;
    if depth > MAX_DEPTH {
        return Err((open, "brackets nested too deep".into()));
    }
    let mut items = Vec::new();
    let mut k = i + 1;
    if is(toks.get(k), ']') {
        return Ok((Val::List(items, open..toks[k].1.end), k + 1));
    }
    loop {
        if toks.get(k).is_none() {
            return Err((open, "`[` not closed".into()));
        }
        let (v, next) = value_at_depth(toks, k, ']', depth, open)?;
        items.push(v);
        k = next;
        match toks.get(k) {
            Some((Tok::Punct(','), _)) => k += 1,
            Some((Tok::Punct(']'), r)) => return Ok((Val::List(items, open..r.end), k + 1)),
            Some((_, r)) => return Err((r.start, "expected `,` or `]`".into())),
            None => return Err((open, "`[` not closed".into())),
        }
    }
}
