//! The ISO 9283 pose characteristics as a self-contained HTML page
//! (`robocal iso9283 --report out.html`): per test, per pose AP, APx/y/z, RP
//! (l̄ + 3·S_l) and APa/b/c, ±RPa/b/c; per pair of poses AD and ±RD — the
//! figures of `core::iso9283::evaluate`, in millimetres and degrees, with the
//! same rounding as the text table (`cli::iso9283::figures_table`).

use super::{page_head, STYLE};
use maud::{html, Markup, DOCTYPE};
use robocal_core::check::iso9283::Iso9283Figures;

/// Four decimals, as the text table prints them.
fn mm(x: f64) -> String {
    format!("{x:.4}")
}

fn abc(v: Option<[f64; 3]>) -> String {
    v.map_or("—".to_string(), |v| {
        format!("{:.4}, {:.4}, {:.4}", v[0], v[1], v[2])
    })
}

/// One test's tables.
pub fn iso9283_section(label: &str, f: &Iso9283Figures) -> Markup {
    html! {
        section {
            h2 { "ISO 9283 pose characteristics: " (label) }
            table {
                thead { tr {
                    th { "pose" } th { "n" } th { "AP [mm]" } th { "APx [mm]" } th { "APy [mm]" }
                    th { "APz [mm]" } th { "RP [mm]" } th { "APa, APb, APc [deg]" } th { "±RPa, ±RPb, ±RPc [deg]" }
                } }
                tbody {
                    @for p in &f.poses {
                        tr {
                            td { (p.pose) } td { (p.cycles) } td { (mm(p.ap_mm)) }
                            td { (mm(p.ap_xyz_mm[0])) } td { (mm(p.ap_xyz_mm[1])) } td { (mm(p.ap_xyz_mm[2])) }
                            td { (mm(p.rp_mm)) } td { (abc(p.ap_abc_deg)) } td { (abc(p.rp_abc_deg)) }
                        }
                    }
                }
            }
            @if !f.distances.is_empty() {
                table {
                    thead { tr {
                        th { "distance" } th { "n" } th { "D_c [mm]" } th { "AD [mm]" } th { "±RD [mm]" }
                    } }
                    tbody {
                        @for d in &f.distances {
                            tr {
                                td { (d.from) "–" (d.to) } td { (d.cycles) } td { (format!("{:.3}", d.commanded_mm)) }
                                td { (mm(d.ad_mm)) } td { (mm(d.rd_mm)) }
                            }
                        }
                    }
                }
            }
        }
    }
}

/// The page: one section per test (label, figures), side by side in order.
pub fn render_iso9283_html(tests: &[(String, Iso9283Figures)]) -> String {
    let title = "ISO 9283 pose characteristics";
    html! {
        (DOCTYPE)
        html lang="en" {
            (page_head(title, STYLE))
            body {
                main {
                    header.top { p.kicker { "robocal " (env!("CARGO_PKG_VERSION")) " · ISO 9283" } h1 { (title) } }
                    @for (label, f) in tests { (iso9283_section(label, f)) }
                    footer {
                        "AP: distance from the commanded position to the barycentre of the attained ones; "
                        "RP = l̄ + 3·S_l; APa/b/c and ±3·S for the orientation angles; AD = D̄ − D_c, "
                        "RD = ±3·S_D between poses (ISO 9283:1998). Millimetres in the frame the attained "
                        "positions were measured in, degrees."
                    }
                }
            }
        }
    }
    .into_string()
}
