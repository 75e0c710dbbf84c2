//! KUKA KRL: a `.src` with its `.dat`, 50 targets declared and inline.

use super::stationary::{swapped, Swapped};
use super::*;
use robocal_core::model::orientation::{rotation_to, OrientationConvention};
use robocal_core::program::LoadSource;
use robocal_core::program::{filter, kuka_status, kuka_turn, TargetStatus};

/// A KRL program visiting the fixture's 50 targets: even ones declared in the
/// `.dat` and moved to by `PTP`, odd ones inline in `LIN`, with logic and
/// comments between them.
fn program(f: &Fixture) -> Vec<ProgramFile> {
    let ik = AnalyticIk::new(&f.controller).unwrap();
    let mut src = String::from(
        "&ACCESS RVP\r\nDEF seam()\r\n; welding seam, taught on the table\r\n\
         INI\r\nPTP {A1 0,A2 90,A3 -20,A4 0,A5 45,A6 0} ; home\r\n\
         $TOOL = TOOL_DATA[1] ; torch\r\nBAS(#BASE, 2)\r\n$VEL.CP = 0.2\r\n",
    );
    let mut dat = String::from("&ACCESS RVP\r\nDEFDAT seam\r\n");
    for (i, q) in f.joints.iter().enumerate() {
        let t = f.target(i);
        let abc = rotation_to(OrientationConvention::KukaAbc, &t.r);
        let deg: Vec<f64> = f
            .controller
            .joints_to_controller(q)
            .iter()
            .map(|v| v.to_degrees())
            .collect();
        let s = kuka_status(&deg, ik.configuration(q).unwrap());
        let agg = format!(
            "{{X {:.4},Y {:.4},Z {:.4},A {:.4},B {:.4},C {:.4},S {s},T {}",
            t.p.x * 1e3,
            t.p.y * 1e3,
            t.p.z * 1e3,
            abc[0],
            abc[1],
            abc[2],
            kuka_turn(&deg)
        );
        if i % 2 == 0 {
            src.push_str(&format!("PTP XP{i} C_PTP\r\n"));
            dat.push_str(&format!("DECL E6POS XP{i}={agg},E1 0.0,E2 0.0}}\r\n"));
        } else {
            src.push_str(&format!("LIN {agg}}} C_DIS ; seam point {i}\r\n"));
            src.push_str("$OUT[3] = TRUE\r\nWAIT SEC 0.2\r\n");
        }
    }
    src.push_str("PTP {A1 0,A2 90,A3 -20,A4 0,A5 45,A6 0}\r\nEND\r\n");
    dat.push_str("ENDDAT\r\n");
    vec![
        ProgramFile {
            name: "seam.src".into(),
            text: src,
        },
        ProgramFile {
            name: "seam.dat".into(),
            text: dat,
        },
    ]
}

#[test]
fn filtered_krl_brings_the_true_tcp_to_the_targets() {
    let f = fixture();
    let files = program(f);
    assert_filter_reaches_targets(f, Language::Krl, "KRL", &files, &f.cell);
}

/// The same program declaring its load: `LOAD_DATA[1]` in a `$config.dat`,
/// taken by `BAS(#TOOL, 1)`.
fn with_load_data(f: &Fixture, mass_kg: f64, z_mm: f64) -> Vec<ProgramFile> {
    let mut files = program(f);
    files[0].text = files[0]
        .text
        .replace("$TOOL = TOOL_DATA[1] ; torch\r\n", "BAS(#TOOL, 1)\r\n");
    files.push(ProgramFile {
        name: "$config.dat".into(),
        text: format!(
            "DEFDAT $CONFIG PUBLIC\r\nLOAD_DATA[1]={{M {mass_kg},CM {{X 0.0,Y 0.0,Z {z_mm},A 0.0,B 0.0,C 0.0}},J {{X 0.0,Y 0.0,Z 0.0}}}}\r\nENDDAT\r\n"
        ),
    });
    files
}

#[test]
fn a_declared_load_is_used_and_one_differing_from_the_cell_is_warned_about() {
    let f = fixture();
    let cell = f.cell_with_load();
    // As the cell's: no warning, solved with the program's load.
    let files = with_load_data(f, 110.0, 250.0);
    let out = filter(Language::Krl, &files, &cell, &f.model, &settings()).unwrap();
    assert_eq!(out.report.filtered, 50);
    for t in &out.report.targets {
        assert!(t.warnings.is_empty(), "{:?}", t.warnings);
        let load = t.load.as_ref().unwrap();
        assert_eq!(load.source, robocal_core::program::LoadSource::Program);
        assert_eq!(
            (load.load.mass_kg, load.load.com_mm),
            (110.0, [0.0, 0.0, 250.0])
        );
    }
    // 20 kg less and 50 mm nearer the flange: a warning naming both, per target.
    let files = with_load_data(f, 90.0, 200.0);
    let out = filter(Language::Krl, &files, &cell, &f.model, &settings()).unwrap();
    for t in &out.report.targets {
        assert_eq!(t.warnings.len(), 1, "{t:?}");
        let w = &t.warnings[0];
        assert!(
            w.contains("90.000 kg at [0.0, 0.0, 200.0] mm")
                && w.contains("110.000 kg at [0.0, 0.0, 250.0] mm"),
            "{w}"
        );
    }
    // The cell's load without a declaration: solved with the cell's.
    let out = filter(Language::Krl, &program(f), &cell, &f.model, &settings()).unwrap();
    let load = out.report.targets[0].load.as_ref().unwrap();
    assert_eq!(load.source, robocal_core::program::LoadSource::Cell);
}

#[test]
fn krl_without_targets_is_byte_identical_and_failures_are_marked() {
    let f = fixture();
    let logic = ProgramFile {
        name: "io.src".into(),
        text: "DEF io()\n; no Cartesian target\nPTP {A1 10,A2 90,A3 -20,A4 0,A5 45,A6 0}\n\
               $OUT[1]=TRUE\nWAIT FOR $IN[2]\nEND\n"
            .into(),
    };
    let out = filter(
        Language::Krl,
        std::slice::from_ref(&logic),
        &f.cell,
        &f.model,
        &settings(),
    )
    .unwrap();
    assert_eq!(out.files[0], logic);
    assert!(out.report.targets.is_empty());

    // Out of reach, an unknown tool: unchanged but for the mark, reported with line and reason.
    let text = "DEF bad()\n$TOOL=TOOL_DATA[1]\n$BASE=BASE_DATA[2]\n\
                LIN {X 9000,Y 0,Z 0,A 0,B 0,C 0} ; far\n$TOOL=TOOL_DATA[7]\n\
                LIN {X 100,Y 0,Z 0,A 0,B 0,C 0}\nEND\n";
    let file = ProgramFile {
        name: "bad.src".into(),
        text: text.into(),
    };
    let out = filter(Language::Krl, &[file], &f.cell, &f.model, &settings()).unwrap();
    let t = &out.report.targets;
    assert_eq!((t[0].line, t[0].status), (4, TargetStatus::Failed));
    assert!(
        t[0].reason.as_ref().unwrap().contains("reach"),
        "{:?}",
        t[0].reason
    );
    assert_eq!((t[1].line, t[1].status), (6, TargetStatus::Failed));
    assert!(t[1].reason.as_ref().unwrap().contains("no tool #7"));
    let lines: Vec<&str> = out.files[0].text.lines().collect();
    assert!(
        lines[3].starts_with("LIN {X 9000,Y 0,Z 0,A 0,B 0,C 0} ; far ; robocal: not filtered: ")
    );
    assert_eq!(
        lines[5],
        format!(
            "LIN {{X 100,Y 0,Z 0,A 0,B 0,C 0}} ; robocal: not filtered: {}",
            t[1].reason.as_ref().unwrap()
        )
    );
    let rest: Vec<&str> = text.lines().collect();
    for i in [0, 1, 2, 4, 6] {
        assert_eq!(lines[i], rest[i]);
    }
}

#[test]
fn an_unparsable_krl_program_fails_with_file_line_and_column() {
    let f = fixture();
    let file = ProgramFile {
        name: "broken.src".into(),
        text: "DEF broken()\n  LIN {X 1,Y 2,Z\nEND\n".into(),
    };
    let e = filter(Language::Krl, &[file], &f.cell, &f.model, &settings()).unwrap_err();
    assert_eq!((e.file.as_str(), e.line, e.column), ("broken.src", 2, 7));
    assert_eq!(
        e.to_string(),
        "broken.src:2:7: aggregate not closed on its line"
    );
}

/// A KRL aggregate of `p` (mm, `A B C` degrees).
fn frame_agg(p: &Pose) -> String {
    let abc = rotation_to(OrientationConvention::KukaAbc, &p.r);
    format!(
        "X {:.4},Y {:.4},Z {:.4},A {:.4},B {:.4},C {:.4}",
        p.p.x * 1e3,
        p.p.y * 1e3,
        p.p.z * 1e3,
        abc[0],
        abc[1],
        abc[2]
    )
}

/// An external-TCP program (`$IPO_MODE = #TCP`): the stationary tool in
/// `BASE_DATA[4]`, the work piece the robot carries in `TOOL_DATA[3]`, the
/// points the fixed tool's pose in the carried work piece; even ones declared
/// and moved to by `PTP`, odd ones inline in `LIN`. With `config` the frames
/// and the load are in a `$config.dat`, else the cell holds them.
fn external_tcp(s: &Swapped, f: &Fixture, config: bool) -> Vec<ProgramFile> {
    let ik = AnalyticIk::new(&s.bare).unwrap();
    let mut src = String::from(
        "&ACCESS RVP\r\nDEF glue()\r\nINI\r\n$IPO_MODE = #TCP ; the nozzle is fixed\r\n\
         $TOOL = TOOL_DATA[3]\r\n$BASE = BASE_DATA[4]\r\n",
    );
    if config {
        src.push_str("$LOAD = LOAD_DATA[3]\r\n");
    }
    let mut dat = String::from("&ACCESS RVP\r\nDEFDAT glue\r\n");
    for (i, q) in s.joints.iter().enumerate() {
        let deg: Vec<f64> = s
            .bare
            .joints_to_controller(q)
            .iter()
            .map(|v| v.to_degrees())
            .collect();
        let agg = format!(
            "{{{},S {},T {}",
            frame_agg(&s.target(f, i)),
            kuka_status(&deg, ik.configuration(q).unwrap()),
            kuka_turn(&deg)
        );
        if i % 2 == 0 {
            src.push_str(&format!("PTP XG{i} C_PTP\r\n"));
            dat.push_str(&format!("DECL E6POS XG{i}={agg},E1 0.0,E2 0.0}}\r\n"));
        } else {
            src.push_str(&format!("LIN {agg}}} C_DIS\r\n"));
        }
    }
    src.push_str("$IPO_MODE = #BASE\r\nEND\r\n");
    dat.push_str("ENDDAT\r\n");
    let mut files = vec![
        ProgramFile {
            name: "glue.src".into(),
            text: src,
        },
        ProgramFile {
            name: "glue.dat".into(),
            text: dat,
        },
    ];
    if config {
        let c = f.truth.payload_com * 1e3;
        files.push(ProgramFile {
            name: "$config.dat".into(),
            text: format!(
                "DEFDAT $CONFIG PUBLIC\r\nTOOL_DATA[3]={{{}}}\r\nBASE_DATA[4]={{{}}}\r\n\
                 LOAD_DATA[3]={{M {},CM {{X {:.3},Y {:.3},Z {:.3},A 0.0,B 0.0,C 0.0}},J {{X 0.0,Y 0.0,Z 0.0}}}}\r\nENDDAT\r\n",
                frame_agg(&s.held),
                frame_agg(&s.fixed_base),
                f.truth.payload_kg,
                c.x,
                c.y,
                c.z
            ),
        });
    }
    files
}

/// External TCP, the frames from the program's `$config.dat` and from the
/// cell (the fixed tool a work object measured in the tracker frame, the
/// carried work piece a tool with the true load): the true tool tip in the
/// truly carried work piece reaches every target.
#[test]
fn an_external_tcp_is_filtered_with_the_roles_swapped() {
    let f = fixture();
    let s = swapped(f);
    let mut cell = Cell::default();
    cell.tools.push(Tool {
        name: "part".into(),
        number: Some(3),
        tcp: s.held,
        load: Some(f.true_load()),
    });
    cell.work_objects.push(WorkObject {
        name: "nozzle".into(),
        number: Some(4),
        frame: WorkObjectFrame::Measurement,
        pose: s.fixed_cell,
    });
    for (config, cell, source) in [
        (true, Cell::default(), LoadSource::Program),
        (false, cell, LoadSource::Cell),
    ] {
        let files = external_tcp(&s, f, config);
        let out = filter(Language::Krl, &files, &cell, &f.model, &settings()).unwrap();
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
            .all(|t| t.load.as_ref().unwrap().source == source));
        let filtered = s.run(f, Language::Krl, &out.files);
        assert!(filtered.iter().all(Option::is_some), "{filtered:?}");
        let max_f = filtered.iter().flatten().copied().fold(0.0, f64::max);
        let (mean_f, _) = mean(&filtered);
        let (mean_u, reached_u) = mean(&s.run(f, Language::Krl, &files));
        println!(
            "KRL external TCP ({}): true tool tip vs target filtered mean {mean_f:.4} mm, \
             max {max_f:.4} mm (40); unfiltered mean {mean_u:.3} mm ({reached_u})",
            if config { "$config.dat" } else { "cell" }
        );
        assert!(mean_f <= 0.05 && max_f <= 0.15, "{mean_f} {max_f}");
        assert!(mean_u > 1.0, "{mean_u}");
    }
    // Without the cell's frames the references cannot be resolved: failed,
    // saying which.
    let out = filter(
        Language::Krl,
        &external_tcp(&s, f, false),
        &Cell::default(),
        &f.model,
        &settings(),
    )
    .unwrap();
    assert_eq!(out.report.failed, 40);
    let why = out.report.targets[0].reason.as_deref().unwrap();
    assert!(why.contains("stationary tool"), "{why}");
}
