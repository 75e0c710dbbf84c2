//! The import graph of a crate, read from its source files.
//!
//! Every file with code is a node, a folder's `mod.rs` (and `lib.rs`)
//! included. A file "imports" the file a path in it resolves to: paths that
//! start at `crate`, `super`, `self` or at one of the file's own child
//! modules (`use jobs::Runner;` in `service/mod.rs`), `use` trees expanded.
//! The path goes down the file modules it names as deep as they go; a name
//! the file it reaches does not define but imports (`pub use a::Thing;`, or
//! a plain `use`, which its child modules see as `super::Thing`) is
//! followed to where that import leads, so a re-export is no hiding place.
//! A re-export itself is no edge of the file that holds it (it passes
//! names through); a path that ends outside the crate (a re-exported
//! `nalgebra` type) is no edge. Comments, strings and `#[cfg(test)]` items
//! are left out, and so are files of tests only (`foo/tests.rs`, or a file
//! its parent declares `#[cfg(test)] mod fixture;`).

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// A module path inside the crate (`["service", "jobs", "shared"]`).
pub type Module = Vec<String>;

/// One source file: whether it is a folder's `mod.rs` (or `lib.rs`), its
/// code without comments, strings and test items.
pub struct File {
    pub code: String,
    /// The items it defines.
    defs: BTreeSet<String>,
    /// Its `use` paths, whether each is public (a re-export), and its glob
    /// imports' modules.
    uses: Vec<(Vec<String>, bool)>,
    globs: Vec<Vec<String>>,
}

impl File {
    fn new(code: &str) -> File {
        let code = strip(code);
        let toks = tokens(&code);
        let mut defs = BTreeSet::new();
        for w in toks.windows(3) {
            if let (Tok::Ident(k), Tok::Ident(n)) = (&w[0], &w[1]) {
                if matches!(
                    k.as_str(),
                    "struct"
                        | "enum"
                        | "fn"
                        | "trait"
                        | "type"
                        | "const"
                        | "static"
                        | "union"
                        | "mod"
                ) {
                    defs.insert(n.clone());
                }
            }
            if w[0] == Tok::Ident("macro_rules".into()) && w[1] == Tok::Other('!') {
                if let Tok::Ident(n) = &w[2] {
                    defs.insert(n.clone());
                }
            }
        }
        let (mut uses, mut globs) = (Vec::new(), Vec::new());
        for i in 0..toks.len() {
            if toks[i] == Tok::Ident("use".into()) {
                let public = i >= 1 && toks[i - 1] == Tok::Ident("pub".into())
                    || i >= 4
                        && toks[i - 1] == Tok::Other(')')
                        && toks[i - 4] == Tok::Ident("pub".into());
                let mut found = Vec::new();
                use_tree(&toks, i + 1, &mut Vec::new(), &mut found);
                for mut p in found {
                    if p.last().map(String::as_str) == Some("*") {
                        p.pop();
                        globs.push(p);
                    } else {
                        uses.push((p, public));
                    }
                }
            }
        }
        File {
            code,
            defs,
            uses,
            globs,
        }
    }

    /// Every path its code names that is an import of its own: its private
    /// `use` paths and the paths written in its code; a re-export (`pub
    /// use`) passes names through and is followed from where they are used.
    pub fn own_paths(&self) -> Vec<Vec<String>> {
        let mut out: Vec<Vec<String>> = self
            .uses
            .iter()
            .filter(|(_, public)| !public)
            .map(|(p, _)| p.clone())
            .collect();
        out.extend(self.globs.iter().cloned());
        out.extend(code_paths(&self.code));
        out
    }
}

/// Every library source file by module path.
pub struct Tree {
    pub files: BTreeMap<Module, File>,
}

impl Tree {
    pub fn read(root: &Path) -> Tree {
        let mut files = BTreeMap::new();
        walk(root, &mut Vec::new(), &mut files);
        Tree { files }
    }

    /// A tree of `(path, code)` pairs: `"service/mod"` is a folder's
    /// `mod.rs`, `""` the crate root.
    pub fn of(files: &[(&str, &str)]) -> Tree {
        let files = files
            .iter()
            .map(|(path, code)| {
                let path = path.strip_suffix("/mod").unwrap_or(path);
                let m: Module = path
                    .split('/')
                    .filter(|s| !s.is_empty())
                    .map(String::from)
                    .collect();
                (m, File::new(code))
            })
            .collect();
        Tree { files }
    }

    /// The files each file imports, without itself.
    pub fn imports(&self) -> BTreeMap<Module, BTreeSet<Module>> {
        let mut out = BTreeMap::new();
        for (module, file) in &self.files {
            let mut targets = BTreeSet::new();
            for path in file.own_paths() {
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

    /// The file `path` leads to from `module`, re-exports followed; `None`
    /// outside the crate.
    pub fn resolve(&self, module: &Module, path: &[String]) -> Option<Module> {
        self.resolve_depth(module, path, 0)
    }

    fn resolve_depth(&self, module: &Module, path: &[String], depth: usize) -> Option<Module> {
        if depth > 16 {
            return None;
        }
        let first = path.first()?;
        let (mut at, rest): (Module, &[String]) = match first.as_str() {
            "crate" => (Vec::new(), &path[1..]),
            "self" => (module.clone(), &path[1..]),
            "super" => (module[..module.len().checked_sub(1)?].to_vec(), &path[1..]),
            child if self.files.contains_key(&child_of(module, child)) => (module.clone(), path),
            _ => return None,
        };
        let mut i = 0;
        while i < rest.len() {
            let seg = &rest[i];
            if seg == "super" {
                at.pop()?;
                i += 1;
                continue;
            }
            let next = child_of(&at, seg);
            if !self.files.contains_key(&next) {
                break;
            }
            at = next;
            i += 1;
        }
        let Some(name) = rest.get(i) else {
            return Some(at);
        };
        let file = self.files.get(&at)?;
        if file.defs.contains(name) {
            return Some(at);
        }
        for (used, _) in &file.uses {
            if used.last() == Some(name) {
                // Followed from the file that imports it.
                return self.resolve_depth(&at, used, depth + 1);
            }
        }
        for glob in &file.globs {
            let mut p = glob.clone();
            p.push(name.clone());
            if let Some(t) = self.resolve_depth(&at, &p, depth + 1) {
                if t != at {
                    return Some(t);
                }
            }
        }
        Some(at)
    }
}

fn child_of(m: &Module, name: &str) -> Module {
    let mut c = m.clone();
    c.push(name.to_string());
    c
}

fn walk(dir: &Path, module: &mut Module, out: &mut BTreeMap<Module, File>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    let test_only = test_only_children(dir, module.is_empty());
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
            let m = match stem {
                "mod" => module.clone(),
                "lib" if module.is_empty() => Vec::new(),
                "main" if module.is_empty() => continue,
                // A file of tests only (`foo/tests.rs`) is a test item.
                "tests" => continue,
                // So is a file its parent declares `#[cfg(test)] mod foo;`.
                _ if test_only.iter().any(|t| t == stem) => continue,
                _ => child_of(module, stem),
            };
            let code = std::fs::read_to_string(&p).unwrap();
            out.insert(m, File::new(&code));
        }
    }
}

/// The modules of `dir` that its parent file (`dir/mod.rs`, `dir.rs`
/// beside it, or `lib.rs` at the crate root) declares under `#[cfg(test)]`.
fn test_only_children(dir: &Path, root: bool) -> Vec<String> {
    let parent = if root {
        dir.join("lib.rs")
    } else if dir.join("mod.rs").exists() {
        dir.join("mod.rs")
    } else {
        dir.with_extension("rs")
    };
    let code = std::fs::read_to_string(parent).unwrap_or_default();
    let mut lines = code.lines().map(str::trim).filter(|l| !l.is_empty());
    let mut out = Vec::new();
    while let Some(line) = lines.next() {
        if line != "#[cfg(test)]" {
            continue;
        }
        let Some(next) = lines.next() else { break };
        let decl = next
            .strip_prefix("pub(crate) ")
            .or(next.strip_prefix("pub(super) "))
            .unwrap_or(next);
        if let Some(name) = decl.strip_prefix("mod ").and_then(|r| r.strip_suffix(';')) {
            out.push(name.trim().to_string());
        }
    }
    out
}

/// The code without comments, string and char literals, and without the
/// items marked `#[cfg(test)]` (a test module, inline or in its own file,
/// or a test-only `use`).
pub fn strip(code: &str) -> String {
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
    without_test_items(&out)
}

/// `code` (comments and strings already out) without each item that
/// follows a `#[cfg(test)]`: up to its `;` or its matching `}`.
fn without_test_items(code: &str) -> String {
    const MARK: &str = "#[cfg(test)]";
    let mut out = String::with_capacity(code.len());
    let mut rest = code;
    while let Some(at) = rest.find(MARK) {
        out.push_str(&rest[..at]);
        let item = &rest[at + MARK.len()..];
        let mut depth = 0usize;
        let mut end = item.len();
        for (k, c) in item.char_indices() {
            match c {
                '{' => depth += 1,
                '}' => {
                    depth = depth.saturating_sub(1);
                    if depth == 0 {
                        end = k + 1;
                        break;
                    }
                }
                ';' if depth == 0 => {
                    end = k + 1;
                    break;
                }
                _ => {}
            }
        }
        rest = &item[end..];
    }
    out.push_str(rest);
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
pub enum Tok {
    Ident(String),
    Sep,
    Open,
    Close,
    Comma,
    Other(char),
}

pub fn tokens(code: &str) -> Vec<Tok> {
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
        } else if c == '*' {
            out.push(Tok::Ident("*".into()));
        } else if !c.is_whitespace() {
            out.push(Tok::Other(c));
        }
    }
    out
}

/// The paths of two or more segments written in the code outside `use`
/// declarations (which of them lead into the crate, [`Tree::resolve`]
/// says).
fn code_paths(code: &str) -> Vec<Vec<String>> {
    let toks = tokens(code);
    let mut out = Vec::new();
    let mut i = 0;
    while i < toks.len() {
        if toks[i] == Tok::Ident("use".into()) {
            i = use_tree(&toks, i + 1, &mut Vec::new(), &mut Vec::new());
            continue;
        }
        if let Tok::Ident(first) = &toks[i] {
            let after_sep = i > 0 && toks[i - 1] == Tok::Sep;
            // `pub(super)`, `pub(crate)`, `pub(in a::b)`: a visibility, no path.
            let visibility =
                i >= 2 && toks[i - 1] == Tok::Other('(') && toks[i - 2] == Tok::Ident("pub".into())
                    || i >= 3 && toks[i - 1] == Tok::Ident("in".into());
            let starts = matches!(first.as_str(), "crate" | "super" | "self");
            let more = toks.get(i + 1) == Some(&Tok::Sep);
            if !after_sep && !visibility && (starts || more) {
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
pub fn use_tree(
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
                    // `self` in a group names the group's module.
                    if prefix.last().map(String::as_str) == Some("self") && prefix.len() > 1 {
                        prefix.pop();
                    }
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

/// "a/b"-like name of a module, for messages (`lib` for the root).
pub fn name(m: &Module) -> String {
    if m.is_empty() {
        "lib".into()
    } else {
        m.join("/")
    }
}

/// The import loops of the files under `folder`: every strongly connected
/// component of two or more files (Tarjan), each as its files' names,
/// sorted.
pub fn import_loops(tree: &Tree, folder: &str) -> Vec<Vec<String>> {
    let imports = tree.imports();
    let prefix: Vec<&str> = folder.split('/').filter(|p| !p.is_empty()).collect();
    let inside = |m: &Module| m.len() >= prefix.len() && m.iter().zip(&prefix).all(|(a, b)| a == b);
    let nodes: Vec<&Module> = imports.keys().filter(|m| inside(m)).collect();
    let index_of: BTreeMap<&Module, usize> =
        nodes.iter().enumerate().map(|(i, m)| (*m, i)).collect();
    let edges: Vec<Vec<usize>> = nodes
        .iter()
        .map(|m| {
            imports[*m]
                .iter()
                .filter_map(|t| index_of.get(t).copied())
                .collect()
        })
        .collect();
    tarjan(&edges)
        .into_iter()
        .filter(|c| c.len() > 1)
        .map(|c| {
            let mut names: Vec<String> = c.into_iter().map(|i| name(nodes[i])).collect();
            names.sort();
            names
        })
        .collect()
}

/// The strongly connected components of a graph given as adjacency lists
/// (Tarjan's algorithm, iterative).
fn tarjan(edges: &[Vec<usize>]) -> Vec<Vec<usize>> {
    let n = edges.len();
    let mut index = vec![usize::MAX; n];
    let mut low = vec![0; n];
    let mut on_stack = vec![false; n];
    let mut stack = Vec::new();
    let mut next = 0;
    let mut out = Vec::new();
    for root in 0..n {
        if index[root] != usize::MAX {
            continue;
        }
        // (node, next edge to look at)
        let mut work = vec![(root, 0usize)];
        index[root] = next;
        low[root] = next;
        next += 1;
        stack.push(root);
        on_stack[root] = true;
        while let Some(&mut (v, ref mut k)) = work.last_mut() {
            if let Some(&w) = edges[v].get(*k) {
                *k += 1;
                if index[w] == usize::MAX {
                    index[w] = next;
                    low[w] = next;
                    next += 1;
                    stack.push(w);
                    on_stack[w] = true;
                    work.push((w, 0));
                } else if on_stack[w] {
                    low[v] = low[v].min(index[w]);
                }
            } else {
                work.pop();
                if let Some(&(u, _)) = work.last() {
                    low[u] = low[u].min(low[v]);
                }
                if low[v] == index[v] {
                    let mut c = Vec::new();
                    while let Some(w) = stack.pop() {
                        on_stack[w] = false;
                        c.push(w);
                        if w == v {
                            break;
                        }
                    }
                    out.push(c);
                }
            }
        }
    }
    out
}

/// Every import from a file of a folder to a file of a folder that comes
/// later in `order` (the crate's top-level folders, lowest floor first):
/// "from -> to". Files of folders not in `order` (and the crate root) are
/// reported as "unplaced: name".
pub fn order_breaches(tree: &Tree, order: &[&str]) -> Vec<String> {
    let rank = |m: &Module| -> Option<usize> {
        let top = m.first()?;
        order.iter().position(|o| o == top)
    };
    let mut out = Vec::new();
    for (m, targets) in tree.imports() {
        if m.is_empty() {
            continue;
        }
        let Some(from) = rank(&m) else {
            out.push(format!("unplaced: {}", name(&m)));
            continue;
        };
        for t in targets {
            if let Some(to) = rank(&t) {
                if to > from {
                    out.push(format!("{} -> {}", name(&m), name(&t)));
                }
            }
        }
    }
    out
}
