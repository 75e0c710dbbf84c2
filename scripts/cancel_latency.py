"""Cancellation latency of a big SKCM-C (TLBO) job, measured from outside.

    python3 scripts/cancel_latency.py [--robocal target/release/robocal] [--population 1000]

Starts `robocal serve` on loopback with a temporary database, uploads 30
simulated YS100 poses, starts `skcm-tlbo` with the given population, waits
until TLBO reports its first generation, requests cancellation and polls the
job. The latency is the job's own `finished_at` minus the `updated_at` of the
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
ap = argparse.ArgumentParser()
ap.add_argument("--robocal", default=os.path.join(ROOT, "target", "release", "robocal"))
ap.add_argument("--population", type=int, default=1000)
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

    subprocess.run([a.robocal, "simulate", "--preset", "ys100", "--poses", "30", "--seed", "1",
                    "--out", f"{work}/q1.csv"], check=True, capture_output=True)
    robot = call("POST", "/v1/robots", {"preset": "ys100"})["id"]
    call("POST", f"/v1/robots/{robot}/measurement-sets?role=identification",
         open(f"{work}/q1.csv", "rb").read(), "text/csv")
    job = call("POST", f"/v1/robots/{robot}/calibrations",
               {"methods": ["skcm-tlbo"], "population": a.population, "generations": 1000})["id"]
    t0 = time.time()
    while True:
        j = call("GET", f"/v1/robots/{robot}/calibrations/{job}")
        if j["progress"]["phase"] == "skcm-tlbo" and j["progress"]["iteration"] >= 1:
            break
        if time.time() - t0 > 600:
            sys.exit("TLBO never reported a generation")
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
    print(f"cancel latency of skcm-tlbo (population {a.population}, generation {j['progress']['iteration']}): "
          f"{server_s:.3f} s by the job's timestamps, {seen:.3f} s until a poll saw `{j['status']}` (goal 1 s)")
finally:
    server.kill()
