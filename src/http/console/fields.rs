//! Form fields more than one console page shows.

use crate::records::VersionRow;
use maud::{html, Markup};

/// The "Model" picker of a solve or a filter: the active version, every
/// stored version (newest first) or the nominal model, sent as `version`.
pub(super) fn model_select(versions: &[VersionRow]) -> Markup {
    html! {
        label { "Model "
            select name="version" {
                option value="active" { "active version" }
                @for ver in versions.iter().rev() {
                    option value=(ver.version) { "v" (ver.version) " " (ver.method) }
                }
                option value="nominal" { "nominal model" }
            }
        }
    }
}
