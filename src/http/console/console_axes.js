// robocal web console, the external axes of the filter, of the measurement
// plan and of the controller data (inlined after console.js, whose helpers it
// uses).

// A JSON text from a file input or a paste area, parsed; null when both are empty.
async function optionalJson(form, fileName, textName, what) {
  const text = await fileOrText(form, fileName, textName);
  if (!text) return null;
  try {
    return JSON.parse(text);
  } catch (e) {
    throw new Error(`${what} is not JSON: ` + e.message);
  }
}

// The filter's external axes into `body`: the controller's track, its
// positioner or turntable (as chosen) and `correct_axes` when ticked.
async function filterAxes(form, body) {
  const track = await optionalJson(form, "controller_track_file", "controller_track", "the controller's track");
  if (track) body.controller_track = track;
  const kind = formValue(form, "controller_plate_kind") || "positioner";
  const plate = await optionalJson(form, "controller_plate_file", "controller_plate", `the controller's ${kind}`);
  if (plate) body[`controller_${kind}`] = plate;
  if (form.elements["correct_axes"].checked) body.correct_axes = true;
}

// A filter report's external axes in one line: the axes named (a
// turntable's one axis, a positioner's two) and whether their values were
// kept or corrected; "" without axes.
function filterAxesText(rep) {
  const axes = [];
  if (rep.track_axis) axes.push(`track ${rep.track_axis}`);
  if (rep.positioner_axes) {
    const plate = rep.positioner_axes.length === 1 ? "turntable" : "positioner";
    axes.push(`${plate} ${rep.positioner_axes.join(", ")}`);
  }
  if (!axes.length) return "";
  const values = rep.axis_values === "corrected" ? "values corrected" : "values kept as programmed";
  return `External axes: ${axes.join("; ")}; ${values}`;
}

// A target's axis values as the table shows them: the track's [mm] and the
// positioner's [°], each "programmed → written" when corrected.
function targetAxesText(t) {
  const parts = [];
  if (t.track_mm !== undefined && t.track_mm !== null) {
    const written = t.track_written_mm === undefined || t.track_written_mm === null ? "" : ` → ${fmtMm(t.track_written_mm)}`;
    parts.push(`${fmtMm(t.track_mm)}${written} mm`);
  }
  if (t.positioner_deg) {
    const at = t.positioner_deg.map(fmtDeg).join(", ");
    const written = t.positioner_written_deg ? ` → ${t.positioner_written_deg.map(fmtDeg).join(", ")}` : "";
    parts.push(`${at}${written}°`);
  }
  return parts.join("; ");
}

// The filter's summary line of the axes, hidden without axes.
function showFilterAxes(rep) {
  const line = document.getElementById("filter-axes");
  line.textContent = filterAxesText(rep);
  line.hidden = !line.textContent;
}

// The plan form's fieldsets: the one of the chosen subject shows.
function showPlanWhat(form) {
  const what = formValue(form, "what") || "robot";
  for (const f of form.querySelectorAll("fieldset.plan-what")) f.hidden = f.dataset.what !== what;
}

document.addEventListener("change", (ev) => {
  if (ev.target.name === "what" && ev.target.form && ev.target.form.id === "measurement-plan") showPlanWhat(ev.target.form);
});
window.addEventListener("pageshow", () => {
  const form = document.getElementById("measurement-plan");
  if (form) showPlanWhat(form);
});

// A number input's value, undefined when empty.
function optionalNumber(form, name) {
  const v = formValue(form, name);
  return v === "" ? undefined : Number(v);
}

// `[min, max]` from two inputs, undefined when both are empty.
function optionalRange(form, prefix, what) {
  const lo = optionalNumber(form, `${prefix}_min`);
  const hi = optionalNumber(form, `${prefix}_max`);
  if (lo === undefined && hi === undefined) return undefined;
  if (lo === undefined || hi === undefined) throw new Error(`${what}: give both ends, or neither for the default`);
  return [lo, hi];
}

// A face plate's plan input (`what`: positioner or turntable): nominal,
// reflectors and the sweeps' fields given.
async function platePlan(form, what) {
  const nominal = await optionalJson(form, `${what}_file`, `${what}_json`, `the nominal ${what}`);
  if (!nominal) throw new Error(`choose the nominal ${what}'s JSON file or paste it`);
  const plate = { nominal, reflectors: reflectorLines(formValue(form, `${what}_reflectors`)) };
  if (!plate.reflectors.length) throw new Error(`give the reflectors' design positions, one x, y, z line each`);
  const sweeps = what === "positioner"
    ? { tilt_deg: ["tilt", "the tilt's sweep"], rotate_deg: ["rotate", "the rotate's sweep"] }
    : { travel_deg: ["travel", "the sweep"] };
  for (const [key, [prefix, label]] of Object.entries(sweeps)) {
    const range = optionalRange(form, prefix, label);
    if (range) plate[key] = range;
    const n = optionalNumber(form, `${prefix}_values`);
    if (n !== undefined) plate[prefix === "travel" ? "values" : `${prefix}_values`] = n;
  }
  const columns = what === "positioner" ? ["tilt_column", "rotate_column"] : ["turntable_column"];
  for (const c of columns) {
    const v = formValue(form, c);
    if (v) plate[c === "turntable_column" ? "column" : c] = v;
  }
  return plate;
}

// The plan's body for a face plate: its plan, the noise and the program.
async function plateBody(form, what) {
  const body = { [what]: await platePlan(form, what), noise_mm: Number(formValue(form, "noise_mm")) };
  const language = formValue(form, "language");
  if (language) {
    body.language = language;
    const name = formValue(form, "name");
    if (name) body.name = name;
  }
  return body;
}

// A plan's answer tables hidden, but `keep`'s.
function planTables(keep) {
  for (const id of ["plan-params", "plan-stations", "plan-sigma", "plan-reflector-sigma"]) {
    document.getElementById(id).hidden = !keep.includes(id);
  }
}

// A face plate's plan: σ per axis and per reflector, the CSV and program.
async function plannedPlate(form, what) {
  const body = await plateBody(form, what);
  const r = (await sendJson("POST", `/v1/robots/${form.dataset.robot}/measurement-plans`, body)).json();
  const summary = `${r.poses} poses of the ${what}'s ${what === "positioner" ? "sweeps" : "sweep"} at ${fmtMm(r.noise_mm)} mm tracker noise`;
  document.getElementById("plan-summary").textContent = summary;
  planDownloads("plan-downloads", `plan-${what}.csv`, r.joints_csv, r.program, "plan-file");
  const tbody = document.querySelector("#plan-sigma tbody");
  tbody.textContent = "";
  for (const s of r.sigma) {
    appendRow(tbody, [s.axis, fmtDeg(s.direction_deg), fmtMm(s.point_mm), fmtDeg(s.zero_offset_deg), Number(s.scale).toExponential(2)], "plan-sigma");
  }
  document.getElementById("plan-reflector-sigma").textContent =
    `σ of the reflectors' positions [mm]: ${r.reflector_sigma_mm.map(fmtMm).join(", ")}`;
  planTables(["plan-sigma", "plan-reflector-sigma"]);
  document.getElementById("plan-result").hidden = false;
  show(summary, true);
}

// A plan over a track: the robot poses' fields with the track, its stations,
// travel and column; the stations as a table.
async function plannedOverTrack(form, robotBody) {
  const track = await optionalJson(form, "track_file", "track_json", "the track");
  if (!track) throw new Error("choose the track's JSON file or paste it");
  const body = { ...robotBody, track };
  const stations = optionalNumber(form, "stations");
  if (stations !== undefined) body.stations = stations;
  const travel = optionalRange(form, "track_travel", "the travel");
  if (travel) body.travel_mm = travel;
  const column = formValue(form, "track_column");
  if (column) body.column = column;
  const r = (await sendJson("POST", `/v1/robots/${form.dataset.robot}/measurement-plans`, body)).json();
  const summary = `${r.poses} poses over ${r.stations.length} stations of the track (${r.column})`;
  document.getElementById("plan-summary").textContent = summary;
  planDownloads("plan-downloads", "plan-track.csv", r.joints_csv, r.program, "plan-file");
  const tbody = document.querySelector("#plan-stations tbody");
  tbody.textContent = "";
  for (const s of r.stations) {
    appendRow(tbody, [fmtMm(s.value_mm), s.points.length, s.in_sight, fmtMm(s.position_sigma_mm), s.angle_sigma_arcsec.map((a) => fixed(a, 2)).join(", ")], "plan-station");
  }
  planTables(["plan-stations"]);
  document.getElementById("plan-result").hidden = false;
  show(summary, true);
}

// The measurement plan by its subject: robot poses (console.js's handler),
// over a track, a positioner's or a turntable's sweeps.
{
  const robotPlan = handlers["measurement-plan"];
  handlers["measurement-plan"] = async function (form) {
    const what = formValue(form, "what") || "robot";
    if (what === "positioner" || what === "turntable") return plannedPlate(form, what);
    if (what === "track") return robotPlan(form, (body) => plannedOverTrack(form, body));
    planTables(["plan-params"]);
    return robotPlan(form);
  };
}

// A cell export's external axes (`kinematics`, with `axes` chosen): the
// calibrated terms the controller cannot hold as a table (or that every one
// is), and the positioner, track or turntable it then computes as JSON
// downloads: `held.json`, or beside a track `held-track.json` and
// `held-positioner.json` or `held-turntable.json`. Answers the message's
// words for the axes ("" without them).
function showExportKinematics(k) {
  document.getElementById("export-kinematics").hidden = !k;
  if (!k) return "";
  const tbody = document.querySelector("#export-not-held tbody");
  tbody.textContent = "";
  for (const n of k.not_held) {
    const value = fixed(n.value, { mm: 3, arcsec: 2 }[n.unit] ?? 6) + (n.unit ? " " + n.unit : "");
    appendRow(tbody, [n.term, value, fmtMm(n.miss_mm)], "not-held");
  }
  document.getElementById("export-not-held").hidden = !k.not_held.length;
  document.getElementById("export-all-held").hidden = k.not_held.length > 0;
  const beside = k.kind.startsWith("track_and_") ? k.kind.slice("track_and_".length) : null;
  const files = beside ? [["track", k.held.track], [beside, k.held[beside]]].map(([kind, held]) => [`held-${kind}.json`, held]) : [["held.json", k.held]];
  const links = document.getElementById("export-held-downloads");
  links.textContent = "What the controller then computes: ";
  for (const [name, held] of files) downloadLink(links, name, JSON.stringify(held, null, 2), "held-file");
  const n = k.not_held.length;
  const missed = n ? `${n} term${n === 1 ? "" : "s"} not held` : "every calibrated term held";
  return ` with the ${k.kind.replaceAll("_", " ")} (${missed})`;
}
