#!/usr/bin/env bash
# Installs Debian's Chromium and chromedriver (when missing) and Selenium in a
# virtual environment, then drives the web console through the whole flow in
# headless Chromium (scripts/console_check.py). Screenshots: target/console-check/.
#
#   scripts/console_check.sh [path/to/robocal]    (default target/debug/robocal)
#   scripts/console_check.sh --install-only       (Chromium and Selenium only)
set -euo pipefail
cd "$(dirname "$0")/.."
INSTALL_ONLY=
if [ "${1:-}" = "--install-only" ]; then
    INSTALL_ONLY=1
    shift
fi
BIN=${1:-target/debug/robocal}
SELENIUM_VERSION=4.51.0
if ! command -v chromium >/dev/null || ! command -v chromedriver >/dev/null; then
    SUDO=""
    if [ "$(id -u)" -ne 0 ]; then
        if command -v sudo >/dev/null && sudo -n true 2>/dev/null; then
            SUDO=sudo
        else
            # Exit status 77: the check cannot run here (no Chromium and no way
            # to install it); .ci/run reports it as skipped, not as passed.
            echo "console_check: Chromium is not installed and this user cannot install it (root or sudo needed)" >&2
            exit 77
        fi
    fi
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq chromium chromium-driver >/dev/null
fi
VENV=target/console-venv
if [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV"
fi
"$VENV/bin/pip" install -q "selenium==$SELENIUM_VERSION"
[ -z "$INSTALL_ONLY" ] || exit 0
"$VENV/bin/python" scripts/console_check.py --robocal "$BIN" --out target/console-check
