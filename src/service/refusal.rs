//! A judged fit's refusal in the words the command line and the API share:
//! the reason's code (its serde name) and `not fitted (CODE): MESSAGE`.

use serde::Serialize;

/// The code a reason, term or noise model serialises to (its snake_case
/// name, e.g. `residual_outlier`), as the reports print it; empty for a
/// value that is not one name.
pub fn code<T: Serialize>(value: &T) -> String {
    serde_json::to_value(value)
        .ok()
        .and_then(|v| v.as_str().map(String::from))
        .unwrap_or_default()
}

/// `not fitted (CODE): MESSAGE`, the words of a refused fit.
pub fn detail<T: Serialize>(reason: &T, message: &str) -> String {
    format!("not fitted ({}): {message}", code(reason))
}
