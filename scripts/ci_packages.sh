#!/usr/bin/env bash
# Installs, in one go, what CI's outside checks would each install on first
# use: Debian's PostgreSQL, Chromium and chromedriver, HAProxy and
# python3-venv (only those missing), then the Python environments of
# scripts/schemathesis.sh and scripts/console_check.sh. .ci/run starts it in
# the background while clippy runs, so the downloads are off the critical
# path, and waits for it before `cargo test`. Each check still installs what
# it needs by itself when run alone; this only does it earlier.
set -euo pipefail
cd "$(dirname "$0")/.."
missing=()
ls /usr/lib/postgresql/*/bin/initdb >/dev/null 2>&1 || missing+=(postgresql)
command -v chromium >/dev/null || missing+=(chromium)
command -v chromedriver >/dev/null || missing+=(chromium-driver)
command -v haproxy >/dev/null || missing+=(haproxy)
python3 -c 'import ensurepip' 2>/dev/null || missing+=(python3-venv)
if [ ${#missing[@]} -gt 0 ]; then
    if [ "$(id -u)" -ne 0 ]; then
        echo "ci_packages: cannot install ${missing[*]} (not root); each check says what it lacks" >&2
    else
        echo "ci_packages: installing ${missing[*]}"
        apt-get update -qq
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}" >/dev/null
    fi
fi
scripts/schemathesis.sh --install-only || echo "ci_packages: schemathesis.sh --install-only exited $?" >&2
scripts/console_check.sh --install-only || echo "ci_packages: console_check.sh --install-only exited $?" >&2
echo "ci_packages: done"
