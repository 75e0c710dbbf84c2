use super::super::Flags;
use super::*;
use nalgebra::Vector3;

fn file(text: &str) -> ProgramFile {
    ProgramFile {
        name: "weld.mod".into(),
        text: text.into(),
    }
}

const MODULE: &str = "MODULE weld\n\
  PERS tooldata torch:=[FALSE,[[0,0,250],[1,0,0,0]],[2,[0,0,100],[1,0,0,0],0,0,0]];\n\
  PERS tooldata gun:=[TRUE,[[10,0,250],[0.9659258,0,0.2588190,0]],[2,[0,0,100],[1,0,0,0],0,0,0]];\n\
  TASK PERS wobjdata table:=[FALSE,TRUE,\"\",[[1500,200,300],[1,0,0,0]],[[0,0,0],[1,0,0,0]]];\n\
  CONST robtarget p10:=[[100,-20.5,300],[0.7071068,0,0.7071068,0],[0,-1,2,1],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]]; ! start\n\
  CONST robtarget path{2}:=[[[1,2,3],[1,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]],\n\
     [[4,5,6],[1,0,0,0],[0,0,0,4],[9E9,9E9,9E9,9E9,9E9,9E9]]];\n\
  CONST jointtarget home:=[[0,0,0,0,30,0],[9E9,9E9,9E9,9E9,9E9,9E9]];\n\
  PROC main()\n\
    MoveAbsJ home, v1000, fine, tool0;\n\
    MoveJ p10, v1000, z50, gun\\WObj:=table; ! approach\n\
    MoveL [[10,20,30],[1,0,0,0],[0,0,0,1],[9E9,9E9,9E9,9E9,9E9,9E9]], v100, fine, gun;\n\
    MoveC \\Conc, path{1}, path{2}, v100, z1, torch\\WObj:=table;\n\
    SetDO do1, 1;\n\
  ENDPROC\n\
ENDMODULE\n";

#[test]
fn robtargets_tools_and_work_objects() {
    let f = file(MODULE);
    let sites = parse(std::slice::from_ref(&f)).unwrap().sites;
    let names: Vec<&str> = sites.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["p10", "inline", "path{1}", "path{2}"]);
    let p10 = &sites[0];
    assert_eq!(p10.line, 5);
    assert_eq!(p10.flags, Flags::Abb { cf: [0, -1, 2, 1] });
    let values: Vec<&str> = p10.slots.iter().map(|r| &f.text[r.clone()]).collect();
    assert_eq!(
        values,
        ["100", "-20.5", "300", "0.7071068", "0", "0.7071068", "0"]
    );
    let FrameSpec::Inline(gun) = &p10.tool else {
        panic!("{:?}", p10.tool)
    };
    assert!((gun.p - Vector3::new(0.01, 0.0, 0.25)).norm() < 1e-12);
    // The gun's tload: 2 kg, centre of gravity 100 mm along the flange's z.
    let load = p10.load.expect("declared load");
    assert_eq!(load.mass_kg, 2.0);
    assert!((load.com - Vector3::new(0.0, 0.0, 0.1)).norm() < 1e-15);
    let FrameSpec::Inline(table) = &p10.work_object else {
        panic!()
    };
    assert!((table.p - Vector3::new(1.5, 0.2, 0.3)).norm() < 1e-12);
    assert!(p10.skip.is_none());
    // The inline target: work object wobj0 (base).
    assert_eq!(sites[1].work_object, FrameSpec::Ref(CellRef::Number(0)));
    // A robot-held tool (robhold TRUE) is filtered; a stationary one
    // (robhold FALSE) with a work object the robot does not hold is not.
    assert!(sites[0].skip.is_none() && sites[1].skip.is_none());
    assert!(sites[2]
        .skip
        .as_ref()
        .unwrap()
        .contains("stationary (robhold FALSE)"));
    assert_eq!(sites[3].line, 7);
}

#[test]
fn a_stationary_tool_swaps_the_roles_with_a_held_work_object() {
    let text = MODULE.replace(
        "wobjdata table:=[FALSE,TRUE,",
        "wobjdata table:=[TRUE,TRUE,",
    );
    let sites = parse(&[file(&text)]).unwrap().sites;
    // torch (robhold FALSE) with table (robhold TRUE): the roles swapped.
    assert!(sites[2].skip.is_none() && sites[2].stationary_tool);
    let FrameSpec::Inline(torch) = &sites[2].tool else {
        panic!("{:?}", sites[2].tool)
    };
    assert!((torch.p - Vector3::new(0.0, 0.0, 0.25)).norm() < 1e-12);
    // gun (robhold TRUE) with table (robhold TRUE): both held, not filtered.
    assert!(!sites[0].stationary_tool);
    assert!(sites[0].skip.as_ref().unwrap().contains("holds both"));
    // gun without a work object: the ordinary case.
    assert!(sites[1].skip.is_none() && !sites[1].stationary_tool);
}

#[test]
fn errors_name_file_line_and_column() {
    let cases = [
        (
            "MODULE m\n  CONST robtarget p:=[[1,2,3],[1,0,0,0],[0,0,0,0]];\nENDMODULE",
            2,
            22,
            "not a robtarget",
        ),
        (
            "MODULE m\n  MoveL [[1,2,3],[1,0,0,0],[0,0,0,0],[9E9], v1, z1, tool0;\nENDMODULE",
            2,
            9,
            "not closed",
        ),
        (
            "MODULE m\n  TPWrite \"abc;\nENDMODULE",
            2,
            11,
            "unterminated",
        ),
    ];
    for (text, line, column, what) in cases {
        let e = parse(&[file(text)]).unwrap_err();
        assert_eq!((e.line, e.column), (line, column), "{text}: {e}");
        assert!(e.message.contains(what), "{}", e.message);
    }
}

#[test]
fn every_motion_is_reported_with_what_it_goes_to() {
    let text = "MODULE m\n\
  CONST robtarget p10:=[[1,2,3],[1,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];\n\
  CONST robtarget p20:=[[1,2,3],[1,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];\n\
  VAR robtarget p30;\n\
  CONST jointtarget home:=[[0,0,0,0,30,0],[9E9,9E9,9E9,9E9,9E9,9E9]];\n\
  PROC go(robtarget target)\n\
    MoveL target, v100, fine, tool0;\n\
  ENDPROC\n\
  PROC main()\n\
    MoveAbsJ home, v1000, fine, tool0;\n\
    MoveL Offs(p10, 0, 0, 50), v100, fine, tool0;\n\
    MoveL RelTool(p10, 0, 0, -20 \\Rz:=10), v100, fine, tool0;\n\
    MoveJ p99, v100, z10, tool0;\n\
    MoveL p30, v100, fine, tool0;\n\
    p20.trans.z := p20.trans.z + 5;\n\
    TriggL p10, v500, gunon, fine, gun1 \\WObj:=wobj0;\n\
    MoveL p20, v100, fine, tool0;\n\
    MoveL [[1,2,3],[1,0,0,0],[0,0,0,0],[9E9,250,9E9,9E9,9E9,9E9]], v100, fine, tool0;\n\
  ENDPROC\n\
ENDMODULE\n";
    let found = parse(&[file(text)]).unwrap();
    let m: Vec<(usize, &str, &str)> = found
        .motions
        .iter()
        .map(|m| (m.line, m.instruction.as_str(), m.name.as_str()))
        .collect();
    assert_eq!(
        m,
        [
            (7, "MoveL", "target"),
            (10, "MoveAbsJ", "home"),
            (11, "MoveL", "Offs(p10, 0, 0, 50)"),
            (12, "MoveL", "RelTool(p10, 0, 0, -20 \\Rz:=10)"),
            (13, "MoveJ", "p99"),
            (14, "MoveL", "p30"),
            (16, "TriggL", "p10"),
            (17, "MoveL", "p20"),
            (18, "MoveL", "inline"),
        ]
    );
    let why = |i: usize| match &found.motions[i].target {
        MotionTarget::RunTime(w) => w.clone(),
        other => panic!("{i}: {other:?}"),
    };
    assert!(why(0).contains("target is a parameter of go"), "{}", why(0));
    assert_eq!(found.motions[1].target, MotionTarget::Joints { note: None });
    assert!(why(2).contains("`Offs(p10, 0, 0, 50)` is computed at run time"));
    assert!(why(3).contains("RelTool"));
    assert_eq!(found.motions[4].target, MotionTarget::Undeclared);
    assert!(why(5).contains("p30 is declared without a value"));
    // Offs and RelTool are not uses of p10: TriggL is its first, with the
    // TriggL's tool (the last positional argument, not its zone).
    let MotionTarget::Site(i) = found.motions[6].target else {
        panic!()
    };
    assert_eq!(found.sites[i].name, "p10");
    assert_eq!(
        found.sites[i].tool,
        FrameSpec::Ref(CellRef::Name("gun1".into()))
    );
    let MotionTarget::Site(i) = found.motions[7].target else {
        panic!()
    };
    assert_eq!(
        found.sites[i].skip.as_deref(),
        Some("p20 is assigned at run time (line 15)")
    );
    let MotionTarget::Site(i) = found.motions[8].target else {
        panic!()
    };
    let none = crate::program::FilterAxes::default();
    let refused = crate::program::axes::place(
        crate::program::Language::Rapid,
        &found.sites[i],
        &none,
        &Pose::identity(),
    )
    .unwrap_err();
    assert!(refused.contains("external axis eax_b to 250"), "{refused}");
}

/// A `wobjdata` with `ufprog FALSE` is moved by its mechanical unit: its
/// object frame on the positioner's face plate (the user frame the
/// controller's, so the one written is not used); moved by no unit, or held
/// by the robot and moved, the target is skipped naming why; `ufprog TRUE`
/// is fixed whatever `ufmec` says.
#[test]
fn a_work_object_a_mechanical_unit_moves_is_on_the_face_plate() {
    let text = "MODULE turn\n\
  PERS tooldata gun:=[TRUE,[[0,0,250],[1,0,0,0]],[2,[0,0,100],[1,0,0,0],0,0,0]];\n\
  TASK PERS wobjdata moved:=[FALSE,FALSE,\"STN1\",[[900,0,0],[1,0,0,0]],[[100,50,60],[1,0,0,0]]];\n\
  TASK PERS wobjdata nounit:=[FALSE,FALSE,\"\",[[0,0,0],[1,0,0,0]],[[0,0,0],[1,0,0,0]]];\n\
  TASK PERS wobjdata held:=[TRUE,FALSE,\"STN1\",[[0,0,0],[1,0,0,0]],[[0,0,0],[1,0,0,0]]];\n\
  TASK PERS wobjdata fixed:=[FALSE,TRUE,\"STN1\",[[900,0,0],[1,0,0,0]],[[100,0,0],[1,0,0,0]]];\n\
  PROC main()\n\
    MoveL [[1,2,3],[1,0,0,0],[0,0,0,0],[10,20,9E9,9E9,9E9,9E9]], v100, fine, gun\\WObj:=moved;\n\
    MoveL [[1,2,3],[1,0,0,0],[0,0,0,0],[10,20,9E9,9E9,9E9,9E9]], v100, fine, gun\\WObj:=nounit;\n\
    MoveL [[1,2,3],[1,0,0,0],[0,0,0,0],[10,20,9E9,9E9,9E9,9E9]], v100, fine, gun\\WObj:=held;\n\
    MoveL [[1,2,3],[1,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]], v100, fine, gun\\WObj:=fixed;\n\
  ENDPROC\n\
ENDMODULE\n";
    let sites = parse(&[file(text)]).unwrap().sites;
    let FrameSpec::FacePlate(on_plate) = &sites[0].work_object else {
        panic!("{:?}", sites[0].work_object)
    };
    assert!((on_plate.p - Vector3::new(0.1, 0.05, 0.06)).norm() < 1e-12);
    assert!(sites[0].skip.is_none());
    let values: Vec<(usize, Option<f64>)> =
        sites[0].axes.iter().map(|a| (a.number, a.value)).collect();
    assert_eq!(values, [(1, Some(10.0)), (2, Some(20.0))]);
    let why = sites[1].skip.as_deref().unwrap();
    assert!(why.contains("by no mechanical unit"), "{why}");
    let why = sites[2].skip.as_deref().unwrap();
    assert!(why.contains("held by the robot and moved"), "{why}");
    let FrameSpec::Inline(fixed) = &sites[3].work_object else {
        panic!("{:?}", sites[3].work_object)
    };
    assert!((fixed.p - Vector3::new(1.0, 0.0, 0.0)).norm() < 1e-12);
}
