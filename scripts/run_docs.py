#!/usr/bin/env python3
"""Runs every ```sh block of README.md and docs/guide/*.md against a robocal binary.

    scripts/run_docs.py target/debug/robocal [FILE.md ...]

The files run in order (README.md first, then docs/guide/ in the order of GUIDE_ORDER, then any
other page of docs/guide/), all in one temporary directory, so a page starts where the quick start
ends, as the pages say. The repository's `examples/`, `data/` and `models/` are linked into it.
Each block runs in its own `bash -e -o pipefail`, with the shell variables the blocks before it
set (as in one terminal), and with these changes, and nothing else:

- `cargo run [--release] [-q] --` becomes the given binary (`robocal` is on PATH too);
- the ports of `127.0.0.1:NNNN` / `localhost:NNNN` become free ports, one per port the pages
  name (8080 is the service of the quick start), and `$API` is its address;
- `curl` fails on an HTTP error answer (4xx, 5xx), printing it (`--fail-with-body`);
- a line that starts `robocal serve` (after any `VAR=value` prefix) starts the service in the
  background with `--bind` on its mapped port, stopping the one this script started on that
  port before (the pages say to stop it), and waits until `/readyz` answers.

Run with no file named, it first checks that README.md has at most 300 lines. A block preceded
by `<!-- not run: REASON -->` is not run and is listed with its reason. A
block that ends with a non-zero status fails the run with its `file:line`, its output and the
log of the services started. Python 3 standard library only.
"""

import os
import re
import shutil
import socket
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
GUIDE_ORDER = [
    "cli.md",
    "file-formats.md",
    "conventions.md",
    "calibration.md",
    "compensators.md",
    "programs.md",
    "solve.md",
    "controller-data.md",
    "tcp-and-work-objects.md",
    "measurement-plans.md",
    "checks.md",
    "exit-codes.md",
    "api.md",
]
LINKED = ["examples", "data", "models"]
BLOCK_TIMEOUT_S = 300
# The README is a guide, not the manual (run with no file named).
README_MAX_LINES = 300
READY_TIMEOUT_S = 60

CARGO_RUN = re.compile(r"cargo run(?: (?:--release|-q|--quiet))* --(?= |$)")
HOST_PORT = re.compile(r"\b(127\.0\.0\.1|localhost):(\d{2,5})\b")
SERVE_LINE = re.compile(r"^(\s*(?:[A-Za-z_][A-Za-z0-9_]*=\S*\s+)*)robocal serve\b(.*)$")
NOT_RUN = re.compile(r"^<!--\s*not run:\s*(.+?)\s*-->$")


@dataclass
class Block:
    """One ```sh block: where it is and what it says."""

    path: Path
    line: int  # 1-based line of the opening fence
    text: str
    not_run: str | None  # the reason, when the page marks it

    def where(self) -> str:
        return f"{self.path.relative_to(ROOT)}:{self.line}"


def blocks_of(path: Path) -> list[Block]:
    """The ```sh blocks of a markdown file, with the `not run` mark before each."""
    lines = path.read_text(encoding="utf-8").split("\n")
    out = []
    i = 0
    while i < len(lines):
        if lines[i].strip() == "```sh":
            start = i
            j = i + 1
            while j < len(lines) and lines[j].strip() != "```":
                j += 1
            if j == len(lines):
                sys.exit(f"{path.relative_to(ROOT)}:{start + 1}: unterminated ```sh block")
            k = start - 1
            while k >= 0 and not lines[k].strip():
                k -= 1
            mark = NOT_RUN.match(lines[k].strip()) if k >= 0 else None
            out.append(Block(path, start + 1, "\n".join(lines[start + 1 : j]) + "\n",
                             mark.group(1) if mark else None))
            i = j
        i += 1
    return out


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Ports:
    """The free port that stands for each port the pages name."""

    def __init__(self):
        self.map: dict[str, int] = {}

    def __getitem__(self, port: str) -> int:
        if port not in self.map:
            self.map[port] = free_port()
        return self.map[port]


PRELUDE = r"""
__robocal_serve() {  # PORT, then the command; the service runs in the background
    local port=$1; shift
    if [ -f ".serve.$port.pid" ]; then
        kill "$(cat ".serve.$port.pid")" 2>/dev/null || true
        while kill -0 "$(cat ".serve.$port.pid")" 2>/dev/null; do sleep 0.1; done
        rm -f ".serve.$port.pid"
    fi
    "$@" >>"serve.$port.log" 2>&1 &
    echo $! > ".serve.$port.pid"
    local i
    for i in $(seq 1 $((READY_TIMEOUT_S * 10))); do
        if command curl -sf "http://127.0.0.1:$port/readyz" >/dev/null; then return 0; fi
        if ! kill -0 "$(cat ".serve.$port.pid")" 2>/dev/null; then
            echo "the service on port $port ended:" >&2; cat "serve.$port.log" >&2; return 1
        fi
        sleep 0.1
    done
    echo "the service on port $port did not become ready" >&2; return 1
}
curl() { command curl --fail-with-body "$@"; }  # an HTTP error answer fails the block
__vars_before=$(compgen -v | sort)
[ -f .vars.sh ] && . ./.vars.sh
__save_vars() {  # the shell variables the blocks so far set, for the next block
    local names
    names=$(comm -13 <(echo "$__vars_before") <(compgen -v | sort) | grep -Ev '^(_|__.*|BASH.*|REPLY|OPT.*|COMP.*|FUNCNAME|PIPESTATUS|GROUPS|LINENO|RANDOM|SRANDOM|SECONDS|EPOCH.*)$' || true)
    if [ -n "$names" ]; then declare -p $names > .vars.sh; fi
}
"""


def rewrite(text: str, ports: Ports) -> str:
    """The block as it runs here (see the module's documentation)."""
    text = CARGO_RUN.sub("robocal", text)
    text = HOST_PORT.sub(lambda m: f"127.0.0.1:{ports[m.group(2)]}", text)
    out = []
    for line in text.split("\n"):
        m = SERVE_LINE.match(line)
        if m:
            prefix, rest = m.group(1), m.group(2)
            bind = re.search(r"--bind[ =]127\.0\.0\.1:(\d+)", rest)
            if bind:
                port = int(bind.group(1))
            else:
                port = ports["8080"]
                rest = f" --bind 127.0.0.1:{port}" + rest
            env = prefix.strip()
            command = f"env {env} robocal serve{rest}" if env else f"robocal serve{rest}"
            line = f"__robocal_serve {port} {command}"
        out.append(line)
    return "\n".join(out)


def stop_services(work: Path):
    for pid_file in work.glob(".serve.*.pid"):
        try:
            os.kill(int(pid_file.read_text().strip()), 15)
        except (ProcessLookupError, ValueError):
            pass


def main() -> int:
    if len(sys.argv) < 2 or sys.argv[1] in ("-h", "--help"):
        print(__doc__.strip())
        return 0 if len(sys.argv) > 1 else 1
    binary = Path(sys.argv[1]).resolve()
    if not os.access(binary, os.X_OK):
        sys.exit(f"{binary}: not an executable")
    if shutil.which("curl") is None:
        sys.exit("curl is needed (the pages use it)")
    if len(sys.argv) > 2:
        files = [Path(f).resolve() for f in sys.argv[2:]]
    else:
        guide = ROOT / "docs" / "guide"
        rest = sorted(p.name for p in guide.glob("*.md") if p.name not in GUIDE_ORDER)
        missing = [n for n in GUIDE_ORDER if not (guide / n).exists()]
        if missing:
            sys.exit(f"GUIDE_ORDER names pages that do not exist: {missing}")
        files = [ROOT / "README.md"] + [guide / n for n in GUIDE_ORDER + rest]
        readme_lines = len((ROOT / "README.md").read_text(encoding="utf-8").splitlines())
        if readme_lines > README_MAX_LINES:
            sys.exit(f"README.md has {readme_lines} lines, more than {README_MAX_LINES}: it is a "
                     "guide; the manual belongs in docs/guide/")

    work = Path(tempfile.mkdtemp(prefix="robocal-docs-"))
    bindir = work / ".bin"
    bindir.mkdir()
    (bindir / "robocal").symlink_to(binary)
    for name in LINKED:
        (work / name).symlink_to(ROOT / name)
    ports = Ports()
    env = {k: v for k, v in os.environ.items() if not k.startswith("ROBOCAL_")
           and k != "DATABASE_URL"}
    env["PATH"] = f"{bindir}{os.pathsep}{env.get('PATH', '')}"
    env["API"] = f"http://127.0.0.1:{ports['8080']}"
    env["READY_TIMEOUT_S"] = str(READY_TIMEOUT_S)

    t0 = time.monotonic()
    ran, not_run = 0, []
    try:
        for path in files:
            for block in blocks_of(path):
                if block.not_run is not None:
                    not_run.append(block)
                    continue
                script = PRELUDE + rewrite(block.text, ports) + "\n__save_vars\n"
                t = time.monotonic()
                try:
                    proc = subprocess.run(["bash", "-e", "-o", "pipefail", "-c", script],
                                          cwd=work, env=env, capture_output=True, text=True,
                                          timeout=BLOCK_TIMEOUT_S)
                    status = proc.returncode
                    output = proc.stdout + proc.stderr
                except subprocess.TimeoutExpired as e:
                    status = f"timed out after {BLOCK_TIMEOUT_S} s"
                    output = (e.stdout or b"").decode(errors="replace") + \
                        (e.stderr or b"").decode(errors="replace")
                took = time.monotonic() - t
                if status != 0:
                    print(f"FAILED {block.where()} (exit {status}, {took:.1f} s):")
                    print(block.text.rstrip())
                    print("--- output:")
                    print(output.rstrip()[-6000:])
                    for log in sorted(work.glob("serve.*.log")):
                        print(f"--- {log.name} (last lines):")
                        print("\n".join(log.read_text(errors="replace").splitlines()[-30:]))
                    return 1
                ran += 1
                print(f"ok {block.where()} ({took:.1f} s)")
    finally:
        stop_services(work)
        if os.environ.get("RUN_DOCS_KEEP"):
            print(f"kept {work}")
        else:
            shutil.rmtree(work, ignore_errors=True)
    print(f"{ran} blocks ran in {time.monotonic() - t0:.0f} s; {len(not_run)} not run:")
    for block in not_run:
        print(f"  not run {block.where()}: {block.not_run}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
