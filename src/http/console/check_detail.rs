//! One check's page: its status with the sentence that says why, the
//! figures (position and orientation errors, the frame shift and whether it
//! explains the errors), the thresholds that judged it, the per-pose errors
//! (the largest kept, at most `service::checks::CHECK_POSES_KEPT`) and the
//! form that re-registers the version it scored on the set it scored (the
//! fix a `shifted` check calls for). Numbers as `super::format` writes them.

use super::format::{deg, mm};
use super::pages::layout;
use super::status::status_tag;
use crate::records::{CheckRow, RobotRow};
use crate::service::checks::{shift_of, status_of};
use maud::{html, Markup};
use robocal_core::check::CheckStatus;
use serde_json::Value;

fn num(v: &Value, key: &str) -> Option<f64> {
    v.get(key)?.as_f64()
}

/// A figure in mm, or `—`.
fn mm_or_dash(v: &Value, key: &str) -> String {
    num(v, key).map_or_else(|| "—".into(), mm)
}

/// A figure in degrees, or `—`.
fn deg_or_dash(v: &Value, key: &str) -> String {
    num(v, key).map_or_else(|| "—".into(), deg)
}

/// The page of check `c` of robot `r`.
pub(super) fn check_page(r: &RobotRow, c: &CheckRow, keys: bool) -> Markup {
    let res = &c.result.0;
    let status = status_of(c);
    let pos = &res["position"];
    let ori = &res["orientation"];
    let shift = &res["frame_shift"];
    let thr = &res["thresholds"];
    let poses = res["poses"].as_array().map(Vec::as_slice).unwrap_or(&[]);
    let total = res["poses_total"].as_u64().unwrap_or(poses.len() as u64);
    layout(
        &format!("Check {} — {}", c.id, r.name),
        keys,
        html! {
            p.crumbs { a href="/ui" { "Robots" } " / " a href={ "/ui/robots/" (r.id) } { (r.name) } " / check " (c.id) }
            h1 { "Check " (c.id) }
            p #check-verdict {
                @match status {
                    Some(s) => { (status_tag(s, shift_of(c).as_ref())) }
                    None => { span { (c.status) } }
                }
                " "
                span #check-summary { (res["summary"].as_str().unwrap_or("")) }
            }
            @if let Some(s) = status { p.note #check-action { "What to do: " (s.action()) } }
            table #check-figures {
                tbody {
                    tr { th { "Scored against" } td { "v" (c.version) } }
                    tr { th { "Set" } td { @if let Some(s) = c.set_id { (s) } @else { "—" } } }
                    tr { th { "Time" } td { time datetime=(c.created_at) { (c.created_at) } } }
                    tr { th { "Temperature [°C]" } td { @if let Some(t) = c.temperature_c { (super::format::fixed(t, 1)) } @else { "—" } } }
                    tr { th { "Poses scored" } td { (total) } }
                    tr { th { "Position error mean / p95 / max [mm]" }
                        td.position { (mm_or_dash(pos, "mean_mm")) " / " (mm_or_dash(pos, "p95_mm")) " / " (mm_or_dash(pos, "max_mm")) } }
                    tr { th { "Orientation error mean / p95 / max [°]" }
                        td { @if ori.is_object() { (deg_or_dash(ori, "mean_deg")) " / " (deg_or_dash(ori, "p95_deg")) " / " (deg_or_dash(ori, "max_deg")) } @else { "— (positions only)" } } }
                    tr { th { "Frame shift" }
                        td #check-frame-shift {
                            @if shift.is_object() {
                                (mm_or_dash(shift, "translation_mm")) " mm, " (deg_or_dash(shift, "rotation_deg")) "°; mean after removing it "
                                (mm_or_dash(shift, "residual_mean_mm")) " mm; "
                                @if shift["explains"].as_bool() == Some(true) { strong { "explains the errors" } } @else { "does not explain the errors" }
                            } @else { "— (fewer than 6 poses, or too alike)" }
                        }
                    }
                    tr { th { "Thresholds (when scored)" }
                        td #check-thresholds {
                            "degraded above " (mm_or_dash(thr, "degraded_mm")) " mm, recalibrate above " (mm_or_dash(thr, "recalibrate_mm")) " mm mean; a frame shift explains the errors when the mean after it is at most "
                            (num(thr, "frame_shift_ratio").map_or_else(|| "—".into(), |f| super::format::fixed(f, 2))) " of the mean"
                        }
                    }
                }
            }
            (reregister_form(r.id, c, status))
            h2 { "Per-pose errors" }
            @if (poses.len() as u64) < total { p.note { "The " (poses.len()) " largest of " (total) " poses, in row order." } }
            table #check-poses {
                thead { tr { th { "Row" } th { "Position [mm]" } th { "Orientation [°]" } } }
                tbody {
                    @for p in poses {
                        tr {
                            td { (p["index"].as_u64().unwrap_or(0)) }
                            td { (mm_or_dash(p, "position_mm")) }
                            td { (deg_or_dash(p, "orientation_deg")) }
                        }
                    }
                }
            }
        },
    )
}

/// Re-register the version the check scored on its set: the button a
/// `shifted` check calls for, offered (less loudly) for any check with a set.
fn reregister_form(robot: i64, c: &CheckRow, status: Option<CheckStatus>) -> Markup {
    let Some(set) = c.set_id else {
        return html! {};
    };
    let shifted = status == Some(CheckStatus::Shifted);
    html! {
        section #reregister-section .alert[shifted] {
            h2 { @if shifted { "The frame moved: re-register" } @else { "Re-register on this set" } }
            p.note {
                "Refits the measurement frame and the measurement tool of v" (c.version) " on the poses of set " (set)
                " (the robot's geometry, compliance and compensation are kept) and stores the result as a new version"
                "; activate it from the versions (asked first), or tick the box to activate it now. Then check again."
            }
            form #reregister data-action="reregister" data-robot=(robot) {
                input type="hidden" name="set_id" value=(set);
                input type="hidden" name="version" value=(c.version);
                label.check { input type="checkbox" name="activate" value="true"; " activate the new version" }
                button type="submit" { "Re-register v" (c.version) " on set " (set) }
            }
        }
    }
}
