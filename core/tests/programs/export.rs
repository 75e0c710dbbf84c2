//! `program::controller`: what the controller must hold, read back by the
//! project's own program parsers to the numbers the filter uses (tool, load,
//! a work object measured in the tracker frame in the base frame, 1e-6 mm).

use super::*;
use robocal_core::model::orientation::{
    rotation_angle_between, rotation_from, OrientationConvention,
};
use robocal_core::program::controller::{export_cell, ExportOptions};
use robocal_core::program::FrameSpec;

/// The one site of `files` with its tool, work object and load.
fn read_back(language: Language, files: &[ProgramFile]) -> (Pose, Pose, Load) {
    let p = parse(language, files).unwrap();
    assert_eq!(p.sites.len(), 1, "{:?}", p.sites);
    let s = &p.sites[0];
    let (FrameSpec::Inline(tool), FrameSpec::Inline(wobj)) = (&s.tool, &s.work_object) else {
        panic!("{:?} / {:?}", s.tool, s.work_object)
    };
    (*tool, *wobj, s.load.expect("a declared load"))
}

fn assert_pose(got: &Pose, want: &Pose, what: &str) {
    let d = (got.p - want.p).norm() * 1e3;
    assert!(d < 1e-6, "{what}: {d} mm");
    let a = rotation_angle_between(&got.r, &want.r);
    assert!(a < 1e-9, "{what}: {a} rad");
}

fn assert_exported(language: Language, files: &[ProgramFile], f: &Fixture) {
    let (tool, wobj, load) = read_back(language, files);
    assert_pose(&tool, &torch(), "tool");
    // The work object measured in the tracker frame, in the calibrated base frame.
    assert_pose(&wobj, &f.wobj_controller(), "work object");
    let want = f.true_load();
    assert!((load.mass_kg - want.mass_kg).abs() < 1e-6);
    assert!((load.com - want.com).norm() < 1e-9, "{:?}", load.com);
}

#[test]
fn exported_cell_data_parse_back_to_what_the_filter_uses() {
    let f = fixture();
    let cell = f.cell_with_load();
    let text = |language: Language, options: &ExportOptions| {
        export_cell(language, &cell, &f.model, options)
            .unwrap()
            .text
    };
    let none = ExportOptions::default();
    let file = |name: &str, text: String| ProgramFile {
        name: name.into(),
        text,
    };

    let krl = text(Language::Krl, &none);
    let files = [
        file("$config.dat", format!("DEFDAT $CONFIG\r\n{krl}ENDDAT\r\n")),
        file(
            "t.src",
            "DEF t()\r\nBAS(#TOOL, 1)\r\nBAS(#BASE, 2)\r\nLIN {X 100,Y 0,Z 0,A 0,B 0,C 0}\r\nEND\r\n".into(),
        ),
    ];
    assert_exported(Language::Krl, &files, f);

    let rapid = text(Language::Rapid, &none);
    let module = format!(
        "MODULE T\r\n{rapid}  PROC main()\r\n    MoveL [[100,0,0],[1,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]], v100, fine, torch\\WObj:=table;\r\n  ENDPROC\r\nENDMODULE\r\n"
    );
    assert_exported(Language::Rapid, &[file("T.mod", module)], f);

    let ur = text(Language::UrScript, &none);
    let script = format!("def t():\n{ur}movel(pose_trans(table, p[0.1, 0, 0, 0, 0, 0]))\nend\n");
    assert_exported(Language::UrScript, &[file("t.script", script)], f);

    // Fanuc: the position registers' elements (those the user gives),
    // UTOOL/UFRAME taken from them.
    let tp = text(
        Language::Fanuc,
        &ExportOptions {
            registers: Some("91..99".parse().unwrap()),
            ..Default::default()
        },
    );
    let register = |n: u32| -> Pose {
        let v: Vec<f64> = (1..=6)
            .map(|j| {
                let key = format!("PR[{n},{j}]=");
                let at = tp.find(&key).unwrap() + key.len();
                tp[at..].split(' ').next().unwrap().parse().unwrap()
            })
            .collect();
        let r = rotation_from(OrientationConvention::FanucWpr, &v[3..]).unwrap();
        Pose::new(r, Vector3::new(v[0], v[1], v[2]) * 1e-3)
    };
    assert!(
        tp.contains("UTOOL[1]=PR[91] ;") && tp.contains("UFRAME[2]=PR[92] ;"),
        "{tp}"
    );
    assert_pose(&register(91), &torch(), "UTOOL");
    assert_pose(&register(92), &f.wobj_controller(), "UFRAME");
    assert!(tp.contains("$PLST_GRP1[1].$PAYLOAD=110.000000 ;"), "{tp}");
    assert!(tp.contains("$PLST_GRP1[1].$PAYLOAD_Z=25.000000 ;"), "{tp}");

    // The filter's answer carries the same data for the program it filtered.
    let prog = format!(
        "DEF t()\r\n$TOOL = TOOL_DATA[1]\r\nBAS(#BASE, 2)\r\nLIN {}\r\nEND\r\n",
        {
            let t = f.target(0);
            let abc =
                robocal_core::model::orientation::rotation_to(OrientationConvention::KukaAbc, &t.r);
            format!(
                "{{X {:.4},Y {:.4},Z {:.4},A {:.4},B {:.4},C {:.4}}}",
                t.p.x * 1e3,
                t.p.y * 1e3,
                t.p.z * 1e3,
                abc[0],
                abc[1],
                abc[2]
            )
        }
    );
    let out = filter(
        Language::Krl,
        &[file("t.src", prog)],
        &cell,
        &f.model,
        &settings(),
    )
    .unwrap();
    assert_eq!(out.report.filtered, 1, "{:?}", out.report.targets);
    let data = &out.report.controller_data;
    let files = [
        file("$config.dat", data.clone()),
        file(
            "u.src",
            "DEF u()\r\nBAS(#TOOL, 1)\r\nBAS(#BASE, 2)\r\nLIN {X 1,Y 0,Z 0,A 0,B 0,C 0}\r\nEND\r\n"
                .into(),
        ),
    ];
    assert_exported(Language::Krl, &files, f);
}

/// The target of `f` at `i` as a KRL inline frame.
fn krl_target(f: &Fixture, i: usize) -> String {
    let t = f.target(i);
    let abc = robocal_core::model::orientation::rotation_to(OrientationConvention::KukaAbc, &t.r);
    format!(
        "{{X {:.4},Y {:.4},Z {:.4},A {:.4},B {:.4},C {:.4}}}",
        t.p.x * 1e3,
        t.p.y * 1e3,
        t.p.z * 1e3,
        abc[0],
        abc[1],
        abc[2]
    )
}

#[test]
fn the_filter_and_the_export_give_an_unnumbered_tool_one_number() {
    // The torch without a number beside a tool numbered 1: both the export
    // and the filter give the torch 2, the lowest free number.
    let f = fixture();
    let mut cell = f.cell_with_load();
    cell.tools[0].number = None;
    cell.tools.push(Tool {
        name: "gun".into(),
        number: Some(1),
        tcp: Pose::from_translation(Vector3::new(0.0, 0.0, 0.1)),
        load: None,
    });
    let krl = export_cell(Language::Krl, &cell, &f.model, &ExportOptions::default()).unwrap();
    let torch_line = krl
        .text
        .lines()
        .find(|l| l.ends_with("; torch"))
        .unwrap()
        .to_string();
    assert!(torch_line.starts_with("TOOL_DATA[2]="), "{}", krl.text);
    assert!(krl
        .text
        .contains("TOOL_DATA[1]={X 0.000000,Y 0.000000,Z 100.000000"));
    let prog = format!(
        "DEF t()\r\n$TOOL = TOOL_DATA[2]\r\nBAS(#BASE, 2)\r\nLIN {}\r\nEND\r\n",
        krl_target(f, 0)
    );
    let file = |name: &str, text: String| ProgramFile {
        name: name.into(),
        text,
    };
    let out = filter(
        Language::Krl,
        &[file("t.src", prog)],
        &cell,
        &f.model,
        &settings(),
    )
    .unwrap();
    assert_eq!(out.report.filtered, 1, "{:?}", out.report.targets);
    // The filter solved with the torch: its controller data name it under
    // the export's number and line.
    let data = &out.report.controller_data;
    assert!(data.lines().any(|l| l == torch_line), "{data}");
    // And the filtered target is the one the torch reaches (the cell with
    // the torch numbered 2 explicitly gives the same program).
    let mut numbered = cell.clone();
    numbered.tools[0].number = Some(2);
    let prog = format!(
        "DEF t()\r\n$TOOL = TOOL_DATA[2]\r\nBAS(#BASE, 2)\r\nLIN {}\r\nEND\r\n",
        krl_target(f, 0)
    );
    let same = filter(
        Language::Krl,
        &[file("t.src", prog)],
        &numbered,
        &f.model,
        &settings(),
    )
    .unwrap();
    assert_eq!(same.files[0].text, out.files[0].text);
}

#[test]
fn the_filter_writes_no_data_for_the_flange_the_base_or_inline_frames() {
    // `$NULLFRAME` base and an inline tool: nothing of the cell is used, so
    // nothing is written (no TOOL_DATA[0] or BASE_DATA[0]).
    let f = fixture();
    let w = f.wobj_controller().compose(&f.target(0));
    let abc = robocal_core::model::orientation::rotation_to(OrientationConvention::KukaAbc, &w.r);
    let t = torch();
    let tabc = robocal_core::model::orientation::rotation_to(OrientationConvention::KukaAbc, &t.r);
    let prog = format!(
        "DEF t()\r\n$TOOL = {{X {:.6},Y {:.6},Z {:.6},A {:.9},B {:.9},C {:.9}}}\r\n$BASE = $NULLFRAME\r\nLIN {{X {:.4},Y {:.4},Z {:.4},A {:.4},B {:.4},C {:.4}}}\r\nEND\r\n",
        t.p.x * 1e3, t.p.y * 1e3, t.p.z * 1e3, tabc[0], tabc[1], tabc[2],
        w.p.x * 1e3, w.p.y * 1e3, w.p.z * 1e3, abc[0], abc[1], abc[2]
    );
    let out = filter(
        Language::Krl,
        &[ProgramFile {
            name: "t.src".into(),
            text: prog,
        }],
        &f.cell_with_load(),
        &f.model,
        &settings(),
    )
    .unwrap();
    assert_eq!(out.report.filtered, 1, "{:?}", out.report.targets);
    assert_eq!(
        out.report.controller_data, "",
        "{}",
        out.report.controller_data
    );
}
