//! The console's cell sections of a robot page: its tools and work objects
//! (list, add, delete) and program filtering (drop program files in, see the
//! per-target report, download the filtered files).

use super::fields::model_select;
use crate::records::VersionRow;
use crate::records::{CellItemRow, ItemFrame};
use maud::{html, Markup};

fn pose_text(r: &CellItemRow) -> String {
    let [x, y, z] = r.pose_json.0.xyz_mm;
    let [a, b, c] = r.pose_json.0.rpy_deg;
    format!("{x}, {y}, {z} mm · {a}, {b}, {c}°")
}

fn items_table(id: i64, path: &str, rows: &[CellItemRow], frames: bool) -> Markup {
    html! {
        @if rows.is_empty() {
            p.empty { "None yet." }
        } @else {
            table.cell-items {
                thead { tr { th { "Name" } th { "Number" } @if frames { th { "Frame" } } th { "Pose (x, y, z · rx, ry, rz)" } th {} } }
                tbody {
                    @for r in rows {
                        tr {
                            td.name { (r.name) }
                            td { @if let Some(n) = r.number { (n) } @else { "—" } }
                            @if frames { td { (if r.frame == ItemFrame::Measurement { "measurement" } else { "base" }) } }
                            td { (pose_text(r)) }
                            td { button.small data-delete={ "/v1/robots/" (id) "/" (path) "/" (r.name) } { "Delete" } }
                        }
                    }
                }
            }
        }
    }
}

fn pose_inputs() -> Markup {
    html! {
        label { "x [mm] " input name="x" type="number" step="any" value="0"; }
        label { "y [mm] " input name="y" type="number" step="any" value="0"; }
        label { "z [mm] " input name="z" type="number" step="any" value="0"; }
        label { "rx [°] " input name="rx" type="number" step="any" value="0"; }
        label { "ry [°] " input name="ry" type="number" step="any" value="0"; }
        label { "rz [°] " input name="rz" type="number" step="any" value="0"; }
    }
}

/// Tools and work objects of robot `id`.
pub fn cell_section(id: i64, tools: &[CellItemRow], work_objects: &[CellItemRow]) -> Markup {
    html! {
        section #cell {
            h2 { "Tools and work objects" }
            p.note { "Production tools (TCP in the flange frame) and work objects (in the robot base or the tracker frame) that programs refer to by name or number (KUKA TOOL_DATA/BASE_DATA, Fanuc UT/UF). Rotations: R = Rz·Ry·Rx." }
            h3 { "Tools" }
            div #tools { (items_table(id, "tools", tools, false)) }
            form #add-tool data-action="put-item" data-url={ "/v1/robots/" (id) "/tools/" } {
                label { "Name " input name="name" required pattern="[A-Za-z0-9_][A-Za-z0-9_.\\-]{0,63}" placeholder="torch"; }
                label { "Number " input name="number" type="number" min="0" max="999" step="1"; }
                (pose_inputs())
                button type="submit" { "Save tool" }
            }
            h3 { "Work objects" }
            div #work-objects { (items_table(id, "frames", work_objects, true)) }
            form #add-frame data-action="put-item" data-url={ "/v1/robots/" (id) "/frames/" } {
                label { "Name " input name="name" required pattern="[A-Za-z0-9_][A-Za-z0-9_.\\-]{0,63}" placeholder="table"; }
                label { "Number " input name="number" type="number" min="0" max="999" step="1"; }
                label { "Frame "
                    select name="frame" { option value="base" { "robot base" } option value="measurement" { "tracker (measurement)" } }
                }
                (pose_inputs())
                button type="submit" { "Save work object" }
            }
        }
    }
}

/// Program filtering for robot `id`.
pub fn filter_section(id: i64, versions: &[VersionRow]) -> Markup {
    html! {
        section #filter-section {
            h2 { "Filter a robot program" }
            p.note { "KUKA KRL (.src with its .dat), ABB RAPID (.mod), Fanuc (.ls) or URScript (.script): every Cartesian target becomes its false target; everything else stays as it is." }
            form #filter data-action="filter" data-robot=(id) {
                label.wide { "Program files " input type="file" name="files" multiple accept=".src,.dat,.mod,.modx,.prg,.sys,.ls,.script,.urscript"; }
                (model_select(versions))
                label { "Language "
                    select name="language" {
                        option value="" { "from the file names" }
                        option value="krl" { "KUKA KRL" } option value="rapid" { "ABB RAPID" }
                        option value="fanuc" { "Fanuc .ls" } option value="urscript" { "URScript" }
                    }
                }
                button type="submit" { "Filter" }
            }
            div #filter-result hidden {
                p #filter-summary {}
                p #filter-downloads {}
                table #filter-report {
                    thead { tr { th { "File" } th { "Line" } th { "Motion" } th { "Status" } th { "Shift [mm]" } th { "Configuration" } th { "Reason" } } }
                    tbody {}
                }
            }
        }
    }
}
