"""Seeds a running robocal with real data behind the ids of openapi.yaml's
examples (robot 1, sets 1 and 2, calibration 1, versions 1 and 2), so that
the Schemathesis examples and coverage phases reach the result, report,
version and solve logic, not only 404s.

    python schemathesis_seed.py http://127.0.0.1:PORT KEY q1.csv q3.csv
"""
import json
import sys
import time
import urllib.request

api, key, ident_csv, valid_csv = sys.argv[1:5]


def call(method, path, body=None, ct="application/json"):
    data = body if isinstance(body, bytes) else (None if body is None else json.dumps(body).encode())
    req = urllib.request.Request(api + path, data=data, method=method,
                                 headers={"Content-Type": ct, "Authorization": f"Bearer {key}"})
    with urllib.request.urlopen(req, timeout=60) as r:
        return json.loads(r.read() or b"null")


robot = call("POST", "/v1/robots", {"preset": "ys100", "name": "seeded"})["id"]
for path, role in ((ident_csv, "identification"), (valid_csv, "validation")):
    with open(path, "rb") as f:
        call("POST", f"/v1/robots/{robot}/measurement-sets?role={role}&name={role}", f.read(), "text/csv")
job = call("POST", f"/v1/robots/{robot}/calibrations", {"methods": ["km", "skcm"]})["id"]
status = "queued"
for _ in range(600):
    status = call("GET", f"/v1/robots/{robot}/calibrations/{job}")["status"]
    if status not in ("queued", "running"):
        break
    time.sleep(0.2)
print(f"schemathesis: seeded robot {robot} with a {status} calibration {job}")
sys.exit(0 if status == "succeeded" else 1)
