//! How the console shows a check's status: each status
//! (`core::check::CheckStatus`) in its colour (only `ok` is green), as a tag
//! with the shift's size when `shifted`, and the style rules for both.

use super::format::{deg, mm};
use crate::records::CheckRow;
use crate::service::checks::status_of;
use maud::{html, Markup};
use robocal_core::check::{CheckStatus, ShiftSize};

/// The colour a status is drawn in: only `ok` is green.
pub(super) fn status_colour(s: CheckStatus) -> &'static str {
    match s {
        CheckStatus::Ok => "#1e7a3c",
        CheckStatus::Degraded => "#b07d00",
        CheckStatus::Recalibrate => "#b3261e",
        CheckStatus::Shifted => "#7a3fb3",
    }
}

/// The colour of a stored check's status (grey for a name not in the table).
pub(super) fn row_colour(c: &CheckRow) -> &'static str {
    status_of(c).map_or("#5b6475", status_colour)
}

/// The style rules of the statuses (part of the console's one style sheet,
/// whose hash the page's `Content-Security-Policy` names): a tag's
/// background, a table cell's text.
pub(super) fn status_css() -> String {
    CheckStatus::ALL
        .iter()
        .map(|s| {
            let (name, colour) = (s.name(), status_colour(*s));
            format!(".status-tag.{name} {{ background: {colour}; }} .status-{name} {{ color: {colour}; font-weight: 600; }}\n")
        })
        .collect()
}

/// `13.127 mm, 0.2636°`.
pub(super) fn shift_text(s: &ShiftSize) -> String {
    format!("{} mm, {}°", mm(s.translation_mm), deg(s.rotation_deg))
}

/// A status as a coloured tag, with the shift's size when shifted.
pub(super) fn status_tag(s: CheckStatus, shift: Option<&ShiftSize>) -> Markup {
    html! {
        span class={ "status-tag " (s.name()) } title=(s.meaning()) {
            (s.name())
            @if let Some(f) = shift { " " (shift_text(f)) }
        }
    }
}
