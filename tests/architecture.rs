//! The import rules of the service crate, read from its source files:
//!
//! - the HTTP layer (`src/http`) never names `crate::db`: it calls the
//!   service, which answers with its own types (or re-exports);
//! - the service (`src/service`) never names `crate::http`;
//! - the service re-exports nothing of the store (`pub use crate::db::…`):
//!   the rows both speak of are `crate::records`;
//! - no two files of the service crate (`src`, the binaries aside) import
//!   each other, directly or round a longer loop (a folder's `mod.rs` is its
//!   namespace, not a node);
//! - nor do two files of the core (`core/src`).
//!
//! A file "imports" the module a `crate::`, `super::` or `self::` path in it
//! resolves to: the deepest file module the path names (`super::jobs::
//! shared::admit` from `service/calibrations.rs` is `service/jobs/shared.rs`;
//! `super::AppState` is the parent's namespace). Comments, strings and the
//! inline `#[cfg(test)]` modules are left out.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// A module path inside the crate (`["service", "jobs", "shared"]`).
type Module = Vec<String>;

/// Every library source file by module path: whether it is a folder's
/// `mod.rs`, and its code.
struct Tree {
    files: BTreeMap<Module, (bool, String)>,
}

impl Tree {
    fn read(root: &Path) -> Tree {
        let mut files = BTreeMap::new();
        walk(root, &mut Vec::new(), &mut files);
        Tree { files }
    }

    /// The modules each file names, without itself.
    fn imports(&self) -> BTreeMap<Module, BTreeSet<Module>> {
        let mut out = BTreeMap::new();
        for (module, (_, code)) in &self.files {
            let mut targets = BTreeSet::new();
            for path in paths(&strip(code)) {
                if let Some(t) = self.resolve(module, &path) {
                    if t != *module {
                        targets.insert(t);
                    }
                }
            }
            out.insert(module.clone(), targets);
        }
        out
    }

    /// The deepest file module `path` names from `module`.
    fn resolve(&self, module: &Module, path: &[String]) -> Option<Module> {
        let mut at: Module = match path.first()?.as_str() {
            "crate" => Vec::new(),
            "self" => module.clone(),
            "super" => module[..module.len().checked_sub(1)?].to_vec(),
            _ => return None,
        };
        for seg in &path[1..] {
            if seg == "super" {
                at.pop()?;
                continue;
            }
            let mut next = at.clone();
            next.push(seg.clone());
            if !self.files.contains_key(&next) {
                break;
            }
            at = next;
        }
        Some(at)
    }

    fn is_namespace(&self, m: &Module) -> bool {
        m.is_empty() || self.files.get(m).is_some_and(|(is_mod, _)| *is_mod)
    }
}

fn walk(dir: &Path, module: &mut Module, out: &mut BTreeMap<Module, (bool, String)>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for p in entries {
        let name = p.file_name().unwrap().to_str().unwrap().to_string();
        if p.is_dir() {
            // The binaries are crates of their own.
            if module.is_empty() && name == "bin" {
                continue;
            }
            module.push(name);
            walk(&p, module, out);
            module.pop();
        } else if let Some(stem) = name.strip_suffix(".rs") {
            let code = std::fs::read_to_string(&p).unwrap();
            let (m, is_mod) = match stem {
                "mod" => (module.clone(), true),
                "lib" if module.is_empty() => (Vec::new(), true),
                "main" if module.is_empty() => continue,
                _ => {
                    let mut m = module.clone();
                    m.push(stem.to_string());
                    (m, false)
                }
            };
            out.insert(m, (is_mod, code));
        }
    }
}

/// The code without comments, string and char literals, and without the
/// inline test module(s) that start at `#[cfg(test)]`.
fn strip(code: &str) -> String {
    let code = match code.find("#[cfg(test)]") {
        Some(i) => &code[..i],
        None => code,
    };
    let b = code.as_bytes();
    let mut out = String::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let rest = &code[i..];
        if rest.starts_with("//") {
            i += rest.find('\n').unwrap_or(rest.len());
        } else if rest.starts_with("/*") {
            i += rest.find("*/").map_or(rest.len(), |j| j + 2);
        } else if rest.starts_with("r#\"") || rest.starts_with("r\"") {
            let hashes = rest[1..].bytes().take_while(|&c| c == b'#').count();
            let close = format!("\"{}", "#".repeat(hashes));
            let open = 2 + hashes;
            i += rest[open..]
                .find(&close)
                .map_or(rest.len(), |j| open + j + close.len());
            out.push_str("\"\"");
        } else if b[i] == b'"' {
            let mut j = i + 1;
            while j < b.len() && b[j] != b'"' {
                j += if b[j] == b'\\' { 2 } else { 1 };
            }
            i = j + 1;
            out.push_str("\"\"");
        } else if b[i] == b'\'' && is_char_literal(rest) {
            let mut j = i + 1;
            while j < b.len() && b[j] != b'\'' {
                j += if b[j] == b'\\' { 2 } else { 1 };
            }
            i = j + 1;
        } else {
            let c = rest.chars().next().unwrap();
            out.push(c);
            i += c.len_utf8();
        }
    }
    out
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

#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Ident(String),
    Sep,
    Open,
    Close,
    Comma,
    Other(char),
}

fn tokens(code: &str) -> Vec<Tok> {
    let mut out = Vec::new();
    let mut chars = code.chars().peekable();
    while let Some(c) = chars.next() {
        if c.is_alphanumeric() || c == '_' {
            let mut s = c.to_string();
            while let Some(&d) = chars.peek() {
                if !(d.is_alphanumeric() || d == '_') {
                    break;
                }
                s.push(d);
                chars.next();
            }
            out.push(Tok::Ident(s));
        } else if c == ':' && chars.peek() == Some(&':') {
            chars.next();
            out.push(Tok::Sep);
        } else if c == '{' {
            out.push(Tok::Open);
        } else if c == '}' {
            out.push(Tok::Close);
        } else if c == ',' {
            out.push(Tok::Comma);
        } else if !c.is_whitespace() {
            out.push(Tok::Other(c));
        }
    }
    out
}

/// Every path the code names that starts at `crate`, `super` or `self`:
/// `use` trees expanded (`use a::{b, c::d}` is `a::b` and `a::c::d`), and
/// the paths written in the code.
fn paths(code: &str) -> Vec<Vec<String>> {
    let toks = tokens(code);
    let mut out = Vec::new();
    let mut i = 0;
    while i < toks.len() {
        if toks[i] == Tok::Ident("use".into()) {
            i = use_tree(&toks, i + 1, &mut Vec::new(), &mut out);
            continue;
        }
        if let Tok::Ident(first) = &toks[i] {
            let starts = matches!(first.as_str(), "crate" | "super" | "self");
            let after_sep = i > 0 && toks[i - 1] == Tok::Sep;
            if starts && !after_sep {
                let mut path = vec![first.clone()];
                let mut j = i + 1;
                while j + 1 < toks.len() && toks[j] == Tok::Sep {
                    match &toks[j + 1] {
                        Tok::Ident(s) => path.push(s.clone()),
                        _ => break,
                    }
                    j += 2;
                }
                out.push(path);
                i = j;
                continue;
            }
        }
        i += 1;
    }
    out
}

/// Reads one use tree from `i` with `prefix`, pushing its full paths; returns
/// the index after it (past the `;` at the top level).
fn use_tree(
    toks: &[Tok],
    mut i: usize,
    prefix: &mut Vec<String>,
    out: &mut Vec<Vec<String>>,
) -> usize {
    let depth = prefix.len();
    loop {
        match toks.get(i) {
            Some(Tok::Ident(s)) if s != "as" => {
                prefix.push(s.clone());
                i += 1;
            }
            Some(Tok::Sep) => i += 1,
            Some(Tok::Open) => {
                i += 1;
                loop {
                    i = use_tree(toks, i, prefix, out);
                    match toks.get(i) {
                        Some(Tok::Comma) => i += 1,
                        Some(Tok::Close) => {
                            i += 1;
                            break;
                        }
                        _ => break,
                    }
                    if toks.get(i) == Some(&Tok::Close) {
                        i += 1;
                        break;
                    }
                }
                prefix.truncate(depth);
                return skip_end(toks, i, depth);
            }
            Some(Tok::Ident(_)) => {
                // `as name`: the alias names nothing new.
                i += 2;
            }
            _ => {
                if prefix.len() > depth {
                    out.push(prefix.clone());
                }
                prefix.truncate(depth);
                return skip_end(toks, i, depth);
            }
        }
    }
}

/// Past the `;` of a top-level use tree; inside braces, stays at `,` or `}`.
fn skip_end(toks: &[Tok], i: usize, depth: usize) -> usize {
    if depth == 0 && toks.get(i) == Some(&Tok::Other(';')) {
        i + 1
    } else {
        i
    }
}

/// "a/b.rs"-like name of a module, for messages.
fn name(m: &Module) -> String {
    if m.is_empty() {
        "lib".into()
    } else {
        m.join("/")
    }
}

/// Every file of `from` naming a module under `to`: "file -> module".
fn layer_breaches(tree: &Tree, from: &str, to: &str) -> Vec<String> {
    let mut out = Vec::new();
    for (m, targets) in tree.imports() {
        if m.first().map(String::as_str) != Some(from) {
            continue;
        }
        for t in targets {
            if t.first().map(String::as_str) == Some(to) {
                out.push(format!("{} -> {}", name(&m), name(&t)));
            }
        }
    }
    out
}

/// A loop of imports between the files (not namespaces) under `folder`, if any.
fn import_loop(tree: &Tree, folder: &str) -> Option<Vec<String>> {
    let imports = tree.imports();
    let prefix: Vec<&str> = folder.split('/').filter(|p| !p.is_empty()).collect();
    let inside = |m: &Module| {
        m.len() >= prefix.len()
            && m.iter().zip(&prefix).all(|(a, b)| a == b)
            && !tree.is_namespace(m)
    };
    let graph: BTreeMap<&Module, Vec<&Module>> = imports
        .iter()
        .filter(|(m, _)| inside(m))
        .map(|(m, ts)| (m, ts.iter().filter(|t| inside(t)).collect()))
        .collect();
    // Depth-first search with the path on a stack; a back edge is a loop.
    fn visit<'a>(
        m: &'a Module,
        graph: &BTreeMap<&'a Module, Vec<&'a Module>>,
        state: &mut BTreeMap<&'a Module, u8>,
        stack: &mut Vec<&'a Module>,
    ) -> Option<Vec<String>> {
        state.insert(m, 1);
        stack.push(m);
        for &t in graph.get(m).into_iter().flatten() {
            match state.get(t) {
                Some(1) => {
                    let from = stack.iter().position(|s| *s == t).unwrap();
                    let mut cycle: Vec<String> = stack[from..].iter().map(|s| name(s)).collect();
                    cycle.push(name(t));
                    return Some(cycle);
                }
                Some(_) => {}
                None => {
                    if let Some(c) = visit(t, graph, state, stack) {
                        return Some(c);
                    }
                }
            }
        }
        stack.pop();
        state.insert(m, 2);
        None
    }
    let mut state = BTreeMap::new();
    for m in graph.keys() {
        if !state.contains_key(m) {
            if let Some(c) = visit(m, &graph, &mut state, &mut Vec::new()) {
                return Some(c);
            }
        }
    }
    None
}

fn src() -> Tree {
    Tree::read(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"))
}

#[test]
fn the_http_layer_never_imports_the_store() {
    let breaches = layer_breaches(&src(), "http", "db");
    assert!(
        breaches.is_empty(),
        "src/http must reach the store through the service (re-export what it needs there): {breaches:#?}"
    );
}

#[test]
fn the_service_never_imports_the_http_layer() {
    let breaches = layer_breaches(&src(), "service", "http");
    assert!(
        breaches.is_empty(),
        "src/service must not depend on the HTTP layer (limits and types live in the service): {breaches:#?}"
    );
}

/// Every `pub use` (or `pub(crate) use`) path of the files under `folder`.
fn public_uses(tree: &Tree, folder: &str) -> Vec<(Module, Vec<String>)> {
    let mut out = Vec::new();
    for (m, (_, code)) in &tree.files {
        if m.first().map(String::as_str) != Some(folder) {
            continue;
        }
        let toks = tokens(&strip(code));
        for i in 0..toks.len() {
            let public = i >= 1 && toks[i - 1] == Tok::Ident("pub".into())
                || i >= 4
                    && toks[i - 1] == Tok::Other(')')
                    && toks[i - 4] == Tok::Ident("pub".into());
            if public && toks[i] == Tok::Ident("use".into()) {
                let mut found = Vec::new();
                use_tree(&toks, i + 1, &mut Vec::new(), &mut found);
                out.extend(found.into_iter().map(|p| (m.clone(), p)));
            }
        }
    }
    out
}

#[test]
fn the_service_re_exports_nothing_of_the_store() {
    let tree = src();
    let found: Vec<String> = public_uses(&tree, "service")
        .into_iter()
        .filter(|(m, p)| {
            tree.resolve(m, p)
                .and_then(|t| t.first().cloned())
                .as_deref()
                == Some("db")
        })
        .map(|(m, p)| format!("{}: pub use {}", name(&m), p.join("::")))
        .collect();
    assert!(
        found.is_empty(),
        "the service answers with its own types or crate::records, never the store's: {found:#?}"
    );
}

#[test]
fn no_two_files_of_the_service_crate_import_each_other() {
    assert_eq!(import_loop(&src(), ""), None, "an import loop in src");
}

#[test]
fn no_two_core_files_import_each_other() {
    let core = Tree::read(&Path::new(env!("CARGO_MANIFEST_DIR")).join("core/src"));
    assert_eq!(import_loop(&core, ""), None, "an import loop in core/src");
}

// The checker itself, on small trees whose answer is known.

fn tree(files: &[(&str, &str)]) -> Tree {
    let files = files
        .iter()
        .map(|(path, code)| {
            let is_mod = path.ends_with("/mod") || path.is_empty();
            let path = path.strip_suffix("/mod").unwrap_or(path);
            let m: Module = path
                .split('/')
                .filter(|s| !s.is_empty())
                .map(String::from)
                .collect();
            (m, (is_mod, code.to_string()))
        })
        .collect();
    Tree { files }
}

#[test]
fn the_checker_sees_grouped_nested_and_inline_paths() {
    let t = tree(&[
        ("", "pub mod db; pub mod http; pub mod service;"),
        ("db/mod", "pub struct Row;"),
        ("db/rows", "pub struct Row;"),
        ("service/mod", "pub mod a; pub mod b; pub mod jobs;"),
        ("service/jobs/mod", "pub mod run;"),
        ("service/jobs/run", "use crate::service::{a::X, b};"),
        ("service/a", "// use crate::http::x;\nconst S: &str = \"crate::http::y\";\nfn f() { super::jobs::run::go(); }"),
        ("service/b", "use super::AppState;"),
        ("http/mod", "pub mod h; pub mod g;"),
        ("http/h", "use crate::service::{self, a::{X as Y, Z}};"),
        ("http/g", "fn f() -> crate::db::rows::Row { todo!() }\n#[cfg(test)]\nmod tests { use crate::db::Row; }"),
    ]);
    assert_eq!(layer_breaches(&t, "http", "db"), vec!["http/g -> db/rows"]);
    assert!(layer_breaches(&t, "service", "http").is_empty());
    let imports = t.imports();
    let run = &imports[&vec!["service".to_string(), "jobs".into(), "run".into()]];
    assert!(run.contains(&vec!["service".to_string(), "a".into()]));
    assert!(run.contains(&vec!["service".to_string(), "b".into()]));
    // a -> run -> a is a loop; b names only its parent's namespace.
    let cycle = import_loop(&t, "service").unwrap();
    assert_eq!(cycle.first(), cycle.last());
    assert!(cycle.contains(&"service/a".to_string()), "{cycle:?}");
    assert!(cycle.contains(&"service/jobs/run".to_string()), "{cycle:?}");
}

#[test]
fn the_checker_sees_a_store_type_re_exported() {
    let t = tree(&[
        ("service/mod", "pub mod a; pub use crate::db::Row;"),
        (
            "service/a",
            "pub(crate) use crate::db::{rows::Other, Listing}; use crate::db::Db;",
        ),
        ("db/mod", "pub mod rows;"),
        ("db/rows", "pub struct Other;"),
    ]);
    let reexported: Vec<String> = public_uses(&t, "service")
        .into_iter()
        .map(|(m, p)| format!("{}: {}", name(&m), p.join("::")))
        .collect();
    assert_eq!(
        reexported,
        vec![
            "service: crate::db::Row",
            "service/a: crate::db::rows::Other",
            "service/a: crate::db::Listing"
        ]
    );
}

#[test]
fn the_checker_finds_no_loop_in_a_one_way_tree() {
    let t = tree(&[
        ("service/mod", "pub mod a; pub mod b; pub use a::T;"),
        ("service/a", "use super::b::f; use super::T;"),
        ("service/b", "use crate::service::T; fn g() -> self::U {}"),
        ("service/c", "use crate::http::Thing;"),
        ("http/mod", "pub struct Thing;"),
    ]);
    assert_eq!(import_loop(&t, "service"), None);
    assert_eq!(
        layer_breaches(&t, "service", "http"),
        vec!["service/c -> http"]
    );
}
