use super::super::Flags;
use super::*;
use crate::model::orientation::rotation_from;
use nalgebra::Vector3;

fn file(name: &str, text: &str) -> ProgramFile {
    ProgramFile {
        name: name.into(),
        text: text.into(),
    }
}

const DAT: &str = "DEFDAT demo\n\
DECL E6POS XP1={X 1200.5,Y -30,Z 900,A 10,B 20,C 30,S 2,T 'B100010',E1 0.0} ; start\r\n\
DECL FDAT FP2={TOOL_NO 3,BASE_NO 2,IPO_FRAME #BASE,POINT2[] \" \"}\n\
DECL E6AXIS XHOME={A1 0,A2 -90,A3 90,A4 0,A5 0,A6 0}\n\
DECL FRAME XUNUSED={X 1,Y 2,Z 3,A 0,B 0,C 0}\n\
ENDDAT\n";

const SRC: &str = "DEF demo()\n\
PTP XHOME\n\
$TOOL = TOOL_DATA[1] ; torch\n\
$BASE=BASE_DATA[2]\n\
PTP XP1 C_PTP\n\
FDAT_ACT=FP2\n\
LIN {X 1000,Y 0,Z 800,A 0,B 90,C 0} ; inline\n\
LIN {X 1000}\n\
LIN_REL {X 10,Y 0,Z 0,A 0,B 0,C 0}\n\
PTP {A1 10,A2 -80,A3 80,A4 0,A5 30,A6 0}\n\
END\n";

#[test]
fn targets_flags_tools_and_bases() {
    let files = [file("demo.src", SRC), file("demo.dat", DAT)];
    let found = parse(&files).unwrap();
    let sites = found.sites;
    let names: Vec<&str> = sites.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["XP1", "inline", "inline", "XUNUSED"]);
    // Every motion, in the order of the lines: XHOME and the axis aggregate
    // are joint motions, LIN_REL is relative.
    let motions: Vec<(usize, &str, &str, &MotionTarget)> = found
        .motions
        .iter()
        .map(|m| (m.line, m.instruction.as_str(), m.name.as_str(), &m.target))
        .collect();
    let joints = MotionTarget::Joints { note: None };
    let relative =
        MotionTarget::RunTime("relative motion: LIN_REL moves from where the robot is".into());
    assert_eq!(
        motions,
        [
            (2, "PTP", "XHOME", &joints),
            (5, "PTP", "XP1", &MotionTarget::Site(0)),
            (7, "LIN", "inline", &MotionTarget::Site(1)),
            (8, "LIN", "inline", &MotionTarget::Site(2)),
            (9, "LIN_REL", "inline", &relative),
            (10, "PTP", "inline", &joints),
        ]
    );
    let p1 = &sites[0];
    assert_eq!((p1.file, p1.line), (1, 2));
    assert_eq!(
        p1.flags,
        Flags::Kuka {
            s: Some(2),
            t: Some(0b100010)
        }
    );
    assert_eq!(p1.tool, FrameSpec::Ref(CellRef::Number(1)));
    assert_eq!(p1.work_object, FrameSpec::Ref(CellRef::Number(2)));
    let pose = p1.pose.unwrap();
    assert!((pose.p - Vector3::new(1.2005, -0.03, 0.9)).norm() < 1e-12);
    let want = rotation_from(OrientationConvention::KukaAbc, &[10.0, 20.0, 30.0]).unwrap();
    assert!((pose.r - want).norm() < 1e-12);
    // The slots are the six values, in X..C order; the mark goes before "\r\n".
    let text = &files[1].text;
    let values: Vec<&str> = p1.slots.iter().map(|r| &text[r.clone()]).collect();
    assert_eq!(values, ["1200.5", "-30", "900", "10", "20", "30"]);
    assert_eq!(&text[p1.mark_at.start..p1.mark_at.start + 2], "\r\n");
    // FDAT_ACT selects tool 3, base 2; no S/T: the nearest solution.
    assert_eq!(sites[1].tool, FrameSpec::Ref(CellRef::Number(3)));
    assert_eq!(sites[1].flags, Flags::Nearest);
    assert!(sites[1].skip.is_none());
    assert!(sites[2].skip.as_ref().unwrap().contains("incomplete"));
    assert!(sites[3].skip.as_ref().unwrap().contains("no motion"));
    assert!(sites.iter().all(|s| s.refuse.is_none()));
}

/// What the motions of a `.src` go to, by name.
fn targets_of(files: &[ProgramFile]) -> Vec<(String, MotionTarget)> {
    parse(files)
        .unwrap()
        .motions
        .into_iter()
        .map(|m| (m.name, m.target))
        .collect()
}

#[test]
fn a_src_without_its_dat_names_what_it_lacks() {
    let src = file("demo.src", SRC);
    let t = targets_of(std::slice::from_ref(&src));
    // XP1 is in the .dat: undeclared. XHOME: KUKA's home, axis values.
    assert_eq!(t[1], ("XP1".into(), MotionTarget::Undeclared));
    let MotionTarget::Joints { note: Some(note) } = &t[0].1 else {
        panic!("{:?}", t[0])
    };
    assert!(note.contains("$config.dat"), "{note}");
    // With the .dat: declared.
    let t = targets_of(&[src, file("demo.dat", DAT)]);
    assert_eq!(t[1], ("XP1".into(), MotionTarget::Site(0)));
}

#[test]
fn positions_set_at_run_time_are_named() {
    let dat = "DECL E6POS XP1={X 1,Y 2,Z 3,A 0,B 0,C 0}\nDECL E6POS XP2={X 1,Y 2,Z 3,A 0,B 0,C 0}\n\
               DECL E6POS XEMPTY\nDECL E6POS XARR[4]\nDECL E6AXIS XJ={A1 0,A2 0,A3 0,A4 0,A5 0,A6 0}\n";
    let src = "PTP $POS_ACT\nLIN XARR[2]\nLIN XEMPTY\nLIN XBASE : XP1\nXP2.Z = XP2.Z + 10\n\
               LIN XP2 C_DIS\nSPTP XJ\nLIN XP1 WITH $VEL = SVEL_CP(0.2, , LCPFAST)\n\
               CIRC XP1, XP2, CA 90\nXTMP = $POS_ACT\nLIN XTMP\n";
    let found = parse(&[file("a.src", src), file("a.dat", dat)]).unwrap();
    let run_time = |i: usize| match &found.motions[i].target {
        MotionTarget::RunTime(why) => why.clone(),
        other => panic!("{i}: {other:?}"),
    };
    assert!(run_time(0).contains("$POS_ACT is a system variable"));
    assert!(run_time(1).contains("`XARR[2]` is computed at run time"));
    assert!(run_time(2).contains("XEMPTY is declared without a value"));
    assert!(run_time(3).contains("`XBASE : XP1`"));
    assert!(run_time(9).contains("XTMP is assigned at run time (a.src line 10)"));
    // XP2 is assigned in the .src: its site is skipped, saying where.
    let MotionTarget::Site(i) = found.motions[4].target else {
        panic!()
    };
    let xp2 = &found.sites[i];
    assert_eq!(xp2.name, "XP2");
    assert_eq!(
        xp2.skip.as_deref(),
        Some("XP2 is assigned at run time (a.src line 5)")
    );
    assert_eq!(found.motions[5].target, MotionTarget::Joints { note: None });
    // The clause after the position is not part of it; CIRC has two.
    assert_eq!(found.motions[6].name, "XP1");
    let circ: Vec<(&str, usize)> = found.motions[7..9]
        .iter()
        .map(|m| (m.name.as_str(), m.line))
        .collect();
    assert_eq!(circ, [("XP1", 9), ("XP2", 9)]);
    assert_eq!(found.motions.len(), 10);
}

#[test]
fn external_axes_are_read_and_refused_without_a_track_naming_the_axis() {
    let src =
        "LIN {X 1,Y 2,Z 3,A 0,B 0,C 0,E1 0.0,E2 0}\nLIN {X 1,Y 2,Z 3,A 0,B 0,C 0,E1 0,E2 250.5}\n";
    let sites = parse(&[file("e.src", src)]).unwrap().sites;
    let values: Vec<_> = sites[1].axes.iter().map(|a| (a.number, a.value)).collect();
    assert_eq!(values, [(1, Some(0.0)), (2, Some(250.5))]);
    let none = crate::program::FilterAxes::default();
    let place =
        |s| crate::program::axes::place(crate::program::Language::Krl, s, &none, &Pose::identity());
    assert!(place(&sites[0]).unwrap().track.is_none());
    let why = place(&sites[1]).unwrap_err();
    assert!(why.contains("external axis E2 to 250.5"), "{why}");
}

#[test]
fn a_point_used_with_two_tools_is_skipped_and_program_frames_win() {
    let dat =
        "DECL POS P={X 1,Y 2,Z 3,A 0,B 0,C 0,S 6}\nTOOL_DATA[4]={X 0,Y 0,Z 250,A 0,B 30,C 0}\n";
    let src = "BAS(#TOOL, 4)\nPTP P\n$TOOL=$NULLFRAME\nLIN P\n";
    let sites = parse(&[file("a.src", src), file("a.dat", dat)])
        .unwrap()
        .sites;
    assert_eq!(sites.len(), 1);
    assert!(sites[0].skip.as_ref().unwrap().contains("lines 2 and 4"));
    let FrameSpec::Inline(tool) = &sites[0].tool else {
        panic!("{:?}", sites[0].tool)
    };
    assert!((tool.p.z - 0.25).abs() < 1e-15);
}

#[test]
fn errors_name_file_line_and_column() {
    let cases = [
        ("PTP {X 1,Y 2\n", 2, 1, 5, "not closed"),
        ("\nLIN {X 1, , Y 2}\n", 2, 2, 11, "component name"),
        ("PTP {X 1,Y}\n", 1, 1, 10, "no value"),
        ("x = \"abc\n", 1, 1, 5, "unterminated"),
        (
            "; a comment with { and \" is fine\nLIN {X 1,Y 2,Z}",
            1,
            2,
            14,
            "no value",
        ),
    ];
    for (src, _, line, column, what) in cases {
        let e = parse(&[file("p.src", src)]).unwrap_err();
        assert_eq!(
            (e.file.as_str(), e.line, e.column),
            ("p.src", line, column),
            "{src}"
        );
        assert!(e.message.contains(what), "{}", e.message);
    }
}

#[test]
fn literals() {
    assert_eq!(integer("'B110'"), Some(6));
    assert_eq!(integer("'h1F'"), Some(31));
    assert_eq!(integer("27"), Some(27));
    assert_eq!(real("1.5E+02"), Some(150.0));
    assert_eq!(real("inf"), None);
    assert_eq!(real("NaN"), None);
}
