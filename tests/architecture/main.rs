//! The import rules of the service crate and the core, read from their
//! source files (the graph: `graph.rs`, every file a node, `mod.rs`
//! included, re-exports followed):
//!
//! - the HTTP layer (`src/http`) never names `crate::db`: it calls the
//!   service, which answers with its own types;
//! - the service (`src/service`) never names `crate::http`;
//! - the service re-exports nothing of the store (`pub use crate::db::…`):
//!   the rows both speak of are `crate::records`;
//! - no two files of the service crate (`src`, the binaries aside) import
//!   each other, directly or round a longer loop, nor two files of the core
//!   (`core/src`): every strongly connected component of the import graph is
//!   one file;
//! - the core's top-level folders are floors ([`CORE_FLOORS`], as
//!   docs/architecture.md lists them): a file imports only from its own
//!   floor or the floors below.

mod graph;
mod size;

use graph::{import_loops, name, order_breaches, tokens, use_tree, Module, Tok, Tree};
use std::path::Path;

/// The core's floors, lowest first: a folder may import from the folders
/// before it, never from one after it (docs/architecture.md).
const CORE_FLOORS: &[&str] = &[
    "stats",
    "csv_write",
    "optim",
    "model",
    "measure",
    "calibrate",
    "solve",
    "cell_fit",
    "program",
    "plan",
    "check",
    "sim",
];

/// Import loops known and left, each a parent file (or `mod.rs`) that holds
/// what its children share and calls into them: each breaks by moving the
/// shared piece into a file of its own (as `plan/settings.rs`,
/// `solve/ik/solver/types.rs`, `program/parsed.rs`,
/// `cell_fit/tcp/outcome.rs`, `service/start.rs` and `http/routing.rs`
/// were). None is left; [`known_loop_edges`] prints the arrows inside each
/// listed one. The test fails on any other loop, and on an entry here that
/// no longer loops.
const KNOWN_LOOPS: &[&[&str]] = &[];

fn src() -> Tree {
    Tree::read(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"))
}

fn core() -> Tree {
    Tree::read(&Path::new(env!("CARGO_MANIFEST_DIR")).join("core/src"))
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

/// Every `pub use` (or `pub(crate) use`) path of the files under `folder`.
fn public_uses(tree: &Tree, folder: &str) -> Vec<(Module, Vec<String>)> {
    let mut out = Vec::new();
    for (m, file) in &tree.files {
        if m.first().map(String::as_str) != Some(folder) {
            continue;
        }
        let toks = tokens(&file.code);
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

/// The loops of `tree` that are not known, as "a <-> b <-> c" lines.
fn unknown_loops(tree: &Tree) -> Vec<String> {
    import_loops(tree, "")
        .into_iter()
        .filter(|c| !KNOWN_LOOPS.iter().any(|k| k.iter().eq(c.iter())))
        .map(|c| c.join(" <-> "))
        .collect()
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
    let loops = unknown_loops(&src());
    assert!(loops.is_empty(), "import loops in src: {loops:#?}");
}

#[test]
fn no_two_core_files_import_each_other() {
    let loops = unknown_loops(&core());
    assert!(loops.is_empty(), "import loops in core/src: {loops:#?}");
}

#[test]
fn the_core_imports_only_from_its_own_floor_or_below() {
    let breaches = order_breaches(&core(), CORE_FLOORS);
    assert!(
        breaches.is_empty(),
        "core/src floors, lowest first, {CORE_FLOORS:?}: an import upwards (or a folder not placed) {breaches:#?}"
    );
}

#[test]
fn the_known_loops_are_still_loops() {
    // An entry that no longer loops must leave the list.
    let mut loops = import_loops(&core(), "");
    loops.extend(import_loops(&src(), ""));
    for k in KNOWN_LOOPS {
        assert!(
            loops.iter().any(|c| k.iter().eq(c.iter())),
            "no longer a loop, drop it from KNOWN_LOOPS: {k:?}"
        );
    }
}

mod checker;

/// The imports between the core's folders, with counts (`cargo test --test
/// architecture core_folder_imports -- --nocapture`): what the floor order
/// rests on.
#[test]
fn core_folder_imports() {
    let mut counts = std::collections::BTreeMap::new();
    for (m, targets) in core().imports() {
        for t in targets {
            let (Some(a), Some(b)) = (m.first(), t.first()) else {
                continue;
            };
            if a != b {
                *counts.entry((a.clone(), b.clone())).or_insert(0) += 1;
            }
        }
    }
    for ((a, b), n) in &counts {
        println!("{a} -> {b}: {n}");
    }
    assert!(!counts.is_empty());
}

/// The imports inside each known loop (`cargo test --test architecture
/// known_loop_edges -- --nocapture`): the arrows a fix has to cut.
#[test]
fn known_loop_edges() {
    for tree in [core(), src()] {
        let imports = tree.imports();
        for k in KNOWN_LOOPS {
            for (m, targets) in &imports {
                if !k.contains(&name(m).as_str()) {
                    continue;
                }
                for t in targets {
                    if k.contains(&name(t).as_str()) && t != m {
                        println!("{} -> {}", name(m), name(t));
                    }
                }
            }
        }
    }
}
