//! A property test over the four program parsers and the filter (issue 42):
//! for generated programs — a random mix of motions to inline, declared,
//! undeclared, run-time and relative positions and to axis values, with
//! comments and other statements between them — every position of every
//! motion is in the report exactly once, in order, with its file, line and
//! name, and the status its kind gives; the motions to axis values are
//! listed apart; the counts add up.

use super::*;
use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use robocal_core::program::{filter, FilterReport, TargetStatus};

/// What a generated line of a program is.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Item {
    /// A motion to a Cartesian position written in the motion.
    Inline,
    /// The same with an external axis set: refused.
    Refused,
    /// A motion to a point declared elsewhere (KRL: in the `.dat`).
    Declared,
    /// A motion to a name nothing declares.
    Undeclared,
    /// A motion to a position set at run time (`variant` picks the form).
    RunTime(u8),
    /// A relative or incremental motion.
    Relative,
    /// A motion to axis values.
    Joint,
    /// A circular motion through two declared points.
    Circular,
    /// A comment that mentions a motion.
    Comment,
    /// Another statement.
    Other,
}

fn item() -> impl Strategy<Value = Item> {
    prop_oneof![
        3 => Just(Item::Inline),
        1 => Just(Item::Refused),
        3 => Just(Item::Declared),
        1 => Just(Item::Undeclared),
        2 => (0u8..3).prop_map(Item::RunTime),
        1 => Just(Item::Relative),
        1 => Just(Item::Joint),
        1 => Just(Item::Circular),
        1 => Just(Item::Comment),
        1 => Just(Item::Other),
    ]
}

/// What the report must say of one position.
#[derive(Debug, Clone, PartialEq)]
enum Expect {
    /// Filtered or failed by the solve.
    Solved,
    /// Failed, the reason naming this text.
    Fails(String),
    Skipped,
}

/// A generated program: its files and, per position of a motion, (file,
/// line, name, what the report says); the joint motions' (file, line).
struct Generated {
    files: Vec<ProgramFile>,
    positions: Vec<(String, usize, String, Expect)>,
    joints: Vec<(String, usize)>,
}

/// A table position (mm) and orientation (KUKA A, B, C in degrees) from a
/// seed: within the YS100's reach around the fixture's table.
fn place(k: usize) -> ([f64; 3], [f64; 3]) {
    let f = k as f64;
    (
        [
            (f * 37.0) % 300.0 - 150.0,
            (f * 53.0) % 300.0 - 150.0,
            50.0 + (f * 29.0) % 200.0,
        ],
        [
            (f * 17.0) % 60.0 - 30.0,
            (f * 11.0) % 20.0 - 10.0,
            180.0 - (f * 7.0) % 20.0,
        ],
    )
}

/// Lines of a program under construction, numbered from 1.
struct Lines(Vec<String>);

impl Lines {
    /// Adds a line; its 1-based number.
    fn push(&mut self, s: impl Into<String>) -> usize {
        self.0.push(s.into());
        self.0.len()
    }

    fn text(&self) -> String {
        self.0.join("\n") + "\n"
    }
}

fn krl(items: &[Item], with_dat: bool) -> Generated {
    let mut src = Lines(vec!["DEF prog()".into()]);
    src.push("DECL E6POS XVAR");
    src.push("DECL E6POS XARR[4]");
    src.push("$TOOL = TOOL_DATA[1]");
    src.push("BAS(#BASE, 2)");
    let mut dat = Lines(vec!["DEFDAT prog".into()]);
    let mut g = Generated {
        files: Vec::new(),
        positions: Vec::new(),
        joints: Vec::new(),
    };
    let agg = |k: usize| {
        let (p, o) = place(k);
        format!(
            "X {:.1},Y {:.1},Z {:.1},A {:.1},B {:.1},C {:.1}",
            p[0], p[1], p[2], o[0], o[1], o[2]
        )
    };
    let declare = |k: usize, g_dat: &mut Lines| -> (String, Expect) {
        let name = format!("XP{k}");
        g_dat.push(format!("DECL E6POS {name}={{{},E1 0.0}}", agg(k)));
        let expect = if with_dat {
            Expect::Solved
        } else {
            Expect::Fails(format!("{name} is not declared"))
        };
        (name, expect)
    };
    for (k, it) in items.iter().enumerate() {
        let at = |s: String, name: &str, e: Expect, g: &mut Generated, src: &mut Lines| {
            let line = src.push(s);
            g.positions.push(("prog.src".into(), line, name.into(), e));
        };
        match *it {
            Item::Inline => at(
                format!("LIN {{{}}} C_DIS", agg(k)),
                "inline",
                Expect::Solved,
                &mut g,
                &mut src,
            ),
            Item::Refused => at(
                format!("LIN {{{},E1 250.0}}", agg(k)),
                "inline",
                Expect::Fails("external axis E1".into()),
                &mut g,
                &mut src,
            ),
            Item::Declared => {
                let (name, e) = declare(k, &mut dat);
                at(format!("PTP {name} C_PTP"), &name, e, &mut g, &mut src);
            }
            Item::Undeclared => {
                let name = format!("XQ{k}");
                at(
                    format!("LIN {name}"),
                    &name,
                    Expect::Fails(format!("{name} is not declared")),
                    &mut g,
                    &mut src,
                );
            }
            Item::RunTime(v) => {
                let name = ["$POS_ACT", "XARR[2]", "XVAR"][usize::from(v)];
                at(
                    format!("LIN {name}"),
                    name,
                    Expect::Skipped,
                    &mut g,
                    &mut src,
                );
            }
            Item::Relative => at(
                "LIN_REL {Z 10.0}".into(),
                "inline",
                Expect::Skipped,
                &mut g,
                &mut src,
            ),
            Item::Joint => {
                let line = src.push("PTP {A1 10,A2 -80,A3 80,A4 0,A5 30,A6 0}");
                g.joints.push(("prog.src".into(), line));
            }
            Item::Circular => {
                let (a, ea) = declare(k, &mut dat);
                let (b, eb) = declare(k + 1000, &mut dat);
                let line = src.push(format!("CIRC {a}, {b}"));
                g.positions.push(("prog.src".into(), line, a, ea));
                g.positions.push(("prog.src".into(), line, b, eb));
            }
            Item::Comment => {
                src.push(format!("; LIN XQ{k} is not a motion"));
            }
            Item::Other => {
                src.push("$OUT[1] = TRUE");
            }
        }
    }
    src.push("END");
    dat.push("ENDDAT");
    g.files.push(ProgramFile {
        name: "prog.src".into(),
        text: src.text(),
    });
    if with_dat {
        g.files.push(ProgramFile {
            name: "prog.dat".into(),
            text: dat.text(),
        });
    }
    g
}

/// A RAPID robtarget literal of position `k` (`eax_a` as given).
fn robtarget(k: usize, eax_a: &str) -> String {
    let (p, _) = place(k);
    format!(
        "[[{:.1},{:.1},{:.1}],[0,1,0,0],[0,0,0,0],[{eax_a},9E9,9E9,9E9,9E9,9E9]]",
        p[0], p[1], p[2]
    )
}

fn rapid(items: &[Item]) -> Generated {
    let mut data = Vec::new();
    let mut body = Vec::new();
    let mut g = Generated {
        files: Vec::new(),
        positions: Vec::new(),
        joints: Vec::new(),
    };
    // (text, positions: (name, expect)), joint?
    let motion = "v100, fine, torch\\WObj:=table;";
    for (k, it) in items.iter().enumerate() {
        let (line, positions, joint): (String, Vec<(String, Expect)>, bool) = match *it {
            Item::Inline => (
                format!("MoveL {}, {motion}", robtarget(k, "9E9")),
                vec![("inline".into(), Expect::Solved)],
                false,
            ),
            Item::Refused => (
                format!("MoveL {}, {motion}", robtarget(k, "150")),
                vec![("inline".into(), Expect::Fails("external axis eax_a".into()))],
                false,
            ),
            Item::Declared => {
                data.push(format!("CONST robtarget p{k}:={};", robtarget(k, "9E9")));
                (
                    format!("MoveJ p{k}, {motion}"),
                    vec![(format!("p{k}"), Expect::Solved)],
                    false,
                )
            }
            Item::Undeclared => (
                format!("MoveL q{k}, {motion}"),
                vec![(
                    format!("q{k}"),
                    Expect::Fails(format!("q{k} is not declared")),
                )],
                false,
            ),
            Item::RunTime(v) => {
                let expr =
                    ["Offs(p0, 0, 0, 10)", "RelTool(p0, 0, 0, -5)", "CRobT()"][usize::from(v)];
                (
                    format!("MoveL {expr}, {motion}"),
                    vec![(expr.into(), Expect::Skipped)],
                    false,
                )
            }
            Item::Relative => (
                format!("MoveL Offs(CRobT(), 0, 0, 5), {motion}"),
                vec![("Offs(CRobT(), 0, 0, 5)".into(), Expect::Skipped)],
                false,
            ),
            Item::Joint => (
                "MoveAbsJ [[0,90,-20,0,45,0],[9E9,9E9,9E9,9E9,9E9,9E9]], v1000, fine, tool0;"
                    .into(),
                Vec::new(),
                true,
            ),
            Item::Circular => {
                data.push(format!("CONST robtarget c{k}:={};", robtarget(k, "9E9")));
                data.push(format!(
                    "CONST robtarget d{k}:={};",
                    robtarget(k + 1000, "9E9")
                ));
                (
                    format!("MoveC c{k}, d{k}, {motion}"),
                    vec![
                        (format!("c{k}"), Expect::Solved),
                        (format!("d{k}"), Expect::Solved),
                    ],
                    false,
                )
            }
            Item::Comment => (format!("! MoveL q{k}, {motion}"), Vec::new(), false),
            Item::Other => ("SetDO do1, 1;".into(), Vec::new(), false),
        };
        body.push((line, positions, joint));
    }
    let mut text = Lines(vec!["MODULE prog".into()]);
    text.push("PERS tooldata torch:=[TRUE,[[125,0,216.5],[0.9659258,0,0.2588190,0]],[2,[0,0,100],[1,0,0,0],0,0,0]];");
    text.push("TASK PERS wobjdata table:=[FALSE,TRUE,\"\",[[1500,200,300],[1,0,0,0]],[[0,0,0],[1,0,0,0]]];");
    for d in data {
        text.push(format!("  {d}"));
    }
    text.push("  PROC main()");
    for (line, positions, joint) in body {
        let n = text.push(format!("    {line}"));
        if joint {
            g.joints.push(("prog.mod".into(), n));
        }
        for (name, e) in positions {
            g.positions.push(("prog.mod".into(), n, name, e));
        }
    }
    text.push("  ENDPROC");
    text.push("ENDMODULE");
    g.files.push(ProgramFile {
        name: "prog.mod".into(),
        text: text.text(),
    });
    g
}

/// A Fanuc `/POS` block of position `n` (Cartesian from seed `k`, with an
/// extended axis when `e1`; or in joint form).
fn fanuc_block(n: usize, k: usize, form: Item) -> String {
    let (p, o) = place(k);
    let head = format!("P[{n}]{{\n   GP1:\n\tUF : 2, UT : 1,");
    if form == Item::Joint {
        return format!("{head}\n\tJ1= 0.000 deg,\tJ2= 90.000 deg,\tJ3= -20.000 deg,\n\tJ4= 0.000 deg,\tJ5= 45.000 deg,\tJ6= 0.000 deg\n}};\n");
    }
    let e1 = if form == Item::Refused {
        ",\n\tE1 = 300.000 mm"
    } else {
        ""
    };
    format!(
        "{head}\t\tCONFIG : 'N U T, 0, 0, 0',\n\tX = {:.3} mm,\tY = {:.3} mm,\tZ = {:.3} mm,\n\tW = {:.3} deg,\tP = {:.3} deg,\tR = {:.3} deg{e1}\n}};\n",
        p[0], p[1], p[2], o[2], o[1], o[0]
    )
}

fn fanuc(items: &[Item]) -> Generated {
    let mut g = Generated {
        files: Vec::new(),
        positions: Vec::new(),
        joints: Vec::new(),
    };
    let mut mn = Lines(vec!["/PROG  PROG".into(), "/MN".into()]);
    let mut pos = String::from("/POS\n");
    let mut n = 0;
    let mut next = |pos: &mut String, k: usize, form: Item| {
        n += 1;
        pos.push_str(&fanuc_block(n, k, form));
        n
    };
    let file = "PROG.LS".to_string();
    for (k, it) in items.iter().enumerate() {
        let no = mn.0.len() - 1;
        let motion = |s: String, name: String, e: Expect, g: &mut Generated, mn: &mut Lines| {
            let line = mn.push(format!("{no:4}:{s} ;"));
            g.positions.push((file.clone(), line, name, e));
        };
        match *it {
            Item::Inline | Item::Declared => {
                let p = next(&mut pos, k, Item::Inline);
                motion(
                    format!("L P[{p}] 100mm/sec FINE"),
                    format!("P[{p}]"),
                    Expect::Solved,
                    &mut g,
                    &mut mn,
                );
            }
            Item::Refused => {
                let p = next(&mut pos, k, Item::Refused);
                let e = Expect::Fails("external axis E1".into());
                motion(
                    format!("L P[{p}] 100mm/sec FINE"),
                    format!("P[{p}]"),
                    e,
                    &mut g,
                    &mut mn,
                );
            }
            Item::Undeclared => {
                let p = 900 + k;
                let e = Expect::Fails(format!("P[{p}] is not declared"));
                motion(
                    format!("L P[{p}] 100mm/sec FINE"),
                    format!("P[{p}]"),
                    e,
                    &mut g,
                    &mut mn,
                );
            }
            Item::RunTime(v) => {
                let (s, name) = match v {
                    0 => ("L PR[3] 100mm/sec FINE".to_string(), "PR[3]".to_string()),
                    1 => (
                        "L P[R[2]] 100mm/sec FINE".to_string(),
                        "P[R[2]]".to_string(),
                    ),
                    _ => {
                        let p = next(&mut pos, k, Item::Inline);
                        (
                            format!("L P[{p}] 100mm/sec FINE Offset,PR[1]"),
                            format!("P[{p}]"),
                        )
                    }
                };
                motion(s, name, Expect::Skipped, &mut g, &mut mn);
            }
            Item::Relative => {
                let p = next(&mut pos, k, Item::Inline);
                motion(
                    format!("L P[{p}] 100mm/sec FINE INC"),
                    format!("P[{p}]"),
                    Expect::Skipped,
                    &mut g,
                    &mut mn,
                );
            }
            Item::Joint => {
                let p = next(&mut pos, k, Item::Joint);
                let line = mn.push(format!("{no:4}:J P[{p}] 100% FINE ;"));
                g.joints.push((file.clone(), line));
            }
            Item::Circular => {
                let a = next(&mut pos, k, Item::Inline);
                let b = next(&mut pos, k + 1000, Item::Inline);
                let line = mn.push(format!("{no:4}:C P[{a}]"));
                mn.push(format!("    :  P[{b}] 100mm/sec FINE ;"));
                g.positions
                    .push((file.clone(), line, format!("P[{a}]"), Expect::Solved));
                g.positions
                    .push((file.clone(), line, format!("P[{b}]"), Expect::Solved));
            }
            Item::Comment => {
                mn.push(format!("{no:4}:  ! L P[{}] is a remark ;", 800 + k));
            }
            Item::Other => {
                mn.push(format!("{no:4}:  DO[1]=ON ;"));
            }
        }
    }
    g.files.push(ProgramFile {
        name: file,
        text: mn.text() + &pos + "/END\n",
    });
    g
}

fn urscript(items: &[Item]) -> Generated {
    let mut g = Generated {
        files: Vec::new(),
        positions: Vec::new(),
        joints: Vec::new(),
    };
    let mut s = Lines(vec!["def prog():".into()]);
    s.push("  set_tcp(p[0.125, 0.0, 0.2165, 0.0, 0.5236, 0.0])");
    s.push("  table = p[1.5, 0.2, 0.3, 0.0, 0.0, 0.35]");
    s.push("  here = get_actual_tcp_pose()");
    let file = "prog.script".to_string();
    let pose = |k: usize| {
        let (p, _) = place(k);
        format!(
            "p[{:.4}, {:.4}, {:.4}, 3.1416, 0.0, 0.0]",
            p[0] * 1e-3,
            p[1] * 1e-3,
            p[2] * 1e-3
        )
    };
    for (k, it) in items.iter().enumerate() {
        let motion = |text: String, name: String, e: Expect, g: &mut Generated, s: &mut Lines| {
            let line = s.push(format!("  {text}"));
            g.positions.push((file.clone(), line, name, e));
        };
        match *it {
            Item::Inline => motion(
                format!("movel(pose_trans(table, {}), a=1.2, v=0.25)", pose(k)),
                "inline".into(),
                Expect::Solved,
                &mut g,
                &mut s,
            ),
            // URScript targets carry no external axes: a motion to a
            // position computed from a pose literal instead.
            Item::Refused => motion(
                format!("movel(pose_add(here, {}))", pose(k)),
                format!("pose_add(here, {})", pose(k)),
                Expect::Skipped,
                &mut g,
                &mut s,
            ),
            Item::Declared => {
                s.push(format!("  w{k} = {}", pose(k)));
                // As Polyscope writes a joint move to a waypoint, every other time.
                let call = if k % 2 == 0 {
                    format!("movej(pose_trans(table, w{k}), a=1.2)")
                } else {
                    format!(
                        "movej(get_inverse_kin(pose_trans(table, w{k}), qnear=[0.0, -1.6, 1.6, 0.0, 1.6, 0.0]), a=1.2)"
                    )
                };
                motion(call, format!("w{k}"), Expect::Solved, &mut g, &mut s);
            }
            Item::Undeclared => motion(
                format!("movel(q{k}, a=1.2)"),
                format!("q{k}"),
                Expect::Fails(format!("q{k} is not declared")),
                &mut g,
                &mut s,
            ),
            Item::RunTime(v) => {
                let (expr, name) = [
                    ("here", "here"),
                    ("get_actual_tcp_pose()", "get_actual_tcp_pose()"),
                    ("get_inverse_kin(here)", "here"),
                ][usize::from(v)];
                let call = format!("movel({expr}, a=1.2)");
                motion(call, name.into(), Expect::Skipped, &mut g, &mut s);
            }
            Item::Relative => motion(
                "movel(pose_trans(here, p[0, 0, 0.01, 0, 0, 0]))".into(),
                "pose_trans(here, p[0, 0, 0.01, 0, 0, 0])".into(),
                Expect::Skipped,
                &mut g,
                &mut s,
            ),
            Item::Joint => {
                let line = s.push("  movej([0.0, -1.6, 1.6, 0.0, 1.6, 0.0], a=1.4, v=1.05)");
                g.joints.push((file.clone(), line));
            }
            Item::Circular => {
                let line = s.push(format!(
                    "  movec(pose_trans(table, {}), pose_trans(table, {}), a=1, v=0.1)",
                    pose(k),
                    pose(k + 1000)
                ));
                g.positions
                    .push((file.clone(), line, "inline".into(), Expect::Solved));
                g.positions
                    .push((file.clone(), line, "inline".into(), Expect::Solved));
            }
            Item::Comment => {
                s.push(format!("  # movel(q{k}) is a comment"));
            }
            Item::Other => {
                s.push("  set_digital_out(1, True)");
            }
        }
    }
    s.push("end");
    g.files.push(ProgramFile {
        name: file,
        text: s.text(),
    });
    g
}

/// The report of `g` says what the generator wrote, once per position.
fn check(language: Language, g: &Generated, r: &FilterReport) -> Result<(), TestCaseError> {
    prop_assert_eq!(r.filtered + r.failed + r.skipped, r.targets.len());
    let got: Vec<(&str, usize, &str)> = r
        .targets
        .iter()
        .map(|t| (t.motion.file.as_str(), t.motion.line, t.name.as_str()))
        .collect();
    let want: Vec<(&str, usize, &str)> = g
        .positions
        .iter()
        .map(|(f, l, n, _)| (f.as_str(), *l, n.as_str()))
        .collect();
    prop_assert_eq!(got, want, "{:?}", language);
    for (t, (_, _, _, e)) in r.targets.iter().zip(&g.positions) {
        let why = t.reason.as_deref().unwrap_or("");
        match e {
            Expect::Solved => {
                prop_assert!(t.status != TargetStatus::Skipped, "{:?} {:?}", language, t)
            }
            Expect::Fails(text) => prop_assert!(
                t.status == TargetStatus::Failed && why.contains(text.as_str()),
                "{:?} {:?}: {}",
                language,
                t,
                text
            ),
            Expect::Skipped => prop_assert!(
                t.status == TargetStatus::Skipped && !why.is_empty(),
                "{:?} {:?}",
                language,
                t
            ),
        }
    }
    let joints: Vec<(&str, usize)> = r
        .joint_motions
        .iter()
        .map(|j| (j.file.as_str(), j.line))
        .collect();
    let want: Vec<(&str, usize)> = g.joints.iter().map(|(f, l)| (f.as_str(), *l)).collect();
    prop_assert_eq!(joints, want, "{:?}", language);
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 64,
        rng_seed: RngSeed::Fixed(0x5eed_0042),
        ..ProptestConfig::default()
    })]

    /// Every motion of a generated program in each language is reported
    /// exactly once, with its file, line, name and status.
    #[test]
    fn every_motion_is_reported_once(
        items in prop::collection::vec(item(), 0..14),
        with_dat in any::<bool>(),
    ) {
        let f = fixture();
        let cases = [
            (Language::Krl, krl(&items, with_dat)),
            (Language::Rapid, rapid(&items)),
            (Language::Fanuc, fanuc(&items)),
            (Language::UrScript, urscript(&items)),
        ];
        for (language, g) in cases {
            let out = filter(language, &g.files, &f.cell, &f.model, &settings()).unwrap();
            check(language, &g, &out.report)?;
        }
    }
}

/// `text` with `cut` bytes from `at` (a fraction of its length, moved back
/// to a character boundary) replaced by `snippet`.
fn spliced(text: &str, at: f64, cut: usize, snippet: &str) -> String {
    let mut start = ((text.len() as f64) * at) as usize;
    while !text.is_char_boundary(start) {
        start -= 1;
    }
    let mut end = (start + cut).min(text.len());
    while !text.is_char_boundary(end) {
        end += 1;
    }
    format!("{}{snippet}{}", &text[..start], &text[end..])
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 256,
        rng_seed: RngSeed::Fixed(0x5eed_1042),
        ..ProptestConfig::default()
    })]

    /// Generated programs with a random splice of brackets, quotes,
    /// separators and names: parsing refuses or succeeds without a panic,
    /// every range it gives lies in its file on character boundaries, and
    /// the filter runs to a report whose counts add up.
    #[test]
    fn spliced_programs_parse_or_are_refused(
        items in prop::collection::vec(item(), 0..8),
        at in 0.0..1.0f64,
        cut in 0usize..24,
        snippet in "[\\[\\](){},:;=\"'\\\\\n PRE0-9.é@!#$]{0,12}",
    ) {
        let f = fixture();
        let cases = [
            (Language::Krl, krl(&items, true)),
            (Language::Rapid, rapid(&items)),
            (Language::Fanuc, fanuc(&items)),
            (Language::UrScript, urscript(&items)),
        ];
        for (language, g) in cases {
            let mut files = g.files;
            files[0].text = spliced(&files[0].text, at, cut, &snippet);
            let Ok(program) = parse(language, &files) else {
                continue;
            };
            let ranges = program
                .sites
                .iter()
                .flat_map(|s| s.slots.iter().chain([&s.mark_at]).map(move |r| (s.file, r)))
                .chain(program.motions.iter().map(|m| (m.file, &m.mark_at)));
            for (file, r) in ranges {
                let t = &files[file].text;
                prop_assert!(
                    r.start <= r.end && r.end <= t.len() && t.is_char_boundary(r.start) && t.is_char_boundary(r.end),
                    "{:?} {:?} in {}", language, r, files[file].name
                );
            }
            let out = filter(language, &files, &f.cell, &f.model, &settings()).unwrap();
            let r = &out.report;
            prop_assert_eq!(r.filtered + r.failed + r.skipped, r.targets.len());
            prop_assert_eq!(r.targets.len() + r.joint_motions.len(), program.motions.len());
        }
    }
}
