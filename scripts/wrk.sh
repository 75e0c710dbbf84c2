#!/usr/bin/env bash
# HTTP throughput of the solve endpoint measured from outside with wrk
# (Debian package `wrk`), on loopback, client and server on the same machine.
#
#   scripts/wrk.sh            (builds the release binaries first)
#
# Starts `robocal serve` with a temporary database, seeds a YS100 calibrated
# with KM + SKCM on simulated data (scripts/schemathesis_seed.py), writes a
# single-target and a 1000-target request body with `robocal-load
# --write-bodies`, then runs wrk: single-target solves on 16 connections
# (2 threads), and 1000-target batches one at a time; latencies from
# `wrk --latency`.
set -euo pipefail
cd "$(dirname "$0")/.."
DURATION=${WRK_DURATION:-15s}
command -v wrk >/dev/null || { apt-get update -qq && apt-get install -y -qq wrk >/dev/null; }
cargo build --release --bins -q
WORK=$(mktemp -d)
SERVER_PID=
cleanup() { [ -n "$SERVER_PID" ] && kill "$SERVER_PID" 2>/dev/null; wait 2>/dev/null; rm -rf "$WORK"; }
trap cleanup EXIT
RUST_LOG=warn,robocal::cli::serve=info target/release/robocal serve --bind 127.0.0.1:0 \
    --database-url "sqlite://$WORK/wrk.db?mode=rwc" 2> "$WORK/server.log" &
SERVER_PID=$!
for _ in $(seq 1 100); do
    ADDR=$(sed -n 's/.*listening on http:\/\/\([0-9.:]*\).*/\1/p' "$WORK/server.log" 2>/dev/null | head -1 || true)
    [ -n "$ADDR" ] && break
    sleep 0.1
done
target/release/robocal simulate --preset ys100 --poses 30 --seed 1 --out "$WORK/q1.csv" >/dev/null
target/release/robocal simulate --preset ys100 --poses 30 --seed 2 --out "$WORK/q3.csv" >/dev/null
python3 scripts/schemathesis_seed.py "http://$ADDR" none "$WORK/q1.csv" "$WORK/q3.csv"
target/release/robocal-load --url "http://$ADDR" --robot 1 --write-bodies "$WORK"
cat > "$WORK/post.lua" <<LUA
wrk.method = "POST"
wrk.headers["Content-Type"] = "application/json"
local f = io.open(os.getenv("BODY"), "rb"); wrk.body = f:read("*a"); f:close()
function response(status, headers, body)
  if status ~= 200 then error("status " .. status) end
end
LUA
# Server CPU time (user + system) per request: independent of what else runs
# on the machine, unlike requests/s.
cpu_ticks() { awk '{print $14 + $15}' "/proc/$SERVER_PID/stat"; }
run() {
    local label=$1 body=$2; shift 2
    echo "== $label: wrk $*"
    local before out requests
    before=$(cpu_ticks)
    out=$(BODY="$body" wrk "$@" --latency -s "$WORK/post.lua" "http://$ADDR/v1/robots/1/solve")
    echo "$out"
    requests=$(echo "$out" | awk '/requests in/ {print $1}')
    awk -v t="$(( $(cpu_ticks) - before ))" -v hz="$(getconf CLK_TCK)" -v n="$requests" \
        'BEGIN { printf "server CPU per request: %.1f us (%d requests)\n", t / hz / n * 1e6, n }'
}
run "single-target solves" "$WORK/single.json" -t2 -c16 -d"$DURATION"
run "1000-target batches, one at a time" "$WORK/batch.json" -t1 -c1 -d"$DURATION"
