#!/usr/bin/env bash
# What the second core saves in CI's longest test binary: core/tests/compensate.rs
# (the real UR5 and WAM calibrations with auto among them), built as `cargo test`
# builds it and run whole, as `cargo test` runs it (two tests at a time on two
# cores), twice: with every cross-validation's folds and region refits one after
# another on one thread (ROBOCAL_TEST_THREADS=1), then side by side on the cores
# available. Prints wall and processor seconds of each; the figures and choices
# the tests assert are the same in both. Run it on an otherwise idle machine.
set -euo pipefail
cd "$(dirname "$0")/.."
# Built at the workspace's root, as CI's `cargo test` builds it (its features
# unified with the service's), and run from core/, as cargo runs it.
bin=$(cargo test --test compensate --no-run --message-format=json 2>/dev/null |
    python3 -c 'import json,sys
for l in sys.stdin:
    m=json.loads(l)
    if m.get("reason")=="compiler-artifact" and m["target"]["name"]=="compensate" and m.get("executable"):
        print(m["executable"])')
cd core
run() {
    local label=$1
    shift
    local t
    t=$(mktemp)
    env "$@" /usr/bin/time -f "%e %U %S" -o "$t" "$bin" >/dev/null 2>&1 || { echo "$label: the tests failed"; exit 1; }
    read -r wall user sys <"$t"
    rm -f "$t"
    python3 -c "import sys; w,u,s=map(float,sys.argv[2:]); print(f'{sys.argv[1]}: wall {w:.0f} s, processor {u+s:.0f} s, {100*(u+s)/w:.0f} % of a core')" "$label" "$wall" "$user" "$sys"
}
run "folds one after another" ROBOCAL_TEST_THREADS=1
run "folds side by side     " ROBOCAL_TEST_THREADS_UNSET=1
