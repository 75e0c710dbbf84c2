//! Built-in robot presets. Values the thesis does not give are stated as
//! assumptions inside each model (`RobotModel::assumptions`).
//!
//! - `ys100`: Hyundai YS100, thesis Table 2.1 (modified DH, β on joint 3), link
//!   masses eq. 3.13, payload 110 kg.
//! - `hh800`: Hyundai HH800, thesis Table 4.1 with the PQRS parallelogram, payload 745 kg.
//! - `ur5`, `ur10`: Universal Robots, standard DH imported by regrouping.

use super::description::{
    ClosedLoopDescription, DhConvention, JointDescription, ModelDescription, PayloadDescription,
    ToolDescription,
};
use super::error::ModelError;
use super::robot::{RobotModel, G0};

/// Names of the built-in robot models [`preset`] knows.
pub const PRESETS: [&str; 4] = ["ys100", "hh800", "ur5", "ur10"];

fn row(alpha_deg: f64, a_mm: f64, d_mm: f64, limits_deg: [f64; 2]) -> JointDescription {
    JointDescription {
        alpha_deg,
        a_mm,
        beta_deg: 0.0,
        b_mm: 0.0,
        d_mm,
        theta_offset_deg: 0.0,
        parallel: None,
        limits_deg,
        sign: 1.0,
        zero_deg: 0.0,
        mass_kg: 0.0,
        com_mm: [0.0; 3],
        compliance_rad_per_nm: 0.0,
    }
}

/// Centre of mass halfway between frame k's origin and frame k+1's origin at the
/// zero configuration, in frame k: `0.5 · (a_k, −d_{k+1}·sin α_k, d_{k+1}·cos α_k)`.
fn midpoint_coms(rows: &mut [JointDescription]) {
    let n = rows.len();
    for k in 0..n - 1 {
        let (al, a, d) = (
            rows[k + 1].alpha_deg.to_radians(),
            rows[k + 1].a_mm,
            rows[k + 1].d_mm,
        );
        rows[k].com_mm = [0.5 * a, -0.5 * d * al.sin(), 0.5 * d * al.cos()];
    }
    rows[n - 1].com_mm = [0.0, 0.0, 0.0];
}

fn ys100() -> ModelDescription {
    let mut joints = vec![
        row(0.0, 0.0, 480.0, [-180.0, 180.0]),
        row(90.0, 320.0, 0.0, [20.0, 160.0]),
        row(0.0, 870.0, 0.0, [-110.0, 90.0]),
        row(90.0, 200.0, 1030.0, [-180.0, 180.0]),
        row(-90.0, 0.0, 0.0, [-125.0, 125.0]),
        row(90.0, 0.0, 185.0, [-180.0, 180.0]),
    ];
    for (j, m) in joints
        .iter_mut()
        .zip([196.7, 79.25, 170.27, 10.58, 22.33, 2.0])
    {
        j.mass_kg = m;
    }
    midpoint_coms(&mut joints);
    ModelDescription {
        name: "ys100".into(),
        convention: DhConvention::Modified,
        joints,
        tool: ToolDescription {
            xyz_mm: [200.0, 50.0, 500.0],
            rpy_deg: [0.0; 3],
        },
        closed_loop: None,
        payload: PayloadDescription {
            com_frame: Default::default(),
            mass_kg: 110.0,
            com_mm: [-200.0, -50.0, -250.0],
            ..PayloadDescription::default()
        },
        gravity_mps2: [0.0, 0.0, -G0],
        assumptions: vec![
            "geometry: thesis Table 2.1 (its d column is labelled deg; read as metres)".into(),
            "link masses: thesis eq. 3.13; payload 110 kg".into(),
            "centres of mass (not in the seed): each link's CoM halfway between its frame origin and the next frame origin at zero joints; link 6 on its axis".into(),
            "payload CoM (not in the seed): 250 mm out along the flange axis, i.e. (-200, -50, -250) mm in the tool frame".into(),
            "joint limits (not in the seed): J1 ±180, J2 20..160, J3 -110..90, J4 ±180, J5 ±125, J6 ±180 deg".into(),
        ],
        joint_maps: None,
    }
}

fn hh800() -> ModelDescription {
    let mut joints = vec![
        row(0.0, 0.0, 1200.0, [-180.0, 180.0]),
        row(90.0, 515.0, 0.0, [50.0, 130.0]),
        row(0.0, 1600.0, 0.0, [-40.0, 40.0]),
        row(90.0, 350.0, 1900.0, [-180.0, 180.0]),
        row(-90.0, 0.0, 0.0, [-120.0, 120.0]),
        row(90.0, 0.0, 445.0, [-180.0, 180.0]),
    ];
    for (j, m) in joints
        .iter_mut()
        .zip([2500.0, 1200.0, 900.0, 500.0, 150.0, 60.0])
    {
        j.mass_kg = m;
    }
    midpoint_coms(&mut joints);
    ModelDescription {
        name: "hh800".into(),
        convention: DhConvention::Modified,
        joints,
        tool: ToolDescription {
            xyz_mm: [200.0, 200.0, 200.0],
            rpy_deg: [0.0; 3],
        },
        closed_loop: Some(ClosedLoopDescription {
            passive_joint: 3,
            l3_mm: 800.0,
            l4_mm: 1600.0,
            l5_mm: 800.0,
            xi_deg: -90.0,
        }),
        payload: PayloadDescription {
            com_frame: Default::default(),
            mass_kg: 745.0,
            com_mm: [-200.0, -200.0, 100.0],
            ..PayloadDescription::default()
        },
        gravity_mps2: [0.0, 0.0, -G0],
        assumptions: vec![
            "geometry and loop lengths: thesis Table 4.1; L3 fixed for scale".into(),
            "joint 3 is the crank motor; the passive joint θ3p = φ − θ2 − ξ with ξ = -90° so that θ2 = 90°, θ3 = 0 gives θ3p = 0 (the thesis prints ξ = 90° with its own angle references)".into(),
            "link masses (not in the seed): 2500, 1200, 900, 500, 150, 60 kg; crank and rod masses neglected".into(),
            "centres of mass (not in the seed): halfway between consecutive frame origins at zero joints".into(),
            "payload 745 kg (thesis), CoM 300 mm out along the flange axis (assumed)".into(),
            "joint limits (not in the seed): J2 50..130, J3 -40..40 deg keep the parallelogram away from its flat singularity".into(),
        ],
        joint_maps: None,
    }
}

/// Universal Robots standard DH with their published link masses and centres of
/// mass (given in the distal DH frames).
fn ur(
    name: &str,
    a: [f64; 6],
    d: [f64; 6],
    mass: [f64; 6],
    com: [[f64; 3]; 6],
) -> ModelDescription {
    let alpha = [90.0, 0.0, 0.0, 90.0, -90.0, 0.0];
    let joints = (0..6)
        .map(|k| {
            let mut r = row(alpha[k], a[k], d[k], [-360.0, 360.0]);
            r.mass_kg = mass[k];
            r.com_mm = com[k];
            r
        })
        .collect();
    ModelDescription {
        name: name.into(),
        convention: DhConvention::Standard,
        joints,
        tool: ToolDescription::default(),
        closed_loop: None,
        payload: PayloadDescription::default(),
        gravity_mps2: [0.0, 0.0, -G0],
        assumptions: vec![
            "geometry, masses and centres of mass: Universal Robots' published standard DH and dynamics tables".into(),
            "tool: flange (set the TCP offset for your tool)".into(),
        ],
        joint_maps: None,
    }
}

/// The model description of a preset, or an error naming the known presets.
pub fn preset_description(name: &str) -> Result<ModelDescription, ModelError> {
    match name.to_ascii_lowercase().as_str() {
        "ys100" => Ok(ys100()),
        "hh800" => Ok(hh800()),
        "ur5" => Ok(ur(
            "ur5",
            [0.0, -425.0, -392.25, 0.0, 0.0, 0.0],
            [89.159, 0.0, 0.0, 109.15, 94.65, 82.3],
            [3.7, 8.393, 2.275, 1.219, 1.219, 0.1879],
            [
                [0.0, -25.61, 1.93],
                [212.5, 0.0, 113.36],
                [150.0, 0.0, 26.5],
                [0.0, -1.8, 16.34],
                [0.0, 1.8, 16.34],
                [0.0, 0.0, -1.159],
            ],
        )),
        "ur10" => Ok(ur(
            "ur10",
            [0.0, -612.0, -572.3, 0.0, 0.0, 0.0],
            [127.3, 0.0, 0.0, 163.941, 115.7, 92.2],
            [7.1, 12.7, 4.27, 2.0, 2.0, 0.365],
            [
                [21.0, 0.0, 27.0],
                [380.0, 0.0, 158.0],
                [240.0, 0.0, 68.0],
                [0.0, 7.0, 18.0],
                [0.0, 7.0, 18.0],
                [0.0, 0.0, -26.0],
            ],
        )),
        _ => Err(ModelError::UnknownPreset(name.to_string())),
    }
}

/// A preset robot model.
pub fn preset(name: &str) -> Result<RobotModel, ModelError> {
    preset_description(name)?.to_model()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_build_and_mark_parallel_axes() {
        for name in PRESETS {
            let m = preset(name).unwrap();
            assert_eq!(m.dof(), 6, "{name}");
        }
        let ys = preset("ys100").unwrap();
        let par: Vec<bool> = ys.links.iter().map(|l| l.parallel).collect();
        assert_eq!(par, [false, false, true, false, false, false]);
        let ur = preset("ur5").unwrap();
        let par: Vec<bool> = ur.links.iter().map(|l| l.parallel).collect();
        assert_eq!(par, [false, false, true, true, false, false]);
        assert!(preset("hh800").unwrap().closed_loop.is_some());
        assert!(matches!(preset("kr16"), Err(ModelError::UnknownPreset(_))));
    }
}
