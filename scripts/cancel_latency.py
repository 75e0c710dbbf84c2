"""Cancellation latency of a running calibration job, measured from outside.

    python3 scripts/cancel_latency.py [--robocal target/release/robocal] [--population 1000]
    python3 scripts/cancel_latency.py --method skcm-nn    (or km-rbf, skcm-iwonn, skcm-tlbonn)

Starts `robocal serve` on loopback with a temporary database. For `skcm-tlbo`
(the default) it uploads 30 simulated YS100 poses, starts the job with the
given population and waits until TLBO reports its first generation. For a
compensator method it uploads 100 identification and 1000 training poses of
the simulated YS100 with unmodelled effects (gear transmission error,
backlash) and waits until the compensator's training reports progress. Then
it requests cancellation and polls the job. The latency is the job's own `finished_at` minus the `updated_at` of the
cancel answer (server clock), and the time until a poll sees `cancelled`
(client clock). The goal is 1 s at any phase.
"""
import argparse
import datetime
import json
import os
import re
import subprocess
import sys
import tempfile
import time
import urllib.request

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# The method names: the spec's `Method` enum (a test keeps it equal to the server's table).
with open(os.path.join(ROOT, "openapi.yaml"), encoding="utf-8") as f:
    METHODS = re.search(r"^    Method:\n\s+type: string\n\s+enum: \[([^\]]*)\]", f.read(), re.M).group(1)
METHODS = [m.strip() for m in METHODS.split(",")]
ap = argparse.ArgumentParser()
ap.add_argument("--robocal", default=os.path.join(ROOT, "target", "release", "robocal"))
ap.add_argument("--population", type=int, default=1000)
ap.add_argument("--method", default="skcm-tlbo", choices=METHODS,
                help="skcm-tlbo or a compensator method; the others end before they can be cancelled")
a = ap.parse_args()

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
        subprocess.run([a.robocal, "simulate", "--preset", "ys100", "--poses", str(poses), "--seed", str(seed),
                        "--set", role, "--out", f"{work}/{name}.csv", *extra], check=True, capture_output=True)
        return open(f"{work}/{name}.csv", "rb").read()

    robot = call("POST", "/v1/robots", {"preset": "ys100"})["id"]
    call("POST", f"/v1/robots/{robot}/measurement-sets?role=identification",
         simulate("q1", 100 if compensator else 30, 1, "identification"), "text/csv")
    if compensator:
        call("POST", f"/v1/robots/{robot}/measurement-sets?role=training",
             simulate("q2", 1000, 2, "training"), "text/csv")
        body = {"methods": [a.method]}
    else:
        body = {"methods": ["skcm-tlbo"], "population": a.population, "generations": 1000}
    job = call("POST", f"/v1/robots/{robot}/calibrations", body)["id"]
    t0 = time.time()
    while True:
        j = call("GET", f"/v1/robots/{robot}/calibrations/{job}")
        p = j["progress"]
        # A compensator method spends its first 5 % on the base fit.
        if p["phase"] == a.method and p["iteration"] >= 1 and (not compensator or p["percent"] > 6):
            break
        if j["status"] != "running" and j["status"] != "queued":
            sys.exit(f"the job ended before it could be cancelled: {j['status']}")
        if time.time() - t0 > 600:
            sys.exit(f"{a.method} never reported progress")
        time.sleep(0.01)
    sent = time.time()
    c = call("POST", f"/v1/robots/{robot}/calibrations/{job}/cancel")
    while True:
        j = call("GET", f"/v1/robots/{robot}/calibrations/{job}")
        if j["status"] != "running":
            break
        time.sleep(0.005)
    seen = time.time() - sent
    server_s = ts(j["finished_at"]) - ts(c["updated_at"])
    what = f"population {a.population}, generation" if not compensator else "training, epoch/generation"
    print(f"cancel latency of {a.method} ({what} {j['progress']['iteration']}, {j['progress']['percent']:.0f} %): "
          f"{server_s:.3f} s by the job's timestamps, {seen:.3f} s until a poll saw `{j['status']}` (goal 1 s)")
finally:
    server.kill()
