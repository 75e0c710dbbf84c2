//! The motion instructions of a Fanuc `/MN` section: `J`, `L`, `C` (via
//! point, then the end point on the continuation line `:  P[m] …`) and `A`,
//! each line `n:` up to its `;`, and the positions they name: `P[n]`,
//! `P[n:"comment"]`, position registers `PR[n]`, indirect `P[R[n]]`; and
//! whether the motion is incremental (`INC`) or offset at run time
//! (`Offset`, `Tool_Offset`, `VOFFSET`). Remarks (`!…`, `//…`) and other
//! instructions are passed over. Offsets are bytes of the file.

use std::ops::Range;

/// A position a motion names.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Reference {
    /// `P[n]`: the number, and where a mark goes (the comment's span
    /// `:"…"`, or empty after the number).
    Position { number: u32, mark_at: Range<usize> },
    /// Anything chosen or set at run time (`PR[n]`, `P[R[n]]`), as written.
    RunTime(String),
}

/// One motion instruction of `/MN`.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct MotionLine {
    /// 1-based line of the instruction (its `n:`).
    pub(super) line: usize,
    /// `J`, `L`, `C` or `A`.
    pub(super) instruction: String,
    /// Its positions, with their text (`P[3]`, `PR[2]`).
    pub(super) positions: Vec<(String, Reference)>,
    /// Why the motion does not go to its positions as recorded (`INC`, an offset).
    pub(super) run_time: Option<String>,
}

/// The motions of the `/MN` section in `text[body]`.
pub(super) fn motions(text: &str, body: Range<usize>) -> Vec<MotionLine> {
    let mut out: Vec<MotionLine> = Vec::new();
    // Statements: a line `n:` and its continuation lines `:`, each as
    // (file offset of its content, content, 1-based line).
    let mut statement: Vec<(usize, &str, usize)> = Vec::new();
    let mut start = body.start;
    let first_line = text[..body.start].matches('\n').count() + 1;
    for (i, raw) in text[body.clone()].split('\n').enumerate() {
        let at = start;
        start += raw.len() + 1;
        let trimmed = raw.trim_start();
        let lead = raw.len() - trimmed.len();
        let digits = trimmed.bytes().take_while(u8::is_ascii_digit).count();
        if digits > 0 && trimmed[digits..].starts_with(':') {
            flush(&mut statement, &mut out);
            let content = at + lead + digits + 1;
            statement.push((content, &text[content..at + raw.len()], first_line + i));
        } else if trimmed.starts_with(':') && !statement.is_empty() {
            let content = at + lead + 1;
            statement.push((content, &text[content..at + raw.len()], first_line + i));
        }
    }
    flush(&mut statement, &mut out);
    out
}

/// Reads a finished statement into `out` when it is a motion.
fn flush(statement: &mut Vec<(usize, &str, usize)>, out: &mut Vec<MotionLine>) {
    let parts = std::mem::take(statement);
    let Some(&(_, first, line)) = parts.first() else {
        return;
    };
    let head = first.trim_start();
    let letter = head.chars().next().unwrap_or(' ').to_ascii_uppercase();
    let after = head.get(1..).unwrap_or("");
    let motion = matches!(letter, 'J' | 'L' | 'C' | 'A')
        && after.starts_with(|c: char| c.is_whitespace() || c == '@' || c == 'P' || c == 'p');
    if !motion {
        return;
    }
    // The via point of `C` is on the first line, its end point on the next
    // (or after the via point on the same line).
    let mut positions = Vec::new();
    let (offset, content) = (parts[0].0, parts[0].1);
    let mut from = first.len() - head.len() + 1;
    if let Some((p, end)) = reference(content, from, offset) {
        positions.push(p);
        from = end;
    }
    if letter == 'C' {
        let second = match parts.get(1) {
            Some(&(offset, content, _)) => reference(content, 0, offset),
            None => reference(content, from, offset),
        };
        positions.extend(second.map(|(p, _)| p));
    }
    let whole: String = parts.iter().map(|p| p.1).collect::<Vec<_>>().join(" ");
    out.push(MotionLine {
        line,
        instruction: letter.to_string(),
        positions,
        run_time: run_time(&code_of(&whole)),
    });
}

/// The statement up to its `;` outside quotes.
fn code_of(s: &str) -> String {
    let mut quote = None;
    for (i, c) in s.char_indices() {
        match (quote, c) {
            (Some(q), c) if c == q => quote = None,
            (Some(_), _) => {}
            (None, '"' | '\'') => quote = Some(c),
            (None, ';') => return s[..i].to_string(),
            _ => {}
        }
    }
    s.to_string()
}

/// Why a motion's positions are not where /POS has them: `INC`, or an
/// offset applied at run time.
fn run_time(code: &str) -> Option<String> {
    let words: Vec<String> = code
        .split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .map(str::to_ascii_uppercase)
        .collect();
    if words.iter().any(|w| w == "INC") {
        return Some("incremental motion (INC): it moves from where the robot is".into());
    }
    let offset = words
        .iter()
        .find(|w| matches!(w.as_str(), "OFFSET" | "TOOL_OFFSET" | "VOFFSET"))?;
    let at = code.to_ascii_uppercase().find(offset.as_str()).unwrap_or(0);
    let clause: String = code[at..]
        .split_whitespace()
        .next()
        .unwrap_or(offset)
        .to_string();
    Some(format!(
        "the position is offset at run time ({clause}): the motion goes elsewhere than its point"
    ))
}

/// The first position reference in `content[from..]` (`content` starts at
/// file offset `offset`): its text and what it is, and where in `content`
/// it ends.
fn reference(content: &str, from: usize, offset: usize) -> Option<((String, Reference), usize)> {
    let code = code_of(content.get(from..)?);
    let b = code.as_bytes();
    let mut i = 0;
    while i < b.len() {
        let boundary = i == 0 || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_');
        let upper = |k: usize| b.get(k).map(u8::to_ascii_uppercase);
        if boundary && upper(i) == Some(b'P') {
            let register = upper(i + 1) == Some(b'R') && b.get(i + 2) == Some(&b'[');
            if register || b.get(i + 1) == Some(&b'[') {
                let open = i + if register { 2 } else { 1 };
                let close = matching(b, open)?;
                let text = code[i..=close].to_string();
                let end = from + close + 1;
                if register {
                    let why = format!("{text} is a position register, set at run time");
                    return Some(((text, Reference::RunTime(why)), end));
                }
                let inner = &code[open + 1..close];
                let digits = inner.bytes().take_while(u8::is_ascii_digit).count();
                let rest = &inner[digits..];
                if digits == 0 || !(rest.is_empty() || rest.starts_with(':')) {
                    let why = format!("{text} is chosen at run time");
                    return Some(((text, Reference::RunTime(why)), end));
                }
                let number: u32 = inner[..digits].parse().ok()?;
                let base = offset + from + open + 1 + digits;
                let mark_at = base..base + rest.len();
                let name = format!("P[{number}]");
                return Some(((name, Reference::Position { number, mark_at }), end));
            }
        }
        i += 1;
    }
    None
}

/// The `]` that closes the `[` at `open` (nested brackets, quotes inside).
fn matching(b: &[u8], open: usize) -> Option<usize> {
    let mut depth = 0;
    let mut quote: Option<u8> = None;
    for (k, &c) in b.iter().enumerate().skip(open) {
        match (quote, c) {
            (Some(q), c) if c == q => quote = None,
            (Some(_), _) => {}
            (None, b'"' | b'\'') => quote = Some(c),
            (None, b'[') => depth += 1,
            (None, b']') => {
                depth -= 1;
                if depth == 0 {
                    return Some(k);
                }
            }
            _ => {}
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn motions_positions_and_options() {
        let mn = "/MN\n   1:  ! it's P[9] ;\n   2:J P[1] 100% FINE    ;\n   3:L PR[3] 500mm/sec FINE ;\n\
                  \x20  4:C P[4]    \n    :  P[5:\"end\"] 20mm/sec CNT100    ;\n   5:L P[6] 100mm/sec FINE INC ;\n\
                  \x20  6:L P[7] 100mm/sec FINE Offset,PR[1] ;\n   7:  DO[1]=ON ;\n   8:L P[R[2]] 10mm/sec FINE ;\n   9:C P[8] P[9] 10mm/sec FINE ;\n/POS\n";
        let end = mn.find("/POS").unwrap();
        let m = motions(mn, 3..end);
        let lines: Vec<(usize, &str)> =
            m.iter().map(|x| (x.line, x.instruction.as_str())).collect();
        assert_eq!(
            lines,
            [
                (3, "J"),
                (4, "L"),
                (5, "C"),
                (7, "L"),
                (8, "L"),
                (10, "L"),
                (11, "C")
            ]
        );
        let names: Vec<Vec<&str>> = m
            .iter()
            .map(|x| x.positions.iter().map(|p| p.0.as_str()).collect())
            .collect();
        assert_eq!(
            names,
            [
                vec!["P[1]"],
                vec!["PR[3]"],
                vec!["P[4]", "P[5]"],
                vec!["P[6]"],
                vec!["P[7]"],
                vec!["P[R[2]]"],
                vec!["P[8]", "P[9]"]
            ]
        );
        let Reference::Position { number, mark_at } = &m[2].positions[1].1 else {
            panic!()
        };
        assert_eq!((*number, &mn[mark_at.clone()]), (5, ":\"end\""));
        let Reference::Position { mark_at, .. } = &m[0].positions[0].1 else {
            panic!()
        };
        assert_eq!(
            (mark_at.start, mark_at.len()),
            (mn.find("P[1]").unwrap() + 3, 0)
        );
        assert!(matches!(m[1].positions[0].1, Reference::RunTime(_)));
        assert!(m[3].run_time.as_ref().unwrap().contains("INC"));
        assert!(m[4].run_time.as_ref().unwrap().contains("Offset,PR[1]"));
        assert!(m[0].run_time.is_none() && m[2].run_time.is_none());
        assert!(matches!(m[5].positions[0].1, Reference::RunTime(_)));
    }
}
