"""The web console's filter, controller data and measurement plan over the
external axes, a step of scripts/console_check_axes.py: a KRL program whose
targets carry `E1` filtered through the robot page's form with the
controller's turntable, a refusal shown with the API's reason, the
controller data exported with the stored turntable's axes (and a track it
has not stored refused), a turntable's and a positioner's sweeps planned
through the plan form; each answer compared with the API's for the same
body. Python 3 standard library and Selenium.
"""
import json
import pathlib

from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import Select


def krl_program(name, targets):
    """A KRL `.src`/`.dat` pair: the tool `tip`'s `$TOOL`, base 3 (the
    part on the face plate), one `PTP` per target `(x, y, z, a, b, c, e1)`
    (no S and T: the solution nearest the previous target's)."""
    src = f"DEF {name}()\n$TOOL = {{X 0,Y 0,Z 150,A 0,B 0,C 0}}\nBAS(#BASE, 3)\n"
    dat = f"DEFDAT {name}\n"
    for i, (x, y, z, a, b, c, e1) in enumerate(targets):
        src += f"PTP XP{i}\n"
        dat += (f"DECL E6POS XP{i}={{X {x:.4f},Y {y:.4f},Z {z:.4f},A {a:.4f},B {b:.4f},C {c:.4f},"
                f"E1 {e1},E2 0,E3 0,E4 0,E5 0,E6 0}}\n")
    return src + "END\n", dat + "ENDDAT\n"


def page_report(driver):
    """The filter's summary, axes line, table rows and the report download."""
    rows = [[td.text for td in r.find_elements(By.TAG_NAME, "td")]
            for r in driver.find_elements(By.CSS_SELECTOR, "#filter-report tbody tr")]
    report = driver.execute_async_script(
        "const done = arguments[0];"
        "fetch(document.getElementById('filter-report-download').href).then(r => r.json()).then(done);")
    files = driver.execute_async_script(
        "const done = arguments[0];"
        "Promise.all([...document.querySelectorAll('#filter-downloads a.filtered-file')]"
        ".map(a => fetch(a.href).then(r => r.text()).then(t => [a.textContent, t]))).then(done);")
    return driver.find_element(By.ID, "filter-axes").text, rows, report, dict(files)


def filter_on_turntable(driver, wait, shot, base, rail_id, nominal, positioner, axes_mod, h):
    """The rail robot with its turntable stored: targets on a part on the
    face plate, predicted at E1 = 30 and 60 (the turntable's values), as a
    KRL program filtered in the page's form with the controller's turntable
    (the nominal JSON) and "correct the axes' values"; the page's report and
    files are the API's for the same body. A positioner's JSON (the robot
    has none stored) is refused with the API's reason."""
    api_raw = axes_mod.api_raw
    for path, item in ((f"/v1/robots/{rail_id}/tools/tip", {"number": 1, "xyz_mm": [0, 0, 150], "rpy_deg": [0, 0, 0]}),
                       (f"/v1/robots/{rail_id}/frames/part", {"number": 3, "frame": "face_plate",
                                                                "xyz_mm": [0, 0, 0], "rpy_deg": [0, 0, 0]})):
        status, answer = api_raw(h.KEY, base, "PUT", path, json.dumps(item).encode(), "application/json")
        assert status in (200, 201), (status, answer)
    targets = []
    for e1, joints in ((30, [10, 90, -20, 0, 45, 0]), (60, [0, 100, 0, 0, 60, 0])):
        p = h.api_post(base, f"/v1/robots/{rail_id}/predict", {
            "readings": [{"joints_deg": joints}], "tool": "tip", "turntable": True, "e1": e1})["results"][0]
        targets.append((p["x"], p["y"], p["z"], p["rz"], p["ry"], p["rx"], e1))
    src, dat = krl_program("turn", targets)
    work = pathlib.Path(nominal).parent / "filter"
    work.mkdir(exist_ok=True)
    (work / "turn.src").write_text(src)
    (work / "turn.dat").write_text(dat)
    driver.get(driver.current_url)
    form = wait.until(lambda d: d.find_element(By.ID, "filter"))
    form.find_element(By.NAME, "files").send_keys(f"{work / 'turn.src'}\n{work / 'turn.dat'}")
    Select(form.find_element(By.NAME, "controller_plate_kind")).select_by_value("turntable")
    form.find_element(By.NAME, "controller_plate_file").send_keys(nominal)
    form.find_element(By.NAME, "correct_axes").click()
    before = h.text_of(driver, "#message")
    form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
    msg = wait.until(lambda d: (t := h.text_of(d, "#message")) and t != before and t)
    body = {"files": [{"name": "turn.src", "content": src}, {"name": "turn.dat", "content": dat}],
            "language": "krl", "version": "active", "controller_turntable": json.loads(pathlib.Path(nominal).read_text()),
            "correct_axes": True}
    want = h.api_post(base, f"/v1/robots/{rail_id}/programs/filter", body)
    rep = want["report"]
    assert rep["filtered"] == 2 and rep["positioner_axes"] == ["E1"] and rep["axis_values"] == "corrected", (msg, rep)
    axes_line, rows, report, files = page_report(driver)
    assert axes_line == "External axes: turntable E1; values corrected", axes_line
    assert report == rep, (report, rep)
    assert files == {f["name"]: f["content"] for f in want["files"]}, files
    for row, t in zip(rows, rep["targets"], strict=True):
        at = ", ".join(axes_mod.shown_number(v, 4) for v in t["positioner_deg"])
        written = ", ".join(axes_mod.shown_number(v, 4) for v in t["positioner_written_deg"])
        assert row[3] == t["status"] and row[-1] == f"{at} → {written}°", (row, t)
    print(f"console_check: filtered on the turntable: {h.text_of(driver, '#filter-summary')}; {axes_line}; "
          f"XP0 at {rows[0][-1]}, the page's report and files the API's")
    shot("filtered-on-turntable", "filter-section")
    # Refused: the controller's positioner, and the robot has none stored.
    refused_body = dict(body, controller_positioner=json.loads(pathlib.Path(positioner).read_text()))
    del refused_body["controller_turntable"]
    status, answer = api_raw(h.KEY, base, "POST", f"/v1/robots/{rail_id}/programs/filter",
                             json.dumps(refused_body).encode(), "application/json")
    assert status == 409, (status, answer)
    refusal = f"409: {json.loads(answer)['detail']}"
    Select(form.find_element(By.NAME, "controller_plate_kind")).select_by_value("positioner")
    plate = form.find_element(By.NAME, "controller_plate_file")
    driver.execute_script("arguments[0].value = '';", plate)
    plate.send_keys(positioner)
    form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
    msg = wait.until(lambda d: (t := h.text_of(d, "#message")) and t.startswith("409") and t)
    assert msg == refusal, (msg, refusal)
    print(f"console_check: refused: {msg}")
    shot("filter-refused", "filter-section")
    for path in (f"/v1/robots/{rail_id}/tools/tip", f"/v1/robots/{rail_id}/frames/part"):
        assert api_raw(h.KEY, base, "DELETE", path)[0] == 204
    driver.get(driver.current_url)


def plan_sweeps(driver, wait, shot, base, rail_id, what, nominal, reflectors, axes_mod, h):
    """A face plate's sweeps (`what`: turntable or positioner) planned in the
    page's plan form with a KRL program: the page's σ, CSV and program are
    the API's for the same body."""
    form = wait.until(lambda d: d.find_element(By.ID, "measurement-plan"))
    Select(form.find_element(By.NAME, "what")).select_by_value(what)
    form.find_element(By.NAME, f"{what}_file").send_keys(nominal)
    box = form.find_element(By.NAME, f"{what}_reflectors")
    box.clear()
    box.send_keys("\n".join(r.replace(",", ", ") for r in reflectors))
    Select(form.find_element(By.NAME, "language")).select_by_value("krl")
    before = h.text_of(driver, "#plan-summary")
    form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
    wait.until(lambda d: (h.text_of(d, "#plan-summary") or before) != before
               or (h.text_of(d, "#message") or "").startswith("4"))
    summary = h.text_of(driver, "#plan-summary")
    plate = {"nominal": json.loads(pathlib.Path(nominal).read_text()),
             "reflectors": [[float(v) for v in r.split(",")] for r in reflectors]}
    want = h.api_post(base, f"/v1/robots/{rail_id}/measurement-plans",
                      {what: plate, "noise_mm": 0.01, "language": "krl"})
    assert summary.startswith(f"{want['poses']} poses of the {what}'s"), (summary, h.text_of(driver, "#message"))
    rows = [[td.text for td in r.find_elements(By.TAG_NAME, "td")]
            for r in driver.find_elements(By.CSS_SELECTOR, "#plan-sigma tbody tr")]
    sn = axes_mod.shown_number
    assert rows == [[s["axis"], sn(s["direction_deg"], 4), sn(s["point_mm"], 3), sn(s["zero_offset_deg"], 4),
                     f"{s['scale']:.2e}".replace("e-0", "e-").replace("e+0", "e+")] for s in want["sigma"]], \
        (rows, want["sigma"])
    refl = h.text_of(driver, "#plan-reflector-sigma")
    assert refl.endswith(", ".join(sn(v, 3) for v in want["reflector_sigma_mm"])), (refl, want["reflector_sigma_mm"])
    files = driver.execute_async_script(
        "const done = arguments[0];"
        "Promise.all([...document.querySelectorAll('#plan-downloads a.plan-file')]"
        ".map(a => fetch(a.href).then(r => r.text()).then(t => [a.textContent, t]))).then(done);")
    assert files[0] == [f"plan-{what}.csv", want["joints_csv"]], files[0]
    assert [f[1] for f in files[1:]] == [f["content"] for f in want["program"]["files"]], files
    assert not driver.find_element(By.ID, "plan-params").is_displayed()
    print(f"console_check: planned the {what}: {summary}; σ {'; '.join(' '.join(r) for r in rows)}; "
          f"{refl}; the CSV and {len(files) - 1} program files the API's")
    shot(f"plan-{what}", "plan-section")


def export_on_turntable(driver, wait, shot, base, rail_id, axes_mod, h):
    """The rail robot with its turntable stored (and no track): the
    controller data form's KRL export with the external axes `turntable`
    shows the API's text for the same body, the not-held table lists the
    API's `kinematics.not_held` terms (the turntable's scale), and the
    `held.json` download is its `kinematics.held`; `track` (none stored) is
    refused with the API's 409 and its detail."""
    form = wait.until(lambda d: d.find_element(By.ID, "export-cell"))
    Select(form.find_element(By.NAME, "language")).select_by_value("krl")
    axes = Select(form.find_element(By.NAME, "axes"))
    assert axes.first_selected_option.get_attribute("value") == "", "an axes kind is chosen by default"
    assert [o.get_attribute("value") for o in axes.options] == \
        ["", "positioner", "track", "turntable", "track_and_positioner", "track_and_turntable"], axes.options
    axes.select_by_value("turntable")
    before = h.text_of(driver, "#message")
    form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
    msg = wait.until(lambda d: (t := h.text_of(d, "#message")) and t != before and t)
    want = h.api_post(base, f"/v1/robots/{rail_id}/cell/export", {"language": "krl", "axes": "turntable"})
    k = want["kinematics"]
    assert k["kind"] == "turntable" and k["not_held"], (msg, k)
    assert msg.startswith("Controller data for krl with the turntable ("), msg
    text = driver.execute_script("return document.getElementById('export-text').textContent")
    assert text == want["text"], "the page's text differs from the API's"
    assert "MACHINE_DEF[2]" in text, text
    rows = [[td.text for td in r.find_elements(By.TAG_NAME, "td")]
            for r in driver.find_elements(By.CSS_SELECTOR, "#export-not-held tbody tr")]
    assert [r[0] for r in rows] == [n["term"] for n in k["not_held"]], (rows, k["not_held"])
    for row, n in zip(rows, k["not_held"], strict=True):
        assert row[2] == axes_mod.shown_number(n["miss_mm"], 3), (row, n)
    assert not driver.find_element(By.ID, "export-all-held").is_displayed()
    files = driver.execute_async_script(
        "const done = arguments[0];"
        "Promise.all([...document.querySelectorAll('#export-held-downloads a.held-file')]"
        ".map(a => fetch(a.href).then(r => r.json()).then(j => [a.download, j]))).then(done);")
    assert [f[0] for f in files] == ["held.json"], files
    assert files[0][1] == k["held"], (files[0][1], k["held"])
    print(f"console_check: exported with the turntable: {msg}; not held: "
          f"{'; '.join(' '.join(r) for r in rows)}; the text, the terms and held.json the API's")
    shot("export-turntable", "export-cell")
    # Refused: the track, and the robot has none stored.
    status, answer = axes_mod.api_raw(h.KEY, base, "POST", f"/v1/robots/{rail_id}/cell/export",
                                      json.dumps({"language": "krl", "axes": "track"}).encode(), "application/json")
    assert status == 409, (status, answer)
    refusal = f"409: {json.loads(answer)['detail']}"
    axes.select_by_value("track")
    form.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
    msg = wait.until(lambda d: (t := h.text_of(d, "#message")) and t.startswith("409") and t)
    assert msg == refusal, (msg, refusal)
    assert "msg bad" in driver.find_element(By.ID, "message").get_attribute("class")
    print(f"console_check: refused: {msg}")
    shot("export-refused", "export-cell")
    driver.get(driver.current_url)
