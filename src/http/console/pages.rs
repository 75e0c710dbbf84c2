//! The console's pages as maud templates (every interpolated value is
//! HTML-escaped by maud).

use super::fields::model_select;
use super::format::{kg, mm};
use crate::calibrate::identify::progress::time_left;
use crate::calibrate::identify::Method;
use crate::http::calibrations::DEFAULT_METHODS;
use crate::measure::convention::MeasuredOrientation;
use crate::measure::external::ExternalAxis;
use crate::measure::SetRole;
use crate::model::presets::PRESETS;
use crate::records::CellItemRow;
use crate::records::RobotRow;
use crate::records::SetRow;
use crate::records::VersionRow;
use crate::records::{CalibrationRow, JobStatus, ProgressDetail};
use crate::report::page_head;
use crate::service::check_reads::RobotWithCheck;
use crate::service::checks::{shift_of, status_of};
use maud::{html, Markup, PreEscaped, DOCTYPE};

/// The page's script: `console.js` and, after it, `console_axes.js` (the
/// filter's and the plan's external axes), inlined as one.
const SCRIPT: &str = concat!(include_str!("console.js"), include_str!("console_axes.js"));
const STYLE_SHEET: &str = include_str!("console.css");

/// The console's one style sheet: `console.css` and the statuses' rules
/// (`status::status_css`).
fn style() -> &'static str {
    static STYLE: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    STYLE.get_or_init(|| format!("{STYLE_SHEET}{}", super::status::status_css()))
}

/// The `Content-Security-Policy` of every console page: everything from this
/// origin only (the pages `fetch` the JSON API), no plug-ins, no framing, no
/// `<base>`; the one inline script and the one inline style sheet are allowed
/// by their SHA-256 (CSP Level 2 hash sources), nothing else inline. The
/// download links are `blob:` URLs the page makes itself; `connect-src`
/// allows reading them back (the browser check does).
pub(super) fn content_security_policy() -> &'static str {
    static CSP: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    CSP.get_or_init(|| {
        format!(
            "default-src 'self'; script-src '{}'; style-src '{}'; connect-src 'self' blob:; \
             img-src 'self'; object-src 'none'; base-uri 'none'; form-action 'self'; \
             frame-ancestors 'none'",
            csp_hash(SCRIPT),
            csp_hash(style())
        )
    })
}

/// `sha256-<base64 of the SHA-256 of text>`.
fn csp_hash(text: &str) -> String {
    use base64::Engine;
    use sha2::{Digest, Sha256};
    let digest = Sha256::digest(text.as_bytes());
    format!(
        "sha256-{}",
        base64::engine::general_purpose::STANDARD.encode(digest)
    )
}

/// Everything the robot page shows.
pub(super) struct RobotView {
    pub robot: RobotRow,
    pub sets: Vec<SetRow>,
    pub calibrations: Vec<CalibrationRow>,
    pub versions: Vec<VersionRow>,
    pub tools: Vec<CellItemRow>,
    pub work_objects: Vec<CellItemRow>,
    /// The stored track, positioner and turntable, if any.
    pub track: Option<crate::records::TrackRow>,
    pub positioner: Option<crate::records::PositionerRow>,
    pub turntable: Option<crate::records::TurntableRow>,
    pub keys: bool,
    /// The latest check's status, the thresholds and the history (oldest first).
    pub status: Option<robocal_core::check::CheckStatus>,
    pub thresholds: robocal_core::check::CheckThresholds,
    pub checks: Vec<crate::records::CheckRow>,
}

pub(super) fn layout(title: &str, keys: bool, body: Markup) -> Markup {
    html! {
        (DOCTYPE)
        html lang="en" {
            (page_head(&format!("{title} — robocal"), style()))
            body {
                header {
                    a.brand href="/ui" { "robocal" }
                    span.sub { "console" }
                    @if keys {
                        label.key {
                            "API key "
                            input #api-key type="password" autocomplete="off"
                                placeholder="needed for changes and solves";
                        }
                    }
                }
                main {
                    div #message .msg hidden {}
                    (body)
                }
                footer {
                    "REST API: " a href="/openapi.yaml" { "/openapi.yaml" }
                }
                script { (PreEscaped(SCRIPT)) }
            }
        }
    }
}

/// The start page: robots (each with its latest check's status) and a form
/// to add one.
pub(super) fn robots(robots: &[RobotWithCheck], total: i64, keys: bool) -> Markup {
    layout(
        "Robots",
        keys,
        html! {
            h1 { "Robots" }
            @if robots.is_empty() {
                p.empty { "No robot yet: add one below." }
            } @else {
                table #robots {
                    thead { tr { th { "Id" } th { "Name" } th { "Model" } th { "Axes" } th { "Active version" } th { "Latest check" } th { "Created" } } }
                    tbody {
                        @for RobotWithCheck { robot: r, latest_check: last } in robots {
                            tr {
                                td { (r.id) }
                                td { a href={ "/ui/robots/" (r.id) } { (r.name) } }
                                td { (r.preset.as_deref().unwrap_or("custom model")) }
                                td { (r.dof) }
                                td { @match r.active_version { Some(v) => { "v" (v) }, None => { "nominal" } } }
                                td.latest-check {
                                    @match last.as_ref().and_then(|c| status_of(c).map(|s| (c, s))) {
                                        Some((c, s)) => {
                                            a href={ "/ui/robots/" (r.id) "/checks/" (c.id) } { (super::status::status_tag(s, shift_of(c).as_ref())) }
                                            " " span.note { (mm(c.mean_mm)) " mm · " time datetime=(c.created_at) { (c.created_at) } }
                                        }
                                        None => { span.note { "no check yet" } }
                                    }
                                }
                                td { time datetime=(r.created_at) { (r.created_at) } }
                            }
                        }
                    }
                }
                @if total > robots.len() as i64 {
                    p.note { "Showing " (robots.len()) " of " (total) " robots." }
                }
            }
            section {
                h2 { "Add a robot" }
                form #create-robot data-action="create-robot" {
                    label { "Name " input name="name" placeholder="e.g. cell 3 robot"; }
                    label { "Preset "
                        select name="preset" {
                            @for p in PRESETS { option value=(p) { (p) } }
                        }
                    }
                    label.wide { "or a model description (JSON, mm/deg; replaces the preset) "
                        textarea name="model" rows="4" placeholder="{\"name\": ..., \"joints\": [...]}" {}
                    }
                    button type="submit" { "Create robot" }
                }
            }
        },
    )
}

fn job_active(s: JobStatus) -> bool {
    s.is_active()
}

fn validation_mean(v: &VersionRow) -> Option<f64> {
    v.stats.0.get("validation")?.get("mean_mm")?.as_f64()
}

/// `re-registered from v2 on set 4 (2.104 → 0.215 mm)` for a version a
/// re-registration made.
fn reregistered_note(v: &VersionRow) -> Markup {
    let r = &v.stats.0["reregistered"];
    let (Some(from), Some(set)) = (r["from_version"].as_i64(), r["set_id"].as_i64()) else {
        return html! {};
    };
    let mean = |k: &str| {
        r["report"][k]["mean_mm"]
            .as_f64()
            .map_or_else(|| "—".into(), mm)
    };
    html! {
        br;
        span.note.reregistered { "re-registered from v" (from) " on set " (set) " (" (mean("before")) " → " (mean("after")) " mm)" }
    }
}

/// One robot: sets, calibrations, versions.
pub(super) fn robot(v: &RobotView) -> Markup {
    let r = &v.robot;
    let id = r.id;
    layout(
        &r.name,
        v.keys,
        html! {
            (robot_heading(r))
            (sets_section(id, &v.sets))
            (calibrations_section(id, &v.calibrations, &v.sets))
            (versions_section(id, &v.versions))
            (solve_section(id, &v.versions))
            (super::check_pages::checks_section(&super::check_pages::ChecksView {
                robot: id,
                status: v.status,
                thresholds: &v.thresholds,
                checks: &v.checks,
                sets: &v.sets,
                versions: &v.versions,
            }))
            (super::cell_pages::cell_section(id, &v.tools, &v.work_objects))
            (super::axes_pages::axes_section(&super::axes_pages::AxesView {
                robot: r,
                track: v.track.as_ref(),
                positioner: v.positioner.as_ref(),
                turntable: v.turntable.as_ref(),
                versions: &v.versions,
                tools: &v.tools,
            }))
            (super::cell_pages::predict_section(id, &v.versions, &v.tools, &v.work_objects))
            (super::cell_pages::filter_section(id, &v.versions))
            (super::plan_pages::plan_sections(id))
        },
    )
}

/// The robot page's breadcrumbs, title and one-line summary.
fn robot_heading(r: &RobotRow) -> Markup {
    html! {
        p.crumbs { a href="/ui" { "Robots" } " / " (r.name) }
        h1 { (r.name) }
        p.note {
            "Robot " (r.id) " · " (r.preset.as_deref().unwrap_or("custom model")) " · " (r.dof) " axes · "
            @match r.active_version { Some(a) => { "active model version " (a) }, None => { "no calibrated version yet (solves use the nominal model)" } }
            " "
            button.small.danger #delete-robot data-delete={ "/v1/robots/" (r.id) } data-then="/ui"
                data-confirm={ "Delete robot " (r.id) " (" (r.name) ") with all its measurement sets, calibrations, versions, checks, tools and work objects? This cannot be undone." } { "Delete robot" }
        }
    }
}

/// The measurement sets: their table and the upload form.
fn sets_section(id: i64, sets: &[SetRow]) -> Markup {
    html! {
        section #sets {
            h2 { "Measurement sets" }
            @if sets.is_empty() {
                p.empty { "No measurements yet: upload a laser-tracker CSV below." }
            } @else {
                table {
                    thead { tr { th { "Id" } th { "Name" } th { "Role" } th { "Session" } th { "Track value" } th { "Poses" } th { "Payload [kg]" } th { "Uploaded" } th {} } }
                    tbody {
                        @for s in sets {
                            tr {
                                td { (s.id) } td { (s.name) } td { (SetRole::from(s.role).as_str()) } td { (s.session) }
                                td.station {
                                    @match (&s.axis_column, s.axis_value) {
                                        (Some(c), Some(v)) => { (c) " = " (v) " mm" }
                                        _ => { "—" }
                                    }
                                }
                                td { (s.row_count) }
                                td { @if let Some(p) = s.payload_kg { (kg(p)) } @else { "—" } }
                                td { time datetime=(s.created_at) { (s.created_at) } }
                                td {
                                    a href={ "/v1/robots/" (id) "/measurement-sets/" (s.id) "/original" } { "original" } " "
                                    button.small.danger data-delete={ "/v1/robots/" (id) "/measurement-sets/" (s.id) }
                                        data-confirm={ "Delete set " (s.id) " (" (s.name) ")? A set a model version or a pending calibration uses is kept." } { "Delete" }
                                }
                            }
                        }
                    }
                }
            }
            (upload_form(id))
        }
    }
}

/// The form that uploads a measurement CSV with its role, units and conventions.
fn upload_form(id: i64) -> Markup {
    html! {
        form #upload data-action="upload" data-robot=(id) {
            label.wide { "CSV file " input type="file" name="file" accept=".csv,text/csv"; }
            label { "Role "
                select name="role" {
                    @for role in SetRole::ALL {
                        option value=(role.as_str()) { (role.as_str()) }
                    }
                }
            }
            label { "Name " input name="name"; }
            label title="How the file's orientation columns (if any) are to be read" { "Orientation "
                select name="orientation" {
                    @for c in MeasuredOrientation::ALL {
                        option value=(c.name()) title=(c.meaning()) selected[c == MeasuredOrientation::default()] { (c.name()) " (" (c.columns().join(", ")) ")" }
                    }
                }
            }
            label { "Tracker session " input name="session" placeholder="default"; }
            label title="A robot on a linear track measured at several track values: the file is stored as one set per value (station), each its own tracker session, in mm and degrees" { "Track column "
                select name="track_column" {
                    option value="" { "none" }
                    @for a in ExternalAxis::ALL {
                        option value=(a.column()) { (a.column()) }
                    }
                }
            }
            label { "Payload [kg] " input name="payload_kg" type="number" step="any" min="0"; }
            label { "Lengths "
                select name="length_unit" { option value="mm" { "mm" } option value="m" { "m" } }
            }
            label { "Angles "
                select name="angle_unit" { option value="deg" { "deg" } option value="rad" { "rad" } }
            }
            label { "Decimal separator "
                select name="decimal" {
                    option value="" { "detect" }
                    option value="point" { "point (1500.25)" }
                    option value="comma" { "comma (1500,25; fields split by ;)" }
                }
            }
            label { "dif columns "
                select name="dif_sign" {
                    option value="plus" { "measured = target + dif" }
                    option value="minus" { "measured = target − dif" }
                }
            }
            button type="submit" { "Upload" }
        }
    }
}

/// The calibrations: their table (newest first) and the form that starts one.
fn calibrations_section(id: i64, calibrations: &[CalibrationRow], sets: &[SetRow]) -> Markup {
    html! {
        section #calibrations {
            h2 { "Calibrations" }
            @if calibrations.is_empty() {
                p.empty { "No calibration yet." }
            } @else {
                table {
                    thead { tr { th { "Id" } th { "Methods" } th { "Status" } th { "Phase" } th { "Progress" } th { "Best" } th { "Created" } th {} } }
                    tbody {
                        @for c in calibrations.iter().rev() {
                            (calibration_row(id, c))
                        }
                    }
                }
            }
            (calibrate_form(id, sets))
        }
    }
}

/// The phase with the candidate and fold it is on, as console.js's
/// `phaseText` writes it: `auto · skcm-nn · fold 3/9`.
fn phase_text(phase: Option<&str>, d: Option<&ProgressDetail>) -> String {
    let mut t = phase.unwrap_or("").to_string();
    if let Some(c) = d.and_then(|d| d.candidate.as_deref()) {
        t += &format!(" · {c}");
    }
    if let Some(f) = d.and_then(|d| d.fold) {
        t += &format!(" · fold {}/{}", f.index, f.of);
    }
    t
}

/// The percentage with the time left, as console.js's `percentText`
/// writes it: `64 % · 1 min 20 s left`.
fn percent_text(percent: f64, d: Option<&ProgressDetail>) -> String {
    match d.and_then(|d| d.eta_s) {
        Some(eta) => format!("{percent:.0} % · {} left", time_left(eta)),
        None => format!("{percent:.0} %"),
    }
}

/// One calibration's table row: status, progress, best result and actions.
fn calibration_row(id: i64, c: &CalibrationRow) -> Markup {
    html! {
        @let url = format!("/v1/robots/{id}/calibrations/{}", c.id);
        tr data-job=(url) data-active=(job_active(c.status)) {
            td { (c.id) }
            td { (c.methods.0.join(", ")) }
            td.status { (c.status.as_str()) }
            @let d = c.progress_detail.as_ref().map(|d| &d.0);
            td.phase { (phase_text(c.phase.as_deref(), d)) }
            td { progress max="100" value=(c.percent) {} " " span.percent { (percent_text(c.percent, d)) } }
            td {
                (c.best_method.as_deref().unwrap_or("—"))
                @if let Some(sum) = &c.summary {
                    br;
                    span.note { (mm(sum.0.mean_mm)) " mm mean on " (sum.0.judged_on) " (nominal " (mm(sum.0.nominal_mean_mm)) ")" }
                    @if !sum.0.warnings.is_empty() || !sum.0.failed_methods.is_empty() {
                        br;
                        span.bad title=(sum.0.warnings.iter().chain(&sum.0.failed_methods).cloned().collect::<Vec<_>>().join("\n")) {
                            (sum.0.warnings.len()) " warnings, " (sum.0.failed_methods.len()) " failed methods"
                        }
                    }
                }
            }
            td { time datetime=(c.created_at) { (c.created_at) } }
            td {
                @if c.status == JobStatus::Succeeded {
                    a href={ (url) "/report" } { "report" } " · "
                    a href={ (url) "/result" } { "result" }
                } @else if job_active(c.status) {
                    button.small.cancel data-post={ (url) "/cancel" }
                        data-confirm={ "Cancel calibration " (c.id) "? Its work so far is dropped." } { "Cancel" }
                } @else if let Some(e) = &c.error {
                    span.bad { (e) }
                }
            }
        }
    }
}

/// The form that starts a calibration: methods, sets by role, seed, payload.
fn calibrate_form(id: i64, sets: &[SetRow]) -> Markup {
    html! {
        form #calibrate data-action="calibrate" data-robot=(id) {
            fieldset {
                legend { "Methods" }
                @for m in Method::ALL {
                    label.check {
                        input type="checkbox" name="method" value=(m.name())
                            checked[DEFAULT_METHODS.contains(&m)];
                        " " (m.name())
                    }
                }
            }
            @for (role, legend) in [(SetRole::Identification, "Identification sets"), (SetRole::Validation, "Validation sets"), (SetRole::Training, "Training sets")] {
                @let of_role: Vec<&SetRow> = sets.iter().filter(|s| SetRole::from(s.role) == role).collect();
                @if !of_role.is_empty() {
                    fieldset.sets data-role=(role.as_str()) {
                        legend { (legend) " (none ticked: every " (role.as_str()) " set)" }
                        @for s in of_role {
                            label.check { input type="checkbox" name={ (role.as_str()) "_set" } value=(s.id); " " (s.id) " " (s.name) }
                        }
                    }
                }
            }
            label { "Seed " input name="seed" type="number" min="0" step="1" placeholder="1"; }
            label { "Payload [kg] " input name="payload_kg" type="number" step="any" min="0" placeholder="model's"; }
            button type="submit" { "Start calibration" }
        }
    }
}

/// The model versions (newest first), with activation and roll-back.
fn versions_section(id: i64, versions: &[VersionRow]) -> Markup {
    html! {
        section #versions {
            h2 { "Model versions" }
            @if versions.is_empty() {
                p.empty { "No model version yet: a successful calibration creates one per method." }
            } @else {
                table {
                    thead { tr { th { "Version" } th { "Method" } th { "Calibration" } th { "Validation mean [mm]" } th { "Created" } th {} } }
                    tbody {
                        @for ver in versions.iter().rev() {
                            tr.active[ver.active] {
                                td { "v" (ver.version) @if ver.active { " " span.tag { "active" } } }
                                td { (ver.method) (reregistered_note(ver)) }
                                td { @if let Some(c) = ver.calibration_id { (c) } @else { "—" } }
                                td { @if let Some(m) = validation_mean(ver) { (mm(m)) } @else { "—" } }
                                td { time datetime=(ver.created_at) { (ver.created_at) } }
                                td {
                                    a href={ "/v1/robots/" (id) "/versions/" (ver.version) "/model.json" } { "model.json" }
                                    @if !ver.active {
                                        " " button.small data-post={ "/v1/robots/" (id) "/versions/" (ver.version) "/activate" }
                                            data-confirm={ "Activate v" (ver.version) " (" (ver.method) ")? Solves and filters will use it from now on." } { "Activate" }
                                    }
                                }
                            }
                        }
                    }
                }
                p { button.small #rollback data-post={ "/v1/robots/" (id) "/versions/rollback" }
                    data-confirm="Roll back to the previously active version? Solves and filters will use it from now on." { "Roll back to the previous active version" } }
            }
        }
    }
}

/// The form that solves a targets CSV, and where its answer appears.
fn solve_section(id: i64, versions: &[VersionRow]) -> Markup {
    html! {
        section #solve-section {
            h2 { "Solve targets" }
            p.note { "A targets CSV (id, x, y, z in mm and the orientation columns of one convention, e.g. a,b,c) in, joint commands and false targets out, as CSV." }
            p.note #solve-axes-note { "The CSV may carry the external axes' values per row, as the controller shows them, solved through the robot's stored track and positioner: an e1 column alone is the track's value [mm]; e1, e2 the positioner's tilt and rotate [°], the targets then on its face plate (keep the first Frame entry); e1, e2, e3 the track's value [mm] and, beside it, the positioner's tilt and rotate [°]. On the turntable (ticked): an e1 column is the stored turntable's value [°], or e2 beside the track's e1." }
            form #solve data-action="solve" data-robot=(id) {
                label.wide { "Targets CSV " input type="file" name="file" accept=".csv,text/csv"; }
                label.wide { "or paste it " textarea name="csv" rows="3" placeholder="id,x,y,z,a,b,c" {} }
                (model_select(versions))
                label { "Frame "
                    // No frame sent: the cell's, or the positioner's face plate with its columns.
                    select name="frame" { option value="" { "cell (tracker); the positioner's face plate with its columns" } option value="base" { "robot base" } }
                }
                label { "Payload [kg] " input name="payload_kg" type="number" step="any" min="0"; }
                label { "Branch " input name="branch" placeholder="e.g. front,up,noflip"; }
                label { input type="checkbox" name="position_only" value="true"; " position only" }
                label title="The targets are on the robot's stored turntable, in its face plate frame: an e1 column is its value [°] (e2 beside a track's e1)" {
                    input type="checkbox" name="turntable" value="true"; " on the turntable" }
                button type="submit" { "Solve" }
            }
            div #solve-result hidden {
                p #solve-summary {}
                p { a #solve-download download="solution.csv" href="#" { "Download the CSV" } }
                pre #solve-csv {}
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibrate::identify::Fold;

    /// A running job's row names the phase, the candidate and the fold, and
    /// the percentage with the time left, as console.js redraws them.
    #[test]
    fn a_running_jobs_row_names_candidate_fold_and_time_left() {
        let d = ProgressDetail {
            candidate: Some("skcm-nn".into()),
            fold: Some(Fold { index: 3, of: 9 }),
            rms_mm: Some(0.1234),
            eta_s: Some(80.4),
        };
        assert_eq!(
            phase_text(Some("auto"), Some(&d)),
            "auto · skcm-nn · fold 3/9"
        );
        assert_eq!(percent_text(31.4, Some(&d)), "31 % · 1 min 20 s left");
        // Before the methods: the phase alone, no time left.
        let none = ProgressDetail::default();
        assert_eq!(
            phase_text(Some("registration"), Some(&none)),
            "registration"
        );
        assert_eq!(percent_text(0.0, Some(&none)), "0 %");
        assert_eq!(phase_text(None, None), "");
    }
}
