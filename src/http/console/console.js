// robocal web console: the page's forms call the REST API (/v1) with fetch.
// The API key (when the service has keys) is kept in this tab's
// sessionStorage and sent as `Authorization: Bearer <key>` on every request.
"use strict";

function apiKey() { return sessionStorage.getItem("robocal-key") || ""; }

function show(msg, ok) {
  const box = document.getElementById("message");
  box.textContent = msg;
  box.className = ok ? "msg ok" : "msg bad";
  box.hidden = false;
}

// A message for the next page (the page reloads after most changes).
function flash(msg) { sessionStorage.setItem("robocal-flash", msg); }

// Numbers as the pages write them (format.rs): mm to 0.001, degrees to
// 0.0001, never "-0".
function fixed(x, d) {
  if (x === null || x === undefined || !isFinite(x)) return "—";
  const s = Number(x).toFixed(d);
  return /^-[0.]*$/.test(s) ? s.slice(1) : s;
}
const fmtMm = (x) => fixed(x, 3);
const fmtDeg = (x) => fixed(x, 4);

async function api(method, url, body, contentType, accept) {
  const headers = {};
  if (apiKey()) headers["Authorization"] = "Bearer " + apiKey();
  if (contentType) headers["Content-Type"] = contentType;
  if (accept) headers["Accept"] = accept;
  const res = await fetch(url, { method, headers, body });
  const text = await res.text();
  if (!res.ok) {
    let detail = text;
    try { detail = JSON.parse(text).detail || text; } catch (e) { /* not JSON */ }
    // The status and the problem's detail, for handlers that answer one kind apart.
    throw Object.assign(new Error(res.status + ": " + detail), { status: res.status, detail });
  }
  return { text, json: () => JSON.parse(text), type: res.headers.get("Content-Type") || "", headers: res.headers };
}

// `body` as JSON to `url`.
const sendJson = (method, url, body) => api(method, url, JSON.stringify(body), "application/json");

function formValue(form, name) {
  const el = form.elements[name];
  return el ? el.value.trim() : "";
}

async function fileOrText(form, fileName, textName) {
  const f = form.elements[fileName];
  if (f && f.files && f.files.length) return await f.files[0].text();
  return formValue(form, textName);
}

const handlers = {
  async "create-robot"(form) {
    const body = { name: formValue(form, "name") || undefined };
    const model = formValue(form, "model");
    if (model) body.model = JSON.parse(model); else body.preset = formValue(form, "preset");
    const r = await sendJson("POST", "/v1/robots", body);
    location.href = "/ui/robots/" + r.json().id;
  },
  async upload(form) {
    const robot = form.dataset.robot;
    const text = await fileOrText(form, "file", "csv");
    if (!text) throw new Error("choose a CSV file or paste its text");
    const q = new URLSearchParams();
    for (const k of ["name", "role", "orientation", "session", "payload_kg", "decimal", "dif_sign"]) {
      const v = formValue(form, k);
      if (v) q.set(k, v);
    }
    // With a track column: one set per track value (station), in mm and degrees.
    const column = formValue(form, "track_column");
    if (column) {
      if (formValue(form, "length_unit") !== "mm" || formValue(form, "angle_unit") !== "deg") {
        throw new Error("a file with a track column is read in mm and degrees: choose those units");
      }
      q.set("column", column);
      await api("POST", `/v1/robots/${robot}/track/measurement-sets?${q}`, text, "text/csv");
    } else {
      for (const k of ["length_unit", "angle_unit"]) q.set(k, formValue(form, k));
      await api("POST", `/v1/robots/${robot}/measurement-sets?${q}`, text, "text/csv");
    }
    location.reload();
  },
  async solve(form) {
    const robot = form.dataset.robot;
    const text = await fileOrText(form, "file", "csv");
    if (!text) throw new Error("choose a targets CSV file or paste its text");
    const q = new URLSearchParams();
    for (const k of ["version", "frame", "payload_kg", "branch"]) {
      const v = formValue(form, k);
      if (v) q.set(k, v);
    }
    if (form.elements["position_only"].checked) q.set("position_only", "true");
    if (form.elements["turntable"].checked) q.set("turntable", "true");
    const r = await api("POST", `/v1/robots/${robot}/solve?${q}`, text, "text/csv", "text/csv");
    // "solved/total" of the whole batch, from the answer's header.
    const [solved, total] = (r.headers.get("X-Robocal-Solved") || "0/0").split("/");
    const summary = `${solved} of ${total} targets solved (model: ${r.headers.get("X-Robocal-Version")}, ${r.headers.get("X-Robocal-Method")})`;
    document.getElementById("solve-summary").textContent = summary;
    document.getElementById("solve-csv").textContent = r.text;
    const link = document.getElementById("solve-download");
    link.href = URL.createObjectURL(new Blob([r.text], { type: "text/csv" }));
    document.getElementById("solve-result").hidden = false;
    show(summary, true);
  },
  async calibrate(form) {
    const robot = form.dataset.robot;
    const methods = [...form.querySelectorAll("input[name=method]:checked")].map((c) => c.value);
    const body = { methods };
    const seed = formValue(form, "seed");
    if (seed) body.seed = Number(seed);
    const payload = formValue(form, "payload_kg");
    if (payload) body.payload_kg = Number(payload);
    // Ticked sets per role; none ticked: the service takes every set of the role.
    for (const role of ["identification", "validation", "training"]) {
      const ids = [...form.querySelectorAll(`input[name=${role}_set]:checked`)].map((c) => Number(c.value));
      if (ids.length) body[role + "_set_ids"] = ids;
    }
    await sendJson("POST", `/v1/robots/${robot}/calibrations`, body);
    location.reload();
  },
  async check(form) {
    const robot = form.dataset.robot;
    const body = { set_id: Number(formValue(form, "set_id")) };
    const version = formValue(form, "version");
    if (version) body.version = Number(version);
    const temperature = formValue(form, "temperature_c");
    if (temperature) body.temperature_c = Number(temperature);
    const c = (await sendJson("POST", `/v1/robots/${robot}/checks`, body)).json();
    flash(`Check ${c.id}: ${c.status}`);
    location.href = `/ui/robots/${robot}/checks/${c.id}`;
  },
  async compare(form) {
    const robot = form.dataset.robot;
    const versions = [...form.querySelectorAll("input[name=version]:checked")].map((c) => Number(c.value));
    if (!versions.length) throw new Error("tick at least one version");
    const body = { set_id: Number(formValue(form, "set_id")), versions };
    const r = (await sendJson("POST", `/v1/robots/${robot}/compare`, body)).json();
    const table = document.getElementById("compare-result");
    const tbody = table.querySelector("tbody");
    tbody.textContent = "";
    for (const v of r.versions) {
      const p = v.result.position;
      const o = v.result.orientation;
      const f = v.result.frame_shift;
      const shift = f ? `${fmtMm(f.translation_mm)} mm, ${fmtDeg(f.rotation_deg)}°` : "—";
      const cells = ["v" + v.version, v.method, fmtMm(p.mean_mm), fmtMm(p.p95_mm), fmtMm(p.max_mm),
        o ? fmtDeg(o.mean_deg) : "—", v.result.status, shift, f ? (f.explains ? "yes" : "no") : "—"];
      const tr = document.createElement("tr");
      tr.className = "compared";
      for (const [i, c] of cells.entries()) {
        const td = document.createElement("td");
        td.textContent = String(c);
        if (i === 6) td.className = `status-${c}`;
        tr.append(td);
      }
      tbody.append(tr);
    }
    table.hidden = false;
    show(`${r.versions.length} versions scored on set ${r.set_id}`, true);
  },
};

document.addEventListener("submit", async (ev) => {
  const form = ev.target;
  const h = handlers[form.dataset.action];
  if (!h) return;
  ev.preventDefault();
  const button = form.querySelector("button[type=submit]");
  if (button) button.disabled = true;
  try {
    await h(form);
  } catch (e) {
    show(e.message, false);
  } finally {
    if (button) button.disabled = false;
  }
});

document.addEventListener("click", async (ev) => {
  const b = ev.target.closest("button[data-post]");
  if (!b) return;
  ev.preventDefault();
  // Activating, rolling back and cancelling are asked first.
  if (b.dataset.confirm && !window.confirm(b.dataset.confirm)) return;
  b.disabled = true;
  try {
    await api("POST", b.dataset.post);
    flash(b.dataset.done || b.textContent.trim() + ": done");
    location.reload();
  } catch (e) {
    show(e.message, false);
    b.disabled = false;
  }
});

// The key form stores the key in this tab only.
document.addEventListener("DOMContentLoaded", () => {
  const said = sessionStorage.getItem("robocal-flash");
  if (said) {
    sessionStorage.removeItem("robocal-flash");
    show(said, true);
  }
  // Times as the browser's local time (the server writes UTC).
  for (const t of document.querySelectorAll("time[datetime]")) {
    const d = new Date(t.dateTime);
    if (!isNaN(d)) {
      t.title = t.dateTime;
      t.textContent = d.toLocaleString();
    }
  }
  const key = document.getElementById("api-key");
  if (key) {
    key.value = apiKey();
    key.addEventListener("change", () => sessionStorage.setItem("robocal-key", key.value.trim()));
  }
  // Live progress: while a job is queued or running, poll it and reload when it ends.
  const rows = document.querySelectorAll("tr[data-job][data-active=true]");
  for (const row of rows) {
    const url = row.dataset.job;
    const timer = setInterval(async () => {
      try {
        const j = (await api("GET", url)).json();
        row.querySelector(".status").textContent = j.status;
        row.querySelector(".phase").textContent = phaseText(j.progress);
        const bar = row.querySelector("progress");
        bar.value = j.progress.percent;
        row.querySelector(".percent").textContent = percentText(j.progress);
        if (j.status !== "queued" && j.status !== "running") {
          clearInterval(timer);
          location.reload();
        }
      } catch (e) {
        clearInterval(timer);
      }
    }, 1000);
  }
});

// A job's phase with the candidate and fold it is on (pages.rs `phase_text`).
function phaseText(p) {
  let t = p.phase || "";
  if (p.candidate) t += " · " + p.candidate;
  if (p.fold) t += " · fold " + p.fold.index + "/" + p.fold.of;
  return t;
}

// Seconds left as `42 s`, `3 min 05 s`, `1 h 02 min` (identify::progress::time_left).
function timeLeft(s) {
  s = Math.max(0, Math.round(s));
  if (s < 60) return s + " s";
  const pad = (n) => String(n).padStart(2, "0");
  if (s < 3600) return Math.floor(s / 60) + " min " + pad(s % 60) + " s";
  return Math.floor(s / 3600) + " h " + pad(Math.floor((s % 3600) / 60)) + " min";
}

// The percentage with the time left (pages.rs `percent_text`).
function percentText(p) {
  const pct = p.percent.toFixed(0) + " %";
  return p.eta_s == null ? pct : pct + " · " + timeLeft(p.eta_s) + " left";
}

// Tools and work objects: save one (PUT by name) with every field of its
// form (number, frame, pose, load), delete one after a confirmation.
handlers["put-item"] = async function (form) {
  const num = (k) => Number(formValue(form, k) || "0");
  const body = {
    xyz_mm: [num("x"), num("y"), num("z")],
    rpy_deg: [num("rx"), num("ry"), num("rz")],
  };
  const n = formValue(form, "number");
  if (n) body.number = Number(n);
  const frame = formValue(form, "frame");
  if (frame) body.frame = frame;
  const mass = formValue(form, "load_mass_kg");
  if (mass) {
    body.load = {
      mass_kg: Number(mass),
      com_mm: [num("load_com_x"), num("load_com_y"), num("load_com_z")],
      frame: formValue(form, "load_frame") || "flange",
    };
    const inertia = ["load_ixx", "load_iyy", "load_izz"].map((k) => formValue(form, k));
    if (inertia.some((v) => v)) {
      if (!inertia.every((v) => v)) throw new Error("give all three moments of inertia, or none");
      body.load.inertia_kgm2 = inertia.map(Number);
    }
  }
  const name = formValue(form, "name");
  const url = form.dataset.url + encodeURIComponent(name);
  await sendJson("PUT", url, body);
  flash(`Saved ${name}`);
  location.reload();
};

document.addEventListener("click", async (ev) => {
  const b = ev.target.closest("button[data-delete]");
  if (!b) return;
  ev.preventDefault();
  if (b.dataset.confirm && !window.confirm(b.dataset.confirm)) return;
  b.disabled = true;
  try {
    await api("DELETE", b.dataset.delete);
    flash("Deleted");
    if (b.dataset.then) location.href = b.dataset.then; else location.reload();
  } catch (e) {
    show(e.message, false);
    b.disabled = false;
  }
});

// Check thresholds: the form gives both levels, the API takes the degraded
// level and the margin up to the recalibrate level.
handlers.thresholds = async function (form) {
  const degraded = Number(formValue(form, "degraded_mm"));
  const recalibrate = Number(formValue(form, "recalibrate_mm"));
  if (!(recalibrate >= degraded)) throw new Error("the recalibrate level must be at least the degraded level");
  const body = { degraded_mm: degraded, margin_mm: Number((recalibrate - degraded).toFixed(9)) };
  const ratio = formValue(form, "frame_shift_ratio");
  if (ratio) body.frame_shift_ratio = Number(ratio);
  await sendJson("PUT", `/v1/robots/${form.dataset.robot}/check-thresholds`, body);
  flash("Thresholds set");
  location.reload();
};

// Re-register a version on a check's set; the new version is listed on the
// robot page (activated only when asked).
handlers.reregister = async function (form) {
  const robot = form.dataset.robot;
  const body = { set_id: Number(formValue(form, "set_id")), version: Number(formValue(form, "version")) };
  if (form.elements["activate"].checked) body.activate = true;
  const v = (await sendJson("POST", `/v1/robots/${robot}/reregister`, body)).json();
  const r = v.stats.reregistered.report;
  flash(`Re-registered as v${v.version}${v.active ? " (active)" : ""}: mean ${fmtMm(r.before.mean_mm)} → ${fmtMm(r.after.mean_mm)} mm on set ${body.set_id}`);
  location.href = `/ui/robots/${robot}#versions`;
};

// The controller's tool, load and work object data, shown and offered;
// with external axes chosen, what the controller holds of them
// (console_axes.js).
handlers["export-cell"] = async function (form) {
  const language = formValue(form, "language");
  const axes = formValue(form, "axes");
  const body = axes ? { language, axes } : { language };
  const r = (await sendJson("POST", `/v1/robots/${form.dataset.robot}/cell/export`, body)).json();
  document.getElementById("export-text").textContent = r.text;
  const link = document.getElementById("export-download");
  link.href = URL.createObjectURL(new Blob([r.text], { type: "text/plain" }));
  link.download = { krl: "config.dat", rapid: "cell.mod", fanuc: "cell.ls", urscript: "cell.script" }[language];
  link.textContent = "Download " + link.download;
  const held = showExportKinematics(r.kinematics);
  document.getElementById("export-result").hidden = false;
  show(`Controller data for ${language}${held} (model: ${r.version === null ? "nominal" : "v" + r.version})`, true);
};

// Predict: joint readings in, poses out.
handlers.predict = async function (form) {
  const readings = [];
  for (const line of formValue(form, "readings").split(/\n/)) {
    const parts = line.split(/[,;\s]+/).filter((p) => p);
    if (!parts.length) continue;
    const reading = {};
    if (isNaN(Number(parts[0]))) reading.id = parts.shift();
    reading.joints_deg = parts.map(Number);
    readings.push(reading);
  }
  if (!readings.length) throw new Error("give at least one joint reading");
  // The frame: none (the tracker's, or the positioner's face plate with
  // e2), the base, or a work object ("wobj:<name>").
  const frame = formValue(form, "frame");
  const body = { readings };
  if (frame.startsWith("wobj:")) body.work_object = frame.slice(5);
  else if (frame) body.frame = frame;
  // The external axes' values given (e1 the track's [mm] or the positioner's
  // tilt [deg], e2, e3 the positioner's); the API refuses a combination the
  // robot's stored axes do not fit, and its reason is shown.
  const axes = [];
  for (const name of ["e1", "e2", "e3"]) {
    const v = formValue(form, name);
    if (!v) continue;
    body[name] = Number(v);
    axes.push(`${name} = ${v}`);
  }
  // On the stored turntable: e1 is its value (e2 beside a track's e1).
  if (form.elements["turntable"].checked) {
    body.turntable = true;
    axes.push("on the turntable");
  }
  const version = formValue(form, "version");
  if (version) body.version = /^[0-9]+$/.test(version) ? Number(version) : version;
  const tool = formValue(form, "tool");
  if (tool) body.tool = tool;
  const payload = formValue(form, "payload_kg");
  if (payload) body.payload_kg = Number(payload);
  const convention = formValue(form, "convention");
  if (convention) body.convention = convention;
  const r = (await sendJson("POST", `/v1/robots/${form.dataset.robot}/predict`, body)).json();
  const tbody = document.querySelector("#predict-table tbody");
  tbody.textContent = "";
  for (const p of r.results) {
    const note = [p.message, p.warning, p.outside_limits.length ? "outside limits: joints " + p.outside_limits.join(", ") : ""].filter((x) => x).join("; ");
    const other = p.orientation ? p.orientation.values.map((v) => fixed(v, 6)).join(", ") : "—";
    const cells = [p.id, p.status, fmtMm(p.x), fmtMm(p.y), fmtMm(p.z), fmtDeg(p.rx), fmtDeg(p.ry), fmtDeg(p.rz), other, note];
    const tr = document.createElement("tr");
    tr.className = "predicted";
    for (const c of cells) {
      const td = document.createElement("td");
      td.textContent = String(c);
      tr.append(td);
    }
    tbody.append(tr);
  }
  const acc = r.accuracy && r.accuracy.mean_mm !== undefined ? `; expected error ${fmtMm(r.accuracy.mean_mm)} mm mean` : "";
  document.getElementById("predict-convention").textContent = convention || "Convention";
  // The axes' values as sent (the answer names the frame, not the values).
  const at = axes.length ? ` (${axes.join(", ")})` : "";
  const summary = `${r.results.length} poses of ${r.tool || "the measured point"} in the ${r.frame} frame${at} at ${fixed(r.payload_kg, 3)} kg (model: ${r.version === null ? "nominal" : "v" + r.version} ${r.method})${acc}`;
  document.getElementById("predict-summary").textContent = summary;
  document.getElementById("predict-result").hidden = false;
  show(summary, true);
};

// Program filtering: the files in, the report as a table, each filtered file
// as a download link.
handlers.filter = async function (form) {
  const robot = form.dataset.robot;
  const input = form.elements["files"];
  if (!input.files.length) throw new Error("choose the program's files");
  const files = [];
  for (const f of input.files) files.push({ name: f.name, content: await f.text() });
  const body = { files };
  const version = formValue(form, "version");
  if (version) body.version = /^[0-9]+$/.test(version) ? Number(version) : version;
  // The language as chosen, else from the first file's extension.
  const byExtension = { src: "krl", dat: "krl", mod: "rapid", modx: "rapid", prg: "rapid", sys: "rapid", ls: "fanuc", script: "urscript", urscript: "urscript" };
  const ext = files[0].name.split(".").pop().toLowerCase();
  body.language = formValue(form, "language") || byExtension[ext];
  if (!body.language) throw new Error("choose the program's language");
  await filterAxes(form, body);
  const r = (await sendJson("POST", `/v1/robots/${robot}/programs/filter`, body)).json();
  const rep = r.report;
  showFilterAxes(rep);
  const summary = `${rep.filtered} targets filtered, ${rep.failed} failed, ${rep.skipped} skipped; ${rep.joint_motions.length} joint motions (model: ${r.version === null ? "nominal" : "v" + r.version} ${r.method})`;
  document.getElementById("filter-summary").textContent = summary;
  const links = document.getElementById("filter-downloads");
  links.textContent = "Download: ";
  for (const f of r.files) downloadLink(links, f.name, f.content, "filtered-file");
  const tbody = document.querySelector("#filter-report tbody");
  tbody.textContent = "";
  for (const t of rep.targets) {
    const cells = [t.motion.file, t.motion.line, `${t.motion.instruction} ${t.name}`, t.status, t.shift_mm === undefined ? "" : fmtMm(t.shift_mm), t.configuration || "", t.reason || "", targetAxesText(t)];
    appendRow(tbody, cells, "target " + t.status);
  }
  const report = document.getElementById("filter-report-download");
  report.href = URL.createObjectURL(new Blob([JSON.stringify(rep, null, 2)], { type: "application/json" }));
  document.getElementById("filter-result").hidden = false;
  show(summary, true);
};

// A file a response holds, as a download link in `box`.
function downloadLink(box, name, text, className) {
  const a = document.createElement("a");
  a.href = URL.createObjectURL(new Blob([text], { type: "text/plain" }));
  a.download = name;
  a.className = className;
  a.textContent = name;
  box.append(a, " ");
}

// A row of cells (text only) appended to `tbody`.
function appendRow(tbody, cells, className) {
  const tr = document.createElement("tr");
  if (className) tr.className = className;
  for (const c of cells) {
    const td = document.createElement("td");
    td.textContent = String(c);
    tr.append(td);
  }
  tbody.append(tr);
}

// A plan's CSV and its program's files (if it has one) as download links in the box `id`.
function planDownloads(id, csvName, csv, program, className) {
  const links = document.getElementById(id);
  links.textContent = "Download: ";
  downloadLink(links, csvName, csv, className);
  if (program) for (const f of program.files) downloadLink(links, f.name, f.content, className);
}

const triple = (form, prefix) => ["x", "y", "z"].map((a) => Number(formValue(form, `${prefix}_${a}`)));

// A measurement plan: the poses, the parameters' predicted standard
// deviations, the joints CSV and the program; with `overTrack`, the body is
// handed to it (a plan over a track, console_axes.js).
handlers["measurement-plan"] = async function (form, overTrack) {
  const body = {
    poses: Number(formValue(form, "poses")),
    candidates: Number(formValue(form, "candidates")),
    workspace: { min_mm: triple(form, "min"), max_mm: triple(form, "max") },
    tracker: {
      position_mm: triple(form, "tracker"),
      axis: triple(form, "axis"),
      max_angle_deg: Number(formValue(form, "max_angle_deg")),
    },
    noise_mm: Number(formValue(form, "noise_mm")),
    seed: Number(formValue(form, "seed")),
  };
  const payload = formValue(form, "payload_kg");
  if (payload) body.payload_kg = Number(payload);
  const language = formValue(form, "language");
  if (language) {
    body.language = language;
    const name = formValue(form, "name");
    if (name) body.name = name;
  }
  if (overTrack) return overTrack(body);
  const r = (await sendJson("POST", `/v1/robots/${form.dataset.robot}/measurement-plans`, body)).json();
  const c = r.counts;
  const summary = `${r.poses} poses chosen from ${c.drawn} candidates (${c.reachable} reachable, ${c.in_box} in the box, ${c.in_sight} in sight) at ${fixed(r.payload_kg, 3)} kg`;
  document.getElementById("plan-summary").textContent = summary;
  planDownloads("plan-downloads", "plan-joints.csv", r.joints_csv, r.program, "plan-file");
  const tbody = document.querySelector("#plan-params tbody");
  tbody.textContent = "";
  for (const m of r.predicted) {
    for (const p of m.params) {
      const std = p.unit === "mm" ? fmtMm(p.std) : p.unit === "deg" ? fmtDeg(p.std) : Number(p.std).toPrecision(3);
      appendRow(tbody, [m.method, p.name, std, p.unit], "plan-param");
    }
    if (m.not_identified.length) appendRow(tbody, [m.method, "not identified: " + m.not_identified.join(", "), "", ""]);
  }
  document.getElementById("plan-result").hidden = false;
  show(summary, true);
};

// ISO 9283: the cube, its plan CSV (also put into the figures form) and its program.
handlers["iso-plan"] = async function (form) {
  const body = { min_mm: triple(form, "min"), max_mm: triple(form, "max"), commands: formValue(form, "commands") };
  const language = formValue(form, "language");
  if (language) {
    body.language = language;
    body.cycles = Number(formValue(form, "cycles"));
  }
  const r = (await sendJson("POST", `/v1/robots/${form.dataset.robot}/iso9283/plan`, body)).json();
  const summary = `Cube of ${fmtMm(r.edge_mm)} mm edge (the box holds ${fmtMm(r.largest_edge_mm)} mm) centred at ${r.centre_mm.map(fmtMm).join(", ")} mm, v${r.version} ${r.commands} commands`;
  document.getElementById("iso-plan-summary").textContent = summary;
  planDownloads("iso-plan-downloads", "iso9283-plan.csv", r.plan_csv, r.program, "iso-file");
  const tbody = document.querySelector("#iso-plan-poses tbody");
  tbody.textContent = "";
  for (const p of r.poses) {
    appendRow(tbody, [p.name, p.commanded_mm.map(fmtMm).join(", "), p.commanded_abc_deg.map(fmtDeg).join(", "), p.joints_deg.map(fmtDeg).join(", ")], "iso-pose");
  }
  document.querySelector("#iso-figures [name=plan_csv]").value = r.plan_csv;
  document.getElementById("iso-plan-result").hidden = false;
  show(summary, true);
};

// ISO 9283 figures from the plan CSV and the measured cycles of one or two
// tests (side by side), with the test's conditions, and the report page.
handlers["iso-figures"] = async function (form) {
  const planCsv = formValue(form, "plan_csv");
  const tests = [];
  for (const suffix of ["", "_2"]) {
    const measured = await fileOrText(form, "measured_file" + suffix, "measured_csv" + suffix);
    if (measured) tests.push({ label: formValue(form, "label" + suffix) || `test ${tests.length + 1}`, plan_csv: planCsv, measured_csv: measured });
  }
  if (!tests.length) throw new Error("choose the measured cycles CSV or paste it");
  const conditions = { robot_id: Number(form.dataset.robot) };
  for (const name of ["load_kg", "speed_percent"]) {
    const v = formValue(form, name);
    if (v) conditions[name] = Number(v);
  }
  for (const name of ["date", "measurement"]) {
    const v = formValue(form, name);
    if (v) conditions[name] = v;
  }
  const body = JSON.stringify({ tests, conditions });
  const r = (await api("POST", "/v1/iso9283/csv", body, "application/json")).json();
  const report = await api("POST", "/v1/iso9283/csv", body, "application/json", "text/html");
  document.getElementById("iso-report-download").href = URL.createObjectURL(new Blob([report.text], { type: "text/html" }));
  const c = r.conditions || {};
  const stated = (x, unit) => (x === null || x === undefined ? "not stated" : x + unit);
  document.getElementById("iso-conditions").textContent =
    `${c.robot || "robot not stated"}, model ${/^[0-9]+$/.test(c.model_version || "") ? "v" + c.model_version : c.model_version || "not stated"}, ${c.date || ""}; load ${stated(c.load_kg, " kg")}, speed ${stated(c.speed_percent, " %")}; measurement: ${c.measurement || "not stated"}`;
  const figure = (f, value) => (f.outcome === "computed" ? value(f) : "— " + f.message);
  const head = (table, first, columns) => {
    const thead = document.querySelector(`#${table} thead`);
    thead.textContent = "";
    const tr = document.createElement("tr");
    for (const text of [first, ...r.tests.flatMap((t) => columns.map((c) => `${c} (${t.label})`))]) {
      const th = document.createElement("th");
      th.textContent = text;
      tr.append(th);
    }
    thead.append(tr);
  };
  head("iso-poses", "Pose", ["Cycles", "AP [mm]", "APx, APy, APz [mm]", "RP [mm]"]);
  const poses = document.querySelector("#iso-poses tbody");
  poses.textContent = "";
  r.tests[0].poses.forEach((p, i) => {
    const cells = [p.pose];
    for (const t of r.tests) {
      const q = t.poses[i];
      cells.push(q.cycles, figure(q.ap, (f) => fmtMm(f.ap_mm)), figure(q.ap, (f) => f.ap_xyz_mm.map(fmtMm).join(", ")), figure(q.rp, (f) => fmtMm(f.rp_mm)));
    }
    appendRow(poses, cells, "iso-figure");
  });
  head("iso-distances", "Poses", ["AD [mm]", "RD [mm]"]);
  const distances = document.querySelector("#iso-distances tbody");
  distances.textContent = "";
  r.tests[0].distances.forEach((d, i) => {
    const cells = [`${d.from}–${d.to}`];
    for (const t of r.tests) {
      const e = t.distances[i];
      cells.push(figure(e.ad, (f) => fmtMm(f.ad_mm)), figure(e.rd, (f) => fmtMm(f.rd_mm)));
    }
    appendRow(distances, cells, "iso-distance");
  });
  document.getElementById("iso-result").hidden = false;
  show(`ISO 9283 figures of ${r.tests.length} test(s): ${r.tests[0].poses.length} poses and ${r.tests[0].distances.length} distances`, true);
};

// Fits: the rows of a textarea as numbers (a leading word kept apart).
function rows(text) {
  const out = [];
  for (const line of text.split(/\n/)) {
    const parts = line.split(/[,;\s]+/).filter((p) => p);
    if (!parts.length) continue;
    const word = isNaN(Number(parts[0])) ? parts.shift() : null;
    out.push({ word, values: parts.map(Number) });
  }
  return out;
}

// A fit's answer: stored (the page reloads with it), or why not (shown).
function fitAnswer(r, what) {
  const f = r.fit;
  if (r.fitted || r.forced) {
    const residual = f.rms_mm !== undefined ? `, residual rms ${fmtMm(f.rms_mm)} mm` : f.scatter_mm ? `, scatter ${f.scatter_mm.map(fmtMm).join(", ")} mm` : "";
    const turned = f.rpy_deg ? `, rx, ry, rz ${f.rpy_deg.map(fmtDeg).join(", ")}°` : "";
    const angle = f.sigma_deg !== undefined ? `, orientation σ ${fmtDeg(f.sigma_deg)}°` : "";
    flash(`Fitted ${what} on v${r.version}: ${f.xyz_mm.map(fmtMm).join(", ")} mm${turned}${residual}${angle}${r.forced ? " (forced: " + r.message + ")" : ""}`);
    location.reload();
    return;
  }
  const box = document.getElementById("fit-result");
  box.textContent = `${what} not fitted (${r.reason}): ${r.message}`;
  box.className = "bad";
  box.hidden = false;
  show(box.textContent, false);
}

// A TCP reading as its method measures it: joints, then the tracker's
// x, y, z (tracker point) and rx, ry, rz (6-D probe).
function toolReading(method, values) {
  if (method === "tracker_point") return { joints_deg: values.slice(0, -3), xyz_mm: values.slice(-3) };
  if (method === "tracker_frame") return { joints_deg: values.slice(0, -6), xyz_mm: values.slice(-6, -3), rpy_deg: values.slice(-3) };
  return { joints_deg: values };
}

handlers["fit-tool"] = async function (form) {
  const method = formValue(form, "method");
  const readings = rows(formValue(form, "readings")).map((r) => toolReading(method, r.values));
  if (!readings.length) throw new Error("give the readings, one a line");
  const body = { method, readings };
  const axis = formValue(form, "axis");
  if (axis) {
    // A plane is touched: joint readings only; a second axis point is measured like the tip.
    const axisRows = rows(formValue(form, "axis_readings")).map((r) => (axis === "plane" ? { joints_deg: r.values } : toolReading(method, r.values)));
    if (!axisRows.length) throw new Error("give the axis readings, one a line");
    body[axis] = axisRows;
  }
  for (const name of ["number", "version"]) {
    const v = formValue(form, name);
    if (v) body[name] = Number(v);
  }
  const rpy = rows(formValue(form, "rpy"))[0];
  if (rpy) {
    if (rpy.values.length !== 3) throw new Error("the orientation is three angles: rx, ry, rz");
    body.rpy_deg = rpy.values;
  }
  if (form.elements["force"].checked) body.force = true;
  const name = formValue(form, "name");
  const r = (await sendJson("POST", `/v1/robots/${form.dataset.robot}/tools/${encodeURIComponent(name)}/fit`, body)).json();
  fitAnswer(r, "tool " + name);
};

handlers["fit-frame"] = async function (form) {
  const tool = formValue(form, "tool");
  const readings = rows(formValue(form, "readings")).map((r) =>
    tool ? { point: r.word, joints_deg: r.values } : { point: r.word, xyz_mm: r.values });
  if (!readings.length) throw new Error("give the points, one a line");
  const body = { readings };
  if (tool) body.tool = tool;
  const name = formValue(form, "name");
  const r = (await sendJson("POST", `/v1/robots/${form.dataset.robot}/frames/${encodeURIComponent(name)}/fit`, body)).json();
  fitAnswer(r, "work object " + name);
};

// External axes: a fit is stored (the page reloads and says so) or refused
// (a 422: nothing stored, what was stored is kept; the reason and the
// message are shown, with what the form can change). `hint(reason, detail)`
// says what to change when the form's choices can be the cause; the box
// under the form (`track-result`, `positioner-result`) and the page's
// message say it.
async function axisFit(what, url, body, fitted, hint) {
  let r;
  try {
    r = (await sendJson("POST", url, body)).json();
  } catch (e) {
    if (e.status !== 422) throw e;
    const detail = String(e.detail).replace(/[.\s]+$/, "");
    const reason = (detail.match(/^not fitted \(([a-z_]+)\)/) || [])[1];
    const more = hint(reason, detail);
    const noun = what.toLowerCase();
    const kept = document.getElementById(noun + "-stored") ? `the stored ${noun} is kept` : `no ${noun} is stored`;
    const box = document.getElementById(noun + "-result");
    box.textContent = `${what} ${detail.startsWith("not fitted") ? "" : "not fitted: "}${detail}.${more ? " " + more : ""} Nothing was stored: ${kept}.`;
    box.className = "bad";
    box.hidden = false;
    show(box.textContent, false);
    return;
  }
  flash(fitted(r));
  location.reload();
}

// Set ids as typed: "12-22", "12, 13, 14", or both ("3, 7-9").
function setIds(text) {
  const ids = [];
  for (const part of text.split(",").map((p) => p.trim()).filter((p) => p)) {
    const m = part.match(/^(\d+)(?:\s*[-–]\s*(\d+))?$/);
    if (!m) throw new Error(`station sets: "${part}" is neither an id nor a range of ids (12-22)`);
    const [a, b] = [Number(m[1]), Number(m[2] || m[1])];
    if (b < a || b - a >= 100) throw new Error(`station sets: "${part}" is not a range of at most 100 ids`);
    for (let i = a; i <= b; i++) ids.push(i);
  }
  return ids;
}

handlers["calibrate-track"] = async function (form) {
  const csv = await fileOrText(form, "file", "csv");
  const sets = formValue(form, "set_ids");
  if (csv && sets) throw new Error("give the measurement file or its station sets, not both");
  if (!csv && !sets) throw new Error("choose the measurement file, paste its text, or give its station sets");
  const column = formValue(form, "column");
  const body = csv ? { csv, column } : { set_ids: setIds(sets), column };
  for (const name of ["sigma_mm", "max_order", "version", "payload_kg"]) {
    const v = formValue(form, name);
    if (v) body[name] = Number(v);
  }
  await axisFit("Track", `/v1/robots/${form.dataset.robot}/track/calibrate`, body,
    (r) => `Track fitted: RMS ${fmtMm(r.rms_mm)} mm over ${r.stations} stations (${r.readings} readings, max ${fmtMm(r.max_mm)} mm; model v${r.version} held)`,
    (reason) => (reason === "missing_column" ? `The form reads the track's value from column ${column}: choose the file's track column.` : ""));
};

// The reflectors' design positions: one x, y, z line [mm] per measurement file.
function reflectorLines(text) {
  return rows(text).map((r, i) => {
    if (r.word !== null || r.values.length !== 3 || !r.values.every(isFinite)) {
      throw new Error(`reflector position line ${i + 1}: give x, y, z in mm (three numbers)`);
    }
    return r.values;
  });
}

// A form's nominal axis (`what`): its JSON file or pasted text, parsed.
async function nominalJson(form, what) {
  const text = await fileOrText(form, "nominal_file", "nominal");
  if (!text) throw new Error(`choose the nominal ${what}'s JSON file or paste it`);
  try {
    return JSON.parse(text);
  } catch (e) {
    throw new Error(`the nominal ${what} is not JSON: ` + e.message);
  }
}

// A form's measurement files (their texts, in the order chosen) and the
// reflectors' design positions, one line per file.
async function reflectorSets(form) {
  const files = form.elements["sets"].files;
  if (!files.length) throw new Error("choose the measurement files, one per reflector");
  const reflectors = reflectorLines(formValue(form, "reflectors"));
  if (reflectors.length !== files.length) {
    throw new Error(`${reflectors.length} reflector position lines for ${files.length} measurement files: give one x, y, z line per file, in the files' order`);
  }
  const sets = [];
  for (const f of files) sets.push(await f.text());
  return { sets, reflectors };
}

// Touches (the positioner form's "readings from"): the version and stored
// tool that placed them; σ is the robot's at the tool's tip, not a tracker's,
// so it must be given.
function touchedWith(form, sigma) {
  const version = Number(formValue(form, "touched_version"));
  if (!(Number.isInteger(version) && version >= 1)) throw new Error("touches: choose the model version that placed them");
  const tool = formValue(form, "touched_tool");
  if (!tool) throw new Error("touches: choose the stored tool that touched (store it under Tools first)");
  if (!sigma) throw new Error("touches need σ [mm]: the robot's accuracy at the tool's tip (e.g. its validation RMS / √3), not a tracker's");
  return { version, tool };
}

handlers["calibrate-positioner"] = async function (form) {
  const nominal = await nominalJson(form, "positioner");
  const tilt = formValue(form, "tilt_column");
  const rotate = formValue(form, "rotate_column");
  if (tilt === rotate) throw new Error(`the tilt and rotate columns are both ${tilt}: choose two columns`);
  const sigma = formValue(form, "sigma_mm");
  const touches = formValue(form, "readings_from") === "touches" ? touchedWith(form, sigma) : null;
  const body = { ...(await reflectorSets(form)), nominal, tilt_column: tilt, rotate_column: rotate };
  if (sigma) body.sigma_mm = Number(sigma);
  if (touches) body.touched_with = touches;
  const from = touches ? `; touches with tool ${touches.tool} of version ${touches.version}` : "";
  await axisFit("Positioner", `/v1/robots/${form.dataset.robot}/positioner/calibrate`, body,
    (r) => `Positioner fitted: RMS ${fmtMm(r.rms_mm)} mm over ${r.readings} readings of ${r.reflectors} reflectors (max ${fmtMm(r.max_mm)} mm)${from}`,
    (reason, detail) => (/\bcolumn/.test(detail) ? `The form reads the tilt from column ${tilt} and the rotate from ${rotate}: choose the files' columns.` : ""));
};

handlers["calibrate-turntable"] = async function (form) {
  const nominal = await nominalJson(form, "turntable");
  const body = { ...(await reflectorSets(form)), nominal, column: formValue(form, "column") };
  const sigma = formValue(form, "sigma_mm");
  if (sigma) body.sigma_mm = Number(sigma);
  await axisFit("Turntable", `/v1/robots/${form.dataset.robot}/turntable/calibrate`, body,
    (r) => `Turntable fitted: RMS ${fmtMm(r.rms_mm)} mm over ${r.readings} readings of ${r.reflectors} reflectors (max ${fmtMm(r.max_mm)} mm)`,
    (reason, detail) => (/\bcolumn/.test(detail) ? `The form reads the axis's value from column ${body.column}: choose the files' column.` : ""));
};

// A fit's measurement files in the order they were chosen, the order the
// reflector lines follow, listed in the form's note.
document.addEventListener("change", (ev) => {
  const input = ev.target;
  const note = input.name === "sets" && input.form && input.form.querySelector("p.files");
  if (!note) return;
  const names = [...input.files].map((f, i) => `${i + 1}. ${f.name}`);
  note.textContent = names.length ? `Files in this order (one reflector line each, in the same order): ${names.join(", ")}` : "";
});

// The positioner's readings: touches show the version and tool to choose,
// and σ is then the robot's, so the tracker's default is cleared (and put
// back for tracker files when nothing else was typed).
document.addEventListener("change", (ev) => {
  const input = ev.target;
  if (input.name !== "readings_from" || !input.form) return;
  const touches = input.value === "touches";
  document.getElementById("positioner-touches").hidden = !touches;
  const sigma = input.form.elements["sigma_mm"];
  if (touches && sigma.value === sigma.defaultValue) sigma.value = "";
  if (!touches && !sigma.value) sigma.value = sigma.defaultValue;
  sigma.placeholder = touches ? "required with touches" : "";
});

// A form the browser restores (a back navigation) keeps its choice of
// readings: the touches group shows when "touches" is still checked.
window.addEventListener("pageshow", () => {
  const checked = document.querySelector('input[name="readings_from"]:checked');
  const group = document.getElementById("positioner-touches");
  if (checked && group) group.hidden = checked.value !== "touches";
});
