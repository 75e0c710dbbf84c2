#!/usr/bin/env bash
# Bounded fuzzing of the parsers with cargo-fuzz (libFuzzer) on the stable
# toolchain (`--sanitizer none`: coverage-guided, no sanitizer; the code under
# test is safe Rust, so what is looked for is panics, overflows caught by debug
# assertions, hangs and broken round trips).
#
#   scripts/fuzz.sh [SECONDS_PER_TARGET]     (default 60)
#   scripts/fuzz.sh --build-only             (install cargo-fuzz, build the targets)
#
# Targets (fuzz/fuzz_targets/): measurement_csv, targets_csv, model_json,
# solve_request and the program parsers program_krl, program_rapid,
# program_fanuc, program_urscript (with the filter), and plan_join (the plan
# CSV and the tracker export join).
# Each run starts from the seeds in fuzz/seeds/<target>/ with a
# fixed libFuzzer seed and writes new inputs to a temporary corpus, so the
# repository is not changed. A crash leaves its input in
# fuzz/artifacts/<target>/ and fails the script; turn it into a regression
# test in tests/fuzz_regressions.rs.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_ONLY=
if [ "${1:-}" = "--build-only" ]; then
    BUILD_ONLY=1
    shift
fi
SECS=${1:-60}
VERSION=0.13.2
if ! cargo fuzz --version 2>/dev/null | grep -q "$VERSION"; then
    cargo install cargo-fuzz --locked --version "$VERSION"
fi
cd fuzz
cargo fuzz build --sanitizer none
[ -z "$BUILD_ONLY" ] || exit 0
# One libFuzzer process per target, as many at once as there are cores
# (`FUZZ_JOBS`, default `nproc`): each is single-threaded, so the targets
# share the wall time instead of queueing.
JOBS=${FUZZ_JOBS:-$(nproc)}
fuzz_one() {
    local target=$1 corpus log code=0 runs new
    corpus=$(mktemp -d)
    log=$(mktemp)
    cargo fuzz run --sanitizer none "$target" "$corpus" "seeds/$target" -- \
        -max_total_time="$SECS" -seed=1 -timeout=10 -rss_limit_mb=2048 \
        -max_len=8192 -print_final_stats=1 >"$log" 2>&1 || code=$?
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log")
    new=$(sed -n 's/^stat::new_units_added: *//p' "$log")
    if [ "$code" -ne 0 ]; then
        tail -40 "$log" >&2
        echo "fuzz: $target FAILED after ${runs:-?} runs; the input is in fuzz/artifacts/$target/" >&2
    else
        echo "fuzz: $target: ${runs:-?} inputs in ${SECS} s, ${new:-?} new coverage units, no failure"
    fi
    rm -rf "$corpus" "$log"
    return "$code"
}
status=0
running=()
for target in measurement_csv targets_csv model_json solve_request \
    program_krl program_rapid program_fanuc program_urscript plan_join; do
    if [ "${#running[@]}" -ge "$JOBS" ]; then
        wait "${running[0]}" || status=1
        running=("${running[@]:1}")
    fi
    fuzz_one "$target" &
    running+=("$!")
done
for pid in "${running[@]}"; do
    wait "$pid" || status=1
done
exit $status
