// robocal web console: the page's forms call the REST API (/v1) with fetch.
// The API key (when the service has keys) is kept in this tab's
// sessionStorage and sent as `Authorization: Bearer <key>` on writes.
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
    for (const k of ["name", "role", "session", "payload_kg", "length_unit", "angle_unit", "decimal", "dif_sign"]) {
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
    await api("POST", `/v1/robots/${robot}/calibrations`, JSON.stringify(body), "application/json");
    location.reload();
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
        row.querySelector(".phase").textContent = j.progress.phase || "";
        const bar = row.querySelector("progress");
        bar.value = j.progress.percent;
        row.querySelector(".percent").textContent = j.progress.percent.toFixed(0) + " %";
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
