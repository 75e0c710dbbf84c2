"""The web console's external-axes section, a step of scripts/console_check.py
(which calls `check_external_axes` with its driver and helpers): a track and a
positioner fitted, refused and deleted through the robot page's forms, poses
predicted and targets solved on the stored positioner's face plate, each
answer compared with the API's. Python 3 standard library and Selenium.
"""
import pathlib
import re
import subprocess
import time

from selenium.webdriver.common.by import By
from selenium.webdriver.support import expected_conditions as EC
from selenium.webdriver.support.ui import Select


def api_raw(key, base, method, path, data=None, content_type=None):
    """A request over the API (not through the page): the status and the
    body's bytes, an error status included."""
    import urllib.error
    import urllib.request
    headers = {"Authorization": f"Bearer {key}"}
    if content_type:
        headers["Content-Type"] = content_type
    req = urllib.request.Request(base + path, data=data, method=method, headers=headers)
    try:
        with urllib.request.urlopen(req, timeout=60) as r:
            return r.status, r.read()
    except urllib.error.HTTPError as e:
        return e.code, e.read()


def printed_fit(printed):
    """The arguments of the `robocal ...` command a `simulate` printed after
    `fit it with: robocal `."""
    import shlex
    for line in printed.splitlines():
        if line.startswith("fit it with: robocal "):
            return shlex.split(line[len("fit it with: robocal "):])
    raise AssertionError(f"no fit command in\n{printed}")


def check_external_axes(driver, wait, shot, base, robocal, work, robot_url, h):
    """Step 7f; `h` is console_check's module (its API and page helpers)."""
    # 7f. External axes, on a second robot: a YS100 (created over the
    # API) calibrated by KM from 30 simulated poses (`robocal simulate`),
    # so it has the active version a track fit holds. The track's file
    # is `robocal track simulate --seed 5` on that version's model file
    # (the robot on the rail is the held version's geometry): fitted in
    # the page's form, the page shows the stored track as the API gives
    # it; the same file with its `e1` column renamed `e2` while the form
    # says e1 is refused (`missing_column`, shown, nothing replaced); the
    # file uploaded as station sets (the sets form's track column) and the
    # track refitted from their ids; the
    # track deleted (the question dismissed once, then accepted). Then a
    # positioner from `robocal positioner simulate --robot ys100`'s
    # files (the nominal JSON, one file per reflector, the reflectors'
    # positions from the command it prints), after the page refuses a
    # reflector line short of the files; with it stored (and no track),
    # the page's predict and solve forms on its face plate
    # (`predict_and_solve_on_positioner`), then it is deleted.
    axes = pathlib.Path(work) / "axes"
    axes.mkdir()
    rail = h.api_post(base, "/v1/robots", {"name": "YS100 on the rail", "preset": "ys100"})
    rail_id = rail["id"]
    ident = axes / "ys100-identification.csv"
    subprocess.run([robocal, "simulate", "--preset", "ys100", "--poses", "30", "--seed", "5",
                    "--out", str(ident)], check=True, capture_output=True)
    status, body = api_raw(h.KEY, base, "POST", f"/v1/robots/{rail_id}/measurement-sets?role=identification",
                           ident.read_bytes(), "text/csv")
    assert status == 201, (status, body)
    job = h.api_post(base, f"/v1/robots/{rail_id}/calibrations", {"methods": ["km"], "seed": 1})
    end = time.time() + 300
    while (j := h.api_get(base, f"/v1/robots/{rail_id}/calibrations/{job['id']}"))["status"] in ("queued", "running"):
        assert time.time() < end, f"the YS100's calibration still {j['status']} after 300 s"
        time.sleep(0.5)
    assert j["status"] == "succeeded", j
    held = h.api_get(base, f"/v1/robots/{rail_id}")["active_version"]
    status, model = api_raw(h.KEY, base, "GET", f"/v1/robots/{rail_id}/versions/{held}/model.json")
    assert status == 200, status
    (axes / "model.json").write_bytes(model)
    printed = subprocess.run([robocal, "track", "simulate", "--out-dir", str(axes / "track"),
                              "--robot", str(axes / "model.json"), "--seed", "5"],
                             check=True, capture_output=True, text=True).stdout
    stations = axes / "track" / "stations.csv"
    assert str(stations) in printed, printed
    rail_url = f"{base}/ui/robots/{rail_id}"
    driver.get(rail_url)
    wait.until(EC.presence_of_element_located((By.ID, "calibrate-track")))
    section = driver.find_element(By.ID, "axes-section").text
    assert "No track stored." in section and "No positioner stored." in section, section
    form = driver.find_element(By.ID, "calibrate-track")
    assert Select(form.find_element(By.NAME, "column")).first_selected_option.get_attribute("value") == "e1"
    assert form.find_element(By.NAME, "sigma_mm").get_attribute("value") == "0.01"
    assert form.find_element(By.NAME, "max_order").get_attribute("value") == "6"
    shot("axes-none", "axes-section")
    form.find_element(By.NAME, "file").send_keys(str(stations))
    form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
    # The page's message box: the fit's flash after the reload, or why not.
    msg = wait.until(lambda d: h.text_of(d, "#message"))
    assert re.fullmatch(r"Track fitted: RMS \d+\.\d{3} mm over 11 stations \(165 readings, max \d+\.\d{3} mm; "
                        f"model v{held} held\\)", msg), msg

    def track_cells():
        return {c: driver.find_element(By.CSS_SELECTOR, f"#track-stored td.{c}").text
                for c in ("column", "from", "version", "stations", "readings", "rms", "max", "sigma")}
    stored = h.api_get(base, f"/v1/robots/{rail_id}/track")
    shown = track_cells()
    assert shown == {"column": "e1", "from": "a posted file", "version": f"v{held}", "stations": "11",
                     "readings": str(stored["readings"]), "rms": f"{stored['rms_mm']:.3f}",
                     "max": f"{stored['max_mm']:.3f}", "sigma": "0.010"}, (shown, stored)
    assert stored["stations"] == 11 and stored["column"] == "e1" and stored["version"] == held, stored
    assert float(shown["rms"]) < 0.05, f"the track's RMS: {shown['rms']} mm"
    assert f"over 11 stations" in msg and f"RMS {shown['rms']} mm" in msg, msg
    created = driver.find_element(By.CSS_SELECTOR, "#track-stored time")
    assert created.get_attribute("datetime") == stored["created_at"], created.get_attribute("datetime")
    assert created.text != stored["created_at"], "the time is not shown in local time"
    print(f"console_check: track fitted, RMS {shown['rms']} mm, max {shown['max']} mm over 11 stations")
    shot("track-fitted", "axes-section")
    # Refused: the track's values in `e2` while the form reads e1.
    renamed = axes / "stations-e2.csv"
    lines = stations.read_text().splitlines(keepends=True)
    header = lines[0].rstrip("\r\n").split(",")
    assert header.count("e1") == 1 and "e2" not in header, header
    renamed.write_text(",".join("e2" if h == "e1" else h for h in header) + "\n" + "".join(lines[1:]))
    form = driver.find_element(By.ID, "calibrate-track")
    form.find_element(By.NAME, "file").send_keys(str(renamed))
    form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
    wait.until(EC.visibility_of_element_located((By.ID, "track-result")))
    refusal = driver.find_element(By.ID, "track-result").text
    msg = driver.find_element(By.ID, "message").text
    assert msg == refusal and "msg bad" in driver.find_element(By.ID, "message").get_attribute("class"), msg
    assert refusal.startswith("Track not fitted (missing_column): ") and "`e1`" in refusal \
        and "column e1" in refusal and refusal.endswith("Nothing was stored: the stored track is kept."), refusal
    assert form.is_enabled(), "a refused fit must not reload the page"
    assert h.api_get(base, f"/v1/robots/{rail_id}/track") == stored, "a refused fit replaced the track"
    assert track_cells() == shown
    print(f"console_check: refused: {refusal}")
    shot("track-refused", "calibrate-track")
    # The same file as station sets (the upload form's track column), each
    # set listed with its track value; the track refitted from their ids (the
    # track form's station sets) is the one fitted from the file.
    upload = driver.find_element(By.ID, "upload")
    upload.find_element(By.NAME, "file").send_keys(str(stations))
    Select(upload.find_element(By.NAME, "track_column")).select_by_value("e1")
    upload.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
    wait.until(h.replaced(upload))
    wait.until(EC.presence_of_element_located((By.ID, "calibrate-track")))
    listed = h.api_get(base, f"/v1/robots/{rail_id}/measurement-sets")["measurement_sets"]
    station_sets = [s for s in listed if "station" in s]
    assert len(station_sets) == 11, listed

    def shown_value(v):  # as the page prints a number: 400, not 400.0
        return str(int(v)) if float(v).is_integer() else repr(v)
    cells = [c.text for c in driver.find_elements(By.CSS_SELECTOR, "#sets td.station")]
    assert [c for c in cells if c != "—"] == [f"e1 = {shown_value(s['station']['value_mm'])} mm"
                                              for s in station_sets], cells
    ids = [s["id"] for s in station_sets]
    assert ids == list(range(ids[0], ids[0] + 11)), ids
    form = driver.find_element(By.ID, "calibrate-track")
    form.find_element(By.NAME, "set_ids").send_keys(f"{ids[0]}-{ids[-1]}")
    form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
    wait.until(h.replaced(form))
    msg = wait.until(lambda d: (t := h.text_of(d, "#message")) and t.startswith("Track fitted") and t)
    refit = h.api_get(base, f"/v1/robots/{rail_id}/track")
    assert refit["set_ids"] == ids and refit["track"] == stored["track"], (refit, stored)
    from_cell = driver.find_element(By.CSS_SELECTOR, "#track-stored td.from").text
    assert from_cell == f"station sets {ids[0]}–{ids[-1]}", from_cell
    print(f"console_check: the stations uploaded as 11 station sets, the track refitted from them: {msg}")
    shot("track-from-sets", "axes-section")
    # Delete the track: asked first; dismissed, it stays; accepted, it is gone.
    button = driver.find_element(By.ID, "delete-track")
    button.click()
    alert = wait.until(EC.alert_is_present())
    assert alert.text.startswith(f"Delete the track of robot {rail_id} (YS100 on the rail)?"), alert.text
    alert.dismiss()
    assert driver.find_elements(By.ID, "track-stored") and button.is_enabled(), "a dismissed delete must not be sent"
    assert api_raw(h.KEY, base, "GET", f"/v1/robots/{rail_id}/track")[0] == 200
    button.click()
    wait.until(EC.alert_is_present()).accept()
    wait.until(h.replaced(button))
    wait.until(EC.presence_of_element_located((By.ID, "calibrate-track")))
    assert not driver.find_elements(By.ID, "track-stored")
    assert "No track stored." in driver.find_element(By.ID, "axes-section").text
    assert api_raw(h.KEY, base, "GET", f"/v1/robots/{rail_id}/track")[0] == 404
    shot("track-deleted", "axes-section")
    # The positioner, from the files `positioner simulate` writes and the
    # reflectors' positions in the command it prints.
    printed = subprocess.run([robocal, "positioner", "simulate", "--out-dir", str(axes / "positioner"),
                              "--robot", "ys100"], check=True, capture_output=True, text=True).stdout
    fit = printed_fit(printed)
    assert fit[:2] == ["positioner", "calibrate"], fit
    sets = fit[2:fit.index("--nominal")]
    nominal = fit[fit.index("--nominal") + 1]
    reflectors = [fit[i + 1] for i, a in enumerate(fit) if a == "--reflector"]
    assert len(sets) == len(reflectors) >= 2 and all(pathlib.Path(f).exists() for f in sets + [nominal]), fit
    form = driver.find_element(By.ID, "calibrate-positioner")
    assert [Select(form.find_element(By.NAME, n)).first_selected_option.get_attribute("value")
            for n in ("tilt_column", "rotate_column")] == ["e1", "e2"]
    form.find_element(By.NAME, "nominal_file").send_keys(nominal)
    form.find_element(By.NAME, "sets").send_keys("\n".join(sets))
    order = driver.find_element(By.ID, "positioner-files").text
    assert order.endswith(", ".join(f"{i + 1}. {pathlib.Path(f).name}" for i, f in enumerate(sets))), order
    # One line short: the page says so and sends nothing.
    form.find_element(By.NAME, "reflectors").send_keys(reflectors[0].replace(",", ", "))
    form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
    wait.until(lambda d: "reflector position lines" in (h.text_of(d, "#message") or ""))
    msg = driver.find_element(By.ID, "message").text
    assert msg == f"1 reflector position lines for {len(sets)} measurement files: " \
        "give one x, y, z line per file, in the files' order", msg
    assert api_raw(h.KEY, base, "GET", f"/v1/robots/{rail_id}/positioner")[0] == 404
    box = form.find_element(By.NAME, "reflectors")
    box.clear()
    box.send_keys("\n".join(r.replace(",", ", ") for r in reflectors))
    form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
    refused = msg
    msg = wait.until(lambda d: (t := h.text_of(d, "#message")) and t != refused and t)
    assert msg.startswith("Positioner fitted: "), msg
    wait.until(EC.presence_of_element_located((By.ID, "positioner-stored")))
    stored = h.api_get(base, f"/v1/robots/{rail_id}/positioner")
    shown = {c: driver.find_element(By.CSS_SELECTOR, f"#positioner-stored td.{c}").text
             for c in ("tilt", "rotate", "from", "reflectors", "readings", "rms", "max", "sigma")}
    assert shown == {"tilt": "e1", "rotate": "e2", "from": "tracker", "reflectors": str(len(sets)),
                     "readings": str(stored["readings"]), "rms": f"{stored['rms_mm']:.3f}",
                     "max": f"{stored['max_mm']:.3f}", "sigma": "0.010"}, (shown, stored)
    assert stored["reflectors"] == len(sets), stored
    assert msg == f"Positioner fitted: RMS {shown['rms']} mm over {shown['readings']} readings of " \
        f"{len(sets)} reflectors (max {shown['max']} mm)", msg
    print(f"console_check: positioner fitted, RMS {shown['rms']} mm over {shown['readings']} readings")
    shot("positioner-fitted", "axes-section")
    assert api_raw(h.KEY, base, "GET", f"/v1/robots/{rail_id}/track")[0] == 404, "a track is still stored"
    predict_and_solve_on_positioner(driver, wait, shot, base, rail_id, h)
    button = driver.find_element(By.ID, "delete-positioner")
    button.click()
    alert = wait.until(EC.alert_is_present())
    assert alert.text.startswith(f"Delete the positioner of robot {rail_id} (YS100 on the rail)?"), alert.text
    alert.accept()
    wait.until(h.replaced(button))
    wait.until(EC.presence_of_element_located((By.ID, "calibrate-positioner")))
    assert "No positioner stored." in driver.find_element(By.ID, "axes-section").text
    assert api_raw(h.KEY, base, "GET", f"/v1/robots/{rail_id}/positioner")[0] == 404
    turntable_through_the_form(driver, wait, shot, base, robocal, axes, rail_id, h)
    positioner_from_touches(driver, wait, shot, base, robocal, axes, rail_id, held, h)
    driver.get(robot_url)
    wait.until(EC.presence_of_element_located((By.ID, "add-tool")))


def simulated_fit(robocal, what, out_dir, *extra):
    """`robocal WHAT simulate --out-dir OUT_DIR EXTRA...`: the measurement
    files, the nominal JSON and the reflectors' positions of the command it
    prints."""
    printed = subprocess.run([robocal, what, "simulate", "--out-dir", str(out_dir), *extra],
                             check=True, capture_output=True, text=True).stdout
    fit = printed_fit(printed)
    assert fit[:2] == [what, "calibrate"], fit
    sets = fit[2:fit.index("--nominal")]
    nominal = fit[fit.index("--nominal") + 1]
    reflectors = [fit[i + 1] for i, a in enumerate(fit) if a == "--reflector"]
    assert len(sets) == len(reflectors) >= 2 and all(pathlib.Path(f).exists() for f in sets + [nominal]), fit
    return sets, nominal, reflectors


def fill_reflector_form(driver, form, what, nominal, sets, reflectors):
    """The nominal JSON file, the measurement files (listed in the order
    they are sent) and one reflector line per file, put into the form of
    `what` (`positioner`, `turntable`)."""
    form.find_element(By.NAME, "nominal_file").send_keys(nominal)
    form.find_element(By.NAME, "sets").send_keys("\n".join(sets))
    order = driver.find_element(By.ID, f"{what}-files").text
    assert order.endswith(", ".join(f"{i + 1}. {pathlib.Path(f).name}" for i, f in enumerate(sets))), order
    box = form.find_element(By.NAME, "reflectors")
    box.clear()
    box.send_keys("\n".join(r.replace(",", ", ") for r in reflectors))


def new_message(driver, wait, h, before):
    """The page's message once it differs from `before` (a reload's flash
    or a refusal)."""
    return wait.until(lambda d: (t := h.text_of(d, "#message")) and t != before and t)


def turntable_cells(driver):
    """The stored turntable's row as the page shows it."""
    return {c: driver.find_element(By.CSS_SELECTOR, f"#turntable-stored td.{c}").text
            for c in ("column", "reflectors", "readings", "direction", "point", "zero", "scale",
                      "rms", "max", "sigma")}


def turntable_as_shown(stored):
    """`GET …/turntable`'s answer written as the page writes it: mm to
    0.001, degrees to 0.0001, the direction and the scale to 1e-6."""
    axis = stored["turntable"]["axis"]
    return {"column": stored["column"], "reflectors": str(stored["reflectors"]),
            "readings": str(stored["readings"]),
            "direction": ", ".join(shown_number(x, 6) for x in axis["direction"]),
            "point": ", ".join(shown_number(x, 3) for x in axis["point_mm"]),
            "zero": shown_number(axis["zero_offset_deg"], 4), "scale": shown_number(axis["scale"], 6),
            "rms": shown_number(stored["rms_mm"], 3), "max": shown_number(stored["max_mm"], 3),
            "sigma": shown_number(stored["sigma_mm"], 3)}


def turntable_through_the_form(driver, wait, shot, base, robocal, axes, rail_id, h):
    """The one-axis turntable of `robocal turntable simulate` (its axis
    tilted 0.05°, a zero offset of -0.4°, a scale off by -1.5e-4): fitted in
    the page's form, shown as `GET …/turntable` gives it (every figure,
    the axis's line, zero offset and scale among them); the same files with
    the form reading `e2` refused with the reason shown and the stored
    turntable kept; deleted after a confirmation."""
    sets, nominal, reflectors = simulated_fit(robocal, "turntable", axes / "turntable")
    assert "No turntable stored." in driver.find_element(By.ID, "axes-section").text
    assert api_raw(h.KEY, base, "GET", f"/v1/robots/{rail_id}/turntable")[0] == 404
    form = driver.find_element(By.ID, "calibrate-turntable")
    assert Select(form.find_element(By.NAME, "column")).first_selected_option.get_attribute("value") == "e1"
    assert form.find_element(By.NAME, "sigma_mm").get_attribute("value") == "0.01"
    fill_reflector_form(driver, form, "turntable", nominal, sets, reflectors)
    before = h.text_of(driver, "#message")
    form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
    msg = new_message(driver, wait, h, before)
    assert msg.startswith("Turntable fitted: "), msg
    wait.until(EC.presence_of_element_located((By.ID, "turntable-stored")))
    stored = h.api_get(base, f"/v1/robots/{rail_id}/turntable")
    shown = turntable_cells(driver)
    assert shown == turntable_as_shown(stored), (shown, stored)
    assert shown["column"] == "e1" and stored["reflectors"] == len(sets), stored
    assert msg == f"Turntable fitted: RMS {shown['rms']} mm over {shown['readings']} readings of " \
        f"{len(sets)} reflectors (max {shown['max']} mm)", msg
    axis = stored["turntable"]["axis"]
    assert abs(axis["zero_offset_deg"] + 0.4) < 0.1 and abs(axis["scale"] - (1 - 1.5e-4)) < 5e-5, axis
    created = driver.find_element(By.CSS_SELECTOR, "#turntable-stored time")
    assert created.get_attribute("datetime") == stored["created_at"], created.get_attribute("datetime")
    print(f"console_check: turntable fitted, RMS {shown['rms']} mm over {shown['readings']} readings; "
          f"zero offset {shown['zero']}°, scale {shown['scale']}, axis through {shown['point']} mm")
    shot("turntable-fitted", "turntable-stored-box")
    predict_and_solve_on_turntable(driver, wait, shot, base, rail_id, h)
    # The filter, the controller data and the plans over the axes
    # (scripts/console_check_axes_programs.py).
    from console_check_axes_programs import export_on_turntable, filter_on_turntable, plan_sweeps
    import sys
    p_sets, p_nominal, p_reflectors = simulated_fit(robocal, "positioner", axes / "plan-positioner")
    filter_on_turntable(driver, wait, shot, base, rail_id, nominal, p_nominal, sys.modules[__name__], h)
    export_on_turntable(driver, wait, shot, base, rail_id, sys.modules[__name__], h)
    plan_sweeps(driver, wait, shot, base, rail_id, "turntable", nominal, reflectors, sys.modules[__name__], h)
    plan_sweeps(driver, wait, shot, base, rail_id, "positioner", p_nominal, p_reflectors, sys.modules[__name__], h)
    # Refused: the form reads the axis's value from e2, the files have e1.
    form = driver.find_element(By.ID, "calibrate-turntable")
    Select(form.find_element(By.NAME, "column")).select_by_value("e2")
    fill_reflector_form(driver, form, "turntable", nominal, sets, reflectors)
    form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
    wait.until(EC.visibility_of_element_located((By.ID, "turntable-result")))
    refusal = driver.find_element(By.ID, "turntable-result").text
    msg = driver.find_element(By.ID, "message").text
    assert msg == refusal and "msg bad" in driver.find_element(By.ID, "message").get_attribute("class"), msg
    assert refusal.startswith("Turntable not fitted") and "`e2`" in refusal and "column e2" in refusal \
        and refusal.endswith("Nothing was stored: the stored turntable is kept."), refusal
    assert h.api_get(base, f"/v1/robots/{rail_id}/turntable") == stored, "a refused fit replaced the turntable"
    assert turntable_cells(driver) == shown
    print(f"console_check: refused: {refusal}")
    shot("turntable-refused", "calibrate-turntable")
    button = driver.find_element(By.ID, "delete-turntable")
    button.click()
    alert = wait.until(EC.alert_is_present())
    assert alert.text.startswith(f"Delete the turntable of robot {rail_id} (YS100 on the rail)?"), alert.text
    alert.accept()
    wait.until(h.replaced(button))
    wait.until(EC.presence_of_element_located((By.ID, "calibrate-turntable")))
    assert "No turntable stored." in driver.find_element(By.ID, "axes-section").text
    assert api_raw(h.KEY, base, "GET", f"/v1/robots/{rail_id}/turntable")[0] == 404
    shot("turntable-deleted", "turntable-stored-box")


def touches_file(base, rail_id, version, tracker_file, h):
    """A touches file (`id,q1…q6,e1,e2`) of the points a tracker's file
    read: each point solved over the API (position only) for version
    `version` carrying the stored tool `pointer`, at the file's axis values;
    a point the robot does not reach is left out."""
    import csv
    rows = list(csv.DictReader(open(tracker_file)))
    targets = [{"id": f"t{i + 1}", "x": float(r["x"]), "y": float(r["y"]), "z": float(r["z"])}
               for i, r in enumerate(rows)]
    solved = h.api_post(base, f"/v1/robots/{rail_id}/solve",
                        {"targets": targets, "position_only": True, "tool": "pointer", "version": version})
    lines = ["id,q1,q2,q3,q4,q5,q6,e1,e2"]
    for r, s in zip(rows, solved["results"], strict=True):
        if s["status"] == "ok":
            lines.append(",".join([s["id"]] + [repr(q) for q in s["joints_deg"]] + [r["e1"], r["e2"]]))
    assert len(lines) > 9, f"the robot reaches {len(lines) - 1} of {len(rows)} points of {tracker_file}"
    return "\n".join(lines) + "\n", len(lines) - 1, len(rows)


def positioner_from_touches(driver, wait, shot, base, robocal, axes, rail_id, held, h):
    """A positioner fitted in the page's form from touches: the tool
    `pointer` (200 mm along the flange's z) stored; the points of
    `robocal positioner simulate --robot <the version's model.json>`'s files
    solved over the API for the held version carrying it, written as touches
    files; the form with "touches" chosen clears the tracker's σ and refuses
    to send without one; with σ the fit is stored, shown as `GET
    …/positioner` gives it (readings from touches with that tool and
    version), and equal to the API's answer for the same body."""
    import json
    status, body = api_raw(h.KEY, base, "PUT", f"/v1/robots/{rail_id}/tools/pointer",
                           json.dumps({"number": 1, "xyz_mm": [0, 0, 200], "rpy_deg": [0, 0, 0]}).encode(),
                           "application/json")
    assert status in (200, 201), (status, body)
    sets, nominal, reflectors = simulated_fit(robocal, "positioner", axes / "touched",
                                              "--robot", str(axes / "model.json"), "--seed", "3")
    touched = []
    for k, f in enumerate(sets):
        text, reached, of = touches_file(base, rail_id, held, f, h)
        path = axes / "touched" / f"touches{k}.csv"
        path.write_text(text)
        touched.append(str(path))
        print(f"console_check: touches of feature {k}: {reached} of {of} points reached")
    driver.get(f"{base}/ui/robots/{rail_id}")
    wait.until(EC.presence_of_element_located((By.ID, "calibrate-positioner")))
    form = driver.find_element(By.ID, "calibrate-positioner")
    assert not driver.find_element(By.ID, "positioner-touches").is_displayed()
    form.find_element(By.CSS_SELECTOR, "input[name=readings_from][value=touches]").click()
    assert driver.find_element(By.ID, "positioner-touches").is_displayed()
    assert form.find_element(By.NAME, "sigma_mm").get_attribute("value") == "", "the tracker's σ kept for touches"
    version = Select(form.find_element(By.NAME, "touched_version"))
    assert version.first_selected_option.get_attribute("value") == str(held)
    Select(form.find_element(By.NAME, "touched_tool")).select_by_value("pointer")
    fill_reflector_form(driver, form, "positioner", nominal, touched, reflectors)
    # No σ: the page says so and sends nothing.
    form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
    wait.until(lambda d: "touches need σ" in (h.text_of(d, "#message") or ""))
    refused = driver.find_element(By.ID, "message").text
    assert refused.startswith("touches need σ [mm]: the robot's accuracy at the tool's tip"), refused
    assert api_raw(h.KEY, base, "GET", f"/v1/robots/{rail_id}/positioner")[0] == 404
    shot("positioner-touches-refused", "calibrate-positioner")
    form.find_element(By.NAME, "sigma_mm").send_keys("0.01")
    form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
    msg = new_message(driver, wait, h, refused)
    assert msg.startswith("Positioner fitted: "), msg
    wait.until(EC.presence_of_element_located((By.ID, "positioner-stored")))
    stored = h.api_get(base, f"/v1/robots/{rail_id}/positioner")
    shown = {c: driver.find_element(By.CSS_SELECTOR, f"#positioner-stored td.{c}").text
             for c in ("tilt", "rotate", "from", "reflectors", "readings", "rms", "max", "sigma")}
    assert shown == {"tilt": "e1", "rotate": "e2", "from": f"touches with tool pointer of version {held}",
                     "reflectors": str(len(sets)), "readings": str(stored["readings"]),
                     "rms": f"{stored['rms_mm']:.3f}", "max": f"{stored['max_mm']:.3f}", "sigma": "0.010"}, \
        (shown, stored)
    assert stored["readings_from"] == {"kind": "touches", "version": held, "tool": "pointer"}, stored
    assert msg == f"Positioner fitted: RMS {shown['rms']} mm over {shown['readings']} readings of " \
        f"{len(sets)} reflectors (max {shown['max']} mm); touches with tool pointer of version {held}", msg
    # The API's answer for the same body: the same positioner and figures.
    same = {"sets": [pathlib.Path(f).read_text() for f in touched],
            "reflectors": [[float(x) for x in r.split(",")] for r in reflectors],
            "nominal": json.loads(pathlib.Path(nominal).read_text()), "tilt_column": "e1", "rotate_column": "e2",
            "sigma_mm": 0.01, "touched_with": {"version": held, "tool": "pointer"}}
    answer = h.api_post(base, f"/v1/robots/{rail_id}/positioner/calibrate", same)
    for k in ("positioner", "readings", "reflectors", "rms_mm", "max_mm", "sigma_mm", "readings_from",
              "tilt_column", "rotate_column"):
        assert answer[k] == stored[k], (k, answer[k], stored[k])
    print(f"console_check: positioner fitted from touches (tool pointer of v{held}), RMS {shown['rms']} mm "
          f"over {shown['readings']} touches, as the API fits the same body")
    shot("positioner-touched", "positioner-stored-box")
    status, _ = api_raw(h.KEY, base, "DELETE", f"/v1/robots/{rail_id}/positioner")
    assert status == 204, status


def shown_number(v, decimals):
    """A number as console.js's `fixed` writes it: `decimals` places, never "-0"."""
    s = f"{v:.{decimals}f}"
    return s[1:] if re.fullmatch(r"-[0.]*", s) else s


def predict_and_solve_on_positioner(driver, wait, shot, base, rail_id, h):
    """The rail robot with its positioner stored and no track: the page's
    predict form given e1 = 20, e2 = 35 (the positioner's tilt and rotate)
    states the poses on the face plate as the API's predict does for the
    same body; `e2` without `e1` is refused with the API's reason; the
    predicted points, as a targets CSV with `e1`, `e2` columns, are solved
    in the page's solve form as the API solves them, and the solved joints
    put the measured point back on those points."""
    import json
    # Within the YS100's joint limits (J2 20..160, J3 -110..90 deg), so the
    # points can be solved back.
    readings = [("p1", [10, 90, -20, 0, 45, 0]), ("p2", [0, 100, 0, 0, 60, 0])]
    form = driver.find_element(By.ID, "predict")
    assert Select(form.find_element(By.NAME, "frame")).first_selected_option.get_attribute("value") == ""
    assert [form.find_element(By.NAME, n).get_attribute("value") for n in ("e1", "e2", "e3")] == ["", "", ""]
    form.find_element(By.NAME, "readings").send_keys(
        "\n".join(f"{i}, " + ", ".join(str(q) for q in js) for i, js in readings))
    form.find_element(By.NAME, "e1").send_keys("20")
    form.find_element(By.NAME, "e2").send_keys("35")
    form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
    wait.until(EC.visibility_of_element_located((By.ID, "predict-result")))
    summary = driver.find_element(By.ID, "predict-summary").text
    rows = [[td.text for td in r.find_elements(By.TAG_NAME, "td")]
            for r in driver.find_elements(By.CSS_SELECTOR, "#predict-table tbody tr")]
    # The same body over the API (the page sends the model select's `active`).
    body = {"readings": [{"id": i, "joints_deg": js} for i, js in readings], "version": "active",
            "e1": 20, "e2": 35}
    want = h.api_post(base, f"/v1/robots/{rail_id}/predict", body)
    assert want["frame"] == "face_plate", want["frame"]
    assert summary.startswith("2 poses of the measured point in the face_plate frame (e1 = 20, e2 = 35) at "), summary
    assert [(r["status"], r["outside_limits"]) for r in want["results"]] == [("ok", [])] * 2, want["results"]
    for row, p in zip(rows, want["results"], strict=True):
        expected = [p["id"], p["status"]] + [shown_number(p[k], 3) for k in "xyz"] \
            + [shown_number(p[k], 4) for k in ("rx", "ry", "rz")]
        assert row[:8] == expected, (row, expected)
    # The face plate is not the cell frame: the same readings without the axes.
    cell = h.api_post(base, f"/v1/robots/{rail_id}/predict", {"readings": body["readings"]})["results"]
    moved = min(sum((c[k] - p[k]) ** 2 for k in "xyz") ** 0.5 for c, p in zip(cell, want["results"]))
    assert moved > 1.0, f"the face plate's poses are only {moved:.3f} mm from the cell frame's"
    print(f"console_check: predicted on the positioner at e1 = 20, e2 = 35: {summary}; "
          f"p1 at {', '.join(rows[0][2:5])} mm, as the API gives it")
    shot("predicted-on-positioner", "predict-section")
    # Refused: e2 without e1, the API's 422 and its reason shown; the table kept.
    form.find_element(By.NAME, "e1").clear()
    assert form.find_element(By.NAME, "e2").get_attribute("value") == "35"
    status, answer = api_raw(h.KEY, base, "POST", f"/v1/robots/{rail_id}/predict",
                             json.dumps({"readings": body["readings"], "version": "active", "e2": 35}).encode(),
                             "application/json")
    assert status == 422, (status, answer)
    refusal = f"422: {json.loads(answer)['detail']}"
    assert "`e2` without `e1`" in refusal, refusal
    form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
    msg = wait.until(lambda d: (t := h.text_of(d, "#message")) and t.startswith("422") and t)
    assert msg == refusal, (msg, refusal)
    assert "msg bad" in driver.find_element(By.ID, "message").get_attribute("class")
    assert driver.find_element(By.ID, "predict-summary").text == summary
    print(f"console_check: refused: {msg}")
    shot("predict-refused", "predict-section")
    # Solve: the predicted points as targets on the face plate, each row at
    # its e1, e2, position only; the page's CSV is the API's.
    csv = "id,x,y,z,e1,e2\n" + "".join(f"{p['id']},{p['x']!r},{p['y']!r},{p['z']!r},20,35\n"
                                       for p in want["results"])
    form = driver.find_element(By.ID, "solve")
    assert Select(form.find_element(By.NAME, "frame")).first_selected_option.get_attribute("value") == ""
    form.find_element(By.NAME, "csv").send_keys(csv)
    form.find_element(By.NAME, "position_only").click()
    form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
    # The answer, or the page's message saying why not (the refusal above until then).
    wait.until(lambda d: d.find_element(By.ID, "solve-result").is_displayed() or h.text_of(d, "#message") != msg)
    assert driver.find_element(By.ID, "solve-result").is_displayed(), driver.find_element(By.ID, "message").text
    summary = driver.find_element(By.ID, "solve-summary").text
    shown = driver.execute_script("return document.getElementById('solve-csv').textContent")
    assert summary.startswith("2 of 2 targets solved"), (summary, shown)
    status, answer = api_raw(h.KEY, base, "POST", f"/v1/robots/{rail_id}/solve?version=active&position_only=true",
                             csv.encode(), "text/csv")
    assert status == 200, (status, answer)
    assert shown == answer.decode(), (shown, answer.decode())
    table = list(csv_rows(shown))
    assert [r["status"] for r in table] == ["ok", "ok"], table
    joints = [[float(r[f"j{j}_deg"]) for j in range(1, 7)] for r in table]
    back = h.api_post(base, f"/v1/robots/{rail_id}/predict", {
        "readings": [{"id": r["id"], "joints_deg": js} for r, js in zip(table, joints)], "e1": 20, "e2": 35})
    worst = max(sum((b[k] - p[k]) ** 2 for k in "xyz") ** 0.5 for b, p in zip(back["results"], want["results"]))
    assert worst < 0.01, f"the solved joints put the point {worst} mm from its target on the face plate"
    print(f"console_check: solved on the positioner: {summary}; the solved joints put the point within "
          f"{worst:.1e} mm of its target on the face plate")
    shot("solved-on-positioner", "solve-section")


def predict_and_solve_on_turntable(driver, wait, shot, base, rail_id, h):
    """The rail robot with its turntable stored and no track: the page's
    predict form ticked "on the turntable" with e1 = 40 states the poses on
    its face plate as the API's predict with `turntable` does; the points,
    as a targets CSV with an `e1` column, are solved in the solve form
    ticked likewise as the API solves them (`?turntable=true`)."""
    readings = [("t1", [10, 90, -20, 0, 45, 0]), ("t2", [0, 100, 0, 0, 60, 0])]
    form = driver.find_element(By.ID, "predict")
    form.find_element(By.NAME, "readings").clear()
    form.find_element(By.NAME, "readings").send_keys(
        "\n".join(f"{i}, " + ", ".join(str(q) for q in js) for i, js in readings))
    for name in ("e1", "e2", "e3"):
        form.find_element(By.NAME, name).clear()
    form.find_element(By.NAME, "e1").send_keys("40")
    form.find_element(By.NAME, "turntable").click()
    form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
    wait.until(lambda d: "on the turntable" in (h.text_of(d, "#predict-summary") or "")
               or (h.text_of(d, "#message") or "").startswith("4"))
    summary = driver.find_element(By.ID, "predict-summary").text
    rows = [[td.text for td in r.find_elements(By.TAG_NAME, "td")]
            for r in driver.find_elements(By.CSS_SELECTOR, "#predict-table tbody tr")]
    body = {"readings": [{"id": i, "joints_deg": js} for i, js in readings], "version": "active",
            "turntable": True, "e1": 40}
    want = h.api_post(base, f"/v1/robots/{rail_id}/predict", body)
    assert want["frame"] == "face_plate", want["frame"]
    assert summary.startswith("2 poses of the measured point in the face_plate frame (e1 = 40, on the turntable) at "), \
        (summary, h.text_of(driver, "#message"))
    for row, p in zip(rows, want["results"], strict=True):
        expected = [p["id"], p["status"]] + [shown_number(p[k], 3) for k in "xyz"] \
            + [shown_number(p[k], 4) for k in ("rx", "ry", "rz")]
        assert row[:8] == expected, (row, expected)
    print(f"console_check: predicted on the turntable at e1 = 40: {summary}, as the API gives it")
    shot("predicted-on-turntable", "predict-section")
    form.find_element(By.NAME, "turntable").click()
    form.find_element(By.NAME, "e1").clear()
    csv = "id,x,y,z,e1\n" + "".join(f"{p['id']},{p['x']!r},{p['y']!r},{p['z']!r},40\n" for p in want["results"])
    form = driver.find_element(By.ID, "solve")
    form.find_element(By.NAME, "csv").clear()
    form.find_element(By.NAME, "csv").send_keys(csv)
    if not form.find_element(By.NAME, "position_only").is_selected():
        form.find_element(By.NAME, "position_only").click()
    form.find_element(By.NAME, "turntable").click()
    before = h.text_of(driver, "#solve-summary")
    form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
    wait.until(lambda d: (h.text_of(d, "#solve-summary") or before) != before
               or (h.text_of(d, "#message") or "").startswith("4"))
    summary = driver.find_element(By.ID, "solve-summary").text
    shown = driver.execute_script("return document.getElementById('solve-csv').textContent")
    assert summary.startswith("2 of 2 targets solved"), (summary, h.text_of(driver, "#message"))
    status, answer = api_raw(h.KEY, base, "POST",
                             f"/v1/robots/{rail_id}/solve?version=active&position_only=true&turntable=true",
                             csv.encode(), "text/csv")
    assert status == 200, (status, answer)
    assert shown == answer.decode(), (shown, answer.decode())
    print(f"console_check: solved on the turntable: {summary}, the page's CSV the API's")
    shot("solved-on-turntable", "solve-section")
    form.find_element(By.NAME, "turntable").click()


def csv_rows(text):
    """The rows of CSV `text` as dicts."""
    import csv
    import io
    return csv.DictReader(io.StringIO(text))
