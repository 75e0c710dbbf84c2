use super::*;

const SCRIPT: &str = "def seam():\n  # tool and frame\n  set_tcp(p[0.0, 0.0, 0.25, 0.0, 0.5, 0.0])\n  table = p[1.5, 0.2, 0.3, 0, 0, 0.35]\n  \
start = p[0.1,0.2,0.3,0,3.14159,0]  # approach\n  movej([0, -1.57, 1.57, 0, 1.57, 0], a=1.4, v=1.05)\n  movej(pose_trans(table, start), a=1.2, v=0.25)\n  \
movel(p[-0.4,0.1,0.2,0,0,1e-3], a=1.2, v=0.25, r=0.001)\n  movec(pose_trans(fixture, p[0.1,0,0,0,0,0]), p[0.2,0,0,0,0,0], a=1, v=0.1)\n  \
force_mode(p[0,0,0,0,0,0], [0,0,1,0,0,0], [0,0,10,0,0,0], 2, [0.1,0.1,0.1,0.35,0.35,0.35])\n  set_digital_out(1, True)\nend\n";

#[test]
fn targets_tools_and_frames() {
    let f = ProgramFile {
        name: "seam.script".into(),
        text: SCRIPT.into(),
    };
    let sites = parse(std::slice::from_ref(&f)).unwrap().sites;
    let names: Vec<&str> = sites.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["start", "inline", "inline", "inline"]);
    let s = &sites[0];
    assert_eq!(s.line, 5);
    let values: Vec<&str> = s.slots.iter().map(|r| &SCRIPT[r.clone()]).collect();
    assert_eq!(values, ["0.1", "0.2", "0.3", "0", "3.14159", "0"]);
    let FrameSpec::Inline(table) = &s.work_object else {
        panic!("{:?}", s.work_object)
    };
    assert!((table.p - Vector3::new(1.5, 0.2, 0.3)).norm() < 1e-12);
    let FrameSpec::Inline(tool) = &s.tool else {
        panic!()
    };
    assert!((tool.p.z - 0.25).abs() < 1e-12);
    assert_eq!(s.after_joints.as_ref().unwrap().len(), 6);
    assert!((s.after_joints.as_ref().unwrap()[1] + 89.954).abs() < 1e-2);
    assert_eq!(&SCRIPT[s.mark_at.start..s.mark_at.start + 1], "\n");
    assert_eq!(sites[1].work_object, FrameSpec::Unset);
    assert_eq!(sites[1].slots.len(), 6);
    assert_eq!(
        sites[2].work_object,
        FrameSpec::Ref(CellRef::Name("fixture".into()))
    );
    assert_eq!(sites[3].work_object, FrameSpec::Unset);
}

#[test]
fn errors_name_file_line_and_column() {
    let cases = [
        ("movel(p[1,2,3], a=1)\n", 1, 8, "six numbers"),
        ("x = 1\nmovel(p[1,2,3,4,5,6, a=1)\n", 2, 8, "not closed"),
        ("textmsg(\"abc)\n", 1, 9, "unterminated"),
    ];
    for (text, line, column, what) in cases {
        let f = ProgramFile {
            name: "p.script".into(),
            text: text.into(),
        };
        let e = parse(&[f]).unwrap_err();
        assert_eq!((e.line, e.column), (line, column), "{text}: {e}");
        assert!(e.message.contains(what), "{}", e.message);
    }
}

#[test]
fn every_motion_is_reported_with_what_it_goes_to() {
    let script = "def go(target):\n  movel(target, a=1)\nend\n\
                  home = [0, -1.57, 1.57, 0, 1.57, 0]\n  movej(home)\n\
                  here = get_actual_tcp_pose()\n  movel(here)\n\
                  movel(pose_add(here, p[0, 0, 0.05, 0, 0, 0]))\n  movel(missing)\n\
                  movej(get_inverse_kin(p[0.4, 0, 0.3, 0, 3.14, 0], qnear=home), a=1.4)\n\
                  movec(p[0.1,0,0,0,0,0], p[0.2,0,0,0,0,0], a=1, v=0.1)\n\
                  movej(get_inverse_kin(here))\n";
    let f = ProgramFile {
        name: "m.script".into(),
        text: script.into(),
    };
    let found = parse(std::slice::from_ref(&f)).unwrap();
    let m: Vec<(usize, &str, &str)> = found
        .motions
        .iter()
        .map(|m| (m.line, m.instruction.as_str(), m.name.as_str()))
        .collect();
    assert_eq!(
        m,
        [
            (2, "movel", "target"),
            (5, "movej", "home"),
            (7, "movel", "here"),
            (8, "movel", "pose_add(here, p[0, 0, 0.05, 0, 0, 0])"),
            (9, "movel", "missing"),
            (10, "movej", "inline"),
            (11, "movec", "inline"),
            (11, "movec", "inline"),
            (12, "movej", "here"),
        ]
    );
    let why = |i: usize| match &found.motions[i].target {
        MotionTarget::RunTime(w) => w.clone(),
        other => panic!("{i}: {other:?}"),
    };
    assert!(why(0).contains("target is a parameter of go"));
    assert_eq!(found.motions[1].target, MotionTarget::Joints { note: None });
    assert!(why(2).contains("here is computed at run time (line 6)"));
    assert!(why(3).contains("is computed at run time"));
    assert_eq!(found.motions[4].target, MotionTarget::Undeclared);
    // get_inverse_kin(x, qnear=home): the pose x, solved from the joints home.
    assert_eq!(found.motions[5].target, MotionTarget::Site(0));
    let home = found.sites[0].after_joints.as_ref().unwrap();
    assert!((home[1] + 89.954).abs() < 1e-2, "{home:?}");
    assert_eq!(found.motions[6].target, MotionTarget::Site(1));
    assert_eq!(found.motions[7].target, MotionTarget::Site(2));
    assert!(found.sites[1].after_joints.is_none());
    assert!(why(8).contains("here is computed at run time (line 6)"));
}
