#!/usr/bin/env python3
"""Drives the web console in a real browser through the whole flow and saves a
screenshot of each step:

  create robot -> upload measurements -> calibrate (live progress) -> report
  -> versions (the best is active) -> solve a targets CSV into a CSV answer
  -> tools and work objects (add, delete) -> filter a URScript program

against a real `robocal serve` with API keys on a temporary database, using
Debian's Chromium and chromedriver through Selenium.

    scripts/console_check.sh [path/to/robocal]     (installs what it needs)
    python3 scripts/console_check.py --robocal target/debug/robocal --out DIR

Data: the real UR5 laser-tracker set in data/ur5-wam-laser-tracker (grid for
identification, the 20 random poses for validation). Exits non-zero on the
first step that does not behave.
"""
import argparse
import os
import pathlib
import shutil
import socket
import subprocess
import sys
import tempfile
import time

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
    grid = DATA / "UR5/3D_UR5_uncalibrated_grid_cleaned.csv"
    random = DATA / "UR5/3D_UR5_uncalibrated_random_cleaned.csv"
    for f in (grid, random):
        if not f.exists():
            raise SystemExit(f"data not found: {f} (set ROBOCAL_DATA_DIR)")

    work = tempfile.mkdtemp(prefix="robocal-console-")
    port = free_port()
    base = f"http://127.0.0.1:{port}"
    env = dict(os.environ, DATABASE_URL=f"sqlite://{work}/console.db?mode=rwc",
               ROBOCAL_API_KEYS=KEY, ROBOCAL_OPEN_READS="1", RUST_LOG="warn")
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

    def shot(name, section=None):
        nonlocal step
        step += 1
        if section is not None:
            driver.execute_script(
                "arguments[0].scrollIntoView()", driver.find_element(By.ID, section))
        path = out / f"{step:02d}-{name}.png"
        driver.save_screenshot(str(path))
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

        # 6. Solve: the first 10 nominal targets of the random set, position
        # only, with the active version; the CSV answer is shown and offered.
        import csv as csvmod
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
        # set: the status, the trend and the history show it; compare the
        # versions on the same set; a roll back asks first (dismissed here).
        form = driver.find_element(By.ID, "run-check")
        Select(form.find_element(By.NAME, "set_id")).select_by_index(0)
        form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
        wait.until(replaced(form))
        wait.until(EC.presence_of_element_located((By.ID, "check-trend")))
        rows = driver.find_elements(By.CSS_SELECTOR, "#checks tbody tr")
        assert len(rows) == 1, f"expected one check, the page lists {len(rows)}"
        status = driver.find_element(By.CSS_SELECTOR, "#check-status .status-tag").text
        # The tag's first word is the status (a shifted one adds the shift's size).
        assert status.split()[0] in ("ok", "degraded", "recalibrate", "shifted"), status
        assert len(driver.find_elements(By.CSS_SELECTOR, "#check-trend circle.check-point")) == 1
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

        # 7. Tools and work objects: add a tool and a work object, add a
        # spare tool and delete it again.
        def save_item(form_id, name, number, xyz, rpy, frame=None):
            form = driver.find_element(By.ID, form_id)
            form.find_element(By.NAME, "name").send_keys(name)
            form.find_element(By.NAME, "number").send_keys(str(number))
            for k, v in zip(("x", "y", "z", "rx", "ry", "rz"), list(xyz) + list(rpy)):
                box = form.find_element(By.NAME, k)
                box.clear()
                box.send_keys(str(v))
            if frame:
                Select(form.find_element(By.NAME, "frame")).select_by_value(frame)
            form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
            wait.until(replaced(form))
            wait.until(EC.presence_of_element_located((By.ID, form_id)))

        def names(table_id):
            return [td.text for td in driver.find_elements(By.CSS_SELECTOR, f"#{table_id} td.name")]

        save_item("add-tool", "torch", 1, (125, 0, 216.5), (0, 30, 0))
        save_item("add-tool", "spare", 2, (0, 0, 100), (0, 0, 0))
        save_item("add-frame", "table", 1, (450, -100, 50), (0, 0, 20), "base")
        assert names("tools") == ["spare", "torch"], names("tools")
        assert names("work-objects") == ["table"], names("work-objects")
        shot("cell", "cell")
        button = driver.find_element(
            By.XPATH, "//div[@id='tools']//tr[td[@class='name' and text()='spare']]//button")
        button.click()
        wait.until(replaced(button))
        wait.until(EC.presence_of_element_located((By.ID, "add-tool")))
        assert names("tools") == ["torch"], names("tools")

        # 8. Filter the sample URScript program: the report lists its targets
        # and the filtered file is offered for download.
        program = ROOT / "examples/programs/urscript/seam.script"
        form = driver.find_element(By.ID, "filter")
        form.find_element(By.NAME, "files").send_keys(str(program))
        form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
        wait.until(EC.visibility_of_element_located((By.ID, "filter-result")))
        summary = driver.find_element(By.ID, "filter-summary").text
        import re
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
        shot("filtered", "filter-section")

        print(f"console_check: the whole flow passed; screenshots in {out}")
    finally:
        if driver is not None:
            driver.quit()
        server.terminate()
        server.wait(timeout=30)


if __name__ == "__main__":
    sys.exit(main())
