#!/usr/bin/env bash
# The peer benchmark in one command (not run by CI): a Python virtual
# environment with numpy, scipy and roboticstoolbox-python, the
# release build, then scripts/peer_bench.py pinned to one core.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=${PEER_VENV:-target/peer-venv}
if [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV" || { apt-get update -qq && apt-get install -y -qq python3-venv >/dev/null && python3 -m venv "$VENV"; }
    "$VENV/bin/pip" install -q --disable-pip-version-check numpy scipy roboticstoolbox-python==1.5.0
fi
cargo build --release -q --bin robocal
taskset -c 0 "$VENV/bin/python" scripts/peer_bench.py --robocal target/release/robocal "$@"
