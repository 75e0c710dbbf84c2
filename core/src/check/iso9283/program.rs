//! The cycle program of an ISO 9283 plan: the joint commands of P1 … P5 in
//! the plan's order, `n` times (the standard's cycles), each motion commented
//! `P<i> cycle <k>` — the names the tracker's points take and
//! [`super::join`] reads back. Joints in the controller convention [deg].

use super::cube::CubePlan;
use super::Iso9283Error;
use crate::program::export::{labelled_joint_program, LabelledJoints};
use crate::program::{Language, ProgramFile};

/// The program `name` in `language` cycling `cycles` times through the
/// plan's poses with a wait of `wait_s` seconds at each.
pub fn cycle_program(
    plan: &CubePlan,
    language: Language,
    name: &str,
    cycles: u32,
    wait_s: f64,
) -> Result<Vec<ProgramFile>, Iso9283Error> {
    let mut joints = Vec::new();
    for p in &plan.poses {
        let q: [f64; 6] = p.joints_deg.as_slice().try_into().map_err(|_| {
            Iso9283Error::InvalidInput(format!(
                "programs need 6 joints, the model has {}",
                p.joints_deg.len()
            ))
        })?;
        joints.push((p.name.as_str(), q));
    }
    let targets: Vec<LabelledJoints> = (1..=cycles)
        .flat_map(|k| {
            joints.iter().map(move |(pose, q)| LabelledJoints {
                label: format!("{pose} cycle {k}"),
                joints_deg: *q,
                track: None,
            })
        })
        .collect();
    let head = format!(
        "robocal ISO 9283 cycles: {} poses, {cycles} cycles, a wait of {wait_s} s at each",
        joints.len()
    );
    Ok(labelled_joint_program(
        language, name, &head, &targets, wait_s,
    ))
}
