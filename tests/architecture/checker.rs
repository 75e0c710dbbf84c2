//! The checker itself, on small trees whose answer is known: it must fail
//! on a planted back arrow and a planted loop (their messages are printed:
//! `cargo test --test architecture checker -- --nocapture`).

use super::graph::{import_loops, order_breaches, Tree};
use super::{layer_breaches, public_uses};

fn m(path: &str) -> Vec<String> {
    path.split('/').map(String::from).collect()
}

#[test]
fn the_checker_sees_grouped_nested_and_inline_paths() {
    let t = Tree::of(&[
        ("", "pub mod db; pub mod http; pub mod service;"),
        ("db/mod", "pub mod rows; pub struct Row;"),
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
    let run = &imports[&m("service/jobs/run")];
    assert!(run.contains(&m("service/a")));
    assert!(run.contains(&m("service/b")));
    // a -> run -> a is a loop.
    let loops = import_loops(&t, "");
    assert_eq!(loops, vec![vec!["service/a", "service/jobs/run"]]);
}

#[test]
fn the_checker_sees_a_store_type_re_exported() {
    let t = Tree::of(&[
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
        .map(|(m, p)| format!("{}: {}", super::name(&m), p.join("::")))
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
    let t = Tree::of(&[
        ("service/mod", "pub mod a; pub mod b; pub use b::T;"),
        ("service/a", "use super::b::f; use super::T;"),
        ("service/b", "pub struct T; fn g() -> self::U {}"),
        ("service/c", "use crate::http::Thing;"),
        ("http/mod", "pub struct Thing;"),
    ]);
    assert!(import_loops(&t, "").is_empty());
    assert_eq!(
        layer_breaches(&t, "service", "http"),
        vec!["service/c -> http"]
    );
    // `super::T` is followed through the re-export to `b`.
    assert!(t.imports()[&m("service/a")].contains(&m("service/b")));
    assert!(!t.imports()[&m("service/a")].contains(&m("service")));
}

/// A folder's `mod.rs` is a node: a child that uses what its `mod.rs`
/// defines, while the `mod.rs` calls into the child by a relative path, is
/// a loop, named with both files.
#[test]
fn a_planted_loop_through_a_mod_rs_fails() {
    let t = Tree::of(&[
        ("", "pub mod cli;"),
        (
            "cli/mod",
            "pub mod plan; pub struct Args; fn run(a: Args) { plan::run(a) }",
        ),
        ("cli/plan", "use super::Args; pub fn run(a: Args) {}"),
        ("cli/other", "use super::Args;"),
    ]);
    let loops = import_loops(&t, "");
    println!("planted loop: {loops:?}");
    assert_eq!(loops, vec![vec!["cli", "cli/plan"]]);
}

/// A loop round three files, one edge hidden behind a re-export.
#[test]
fn a_planted_loop_behind_a_re_export_fails() {
    let t = Tree::of(&[
        ("a/mod", "mod x; mod y; mod z; pub use z::Zed;"),
        ("a/x", "use super::y::Why; pub struct Ex;"),
        ("a/y", "use super::Zed; pub struct Why;"),
        ("a/z", "use crate::a::x::Ex; pub struct Zed;"),
    ]);
    let loops = import_loops(&t, "");
    println!("planted loop behind a re-export: {loops:?}");
    assert_eq!(loops, vec![vec!["a/x", "a/y", "a/z"]]);
}

/// An import from a lower floor to a higher one is named; one downwards is
/// not, nor one within a floor.
#[test]
fn a_planted_back_arrow_fails() {
    let t = Tree::of(&[
        ("", "pub mod model; pub mod calibrate;"),
        ("model/mod", "pub mod bounds; pub mod robot;"),
        ("model/robot", "pub struct Robot;"),
        (
            "model/bounds",
            "use crate::calibrate::compensate::Stored; use super::robot::Robot;",
        ),
        ("calibrate/mod", "pub mod compensate;"),
        (
            "calibrate/compensate",
            "pub struct Stored; use crate::model::robot::Robot;",
        ),
    ]);
    let breaches = order_breaches(&t, &["model", "calibrate"]);
    println!("planted back arrow: {breaches:?}");
    assert_eq!(breaches, vec!["model/bounds -> calibrate/compensate"]);
    // A folder left out of the order is named too.
    assert_eq!(
        order_breaches(&t, &["model"]),
        vec!["unplaced: calibrate", "unplaced: calibrate/compensate"]
    );
}

/// Test items are no imports, wherever they sit.
#[test]
fn test_items_are_left_out() {
    let t = Tree::of(&[
        ("a/mod", "pub mod b;\n#[cfg(test)]\nuse crate::a::b::X;\npub struct Y;"),
        ("a/b", "pub struct X; use super::Y;\n#[cfg(test)]\nmod tests { use crate::c::Z; }\nfn after() {}"),
        ("c", "pub struct Z;"),
    ]);
    assert!(import_loops(&t, "").is_empty());
    assert!(!t.imports()[&m("a/b")].contains(&m("c")));
}

/// A file its parent declares `#[cfg(test)] mod f;` is a test item too: read
/// from disk, it is no node, while its untested sibling is.
#[test]
fn files_declared_for_tests_only_are_left_out() {
    let root = std::env::temp_dir().join(format!("robocal-arch-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    std::fs::create_dir_all(root.join("a")).unwrap();
    let write = |p: &str, code: &str| std::fs::write(root.join(p), code).unwrap();
    write("lib.rs", "pub mod a;\npub mod c;\n");
    write("a/mod.rs", "pub mod b;\n#[cfg(test)]\nmod fixture;\n");
    write("a/b.rs", "pub struct X;\n");
    write("a/fixture.rs", "use crate::c::Z;\n");
    write("c.rs", "pub struct Z; use crate::a::b::X;\n");
    let t = Tree::read(&root);
    std::fs::remove_dir_all(&root).unwrap();
    assert!(t.files.contains_key(&m("a/b")));
    assert!(!t.files.contains_key(&m("a/fixture")));
    assert!(import_loops(&t, "").is_empty());
}
