#!/usr/bin/env python3
"""Renders the calibration report of the real UR5 data (1000 grid poses for
identification, 20 random poses for validation; km and skcm) with
`robocal calibrate --html` and screenshots it in headless Chromium at 1400 and
1000 px wide, the whole page and each section, into target/report-screenshots/.

    python3 scripts/report_screenshots.py [--robocal target/debug/robocal]

Needs Debian's chromium and chromedriver and Selenium (e.g. the venv that
scripts/console_check.sh creates). Exits non-zero when a section is missing or
the page asks for anything outside itself.
"""
import argparse
import os
import pathlib
import subprocess
import sys

from selenium import webdriver
from selenium.webdriver.chrome.options import Options
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.by import By

ROOT = pathlib.Path(__file__).resolve().parent.parent
DATA = pathlib.Path(os.environ.get(
    "ROBOCAL_DATA_DIR", ROOT / "data/ur5-wam-laser-tracker"))
SECTIONS = ["warnings", "statistics", "histograms", "per-axis", "positions",
            "poses", "solvers", "parameters"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--robocal", default=str(ROOT / "target/debug/robocal"))
    ap.add_argument("--out", default=str(ROOT / "target/report-screenshots"))
    a = ap.parse_args()
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    html = out / "report-ur5.html"
    subprocess.run([
        a.robocal, "calibrate", "--model", str(ROOT / "models/ur5.json"),
        "--identify", str(DATA / "UR5/3D_UR5_uncalibrated_grid_cleaned.csv"),
        "--validate", str(DATA / "UR5/3D_UR5_uncalibrated_random_cleaned.csv"),
        "--method", "km,skcm", "--html", str(html),
    ], check=True, stdout=subprocess.DEVNULL)
    opts = Options()
    for arg in ["--headless=new", "--no-sandbox", "--disable-gpu",
                "--disable-dev-shm-usage", "--hide-scrollbars"]:
        opts.add_argument(arg)
    opts.binary_location = "/usr/bin/chromium"
    driver = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=opts)
    try:
        for width in (1400, 1000):
            driver.set_window_size(width, 1000)
            driver.get(html.as_uri())
            # Anything the page loads besides itself is an external asset.
            loaded = driver.execute_script(
                "return performance.getEntriesByType('resource').map(e => e.name)")
            if loaded:
                sys.exit(f"the report loaded external resources: {loaded}")
            height = driver.execute_script("return document.body.scrollHeight")
            driver.set_window_size(width, min(height + 200, 16000))
            driver.save_screenshot(str(out / f"report-{width}-full.png"))
            for s in SECTIONS:
                els = driver.find_elements(By.ID, s)
                if not els:
                    sys.exit(f"section #{s} missing")
                els[0].screenshot(str(out / f"report-{width}-{s}.png"))
            print(f"{width} px: page {height} px high, {len(SECTIONS)} sections")
    finally:
        driver.quit()
    print(f"screenshots in {out}")


if __name__ == "__main__":
    main()
