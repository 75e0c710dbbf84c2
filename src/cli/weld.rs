//! A KRL weld program for the simulated cells (`positioner simulate
//! --robot`, `track simulate`): a torch (tool 1) `LIN` to points of a part,
//! each at its external axes' values, as a controller would run it.
//!
//! Each target points the torch into the part (`C 180` in the work object)
//! and is spun about its axis in 15° steps until every joint the controller
//! computes is 2° clear of the sign its flags record; `S` and `T` are the
//! nominal controller's own (its closed form on the torch, elbow up in front
//! where a spin allows it, else any branch within the limits, the solution
//! nearest the previous target's). A point out of reach is left out and
//! named. Frames: a station's `frame` is the work object in the
//! controller's robot base frame at that station's axis values; points are
//! in the work object [m]; lengths mm in the files.

use nalgebra::Vector3;
use robocal_core::model::calibrated::CompensatedModel;
use robocal_core::model::orientation::{rotation_to, OrientationConvention};
use robocal_core::model::pose::rpy_matrix;
use robocal_core::model::{Pose, Tool};
use robocal_core::program::{kuka_status, kuka_turn};
use robocal_core::solve::ik::{AnalyticIk, Elbow, Shoulder};
use std::fmt::Write as _;

/// The torch: TCP in the flange frame [mm] and its `rpy_deg`.
pub(crate) const TORCH_MM: [f64; 3] = [125.0, 0.0, 216.50635];
pub(crate) const TORCH_RPY_DEG: [f64; 3] = [0.0, 30.0, 0.0];
/// How far every controller joint stays from the sign its flags record [deg].
const FLAG_MARGIN_DEG: f64 = 2.0;

/// Where the controller puts the work object at one set of axis values,
/// and the points to weld there.
pub(crate) struct Station {
    /// The work object in the controller's robot base frame at the values.
    pub(crate) frame: Pose,
    /// The `E1 …,E6 …` of the targets' `E6POS`.
    pub(crate) axes: String,
    /// The values as the output names them (`at axes [10, 20]°`).
    pub(crate) label: String,
    /// The points in the work object [m] and their names (`point [..] mm`).
    pub(crate) points: Vec<(Vector3<f64>, String)>,
}

/// A program's `.src` and `.dat`, and the targets left out.
pub(crate) struct Weld {
    /// `part.src`.
    pub(crate) src: String,
    /// `part.dat`.
    pub(crate) dat: String,
    /// The points left out, named with their station: out of the nominal
    /// robot's reach with the torch pointing into the part.
    pub(crate) left_out: Vec<String>,
}

/// The program `part` for `model`'s nominal robot with the torch: `head`
/// the lines after `DEF part()` (comment, `$TOOL`, `$BASE`); `Err` when no
/// point is within reach.
pub(crate) fn weld(
    model: &CompensatedModel,
    head: &str,
    stations: &[Station],
) -> Result<Weld, String> {
    let mut controller = model.nominal.clone();
    controller.tool = Tool {
        p: Vector3::from(TORCH_MM) * 1e-3,
        rpy: TORCH_RPY_DEG.map(f64::to_radians),
    };
    let ik = AnalyticIk::new(&controller)
        .map_err(|e| format!("the robot's nominal model has no closed form: {e}"))?;
    let mut src = format!("DEF part()\n{head}");
    let mut dat = String::from("DEFDAT part\n");
    let mut previous: Option<Vec<f64>> = None;
    let mut n = 0;
    let mut left_out = Vec::new();
    for station in stations {
        for (at, name) in &station.points {
            // Elbow up in front where the part allows, else any branch.
            let Some((target, q_deg, configuration, q)) =
                [true, false].into_iter().find_map(|upright| {
                    (0..24).find_map(|k| {
                        let spin = (15.0 * f64::from(k)).to_radians();
                        let target = Pose::new(rpy_matrix(std::f64::consts::PI, 0.0, spin), *at);
                        let tcp = station.frame.compose(&target);
                        ik.solve(&tcp, previous.as_deref())
                            .into_iter()
                            .filter(|s| {
                                s.within_limits
                                    && !s.singular
                                    && (!upright
                                        || s.configuration.elbow == Elbow::Up
                                            && s.configuration.shoulder == Shoulder::Front)
                            })
                            .map(|s| {
                                let q_deg: Vec<f64> = controller
                                    .joints_to_controller(&s.q)
                                    .iter()
                                    .map(|q| q.to_degrees())
                                    .collect();
                                (target, q_deg, s.configuration, s.q)
                            })
                            .filter(|c| c.1.iter().all(|q| q.abs() >= FLAG_MARGIN_DEG))
                            .min_by(|a, b| {
                                distance(&a.3, previous.as_deref())
                                    .total_cmp(&distance(&b.3, previous.as_deref()))
                            })
                    })
                })
            else {
                left_out.push(format!("{name} at {}", station.label));
                continue;
            };
            n += 1;
            previous = Some(q.to_vec());
            let s = kuka_status(&q_deg, configuration);
            let abc = rotation_to(OrientationConvention::KukaAbc, &target.r);
            writeln!(src, "LIN XP{n}").expect("a String takes writes");
            writeln!(
                dat,
                "DECL E6POS XP{n}={{X {:.3},Y {:.3},Z {:.3},A {:.3},B {:.3},C {:.3},S {s},T {},{}}}",
                target.p.x * 1e3,
                target.p.y * 1e3,
                target.p.z * 1e3,
                abc[0],
                abc[1],
                abc[2],
                kuka_turn(&q_deg),
                station.axes
            )
            .expect("a String takes writes");
        }
    }
    if n == 0 {
        return Err(format!(
            "none of the part's points is within the nominal robot's reach (every branch within \
             the limits, joints {FLAG_MARGIN_DEG}° clear of 0)"
        ));
    }
    src.push_str("END\n");
    dat.push_str("ENDDAT\n");
    Ok(Weld { src, dat, left_out })
}

/// Sum of absolute joint differences [rad]; 0 without a previous solution.
fn distance(q: &[f64], previous: Option<&[f64]>) -> f64 {
    previous.map_or(0.0, |p| q.iter().zip(p).map(|(a, b)| (a - b).abs()).sum())
}
