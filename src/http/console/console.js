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
    throw new Error(res.status + ": " + detail);
  }
  return { text, json: () => JSON.parse(text), type: res.headers.get("Content-Type") || "", headers: res.headers };
}

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
    const r = await api("POST", "/v1/robots", JSON.stringify(body), "application/json");
    location.href = "/ui/robots/" + r.json().id;
  },
  async upload(form) {
    const robot = form.dataset.robot;
    const text = await fileOrText(form, "file", "csv");
    if (!text) throw new Error("choose a CSV file or paste its text");
    const q = new URLSearchParams();
    for (const k of ["name", "role", "orientation", "session", "payload_kg", "length_unit", "angle_unit", "decimal", "dif_sign"]) {
      const v = formValue(form, k);
      if (v) q.set(k, v);
    }
    await api("POST", `/v1/robots/${robot}/measurement-sets?${q}`, text, "text/csv");
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
    await api("POST", `/v1/robots/${robot}/calibrations`, JSON.stringify(body), "application/json");
    location.reload();
  },
  async check(form) {
    const robot = form.dataset.robot;
    const body = { set_id: Number(formValue(form, "set_id")) };
    const version = formValue(form, "version");
    if (version) body.version = Number(version);
    const temperature = formValue(form, "temperature_c");
    if (temperature) body.temperature_c = Number(temperature);
    await api("POST", `/v1/robots/${robot}/checks`, JSON.stringify(body), "application/json");
    location.reload();
  },
  async compare(form) {
    const robot = form.dataset.robot;
    const versions = [...form.querySelectorAll("input[name=version]:checked")].map((c) => Number(c.value));
    if (!versions.length) throw new Error("tick at least one version");
    const body = { set_id: Number(formValue(form, "set_id")), versions };
    const r = (await api("POST", `/v1/robots/${robot}/compare`, JSON.stringify(body), "application/json")).json();
    const table = document.getElementById("compare-result");
    const tbody = table.querySelector("tbody");
    tbody.textContent = "";
    for (const v of r.versions) {
      const p = v.result.position;
      const o = v.result.orientation;
      const f = v.result.frame_shift;
      const shift = f ? `${f.translation_mm.toFixed(3)} mm, ${f.rotation_deg.toFixed(4)}°` : "—";
      const cells = ["v" + v.version, v.method, p.mean_mm.toFixed(4), p.p95_mm.toFixed(4), p.max_mm.toFixed(4),
        o ? o.mean_deg.toFixed(4) : "—", v.result.status, shift, f ? (f.explains ? "yes" : "no") : "—"];
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
  // Activating and rolling back change what every solve uses: asked first.
  if (b.dataset.confirm && !window.confirm(b.dataset.confirm)) return;
  b.disabled = true;
  try {
    await api("POST", b.dataset.post);
    location.reload();
  } catch (e) {
    show(e.message, false);
    b.disabled = false;
  }
});

// The key form stores the key in this tab only.
document.addEventListener("DOMContentLoaded", () => {
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

// Tools and work objects: save one (PUT by name), delete one.
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
  const url = form.dataset.url + encodeURIComponent(formValue(form, "name"));
  await api("PUT", url, JSON.stringify(body), "application/json");
  location.reload();
};

document.addEventListener("click", async (ev) => {
  const b = ev.target.closest("button[data-delete]");
  if (!b) return;
  ev.preventDefault();
  b.disabled = true;
  try {
    await api("DELETE", b.dataset.delete);
    location.reload();
  } catch (e) {
    show(e.message, false);
    b.disabled = false;
  }
});

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
  const r = (await api("POST", `/v1/robots/${robot}/programs/filter`, JSON.stringify(body), "application/json")).json();
  const rep = r.report;
  const summary = `${rep.filtered} targets filtered, ${rep.failed} failed, ${rep.skipped} skipped; ${rep.joint_motions.length} joint motions (model: ${r.version === null ? "nominal" : "v" + r.version} ${r.method})`;
  document.getElementById("filter-summary").textContent = summary;
  const links = document.getElementById("filter-downloads");
  links.textContent = "Download: ";
  for (const f of r.files) {
    const a = document.createElement("a");
    a.href = URL.createObjectURL(new Blob([f.content], { type: "text/plain" }));
    a.download = f.name;
    a.className = "filtered-file";
    a.textContent = f.name;
    links.append(a, " ");
  }
  const tbody = document.querySelector("#filter-report tbody");
  tbody.textContent = "";
  for (const t of rep.targets) {
    const tr = document.createElement("tr");
    tr.className = "target " + t.status;
    const cells = [t.motion.file, t.motion.line, `${t.motion.instruction} ${t.name}`, t.status, t.shift_mm === undefined ? "" : t.shift_mm.toFixed(3), t.configuration || "", t.reason || ""];
    for (const c of cells) {
      const td = document.createElement("td");
      td.textContent = String(c);
      tr.append(td);
    }
    tbody.append(tr);
  }
  document.getElementById("filter-result").hidden = false;
  show(summary, true);
};
