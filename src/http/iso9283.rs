//! `POST /v1/iso9283`: ISO 9283 pose accuracy and repeatability (AP, RP,
//! APa/b/c, ±RPa/b/c) and distance accuracy and repeatability (AD, RD) from
//! measured cycles of the standard's test cube, for one or more tests side by
//! side (e.g. the nominal and the filtered program). The same as `robocal
//! iso9283 --plan P --measured M`.

use super::{ApiError, ApiJson, AppState};
use crate::service;
use crate::service::iso9283::Iso9283Test;
use axum::extract::State;
use axum::response::{IntoResponse, Response};
use robocal_core::check::iso9283::Iso9283Figures;
use serde::{Deserialize, Serialize};

/// One test of the request.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TestIn {
    pub label: String,
    pub plan_csv: String,
    pub measured_csv: String,
}

/// `POST /v1/iso9283` body.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Iso9283Request {
    pub tests: Vec<TestIn>,
}

/// One test's figures.
#[derive(Debug, Serialize)]
pub struct TestFigures {
    pub label: String,
    pub figures: Iso9283Figures,
}

pub async fn figures(
    State(_state): State<AppState>,
    ApiJson(body): ApiJson<Iso9283Request>,
) -> Result<Response, ApiError> {
    let tests = body
        .tests
        .into_iter()
        .map(|t| Iso9283Test {
            label: t.label,
            plan_csv: t.plan_csv,
            measured_csv: t.measured_csv,
        })
        .collect();
    let out: Vec<TestFigures> = service::iso9283::figures(tests)
        .await?
        .into_iter()
        .map(|(label, figures)| TestFigures { label, figures })
        .collect();
    Ok(axum::Json(serde_json::json!({ "tests": out })).into_response())
}

pub fn routes() -> Vec<super::Route> {
    vec![super::post("/v1/iso9283", figures)]
}
