//! Every motion of a program is in the filter's report (issue 42): a `.src`
//! without its `.dat` fails naming each position it lacks; position
//! registers, `INC`, offsets, `LIN_REL`, `Offs` and `RelTool` are skipped
//! with their reason; targets with external-axis values are refused naming
//! the axis; a failed flag names the configurations that do reach the
//! target; an unflagged target gets the configuration `solve` gives it.

use super::examples::{cell, read};
use super::*;
use robocal_core::model::orientation::{rotation_to, OrientationConvention};
use robocal_core::program::{filter, kuka_status, kuka_turn, FilterReport, TargetStatus};
use robocal_core::sim::{synthetic_calibration, SyntheticErrors};
use robocal_core::solve::cell::{CellOptions, CellRef, CellSolver};

use TargetStatus::{Failed, Filtered, Skipped};

fn ys100() -> CompensatedModel {
    synthetic_calibration(
        &preset("ys100").unwrap(),
        &SyntheticErrors::typical(1e-6),
        3,
    )
}

/// (motion line, instruction, name, status) of every report line.
fn lines(r: &FilterReport) -> Vec<(usize, &str, &str, TargetStatus)> {
    r.targets
        .iter()
        .map(|t| {
            (
                t.motion.line,
                t.motion.instruction.as_str(),
                t.name.as_str(),
                t.status,
            )
        })
        .collect()
}

/// The report's counts add up to its lines.
fn assert_counts(r: &FilterReport) {
    assert_eq!(r.filtered + r.failed + r.skipped, r.targets.len(), "{r:?}");
    for (s, n) in [
        (Filtered, r.filtered),
        (Failed, r.failed),
        (Skipped, r.skipped),
    ] {
        assert_eq!(r.targets.iter().filter(|t| t.status == s).count(), n);
    }
}

fn reason<'a>(r: &'a FilterReport, name: &str) -> &'a str {
    r.targets
        .iter()
        .find(|t| t.name == name)
        .and_then(|t| t.reason.as_deref())
        .unwrap_or_else(|| panic!("no reason for {name}: {r:?}"))
}

#[test]
fn a_src_without_its_dat_fails_naming_each_position() {
    let model = ys100();
    let src = read("krl/seam.src");
    let out = filter(
        Language::Krl,
        std::slice::from_ref(&src),
        &cell("cell.json"),
        &model,
        &settings(),
    )
    .unwrap();
    let r = &out.report;
    assert_eq!(
        lines(r),
        [
            (12, "PTP", "XP1", Failed),
            (13, "LIN", "XP2", Failed),
            (15, "LIN", "inline", Filtered),
            (16, "CIRC", "XAUX", Failed),
            (16, "CIRC", "XP4", Failed),
            (17, "LIN", "inline", Filtered),
            (19, "LIN_REL", "inline", Skipped),
        ]
    );
    assert_counts(r);
    assert_eq!((r.filtered, r.failed, r.skipped), (2, 4, 1));
    let why = reason(r, "XP1");
    assert_eq!(
        why,
        "XP1 is not declared in the program's files (a .src needs its .dat)"
    );
    assert!(reason(r, "XP4").starts_with("XP4 is not declared"));
    assert!(r.targets[6]
        .reason
        .as_ref()
        .unwrap()
        .starts_with("relative motion: LIN_REL"));
    // The home moves are joint motions, listed apart, saying why.
    let joints: Vec<(usize, &str)> = r
        .joint_motions
        .iter()
        .map(|j| (j.line, j.name.as_str()))
        .collect();
    assert_eq!(joints, [(8, "XHOME"), (20, "XHOME")]);
    assert!(r.joint_motions[0]
        .note
        .as_ref()
        .unwrap()
        .contains("$config.dat"));
    // The motions lacking their positions are marked in the program.
    let text: Vec<&str> = out.files[0].text.lines().collect();
    assert_eq!(
        text[11],
        format!("PTP XP1 C_PTP ; robocal: not filtered: {why}")
    );
    assert!(text[15].starts_with("CIRC XAUX, XP4 ; robocal: not filtered: XAUX is not declared"));
    assert!(text[15].contains("; robocal: not filtered: XP4 is not declared"));

    // With its .dat: the named points are filtered where they are declared.
    let out = filter(
        Language::Krl,
        &[src, read("krl/seam.dat")],
        &cell("cell.json"),
        &model,
        &settings(),
    )
    .unwrap();
    let r = &out.report;
    assert_counts(r);
    assert_eq!((r.filtered, r.failed, r.skipped), (6, 0, 1));
    let xp1 = &r.targets[0];
    assert_eq!(
        (
            xp1.file.as_str(),
            xp1.line,
            xp1.motion.file.as_str(),
            xp1.motion.line
        ),
        ("seam.dat", 6, "seam.src", 12)
    );
    assert!(r.unused.is_empty(), "{:?}", r.unused);
}

#[test]
fn fanuc_registers_increments_offsets_and_missing_positions_are_reported() {
    let model = ys100();
    let mut ls = read("fanuc/SEAM.LS");
    ls.text = ls.text.replace(
        "  10:  DO[3]=OFF ;\n",
        "  10:  DO[3]=OFF ;\n  11:L PR[3] 200mm/sec FINE    ;\n  12:L P[2] 100mm/sec FINE INC ;\n\
         \x20 13:L P[3] 100mm/sec FINE Offset,PR[1] ;\n  14:L P[9] 100mm/sec FINE ;\n",
    );
    let out = filter(
        Language::Fanuc,
        std::slice::from_ref(&ls),
        &cell("cell.json"),
        &model,
        &settings(),
    )
    .unwrap();
    let r = &out.report;
    assert_counts(r);
    assert_eq!(
        lines(r),
        [
            (26, "J", "P[1]", Filtered),
            (27, "L", "P[2]", Filtered),
            (29, "L", "P[3]", Filtered),
            (30, "C", "P[4]", Filtered),
            (30, "C", "P[5]", Filtered),
            (33, "L", "PR[3]", Skipped),
            (34, "L", "P[2]", Skipped),
            (35, "L", "P[3]", Skipped),
            (36, "L", "P[9]", Failed),
        ]
    );
    assert_eq!(
        reason(r, "PR[3]"),
        "PR[3] is a position register, set at run time"
    );
    assert!(r.targets[6].reason.as_ref().unwrap().contains("(INC)"));
    assert!(r.targets[7]
        .reason
        .as_ref()
        .unwrap()
        .contains("Offset,PR[1]"));
    assert_eq!(
        reason(r, "P[9]"),
        "P[9] is not declared in the program's files (no such position in /POS)"
    );
    assert!(out.files[0]
        .text
        .contains("  14:L P[9:\"robocal: failed\"] 100mm/sec FINE ;\n"));
    // The home position is in joint form: a joint motion.
    let joints: Vec<usize> = r.joint_motions.iter().map(|j| j.line).collect();
    assert_eq!(joints, [25, 37]);
}

#[test]
fn rapid_offs_and_reltool_are_skipped_and_their_point_filtered_where_used() {
    let model = ys100();
    let mut module = read("rapid/Seam.mod");
    module.text = module.text.replace(
        "    SetDO doArc, 0; ! arc off\n",
        "    SetDO doArc, 0; ! arc off\n    MoveL Offs(p20, 0, 0, 50), v200, fine, torch\\WObj:=table;\n    \
         MoveL RelTool(p20, 0, 0, -20 \\Rz:=10), v200, fine, torch\\WObj:=table;\n    MoveL p30, v200, fine, torch\\WObj:=table;\n",
    );
    let out = filter(
        Language::Rapid,
        std::slice::from_ref(&module),
        &Cell::default(),
        &model,
        &settings(),
    )
    .unwrap();
    let r = &out.report;
    assert_counts(r);
    assert_eq!(
        lines(r),
        [
            (13, "MoveJ", "p10", Filtered),
            (14, "MoveL", "p20", Filtered),
            (16, "MoveL", "inline", Filtered),
            (17, "MoveC", "arc{1}", Filtered),
            (17, "MoveC", "arc{2}", Filtered),
            (19, "MoveL", "Offs(p20, 0, 0, 50)", Skipped),
            (20, "MoveL", "RelTool(p20, 0, 0, -20 \\Rz:=10)", Skipped),
            (21, "MoveL", "p30", Failed),
        ]
    );
    assert_eq!(
        reason(r, "Offs(p20, 0, 0, 50)"),
        "`Offs(p20, 0, 0, 50)` is computed at run time"
    );
    assert!(reason(r, "p30").starts_with("p30 is not declared"));
    let joints: Vec<usize> = r.joint_motions.iter().map(|j| j.line).collect();
    assert_eq!(joints, [12, 22]);
}

#[test]
fn targets_with_external_axes_are_refused_naming_the_axis() {
    let model = ys100();
    // KRL: an E6POS with E1 = 500 in the .dat.
    let dat = read("krl/seam.dat");
    let krl = [
        read("krl/seam.src"),
        ProgramFile {
            text: dat
                .text
                .replace("C 180.0,S 0,T 5,E1 0.0", "C 180.0,S 0,T 5,E1 500.0"),
            ..dat.clone()
        },
    ];
    // RAPID: p20 on a track (eax_a = 1200 mm).
    let mut rapid = read("rapid/Seam.mod");
    rapid.text = rapid.text.replacen(
        "[[100,0,0],[0,1,0,0],[-1,1,1,0],[9E+09,",
        "[[100,0,0],[0,1,0,0],[-1,1,1,0],[1200,",
        1,
    );
    // Fanuc: P[2] with an extended axis, P[3] with a second group.
    let mut fanuc = read("fanuc/SEAM.LS");
    fanuc.text = fanuc.text.replace(
        "X =    100.000  mm,\tY =      0.000  mm,\tZ =      0.000  mm,\n\tW =   180.000 deg,\tP =     0.000 deg,\tR =     0.000 deg\n",
        "X =    100.000  mm,\tY =      0.000  mm,\tZ =      0.000  mm,\n\tW =   180.000 deg,\tP =     0.000 deg,\tR =     0.000 deg,\n\tE1 =   750.000  mm\n",
    );
    fanuc.text = fanuc.text.replace(
        "X =    200.000  mm,\tY =     50.000  mm,\tZ =      0.000  mm,\n\tW =   180.000 deg,\tP =     0.000 deg,\tR =     0.000 deg\n",
        "X =    200.000  mm,\tY =     50.000  mm,\tZ =      0.000  mm,\n\tW =   180.000 deg,\tP =     0.000 deg,\tR =     0.000 deg\n   GP2:\n\tUF : 0, UT : 1,\n\tJ1 =    90.000 deg\n",
    );
    let cases = [
        (
            Language::Krl,
            krl.to_vec(),
            cell("cell.json"),
            "XP1",
            "external axis E1 to 500.0",
            5,
        ),
        (
            Language::Rapid,
            vec![rapid],
            Cell::default(),
            "p20",
            "external axis eax_a to 1200",
            4,
        ),
        (
            Language::Fanuc,
            vec![fanuc.clone()],
            cell("cell.json"),
            "P[2]",
            "external axis E1 to 750.000 mm",
            3,
        ),
        (
            Language::Fanuc,
            vec![fanuc],
            cell("cell.json"),
            "P[3]",
            "motion group GP2",
            3,
        ),
    ];
    for (language, files, cell, name, axis, filtered) in cases {
        let out = filter(language, &files, &cell, &model, &settings()).unwrap();
        let r = &out.report;
        assert_counts(r);
        let t = r.targets.iter().find(|t| t.name == name).unwrap();
        assert_eq!(t.status, Failed, "{language:?} {t:?}");
        let why = t.reason.as_deref().unwrap();
        assert!(
            why.contains(axis) && why.contains("the cell does not model"),
            "{language:?}: {why}"
        );
        assert!(r.filtered >= filtered, "{language:?}: {r:?}");
        // Unchanged but for its mark.
        let marked: String = match language {
            Language::Krl => format!(" ; robocal: not filtered: {why}"),
            Language::Rapid => format!(" ! robocal: not filtered: {why}"),
            _ => ":\"robocal: failed\"".into(),
        };
        let f = files.iter().position(|f| f.name == t.file).unwrap();
        assert!(out.files[f].text.contains(&marked), "{language:?}");
    }
}

/// The KUKA flags (`S s T t`) of every solution of the nominal controller
/// (the closed form of the nominal model with the torch, every 2π
/// representative within the limits) for `tcp` in the base frame.
fn controller_flags(f: &Fixture, tcp: &Pose) -> Vec<String> {
    let ik = AnalyticIk::new(&f.controller).unwrap();
    let limits: Vec<[f64; 2]> = f.controller.links.iter().map(|l| l.limits).collect();
    let mut out = Vec::new();
    for s in ik.solve(tcp, None) {
        let mut all: Vec<Vec<f64>> = vec![Vec::new()];
        for (k, q) in s.q.iter().enumerate() {
            let turns = (-2..=2).map(|t| q + f64::from(t) * std::f64::consts::TAU);
            let reps: Vec<f64> = turns
                .filter(|v| *v >= limits[k][0] - 1e-9 && *v <= limits[k][1] + 1e-9)
                .collect();
            all = all
                .into_iter()
                .flat_map(|h| {
                    reps.iter().map(move |v| {
                        let mut h = h.clone();
                        h.push(*v);
                        h
                    })
                })
                .collect();
        }
        for q in all {
            let deg: Vec<f64> = f
                .controller
                .joints_to_controller(&q)
                .iter()
                .map(|v| v.to_degrees())
                .collect();
            let text = format!(
                "S {} T {}",
                kuka_status(&deg, s.configuration),
                kuka_turn(&deg)
            );
            if !out.contains(&text) {
                out.push(text);
            }
        }
    }
    out.sort();
    out
}

/// A one-target KRL program in tool 1, base 2, with `flags` (`,S 2,T 35` or empty).
fn one_target(t: &Pose, flags: &str) -> ProgramFile {
    let abc = rotation_to(OrientationConvention::KukaAbc, &t.r);
    ProgramFile {
        name: "one.src".into(),
        text: format!(
            "DEF one()\n$TOOL = TOOL_DATA[1]\nBAS(#BASE, 2)\nLIN {{X {:.4},Y {:.4},Z {:.4},A {:.4},B {:.4},C {:.4}{flags}}}\nEND\n",
            t.p.x * 1e3,
            t.p.y * 1e3,
            t.p.z * 1e3,
            abc[0],
            abc[1],
            abc[2]
        ),
    }
}

#[test]
fn a_failed_flag_names_the_configurations_that_reach_the_target() {
    let f = fixture();
    let target = f.target(3);
    let tcp = f.wobj_controller().compose(&target);
    let reachable = controller_flags(f, &tcp);
    assert!(reachable.len() >= 2, "{reachable:?}");
    // Flags no solution carries: every status with a turn no solution has.
    let (deg, _) = f.flag_input(3);
    let t = kuka_turn(&deg) ^ 0b1000;
    let s = (0..8)
        .find(|s| !reachable.contains(&format!("S {s} T {t}")))
        .unwrap();
    let program = one_target(&target, &format!(",S {s},T {t}"));
    let out = filter(Language::Krl, &[program], &f.cell, &f.model, &settings()).unwrap();
    let line = &out.report.targets[0];
    assert_eq!(line.status, Failed, "{line:?}");
    let mut got: Vec<String> = line
        .reachable
        .iter()
        .map(|r| r.flags.clone().unwrap())
        .collect();
    got.sort();
    assert_eq!(got, reachable);
    let why = line.reason.as_deref().unwrap();
    assert!(why.contains("; reachable with S "), "{why}");
    // Each configuration named is the one of its flags (bits 0 and 1 of S).
    for r in &line.reachable {
        let s: u32 = r.flags.as_ref().unwrap()[2..3].parse().unwrap();
        let c = robocal_core::solve::ik::Configuration::parse(&r.configuration).unwrap();
        assert_eq!(
            s & 1 == 1,
            c.shoulder == robocal_core::solve::ik::Shoulder::Back
        );
        assert_eq!(s & 2 == 2, c.elbow == robocal_core::solve::ik::Elbow::Down);
    }
}

#[test]
fn an_unflagged_target_gets_the_configuration_solve_gives_it() {
    let f = fixture();
    let tool = f.cell.tool(&CellRef::Number(1)).unwrap();
    let wobj = f.cell.work_object(&CellRef::Number(2)).unwrap();
    let solver = CellSolver::for_tool(&f.model, Some(&tool), settings());
    // Targets where the nominal controller's first solution (the filter's
    // old choice without a previous target) is not the configuration
    // `solve` gives: there the two answers differed.
    let mut compared = 0;
    for i in 0..f.joints.len() {
        let program = one_target(&f.target(i), "");
        let pose = parse(Language::Krl, std::slice::from_ref(&program))
            .unwrap()
            .sites[0]
            .pose
            .unwrap();
        let solved = solver.solve(&wobj, &pose, &CellOptions::default());
        let first = solver.nominal_solutions(&wobj, &pose);
        let c = solved.solution.branch;
        if !solved.solution.converged || first.first().map(|q| solver.configuration(q)) == Some(c) {
            continue;
        }
        compared += 1;
        let out = filter(Language::Krl, &[program], &f.cell, &f.model, &settings()).unwrap();
        let line = &out.report.targets[0];
        assert_eq!(line.status, Filtered, "{line:?}");
        assert_eq!(line.configuration, c.map(|c| c.to_string()));
        let want = solver.solver().controller_degrees(&solved.solution.q);
        for (a, b) in line.joints_deg.as_ref().unwrap().iter().zip(&want) {
            assert!((a - b).abs() < 1e-9, "target {i}: {a} vs {b} deg");
        }
        // The false target written (4 decimals) is the solve's.
        let written = parse(Language::Krl, &out.files).unwrap().sites[0]
            .pose
            .unwrap();
        let ft = solved.false_target.unwrap();
        assert!((written.p - ft.p).norm() < 1e-7, "target {i}");
        assert!((written.r - ft.r).norm() < 1e-5, "target {i}");
    }
    assert!(
        compared >= 3,
        "{compared} targets where the old choice differed"
    );
}
