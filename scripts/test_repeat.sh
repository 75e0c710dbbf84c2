#!/usr/bin/env bash
# Runs a test command several times in a row under one condition and prints
# one line per run (exit code, wall seconds, load average), so that "fast,
# slow and loaded give the same verdict" can be shown on any machine:
#
#   scripts/test_repeat.sh idle   5 [cargo test args...]   # as it is
#   scripts/test_repeat.sh pinned 5 [cargo test args...]   # taskset -c 0: one core
#   scripts/test_repeat.sh hog    5 [cargo test args...]   # a busy loop on every core beside it
#
# Without cargo test args it runs the whole suite (`cargo test`, the README's
# command). Logs: target/test-repeat/<condition>-<run>.log. Exits non-zero
# when any run failed.
set -uo pipefail
cd "$(dirname "$0")/.."
COND=${1:?condition: idle, pinned or hog}
RUNS=${2:-5}
shift 2 || shift $#
PREFIX=()
HOGS=()
case "$COND" in
    idle) ;;
    pinned) PREFIX=(taskset -c 0) ;;
    hog)
        for _ in $(seq "$(nproc)"); do
            (while :; do :; done) &
            HOGS+=($!)
        done
        ;;
    *) echo "unknown condition $COND (idle, pinned, hog)" >&2; exit 1 ;;
esac
cleanup() { [ ${#HOGS[@]} -eq 0 ] || kill "${HOGS[@]}" 2>/dev/null || true; }
trap cleanup EXIT
mkdir -p target/test-repeat
failed=0
for i in $(seq "$RUNS"); do
    log=target/test-repeat/$COND-$i.log
    start=$(date +%s)
    "${PREFIX[@]}" cargo test "$@" >"$log" 2>&1
    code=$?
    [ "$code" -eq 0 ] || failed=1
    echo "$COND run $i: exit $code, $(( $(date +%s) - start )) s, load $(cut -d' ' -f1-3 /proc/loadavg), $(grep -c '^test result: ok' "$log") binaries ok, log $log"
done
exit "$failed"
