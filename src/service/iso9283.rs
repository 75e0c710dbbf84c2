//! ISO 9283 pose characteristics from measured cycles (`core::iso9283`):
//! per test, the plan's commanded poses and the attained positions of every
//! cycle give AP, RP, APa/b/c, ±RPa/b/c, AD and RD. Nothing is stored.

use super::ServiceError;
use robocal_core::check::iso9283::csv::{read_cycles_csv, read_plan_csv};
use robocal_core::check::iso9283::{evaluate, Iso9283Figures};

/// Most tests in one request (a nominal and a filtered run side by side).
pub const TESTS_MAX: usize = 8;

/// One test: the plan CSV (`robocal iso9283 plan --csv`) and its measured
/// cycles (`pose,cycle,x_mm,y_mm,z_mm[,rx_deg,ry_deg,rz_deg]`).
#[derive(Debug, Clone)]
pub struct Iso9283Test {
    pub label: String,
    pub plan_csv: String,
    pub measured_csv: String,
}

/// The figures of each test, in order; a test that cannot be read says which
/// and where.
pub async fn figures(
    tests: Vec<Iso9283Test>,
) -> Result<Vec<(String, Iso9283Figures)>, ServiceError> {
    if tests.is_empty() || tests.len() > TESTS_MAX {
        return Err(ServiceError::Invalid(format!(
            "send 1 to {TESTS_MAX} tests, got {}",
            tests.len()
        )));
    }
    tokio::task::spawn_blocking(move || {
        tests
            .into_iter()
            .map(|t| {
                let fail = |what: &str, e: robocal_core::check::iso9283::Iso9283Error| {
                    ServiceError::Invalid(format!("test `{}`, {what}: {e}", t.label))
                };
                let commanded = read_plan_csv(&t.plan_csv).map_err(|e| fail("plan_csv", e))?;
                let cycles = read_cycles_csv(&t.measured_csv, &commanded)
                    .map_err(|e| fail("measured_csv", e))?;
                let f = evaluate(&cycles).map_err(|e| fail("measured_csv", e))?;
                Ok((t.label.clone(), f))
            })
            .collect()
    })
    .await
    .map_err(|e| ServiceError::Internal(format!("iso9283 task: {e}")))?
}
