//! ISO 9283 pose characteristics from measured cycles (`core::iso9283`):
//! per test, the commanded poses and the attained positions of every cycle
//! give AP, RP, APa/b/c, ±RPa/b/c, AD and RD, each with its outcome
//! (`core::iso9283::outcome`). The tests come as poses ([`figures`]) or as
//! the two CSV texts of `robocal iso9283` ([`figures_csv`]). Nothing is
//! stored.

use super::{AppState, ServiceError};
use robocal_core::check::iso9283::csv::{read_cycles_csv, read_plan_csv};
use robocal_core::check::iso9283::outcome::{CommandedPose, CycleReading, PoseData};
use robocal_core::check::iso9283::{assess, Assessment, Iso9283Error};

/// Most tests in one request (a nominal and a filtered run side by side).
pub const TESTS_MAX: usize = 8;

/// One test: a label and its poses (commanded and measured).
#[derive(Debug, Clone)]
pub struct Iso9283Test {
    pub label: String,
    pub poses: Vec<PoseData>,
}

/// One test as CSV: the plan CSV (`robocal iso9283 plan --csv`) and its
/// measured cycles (`pose,cycle,x_mm,y_mm,z_mm[,rx_deg,ry_deg,rz_deg]`).
#[derive(Debug, Clone)]
pub struct Iso9283CsvTest {
    pub label: String,
    pub plan_csv: String,
    pub measured_csv: String,
}

fn count(n: usize) -> Result<(), ServiceError> {
    if n == 0 || n > TESTS_MAX {
        return Err(ServiceError::Invalid(format!(
            "send 1 to {TESTS_MAX} tests, got {n}"
        )));
    }
    Ok(())
}

fn invalid(label: &str, what: &str, e: Iso9283Error) -> ServiceError {
    ServiceError::Invalid(format!("test `{label}`, {what}: {e}"))
}

/// The figures of each test, in order; values out of bounds name the test.
pub async fn figures(
    state: &AppState,
    tests: Vec<Iso9283Test>,
) -> Result<Vec<(String, Assessment)>, ServiceError> {
    count(tests.len())?;
    super::heavy::run(state, "iso9283", move |_| assess_all(tests)).await?
}

fn assess_all(tests: Vec<Iso9283Test>) -> Result<Vec<(String, Assessment)>, ServiceError> {
    tests
        .into_iter()
        .map(|t| {
            let a = assess(&t.poses).map_err(|e| invalid(&t.label, "poses", e))?;
            Ok((t.label, a))
        })
        .collect()
}

fn csv_poses(t: &Iso9283CsvTest) -> Result<Vec<PoseData>, ServiceError> {
    let commanded = read_plan_csv(&t.plan_csv).map_err(|e| invalid(&t.label, "plan_csv", e))?;
    let cycles = read_cycles_csv(&t.measured_csv, &commanded)
        .map_err(|e| invalid(&t.label, "measured_csv", e))?;
    Ok(commanded
        .iter()
        .zip(cycles)
        .map(|(c, p)| {
            let abc = p.attained_abc_deg.as_ref();
            PoseData {
                name: c.name.clone(),
                commanded: Some(CommandedPose {
                    xyz_mm: c.xyz_mm,
                    abc_deg: c.abc_deg,
                }),
                measured: Some(
                    p.cycles
                        .iter()
                        .zip(&p.attained_mm)
                        .enumerate()
                        .map(|(k, (cycle, xyz))| CycleReading {
                            cycle: *cycle,
                            xyz_mm: *xyz,
                            abc_deg: abc.map(|a| a[k]),
                        })
                        .collect(),
                ),
            }
        })
        .collect())
}

/// The figures of each CSV test, in order; a CSV that cannot be read says
/// which test, which file and where.
pub async fn figures_csv(
    state: &AppState,
    tests: Vec<Iso9283CsvTest>,
) -> Result<Vec<(String, Assessment)>, ServiceError> {
    count(tests.len())?;
    super::heavy::run(state, "iso9283", move |_| {
        let tests = tests
            .iter()
            .map(|t| {
                Ok(Iso9283Test {
                    label: t.label.clone(),
                    poses: csv_poses(t)?,
                })
            })
            .collect::<Result<Vec<_>, ServiceError>>()?;
        assess_all(tests)
    })
    .await?
}
