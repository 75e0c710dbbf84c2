//! The console's "Is it still accurate?" section of a robot page: the status
//! by the latest check, a trend plot of every check's mean error against
//! time (thresholds drawn, version changes marked), the history, a form to
//! run a check, and the comparison of versions on one set. Every status
//! (`core::check::CheckStatus`) has its colour and its meaning (the legend);
//! a `shifted` check shows the shift's size wherever it is shown.

use crate::records::CheckRow;
use crate::records::SetRow;
use crate::records::VersionRow;
use crate::service::checks::{shift_of, status_of};
use maud::{html, Markup};
use robocal_core::check::{CheckStatus, CheckThresholds, ShiftSize};

/// Everything the section shows.
pub struct ChecksView<'a> {
    pub robot: i64,
    pub status: Option<CheckStatus>,
    pub thresholds: &'a CheckThresholds,
    /// Oldest first.
    pub checks: &'a [CheckRow],
    pub sets: &'a [SetRow],
    pub versions: &'a [VersionRow],
}

/// The colour a status is drawn in: only `ok` is green.
pub fn status_colour(s: CheckStatus) -> &'static str {
    match s {
        CheckStatus::Ok => "#1e7a3c",
        CheckStatus::Degraded => "#b07d00",
        CheckStatus::Recalibrate => "#b3261e",
        CheckStatus::Shifted => "#7a3fb3",
    }
}

/// The colour of a stored check's status (grey for a name not in the table).
fn row_colour(c: &CheckRow) -> &'static str {
    status_of(c).map_or("#5b6475", status_colour)
}

/// The style rules of the statuses (part of the console's one style sheet,
/// whose hash the page's `Content-Security-Policy` names): a tag's
/// background, a table cell's text.
pub fn status_css() -> String {
    CheckStatus::ALL
        .iter()
        .map(|s| {
            let (name, colour) = (s.name(), status_colour(*s));
            format!(".status-tag.{name} {{ background: {colour}; }} .status-{name} {{ color: {colour}; font-weight: 600; }}\n")
        })
        .collect()
}

/// `13.127 mm, 0.2636°`.
fn shift_text(s: &ShiftSize) -> String {
    format!("{:.3} mm, {:.4}°", s.translation_mm, s.rotation_deg)
}

/// A status as a coloured tag, with the shift's size when shifted.
fn status_tag(s: CheckStatus, shift: Option<&ShiftSize>) -> Markup {
    html! {
        span class={ "status-tag " (s.name()) } title=(s.meaning()) {
            (s.name())
            @if let Some(f) = shift { " " (shift_text(f)) }
        }
    }
}

/// Plot size [px].
const W: f64 = 640.0;
const H: f64 = 200.0;
const PAD: f64 = 36.0;

/// The trend of the checks' mean errors as inline SVG: one point per check in
/// order (x: check number, labelled by date), a dashed line per threshold,
/// and a vertical mark where the version scored changes.
fn trend(checks: &[CheckRow], t: &CheckThresholds) -> Markup {
    let top = checks
        .iter()
        .map(|c| c.mean_mm)
        .filter(|m| m.is_finite())
        .fold(t.recalibrate_mm * 1.25, f64::max);
    let n = checks.len().max(2) as f64;
    let x = |i: usize| PAD + (W - 2.0 * PAD) * i as f64 / (n - 1.0);
    let y = |mm: f64| H - PAD - (H - 2.0 * PAD) * (mm.clamp(0.0, top) / top);
    let points: String = checks
        .iter()
        .enumerate()
        .map(|(i, c)| format!("{:.1},{:.1}", x(i), y(c.mean_mm)))
        .collect::<Vec<_>>()
        .join(" ");
    html! {
        svg #check-trend width=(W) height=(H) viewBox={ "0 0 " (W) " " (H) } role="img"
            aria-label="mean position error of every check against time" {
            line x1=(PAD) y1=(H - PAD) x2=(W - PAD) y2=(H - PAD) stroke="#5b6475" {}
            line x1=(PAD) y1=(PAD) x2=(PAD) y2=(H - PAD) stroke="#5b6475" {}
            text x="4" y=(PAD - 8.0) font-size="11" fill="#5b6475" { "mean [mm]" }
            text x="4" y=(H - PAD + 4.0) font-size="11" fill="#5b6475" { "0" }
            @for (mm, name, colour) in [(t.degraded_mm, "degraded", "#b07d00"), (t.recalibrate_mm, "recalibrate", "#b3261e")] {
                line x1=(PAD) y1=(y(mm)) x2=(W - PAD) y2=(y(mm)) stroke=(colour) stroke-dasharray="5 4" {
                    title { (name) }
                }
                text x=(W - PAD + 2.0) y=(y(mm) + 4.0) font-size="10" fill=(colour) { (format!("{mm}")) }
            }
            @for (i, c) in checks.iter().enumerate() {
                @if i > 0 && checks[i - 1].version != c.version {
                    line.version-change x1=(x(i) - 0.5 * (x(i) - x(i - 1))) y1=(PAD) x2=(x(i) - 0.5 * (x(i) - x(i - 1))) y2=(H - PAD)
                        stroke="#1f5fbf" stroke-dasharray="2 3" {}
                    text x=(x(i) - 0.5 * (x(i) - x(i - 1)) + 2.0) y=(PAD - 4.0) font-size="10" fill="#1f5fbf" { "v" (c.version) }
                }
            }
            @if checks.len() > 1 {
                polyline points=(points) fill="none" stroke="#1d2330" stroke-width="1.5" {}
            }
            @for (i, c) in checks.iter().enumerate() {
                circle.check-point cx=(format!("{:.1}", x(i))) cy=(format!("{:.1}", y(c.mean_mm))) r="4"
                    fill=(row_colour(c)) data-status=(c.status) {
                    title {
                        (c.created_at) ": " (format!("{:.4}", c.mean_mm)) " mm, " (c.status)
                        @if let Some(f) = shift_of(c) { " by a frame shift of " (shift_text(&f)) }
                        ", v" (c.version)
                    }
                }
            }
        }
    }
}

fn set_options(sets: &[SetRow]) -> Markup {
    html! {
        @for s in sets.iter().rev() {
            option value=(s.id) { (s.id) " " (s.name) " (" (s.row_count) " poses)" }
        }
    }
}

/// The section.
pub fn checks_section(v: &ChecksView) -> Markup {
    let id = v.robot;
    html! {
        section #checks-section {
            h2 { "Is it still accurate?" }
            p #check-status {
                "Status: "
                @match v.status {
                    Some(s) => {
                        (status_tag(s, v.checks.last().and_then(shift_of).as_ref()))
                        " " span.note { (s.action()) }
                    }
                    None => { span.note { "no check yet" } }
                }
                span.note { " · degraded above " (v.thresholds.degraded_mm) " mm, recalibrate above " (v.thresholds.recalibrate_mm) " mm mean" }
            }
            dl #check-statuses {
                @for s in CheckStatus::ALL {
                    dt { span class={ "status-tag " (s.name()) } { (s.name()) } }
                    dd { (s.meaning()) "; " (s.action()) }
                }
            }
            @if v.checks.is_empty() {
                p.empty { "No check yet: score a fresh measurement set against a version below." }
            } @else {
                (trend(v.checks, v.thresholds))
                table #checks {
                    thead { tr { th { "Check" } th { "Time" } th { "Version" } th { "Set" } th { "Mean [mm]" } th { "Status" } th { "Frame shift" } th { "Temperature [°C]" } } }
                    tbody {
                        @for c in v.checks.iter().rev() {
                            tr {
                                td { (c.id) }
                                td { time datetime=(c.created_at) { (c.created_at) } }
                                td { "v" (c.version) }
                                td { @if let Some(s) = c.set_id { (s) } @else { "—" } }
                                td { (format!("{:.4}", c.mean_mm)) }
                                td class={ "check-status status-" (c.status) } { (c.status) }
                                td.check-shift { @if let Some(f) = shift_of(c) { (shift_text(&f)) } @else { "—" } }
                                td { @if let Some(t) = c.temperature_c { (t) } @else { "—" } }
                            }
                        }
                    }
                }
            }
            @if v.sets.is_empty() || v.versions.is_empty() {
                p.note { "A check needs a calibrated version and a measurement set." }
            } @else {
                form #run-check data-action="check" data-robot=(id) {
                    label { "Set " select name="set_id" { (set_options(v.sets)) } }
                    label { "Version "
                        select name="version" {
                            option value="" { "active" }
                            @for ver in v.versions.iter().rev() { option value=(ver.version) { "v" (ver.version) " " (ver.method) } }
                        }
                    }
                    label { "Temperature [°C] " input name="temperature_c" type="number" step="any"; }
                    button type="submit" { "Run check" }
                }
                h3 { "Compare versions on one set" }
                form #compare data-action="compare" data-robot=(id) {
                    label { "Set " select name="set_id" { (set_options(v.sets)) } }
                    fieldset {
                        legend { "Versions" }
                        @for ver in v.versions.iter().rev() {
                            label.check { input type="checkbox" name="version" value=(ver.version) checked; " v" (ver.version) " " (ver.method) }
                        }
                    }
                    button type="submit" { "Compare" }
                }
                table #compare-result hidden {
                    thead { tr { th { "Version" } th { "Method" } th { "Mean [mm]" } th { "p95 [mm]" } th { "Max [mm]" } th { "Orientation mean [°]" } th { "Status" } th { "Frame shift [mm, °]" } th { "Explains" } } }
                    tbody {}
                }
            }
        }
    }
}
