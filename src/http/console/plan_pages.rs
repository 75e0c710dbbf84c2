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

/// Both sections, for robot `id`.
pub fn plan_sections(id: i64) -> Markup {
    html! {
        section #plan-section {
            h2 { "Plan the measurements" }
            p.note { "Poses chosen for D-optimality of the identification within a box (base frame) and the tracker's line of sight; the standard deviation each parameter would be identified with for the tracker's noise." }
            form #measurement-plan data-action="measurement-plan" data-robot=(id) {
                label { "Poses " input name="poses" type="number" min="1" max="300" step="1" value="30"; }
                label { "Candidates " input name="candidates" type="number" min="1" max="5000" step="1" value="400"; }
                (triple("Box min", "min", [-600.0, -600.0, 0.0]))
                (triple("Box max", "max", [600.0, 600.0, 800.0]))
                (triple("Tracker", "tracker", [2000.0, 0.0, 500.0]))
                label { "Sight cone [°] " input name="max_angle_deg" type="number" step="any" min="0" max="180" value="90"; }
                label { "Tracker noise [mm] " input name="noise_mm" type="number" step="any" min="0" value="0.01"; }
                label { "Seed " input name="seed" type="number" min="0" step="1" value="1"; }
                (language_select(true))
                button type="submit" { "Plan" }
            }
            div #plan-result hidden {
                p #plan-summary {}
                p #plan-downloads {}
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
            form #iso-figures data-action="iso-figures" {
                label { "Test " input name="label" value="nominal"; }
                label.wide { "Plan CSV (filled by the layout above) " textarea name="plan_csv" rows="3" {} }
                label.wide { "Measured cycles CSV " input type="file" name="measured_file" accept=".csv,text/csv"; }
                label.wide { "or paste it " textarea name="measured_csv" rows="3" placeholder="pose,cycle,x_mm,y_mm,z_mm" {} }
                button type="submit" { "Figures" }
            }
            div #iso-result hidden {
                p { a #iso-report-download download="iso9283-report.html" href="#" { "Download the report (HTML)" } }
                table #iso-poses {
                    thead { tr { th { "Pose" } th { "Cycles" } th { "AP [mm]" } th { "APx, APy, APz [mm]" } th { "RP [mm]" } } }
                    tbody {}
                }
                table #iso-distances {
                    thead { tr { th { "Poses" } th { "AD [mm]" } th { "RD [mm]" } } }
                    tbody {}
                }
            }
        }
    }
}
