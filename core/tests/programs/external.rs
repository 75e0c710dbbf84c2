//! What the external-axis program tests (`track.rs`, `positioner.rs`)
//! share: the programs in KRL, RAPID and Fanuc, each target with the text
//! its external axes take; the nominal controller's solution of a target on
//! its flags, nearest the previous joints (closed form); the acceptance's
//! figures. Units as the programs write them: mm and degrees.

use super::*;
use robocal_core::model::orientation::{
    rotation_angle_between, rotation_to, OrientationConvention,
};
use robocal_core::program::{
    abb_cf, fanuc_config, fanuc_config_text, kuka_status, kuka_turn, FilterReport,
};

/// One target as a program writes it: its pose in the work object, the
/// controller joints [deg] and configuration its flags come from, and its
/// external axes as each language writes them.
pub struct Written<'a> {
    pub pose: &'a Pose,
    pub deg: &'a [f64],
    pub conf: Configuration,
    /// KRL: the `E6POS`'s `E1 …,E6 …`.
    pub krl_axes: String,
    /// RAPID: the `robtarget`'s `[eax_a,…,eax_f]`.
    pub rapid_axes: String,
    /// Fanuc: what follows `GP1`'s `R = …` (`,\tE1 = … mm` or a `GP2` block).
    pub fanuc_axes: String,
}

/// A KRL program `name` (`.src` with `head` after its first joint move,
/// `.dat` with one `E6POS` per target), a `LIN` to each.
pub fn krl_program(name: &str, head: &str, targets: &[Written]) -> Vec<ProgramFile> {
    let mut src = format!("DEF {name}()\r\nPTP {{A1 0,A2 90,A3 -20,A4 0,A5 45,A6 0}}\r\n{head}");
    let mut dat = format!("DEFDAT {name}\r\n");
    for (i, w) in targets.iter().enumerate() {
        let (t, abc) = (
            w.pose,
            rotation_to(OrientationConvention::KukaAbc, &w.pose.r),
        );
        src.push_str(&format!("LIN XP{i}\r\n"));
        dat.push_str(&format!(
            "DECL E6POS XP{i}={{X {:.4},Y {:.4},Z {:.4},A {:.4},B {:.4},C {:.4},S {},T {},{}}}\r\n",
            t.p.x * 1e3,
            t.p.y * 1e3,
            t.p.z * 1e3,
            abc[0],
            abc[1],
            abc[2],
            kuka_status(w.deg, w.conf),
            kuka_turn(w.deg),
            w.krl_axes
        ));
    }
    src.push_str("END\r\n");
    dat.push_str("ENDDAT\r\n");
    vec![
        ProgramFile {
            name: format!("{name}.src"),
            text: src,
        },
        ProgramFile {
            name: format!("{name}.dat"),
            text: dat,
        },
    ]
}

/// A RAPID module `name` declaring `data` (tooldata, wobjdata), one
/// `robtarget` per target and a `MoveL` to each with the tool `torch` in
/// work object `part`.
pub fn rapid_program(name: &str, data: &str, targets: &[Written]) -> Vec<ProgramFile> {
    let mut text = format!("MODULE {name}\r\n{data}");
    let mut body = String::from("  PROC main()\r\n");
    for (i, w) in targets.iter().enumerate() {
        let literal = super::rapid::robtarget(w.pose, abb_cf(w.deg, w.conf), &w.rapid_axes);
        text.push_str(&format!("  CONST robtarget p{i}:={literal};\r\n"));
        body.push_str(&format!(
            "    MoveL p{i}, v200, fine, torch\\WObj:=part;\r\n"
        ));
    }
    text.push_str(&body);
    text.push_str("  ENDPROC\r\nENDMODULE\r\n");
    vec![ProgramFile {
        name: format!("{name}.mod"),
        text,
    }]
}

/// A Fanuc program `name` in user frame `uf` with tool 1, a linear motion
/// to each target's position.
pub fn fanuc_program(name: &str, uf: u32, targets: &[Written]) -> Vec<ProgramFile> {
    let mut mn =
        format!("/PROG  {name}\r\n/MN\r\n   1:  UFRAME_NUM={uf} ;\r\n   2:  UTOOL_NUM=1 ;\r\n");
    let mut pos = String::from("/POS\r\n");
    for (i, w) in targets.iter().enumerate() {
        let (t, wpr) = (
            w.pose,
            rotation_to(OrientationConvention::FanucWpr, &w.pose.r),
        );
        mn.push_str(&format!(
            "{:4}:L P[{}] 500mm/sec FINE    ;\r\n",
            i + 3,
            i + 1
        ));
        pos.push_str(&format!(
            "P[{}]{{\r\n   GP1:\r\n\tUF : {uf}, UT : 1,\t\tCONFIG : '{}',\r\n\
             \tX = {:9.3}  mm,\tY = {:9.3}  mm,\tZ = {:9.3}  mm,\r\n\
             \tW = {:9.3} deg,\tP = {:9.3} deg,\tR = {:9.3} deg{}\r\n}};\r\n",
            i + 1,
            fanuc_config_text(&fanuc_config(w.deg, w.conf)),
            t.p.x * 1e3,
            t.p.y * 1e3,
            t.p.z * 1e3,
            wpr[0],
            wpr[1],
            wpr[2],
            w.fanuc_axes
        ));
    }
    pos.push_str("/END\r\n");
    vec![ProgramFile {
        name: format!("{}.LS", name.to_ascii_uppercase()),
        text: mn + &pos,
    }]
}

/// The nominal controller's joints for the tool pose `tcp` (its base
/// frame): its closed-form solutions within the limits that carry the
/// site's flags, the one nearest `previous` (model convention).
pub fn controller_solution(
    ik: &AnalyticIk,
    controller: &RobotModel,
    site: &Site,
    tcp: &Pose,
    previous: Option<&[f64]>,
) -> Option<Vec<f64>> {
    let d = |x: &[f64]| match previous {
        Some(p) => x.iter().zip(p).map(|(u, v)| (u - v).abs()).sum::<f64>(),
        None => 0.0,
    };
    let degrees = |q: &[f64]| -> Vec<f64> {
        controller
            .joints_to_controller(q)
            .iter()
            .map(|v| v.to_degrees())
            .collect()
    };
    ik.solve(tcp, previous)
        .into_iter()
        .filter(|s| s.within_limits)
        .map(|s| s.q.to_vec())
        .filter(|q| site.flags.admits(&degrees(q), ik.configuration(q)))
        .min_by(|a, b| d(a).total_cmp(&d(b)))
}

/// The root-mean-square of `v`.
pub fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

/// How far the true torch is from a true target: its tip [mm] and its
/// orientation [deg].
#[derive(Debug, Clone, Copy)]
pub struct Miss {
    /// The tip's distance [mm].
    pub mm: f64,
    /// The angle between the torch's and the target's orientations [deg].
    pub deg: f64,
}

impl Miss {
    /// The miss of the true torch `got` from the true target `want`.
    pub fn of(got: &Pose, want: &Pose) -> Miss {
        Miss {
            mm: (got.p - want.p).norm() * 1e3,
            deg: rotation_angle_between(&got.r, &want.r).to_degrees(),
        }
    }
}

/// The calibration's validation error a program is judged against: RMS
/// over poses it never fitted, of the tool tip [mm] and of its orientation
/// [deg].
#[derive(Debug, Clone, Copy)]
pub struct Validation {
    /// RMS of the tip's distance [mm].
    pub mm: f64,
    /// RMS of the orientation's angle [deg].
    pub deg: f64,
}

/// The calibrated robot's orientation error [deg], RMS over `n` random
/// configurations it never fitted: the angle between its flange's and the
/// true robot's in the cell frame (the tools' own rotations taken off), the
/// i-th configuration's bases placed by `place(i)`: (the model's, the
/// truth's) base in the cell frame.
pub fn orientation_rms_deg(
    calibrated: &RobotModel,
    truth: &robocal_core::sim::TrueRobot,
    n: usize,
    place: impl Fn(usize) -> (Pose, Pose),
    rng: &mut ChaCha8Rng,
) -> f64 {
    let angles: Vec<f64> = random_configurations(calibrated, n, rng)
        .iter()
        .enumerate()
        .map(|(i, q)| {
            let (model_base, true_base) = place(i);
            let model = model_base.r
                * robocal_core::model::kinematics::fk(calibrated, q)
                    .unwrap()
                    .r
                * tool_pose(calibrated).r.transpose();
            let true_r = true_base.r
                * truth.true_pose_base(q, None).unwrap().r
                * tool_pose(&truth.model).r.transpose();
            rotation_angle_between(&model, &true_r).to_degrees()
        })
        .collect();
    rms(&angles)
}

/// The acceptance's figures, printed and asserted: every filtered target
/// run by the controller, their true torch tips within `1.5 × bound.mm` RMS
/// of the true targets and their orientations within `1.5 × bound.deg`
/// RMS; the unfiltered program's tips more than 1 mm RMS off. `label` says
/// where (`Krl on the track`), `bound_is` what the bound is.
pub fn assert_figures(
    label: &str,
    bound_is: &str,
    bound: Validation,
    filtered: Vec<Option<Miss>>,
    unfiltered: Vec<Option<Miss>>,
) {
    let filtered: Vec<Miss> = filtered
        .into_iter()
        .map(|e| e.expect("the controller runs every filtered target"))
        .collect();
    let unfiltered: Vec<Miss> = unfiltered.into_iter().flatten().collect();
    let mm = |v: &[Miss]| v.iter().map(|m| m.mm).collect::<Vec<f64>>();
    let deg = |v: &[Miss]| v.iter().map(|m| m.deg).collect::<Vec<f64>>();
    let max = |v: &[f64]| v.iter().copied().fold(0.0, f64::max);
    println!(
        "{label}: true torch tip off the true target, filtered rms {:.4} mm (max {:.4}, {} targets), unfiltered rms {:.3} mm (max {:.3}, {} runnable); {bound_is} {:.4} mm",
        rms(&mm(&filtered)),
        max(&mm(&filtered)),
        filtered.len(),
        rms(&mm(&unfiltered)),
        max(&mm(&unfiltered)),
        unfiltered.len(),
        bound.mm
    );
    println!(
        "{label}: true torch orientation off the target's, filtered rms {:.5}° (max {:.5}°), unfiltered rms {:.4}° (max {:.4}°); {bound_is} {:.5}°",
        rms(&deg(&filtered)),
        max(&deg(&filtered)),
        rms(&deg(&unfiltered)),
        max(&deg(&unfiltered)),
        bound.deg
    );
    assert!(rms(&mm(&filtered)) <= 1.5 * bound.mm, "{label}");
    assert!(
        rms(&deg(&filtered)) <= 1.5 * bound.deg,
        "{label}: orientation"
    );
    assert!(rms(&mm(&unfiltered)) > 1.0, "{label}");
}

/// Every one of the report's `n` targets filtered, none failed or skipped
/// (else the first with a reason is shown).
pub fn assert_every_target_filtered(r: &FilterReport, n: usize) {
    assert_eq!(
        (r.filtered, r.failed, r.skipped),
        (n, 0, 0),
        "{:?}",
        r.targets.iter().find(|t| t.reason.is_some())
    );
}

/// The report names the positioner's axes `names` and each target's values
/// are `want`'s, kept as programmed (within 1e-3°: the programs write 4
/// decimals).
pub fn assert_positioner_values_kept(
    r: &FilterReport,
    names: &[&str],
    want: impl IntoIterator<Item = [f64; 2]>,
) {
    let names: Vec<String> = names.iter().map(|n| n.to_string()).collect();
    assert_eq!(r.positioner_axes, Some(names));
    for (t, v) in r.targets.iter().zip(want) {
        let got = t.positioner_deg.unwrap();
        assert!((got[0] - v[0]).abs() < 1e-3 && (got[1] - v[1]).abs() < 1e-3);
    }
}
