//! What `robocal track calibrate` and `robocal positioner calibrate` print and
//! write for a fit judged before it is written: a refusal (`--json`: the
//! reason code and the refusal's fields, nothing written), or the model file
//! written and the fit with its held-out validation (`--json`: one object;
//! a positioner's also says where its readings came from, `readings_from`:
//! a tracker, or touches).
//! Errors of the held-out readings are in mm.

use crate::service::positioners::ReadingsFrom;
use anyhow::Context;
use robocal_core::stats::ErrorStats;
use serde::Serialize;

#[derive(Serialize)]
struct Fitted<'a, F, V> {
    fitted: bool,
    out: &'a str,
    #[serde(skip_serializing_if = "Option::is_none")]
    readings_from: Option<&'a ReadingsFrom>,
    fit: &'a F,
    validation: Option<&'a V>,
}

#[derive(Serialize)]
struct Refusal<'a, R> {
    fitted: bool,
    reason: &'a str,
    #[serde(flatten)]
    refused: &'a R,
}

/// Prints the refusal as JSON when `json`; the caller then returns its error.
pub fn print_refusal<R: Serialize>(json: bool, reason: &str, refused: &R) -> anyhow::Result<()> {
    if json {
        let body = Refusal {
            fitted: false,
            reason,
            refused,
        };
        println!("{}", serde_json::to_string_pretty(&body)?);
    }
    Ok(())
}

/// Writes `model_json` (the `what` file) to `out`; with `json`, returns the
/// fit, where its readings came from (when given) and its validation as one
/// JSON object, else `None` (the caller renders its text report).
pub fn write_fitted<F: Serialize, V: Serialize>(
    what: &str,
    out: &str,
    model_json: String,
    readings_from: Option<&ReadingsFrom>,
    fit: &F,
    validation: Option<&V>,
    json: bool,
) -> anyhow::Result<Option<String>> {
    std::fs::write(out, model_json + "\n")
        .with_context(|| format!("cannot write {what} file {out}"))?;
    if !json {
        return Ok(None);
    }
    let body = Fitted {
        fitted: true,
        out,
        readings_from,
        fit,
        validation,
    };
    Ok(Some(serde_json::to_string_pretty(&body)? + "\n"))
}

pub use crate::service::refusal::code;

/// RMS and max of held-out errors [mm] (`ErrorStats`), as the validations
/// report them.
pub fn rms_and_max_mm(errors_mm: &[f64]) -> (f64, f64) {
    let s = ErrorStats::from_errors_mm(errors_mm);
    (s.rms_mm, s.max_mm)
}
