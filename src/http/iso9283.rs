//! `POST /v1/iso9283`: ISO 9283 pose accuracy and repeatability (AP, RP,
//! APa/b/c, ±RPa/b/c) and distance accuracy and repeatability (AD, RD) from
//! measured cycles of the standard's test cube, for one or more tests side by
//! side (e.g. the nominal and the filtered program), each figure with its
//! outcome (`core::iso9283::outcome`): computed, or not with a typed reason.
//! The plan's commanded poses and the measured cycles come as JSON keyed by
//! pose (`P1` … `P5`), cycle `k` the `k`-th entry (`null`: not measured).
//!
//! `POST /v1/iso9283/csv`: the same figures from the two CSV texts of
//! `robocal iso9283 --plan P --measured M` (a grammar the spec cannot state:
//! an unreadable CSV is 422 naming the test, the file and the line).
//!
//! Both take optional `conditions` (robot id and version, date, load,
//! speed, measurement) and answer them resolved beside the figures — the
//! robot's name and the version's SHA-256 from the store — or, with
//! `Accept: text/html`, the ISO 9283 report page (`report::iso9283`).

use super::input::{object_or_null, objects, present, present_int};
use super::{ApiError, ApiJson, AppState};
use crate::report::iso9283::render_iso9283_html;
use crate::service;
use crate::service::iso9283::{ConditionsCommand, Iso9283CsvTest, Iso9283Test};
use axum::extract::State;
use axum::http::{header, HeaderMap};
use axum::response::{IntoResponse, Response};
use robocal_core::check::iso9283::outcome::{CommandedPose, CycleReading, PoseData, CYCLES_MAX};
use robocal_core::check::iso9283::Assessment;
use serde::{Deserialize, Deserializer, Serialize};
use std::collections::BTreeMap;

/// Longest test label (characters).
pub const LABEL_MAX: usize = 200;

/// The standard's poses of the test cube.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Deserialize)]
pub enum PoseName {
    /// Pose P1, the cube's centre.
    P1,
    /// Pose P2, 10 % of the diagonal from corner C1 towards C7.
    P2,
    /// Pose P3, 10 % of the diagonal from corner C2 towards C8.
    P3,
    /// Pose P4, 10 % of the diagonal from corner C7 towards C1.
    P4,
    /// Pose P5, 10 % of the diagonal from corner C8 towards C2.
    P5,
}

impl PoseName {
    /// Every pose, P1 to P5.
    pub const ALL: [PoseName; 5] = [
        PoseName::P1,
        PoseName::P2,
        PoseName::P3,
        PoseName::P4,
        PoseName::P5,
    ];

    /// The pose's key in requests and answers: `P1` … `P5`.
    pub fn name(self) -> &'static str {
        match self {
            PoseName::P1 => "P1",
            PoseName::P2 => "P2",
            PoseName::P3 => "P3",
            PoseName::P4 => "P4",
            PoseName::P5 => "P5",
        }
    }
}

/// A record that must be a JSON object (not `null`, not an array).
#[derive(Debug)]
struct Rec<T>(T);

impl<'de, T: Deserialize<'de>> Deserialize<'de> for Rec<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        object_or_null(d)?
            .map(Rec)
            .ok_or_else(|| serde::de::Error::custom("expected a JSON object, not null"))
    }
}

/// A cycle's entry: an object, or `null` for a cycle not measured.
#[derive(Debug)]
struct Slot(Option<CycleIn>);

impl<'de> Deserialize<'de> for Slot {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        object_or_null(d).map(Slot)
    }
}

/// A commanded pose of the plan [mm, deg].
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct CommandedIn {
    xyz_mm: Vec<f64>,
    #[serde(default, deserialize_with = "present")]
    abc_deg: Option<Vec<f64>>,
}

/// An attained pose of one cycle [mm, deg].
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct CycleIn {
    xyz_mm: Vec<f64>,
    #[serde(default, deserialize_with = "present")]
    abc_deg: Option<Vec<f64>>,
}

/// One test of the request.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct TestIn {
    label: String,
    plan: BTreeMap<PoseName, Rec<CommandedIn>>,
    measured: BTreeMap<PoseName, Vec<Slot>>,
}

/// The test's conditions as a request states them.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct ConditionsIn {
    #[serde(default, deserialize_with = "present_int")]
    robot_id: Option<i64>,
    #[serde(default, deserialize_with = "present_int")]
    version: Option<i64>,
    #[serde(default, deserialize_with = "present")]
    date: Option<String>,
    #[serde(default, deserialize_with = "present")]
    load_kg: Option<f64>,
    #[serde(default, deserialize_with = "present")]
    speed_percent: Option<f64>,
    #[serde(default, deserialize_with = "present")]
    measurement: Option<String>,
}

/// Longest `conditions.measurement` (characters).
pub const MEASUREMENT_MAX: usize = 500;
/// Largest `conditions.load_kg`.
pub const LOAD_MAX_KG: f64 = 10_000.0;
/// Largest `conditions.speed_percent`.
pub const SPEED_MAX_PERCENT: f64 = 1_000.0;

impl ConditionsIn {
    fn command(self) -> Result<ConditionsCommand, ApiError> {
        let within = |what: &str, v: Option<f64>, max: f64| match v {
            Some(x) if !(x.is_finite() && (0.0..=max).contains(&x)) => Err(ApiError::invalid(
                format!("`conditions.{what}`: 0 to {max}, got {x}"),
            )),
            _ => Ok(()),
        };
        within("load_kg", self.load_kg, LOAD_MAX_KG)?;
        within("speed_percent", self.speed_percent, SPEED_MAX_PERCENT)?;
        if let Some(m) = &self.measurement {
            let n = m.chars().count();
            if n > MEASUREMENT_MAX {
                return Err(ApiError::invalid(format!(
                    "`conditions.measurement`: at most {MEASUREMENT_MAX} characters, got {n}"
                )));
            }
        }
        Ok(ConditionsCommand {
            robot_id: self.robot_id,
            version: self.version,
            date: self.date,
            load_kg: self.load_kg,
            speed_percent: self.speed_percent,
            measurement: self.measurement,
        })
    }
}

/// `POST /v1/iso9283` body.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Iso9283Request {
    #[serde(deserialize_with = "objects")]
    tests: Vec<TestIn>,
    #[serde(default, deserialize_with = "present")]
    conditions: Option<ConditionsIn>,
}

/// One test of the CSV form.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct CsvTestIn {
    label: String,
    plan_csv: String,
    measured_csv: String,
}

/// `POST /v1/iso9283/csv` body.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Iso9283CsvRequest {
    #[serde(deserialize_with = "objects")]
    tests: Vec<CsvTestIn>,
    #[serde(default, deserialize_with = "present")]
    conditions: Option<ConditionsIn>,
}

/// One test's figures.
#[derive(Debug, Serialize)]
struct TestOut {
    label: String,
    #[serde(flatten)]
    figures: Assessment,
}

fn check_label(label: &str) -> Result<(), ApiError> {
    let n = label.chars().count();
    if n > LABEL_MAX {
        return Err(ApiError::invalid(format!(
            "a test label has at most {LABEL_MAX} characters, got {n}"
        )));
    }
    Ok(())
}

fn triple(v: &[f64], what: impl Fn() -> String) -> Result<[f64; 3], ApiError> {
    v.try_into()
        .map_err(|_| ApiError::invalid(format!("{}: expected 3 numbers, got {}", what(), v.len())))
}

/// The poses of one test, in the order P1 … P5: those the plan commands or
/// `measured` lists; cycle `k` is the `k`-th entry of a pose's list.
fn poses(t: &TestIn) -> Result<Vec<PoseData>, ApiError> {
    check_label(&t.label)?;
    if t.plan.is_empty() {
        return Err(ApiError::invalid(format!(
            "test `{}`: the plan commands no pose; give at least one of P1 … P5",
            t.label
        )));
    }
    let mut out = Vec::new();
    for name in PoseName::ALL {
        let (commanded, slots) = (t.plan.get(&name), t.measured.get(&name));
        if commanded.is_none() && slots.is_none() {
            continue;
        }
        let at = |what: &str| format!("test `{}`, {what}.{}", t.label, name.name());
        let commanded = commanded
            .map(|Rec(c)| -> Result<CommandedPose, ApiError> {
                Ok(CommandedPose {
                    xyz_mm: triple(&c.xyz_mm, || at("plan") + ".xyz_mm")?,
                    abc_deg: c
                        .abc_deg
                        .as_deref()
                        .map(|v| triple(v, || at("plan") + ".abc_deg"))
                        .transpose()?,
                })
            })
            .transpose()?;
        let measured = slots
            .map(|slots| -> Result<Vec<CycleReading>, ApiError> {
                if slots.len() > CYCLES_MAX {
                    return Err(ApiError::invalid(format!(
                        "{}: {} cycles; at most {CYCLES_MAX}",
                        at("measured"),
                        slots.len()
                    )));
                }
                let mut cycles = Vec::new();
                for (k, Slot(s)) in slots.iter().enumerate() {
                    let Some(c) = s else { continue };
                    let at = || format!("{}[{k}]", at("measured"));
                    cycles.push(CycleReading {
                        cycle: k as u32 + 1,
                        xyz_mm: triple(&c.xyz_mm, || at() + ".xyz_mm")?,
                        abc_deg: c
                            .abc_deg
                            .as_deref()
                            .map(|v| triple(v, || at() + ".abc_deg"))
                            .transpose()?,
                    });
                }
                Ok(cycles)
            })
            .transpose()?;
        out.push(PoseData {
            name: name.name().to_string(),
            commanded,
            measured,
        });
    }
    Ok(out)
}

/// Whether the client asks for the HTML report (`Accept` lists `text/html`
/// with a non-zero quality).
fn wants_html(headers: &HeaderMap) -> bool {
    headers
        .get_all(header::ACCEPT)
        .iter()
        .filter_map(|v| v.to_str().ok())
        .flat_map(|v| v.split(','))
        .any(|range| {
            let mut parts = range.split(';').map(str::trim);
            let media = parts.next().unwrap_or("");
            let zero = parts.any(|p| {
                p.strip_prefix("q=")
                    .and_then(|q| q.parse::<f64>().ok())
                    .is_some_and(|q| q == 0.0)
            });
            media.eq_ignore_ascii_case("text/html") && !zero
        })
}

/// The figures as JSON (with the conditions) or as the HTML report.
async fn answer(
    state: &AppState,
    headers: &HeaderMap,
    tests: Vec<(String, Assessment)>,
    texts: &[Option<String>],
    conditions: Option<ConditionsIn>,
) -> Result<Response, ApiError> {
    let cmd = conditions.unwrap_or_default().command()?;
    let sets = service::iso9283::measured_sets(&tests, texts);
    let conditions = service::iso9283::conditions(state, cmd, sets).await?;
    if wants_html(headers) {
        let page = render_iso9283_html(&conditions, &tests);
        return Ok(([(header::CONTENT_TYPE, "text/html; charset=utf-8")], page).into_response());
    }
    let tests: Vec<TestOut> = tests
        .into_iter()
        .map(|(label, figures)| TestOut { label, figures })
        .collect();
    Ok(axum::Json(serde_json::json!({ "conditions": conditions, "tests": tests })).into_response())
}

async fn figures(
    State(state): State<AppState>,
    headers: HeaderMap,
    ApiJson(body): ApiJson<Iso9283Request>,
) -> Result<Response, ApiError> {
    let tests = body
        .tests
        .iter()
        .map(|t| {
            Ok(Iso9283Test {
                label: t.label.clone(),
                poses: poses(t)?,
            })
        })
        .collect::<Result<Vec<_>, ApiError>>()?;
    let assessed = service::iso9283::figures(&state, tests).await?;
    answer(&state, &headers, assessed, &[], body.conditions).await
}

async fn figures_csv(
    State(state): State<AppState>,
    headers: HeaderMap,
    ApiJson(body): ApiJson<Iso9283CsvRequest>,
) -> Result<Response, ApiError> {
    let tests = body
        .tests
        .into_iter()
        .map(|t| {
            check_label(&t.label)?;
            Ok(Iso9283CsvTest {
                label: t.label,
                plan_csv: t.plan_csv,
                measured_csv: t.measured_csv,
            })
        })
        .collect::<Result<Vec<_>, ApiError>>()?;
    let texts: Vec<Option<String>> = tests.iter().map(|t| Some(t.measured_csv.clone())).collect();
    let assessed = service::iso9283::figures_csv(&state, tests).await?;
    answer(&state, &headers, assessed, &texts, body.conditions).await
}

/// The routes of the ISO 9283 figures and of the test cube's plan.
pub fn routes() -> Vec<super::Route> {
    vec![
        super::post("/v1/iso9283", figures),
        super::post("/v1/iso9283/csv", figures_csv),
        super::post("/v1/robots/{id}/iso9283/plan", super::iso9283_plan::plan),
    ]
}
