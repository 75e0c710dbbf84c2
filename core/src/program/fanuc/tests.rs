use super::*;

const LS: &str = "/PROG  SEAM\n/ATTR\nCOMMENT\t\t= \"don't\";\n/MN\n   1:  UFRAME_NUM=2 ;\n   2:J P[1] 100% FINE    ;\n   3:L P[2:\"seam\"] 500mm/sec CNT100    ;\n   4:  ! it's a comment ;\n/POS\nP[1]{\n   GP1:\n\tUF : 2, UT : 1,\t\tCONFIG : 'N U T, 0, -1, 1',\n\tX =  1250.000  mm,\tY =   -30.500  mm,\tZ =   900.000  mm,\n\tW =   180.000 deg,\tP =     10.000 deg,\tR =    -5.000 deg\n};\nP[2:\"seam\"]{\n   GP1:\n\tUF : 2, UT : 1,\n\tJ1=    10.000 deg,\tJ2=   -20.000 deg,\tJ3=    30.000 deg,\n\tJ4=     0.000 deg,\tJ5=    45.000 deg,\tJ6=     0.000 deg\n};\n/END\n";

#[test]
fn cartesian_positions_with_frames_and_config() {
    let f = ProgramFile {
        name: "seam.ls".into(),
        text: LS.into(),
    };
    let sites = parse(std::slice::from_ref(&f)).unwrap().sites;
    assert_eq!(sites.len(), 1);
    let p = &sites[0];
    assert_eq!((p.name.as_str(), p.line), ("P[1]", 10));
    assert_eq!(p.tool, FrameSpec::Ref(CellRef::Number(1)));
    assert_eq!(p.work_object, FrameSpec::Ref(CellRef::Number(2)));
    assert_eq!(
        p.flags,
        Flags::Fanuc {
            flip: false,
            up: true,
            front: true,
            turns: [0, -1, 1]
        }
    );
    let values: Vec<&str> = p.slots.iter().map(|r| &LS[r.clone()]).collect();
    assert_eq!(
        values,
        ["1250.000", "-30.500", "900.000", "180.000", "10.000", "-5.000"]
    );
    assert_eq!(&LS[p.mark_at.clone()], "");
    assert_eq!(&LS[p.mark_at.start..p.mark_at.start + 1], "]");
    let want = rotation_from(OrientationConvention::FanucWpr, &[180.0, 10.0, -5.0]).unwrap();
    assert!((p.pose.unwrap().r - want).norm() < 1e-12);
}

#[test]
fn errors_name_file_line_and_column() {
    let cases = [
        (
            "/POS\nP[1]{\n GP1:\n  X = abc mm\n};\n/END\n",
            4,
            7,
            "not a number",
        ),
        ("/POS\nP[1]{\n GP1:\n  X = 1 mm\n/END\n", 2, 1, "not closed"),
        ("/POS\nQ[1]{};\n", 2, 1, "expected `P[n]{`"),
        (
            "/POS\nP[1]{ GP1: UF : 1, CONFIG : 'N Q T', };\n",
            2,
            29,
            "CONFIG",
        ),
    ];
    for (text, line, column, what) in cases {
        let f = ProgramFile {
            name: "p.ls".into(),
            text: text.into(),
        };
        let e = parse(&[f]).unwrap_err();
        assert_eq!(
            (e.file.as_str(), e.line, e.column),
            ("p.ls", line, column),
            "{text}: {e}"
        );
        assert!(e.message.contains(what), "{}", e.message);
    }
}

#[test]
fn motions_name_their_positions_and_what_they_are() {
    let ls = "/PROG  T\n/MN\n   1:J P[1] 100% FINE    ;\n   2:L PR[3] 500mm/sec FINE    ;\n   3:L P[7] 500mm/sec FINE    ;\n\
              \x20  4:L P[1] 100mm/sec FINE INC ;\n   5:L P[2] 100mm/sec FINE    ;\n   6:J P[3] 100% FINE ;\n\
              /POS\nP[1]{\n   GP1:\n\tUF : 2, UT : 1,\t\tCONFIG : 'N U T, 0, 0, 0',\n\
              \tX = 1.000 mm,\tY = 2.000 mm,\tZ = 3.000 mm,\n\tW = 0.000 deg,\tP = 0.000 deg,\tR = 0.000 deg\n};\n\
              P[2]{\n   GP1:\n\tUF : 2, UT : 1,\t\tCONFIG : 'N U T, 0, 0, 0',\n\
              \tX = 1.000 mm,\tY = 2.000 mm,\tZ = 3.000 mm,\n\tW = 0.000 deg,\tP = 0.000 deg,\tR = 0.000 deg,\n\
              \tE1 = 500.000 mm\n};\n\
              P[3]{\n   GP1:\n\tUF : 2, UT : 1,\t\tCONFIG : 'N U T, 0, 0, 0',\n\
              \tX = 1.000 mm,\tY = 2.000 mm,\tZ = 3.000 mm,\n\tW = 0.000 deg,\tP = 0.000 deg,\tR = 0.000 deg\n\
              \x20  GP2:\n\tUF : 0, UT : 1,\n\tJ1 = 10.000 deg\n};\n/END\n";
    let f = ProgramFile {
        name: "t.ls".into(),
        text: ls.into(),
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
            (3, "J", "P[1]"),
            (4, "L", "PR[3]"),
            (5, "L", "P[7]"),
            (6, "L", "P[1]"),
            (7, "L", "P[2]"),
            (8, "J", "P[3]"),
        ]
    );
    assert_eq!(found.motions[0].target, MotionTarget::Site(0));
    let MotionTarget::RunTime(why) = &found.motions[1].target else {
        panic!()
    };
    assert!(why.contains("PR[3] is a position register"), "{why}");
    assert_eq!(found.motions[2].target, MotionTarget::Undeclared);
    // The mark of P[7] goes into its reference, as the comment of a position.
    assert_eq!(&ls[found.motions[2].mark_at.start..][..1], "]");
    let MotionTarget::RunTime(why) = &found.motions[3].target else {
        panic!()
    };
    assert!(why.contains("INC"), "{why}");
    let refused = |i: usize| {
        let MotionTarget::Site(s) = found.motions[i].target else {
            panic!("{i}")
        };
        let site = &found.sites[s];
        let none = crate::program::FilterAxes::default();
        site.refuse.clone().unwrap_or_else(|| {
            crate::program::axes::place(
                crate::program::Language::Fanuc,
                site,
                &none,
                &Pose::identity(),
            )
            .unwrap_err()
        })
    };
    assert!(
        refused(4).contains("external axis E1 to 500.000 mm"),
        "{}",
        refused(4)
    );
    assert!(refused(5).contains("motion group GP2"), "{}", refused(5));
    assert!(found.sites[0].refuse.is_none() && found.sites[0].axes.is_empty());
    let MotionTarget::Site(s) = found.motions[4].target else {
        panic!()
    };
    let e1 = &found.sites[s].axes[0];
    assert_eq!((e1.number, e1.value), (1, Some(500.0)));
}
