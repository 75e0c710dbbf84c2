#!/usr/bin/env python3
"""Drives the web console in a real browser through the whole flow and saves a
screenshot of each step:

  create robot -> upload measurements -> calibrate (live progress) -> report
  -> versions (the best is active) -> a second calibration (`auto`) held at
  the test gate on a candidate's fold, its row showing `auto · candidate ·
  fold k/n` and the time left, and cancelled (confirmed) -> solve a targets CSV into a CSV answer
  -> check, its page (per-pose errors, summary, frame shift, thresholds)
  -> thresholds set -> a check on a rigidly shifted copy of the set says
  `shifted` -> re-register from it -> activate the new version (confirmed)
  -> check again -> tools and work objects with loads (add, edit in the
  prefilled form and read back over the API, delete confirmed) ->
  controller data -> predict -> fit a work object, a tool from a tracker
  point and a tool from a 6-D probe (readings made from a known tool offset
  with seeded noise; the fit must find it within the noise) -> external axes
  on a second robot (a YS100): a track fitted from `robocal track simulate`'s
  file, a refused one shown, the file as station sets and the track
  refitted from them, the track deleted (confirmed), a positioner
  fitted from `robocal positioner simulate`'s files and deleted -> filter a
  URScript program (files and report downloaded) -> measurement plan ->
  ISO 9283 -> delete a set and a robot (confirmed) -> robot list with the
  latest check's status

against a real `robocal serve` with API keys on a temporary database, using
Debian's Chromium and chromedriver through Selenium.

    scripts/console_check.sh [path/to/robocal]     (installs what it needs)
    python3 scripts/console_check.py --robocal target/debug/robocal --out DIR

Data: the real UR5 laser-tracker set in data/ur5-wam-laser-tracker (grid for
identification, the 20 random poses for validation). Exits non-zero on the
first step that does not behave.
"""
import argparse
import csv as csvmod
import math
import os
import pathlib
from random import Random
import re
import shutil
import socket
import statistics
import subprocess
import sys
import tempfile
import time

from console_check_axes import check_external_axes
from console_check_rotations import (fixed_xyz, intrinsic_xyz, matmul, rotation,
                                     rotation_angle, rotation_rpy)
from selenium import webdriver
from selenium.webdriver.chrome.options import Options
from selenium.common.exceptions import StaleElementReferenceException, WebDriverException
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.by import By
from selenium.webdriver.support import expected_conditions as EC
from selenium.webdriver.support.ui import Select, WebDriverWait

ROOT = pathlib.Path(__file__).resolve().parent.parent
DATA = pathlib.Path(os.environ.get(
    "ROBOCAL_DATA_DIR", ROOT / "data/ur5-wam-laser-tracker"))
KEY = "console-check-key"


def replaced(element):
    """Wait condition: `element` left the document (the page reloaded).
    Chromium sometimes answers a query on a node of the unloaded page with a
    generic inspector error instead of a stale-element error; both mean the
    node is gone."""
    def gone(_driver):
        try:
            element.is_enabled()
            return False
        except (StaleElementReferenceException, WebDriverException):
            return True
    return gone


def text_of(driver, css):
    """The text of the first element matching `css`, or None while the page
    is reloading (the element left the document) or has none."""
    try:
        found = driver.find_elements(By.CSS_SELECTOR, css)
        return found[0].text if found else None
    except (StaleElementReferenceException, WebDriverException):
        return None


def api_get(base, path):
    """GET a JSON resource over the API (not through the page)."""
    import json
    import urllib.request
    req = urllib.request.Request(base + path, headers={"Authorization": f"Bearer {KEY}"})
    with urllib.request.urlopen(req, timeout=30) as r:
        return json.loads(r.read())


def shifted_copy(src, dst, shift_mm):
    """`src` with every measured position moved by `shift_mm` (a rigid
    translation of the tracker frame): measured = target + dif, so the dif
    columns move."""
    with open(src) as f, open(dst, "w", newline="") as g:
        rows = list(csvmod.DictReader(f))
        out = csvmod.DictWriter(g, fieldnames=list(rows[0].keys()))
        out.writeheader()
        for r in rows:
            for k, d in zip(("x_dif", "y_dif", "z_dif"), shift_mm):
                r[k] = repr(float(r[k]) + d)
            out.writerow(r)


def api_post(base, path, body):
    """POST a JSON body over the API (not through the page); the JSON answer."""
    import json
    import urllib.request
    req = urllib.request.Request(base + path, data=json.dumps(body).encode(), method="POST",
                                 headers={"Authorization": f"Bearer {KEY}",
                                          "Content-Type": "application/json"})
    with urllib.request.urlopen(req, timeout=60) as r:
        return json.loads(r.read())


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_http(url, seconds=60):
    import urllib.request
    end = time.time() + seconds
    while time.time() < end:
        try:
            with urllib.request.urlopen(url, timeout=2) as r:
                if r.status == 200:
                    return
        except Exception:
            time.sleep(0.2)
    raise SystemExit(f"the service did not answer {url} within {seconds} s")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--robocal", default=str(ROOT / "target/debug/robocal"))
    ap.add_argument("--out", default=str(ROOT / "target/console-check"))
    ap.add_argument("--chromium", default=shutil.which("chromium") or "/usr/bin/chromium")
    ap.add_argument("--chromedriver", default=shutil.which("chromedriver") or "/usr/bin/chromedriver")
    args = ap.parse_args()
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for old in out.glob("*.png"):
        old.unlink()
    grid = DATA / "UR5/3D_UR5_uncalibrated_grid_cleaned.csv"
    random = DATA / "UR5/3D_UR5_uncalibrated_random_cleaned.csv"
    for f in (grid, random):
        if not f.exists():
            raise SystemExit(f"data not found: {f} (set ROBOCAL_DATA_DIR)")

    work = tempfile.mkdtemp(prefix="robocal-console-")
    # Calibrations wait while this file exists (the service's test gate):
    # the cancel step holds one there instead of hoping it still runs.
    gate = pathlib.Path(work) / "gate"
    port = free_port()
    base = f"http://127.0.0.1:{port}"
    env = dict(os.environ, DATABASE_URL=f"sqlite://{work}/console.db?mode=rwc",
               ROBOCAL_API_KEYS=KEY, ROBOCAL_OPEN_READS="1",
               ROBOCAL_TEST_GATE_FILE=str(gate),
               RUST_LOG="warn,robocal::service::gate=info")
    server = subprocess.Popen([args.robocal, "serve", "--bind", f"127.0.0.1:{port}"],
                              env=env, stdout=open(f"{work}/server.log", "w"),
                              stderr=subprocess.STDOUT)
    opts = Options()
    opts.binary_location = args.chromium
    for a in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage",
              "--window-size=1400,1000"):
        opts.add_argument(a)
    driver = None
    step = 0
    shots = []

    def shot(name, section=None):
        nonlocal step
        step += 1
        if section is not None:
            driver.execute_script(
                "arguments[0].scrollIntoView()", driver.find_element(By.ID, section))
        path = out / f"{step:02d}-{name}.png"
        driver.save_screenshot(str(path))
        shots.append(path.name)
        print(f"console_check: step {step} {name}: ok ({path})")

    try:
        wait_http(f"{base}/healthz")
        driver = webdriver.Chrome(service=Service(args.chromedriver), options=opts)
        wait = WebDriverWait(driver, 120)

        # 1. Start page, key, create a robot from the UR5 preset.
        driver.get(f"{base}/ui")
        key = driver.find_element(By.ID, "api-key")
        key.send_keys(KEY)
        key.send_keys("\t")
        form = driver.find_element(By.ID, "create-robot")
        form.find_element(By.NAME, "name").send_keys("UR5 cell 1")
        Select(form.find_element(By.NAME, "preset")).select_by_value("ur5")
        shot("robots")
        form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
        wait.until(EC.url_contains("/ui/robots/"))
        wait.until(EC.presence_of_element_located((By.ID, "upload")))
        shot("robot-created")

        # 2. Upload the grid (identification) and the random poses (validation).
        for n, (path, role) in enumerate(((grid, "identification"), (random, "validation"))):
            form = driver.find_element(By.ID, "upload")
            form.find_element(By.NAME, "file").send_keys(str(path))
            Select(form.find_element(By.NAME, "role")).select_by_value(role)
            form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
            # The page reloads when the upload is stored.
            wait.until(replaced(form))
            wait.until(lambda d: len(d.find_elements(By.CSS_SELECTOR, "#sets tbody tr")) == n + 1)
        rows = driver.find_elements(By.CSS_SELECTOR, "#sets tbody tr")
        assert len(rows) == 2, f"expected 2 sets, the page lists {len(rows)}"
        shot("uploaded", "sets")

        # 3. Calibrate with KM only, the grid picked as the identification set
        # and the random poses as the validation set; watch the job until it
        # succeeds.
        form = driver.find_element(By.ID, "calibrate")
        for box in form.find_elements(By.NAME, "method"):
            if box.is_selected() != (box.get_attribute("value") == "km"):
                box.click()
        picks = [form.find_elements(By.NAME, f"{role}_set") for role in ("identification", "validation")]
        assert [len(p) for p in picks] == [1, 1], f"set pickers: {[len(p) for p in picks]}"
        for p in picks:
            p[0].click()
        form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
        wait.until(replaced(form))
        wait.until(EC.presence_of_element_located((By.CSS_SELECTOR, "#calibrations tbody tr")))
        shot("calibration-started", "calibrations")
        wait.until(lambda d: d.find_element(By.CSS_SELECTOR, "#calibrations tbody tr .status").text
                   in ("succeeded", "failed", "cancelled"))
        status = driver.find_element(By.CSS_SELECTOR, "#calibrations tbody tr .status").text
        assert status == "succeeded", f"the calibration ended {status}"
        shot("calibration-done", "calibrations")

        # 4. The report.
        robot_url = driver.current_url
        driver.find_element(By.LINK_TEXT, "report").click()
        wait.until(EC.presence_of_element_located((By.TAG_NAME, "h1")))
        assert "KM" in driver.page_source, "the report does not show the KM method"
        shot("report")
        driver.get(robot_url)

        # 5. Versions: the first calibration activated its best; roll back is
        # refused with one activation only, so activate explicitly.
        wait.until(EC.presence_of_element_located((By.CSS_SELECTOR, "#versions tbody tr")))
        assert driver.find_elements(By.CSS_SELECTOR, "#versions tr.active"), "no active version"
        shot("versions", "versions")


        # 5b. Cancel a running calibration: the test gate holds an `auto`
        # job inside a candidate's cross-validation (the file's text: phase
        # `auto` from 11 %, past the first percent of the methods' 90 % so
        # with a time left, at a report that names a fold; the server logs
        # that it waits there), the Cancel button asks first (a dismissed
        # question sends nothing), then the job ends `cancelled`.
        gate.write_text("auto 11 fold\n")
        form = driver.find_element(By.ID, "calibrate")
        for box in form.find_elements(By.NAME, "method"):
            if box.is_selected() != (box.get_attribute("value") == "auto"):
                box.click()
        form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
        wait.until(replaced(form))
        log = pathlib.Path(work) / "server.log"
        wait.until(lambda d: "work held at the test gate" in log.read_text())
        wait.until(lambda d: text_of(d, "#calibrations tbody tr .status") == "running")
        # Live progress: the page polls the held job and shows the candidate
        # and fold it is held on, its percentage and the time left.
        # The row may first show reports from before the hold; the held one
        # (a fold at 11 % or later) stays.
        held_phase = re.compile(r"auto · ([a-z-]+) · fold (\d+)/(\d+)")
        held_percent = re.compile(r"(\d+) % · (\d+ s|\d+ min \d\d s|\d+ h \d\d min) left")

        def held_row(d):
            phase = held_phase.fullmatch(text_of(d, "#calibrations tbody tr .phase") or "")
            pct = held_percent.fullmatch(text_of(d, "#calibrations tbody tr .percent") or "")
            return (phase, pct) if phase and pct and int(pct.group(1)) >= 11 else None
        phase, pct = wait.until(held_row)
        candidate, index, of = phase.group(1), int(phase.group(2)), int(phase.group(3))
        assert candidate in ("km-rbf", "km-gp", "skcm-nn", "skcm-iwonn", "skcm-tlbonn", "skcm-gp",
                             "km-maps-gp", "skcm-maps-gp"), f"not a compensator: {candidate}"
        # 5 random folds and 4 blocked ones (the defaults).
        assert of == 9 and 1 <= index <= of, f"the held job's fold: {index}/{of}"
        print(f"console_check: held at {phase.group(0)}, {pct.group(0)}")
        shot("calibration-held", "calibrations")
        cancel = driver.find_element(By.CSS_SELECTOR, "#calibrations tbody tr button.cancel")
        cancel.click()
        alert = wait.until(EC.alert_is_present())
        assert alert.text.startswith("Cancel calibration"), alert.text
        alert.dismiss()
        assert text_of(driver, "#calibrations tbody tr .status") == "running", "a dismissed cancel must not be sent"
        cancel.click()
        wait.until(EC.alert_is_present()).accept()
        wait.until(lambda d: text_of(d, "#calibrations tbody tr .status") == "cancelled")
        gate.unlink()
        shot("calibration-cancelled", "calibrations")
        statuses = [td.text for td in driver.find_elements(By.CSS_SELECTOR, "#calibrations tbody tr .status")]
        assert statuses == ["cancelled", "succeeded"], statuses

        # 6. Solve: the first 10 nominal targets of the random set, position
        # only, with the active version; the CSV answer is shown and offered.
        targets = pathlib.Path(work) / "targets.csv"
        with open(random) as f, open(targets, "w") as g:
            rows = list(csvmod.DictReader(f))[:10]
            g.write("id,x,y,z\n")
            for i, r in enumerate(rows):
                g.write(f"t{i + 1},{r['x_t']},{r['y_t']},{r['z_t']}\n")
        form = driver.find_element(By.ID, "solve")
        form.find_element(By.NAME, "file").send_keys(str(targets))
        form.find_element(By.NAME, "position_only").click()
        form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
        wait.until(EC.visibility_of_element_located((By.ID, "solve-result")))
        summary = driver.find_element(By.ID, "solve-summary").text
        assert summary.startswith("10 of 10 targets solved"), f"solve: {summary}"
        answer = driver.find_element(By.ID, "solve-csv").text.splitlines()
        assert answer[0].startswith("id,status,reason,branch,j1_deg"), answer[0]
        assert len(answer) == 11 and all(",ok," in l for l in answer[1:]), answer
        shot("solved", "solve-section")

        # 6b. Is it still accurate? Check the active version on the random
        # set: the check's page shows the status with its sentence, the
        # figures, the frame shift, the thresholds and every pose's error.
        active_version = int(driver.find_element(
            By.CSS_SELECTOR, "#versions tr.active td").text.split()[0][1:])
        robot_id = int(robot_url.rstrip("/").split("/")[-1])

        def run_check(set_id):
            form = driver.find_element(By.ID, "run-check")
            Select(form.find_element(By.NAME, "set_id")).select_by_value(str(set_id))
            form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
            wait.until(EC.url_contains("/checks/"))
            wait.until(EC.presence_of_element_located((By.ID, "check-summary")))

        set_ids = [int(td.text) for td in driver.find_elements(By.CSS_SELECTOR, "#sets tbody tr td:first-child")]
        random_set = set_ids[1]
        run_check(random_set)
        status = driver.find_element(By.CSS_SELECTOR, "#check-verdict .status-tag").text.split()[0]
        assert status in ("ok", "degraded", "recalibrate", "shifted"), status
        assert driver.find_element(By.ID, "check-summary").text, "no summary sentence"
        poses = driver.find_elements(By.CSS_SELECTOR, "#check-poses tbody tr")
        assert len(poses) == 20, f"expected the 20 poses' errors, the page lists {len(poses)}"
        figures = driver.find_element(By.ID, "check-figures").text
        assert "Frame shift" in figures and "degraded above 0.500 mm" in figures, figures
        for number in re.findall(r"-?\d+\.\d+", figures + driver.find_element(By.ID, "check-poses").text):
            assert len(number.split(".")[1]) in (1, 2, 3, 4), f"a number to too many decimals: {number}"
            assert not re.fullmatch(r"-0\.0*", number), f"a negative zero: {number}"
        shot("check-detail")
        driver.find_element(By.LINK_TEXT, driver.find_element(By.CSS_SELECTOR, ".crumbs a + a").text).click()
        wait.until(EC.presence_of_element_located((By.ID, "check-trend")))
        rows = driver.find_elements(By.CSS_SELECTOR, "#checks tbody tr")
        assert len(rows) == 1, f"expected one check, the page lists {len(rows)}"
        assert len(driver.find_elements(By.CSS_SELECTOR, "#check-trend .check-point")) == 1
        # Local times: the cell shows the browser's rendering, the UTC stamp stays in the title.
        cell = driver.find_element(By.CSS_SELECTOR, "#checks tbody tr time")
        assert cell.get_attribute("title") == cell.get_attribute("datetime"), cell.get_attribute("title")
        assert cell.text != cell.get_attribute("datetime"), cell.text
        form = driver.find_element(By.ID, "compare")
        form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
        wait.until(EC.visibility_of_element_located((By.ID, "compare-result")))
        compared = driver.find_elements(By.CSS_SELECTOR, "#compare-result tbody tr.compared")
        assert len(compared) == len(driver.find_elements(By.CSS_SELECTOR, "#versions tbody tr")), len(compared)
        shot("checks", "checks-section")
        rollback = driver.find_element(By.ID, "rollback")
        rollback.click()
        alert = wait.until(EC.alert_is_present())
        assert "Roll back" in alert.text, alert.text
        alert.dismiss()
        assert rollback.is_enabled(), "a dismissed roll back must not be sent"
        assert driver.find_elements(By.CSS_SELECTOR, "#versions tr.active"), "still an active version"

        # 6c. Thresholds: set tighter ones in the form; the page and the
        # trend show them, and the API reads them back.
        form = driver.find_element(By.ID, "check-thresholds-form")
        for k, v in (("degraded_mm", "0.6"), ("recalibrate_mm", "1.2")):
            box = form.find_element(By.NAME, k)
            box.clear()
            box.send_keys(v)
        form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
        wait.until(replaced(form))
        wait.until(EC.presence_of_element_located((By.ID, "thresholds-text")))
        text = driver.find_element(By.ID, "thresholds-text").text
        assert "degraded above 0.600 mm, recalibrate above 1.200 mm" in text, text
        t = api_get(base, f"/v1/robots/{robot_id}/status")["thresholds"]
        assert (t["degraded_mm"], t["recalibrate_mm"]) == (0.6, 1.2), t
        assert len(driver.find_elements(By.CSS_SELECTOR, "#check-trend line.threshold")) == 2
        shot("thresholds", "checks-section")

        # 6d. The tracker moved: the same poses measured 2.5 mm off. A check
        # says `shifted`, its page offers the re-registration; re-register
        # (a new version, not yet active), activate it (asked first), check
        # again: the shift is gone.
        moved = pathlib.Path(work) / "moved.csv"
        shifted_copy(random, moved, (1.5, -2.0, 0.0))
        form = driver.find_element(By.ID, "upload")
        form.find_element(By.NAME, "file").send_keys(str(moved))
        Select(form.find_element(By.NAME, "role")).select_by_value("check")
        form.find_element(By.NAME, "name").send_keys("after the move")
        form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
        wait.until(replaced(form))
        wait.until(lambda d: len(d.find_elements(By.CSS_SELECTOR, "#sets tbody tr")) == 3)
        moved_set = max(int(td.text) for td in driver.find_elements(By.CSS_SELECTOR, "#sets tbody tr td:first-child"))
        run_check(moved_set)
        tag = driver.find_element(By.CSS_SELECTOR, "#check-verdict .status-tag").text
        assert tag.startswith("shifted"), f"the moved set should say shifted: {tag}"
        assert "explains the errors" in driver.find_element(By.ID, "check-frame-shift").text
        assert driver.find_elements(By.CSS_SELECTOR, "section.alert #reregister"), "no re-register button"
        shot("check-shifted")
        driver.get(robot_url)
        wait.until(EC.presence_of_element_located((By.ID, "shifted-action")))
        shot("status-shifted", "checks-section")
        driver.find_element(By.CSS_SELECTOR, "#shifted-action a").click()
        wait.until(EC.presence_of_element_located((By.ID, "reregister")))
        form = driver.find_element(By.ID, "reregister")
        form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
        wait.until(EC.url_contains("#versions"))
        wait.until(EC.presence_of_element_located((By.CSS_SELECTOR, "#versions .reregistered")))
        msg = driver.find_element(By.ID, "message").text
        assert msg.startswith("Re-registered as v"), msg
        new_version = int(msg.split()[2].rstrip(":")[1:])
        note = driver.find_element(By.CSS_SELECTOR, "#versions .reregistered").text
        assert f"from v{active_version} on set {moved_set}" in note, note
        assert int(driver.find_element(By.CSS_SELECTOR, "#versions tr.active td").text.split()[0][1:]) == active_version
        shot("reregistered", "versions")
        activate = driver.find_element(
            By.CSS_SELECTOR, f"#versions button[data-post$='/versions/{new_version}/activate']")
        activate.click()
        alert = wait.until(EC.alert_is_present())
        assert f"Activate v{new_version}" in alert.text, alert.text
        alert.accept()
        wait.until(replaced(activate))
        wait.until(EC.presence_of_element_located((By.CSS_SELECTOR, "#versions tr.active")))
        active = driver.find_element(By.CSS_SELECTOR, "#versions tr.active td").text.split()[0]
        assert active == f"v{new_version}", active
        shot("activated", "versions")
        run_check(moved_set)
        tag = driver.find_element(By.CSS_SELECTOR, "#check-verdict .status-tag").text
        assert tag.split()[0] in ("ok", "degraded"), f"after re-registration: {tag}"
        shot("check-after-reregister")
        driver.get(robot_url)
        wait.until(EC.presence_of_element_located((By.ID, "check-trend")))
        assert len(driver.find_elements(By.CSS_SELECTOR, "#check-trend .check-point")) == 3
        assert len(driver.find_elements(By.CSS_SELECTOR, "#check-trend .version-change")) == 1
        # A time axis, and a scale the one outlier (the shifted check, about
        # 2.5 mm) does not set: the thresholds stay in the plot and the
        # outlier sits on the top edge with its value.
        ticks = [t.text for t in driver.find_elements(By.CSS_SELECTOR, "#check-trend text.time-tick")]
        assert len(ticks) >= 2 and all(ticks), f"time axis ticks: {ticks}"
        top = max(float(t.text) for t in driver.find_elements(By.CSS_SELECTOR, "#check-trend text.y-tick"))
        assert 1.2 <= top < 2.0, f"the y axis tops out at {top} mm"
        off = [t.text for t in driver.find_elements(By.CSS_SELECTOR, "#check-trend text.off-scale-label")]
        assert len(off) == 1 and off[0].startswith("↑ ") and float(off[0][2:]) > top, \
            f"off-scale labels: {off} above {top} mm"
        shot("trend", "checks-section")

        # 7. Tools and work objects: add a tool with its load and a work
        # object, edit the tool in its prefilled form (only x changes) and
        # read it back over the API: its number and load are kept. Add a
        # spare tool and delete it, asked first (a dismissed question keeps it).
        def fill(form, values):
            for k, v in values.items():
                box = form.find_element(By.NAME, k)
                if box.tag_name == "select":
                    Select(box).select_by_value(v)
                else:
                    box.clear()
                    box.send_keys(str(v))

        def save_item(form_id, values):
            form = driver.find_element(By.ID, form_id)
            fill(form, values)
            form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
            wait.until(replaced(form))
            wait.until(EC.presence_of_element_located((By.ID, "add-tool")))

        def names(table_id):
            return [td.text for td in driver.find_elements(By.CSS_SELECTOR, f"#{table_id} td.name")]

        save_item("add-tool", dict(name="torch", number=1, x=125, y=0, z=216.5, rx=0, ry=30, rz=0,
                                   load_mass_kg=2.5, load_com_x=0, load_com_y=10, load_com_z=80,
                                   load_frame="tool", load_ixx=0.01, load_iyy=0.02, load_izz=0.015))
        save_item("add-tool", dict(name="spare", number=2, x=0, y=0, z=100))
        save_item("add-frame", dict(name="table", number=1, frame="base", x=450, y=-100, z=50, rz=20))
        assert names("tools") == ["spare", "torch"], names("tools")
        assert names("work-objects") == ["table"], names("work-objects")
        before = api_get(base, f"/v1/robots/{robot_id}/tools/torch")
        assert before["load"]["mass_kg"] == 2.5 and before["number"] == 1, before
        shot("cell", "cell")
        row = driver.find_element(By.CSS_SELECTOR, "#tools tr[data-item=torch]")
        row.find_element(By.CSS_SELECTOR, "details.edit summary").click()
        form = driver.find_element(By.ID, "edit-tools-torch")
        assert form.find_element(By.NAME, "load_mass_kg").get_attribute("value") == "2.5"
        assert form.find_element(By.NAME, "number").get_attribute("value") == "1"
        shot("tool-edit", "cell")
        save_item("edit-tools-torch", dict(x=126))
        after = api_get(base, f"/v1/robots/{robot_id}/tools/torch")
        expected = dict(before, xyz_mm=[126.0, 0.0, 216.5])
        for k in ("name", "number", "xyz_mm", "rpy_deg", "load"):
            assert after.get(k) == expected.get(k), f"re-saving the tool changed {k}: {before.get(k)} -> {after.get(k)}"
        load_text = driver.find_element(By.CSS_SELECTOR, "#tools tr[data-item=torch] td.load").text
        assert load_text.startswith("2.500 kg at 0.000, 10.000, 80.000 mm (tool)"), load_text
        button = driver.find_element(By.CSS_SELECTOR, "#tools tr[data-item=spare] button[data-delete]")
        button.click()
        alert = wait.until(EC.alert_is_present())
        assert "Delete tool spare?" in alert.text, alert.text
        alert.dismiss()
        assert names("tools") == ["spare", "torch"], names("tools")
        button.click()
        wait.until(EC.alert_is_present()).accept()
        wait.until(replaced(button))
        wait.until(EC.presence_of_element_located((By.ID, "add-tool")))
        assert names("tools") == ["torch"], names("tools")

        # 7b. The controller's data for the tools, loads and work objects.
        form = driver.find_element(By.ID, "export-cell")
        Select(form.find_element(By.NAME, "language")).select_by_value("krl")
        form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
        wait.until(EC.visibility_of_element_located((By.ID, "export-result")))
        text = driver.find_element(By.ID, "export-text").text
        assert "TOOL_DATA[1]" in text and "LOAD_DATA[1]" in text and "BASE_DATA[1]" in text, text
        downloaded = driver.execute_async_script(
            "const done = arguments[0];"
            "fetch(document.getElementById('export-download').href).then(r => r.text()).then(done);")
        shown = driver.execute_script("return document.getElementById('export-text').textContent")
        assert downloaded == shown, "the download differs from the data shown"
        shot("controller-data", "cell")

        # 7c. Predict the torch's pose from three readings of the random set.
        with open(random) as f:
            joints = [[r[f"joint_{j}"] for j in range(1, 7)] for r in list(csvmod.DictReader(f))[:3]]
        form = driver.find_element(By.ID, "predict")
        form.find_element(By.NAME, "readings").send_keys(
            "\n".join(f"p{i + 1}, " + ", ".join(js) for i, js in enumerate(joints)))
        Select(form.find_element(By.NAME, "tool")).select_by_value("torch")
        form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
        wait.until(EC.visibility_of_element_located((By.ID, "predict-result")))
        rows = driver.find_elements(By.CSS_SELECTOR, "#predict-table tbody tr")
        assert [r.find_elements(By.TAG_NAME, "td")[1].text for r in rows] == ["ok"] * 3, \
            [r.text for r in rows]
        x = rows[0].find_elements(By.TAG_NAME, "td")[2].text
        assert re.fullmatch(r"-?\d+\.\d{3}", x), f"x to 0.001 mm: {x}"
        shot("predicted", "predict-section")

        # 7c'. Every option of predict: the same readings in the base frame,
        # then in the work object `table` (base frame, at 450, -100, 50 mm,
        # turned 20° about z) with the torch's 2.5 kg given and KUKA A, B, C
        # beside rx, ry, rz. The work object's pose is the base pose moved by
        # the inverse of the table's transform; A, B, C = rz, ry, rx (both
        # R = Rz·Ry·Rx).
        def predict(frame, **extra):
            form = driver.find_element(By.ID, "predict")
            summary = driver.find_element(By.ID, "predict-summary").text
            fill(form, dict(frame=frame, **extra))
            form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
            wait.until(lambda d: d.find_element(By.ID, "predict-summary").text != summary)
            return [[td.text for td in r.find_elements(By.TAG_NAME, "td")]
                    for r in driver.find_elements(By.CSS_SELECTOR, "#predict-table tbody tr")]

        in_base = predict("base")
        in_table = predict("wobj:table", payload_kg="2.5", convention="kuka_abc")
        summary = driver.find_element(By.ID, "predict-summary").text
        assert "work_object frame at 2.500 kg" in summary, summary
        assert driver.find_element(By.ID, "predict-convention").text == "kuka_abc"
        turn = math.radians(20.0)
        for b, w in zip(in_base, in_table):
            dx, dy, dz = float(b[2]) - 450.0, float(b[3]) + 100.0, float(b[4]) - 50.0
            want = (math.cos(turn) * dx + math.sin(turn) * dy,
                    -math.sin(turn) * dx + math.cos(turn) * dy, dz)
            got = tuple(float(v) for v in w[2:5])
            assert all(abs(g - e) < 0.003 for g, e in zip(got, want)), (b, w, want)
            abc = [float(v) for v in w[8].split(", ")]
            rpy = [float(v) for v in w[5:8]]
            for a, r in zip(abc, reversed(rpy)):
                assert abs((a - r + 180.0) % 360.0 - 180.0) < 0.001, (w, abc, rpy)
        shot("predicted-work-object", "predict-section")

        # 7d. Fits: a work object from three tracker points (stored, listed
        # with the version's base-frame pose), and a tool's TCP from the
        # moved set's 20 readings (joints and the tracker's position of the
        # reflector, the tool frame parallel to the flange's): stored.
        form = driver.find_element(By.ID, "fit-frame")
        fill(form, dict(name="fixture"))
        form.find_element(By.NAME, "readings").send_keys(
            "origin, 400, 0, 100\nx, 500, 0, 100\nxy, 400, 100, 100")
        form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
        wait.until(replaced(form))
        wait.until(EC.presence_of_element_located((By.ID, "fit-frame")))
        msg = driver.find_element(By.ID, "message").text
        assert msg.startswith("Fitted work object fixture on v"), msg
        assert names("work-objects") == ["fixture", "table"], names("work-objects")
        shot("work-object-fitted", "cell")
        with open(moved) as f:
            lines = [", ".join([r[f"joint_{j}"] for j in range(1, 7)]
                               + [repr(float(r[f"{a}_t"]) + float(r[f"{a}_dif"])) for a in "xyz"])
                     for r in csvmod.DictReader(f)]
        form = driver.find_element(By.ID, "fit-tool")
        # Named version (the active one, re-registered on the moved set) and tool number.
        active = api_get(base, f"/v1/robots/{robot_id}")["active_version"]
        fill(form, dict(name="probe", method="tracker_point", rpy="0, 0, 0", number=7, version=active))
        driver.execute_script("arguments[0].value = arguments[1]",
                              form.find_element(By.NAME, "readings"), "\n".join(lines))
        form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
        wait.until(lambda d: text_of(d, "#message") and (
            text_of(d, "#message").startswith("Fitted tool probe") or "not fitted" in text_of(d, "#message")))
        msg = driver.find_element(By.ID, "message").text
        assert msg.startswith(f"Fitted tool probe on v{active}:"), msg
        assert names("tools") == ["probe", "torch"], names("tools")
        assert api_get(base, f"/v1/robots/{robot_id}/tools/probe")["number"] == 7
        shot("tool-fitted", "cell")

        # 7d'. A 6-D probe: the tool `probe6` at a known offset from the
        # flange, its frame measured by the tracker at the moved set's 20
        # joint readings. The readings are made here: the active version's
        # pose of the known tool in the measurement frame (predict over the
        # API), plus seeded noise of 0.01 mm per axis and a 0.002° rotation
        # per axis. The console's 6-D fit must find the offset again within
        # four standard errors of that noise (σ/√20 per axis).
        known_xyz, known_rpy = [40.0, -25.0, 180.0], [10.0, 25.0, -5.0]
        with open(moved) as f:
            joints = [[float(r[f"joint_{j}"]) for j in range(1, 7)] for r in csvmod.DictReader(f)]
        poses = api_post(base, f"/v1/robots/{robot_id}/predict", {
            "readings": [{"joints_deg": q} for q in joints],
            "tool": {"xyz_mm": known_xyz, "rpy_deg": known_rpy}})["results"]
        rng = Random(2026)
        noise_mm, noise_deg = 0.01, 0.002
        lines = []
        for q, p in zip(joints, poses):
            assert p["status"] == "ok", p
            xyz = [p[a] + rng.gauss(0.0, noise_mm) for a in "xyz"]
            turn = rotation([rng.gauss(0.0, noise_deg) for _ in range(3)])
            rpy = fixed_xyz(matmul(turn, rotation_rpy([p["rx"], p["ry"], p["rz"]])))
            lines.append(", ".join(repr(v) for v in q + xyz + rpy))
        form = driver.find_element(By.ID, "fit-tool")
        fill(form, dict(name="probe6", method="tracker_frame", rpy="", number="", version=""))
        driver.execute_script("arguments[0].value = arguments[1]",
                              form.find_element(By.NAME, "readings"), "\n".join(lines))
        form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
        wait.until(lambda d: text_of(d, "#message") and (
            text_of(d, "#message").startswith("Fitted tool probe6") or "not fitted" in text_of(d, "#message")))
        msg = driver.find_element(By.ID, "message").text
        assert msg.startswith("Fitted tool probe6 on v") and "rx, ry, rz" in msg, msg
        fitted = api_get(base, f"/v1/robots/{robot_id}/tools/probe6")
        bound_mm = 4.0 * noise_mm / math.sqrt(len(lines))
        off = [g - k for g, k in zip(fitted["xyz_mm"], known_xyz)]
        assert all(abs(d) < bound_mm for d in off), f"TCP off by {off} mm (bound {bound_mm:.4f})"
        angle = rotation_angle(rotation_rpy(fitted["rpy_deg"]), rotation_rpy(known_rpy))
        bound_deg = 4.0 * noise_deg * math.sqrt(3.0 / len(lines))
        assert angle < bound_deg, f"tool frame off by {angle}° (bound {bound_deg:.5f}°)"
        shown = driver.find_element(By.CSS_SELECTOR, "#tools tr[data-item=probe6] td.pose").text
        want = ", ".join(f"{v:.3f}" for v in fitted["xyz_mm"]) + " mm · " \
            + ", ".join(f"{v:.4f}" for v in fitted["rpy_deg"]) + "°"
        assert shown == want, (shown, want)
        print(f"console_check: 6-D probe fit off by {max(abs(d) for d in off):.5f} mm "
              f"(bound {bound_mm:.5f}) and {angle:.5f}° (bound {bound_deg:.5f})")
        shot("tool-fitted-6d", "cell")
        # A work object deleted, asked first.
        button = driver.find_element(By.CSS_SELECTOR, "#work-objects tr[data-item=fixture] button[data-delete]")
        button.click()
        alert = wait.until(EC.alert_is_present())
        assert "Delete work object fixture?" in alert.text, alert.text
        alert.accept()
        wait.until(replaced(button))
        wait.until(EC.presence_of_element_located((By.ID, "add-tool")))
        assert names("work-objects") == ["table"], names("work-objects")

        # 7e. A 6-D check set uploaded in another orientation convention: the
        # measured point's pose at the moved set's joints (predict, no tool)
        # with the same kind of seeded noise, its orientation written as
        # intrinsic x, y', z'' angles (R = Rx·Ry·Rz) and uploaded with that
        # convention chosen in the form. Checked, its errors are the noise's:
        # under 0.01° and 0.05 mm mean (the same angles read as fixed-axis
        # ones would be degrees off, checked here too).
        points = api_post(base, f"/v1/robots/{robot_id}/predict",
                          {"readings": [{"joints_deg": q} for q in joints]})["results"]
        six = pathlib.Path(work) / "six-d.csv"
        misread = []
        with open(six, "w") as g:
            g.write("q1,q2,q3,q4,q5,q6,x,y,z,rx,ry,rz\n")
            for q, p in zip(joints, points):
                assert p["status"] == "ok", p
                xyz = [p[a] + rng.gauss(0.0, noise_mm) for a in "xyz"]
                turn = rotation([rng.gauss(0.0, noise_deg) for _ in range(3)])
                r = matmul(turn, rotation_rpy([p["rx"], p["ry"], p["rz"]]))
                abc = intrinsic_xyz(r)
                misread.append(rotation_angle(rotation_rpy(abc), r))
                g.write(",".join(repr(v) for v in q + xyz + abc) + "\n")
        assert statistics.mean(misread) > 1.0, f"the conventions barely differ here: {misread}"
        n_sets = len(driver.find_elements(By.CSS_SELECTOR, "#sets tbody tr"))
        form = driver.find_element(By.ID, "upload")
        form.find_element(By.NAME, "file").send_keys(str(six))
        Select(form.find_element(By.NAME, "role")).select_by_value("check")
        Select(form.find_element(By.NAME, "orientation")).select_by_value("intrinsic_xyz")
        form.find_element(By.NAME, "name").send_keys("6-D probe")
        form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
        wait.until(replaced(form))
        wait.until(lambda d: len(d.find_elements(By.CSS_SELECTOR, "#sets tbody tr")) == n_sets + 1)
        six_set = max(int(td.text) for td in driver.find_elements(By.CSS_SELECTOR, "#sets tbody tr td:first-child"))
        run_check(six_set)
        orientation = driver.find_element(
            By.XPATH, "//table[@id='check-figures']//tr[th[starts-with(., 'Orientation error')]]/td").text
        assert float(orientation.split(" / ")[0]) < 0.01, f"orientation error mean / p95 / max: {orientation}"
        position = driver.find_element(By.CSS_SELECTOR, "#check-figures td.position").text
        assert float(position.split(" / ")[0]) < 0.05, f"position error mean / p95 / max: {position}"
        shot("check-6d-intrinsic")
        driver.get(robot_url)
        wait.until(EC.presence_of_element_located((By.ID, "add-tool")))
        n_sets += 1

        # 7f. External axes on a second robot (scripts/console_check_axes.py).
        check_external_axes(driver, wait, shot, base, args.robocal, work, robot_url, sys.modules[__name__])

        # 8. Filter the sample URScript program: the report lists its targets
        # and the filtered file is offered for download.
        program = ROOT / "examples/programs/urscript/seam.script"
        form = driver.find_element(By.ID, "filter")
        form.find_element(By.NAME, "files").send_keys(str(program))
        form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
        wait.until(EC.visibility_of_element_located((By.ID, "filter-result")))
        summary = driver.find_element(By.ID, "filter-summary").text
        m = re.match(r"(\d+) targets filtered, (\d+) failed, (\d+) skipped", summary)
        assert m and int(m.group(1)) > 0, f"filter: {summary}"
        rows = driver.find_elements(By.CSS_SELECTOR, "#filter-report tbody tr")
        assert len(rows) == sum(int(g) for g in m.groups()), (summary, len(rows))
        links = [a.text for a in driver.find_elements(By.CSS_SELECTOR, "#filter-downloads a.filtered-file")]
        assert links == ["seam.script"], links
        filtered = driver.execute_async_script(
            "const done = arguments[0];"
            "fetch(document.querySelector('#filter-downloads a').href)"
            ".then(r => r.text()).then(done);")
        original = program.read_text()
        assert filtered != original and len(filtered.splitlines()) == len(original.splitlines()), \
            "the filtered program should differ in its target values only"
        report = driver.execute_async_script(
            "const done = arguments[0];"
            "fetch(document.getElementById('filter-report-download').href).then(r => r.json()).then(done);")
        assert len(report["targets"]) == len(rows), "the report download lists other targets"
        shot("filtered", "filter-section")

        # 8b. A measurement plan: 12 poses in a box, a KRL program and the
        # joints CSV to download, every identified parameter's predicted std.
        form = driver.find_element(By.ID, "measurement-plan")
        # Every option: the reflector's axis along the tool's x, a 3 kg
        # payload, the KRL program named CELL_PLAN.
        fill(form, dict(poses=12, candidates=200, max_angle_deg=180, axis_x=1, axis_z=0,
                        payload_kg=3, language="krl", name="CELL_PLAN"))
        form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
        wait.until(EC.visibility_of_element_located((By.ID, "plan-result")))
        summary = driver.find_element(By.ID, "plan-summary").text
        assert summary.startswith("12 poses chosen from 200 candidates"), summary
        assert summary.endswith("at 3.000 kg"), summary
        files = [a.text for a in driver.find_elements(By.CSS_SELECTOR, "#plan-downloads a.plan-file")]
        assert files[0] == "plan-joints.csv" and "CELL_PLAN.src" in files, files
        joints_csv = driver.execute_async_script(
            "const done = arguments[0];"
            "fetch(document.querySelector('#plan-downloads a').href).then(r => r.text()).then(done);")
        assert len(joints_csv.strip().splitlines()) == 13, joints_csv
        assert driver.find_elements(By.CSS_SELECTOR, "#plan-params tr.plan-param"), "no predicted std"
        shot("measurement-plan", "plan-section")

        # 8c. ISO 9283: lay out the cube on the active version, measure five
        # cycles (made here: each pose's commanded position plus offsets
        # whose mean is (0.1, -0.05, 0) mm, so AP = 0.112 mm at every pose),
        # the figures and the report.
        form = driver.find_element(By.ID, "iso-plan")
        Select(form.find_element(By.NAME, "language")).select_by_value("urscript")
        fill(form, dict(cycles=5))
        form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
        wait.until(EC.visibility_of_element_located((By.ID, "iso-plan-result")))
        assert len(driver.find_elements(By.CSS_SELECTOR, "#iso-plan-poses tr.iso-pose")) == 5
        plan_csv = driver.execute_script("return document.querySelector('#iso-figures [name=plan_csv]').value")
        measured = pathlib.Path(work) / "iso-measured.csv"
        with open(measured, "w") as g:
            g.write("pose,cycle,x_mm,y_mm,z_mm\n")
            for r in csvmod.DictReader(plan_csv.splitlines()):
                for k in range(1, 6):
                    x, y, z = (float(r[c]) for c in ("x_mm", "y_mm", "z_mm"))
                    g.write(f"{r['pose']},{k},{x + 0.1 + 0.01 * (k - 3)!r},{y - 0.05!r},{z + 0.02 * (k - 3)!r}\n")
        # A second test beside it, "after": offsets whose mean is (0, 0.03,
        # 0.04) mm, so AP = 0.050 mm at every pose; and the test conditions.
        after = pathlib.Path(work) / "iso-after.csv"
        with open(after, "w") as g:
            g.write("pose,cycle,x_mm,y_mm,z_mm\n")
            for r in csvmod.DictReader(plan_csv.splitlines()):
                for k in range(1, 6):
                    x, y, z = (float(r[c]) for c in ("x_mm", "y_mm", "z_mm"))
                    g.write(f"{r['pose']},{k},{x + 0.01 * (k - 3)!r},{y + 0.03!r},{z + 0.04 + 0.02 * (k - 3)!r}\n")
        shot("iso-plan", "iso-section")
        form = driver.find_element(By.ID, "iso-figures")
        form.find_element(By.NAME, "measured_file").send_keys(str(measured))
        form.find_element(By.NAME, "measured_file_2").send_keys(str(after))
        fill(form, dict(load_kg=3.5, speed_percent=100, measurement="laser tracker AT960"))
        form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
        wait.until(EC.visibility_of_element_located((By.ID, "iso-result")))
        heads = [th.text for th in driver.find_elements(By.CSS_SELECTOR, "#iso-poses thead th")]
        assert heads[2] == "AP [mm] (before)" and heads[6] == "AP [mm] (after)", heads
        figures = driver.find_elements(By.CSS_SELECTOR, "#iso-poses tr.iso-figure")
        aps = [(r.find_elements(By.TAG_NAME, "td")[2].text, r.find_elements(By.TAG_NAME, "td")[6].text)
               for r in figures]
        assert aps == [("0.112", "0.050")] * 5, aps
        assert len(driver.find_elements(By.CSS_SELECTOR, "#iso-distances tr.iso-distance")) == 10
        conditions = driver.find_element(By.ID, "iso-conditions").text
        assert re.match(r"UR5 cell 1, model v\d+, \d{4}-\d{2}-\d{2}; ", conditions) and "load 3.5 kg, speed 100 %" in conditions \
            and "laser tracker AT960" in conditions, conditions
        report = driver.execute_async_script(
            "const done = arguments[0];"
            "fetch(document.getElementById('iso-report-download').href).then(r => r.text()).then(done);")
        assert "<html" in report.lower() and "P1" in report, report[:200]
        assert "UR5 cell 1" in report and "laser tracker AT960" in report and "after" in report, report[:400]
        shot("iso-figures", "iso-result")

        # 8d. Roll back (asked first): the version active before the
        # re-registration is active again, on the page and over the API.
        rollback = driver.find_element(By.ID, "rollback")
        rollback.click()
        alert = wait.until(EC.alert_is_present())
        assert "Roll back" in alert.text, alert.text
        alert.accept()
        wait.until(replaced(rollback))
        wait.until(EC.presence_of_element_located((By.CSS_SELECTOR, "#versions tr.active")))
        active = driver.find_element(By.CSS_SELECTOR, "#versions tr.active td").text.split()[0]
        assert active == f"v{active_version}", f"after the roll back {active} is active"
        assert api_get(base, f"/v1/robots/{robot_id}")["active_version"] == active_version
        shot("rolled-back", "versions")

        # 9. Delete a set (asked first): a spare upload of eight poses.
        spare = pathlib.Path(work) / "spare.csv"
        spare.write_text("".join(random.read_text().splitlines(keepends=True)[:9]))
        form = driver.find_element(By.ID, "upload")
        form.find_element(By.NAME, "file").send_keys(str(spare))
        Select(form.find_element(By.NAME, "role")).select_by_value("check")
        form.find_element(By.NAME, "name").send_keys("spare")
        form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
        wait.until(replaced(form))
        wait.until(lambda d: len(d.find_elements(By.CSS_SELECTOR, "#sets tbody tr")) == n_sets + 1)
        button = driver.find_elements(By.CSS_SELECTOR, "#sets tbody tr button[data-delete]")[-1]
        button.click()
        alert = wait.until(EC.alert_is_present())
        assert "Delete set" in alert.text and "(spare)" in alert.text, alert.text
        alert.accept()
        wait.until(replaced(button))
        wait.until(lambda d: len(d.find_elements(By.CSS_SELECTOR, "#sets tbody tr")) == n_sets)
        shot("set-deleted", "sets")

        # 10. The robot list shows each robot's latest check; a second robot
        # is created and deleted from its page (asked first).
        driver.get(f"{base}/ui")
        cell = driver.find_element(By.CSS_SELECTOR, "#robots td.latest-check")
        assert cell.text.split()[0] in ("ok", "degraded"), cell.text
        form = driver.find_element(By.ID, "create-robot")
        form.find_element(By.NAME, "name").send_keys("scratch")
        form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
        wait.until(EC.presence_of_element_located((By.ID, "delete-robot")))
        button = driver.find_element(By.ID, "delete-robot")
        button.click()
        alert = wait.until(EC.alert_is_present())
        assert "Delete robot" in alert.text and "scratch" in alert.text, alert.text
        alert.accept()
        wait.until(EC.url_to_be(f"{base}/ui"))
        wait.until(EC.presence_of_element_located((By.ID, "robots")))
        assert [a.text for a in driver.find_elements(By.CSS_SELECTOR, "#robots tbody td a[href^='/ui/robots/']")] \
            and "scratch" not in driver.find_element(By.ID, "robots").text
        shot("robots-final")

        print(f"console_check: the whole flow passed; screenshots in {out}")
    finally:
        # One page with every screenshot, for the CI run's artifacts.
        (out / "index.html").write_text(
            "<!doctype html><meta charset=utf-8><title>robocal console check</title>\n"
            + "".join(f"<h2>{n}</h2><img src='{n}' width=1000>\n" for n in shots))
        if driver is not None:
            driver.quit()
        server.terminate()
        server.wait(timeout=30)


if __name__ == "__main__":
    sys.exit(main())
