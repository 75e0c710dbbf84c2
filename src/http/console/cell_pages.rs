//! The console's cell sections of a robot page: its tools (with their
//! loads) and work objects (list, add, edit in a form prefilled with every
//! stored field, delete after a confirmation), their fits from readings,
//! the controller's data for them, and program filtering (drop program files in, see the per-target
//! report, download the filtered files and the report).

use super::fields::model_select;
use super::format::{deg, fixed, kg, mm, trimmed, DEG_DECIMALS, KG_DECIMALS, MM_DECIMALS};
use crate::program::controller::AxesKind;
use crate::records::VersionRow;
use crate::records::{CellItemRow, ItemFrame};
use maud::{html, Markup};
use robocal_core::cell_fit::tcp::TcpMethod;
use robocal_core::model::load::LoadFrame;
use robocal_core::model::orientation::OrientationConvention;

/// Which kind of cell item a form or table holds.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Tool,
    WorkObject,
}

impl Kind {
    /// The API's collection (`/v1/robots/{id}/<path>/{name}`).
    fn path(self) -> &'static str {
        match self {
            Kind::Tool => "tools",
            Kind::WorkObject => "frames",
        }
    }

    fn noun(self) -> &'static str {
        match self {
            Kind::Tool => "tool",
            Kind::WorkObject => "work object",
        }
    }
}

fn pose_text(r: &CellItemRow) -> String {
    let [x, y, z] = r.pose_json.0.xyz_mm;
    let [a, b, c] = r.pose_json.0.rpy_deg;
    format!(
        "{}, {}, {} mm · {}, {}, {}°",
        mm(x),
        mm(y),
        mm(z),
        deg(a),
        deg(b),
        deg(c)
    )
}

/// `2.500 kg at 0.000, 0.000, 80.000 mm (flange)`, or `—`.
fn load_text(r: &CellItemRow) -> String {
    let Some(l) = r.load_json.as_ref().map(|l| &l.0) else {
        return "—".into();
    };
    let [x, y, z] = l.com_mm;
    let frame = match l.frame {
        LoadFrame::Flange => "flange",
        LoadFrame::Tool => "tool",
    };
    let mut t = format!(
        "{} kg at {}, {}, {} mm ({frame})",
        kg(l.mass_kg),
        mm(x),
        mm(y),
        mm(z)
    );
    if let Some([a, b, c]) = l.inertia_kgm2 {
        t += &format!(
            "; inertia {}, {}, {} kg·m²",
            fixed(a, 6),
            fixed(b, 6),
            fixed(c, 6)
        );
    }
    t
}

fn items_table(id: i64, kind: Kind, rows: &[CellItemRow]) -> Markup {
    let frames = kind == Kind::WorkObject;
    html! {
        @if rows.is_empty() {
            p.empty { "None yet." }
        } @else {
            table.cell-items {
                thead { tr { th { "Name" } th { "Number" } @if frames { th { "Frame" } } th { "Pose (x, y, z · rx, ry, rz)" } @if !frames { th { "Load" } } th {} } }
                tbody {
                    @for r in rows {
                        tr data-item=(r.name) {
                            td.name { (r.name) }
                            td.number { @if let Some(n) = r.number { (n) } @else { "—" } }
                            @if frames { td { (r.frame.as_str()) } }
                            td.pose { (pose_text(r)) }
                            @if !frames { td.load { (load_text(r)) } }
                            td {
                                details.edit {
                                    summary { "Edit" }
                                    (item_form(id, kind, Some(r)))
                                }
                                button.small.danger data-delete={ "/v1/robots/" (id) "/" (kind.path()) "/" (r.name) }
                                    data-confirm={ "Delete " (kind.noun()) " " (r.name) "? Programs that name it will no longer filter." } { "Delete" }
                            }
                        }
                    }
                }
            }
        }
    }
}

/// A number input prefilled with `value` rounded to `decimals` (empty when `None`).
fn number_input(label: &str, name: &str, value: Option<f64>, decimals: usize) -> Markup {
    html! {
        label { (label) " "
            input name=(name) type="number" step="any" value=[value.map(|v| trimmed(v, decimals))];
        }
    }
}

/// The form that saves a tool or work object: empty to add one, prefilled
/// with every stored field (number, frame, pose, load) to edit `item`; its
/// name is the identity and is not edited.
fn item_form(id: i64, kind: Kind, item: Option<&CellItemRow>) -> Markup {
    let pose = item.map(|r| &r.pose_json.0);
    let xyz = |i: usize| Some(pose.map_or(0.0, |p| p.xyz_mm[i]));
    let rpy = |i: usize| Some(pose.map_or(0.0, |p| p.rpy_deg[i]));
    let load = item.and_then(|r| r.load_json.as_ref()).map(|l| &l.0);
    let form_id = match (kind, item) {
        (Kind::Tool, None) => "add-tool".to_string(),
        (Kind::WorkObject, None) => "add-frame".to_string(),
        (_, Some(r)) => format!("edit-{}-{}", kind.path(), r.name),
    };
    html! {
        form id=(form_id) data-action="put-item" data-url={ "/v1/robots/" (id) "/" (kind.path()) "/" } {
            @match item {
                Some(r) => { input type="hidden" name="name" value=(r.name); }
                None => { label { "Name " input name="name" required pattern="[A-Za-z0-9_][A-Za-z0-9_.\\-]{0,63}" placeholder=(if kind == Kind::Tool { "torch" } else { "table" }); } }
            }
            label { "Number " input name="number" type="number" min="0" max="999" step="1" value=[item.and_then(|r| r.number)]; }
            @if kind == Kind::WorkObject {
                @let frame = item.map_or(ItemFrame::Base, |r| r.frame);
                label { "Frame "
                    select name="frame" {
                        option value="base" selected[frame == ItemFrame::Base] { "robot base" }
                        option value="measurement" selected[frame == ItemFrame::Measurement] { "tracker (measurement)" }
                        option value="face_plate" selected[frame == ItemFrame::FacePlate] { "positioner's face plate" }
                    }
                }
            }
            (number_input("x [mm]", "x", xyz(0), MM_DECIMALS))
            (number_input("y [mm]", "y", xyz(1), MM_DECIMALS))
            (number_input("z [mm]", "z", xyz(2), MM_DECIMALS))
            (number_input("rx [°]", "rx", rpy(0), DEG_DECIMALS))
            (number_input("ry [°]", "ry", rpy(1), DEG_DECIMALS))
            (number_input("rz [°]", "rz", rpy(2), DEG_DECIMALS))
            @if kind == Kind::Tool {
                fieldset.load {
                    legend { "Load (empty mass: none; the model's payload is carried)" }
                    (number_input("Mass [kg]", "load_mass_kg", load.map(|l| l.mass_kg), KG_DECIMALS))
                    (number_input("CoM x [mm]", "load_com_x", load.map(|l| l.com_mm[0]), MM_DECIMALS))
                    (number_input("CoM y [mm]", "load_com_y", load.map(|l| l.com_mm[1]), MM_DECIMALS))
                    (number_input("CoM z [mm]", "load_com_z", load.map(|l| l.com_mm[2]), MM_DECIMALS))
                    @let tool_frame = load.is_some_and(|l| l.frame == LoadFrame::Tool);
                    label { "CoM frame "
                        select name="load_frame" {
                            option value="flange" selected[!tool_frame] { "flange" }
                            option value="tool" selected[tool_frame] { "tool" }
                        }
                    }
                    @let inertia = load.and_then(|l| l.inertia_kgm2);
                    (number_input("Ixx [kg·m²]", "load_ixx", inertia.map(|i| i[0]), 6))
                    (number_input("Iyy [kg·m²]", "load_iyy", inertia.map(|i| i[1]), 6))
                    (number_input("Izz [kg·m²]", "load_izz", inertia.map(|i| i[2]), 6))
                }
            }
            button type="submit" { "Save " (kind.noun()) }
        }
    }
}

/// Tools and work objects of robot `id`.
pub(super) fn cell_section(id: i64, tools: &[CellItemRow], work_objects: &[CellItemRow]) -> Markup {
    html! {
        section #cell {
            h2 { "Tools and work objects" }
            p.note { "Production tools (TCP in the flange frame, with the load they carry) and work objects (in the robot base or the tracker frame) that programs refer to by name or number (KUKA TOOL_DATA/BASE_DATA, Fanuc UT/UF). Rotations: R = Rz·Ry·Rx. Edit opens the stored values; saving keeps every field shown." }
            h3 { "Tools" }
            div #tools { (items_table(id, Kind::Tool, tools)) }
            (item_form(id, Kind::Tool, None))
            h3 { "Work objects" }
            div #work-objects { (items_table(id, Kind::WorkObject, work_objects)) }
            (item_form(id, Kind::WorkObject, None))
            (fit_forms(id, tools))
            (export_form(id))
        }
    }
}

/// The controller's tool, load and work object data (`POST …/cell/export`),
/// with the robot's stored external axes for KRL (`axes`, every
/// [`AxesKind`]): what the controller cannot hold and what it then computes.
fn export_form(id: i64) -> Markup {
    html! {
        h3 { "Controller data" }
        form #export-cell data-action="export-cell" data-robot=(id) {
            label { "Language "
                select name="language" {
                    option value="krl" { "KUKA KRL ($config.dat)" } option value="rapid" { "ABB RAPID" }
                    option value="fanuc" { "Fanuc TP" } option value="urscript" { "URScript" }
                }
            }
            label title="KRL only: the robot's stored axes written as the controller's external kinematic systems" { "External axes (KRL) "
                select name="axes" {
                    option value="" { "none" }
                    @for k in AxesKind::ALL { option value=(k.name()) { (k.name().replace('_', " ")) } }
                }
            }
            button type="submit" { "Export" }
        }
        div #export-result hidden {
            p { a #export-download href="#" { "Download" } }
            pre #export-text {}
            div #export-kinematics hidden {
                p #export-held-downloads {}
                p #export-all-held hidden { "Every calibrated term is held." }
                table #export-not-held {
                    thead { tr { th { "Not held" } th { "Value" } th { "Miss [mm]" } } }
                    tbody {}
                }
            }
        }
    }
}

/// Fit a tool's TCP or a work object from readings (`POST …/tools/{name}/fit`,
/// `POST …/frames/{name}/fit`) on the calibrated version; the fitted item
/// is stored (a refit keeps a tool's load and number).
fn fit_forms(id: i64, tools: &[CellItemRow]) -> Markup {
    html! {
        h3 { "Fit a tool (TCP)" }
        p.note { "One reading a line: the joints [°] (fixed point: the tip held at one point in 4 or more orientations), followed by the tracker's x, y, z [mm] for a reflector on the tool (tracker point), and rx, ry, rz [°] for a 6-D probe (tracker frame). The tool's axis, when the readings fit its position only: readings of a second point on the axis nearer the flange, measured like the tip, or joint readings with the tool flat on a plane (3 or more touches)." }
        form #fit-tool data-action="fit-tool" data-robot=(id) {
            label { "Tool " input name="name" required pattern="[A-Za-z0-9_][A-Za-z0-9_.\\-]{0,63}" placeholder="torch"; }
            label { "Method "
                select name="method" {
                    @for m in TcpMethod::ALL { option value=(m.as_str()) { (tcp_method_text(m)) } }
                }
            }
            label.wide { "Readings " textarea name="readings" rows="3" placeholder="10, -80, 95, -105, -90, 12" {} }
            label { "Tool axis "
                select name="axis" {
                    option value="" { "— (position only)" }
                    option value="axis_point" { "a second point on the axis" }
                    option value="plane" { "the tool flat on a plane (joints)" }
                }
            }
            label.wide { "Axis readings " textarea name="axis_readings" rows="2" placeholder="as the readings" {} }
            label title="The tool's orientation when the readings fit its position only; empty: the stored tool's, kept" { "rx, ry, rz [°] "
                input name="rpy" placeholder="e.g. 0, 0, 0"; }
            label title="The controller's tool number; empty: the stored tool's, kept" { "Number " input name="number" type="number" min="1" max="999" step="1"; }
            label title="The calibrated version to fit on; empty: the active one" { "Version " input name="version" type="number" min="1" step="1" placeholder="active"; }
            label.check { input type="checkbox" name="force" value="true"; " store even a fit judged implausible" }
            button type="submit" { "Fit tool" }
        }
        h3 { "Fit a work object" }
        p.note { "One point a line: origin, x (on its x axis) or xy (in its xy plane), then the tracker's x, y, z [mm], or the joints [°] when touched with a tool." }
        form #fit-frame data-action="fit-frame" data-robot=(id) {
            label { "Work object " input name="name" required pattern="[A-Za-z0-9_][A-Za-z0-9_.\\-]{0,63}" placeholder="table"; }
            label { "Touched with "
                select name="tool" {
                    option value="" { "— (tracker points)" }
                    @for t in tools { option value=(t.name) { (t.name) } }
                }
            }
            label.wide { "Points " textarea name="readings" rows="3" placeholder="origin, 400, 0, 100" {} }
            button type="submit" { "Fit work object" }
        }
        p #fit-result hidden {}
    }
}

/// What a TCP method reads, for its choice in the form.
fn tcp_method_text(m: TcpMethod) -> &'static str {
    match m {
        TcpMethod::FixedPoint => "fixed point (joints)",
        TcpMethod::TrackerPoint => "tracker point (joints, x, y, z)",
        TcpMethod::TrackerFrame => "6-D probe (joints, x, y, z, rx, ry, rz)",
    }
}

/// Program filtering for robot `id`.
pub(super) fn filter_section(id: i64, versions: &[VersionRow]) -> Markup {
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
                (filter_axes_fields())
                button type="submit" { "Filter" }
            }
            div #filter-result hidden {
                p #filter-summary {}
                p #filter-axes hidden {}
                p #filter-downloads {}
                p { a #filter-report-download download="filter-report.json" href="#" { "Download the report (JSON)" } }
                table #filter-report {
                    thead { tr { th { "File" } th { "Line" } th { "Motion" } th { "Status" } th { "Shift [mm]" } th { "Configuration" } th { "Reason" } th { "Axes" } } }
                    tbody {}
                }
            }
        }
    }
}

/// The filter's optional external axes: the controller's own track and its
/// positioner or turntable (JSON files or pasted), and whether their values
/// are corrected (`controller_track`, `controller_positioner`,
/// `controller_turntable`, `correct_axes`).
fn filter_axes_fields() -> Markup {
    html! {
        fieldset #filter-axes-fields {
            legend { "External axes (optional): the controller's own, as it believes them; the robot's stored ones are the real" }
            label.wide { "The controller's track (JSON) " input type="file" name="controller_track_file" accept=".json,application/json"; }
            label.wide { "or paste it " textarea name="controller_track" rows="2" placeholder="{\"direction\": …}" {} }
            label { "The face plate's axes "
                select name="controller_plate_kind" {
                    option value="positioner" { "positioner (tilt-rotate)" } option value="turntable" { "turntable" }
                }
            }
            label.wide { "The controller's positioner or turntable (JSON) " input type="file" name="controller_plate_file" accept=".json,application/json"; }
            label.wide { "or paste it " textarea name="controller_plate" rows="2" {} }
            label title="Write the axes' values so the real axes stand where the controller believes the programmed values put them" {
                input type="checkbox" name="correct_axes" value="true"; " correct the axes' values" }
        }
    }
}

/// Predict poses from joint readings (`POST …/predict`) for robot `id`:
/// every option of the API — model, tool, frame (tracker, base or a work
/// object), payload, a second orientation convention and the external
/// axes' values `e1`, `e2`, `e3` (the robot's stored track and positioner).
pub(super) fn predict_section(
    id: i64,
    versions: &[VersionRow],
    tools: &[CellItemRow],
    work_objects: &[CellItemRow],
) -> Markup {
    html! {
        section #predict-section {
            h2 { "Predict poses" }
            p.note { "Controller joint readings in degrees, one reading a line (an id first is optional: p1, 10, -80, 95, 0, 45, 0); the pose of the measured point or of a tool, in mm and degrees (R = Rz·Ry·Rx), and in a controller's convention when one is chosen." }
            p.note #predict-axes-note { "External axes, as the controller shows them, through the robot's stored track and positioner: e1 alone is the track's value [mm]; e1, e2 the positioner's tilt and rotate [°], the poses then on its face plate (keep the first Frame entry); e1, e2, e3 the track's value [mm] and, beside it, the positioner's tilt and rotate [°]. On the turntable (ticked): e1 is the stored turntable's value [°], or e2 beside the track's e1. Leave them empty for none; the service refuses a combination the stored axes do not fit, saying why." }
            form #predict data-action="predict" data-robot=(id) {
                label.wide { "Joint readings " textarea name="readings" rows="3" placeholder="p1, 10, -80, 95, 0, 45, 0" {} }
                (model_select(versions))
                label { "Tool "
                    select name="tool" {
                        option value="" { "the measured point" }
                        @for t in tools { option value=(t.name) { (t.name) } }
                    }
                }
                label { "Frame "
                    select name="frame" {
                        // No frame sent: the tracker's, or the positioner's face plate with e2.
                        option value="" { "tracker (measurement frame); the positioner's face plate with e2" }
                        option value="base" { "robot base" }
                        @for w in work_objects { option value={ "wobj:" (w.name) } { "work object " (w.name) } }
                    }
                }
                label title="The payload the compliance and compensation use; the version's payload when empty" { "Payload [kg] "
                    input name="payload_kg" type="number" step="any" min="0" max=(crate::http::PAYLOAD_MAX_KG); }
                label { "Orientation also as "
                    select name="convention" {
                        option value="" { "rx, ry, rz only" }
                        @for c in OrientationConvention::ALL { option value=(c.name()) { (c.name()) } }
                    }
                }
                label { "e1 (track [mm], or the positioner's tilt [°] without a track) "
                    input name="e1" type="number" step="any"; }
                label { "e2 (the positioner's tilt [°] beside a track, else its rotate) "
                    input name="e2" type="number" step="any"; }
                label { "e3 (the positioner's rotate [°] beside a track) "
                    input name="e3" type="number" step="any"; }
                label title="The part is on the robot's stored turntable: e1 is its value [°] (e2 beside a track's e1), the poses on its face plate" {
                    input type="checkbox" name="turntable" value="true"; " on the turntable" }
                button type="submit" { "Predict" }
            }
            div #predict-result hidden {
                p #predict-summary {}
                table #predict-table {
                    thead { tr { th { "Id" } th { "Status" } th { "x [mm]" } th { "y [mm]" } th { "z [mm]" } th { "rx [°]" } th { "ry [°]" } th { "rz [°]" } th #predict-convention { "Convention" } th { "Note" } } }
                    tbody {}
                }
            }
        }
    }
}
