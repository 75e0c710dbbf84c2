#!/usr/bin/env bash
# API fuzzing of `robocal serve` against openapi.yaml with Schemathesis.
#
#   scripts/schemathesis.sh [path/to/robocal [schemathesis options...]]
#   scripts/schemathesis.sh --install-only   (its Python environment only)
#
# (robocal default: target/debug/robocal; further options go to `schemathesis
# run`, e.g. `--include-operation-id solve` or `--report har`.)
#
# Starts the service on a loopback port with a temporary database and two API
# keys, then runs Schemathesis with every check (its default; see schemathesis.toml), every phase
# (examples, coverage, fuzzing, stateful), a bounded number of examples per
# operation and a fixed seed. Exits non-zero on any failure. Afterwards a
# SQLite database must pass `PRAGMA integrity_check` and `PRAGMA foreign_key_check`.
#
# Environment: SCHEMATHESIS_VENV (default target/schemathesis-venv),
# SCHEMATHESIS_MAX_EXAMPLES (default 25), SCHEMATHESIS_SEED (default 20261122),
# SCHEMATHESIS_DATABASE_URL (default a SQLite file in a temporary directory;
# `postgres://…` runs the server on that (empty) PostgreSQL database).
set -euo pipefail
cd "$(dirname "$0")/.."

INSTALL_ONLY=
if [ "${1:-}" = "--install-only" ]; then
    INSTALL_ONLY=1
    shift
fi
BIN=${1:-target/debug/robocal}
shift || true
VENV=${SCHEMATHESIS_VENV:-target/schemathesis-venv}
VERSION=4.32.5
MAX_EXAMPLES=${SCHEMATHESIS_MAX_EXAMPLES:-25}
SEED=${SCHEMATHESIS_SEED:-20261122}

if ! "$VENV/bin/schemathesis" --version 2>/dev/null | grep -q "$VERSION"; then
    if ! python3 -m venv "$VENV" 2>/dev/null; then
        # Debian's python3 keeps venv/ensurepip in a separate package.
        echo "schemathesis.sh: installing python3-venv" >&2
        apt-get update -qq && apt-get install -y -qq python3-venv >/dev/null
        rm -rf "$VENV"
        python3 -m venv "$VENV"
    fi
    "$VENV/bin/pip" install -q --disable-pip-version-check "schemathesis==$VERSION"
fi
[ -z "$INSTALL_ONLY" ] || exit 0
[ -x "$BIN" ] || { echo "schemathesis.sh: $BIN not found; build it with cargo build" >&2; exit 2; }

WORK=$(mktemp -d)
SERVER_PID=
cleanup() {
    if [ -n "$SERVER_PID" ]; then kill "$SERVER_PID" 2>/dev/null || true; wait "$SERVER_PID" 2>/dev/null || true; fi
    rm -rf "$WORK"
}
trap cleanup EXIT

DATABASE_URL=${SCHEMATHESIS_DATABASE_URL:-sqlite://$WORK/api.db?mode=rwc}

# Small budgets keep jobs short in a debug build; queues large enough that a
# run of this size never saturates the service (429 is tested in tests/api.rs).
ROBOCAL_API_KEYS=ci-key-1,ci-key-2 RUST_LOG=warn,robocal::cli::serve=info "$BIN" serve \
    --bind 127.0.0.1:0 \
    --database-url "$DATABASE_URL" \
    --job-time-limit 20 \
    --max-queued-jobs 10000 --max-queued-solves 64 \
    2> >(tee "$WORK/server.log" >&2) &
SERVER_PID=$!
ADDR=
for _ in $(seq 1 300); do
    ADDR=$(sed -n 's/.*listening on http:\/\/\([0-9.:]*\).*/\1/p' "$WORK/server.log" 2>/dev/null | head -1 || true)
    [ -n "$ADDR" ] && break
    kill -0 "$SERVER_PID" 2>/dev/null || { echo "schemathesis.sh: the server exited" >&2; exit 1; }
    sleep 0.1
done
[ -n "$ADDR" ] || { echo "schemathesis.sh: the server did not report its address" >&2; exit 1; }
echo "schemathesis.sh: robocal on http://$ADDR, schemathesis $VERSION, $MAX_EXAMPLES examples per operation, seed $SEED"

"$BIN" simulate --preset ys100 --poses 30 --seed 1 --out "$WORK/q1.csv" >/dev/null
"$BIN" simulate --preset ys100 --poses 30 --seed 2 --out "$WORK/q3.csv" >/dev/null
"$VENV/bin/python" scripts/schemathesis_seed.py "http://$ADDR" ci-key-1 "$WORK/q1.csv" "$WORK/q3.csv"

start=$(date +%s)
status=0
# scripts/schemathesis_site/sitecustomize.py: one ast.parse at a time (its docstring).
PYTHONPATH="scripts/schemathesis_site${PYTHONPATH:+:$PYTHONPATH}" "$VENV/bin/schemathesis" --config-file scripts/schemathesis.toml run openapi.yaml \
    --url "http://$ADDR" \
    --phases examples,coverage,fuzzing,stateful \
    --max-examples "$MAX_EXAMPLES" \
    --seed "$SEED" \
    --workers 2 \
    --request-timeout 30 \
    --header "Authorization: Bearer ci-key-1" \
    --generation-database none \
    --no-color \
    --report junit --report-dir "${SCHEMATHESIS_REPORT_DIR:-target/schemathesis-report}" \
    "$@" \
    || status=$?
echo "schemathesis.sh: finished in $(( $(date +%s) - start )) s with exit code $status"

kill "$SERVER_PID"
wait "$SERVER_PID" 2>/dev/null || true
SERVER_PID=
case "$DATABASE_URL" in
postgres*)
    # PostgreSQL enforces every key and check on every write.
    echo "schemathesis.sh: database after the run: $(psql -At "$DATABASE_URL" -c 'SELECT COUNT(*) FROM robots') robots (PostgreSQL)"
    exit $status
    ;;
esac
# The database the fuzzing left behind is sound.
"$VENV/bin/python" - "$WORK/api.db" <<'EOF'
import sqlite3, sys
con = sqlite3.connect(sys.argv[1])
ic = con.execute("PRAGMA integrity_check").fetchall()
fk = con.execute("PRAGMA foreign_key_check").fetchall()
robots = con.execute("SELECT COUNT(*) FROM robots").fetchone()[0]
print(f"schemathesis.sh: database after the run: integrity_check {ic[0][0]}, foreign_key_check {len(fk)} violations, {robots} robots")
sys.exit(0 if ic == [("ok",)] and not fk else 1)
EOF
exit $status
