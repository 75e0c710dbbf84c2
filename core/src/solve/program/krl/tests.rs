use super::*;

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
    let sites = parse(&files).unwrap().sites;
    let names: Vec<&str> = sites.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["XP1", "inline", "inline", "inline", "XUNUSED"]);
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
    assert_eq!(sites[3].skip.as_deref(), Some("relative motion"));
    assert!(sites[4].skip.as_ref().unwrap().contains("no motion"));
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
