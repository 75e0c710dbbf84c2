#!/usr/bin/env bash
# HTTP throughput of the solve endpoint measured from outside with wrk
# (Debian package `wrk`), on loopback, client and servers on the same machine:
# one `robocal serve` on SQLite against two replicas on one PostgreSQL behind
# a load balancer.
#
#   scripts/wrk.sh                      (builds the release binaries first)
#   WRK_ROUNDS=2 scripts/wrk.sh         both backends back to back, twice
#   WRK_BACKENDS=sqlite scripts/wrk.sh  the SQLite replica only
#   WRK_LB=lua scripts/wrk.sh           no haproxy: wrk's threads split over the replicas
#
# SQLite: one replica on a temporary file. PostgreSQL: a throw-away cluster
# (scripts/pg_temp.sh, Debian's package, with pg_stat_statements loaded), two
# replicas on one database, and haproxy (Debian's, installed when missing)
# with a config generated for the two ports: round robin, health checked on
# /readyz like deploy/haproxy.cfg. With WRK_LB=lua, or when haproxy cannot
# start, wrk's Lua `setup` gives each wrk thread one replica's address
# instead (the batch run's single thread then uses one replica).
#
# Each backend is seeded alike (a YS100 calibrated with KM + SKCM on
# simulated data, scripts/schemathesis_seed.py); the request bodies come from
# `robocal-load --write-bodies` once and serve both. wrk runs single-target
# solves on 16 connections (2 threads) and 1000-target batches one at a time,
# latencies from `wrk --latency`. Printed per run: requests/s, p50/p99, the
# replicas' CPU time per request (user + system; haproxy's apart) and, on
# PostgreSQL, the statements the database executed during the run
# (pg_stat_statements), all and those other than the job runners' timed
# claims and haproxy's /readyz: the solve path must not query per request (a
# replica loads a robot on its first solves: a 2 s warm-up per backend comes
# first, its statements printed). The end prints a table and the ratios
# PostgreSQL / SQLite per round.
set -euo pipefail
cd "$(dirname "$0")/.."
DURATION=${WRK_DURATION:-15s}
ROUNDS=${WRK_ROUNDS:-1}
BACKENDS=${WRK_BACKENDS:-sqlite postgres}
LB=${WRK_LB:-haproxy}
command -v wrk >/dev/null || { apt-get update -qq && apt-get install -y -qq wrk >/dev/null; }
if [[ $BACKENDS == *postgres* && $LB == haproxy ]] && ! command -v haproxy >/dev/null; then
    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq haproxy >/dev/null || true
fi
cargo build --release --bins -q
WORK=$(mktemp -d)
chmod 755 "$WORK" # the PostgreSQL cluster inside belongs to `postgres`
declare -A PID ADDR
PG_UP=
cleanup() {
    local p
    for p in "${PID[@]}"; do kill "$p" 2>/dev/null || true; done
    wait 2>/dev/null || true
    [ -n "$PG_UP" ] && scripts/pg_temp.sh stop "$WORK/pg" >/dev/null 2>&1
    rm -rf "$WORK"
}
trap cleanup EXIT
free_port() { python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'; }

# start_server NAME DATABASE_URL: PID[NAME], ADDR[NAME].
start_server() {
    local name=$1 url=$2 a=
    RUST_LOG=warn,robocal::cli::serve=info target/release/robocal serve --bind 127.0.0.1:0 \
        --database-url "$url" 2>"$WORK/$name.log" &
    PID[$name]=$!
    for _ in $(seq 1 300); do
        a=$(sed -n 's/.*listening on http:\/\/\([0-9.:]*\).*/\1/p' "$WORK/$name.log" 2>/dev/null | head -1 || true)
        [ -n "$a" ] && break
        sleep 0.1
    done
    [ -n "$a" ] || { cat "$WORK/$name.log" >&2; exit 1; }
    ADDR[$name]=$a
}

target/release/robocal simulate --preset ys100 --poses 30 --seed 1 --out "$WORK/q1.csv" >/dev/null
target/release/robocal simulate --preset ys100 --poses 30 --seed 2 --out "$WORK/q3.csv" >/dev/null
seed() { python3 scripts/schemathesis_seed.py "http://$1" none "$WORK/q1.csv" "$WORK/q3.csv"; }

declare -A URL CPU_PIDS
if [[ $BACKENDS == *sqlite* ]]; then
    start_server sqlite "sqlite://$WORK/wrk.db?mode=rwc"
    seed "${ADDR[sqlite]}"
    URL[sqlite]="http://${ADDR[sqlite]}"
    CPU_PIDS[sqlite]=${PID[sqlite]}
fi
if [[ $BACKENDS == *postgres* ]]; then
    PG_ADMIN=$(PG_TEMP_OPTS="-c shared_preload_libraries=pg_stat_statements" \
        scripts/pg_temp.sh start "$WORK/pg" "${WRK_PG_PORT:-$(free_port)}")
    PG_UP=1
    psql -q "$PG_ADMIN" -c "CREATE DATABASE wrk"
    PG_URL=${PG_ADMIN%/postgres}/wrk
    psql -q "$PG_URL" -c "CREATE EXTENSION pg_stat_statements"
    start_server pg_a "$PG_URL"
    start_server pg_b "$PG_URL"
    seed "${ADDR[pg_a]}"
    CPU_PIDS[postgres]="${PID[pg_a]} ${PID[pg_b]}"
    if [ "$LB" = haproxy ] && command -v haproxy >/dev/null; then
        LB_PORT=$(free_port)
        cat >"$WORK/haproxy.cfg" <<CFG
global
    maxconn 4096
defaults
    mode http
    timeout connect 5s
    timeout client 120s
    timeout server 120s
frontend robocal
    bind 127.0.0.1:$LB_PORT
    default_backend replicas
backend replicas
    balance roundrobin
    option httpchk GET /readyz
    http-check expect status 200
    default-server inter 2s fall 2 rise 2
    server a ${ADDR[pg_a]} check
    server b ${ADDR[pg_b]} check
CFG
        haproxy -db -f "$WORK/haproxy.cfg" >"$WORK/haproxy.log" 2>&1 &
        PID[haproxy]=$!
        ok=0
        for _ in $(seq 1 100); do
            if curl -sf "http://127.0.0.1:$LB_PORT/readyz" >/dev/null; then ok=$((ok + 1)); fi
            [ "$ok" -ge 4 ] && break
            sleep 0.1
        done
        if [ "$ok" -ge 4 ]; then
            URL[postgres]="http://127.0.0.1:$LB_PORT"
            echo "PostgreSQL: two replicas (${ADDR[pg_a]}, ${ADDR[pg_b]}) behind haproxy on 127.0.0.1:$LB_PORT"
        else
            echo "haproxy did not start ($(cat "$WORK/haproxy.log")); falling back to wrk's Lua split" >&2
            kill "${PID[haproxy]}" 2>/dev/null || true
            unset 'PID[haproxy]'
            LB=lua
        fi
    else
        LB=lua
    fi
    if [ "$LB" = lua ]; then
        URL[postgres]="http://${ADDR[pg_a]}"
        TARGETS="${ADDR[pg_a]} ${ADDR[pg_b]}"
        echo "PostgreSQL: two replicas (${ADDR[pg_a]}, ${ADDR[pg_b]}), wrk's threads split over them (no load balancer)"
    fi
fi

first=${BACKENDS%% *}
target/release/robocal-load --url "${URL[$first]}" --robot 1 --write-bodies "$WORK"
cat >"$WORK/post.lua" <<'LUA'
wrk.method = "POST"
wrk.headers["Content-Type"] = "application/json"
local f = io.open(os.getenv("BODY"), "rb"); wrk.body = f:read("*a"); f:close()
function response(status, headers, body)
  if status ~= 200 then error("status " .. status) end
end
-- TARGETS="host:port host:port": wrk thread i sends to address i (round robin).
local targets, addrs, threads = os.getenv("TARGETS"), {}, 0
if targets and targets ~= "" then
  function setup(thread)
    if #addrs == 0 then
      for host, port in targets:gmatch("([^%s:]+):(%d+)") do
        addrs[#addrs + 1] = wrk.lookup(host, port)[1]
      end
    end
    thread.addr = addrs[threads % #addrs + 1]
    threads = threads + 1
  end
end
LUA

# CPU time (user + system) of processes in clock ticks: independent of what
# else runs on the machine, unlike requests/s.
cpu_ticks() { local t=0 p; for p in "$@"; do t=$((t + $(awk '{print $14 + $15}' "/proc/$p/stat"))); done; echo $t; }
# Statements the robocal database executed (pg_stat_statements), the stats queries aside.
pg_sql() { psql -qAtX "$PG_URL" -c "$1"; }
PG_STMTS="FROM pg_stat_statements WHERE dbid = (SELECT oid FROM pg_database WHERE datname = 'wrk') AND query NOT LIKE '%pg_stat_statements%'"
to_ms() { awk '{ v = $1 + 0; if ($1 ~ /us$/) v /= 1000; else if ($1 ~ /ms$/) v *= 1; else if ($1 ~ /m$/) v *= 60000; else if ($1 ~ /s$/) v *= 1000; printf "%.3f", v }'; }

# run ROUND BACKEND KIND BODY wrk-args... (ROUND 0: the warm-up, not in the summary)
run() {
    local round=$1 backend=$2 kind=$3 body=$4; shift 4
    echo "== $([ "$round" = 0 ] && echo warm-up || echo "round $round"), $backend, $kind: wrk $*"
    local before lb_before=0 out requests rps p50 p99 ticks cpu stmts=- solve
    [ "$backend" = postgres ] && pg_sql "SELECT pg_stat_statements_reset()" >/dev/null
    before=$(cpu_ticks ${CPU_PIDS[$backend]})
    [ "$backend" = postgres ] && [ -n "${PID[haproxy]:-}" ] && lb_before=$(cpu_ticks "${PID[haproxy]}")
    out=$(BODY="$body" TARGETS="$([ "$backend" = postgres ] && echo "${TARGETS:-}")" \
        wrk "$@" --latency -s "$WORK/post.lua" "${URL[$backend]}/v1/robots/1/solve")
    ticks=$(($(cpu_ticks ${CPU_PIDS[$backend]}) - before))
    echo "$out"
    requests=$(echo "$out" | awk '/requests in/ {print $1}')
    rps=$(echo "$out" | awk '/^Requests\/sec:/ {print $2}')
    p50=$(echo "$out" | awk '$1 == "50%" {print $2}' | to_ms)
    p99=$(echo "$out" | awk '$1 == "99%" {print $2}' | to_ms)
    cpu=$(awk -v t="$ticks" -v hz="$(getconf CLK_TCK)" -v n="$requests" 'BEGIN { printf "%.1f", t / hz / n * 1e6 }')
    echo "server CPU per request: $cpu us ($requests requests; all replicas)"
    if [ "$backend" = postgres ]; then
        [ -n "${PID[haproxy]:-}" ] && awk -v t="$(($(cpu_ticks "${PID[haproxy]}") - lb_before))" \
            -v hz="$(getconf CLK_TCK)" -v n="$requests" \
            'BEGIN { printf "haproxy CPU per request: %.1f us\n", t / hz / n * 1e6 }'
        # The runners' job claims and the load balancer's /readyz are timed, not per request.
        stmts=$(pg_sql "SELECT coalesce(sum(calls), 0) $PG_STMTS")
        solve=$(pg_sql "SELECT coalesce(sum(calls), 0) $PG_STMTS AND query NOT LIKE '%FROM calibrations%'
            AND query NOT LIKE '%_sqlx_migrations%'")
        echo "PostgreSQL statements during the run: $stmts for $requests requests, $solve of them" \
            "neither a job claim nor a readiness check; by statement:"
        stmts="$stmts/$solve"
        pg_sql "SELECT calls || '  ' || left(regexp_replace(query, '\s+', ' ', 'g'), 90) $PG_STMTS ORDER BY calls DESC LIMIT 5" |
            sed 's/^/    /'
    fi
    [ "$round" = 0 ] && return
    printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$round" "$backend" "$kind" "$rps" "$p50" "$p99" "$cpu" "$stmts" >>"$WORK/results.tsv"
}

# Each replica loads the robot on its first solves (on PostgreSQL: the robot,
# its versions and the active model file, once per replica and request that
# finds the cache empty).
for backend in $BACKENDS; do
    run 0 "$backend" single "$WORK/single.json" -t2 -c16 -d2s >"$WORK/warmup.log"
    grep -E '^(Requests/sec|PostgreSQL statements)' "$WORK/warmup.log" | sed "s/^/warm-up, $backend: /"
done
for round in $(seq 1 "$ROUNDS"); do
    for backend in $BACKENDS; do
        run "$round" "$backend" single "$WORK/single.json" -t2 -c16 -d"$DURATION"
        run "$round" "$backend" batch "$WORK/batch.json" -t1 -c1 -d"$DURATION"
    done
done

echo
echo "== summary$([[ $BACKENDS == *postgres* ]] && echo " (PostgreSQL: two replicas, load balancer: $LB)")"
printf 'round\tbackend\trun\treq/s\tp50 ms\tp99 ms\tCPU us/req\tdb statements (all/solve path)\n'
cat "$WORK/results.tsv"
if [[ $BACKENDS == *sqlite* && $BACKENDS == *postgres* ]]; then
    awk -F'\t' '
        { v[$1, $2, $3, "rps"] = $4; v[$1, $2, $3, "p50"] = $5; v[$1, $2, $3, "p99"] = $6; v[$1, $2, $3, "cpu"] = $7; if ($1 > n) n = $1 }
        END {
            print "ratios PostgreSQL / SQLite:"
            for (r = 1; r <= n; r++)
                printf "round %d: single-target req/s %.2f, CPU per request %.2f; batch p50 %.2f, p99 %.2f\n", r,
                    v[r, "postgres", "single", "rps"] / v[r, "sqlite", "single", "rps"],
                    v[r, "postgres", "single", "cpu"] / v[r, "sqlite", "single", "cpu"],
                    v[r, "postgres", "batch", "p50"] / v[r, "sqlite", "batch", "p50"],
                    v[r, "postgres", "batch", "p99"] / v[r, "sqlite", "batch", "p99"]
        }' "$WORK/results.tsv"
fi
