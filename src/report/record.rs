//! The report's "Record" section: what was fitted, on which data, by which
//! robocal (`service::record::CalibrationRecord`).

use crate::service::record::CalibrationRecord;
use maud::{html, Markup};

/// The record as a section of the report page.
pub fn record_section(r: &CalibrationRecord) -> Markup {
    html! {
        section {
            h2 { "Record" }
            dl.meta {
                div { dt { "robocal" } dd { (r.robocal_version) } }
                div { dt { "Robot" } dd { (r.robot_name) " (id " (r.robot_id) ")" } }
                div { dt { "Calibration" } dd { (r.calibration_id) " · " (r.status) } }
                div { dt { "Queued" } dd { (r.created_at) } }
                div { dt { "Finished" } dd { (r.finished_at.as_deref().unwrap_or("—")) } }
                div { dt { "Methods" } dd { (r.methods.join(", ")) } }
                div { dt { "Versions" } dd {
                    @if r.versions.is_empty() { "none" }
                    @for (i, v) in r.versions.iter().enumerate() {
                        @if i > 0 { ", " }
                        "v" (v.version) " " (v.method) @if v.active { " (active)" }
                    }
                } }
            }
            table {
                thead { tr { th { "Set" } th { "Used as" } th { "Name" } th { "Rows" } th { "SHA-256 of the upload" } } }
                tbody {
                    @for s in &r.sets {
                        tr {
                            td { (s.id) }
                            td { (s.used_as) }
                            td { (s.name.as_deref().unwrap_or("deleted")) }
                            td { (s.row_count.map_or("—".to_string(), |n| n.to_string())) }
                            td { code { (s.sha256.as_deref().unwrap_or("—")) } }
                        }
                    }
                }
            }
            p.rule { "Settings: " code { (r.options.to_string()) } }
        }
    }
}
