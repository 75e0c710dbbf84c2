//! ABB RAPID: a module with tooldata, wobjdata and 50 robtargets, declared and inline;
//! a module of 40 with a stationary tool and a work object the robot holds.

use super::stationary::{swapped, Swapped};
use super::*;
use robocal_core::model::orientation::{rotation_to, OrientationConvention};
use robocal_core::program::{abb_cf, filter, LoadSource, TargetStatus};

fn literal(p: &Pose, cf: [i32; 4]) -> String {
    robtarget(p, cf, "[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]")
}

/// A `robtarget` literal of `p` (mm, quaternion) with configuration `cf`
/// and the external axes `axes` as written (`[eax_a,…,eax_f]`).
pub(super) fn robtarget(p: &Pose, cf: [i32; 4], axes: &str) -> String {
    let q = rotation_to(OrientationConvention::AbbQ1q4, &p.r);
    format!(
        "[[{:.4},{:.4},{:.4}],[{:.9},{:.9},{:.9},{:.9}],[{},{},{},{}],{axes}]",
        p.p.x * 1e3,
        p.p.y * 1e3,
        p.p.z * 1e3,
        q[0],
        q[1],
        q[2],
        q[3],
        cf[0],
        cf[1],
        cf[2],
        cf[3]
    )
}

pub(super) fn frame(p: &Pose) -> String {
    let q = rotation_to(OrientationConvention::AbbQ1q4, &p.r);
    format!(
        "[[{:.4},{:.4},{:.4}],[{:.9},{:.9},{:.9},{:.9}]]",
        p.p.x * 1e3,
        p.p.y * 1e3,
        p.p.z * 1e3,
        q[0],
        q[1],
        q[2],
        q[3]
    )
}

/// A module visiting the fixture's targets: even ones declared and moved to
/// by `MoveJ`, odd ones inline in `MoveL`, with the tool (robot-held,
/// `robhold TRUE`, its `tload` the true payload on the flange) and the work
/// object declared in the module (in the controller's base frame).
fn module(f: &Fixture) -> Vec<ProgramFile> {
    let mut decl = format!(
        "MODULE Seam\r\n  ! welding seam on the table\r\n  PERS tooldata torch:=[TRUE,{},[{:.3},[{:.3},{:.3},{:.3}],[1,0,0,0],0,0,0]];\r\n  \
         TASK PERS wobjdata table:=[FALSE,TRUE,\"\",{},[[0,0,0],[1,0,0,0]]];\r\n  \
         CONST jointtarget home:=[[0,90,-20,0,45,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];\r\n",
        frame(&torch()),
        f.truth.payload_kg,
        f.truth.payload_com.x * 1e3,
        f.truth.payload_com.y * 1e3,
        f.truth.payload_com.z * 1e3,
        frame(&f.wobj_controller())
    );
    let mut body = String::from("  PROC main()\r\n    MoveAbsJ home, v1000, fine, tool0;\r\n");
    for i in 0..f.joints.len() {
        let (deg, c) = f.flag_input(i);
        let lit = literal(&f.target(i), abb_cf(&deg, c));
        if i % 2 == 0 {
            decl.push_str(&format!("  CONST robtarget p{i}:={lit};\r\n"));
            body.push_str(&format!(
                "    MoveJ p{i}, v1000, z50, torch\\WObj:=table;\r\n"
            ));
        } else {
            body.push_str(&format!(
                "    MoveL {lit}, v200, fine, torch\\WObj:=table; ! seam point {i}\r\n    SetDO doWeld, 1;\r\n"
            ));
        }
    }
    body.push_str("    MoveAbsJ home, v1000, fine, tool0;\r\n  ENDPROC\r\nENDMODULE\r\n");
    vec![ProgramFile {
        name: "Seam.mod".into(),
        text: decl + &body,
    }]
}

#[test]
fn filtered_rapid_brings_the_true_tcp_to_the_targets() {
    let f = fixture();
    let files = module(f);
    let empty = Cell::default();
    assert_filter_reaches_targets(f, Language::Rapid, "RAPID", &files, &empty);
    // Every target was solved with the module's tload.
    let out = filter(Language::Rapid, &files, &empty, &f.model, &settings()).unwrap();
    for t in &out.report.targets {
        let load = t.load.as_ref().unwrap();
        assert_eq!(load.source, LoadSource::Program);
        assert_eq!(load.load.mass_kg, f.truth.payload_kg);
    }
}

/// The module: the stationary tool and the robot-held work object
/// declared, the tool's tload the true payload on the flange (RAPID: for
/// a stationary tool, the load of the gripper holding the work object).
fn glue_module(s: &Swapped, f: &Fixture) -> ProgramFile {
    let ik = AnalyticIk::new(&s.bare).unwrap();
    let mut decl = format!(
            "MODULE Glue\r\n  PERS tooldata nozzle:=[FALSE,{},[{:.3},[{:.3},{:.3},{:.3}],[1,0,0,0],0,0,0]];\r\n  \
             PERS wobjdata part:=[TRUE,TRUE,\"\",{},[[0,0,0],[1,0,0,0]]];\r\n",
            frame(&s.fixed_base),
            f.truth.payload_kg,
            f.truth.payload_com.x * 1e3,
            f.truth.payload_com.y * 1e3,
            f.truth.payload_com.z * 1e3,
            frame(&s.held)
        );
    let mut body = String::from("  PROC main()\r\n");
    for (i, q) in s.joints.iter().enumerate() {
        let deg: Vec<f64> = s
            .bare
            .joints_to_controller(q)
            .iter()
            .map(|v| v.to_degrees())
            .collect();
        let lit = literal(&s.target(f, i), abb_cf(&deg, ik.configuration(q).unwrap()));
        if i % 2 == 0 {
            decl.push_str(&format!("  CONST robtarget g{i}:={lit};\r\n"));
            body.push_str(&format!(
                "    MoveJ g{i}, v500, z10, nozzle\\WObj:=part;\r\n"
            ));
        } else {
            body.push_str(&format!(
                "    MoveL {lit}, v100, fine, nozzle\\WObj:=part;\r\n"
            ));
        }
    }
    body.push_str("  ENDPROC\r\nENDMODULE\r\n");
    ProgramFile {
        name: "Glue.mod".into(),
        text: decl + &body,
    }
}

#[test]
fn a_stationary_tool_with_a_robot_held_work_object_is_filtered() {
    let f = fixture();
    let s = swapped(f);
    let file = glue_module(&s, f);
    let out = filter(
        Language::Rapid,
        std::slice::from_ref(&file),
        &Cell::default(),
        &f.model,
        &settings(),
    )
    .unwrap();
    let r = &out.report;
    assert_eq!(
        (r.filtered, r.failed, r.skipped),
        (40, 0, 0),
        "{:?}",
        r.targets
    );
    assert!(r
        .targets
        .iter()
        .all(|t| t.load.as_ref().unwrap().source == LoadSource::Program));
    let filtered = s.run(f, Language::Rapid, &out.files);
    assert!(filtered.iter().all(Option::is_some), "{filtered:?}");
    let max_f = filtered.iter().flatten().copied().fold(0.0, f64::max);
    let (mean_f, _) = mean(&filtered);
    let (mean_u, reached_u) = mean(&s.run(f, Language::Rapid, std::slice::from_ref(&file)));
    println!(
        "RAPID stationary tool, robot-held work object: true tool tip vs target filtered \
         mean {mean_f:.4} mm, max {max_f:.4} mm (40); unfiltered mean {mean_u:.3} mm ({reached_u})"
    );
    assert!(mean_f <= 0.05 && max_f <= 0.15, "{mean_f} {max_f}");
    assert!(mean_u > 1.0, "{mean_u}");
    // A stationary tool with a fixed work object, and a robot-held tool with
    // a robot-held work object, are reported, not filtered.
    for (from, to) in [
        ("wobjdata part:=[TRUE,", "wobjdata part:=[FALSE,"),
        ("tooldata nozzle:=[FALSE,", "tooldata nozzle:=[TRUE,"),
    ] {
        let bad = ProgramFile {
            name: "Bad.mod".into(),
            text: file.text.replacen(from, to, 1),
        };
        let out = filter(
            Language::Rapid,
            &[bad],
            &Cell::default(),
            &f.model,
            &settings(),
        )
        .unwrap();
        assert_eq!((out.report.filtered, out.report.skipped), (0, 40));
        let why = out.report.targets[0].reason.as_deref().unwrap();
        assert!(why.contains("robhold"), "{why}");
    }
}

#[test]
fn rapid_without_targets_is_byte_identical_and_failures_are_marked() {
    let f = fixture();
    let logic = ProgramFile {
        name: "Io.mod".into(),
        text: "MODULE Io\n  PROC main()\n    MoveAbsJ [[0,90,-20,0,45,0],[9E9,9E9,9E9,9E9,9E9,9E9]], v100, fine, tool0;\n    \
               SetDO do1, 1; ! gripper\n    WaitDI di2, 1;\n  ENDPROC\nENDMODULE\n"
            .into(),
    };
    let out = filter(
        Language::Rapid,
        std::slice::from_ref(&logic),
        &f.cell,
        &f.model,
        &settings(),
    )
    .unwrap();
    assert_eq!(out.files[0], logic);
    let text = "MODULE Bad\n  PROC main()\n    MoveL [[9000,0,0],[1,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]], v100, fine, torch\\WObj:=table;\n  ENDPROC\nENDMODULE\n";
    let file = ProgramFile {
        name: "Bad.mod".into(),
        text: text.into(),
    };
    let out = filter(Language::Rapid, &[file], &f.cell, &f.model, &settings()).unwrap();
    let t = &out.report.targets[0];
    assert_eq!((t.line, t.status), (3, TargetStatus::Failed));
    let line = out.files[0].text.lines().nth(2).unwrap().to_string();
    assert_eq!(
        line,
        format!(
            "{} ! robocal: not filtered: {}",
            text.lines().nth(2).unwrap(),
            t.reason.as_ref().unwrap()
        )
    );
}
