//! The size rules: no source file of either crate, their tests, benches,
//! examples and fuzz targets over [`MAX_FILE_LINES`] lines; no function of
//! the crates' code (their inline unit tests included), benches, examples and
//! fuzz targets over [`MAX_FN_LINES`] lines from its `fn` line to its closing
//! brace. The integration tests' scenarios (`tests/`, `core/tests/`) are held
//! to the file limit only: an end-to-end scenario reads best as one story.

use std::path::{Path, PathBuf};

/// The longest a source file may be, in lines.
pub const MAX_FILE_LINES: usize = 900;

/// The longest a function may be, in lines, signature to closing brace.
pub const MAX_FN_LINES: usize = 120;

/// The folders of code whose `.rs` files both rules cover, from the
/// repository root.
const CODE: &[&str] = &[
    "src",
    "benches",
    "core/src",
    "core/benches",
    "core/examples",
    "fuzz/fuzz_targets",
];

/// The folders of integration tests, held to the file limit only.
const TESTS: &[&str] = &["tests", "core/tests"];

/// A function and its length in lines.
#[derive(Debug, PartialEq)]
pub struct Function {
    pub name: String,
    /// 1-based line of its `fn` keyword.
    pub line: usize,
    pub lines: usize,
}

/// Every `.rs` file under `roots`.
fn sources(roots: &[&str]) -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let Ok(entries) = std::fs::read_dir(dir) else {
            return;
        };
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                walk(&p, out);
            } else if p.extension().is_some_and(|x| x == "rs") {
                out.push(p);
            }
        }
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut out = Vec::new();
    for r in roots {
        walk(&root.join(r), &mut out);
    }
    out.sort();
    out
}

/// `code` with the contents of comments, strings and char literals blanked
/// (newlines kept), so braces and `fn` inside them do not count.
fn blanked(code: &str) -> String {
    let b = code.as_bytes();
    let mut out = String::with_capacity(b.len());
    let keep_lines = |s: &str, out: &mut String| {
        out.extend(s.chars().map(|c| if c == '\n' { '\n' } else { ' ' }));
    };
    let mut i = 0;
    while i < b.len() {
        let rest = &code[i..];
        let end = if rest.starts_with("//") {
            rest.find('\n').unwrap_or(rest.len())
        } else if rest.starts_with("/*") {
            rest.find("*/").map_or(rest.len(), |j| j + 2)
        } else if let Some(hashes) = raw_string_hashes(rest) {
            let open = rest.find('"').unwrap();
            let close = format!("\"{}", "#".repeat(hashes));
            rest[open + 1..]
                .find(&close)
                .map_or(rest.len(), |j| open + 1 + j + close.len())
        } else if b[i] == b'"' {
            let mut j = 1;
            while j < rest.len() && rest.as_bytes()[j] != b'"' {
                j += if rest.as_bytes()[j] == b'\\' { 2 } else { 1 };
            }
            (j + 1).min(rest.len())
        } else if b[i] == b'\'' && is_char_literal(rest) {
            let mut j = 1;
            while j < rest.len() && rest.as_bytes()[j] != b'\'' {
                j += if rest.as_bytes()[j] == b'\\' { 2 } else { 1 };
            }
            (j + 1).min(rest.len())
        } else {
            let c = rest.chars().next().unwrap();
            out.push(c);
            i += c.len_utf8();
            continue;
        };
        keep_lines(&rest[..end], &mut out);
        i += end;
    }
    out
}

/// The `#`s of a raw string literal starting `rest` (`r"…"`, `r#"…"#`,
/// `br"…"`), `None` when `rest` starts no raw string.
fn raw_string_hashes(rest: &str) -> Option<usize> {
    let after = rest.strip_prefix('b').unwrap_or(rest).strip_prefix('r')?;
    let hashes = after.len() - after.trim_start_matches('#').len();
    after[hashes..].starts_with('"').then_some(hashes)
}

/// `'x'` or `'\n'`, not a lifetime (`'a`, `'static`).
fn is_char_literal(rest: &str) -> bool {
    let mut chars = rest.chars().skip(1);
    match chars.next() {
        Some('\\') => true,
        Some(_) => chars.next() == Some('\''),
        None => false,
    }
}

/// Every function with a body in `code`: from the line of `fn name` to the
/// line of the brace that closes its body (declarations without a body and
/// `fn(…)` types are not functions).
pub fn functions(code: &str) -> Vec<Function> {
    let code = blanked(code);
    let b = code.as_bytes();
    let word = |i: usize| i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_');
    let line_of = |i: usize| code[..i].bytes().filter(|&c| c == b'\n').count() + 1;
    let mut out = Vec::new();
    let mut i = 0;
    while let Some(k) = code[i..].find("fn") {
        let at = i + k;
        i = at + 2;
        if (at > 0 && word(at - 1)) || !b.get(at + 2).is_some_and(|c| c.is_ascii_whitespace()) {
            continue;
        }
        let name: String = code[at + 2..]
            .trim_start()
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        if name.is_empty() {
            continue;
        }
        // The body opens at the first `{` before any `;` (a declaration).
        let Some(open) = code[at..].find(['{', ';']).map(|j| at + j) else {
            break;
        };
        if b[open] == b';' {
            continue;
        }
        let mut depth = 0usize;
        let mut close = code.len() - 1;
        for (j, c) in code[open..].char_indices() {
            match c {
                '{' => depth += 1,
                '}' => {
                    depth -= 1;
                    if depth == 0 {
                        close = open + j;
                        break;
                    }
                }
                _ => {}
            }
        }
        let line = line_of(at);
        out.push(Function {
            name,
            line,
            lines: line_of(close) - line + 1,
        });
        // Functions nested in this one are measured too.
        i = open + 1;
    }
    out
}

fn shown(p: &Path) -> String {
    p.strip_prefix(env!("CARGO_MANIFEST_DIR"))
        .unwrap_or(p)
        .display()
        .to_string()
}

#[test]
fn no_file_is_over_the_line_limit() {
    let long: Vec<String> = sources(CODE)
        .iter()
        .chain(&sources(TESTS))
        .filter_map(|p| {
            let n = std::fs::read_to_string(p).unwrap().lines().count();
            (n > MAX_FILE_LINES).then(|| format!("{} ({n} lines)", shown(p)))
        })
        .collect();
    assert!(
        long.is_empty(),
        "files over {MAX_FILE_LINES} lines: {long:#?}"
    );
}

#[test]
fn no_function_is_over_the_line_limit() {
    let files = sources(CODE);
    assert!(files.len() > 100, "only {} files found", files.len());
    let long: Vec<String> = files
        .iter()
        .flat_map(|p| {
            let code = std::fs::read_to_string(p).unwrap();
            functions(&code)
                .into_iter()
                .filter(|f| f.lines > MAX_FN_LINES)
                .map(move |f| format!("{}:{} fn {} ({} lines)", shown(p), f.line, f.name, f.lines))
        })
        .collect();
    assert!(
        long.is_empty(),
        "functions over {MAX_FN_LINES} lines: {long:#?}"
    );
}

#[test]
fn functions_are_measured_from_fn_to_their_closing_brace() {
    let code = r#"
/// A doc line with fn inside and a brace {
pub(crate) fn first(a: impl Fn(u8) -> u8) -> u8 {
    let s = "} fn fake() {";
    let c = '}';
    a(1)
}

trait T {
    fn declared(&self);
    fn defaulted(&self) -> u8 where Self: Sized {
        // } a comment brace
        let f: fn(u8) -> u8 = |x| x;
        f(2)
    }
}
"#;
    assert_eq!(
        functions(code),
        vec![
            Function {
                name: "first".into(),
                line: 3,
                lines: 5
            },
            Function {
                name: "defaulted".into(),
                line: 11,
                lines: 5
            },
        ]
    );
    // A planted long function is found.
    let body = "    let x = 1;\n".repeat(MAX_FN_LINES);
    let long = format!("fn planted() {{\n{body}}}\n");
    let f = functions(&long);
    assert_eq!(f.len(), 1);
    assert_eq!(f[0].lines, MAX_FN_LINES + 2);
}
