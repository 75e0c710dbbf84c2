#!/usr/bin/env python3
"""Peak and retained memory of `robocal serve` under concurrent large requests.

    python3 scripts/memory_check.py target/release/robocal

Starts the service on a fresh SQLite database (loopback), calibrates a YS100
(KM on 30 simulated poses), uploads a 10,000-pose and a 100,000-pose set, and
then, sampling the server's resident memory (VmRSS) every 20 ms:
  1. three concurrent comparisons of the 100,000-pose set against 20 versions
     (refused: beyond the poses x versions cap);
  2. three concurrent comparisons of the 10,000-pose set against 20 versions
     (at the cap);
  3. sixteen concurrent predictions of 100,000 readings each.
For each it prints the answers' status codes, the peak RSS, and the RSS 10 s
after the last answer (what the server kept). Figures quoted in docs come
from this script.
"""
import json
import os
import subprocess
import sys
import tempfile
import threading
import time
import urllib.error
import urllib.request


def rss_mb(pid):
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    return 0.0


class Sampler(threading.Thread):
    def __init__(self, pid):
        super().__init__(daemon=True)
        self.pid, self.peak, self.stop = pid, 0.0, False

    def run(self):
        while not self.stop:
            self.peak = max(self.peak, rss_mb(self.pid))
            time.sleep(0.02)


def request(base, method, path, body=None, ctype="application/json"):
    data = None
    if body is not None:
        data = body if isinstance(body, bytes) else json.dumps(body).encode()
    req = urllib.request.Request(base + path, data=data, method=method)
    if data is not None:
        req.add_header("Content-Type", ctype)
    try:
        with urllib.request.urlopen(req, timeout=3600) as r:
            return r.status, r.read()
    except urllib.error.HTTPError as e:
        return e.code, e.read()


def concurrently(n, f):
    out = [None] * n
    def one(i):
        out[i] = f(i)
    ts = [threading.Thread(target=one, args=(i,)) for i in range(n)]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    return out


def main():
    binary = os.path.abspath(sys.argv[1])
    work = tempfile.mkdtemp()
    port = 18000 + os.getpid() % 1000
    base = f"http://127.0.0.1:{port}"
    sim = lambda n, seed, out: subprocess.run(
        [binary, "simulate", "--preset", "ys100", "--poses", str(n), "--seed", str(seed), "--out", out],
        check=True, capture_output=True)
    for n, seed in [(30, 1), (10000, 2), (100000, 3)]:
        sim(n, seed, f"{work}/s{n}.csv")
    server = subprocess.Popen(
        [binary, "serve", "--bind", f"127.0.0.1:{port}", "--database-url", f"sqlite://{work}/m.db?mode=rwc",
         # The 100,000-pose CSV is larger than the default 16 MiB body.
         "--body-limit", str(64 << 20)],
        env={**os.environ, "RUST_LOG": "warn"}, stderr=subprocess.DEVNULL)
    try:
        for _ in range(600):
            try:
                if request(base, "GET", "/healthz")[0] == 200:
                    break
            except OSError:
                time.sleep(0.1)
        s, r = request(base, "POST", "/v1/robots", {"preset": "ys100"})
        rid = json.loads(r)["id"]
        ids = {}
        for n, role in [(30, "identification"), (10000, "validation"), (100000, "validation")]:
            with open(f"{work}/s{n}.csv", "rb") as f:
                s, r = request(base, "POST", f"/v1/robots/{rid}/measurement-sets?role={role}&name=s{n}", f.read(), "text/csv")
            assert s == 201, r
            ids[n] = json.loads(r)["id"]
        s, r = request(base, "POST", f"/v1/robots/{rid}/calibrations",
                       {"methods": ["km"], "identification_set_ids": [ids[30]], "validation_set_ids": []})
        job = json.loads(r)["id"]
        while json.loads(request(base, "GET", f"/v1/robots/{rid}/calibrations/{job}")[1])["status"] in ("queued", "running"):
            time.sleep(0.2)
        readings = [{"id": f"r{i}", "joints_deg": [10, 5 + i % 7, 3, 0, 30, 0]} for i in range(100000)]
        cases = [
            ("3 compares, 100,000 poses x 20 versions", 3,
             lambda i: request(base, "POST", f"/v1/robots/{rid}/compare", {"set_id": ids[100000], "versions": [1] * 20})[0]),
            ("3 compares, 10,000 poses x 20 versions", 3,
             lambda i: request(base, "POST", f"/v1/robots/{rid}/compare", {"set_id": ids[10000], "versions": [1] * 20})[0]),
            ("16 predicts of 100,000 readings", 16,
             lambda i: request(base, "POST", f"/v1/robots/{rid}/predict", {"version": "nominal", "readings": readings})[0]),
        ]
        print(f"baseline RSS {rss_mb(server.pid):.0f} MB")
        for name, n, f in cases:
            sampler = Sampler(server.pid)
            sampler.start()
            t0 = time.time()
            codes = concurrently(n, f)
            took = time.time() - t0
            time.sleep(10)
            sampler.stop = True
            sampler.join()
            counts = {c: codes.count(c) for c in sorted(set(codes))}
            print(f"{name}: answers {counts} in {took:.1f} s; peak RSS {sampler.peak:.0f} MB, "
                  f"10 s after {rss_mb(server.pid):.0f} MB")
    finally:
        server.terminate()
        server.wait()


if __name__ == "__main__":
    main()
