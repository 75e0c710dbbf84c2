//! The console's "Is it still accurate?" section of a robot page: the status
//! by the latest check, a trend plot of every check's mean error against
//! time (`super::trend`), the history (each check links to its page,
//! `super::check_detail`), the thresholds and their form, a form to run a
//! check, and the comparison of versions on one set. A latest check that says
//! `shifted` offers the re-registration at once. Every status
//! (`core::check::CheckStatus`) has its colour (`super::status`) and its
//! meaning (the legend); a `shifted` check shows the shift's size wherever
//! it is shown.

use super::format::{mm, trimmed, MM_DECIMALS};
use super::status::{shift_text, status_tag};
use crate::records::CheckRow;
use crate::records::SetRow;
use crate::records::VersionRow;
use crate::service::checks::shift_of;
use maud::{html, Markup};
use robocal_core::check::{CheckStatus, CheckThresholds};

/// Everything the section shows.
pub(super) struct ChecksView<'a> {
    pub robot: i64,
    pub status: Option<CheckStatus>,
    pub thresholds: &'a CheckThresholds,
    /// Oldest first.
    pub checks: &'a [CheckRow],
    pub sets: &'a [SetRow],
    pub versions: &'a [VersionRow],
}

fn set_options(sets: &[SetRow]) -> Markup {
    html! {
        @for s in sets.iter().rev() {
            option value=(s.id) { (s.id) " " (s.name) " (" (s.row_count) " poses)" }
        }
    }
}

/// The section.
pub(super) fn checks_section(v: &ChecksView) -> Markup {
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
                span.note #thresholds-text { " · degraded above " (mm(v.thresholds.degraded_mm)) " mm, recalibrate above " (mm(v.thresholds.recalibrate_mm)) " mm mean" }
            }
            @if let (Some(CheckStatus::Shifted), Some(last)) = (v.status, v.checks.last()) {
                p #shifted-action {
                    "The latest check says the frame moved: "
                    a.button href={ "/ui/robots/" (id) "/checks/" (last.id) "#reregister-section" } { "Re-register from check " (last.id) }
                }
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
                (super::trend::trend(v.checks, v.thresholds))
                table #checks {
                    thead { tr { th { "Check" } th { "Time" } th { "Version" } th { "Set" } th { "Mean [mm]" } th { "Status" } th { "Frame shift" } th { "Temperature [°C]" } } }
                    tbody {
                        @for c in v.checks.iter().rev() {
                            tr {
                                td { a.check-link href={ "/ui/robots/" (id) "/checks/" (c.id) } { "check " (c.id) } }
                                td { time datetime=(c.created_at) { (c.created_at) } }
                                td { "v" (c.version) }
                                td { @if let Some(s) = c.set_id { (s) } @else { "—" } }
                                td { (mm(c.mean_mm)) }
                                td class={ "check-status status-" (c.status) } { (c.status) }
                                td.check-shift { @if let Some(f) = shift_of(c) { (shift_text(&f)) } @else { "—" } }
                                td { @if let Some(t) = c.temperature_c { (super::format::fixed(t, 1)) } @else { "—" } }
                            }
                        }
                    }
                }
            }
            (thresholds_form(id, v.thresholds))
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

/// The form that sets the robot's thresholds, prefilled with those in force.
fn thresholds_form(id: i64, t: &CheckThresholds) -> Markup {
    html! {
        form #check-thresholds-form data-action="thresholds" data-robot=(id) {
            label { "Degraded above [mm] " input name="degraded_mm" type="number" step="any" min="0" value=(trimmed(t.degraded_mm, MM_DECIMALS)); }
            label { "Recalibrate above [mm] " input name="recalibrate_mm" type="number" step="any" min="0" value=(trimmed(t.recalibrate_mm, MM_DECIMALS)); }
            label title="A frame shift explains the errors when the mean after removing it is at most this fraction of the mean" { "Frame-shift ratio "
                input name="frame_shift_ratio" type="number" step="any" min="0" max="1" value=(t.frame_shift_ratio); }
            button type="submit" { "Set thresholds" }
        }
    }
}
