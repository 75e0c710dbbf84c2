//! The console's external axes section of a robot page: the linear track
//! carrying the robot, the two-axis positioner and the one-axis turntable in
//! its cell, each as stored (what it was fitted on, its residuals, delete
//! after a confirmation) or "none stored", and the form that fits it from
//! measurement files (`POST …/track/calibrate`, `POST
//! …/positioner/calibrate`, `POST …/turntable/calibrate`); the positioner
//! also from touches with one of the robot's stored tools, placed by one of
//! its versions. A refused fit stores nothing; the page shows why and keeps
//! what was stored. Lengths in mm to 0.001, angles in degrees to 0.0001.

use super::format::{deg, fixed, mm};
use crate::http::{tracks, PAYLOAD_MAX_KG};
use crate::records::{CellItemRow, PositionerRow, RobotRow, TrackRow, TurntableRow, VersionRow};
use maud::{html, Markup};
use robocal_core::calibrate::external::track::DEFAULT_MAX_ORDER;
use robocal_core::measure::external::ExternalAxis;
use robocal_core::model::external::travel_map::MAX_MAP_ORDER;
use robocal_core::model::external::TurntableDescription;

/// Decimals of a unitless figure: a unit direction's components, a scale.
const UNITLESS_DECIMALS: usize = 6;

/// What the section shows: the robot's stored track, positioner and
/// turntable, if any, and the versions and tools a positioner can be
/// touched with.
pub(super) struct AxesView<'a> {
    pub robot: &'a RobotRow,
    pub track: Option<&'a TrackRow>,
    pub positioner: Option<&'a PositionerRow>,
    pub turntable: Option<&'a TurntableRow>,
    pub versions: &'a [VersionRow],
    pub tools: &'a [CellItemRow],
}

/// The section `#axes-section` of robot `v.robot`.
pub(super) fn axes_section(v: &AxesView) -> Markup {
    let id = v.robot.id;
    html! {
        section #axes-section {
            h2 { "External axes" }
            p.note { "A linear track carrying the robot, a two-axis (tilt-rotate) positioner and a one-axis turntable in its cell, each fitted from the tracker's readings (the positioner also from touches with a calibrated tool) and stored for this robot. A fit is judged before it is stored: a refused fit stores nothing, and the page says why." }
            h3 { "Linear track" }
            div #track-stored-box {
                @match v.track {
                    Some(t) => { (track_table(v.robot, t)) }
                    None => { p.empty #no-track { "No track stored." } }
                }
            }
            (track_form(id))
            h3 { "Positioner" }
            div #positioner-stored-box {
                @match v.positioner {
                    Some(p) => { (positioner_table(v.robot, p)) }
                    None => { p.empty #no-positioner { "No positioner stored." } }
                }
            }
            (positioner_form(v))
            h3 { "Turntable" }
            div #turntable-stored-box {
                @match v.turntable {
                    Some(t) => { (turntable_table(v.robot, t)) }
                    None => { p.empty #no-turntable { "No turntable stored." } }
                }
            }
            (turntable_form(id))
        }
    }
}

/// The stored track: what it was fitted on and its residuals.
fn track_table(r: &RobotRow, t: &TrackRow) -> Markup {
    let url = format!("/v1/robots/{}/track", r.id);
    html! {
        table #track-stored {
            thead { tr { th { "Column" } th { "Readings from" } th { "Model version held" } th { "Stations" } th { "Readings" } th { "RMS [mm]" } th { "Max [mm]" } th { "σ [mm]" } th { "Created" } th {} } }
            tbody {
                tr {
                    td.column { (t.axis_column) }
                    td.from { (track_readings_from(t)) }
                    td.version { "v" (t.version) }
                    td.stations { (t.stations) }
                    td.readings { (t.readings) }
                    td.rms { (mm(t.rms_mm)) }
                    td.max { (mm(t.max_mm)) }
                    td.sigma { (mm(t.sigma_mm)) }
                    td { time datetime=(t.created_at) { (t.created_at) } }
                    td {
                        a href=(url) { "track JSON" } " "
                        a href={ (url) "/fit-request" } title="The calibrate request that fitted it, readings included; post it again to refit" { "fit request" } " "
                        button.small.danger #delete-track data-delete=(url)
                            data-confirm={ "Delete the track of robot " (r.id) " (" (r.name) ")? Predictions, solves and filters that give a track value are refused until a track is fitted again." } { "Delete the track" }
                    }
                }
            }
        }
    }
}

/// Where a stored track's readings came from: its station sets' ids
/// (runs of consecutive ids as `12–22`), or a posted file.
fn track_readings_from(t: &TrackRow) -> String {
    let ids = match t.fitted_from_sets() {
        Ok(Some(ids)) => ids,
        Ok(None) => return "a posted file".into(),
        Err(e) => return format!("station sets (unreadable: {e})"),
    };
    let mut runs: Vec<(i64, i64)> = Vec::new();
    for id in ids {
        match runs.last_mut() {
            Some((_, end)) if *end + 1 == id => *end = id,
            _ => runs.push((id, id)),
        }
    }
    let runs: Vec<String> = runs
        .iter()
        .map(|&(a, b)| {
            if a == b {
                a.to_string()
            } else {
                format!("{a}–{b}")
            }
        })
        .collect();
    format!("station sets {}", runs.join(", "))
}

/// The stored positioner: what it was fitted on and its residuals.
fn positioner_table(r: &RobotRow, p: &PositionerRow) -> Markup {
    let url = format!("/v1/robots/{}/positioner", r.id);
    html! {
        table #positioner-stored {
            thead { tr { th { "Tilt column" } th { "Rotate column" } th { "Readings from" } th { "Reflectors" } th { "Readings" } th { "RMS [mm]" } th { "Max [mm]" } th { "σ [mm]" } th { "Created" } th {} } }
            tbody {
                tr {
                    td.tilt { (p.tilt_column) }
                    td.rotate { (p.rotate_column) }
                    td.from {
                        @match (p.touched_version, &p.touched_tool) {
                            (Some(v), Some(t)) => { "touches with tool " (t) " of version " (v) }
                            _ => { "tracker" }
                        }
                    }
                    td.reflectors { (p.reflectors) }
                    td.readings { (p.readings) }
                    td.rms { (mm(p.rms_mm)) }
                    td.max { (mm(p.max_mm)) }
                    td.sigma { (mm(p.sigma_mm)) }
                    td { time datetime=(p.created_at) { (p.created_at) } }
                    td {
                        a href=(url) { "positioner JSON" } " "
                        a href={ (url) "/fit-request" } title="The calibrate request that fitted it, readings included; post it again to refit" { "fit request" } " "
                        button.small.danger #delete-positioner data-delete=(url)
                            data-confirm={ "Delete the positioner of robot " (r.id) " (" (r.name) ")? Solves, predictions and filters that give positioner values are refused until a positioner is fitted again." } { "Delete the positioner" }
                    }
                }
            }
        }
    }
}

/// A select of the columns `e1` … `e6`, `default` chosen.
fn column_select(label: &str, name: &str, default: ExternalAxis) -> Markup {
    html! {
        label { (label) " "
            select name=(name) {
                @for a in ExternalAxis::ALL {
                    option value=(a.column()) selected[a == default] { (a.column()) }
                }
            }
        }
    }
}

/// The tracker's σ per coordinate, prefilled with the API's default.
fn sigma_input(default: f64) -> Markup {
    html! {
        label title="The tracker's noise per coordinate, 1σ; the fit is judged against it" { "Tracker σ [mm] "
            input name="sigma_mm" type="number" step="any" min="0" max="10" value=(default) required; }
    }
}

/// The form that fits the track (`POST …/track/calibrate`).
fn track_form(id: i64) -> Markup {
    html! {
        p.note { "One measurement file: the reflector at 3 or more robot poses (not on a line) at each of 5 or more track values; columns q1…qN (controller degrees), the track's value [mm] in an e column, x, y, z [mm] in the tracker frame. Or the station sets that file was uploaded as (Measurement sets, with a track column), read as the file. The robot's calibrated version is held (the active one unless a version is given). A fit replaces the stored track." }
        form #calibrate-track data-action="calibrate-track" data-robot=(id) {
            label.wide { "Measurement file " input type="file" name="file" accept=".csv,text/csv"; }
            label.wide { "or paste it " textarea name="csv" rows="3" placeholder="q1,q2,q3,q4,q5,q6,e1,x,y,z" {} }
            label.wide title="The ids of station sets stored from one file with a track column, in the file's order" { "or its station sets "
                input name="set_ids" placeholder="e.g. 12-22 or 12, 13, 14"; }
            (column_select("Track column", "column", ExternalAxis::E1))
            (sigma_input(tracks::DEFAULT_SIGMA_MM))
            label title="The highest order of the carriage maps tried; 0: a straight rail" { "Highest map order "
                input name="max_order" type="number" min="0" max=(MAX_MAP_ORDER) step="1" value=(DEFAULT_MAX_ORDER) required; }
            label title="The calibrated version held; empty: the active one" { "Version "
                input name="version" type="number" min="1" step="1" placeholder="active"; }
            label title="The payload of readings that give none; empty: the version's" { "Payload [kg] "
                input name="payload_kg" type="number" step="any" min="0" max=(PAYLOAD_MAX_KG) placeholder="version's"; }
            button type="submit" { "Fit the track" }
        }
        p #track-result hidden {}
    }
}

/// The form that fits the positioner (`POST …/positioner/calibrate`), from
/// tracker files or from touches (`touched_with`).
fn positioner_form(v: &AxesView) -> Markup {
    html! {
        p.note { "One measurement file per reflector on the face plate: each axis swept over 90° or more at 4 or more values with the other held; the axes' values [°] in two e columns, x, y, z [mm] in the tracker frame; no joints needed. Or, with readings from touches, one touches file per feature on the face plate (id, q1…qN controller degrees and the axes' two e columns), placed by the chosen version's robot carrying the chosen stored tool; σ is then the robot's accuracy at the tool's tip and must be given. The reflectors' (features') design positions on the face plate [mm], one x, y, z line per file, in the files' order (the first is the reference). A fit replaces the stored positioner." }
        form #calibrate-positioner data-action="calibrate-positioner" data-robot=(v.robot.id) {
            (nominal_inputs("positioner", "{\"cell_from_base\": ..., \"tilt\": ..., \"rotate\": ..., \"face_plate\": ...}"))
            (readings_from(v))
            (reflector_inputs("positioner"))
            (column_select("Tilt column", "tilt_column", ExternalAxis::E1))
            (column_select("Rotate column", "rotate_column", ExternalAxis::E2))
            label title="Tracker files: the tracker's noise per coordinate, 1σ (empty: 0.01). Touches: the robot's accuracy at the tool's tip, 1σ (required). The fit is judged against it" { "σ [mm] "
                input name="sigma_mm" type="number" step="any" min="0" max="10" value=(crate::http::positioners::DEFAULT_SIGMA_MM); }
            button type="submit" { "Fit the positioner" }
        }
        p #positioner-result hidden {}
    }
}

/// The nominal axis's JSON: a file, or its text pasted.
fn nominal_inputs(what: &str, placeholder: &str) -> Markup {
    html! {
        label.wide { "Nominal " (what) " (JSON) " input type="file" name="nominal_file" accept=".json,application/json"; }
        label.wide { "or paste it " textarea name="nominal" rows="3" placeholder=(placeholder) {} }
    }
}

/// One measurement file per reflector (the order they are sent listed in
/// `#{what}-files`) and the reflectors' design positions, a line per file.
fn reflector_inputs(what: &str) -> Markup {
    html! {
        label.wide { "Measurement files, one per reflector " input type="file" name="sets" multiple accept=".csv,text/csv"; }
        p.note.files id={ (what) "-files" } {}
        label.wide { "Reflectors' design positions [mm], one x, y, z line per file " textarea name="reflectors" rows="3" placeholder="400, 0, 20" {} }
    }
}

/// Where the positioner's readings come from: tracker files, or touches
/// placed by one of the robot's versions (newest first, the active one
/// chosen; a number without any) carrying one of its stored tools.
fn readings_from(v: &AxesView) -> Markup {
    html! {
        fieldset.readings-from {
            legend { "Readings from" }
            label.check { input type="radio" name="readings_from" value="tracker" checked; " tracker files" }
            label.check { input type="radio" name="readings_from" value="touches"; " touches" }
        }
        fieldset #positioner-touches hidden {
            legend { "Touched with" }
            @if v.versions.is_empty() {
                label title="The model version whose calibrated robot placed the touches" { "Version "
                    input name="touched_version" type="number" min="1" step="1" placeholder="none calibrated"; }
            } @else {
                label title="The model version whose calibrated robot placed the touches" { "Version "
                    select name="touched_version" {
                        @for ver in v.versions.iter().rev() {
                            option value=(ver.version) selected[v.robot.active_version == Some(ver.version)] { "v" (ver.version) " " (ver.method) }
                        }
                    }
                }
            }
            label title="The robot's stored tool that touched the features" { "Tool "
                select name="touched_tool" {
                    @if v.tools.is_empty() { option value="" { "no tool stored" } }
                    @for t in v.tools { option value=(t.name) { (t.name) } }
                }
            }
        }
    }
}

/// The stored turntable: what it was fitted on, its residuals and its axis
/// (the line in its base frame, the zero offset, the scale), from the
/// stored JSON.
fn turntable_table(r: &RobotRow, t: &TurntableRow) -> Markup {
    let url = format!("/v1/robots/{}/turntable", r.id);
    let described: Option<TurntableDescription> = serde_json::from_str(&t.turntable_json).ok();
    let axis = described.map(|d| d.axis);
    let triple = |v: [f64; 3], f: &dyn Fn(f64) -> String| v.map(f).join(", ");
    let unitless = |x: f64| fixed(x, UNITLESS_DECIMALS);
    html! {
        table #turntable-stored {
            thead { tr { th { "Column" } th { "Reflectors" } th { "Readings" } th { "Axis direction" } th { "Axis point [mm]" } th { "Zero offset [°]" } th { "Scale" } th { "RMS [mm]" } th { "Max [mm]" } th { "σ [mm]" } th { "Created" } th {} } }
            tbody {
                tr {
                    td.column { (t.value_column) }
                    td.reflectors { (t.reflectors) }
                    td.readings { (t.readings) }
                    td.direction { (axis.map_or("—".into(), |a| triple(a.direction, &unitless))) }
                    td.point { (axis.map_or("—".into(), |a| triple(a.point_mm, &mm))) }
                    td.zero { (axis.map_or("—".into(), |a| deg(a.zero_offset_deg))) }
                    td.scale { (axis.map_or("—".into(), |a| unitless(a.scale))) }
                    td.rms { (mm(t.rms_mm)) }
                    td.max { (mm(t.max_mm)) }
                    td.sigma { (mm(t.sigma_mm)) }
                    td { time datetime=(t.created_at) { (t.created_at) } }
                    td {
                        a href=(url) { "turntable JSON" } " "
                        a href={ (url) "/fit-request" } title="The calibrate request that fitted it, readings included; post it again to refit" { "fit request" } " "
                        button.small.danger #delete-turntable data-delete=(url)
                            data-confirm={ "Delete the turntable of robot " (r.id) " (" (r.name) ")? Fitting it again needs its measurement files." } { "Delete the turntable" }
                    }
                }
            }
        }
    }
}

/// The form that fits the turntable (`POST …/turntable/calibrate`).
fn turntable_form(id: i64) -> Markup {
    html! {
        p.note { "One measurement file per reflector on the face plate: the axis swept over 90° or more at 4 or more values; its value [°] in an e column, x, y, z [mm] in the tracker frame; no joints needed. The reflectors' design positions on the face plate [mm], one x, y, z line per file, in the files' order (the first is the reference). No calibrated version is needed. A fit replaces the stored turntable." }
        form #calibrate-turntable data-action="calibrate-turntable" data-robot=(id) {
            (nominal_inputs("turntable", "{\"cell_from_base\": ..., \"axis\": ..., \"face_plate\": ...}"))
            (reflector_inputs("turntable"))
            (column_select("Axis column", "column", ExternalAxis::E1))
            (sigma_input(crate::http::positioners::DEFAULT_SIGMA_MM))
            button type="submit" { "Fit the turntable" }
        }
        p #turntable-result hidden {}
    }
}
