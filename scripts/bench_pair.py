#!/usr/bin/env python3
"""Criterion benchmarks of two commits against each other, as ratios.

    scripts/bench_pair.py OLD NEW [--rounds N] [--pin CPU] [--bins DIR] [--no-build] BENCH[:FILTER] ...

Builds the bench binaries of both commits (release, `cargo bench --no-run`,
each in a detached worktree under DIR, one shared target directory so the
dependencies build once), then runs each BENCH of both alternately, N rounds
(old first in even rounds, new first in odd ones, so a drift of the machine
falls on both), optionally pinned to one CPU with taskset. Prints per
benchmark the median of the rounds' criterion estimates and new/old.
BENCH is a bench target of the root crate or the core (`ik`, `calibration`,
`ik_newton`, `compensate`, `filter`); FILTER is criterion's regex.
"""
import argparse
import json
import os
import re
import shutil
import statistics
import subprocess
import sys

UNIT = {"ps": 1e-12, "ns": 1e-9, "µs": 1e-6, "us": 1e-6, "ms": 1e-3, "s": 1.0}
TIME = re.compile(r"time:\s+\[[\d.]+ \S+ ([\d.]+) (\S+) [\d.]+ \S+\]")


def build(repo, rev, bins, tag):
    tree = os.path.join(bins, "tree-" + tag)
    if not os.path.isdir(tree):
        subprocess.run(["git", "-C", repo, "worktree", "add", "--detach", tree, rev], check=True)
    env = dict(os.environ, CARGO_TARGET_DIR=os.path.join(bins, "target"))
    out = subprocess.run(
        ["cargo", "bench", "--no-run", "-p", "robocal", "-p", "robocal-core",
         "--message-format=json"],
        cwd=tree, env=env, capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"{rev}: cargo bench --no-run failed:\n{out.stderr[-3000:]}")
    for line in out.stdout.splitlines():
        m = json.loads(line)
        if (m.get("reason") == "compiler-artifact" and m.get("executable")
                and "bench" in m["target"]["kind"]):
            shutil.copy(m["executable"], os.path.join(bins, f"{tag}_{m['target']['name']}"))


def run(binary, filt, pin):
    cmd = [binary, "--bench", "--noplot", "--warm-up-time", "1", "--measurement-time", "4",
           "--discard-baseline"] + ([filt] if filt else [])
    if pin is not None:
        cmd = ["taskset", "-c", str(pin)] + cmd
    os.makedirs("/tmp/bench_pair", exist_ok=True)
    out = subprocess.run(cmd, cwd="/tmp/bench_pair", capture_output=True, text=True, check=True)
    found, name = {}, None
    for line in out.stdout.splitlines():
        m = TIME.search(line)
        head = line.split("time:")[0].strip()
        if head and not line.startswith(("Benchmarking", "Found", "Warning", " ")):
            name = head
        if m and name:
            found[name] = float(m.group(1)) * UNIT[m.group(2)]
    return found


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("benches", nargs="+")
    ap.add_argument("--rounds", type=int, default=4)
    ap.add_argument("--pin", type=int)
    ap.add_argument("--bins", default="/tmp/bench_pair_bins")
    ap.add_argument("--no-build", action="store_true",
                    help="use the old_BENCH and new_BENCH binaries already in --bins")
    a = ap.parse_args()
    repo = subprocess.run(["git", "rev-parse", "--show-toplevel"], capture_output=True,
                          text=True, check=True).stdout.strip()
    os.makedirs(a.bins, exist_ok=True)
    if not a.no_build:
        for tag, rev in (("old", a.old), ("new", a.new)):
            build(repo, rev, a.bins, tag)
    for spec in a.benches:
        bench, _, filt = spec.partition(":")
        times = {}
        for r in range(a.rounds):
            for tag in (("old", "new") if r % 2 == 0 else ("new", "old")):
                for name, t in run(os.path.join(a.bins, f"{tag}_{bench}"), filt, a.pin).items():
                    times.setdefault(name, {}).setdefault(tag, []).append(t)
        for name, by in times.items():
            old, new = statistics.median(by["old"]), statistics.median(by["new"])
            print(f"{bench:12} {name:55} old {old * 1e6:12.3f} µs  new {new * 1e6:12.3f} µs  "
                  f"new/old {new / old:.3f}  ({len(by['old'])} rounds)")


if __name__ == "__main__":
    main()
