"""Cancellation latency of a running calibration job, measured from outside.

    python3 scripts/cancel_latency.py [--robocal target/release/robocal] [--population 1000]
    python3 scripts/cancel_latency.py --method skcm-nn    (or km-rbf, skcm-iwonn, skcm-tlbonn, km-gp, ...)
    python3 scripts/cancel_latency.py --method auto --poses 10000 --one-set --validation 300 --at skcm-gp:final
    python3 scripts/cancel_latency.py --method auto --list-stages

Starts `robocal serve` on loopback with a temporary database. For `skcm-tlbo`
(the default) it uploads 30 simulated YS100 poses, starts the job with the
given population and waits until TLBO reports its first generation. For a
compensator, joint-map or `auto` method it uploads `--ident` identification
and `--poses` training poses of the simulated YS100 with unmodelled effects
(gear transmission error, backlash; `--one-set`: the `--poses` poses identify
and train, and `--transmission` adds fine per-joint transmission errors, as the
docs/benchmarks.md's 10,000-pose `skcm,auto` run). `auto` runs as `["skcm", "auto"]`, what
the CLI's `--method skcm,auto` runs.

When to cancel: by default once the method's training reports progress; with
`--at STAGE` once the job's progress (phase and percent, as the API returns
them) enters the stage (`--list-stages` prints them with their windows); with
`--after S` S seconds later (without `--at`: S seconds after the job started
running). The stage windows follow the progress layout of `identify/methods`
(auto.rs, compensated.rs, maps.rs and the method weights of methods/mod.rs).

Then it requests cancellation and polls the job. The latency is the job's own
`finished_at` minus the `updated_at` of the cancel answer (server clock), and
the time until a poll sees `cancelled` (client clock). The goal is 1 s at any
phase.
"""
import argparse
import datetime
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
import urllib.error
import urllib.request

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# The method names: the spec's `Method` enum (a test keeps it equal to the server's table).
with open(os.path.join(ROOT, "openapi.yaml"), encoding="utf-8") as f:
    METHODS = re.search(r"^    Method:\n\s+type: string\n\s+enum: \[([^\]]*)\]", f.read(), re.M).group(1)
METHODS = [m.strip() for m in METHODS.split(",")]

# Progress weights of the methods (identify/methods/mod.rs, `weight`): a job
# spends 0-10 % before its methods, then each method its share of 10-100 %.
WEIGHTS = {"km": 1, "skcm": 1, "skcm-tlbo": 8, "skcm-payload": 2, "km-maps": 3, "skcm-maps": 3,
           "km-rbf": 2, "skcm-nn": 6, "skcm-iwonn": 6, "skcm-tlbonn": 6, "km-gp": 2, "skcm-gp": 2,
           "km-maps-gp": 4, "skcm-maps-gp": 4, "auto": 12}
# `auto` on a robot with gravity torques: one unit of its span per candidate, in
# this order (auto.rs: the compensators of KM, of SKCM, then per base its maps
# and the compensators on them).
AUTO_UNITS = ["km-rbf", "km-gp", "skcm-nn", "skcm-iwonn", "skcm-tlbonn", "skcm-gp",
              "km-maps", "km-maps-gp", "skcm-maps", "skcm-maps-gp"]
CV_FOLDS, BLOCKED_FOLDS = 5, 4
MAP_ROUNDS = 2


def compensator_stages(name, lo, hi):
    """A compensator's cross-validation (random folds, blocked folds) and final training."""
    stages = CV_FOLDS + BLOCKED_FOLDS + 1
    at = lambda s: lo + (hi - lo) * s / stages
    return [(f"{name}:cv", at(0), at(CV_FOLDS)),
            (f"{name}:blocked", at(CV_FOLDS), at(CV_FOLDS + BLOCKED_FOLDS)),
            (f"{name}:final", at(stages - 1), hi)]


def maps_stages(name, lo, hi):
    """Per round: the maps' fit with its cross-validation, then the LM refit."""
    stages = 2 * MAP_ROUNDS + 1
    at = lambda s: lo + (hi - lo) * s / stages
    out = []
    for r in range(MAP_ROUNDS):
        out.append((f"{name}:cv{r + 1}", at(1 + 2 * r), at(2 + 2 * r)))
        out.append((f"{name}:refit{r + 1}", at(2 + 2 * r), at(3 + 2 * r)))
    return out


def stages_of(methods):
    """(name, phase, lo %, hi %) of every stage of a job running `methods`."""
    total = sum(WEIGHTS[m] for m in methods)
    done, out = 0, []
    for m in methods:
        lo = 10 + 90 * done / total
        hi = 10 + 90 * (done + WEIGHTS[m]) / total
        done += WEIGHTS[m]
        out.append((m, m, lo, hi))
        if m == "auto":
            unit = (hi - lo) / len(AUTO_UNITS)
            for i, u in enumerate(AUTO_UNITS):
                a, b = lo + i * unit, lo + (i + 1) * unit
                sub = maps_stages(u, a, b) if u.endswith("-maps") else compensator_stages(u, a, b)
                out += [(n, m, x, y) for n, x, y in sub]
        elif m.endswith("-maps"):
            out += [(n, m, x, y) for n, x, y in maps_stages(m, lo, hi)]
        elif m in WEIGHTS and m not in ("km", "skcm", "skcm-tlbo", "skcm-payload"):
            # A compensator method: 5 % base fit, then its trainings.
            out += [(n, m, x, y) for n, x, y in compensator_stages(m, lo + 0.05 * (hi - lo), hi)]
    return out


def stage_at(stages, phase, percent):
    """The narrowest stage containing the progress (phase, percent)."""
    inside = [s for s in stages if s[1] == phase and s[2] <= percent < s[3]]
    return min(inside, key=lambda s: s[3] - s[2])[0] if inside else phase


ap = argparse.ArgumentParser()
ap.add_argument("--robocal", default=os.path.join(ROOT, "target", "release", "robocal"))
ap.add_argument("--population", type=int, default=1000)
ap.add_argument("--method", default="skcm-tlbo", choices=METHODS,
                help="skcm-tlbo, a compensator or joint-map method, or auto (run as skcm,auto)")
ap.add_argument("--poses", type=int, default=1000, help="training poses (compensators, auto)")
ap.add_argument("--ident", type=int, default=100, help="identification poses (compensators, auto)")
ap.add_argument("--one-set", action="store_true",
                help="the --poses poses identify and train (no separate training set)")
ap.add_argument("--validation", type=int, default=0, help="validation poses (seed 12)")
ap.add_argument("--transmission", default="20,30",
                help="with --one-set: fine transmission errors `arcsec,harmonics` (empty: none)")
ap.add_argument("--at", help="cancel once the job's progress enters this stage (--list-stages)")
ap.add_argument("--after", type=float, default=None,
                help="seconds to wait after the stage is reached (or after the job started)")
ap.add_argument("--list-stages", action="store_true")
a = ap.parse_args()

methods = ["skcm", "auto"] if a.method == "auto" else [a.method]
STAGES = stages_of(methods)
if a.list_stages:
    for name, phase, lo, hi in STAGES:
        print(f"{name:24} phase {phase:14} {lo:6.2f} - {hi:6.2f} %")
    sys.exit(0)
if a.at is not None and a.at not in [s[0] for s in STAGES]:
    sys.exit(f"no stage {a.at!r} in a {','.join(methods)} job; see --list-stages")

work = tempfile.mkdtemp()
server = subprocess.Popen([a.robocal, "serve", "--bind", "127.0.0.1:0", "--database-url",
                           f"sqlite://{work}/c.db?mode=rwc"], stderr=subprocess.PIPE, text=True,
                          env={**os.environ, "RUST_LOG": "warn,robocal::cli::serve=info"})
try:
    addr = None
    for line in server.stderr:
        m = re.search(r"listening on http://(\S+)", line)
        if m:
            addr = m.group(1)
            break
    api = f"http://{addr}"

    def call(method, path, body=None, ct="application/json"):
        data = body if isinstance(body, bytes) else (None if body is None else json.dumps(body).encode())
        req = urllib.request.Request(api + path, data=data, method=method, headers={"Content-Type": ct})
        with urllib.request.urlopen(req) as r:
            return json.loads(r.read() or b"null")

    def ts(s):
        return datetime.datetime.strptime(s, "%Y-%m-%dT%H:%M:%S.%fZ").timestamp()

    compensator = a.method != "skcm-tlbo"

    def simulate(name, poses, seed, role):
        extra = ["--gear-error", "0.0023,1", "--backlash-deg", "0.0011"] if compensator else []
        if a.one_set:
            extra = ["--gear-error", "0.003,1", "--backlash-deg", "0.001"]
            if a.transmission:
                extra += ["--transmission", a.transmission]
        subprocess.run([a.robocal, "simulate", "--preset", "ys100", "--poses", str(poses), "--seed", str(seed),
                        "--set", role, "--out", f"{work}/{name}.csv", *extra], check=True, capture_output=True)
        return open(f"{work}/{name}.csv", "rb").read()

    robot = call("POST", "/v1/robots", {"preset": "ys100"})["id"]
    if a.one_set:
        call("POST", f"/v1/robots/{robot}/measurement-sets?role=identification",
             simulate("q1", a.poses, 11, "identification"), "text/csv")
    else:
        call("POST", f"/v1/robots/{robot}/measurement-sets?role=identification",
             simulate("q1", a.ident if compensator else 30, 1, "identification"), "text/csv")
    if compensator and not a.one_set:
        call("POST", f"/v1/robots/{robot}/measurement-sets?role=training",
             simulate("q2", a.poses, 2, "training"), "text/csv")
    if a.validation > 0:
        call("POST", f"/v1/robots/{robot}/measurement-sets?role=validation",
             simulate("q3", a.validation, 12, "validation"), "text/csv")
    if compensator:
        body = {"methods": methods}
    else:
        body = {"methods": ["skcm-tlbo"], "population": a.population, "generations": 1000}
    job = call("POST", f"/v1/robots/{robot}/calibrations", body)["id"]
    t0 = time.time()
    started = None
    reached = None
    window = next((s for s in STAGES if s[0] == a.at), None)
    while True:
        j = call("GET", f"/v1/robots/{robot}/calibrations/{job}")
        p = j["progress"]
        now = time.time()
        if j["status"] == "running" and started is None:
            started = now
        if window is not None:
            if reached is None and p["phase"] == window[1] and window[2] <= p["percent"]:
                # A stage shorter than a poll may be passed: the report names where the job was.
                reached = now
        elif a.after is not None:
            reached = started
        elif p["phase"] == a.method and p["iteration"] >= 1 and (not compensator or p["percent"] > 6):
            # A compensator method spends its first 5 % on the base fit.
            reached = now
        if reached is not None and now - reached >= (a.after or 0.0):
            break
        if j["status"] != "running" and j["status"] != "queued":
            sys.exit(f"the job ended before it could be cancelled: {j['status']}")
        if now - t0 > 3600:
            sys.exit(f"{a.method} never reached the point to cancel at")
        time.sleep(0.02)
    before = stage_at(STAGES, p["phase"], p["percent"])
    sent = time.time()
    try:
        c = call("POST", f"/v1/robots/{robot}/calibrations/{job}/cancel")
    except urllib.error.HTTPError as e:
        if e.code != 409:
            raise
        j = call("GET", f"/v1/robots/{robot}/calibrations/{job}")
        sys.exit(f"the job ended ({j['status']}) before the cancel arrived")
    while True:
        j = call("GET", f"/v1/robots/{robot}/calibrations/{job}")
        if j["status"] != "running":
            break
        time.sleep(0.005)
    seen = time.time() - sent
    server_s = ts(j["finished_at"]) - ts(c["updated_at"])
    p = j["progress"]
    if a.at is not None or a.after is not None or a.method == "auto":
        what = (f"{','.join(methods)} on {a.poses} poses, cancelled {sent - started:.1f} s "
                f"into the job at {before}, last progress {stage_at(STAGES, p['phase'], p['percent'])} "
                f"iteration {p['iteration']}, {p['percent']:.1f} %")
        print(f"cancel latency ({what}): {server_s:.3f} s by the job's timestamps, "
              f"{seen:.3f} s until a poll saw `{j['status']}` (goal 1 s)")
    else:
        what = f"population {a.population}, generation" if not compensator else "training, epoch/generation"
        print(f"cancel latency of {a.method} ({what} {p['iteration']}, {p['percent']:.0f} %): "
              f"{server_s:.3f} s by the job's timestamps, {seen:.3f} s until a poll saw `{j['status']}` (goal 1 s)")
finally:
    server.kill()
    server.wait()
    shutil.rmtree(work, ignore_errors=True)
