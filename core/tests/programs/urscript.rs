//! URScript on a UR5: 50 targets in a feature frame (`pose_trans`), the tool by `set_tcp`.

use super::*;
use robocal_core::model::orientation::{rotation_to, OrientationConvention};
use robocal_core::program::{filter, TargetStatus};

fn pose_literal(p: &Pose) -> String {
    let r = rotation_to(OrientationConvention::UrRotvec, &p.r);
    format!(
        "p[{:.7}, {:.7}, {:.7}, {:.7}, {:.7}, {:.7}]",
        p.p.x, p.p.y, p.p.z, r[0], r[1], r[2]
    )
}

/// A script visiting the fixture's targets in the feature `table` (its value
/// in the controller's base frame): even ones through variables, odd ones inline.
fn script(f: &Fixture) -> Vec<ProgramFile> {
    let mut s = format!(
        "def seam():\n  # welding seam on the table\n  set_tcp({})\n  set_payload({}, [{}, {}, {}])\n  global table = {}\n  \
         movej([{}], a=1.4, v=1.05)  # home\n",
        pose_literal(&torch()),
        f.truth.payload_kg,
        f.truth.payload_com.x,
        f.truth.payload_com.y,
        f.truth.payload_com.z,
        pose_literal(&f.wobj_controller()),
        UR_HOME.map(|v| v.to_string()).join(", ")
    );
    for i in 0..f.joints.len() {
        let lit = pose_literal(&f.target(i));
        if i % 2 == 0 {
            s.push_str(&format!(
                "  p{i} = {lit}\n  movej(pose_trans(table, p{i}), a=1.2, v=0.25)\n"
            ));
        } else {
            s.push_str(&format!(
                "  movel(pose_trans(table, {lit}), a=1.2, v=0.25, r=0.001)  # seam point {i}\n  set_digital_out(1, True)\n"
            ));
        }
    }
    s.push_str("end\nseam()\n");
    vec![ProgramFile {
        name: "seam.script".into(),
        text: s,
    }]
}

#[test]
fn filtered_urscript_brings_the_true_tcp_to_the_targets() {
    let f = fixture_ur5();
    let files = script(f);
    assert_filter_reaches_targets(f, Language::UrScript, "URScript", &files, &Cell::default());
}

#[test]
fn urscript_without_targets_is_byte_identical_and_failures_are_marked() {
    let f = fixture_ur5();
    let text = "def io():\n  movej([0, -1.57, 1.57, 0, 1.57, 0])  # joints only\n  set_digital_out(1, True)\n  sleep(0.5)\nend\n";
    let file = ProgramFile {
        name: "io.script".into(),
        text: text.into(),
    };
    let out = filter(
        Language::UrScript,
        std::slice::from_ref(&file),
        &f.cell,
        &f.model,
        &settings(),
    )
    .unwrap();
    assert_eq!(out.files[0], file);
    let far = "set_tcp(p[0,0,0.1,0,0,0])\nmovel(p[5.0, 0, 0, 0, 0, 0], a=1)  # far\n";
    let file = ProgramFile {
        name: "far.script".into(),
        text: far.into(),
    };
    let out = filter(Language::UrScript, &[file], &f.cell, &f.model, &settings()).unwrap();
    let t = &out.report.targets[0];
    assert_eq!((t.line, t.status), (2, TargetStatus::Failed));
    assert_eq!(
        out.files[0].text,
        format!(
            "set_tcp(p[0,0,0.1,0,0,0])\nmovel(p[5.0, 0, 0, 0, 0, 0], a=1)  # far  # robocal: not filtered: {}\n",
            t.reason.as_ref().unwrap()
        )
    );
}
