//! The console's planning sections of a robot page: a measurement plan
//! (`POST …/measurement-plans`: D-optimal poses in a box within the
//! tracker's sight, the parameters' predicted standard deviations, the
//! joints CSV and the program to download) and ISO 9283 (`POST
//! …/iso9283/plan`: the test cube and its cycle program; `POST
//! /v1/iso9283/csv`: the figures from the plan CSV and the measured cycles,
//! and the report page to download). Lengths in mm, base frame; angles in
//! degrees, `R = Rz·Ry·Rx`.

use maud::{html, Markup};

/// Three number inputs `{prefix}_x`, `_y`, `_z` with a label each.
fn triple(label: &str, prefix: &str, values: [f64; 3]) -> Markup {
    html! {
        @for (axis, v) in ["x", "y", "z"].iter().zip(values) {
            label { (label) " " (axis) " [mm] "
                input name={ (prefix) "_" (axis) } type="number" step="any" value=(v) required;
            }
        }
    }
}

/// The program languages, with a "none" choice first when `optional`.
fn language_select(optional: bool) -> Markup {
    html! {
        label { "Program "
            select name="language" {
                @if optional { option value="" { "none" } }
                option value="krl" { "KUKA KRL" } option value="rapid" { "ABB RAPID" }
                option value="fanuc" { "Fanuc TP" } option value="urscript" { "URScript" }
            }
        }
    }
}

/// The measurement plan's subject: robot poses, poses over a track, a
/// positioner's sweeps or a turntable's sweep (`what`; the matching
/// fieldset shows).
fn what_to_plan() -> Markup {
    html! {
        label { "What to plan "
            select name="what" {
                option value="robot" { "robot poses" } option value="track" { "robot poses over a track" }
                option value="positioner" { "a positioner's sweeps" } option value="turntable" { "a turntable's sweep" }
            }
        }
    }
}

/// A nominal axis's JSON (file or pasted) and, for a face plate, the
/// reflectors' design positions, inputs named `{what}_…`.
fn nominal_inputs(what: &str, reflectors: bool) -> Markup {
    html! {
        label.wide { "Nominal " (what) " (JSON) " input type="file" name={ (what) "_file" } accept=".json,application/json"; }
        label.wide { "or paste it " textarea name={ (what) "_json" } rows="2" {} }
        @if reflectors {
            label.wide title="The reflectors' design positions on the face plate [mm]; the first is the reference" { "Reflectors (x, y, z [mm], one a line) "
                textarea name={ (what) "_reflectors" } rows="2" placeholder="400, 0, 20" {} }
        }
    }
}

/// A column select `name` (`e1` … `e6`), "API default" first.
fn column_select(label: &str, name: &str) -> Markup {
    html! {
        label { (label) " "
            select name=(name) {
                option value="" { "default" }
                @for c in ["e1", "e2", "e3", "e4", "e5", "e6"] { option value=(c) { (c) } }
            }
        }
    }
}

/// A sweep's lowest and highest value and its count, each empty for the
/// API's default (inputs `{prefix}_min`, `_max`, `_values`).
fn sweep_inputs(label: &str, prefix: &str, unit: &str, default: &str) -> Markup {
    html! {
        label { (label) " from [" (unit) "] " input name={ (prefix) "_min" } type="number" step="any" placeholder=(default); }
        label { "to [" (unit) "] " input name={ (prefix) "_max" } type="number" step="any"; }
        label { "values " input name={ (prefix) "_values" } type="number" min="4" max="150" step="1" placeholder="default"; }
    }
}

/// The inputs of a plan over a track, a positioner or a turntable, each in
/// its fieldset, shown when chosen; empty fields take the API's defaults.
fn axes_plan_fields() -> Markup {
    html! {
        fieldset.plan-what data-what="track" hidden {
            legend { "Over a track: poses per station (Poses above, e.g. 4) at stations over its travel; the box, the tracker and the sight as above (the tracker in the cell frame)" }
            (nominal_inputs("track", false))
            label { "Stations " input name="stations" type="number" min="5" step="1" placeholder="one every 400 mm"; }
            label { "Travel from [mm] " input name="track_travel_min" type="number" step="any" placeholder="the track's"; }
            label { "to [mm] " input name="track_travel_max" type="number" step="any"; }
            (column_select("Column", "track_column"))
        }
        fieldset.plan-what data-what="positioner" hidden {
            legend { "A positioner's sweeps (the noise, program and name above apply)" }
            (nominal_inputs("positioner", true))
            (sweep_inputs("Tilt", "tilt", "°", "-90"))
            (sweep_inputs("Rotate", "rotate", "°", "-165"))
            (column_select("Tilt column", "tilt_column"))
            (column_select("Rotate column", "rotate_column"))
        }
        fieldset.plan-what data-what="turntable" hidden {
            legend { "A turntable's sweep (the noise, program and name above apply)" }
            (nominal_inputs("turntable", true))
            (sweep_inputs("Sweep", "travel", "°", "-165"))
            (column_select("Column", "turntable_column"))
        }
    }
}

/// The answer of a plan over the axes: a track's stations, a face plate's
/// σ per axis and per reflector.
fn axes_plan_results() -> Markup {
    html! {
        table #plan-stations hidden {
            thead { tr { th { "Station [mm]" } th { "Points" } th { "In sight" } th { "σ position [mm]" } th { "σ angles x, y, z [arcsec]" } } }
            tbody {}
        }
        table #plan-sigma hidden {
            thead { tr { th { "Axis" } th { "σ direction [°]" } th { "σ point [mm]" } th { "σ zero offset [°]" } th { "σ scale" } } }
            tbody {}
        }
        p #plan-reflector-sigma hidden {}
    }
}

/// Both sections, for robot `id`.
pub(super) fn plan_sections(id: i64) -> Markup {
    html! {
        section #plan-section {
            h2 { "Plan the measurements" }
            p.note { "Poses chosen for D-optimality of the identification within a box (base frame) and the tracker's line of sight (a cone about the reflector's axis); the standard deviation each parameter would be identified with for the tracker's noise, at the payload given." }
            form #measurement-plan data-action="measurement-plan" data-robot=(id) {
                (what_to_plan())
                label { "Poses " input name="poses" type="number" min="1" max="300" step="1" value="30"; }
                label { "Candidates " input name="candidates" type="number" min="1" max="5000" step="1" value="400"; }
                (triple("Box min", "min", [-600.0, -600.0, 0.0]))
                (triple("Box max", "max", [600.0, 600.0, 800.0]))
                (triple("Tracker", "tracker", [2000.0, 0.0, 500.0]))
                @for (axis, v) in ["x", "y", "z"].iter().zip([0.0, 0.0, 1.0]) {
                    label title="The reflector's axis in the tool frame (not zero); the sight cone is about it" { "Reflector axis " (axis) " "
                        input name={ "axis_" (axis) } type="number" step="any" value=(v) required;
                    }
                }
                label { "Sight cone [°] " input name="max_angle_deg" type="number" step="any" min="0" max="180" value="90"; }
                label { "Tracker noise [mm] " input name="noise_mm" type="number" step="any" min="0" value="0.01"; }
                label title="The payload carried while measuring; the robot's when empty" { "Payload [kg] "
                    input name="payload_kg" type="number" step="any" min="0" max=(crate::http::PAYLOAD_MAX_KG); }
                label { "Seed " input name="seed" type="number" min="0" step="1" value="1"; }
                (axes_plan_fields())
                (language_select(true))
                label { "Program name " input name="name" pattern="[A-Za-z][A-Za-z0-9_]{0,23}" placeholder="plan"; }
                button type="submit" { "Plan" }
            }
            div #plan-result hidden {
                p #plan-summary {}
                p #plan-downloads {}
                (axes_plan_results())
                table #plan-params {
                    thead { tr { th { "Method" } th { "Parameter" } th { "Predicted std" } th { "Unit" } } }
                    tbody {}
                }
            }
        }
        section #iso-section {
            h2 { "ISO 9283 pose accuracy and repeatability" }
            p.note { "1. Lay out the test cube in a box (base frame) on a model version and get its plan CSV and cycle program. 2. Run the program, measure every pose of every cycle. 3. Give the plan CSV and the measured cycles (pose,cycle,x_mm,y_mm,z_mm[,rx_deg,ry_deg,rz_deg]) for AP, RP, AD and RD, and the report." }
            form #iso-plan data-action="iso-plan" data-robot=(id) {
                (triple("Box min", "min", [150.0, -350.0, 100.0]))
                (triple("Box max", "max", [650.0, 350.0, 600.0]))
                label { "Commands "
                    select name="commands" { option value="filtered" { "filtered (calibrated)" } option value="nominal" { "nominal" } }
                }
                (language_select(true))
                label { "Cycles " input name="cycles" type="number" min="2" max="1000" step="1" value="30"; }
                button type="submit" { "Lay out the cube" }
            }
            div #iso-plan-result hidden {
                p #iso-plan-summary {}
                p #iso-plan-downloads {}
                table #iso-plan-poses {
                    thead { tr { th { "Pose" } th { "x, y, z [mm] (measurement frame)" } th { "a, b, c [°]" } th { "Joints [°]" } } }
                    tbody {}
                }
            }
            form #iso-figures data-action="iso-figures" data-robot=(id) {
                label.wide { "Plan CSV (filled by the layout above) " textarea name="plan_csv" rows="3" {} }
                fieldset {
                    legend { "Test 1" }
                    label { "Label " input name="label" value="before"; }
                    label.wide { "Measured cycles CSV " input type="file" name="measured_file" accept=".csv,text/csv"; }
                    label.wide { "or paste it " textarea name="measured_csv" rows="2" placeholder="pose,cycle,x_mm,y_mm,z_mm" {} }
                }
                fieldset {
                    legend { "Test 2 (optional: side by side with test 1, with the change)" }
                    label { "Label " input name="label_2" value="after"; }
                    label.wide { "Measured cycles CSV " input type="file" name="measured_file_2" accept=".csv,text/csv"; }
                    label.wide { "or paste it " textarea name="measured_csv_2" rows="2" placeholder="pose,cycle,x_mm,y_mm,z_mm" {} }
                }
                fieldset {
                    legend { "Test conditions (stated in the report with this robot, its active version and the model's SHA-256)" }
                    label { "Date " input name="date" type="date"; }
                    label { "Load [kg] " input name="load_kg" type="number" step="any" min="0" max=(crate::http::PAYLOAD_MAX_KG); }
                    label { "Speed [%] " input name="speed_percent" type="number" step="any" min="0" max="100"; }
                    label.wide { "Measurement " input name="measurement" maxlength="200" placeholder="e.g. laser tracker, serial number, SMR"; }
                }
                button type="submit" { "Figures" }
            }
            div #iso-result hidden {
                p { a #iso-report-download download="iso9283-report.html" href="#" { "Download the report (HTML)" } }
                p #iso-conditions {}
                table #iso-poses {
                    thead {}
                    tbody {}
                }
                table #iso-distances {
                    thead {}
                    tbody {}
                }
            }
        }
    }
}
