#!/usr/bin/env python3
"""Counts the core's public surface: `pub mod` declarations and public items
(`pub fn`, `pub struct`, `pub enum`, `pub trait`, `pub type`, `pub const`,
`pub static`, `pub use`; `pub(crate)` and `pub(super)` are not public) in
core/src, inline test modules and `tests.rs` files left out, and the files
and folders they live in.

Usage: scripts/house_counts.py [REPOSITORY_ROOT]   (default: this repository)
"""
import os
import re
import sys

ITEM = re.compile(r"^\s*pub\s+(?:(?:async|unsafe|const)\s+)*(mod|fn|struct|enum|trait|type|const|static|use)\b")


def code_lines(text):
    """The lines before the first `#[cfg(test)]` (the inline tests)."""
    cut = text.find("#[cfg(test)]")
    return (text if cut < 0 else text[:cut]).splitlines()


def counts(root):
    core = os.path.join(root, "core", "src")
    out = {"files": 0, "folders": 0}
    for dirpath, dirnames, filenames in os.walk(core):
        out["folders"] += 1
        for f in filenames:
            if not f.endswith(".rs") or f == "tests.rs" or f.endswith("_tests.rs"):
                continue
            out["files"] += 1
            with open(os.path.join(dirpath, f), encoding="utf-8") as fh:
                for line in code_lines(fh.read()):
                    m = ITEM.match(line)
                    if m:
                        key = "pub " + m.group(1)
                        out[key] = out.get(key, 0) + 1
    out["public items"] = sum(v for k, v in out.items() if k.startswith("pub ") and k != "pub mod")
    return out


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..")
    c = counts(root)
    order = ["files", "folders", "pub mod", "public items", "pub fn", "pub struct", "pub enum",
             "pub trait", "pub type", "pub const", "pub static", "pub use"]
    for k in order:
        print(f"{k}: {c.get(k, 0)}")


if __name__ == "__main__":
    main()
