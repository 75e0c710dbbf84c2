//! The export's decisions on the cells of issue 42: one number per item in
//! every language, 0 refused where it is the flange or the base, RAPID
//! identifiers valid and distinct, registers only when given. The texts are
//! read back with the project's own parsers where they define frames
//! (`core/tests/programs/export.rs` reads the poses back to 1e-6 mm).

use super::*;
use crate::model::preset;
use crate::program::{parse, FrameSpec, ProgramFile};
use crate::solve::cell::{Tool, WorkObject, WorkObjectFrame};
use nalgebra::Vector3;

fn model() -> CompensatedModel {
    CompensatedModel::from_nominal(preset("ys100").unwrap())
}

fn tool(name: &str, number: Option<u32>, z_mm: f64) -> Tool {
    Tool {
        name: name.into(),
        number,
        tcp: Pose::from_translation(Vector3::new(0.0, 0.0, z_mm * 1e-3)),
        load: None,
    }
}

fn wobj(name: &str, number: Option<u32>, x_mm: f64) -> WorkObject {
    WorkObject {
        name: name.into(),
        number,
        frame: WorkObjectFrame::Base,
        pose: Pose::from_translation(Vector3::new(x_mm * 1e-3, 0.0, 0.0)),
    }
}

/// A tool numbered 2 and one without a number; likewise two work objects.
fn mixed_cell() -> Cell {
    Cell {
        tools: vec![tool("gun", Some(2), 200.0), tool("torch", None, 300.0)],
        work_objects: vec![
            wobj("table", Some(1), 1000.0),
            wobj("fixture", None, 1500.0),
        ],
    }
}

fn count(text: &str, what: &str) -> usize {
    text.matches(what).count()
}

#[test]
fn every_item_has_its_own_number_in_krl_and_fanuc() {
    let cell = mixed_cell();
    let krl = export_cell(Language::Krl, &cell, &model(), &ExportOptions::default()).unwrap();
    assert_eq!(count(&krl.text, "TOOL_DATA[2]="), 1, "{}", krl.text);
    assert_eq!(count(&krl.text, "TOOL_DATA[1]="), 1, "{}", krl.text);
    assert_eq!(count(&krl.text, "BASE_DATA[1]="), 1, "{}", krl.text);
    assert_eq!(count(&krl.text, "BASE_DATA[2]="), 1, "{}", krl.text);
    assert!(krl
        .text
        .contains("TOOL_DATA[1]={X 0.000000,Y 0.000000,Z 300.000000"));
    assert!(
        krl.text.contains("BASE_DATA[2]={X 1500.000000,"),
        "{}",
        krl.text
    );
    // Reported in the text and in the answer.
    assert!(
        krl.text
            .contains("; robocal: tool `torch` has no number: TOOL_DATA[1], the lowest free"),
        "{}",
        krl.text
    );
    let given: Vec<(ItemKind, &str, u32)> = krl
        .assigned
        .iter()
        .map(|a| (a.kind, a.name.as_str(), a.number))
        .collect();
    assert_eq!(
        given,
        vec![
            (ItemKind::Tool, "torch", 1),
            (ItemKind::WorkObject, "fixture", 2)
        ]
    );
    // The project's KRL parser reads the data back under those numbers.
    let files = [
        ProgramFile {
            name: "$config.dat".into(),
            text: format!("DEFDAT $CONFIG\r\n{}ENDDAT\r\n", krl.text),
        },
        ProgramFile {
            name: "t.src".into(),
            text: "DEF t()\r\nBAS(#TOOL, 1)\r\nBAS(#BASE, 2)\r\nLIN {X 1,Y 0,Z 0,A 0,B 0,C 0}\r\nEND\r\n"
                .into(),
        },
    ];
    let p = parse(Language::Krl, &files).unwrap();
    let (FrameSpec::Inline(t), FrameSpec::Inline(w)) = (&p.sites[0].tool, &p.sites[0].work_object)
    else {
        panic!("{:?}", p.sites[0])
    };
    assert!((t.p.z - 0.3).abs() < 1e-9 && (w.p.x - 1.5).abs() < 1e-9);

    let tp = export_cell(Language::Fanuc, &cell, &model(), &ExportOptions::default()).unwrap();
    for data in ["UTOOL[2]", "UTOOL[1]", "UFRAME[1]", "UFRAME[2]"] {
        assert_eq!(count(&tp.text, &format!("! {data} X ")), 1, "{}", tp.text);
    }
    assert_eq!(count(&tp.text, "$PLST_GRP1[1].$PAYLOAD="), 1, "{}", tp.text);
    assert_eq!(count(&tp.text, "$PLST_GRP1[2].$PAYLOAD="), 1, "{}", tp.text);
    assert_eq!(tp.assigned, krl.assigned);
    // RAPID and URScript name their data: no numbers to report.
    let rapid = export_cell(Language::Rapid, &cell, &model(), &ExportOptions::default()).unwrap();
    assert!(rapid.assigned.is_empty());
}

#[test]
fn the_filter_finds_an_unnumbered_item_under_the_number_the_export_gives_it() {
    let cell = mixed_cell();
    let data = controller_data(&cell, &model());
    for t in &data.tools {
        let found = cell.tool(&CellRef::Number(t.number)).unwrap();
        assert_eq!(found.name, t.name);
        assert_eq!(found.number, Some(t.number));
    }
    for f in &data.frames {
        assert_eq!(
            cell.work_object(&CellRef::Number(f.number)).unwrap().name,
            f.name
        );
    }
    // A number two items hold is refused by both, naming both.
    let mut twice = mixed_cell();
    twice.tools[1].number = Some(2);
    let e = export_cell(Language::Krl, &twice, &model(), &ExportOptions::default()).unwrap_err();
    assert!(e.to_string().contains("`gun` and `torch`"), "{e}");
    let e = twice.tool(&CellRef::Number(2)).unwrap_err();
    assert!(e.to_string().contains("`gun` and `torch`"), "{e}");
}

use crate::solve::cell::CellRef;

#[test]
fn number_0_and_numbers_beyond_the_controller_are_refused_naming_the_item() {
    let mut cell = mixed_cell();
    cell.tools[0].number = Some(0);
    for (language, part) in [
        (Language::Krl, "TOOL_DATA[1..16]"),
        (Language::Fanuc, "UTOOL[1..10]"),
    ] {
        let e = export_cell(language, &cell, &model(), &ExportOptions::default()).unwrap_err();
        let m = e.to_string();
        assert!(matches!(e, ExportError::NumberZero { .. }), "{m}");
        assert!(
            m.contains("tool `gun` has number 0") && m.contains(part),
            "{m}"
        );
    }
    // RAPID has no numbers: the same cell exports.
    assert!(export_cell(Language::Rapid, &cell, &model(), &ExportOptions::default()).is_ok());
    // A work object 0 is the world/base frame.
    let mut cell = mixed_cell();
    cell.work_objects[0].number = Some(0);
    let e = export_cell(Language::Fanuc, &cell, &model(), &ExportOptions::default()).unwrap_err();
    assert!(
        e.to_string()
            .contains("work object `table` has number 0, which is the world frame"),
        "{e}"
    );
    // Fanuc has nine user frames; KRL 32 bases.
    let mut cell = mixed_cell();
    cell.work_objects[0].number = Some(12);
    let e = export_cell(Language::Fanuc, &cell, &model(), &ExportOptions::default()).unwrap_err();
    assert!(
        e.to_string()
            .contains("`table` has number 12: the controller has UFRAME[1..9]"),
        "{e}"
    );
    assert!(export_cell(Language::Krl, &cell, &model(), &ExportOptions::default()).is_ok());
    // Seventeen tools: the last unnumbered one finds no free KRL number.
    let cell = Cell {
        tools: (1..=17)
            .map(|i| tool(&format!("t{i:02}"), None, 100.0))
            .collect(),
        work_objects: vec![],
    };
    let e = export_cell(Language::Krl, &cell, &model(), &ExportOptions::default()).unwrap_err();
    assert!(
        e.to_string()
            .contains("tool `t17` has no number and the lowest free one is 17"),
        "{e}"
    );
}

#[test]
fn rapid_declares_every_item_once_under_a_valid_identifier() {
    let long = "w".repeat(64);
    let cell = Cell {
        tools: vec![
            tool("a.b-c", None, 100.0),
            tool("a_b_c", None, 200.0),
            tool(&long, None, 300.0),
            tool("torch", None, 400.0),
        ],
        work_objects: vec![wobj("torch", None, 1000.0)],
    };
    let out = export_cell(Language::Rapid, &cell, &model(), &ExportOptions::default()).unwrap();
    let declared: Vec<&str> = out
        .text
        .lines()
        .filter_map(|l| l.trim().split_once(":=").map(|(h, _)| h))
        .filter_map(|h| h.split_whitespace().last())
        .collect();
    assert_eq!(declared.len(), 5, "{}", out.text);
    let mut keys: Vec<String> = declared.iter().map(|d| d.to_ascii_lowercase()).collect();
    keys.sort();
    keys.dedup();
    assert_eq!(keys.len(), 5, "{declared:?}");
    assert!(declared.iter().all(|d| d.len() <= 32), "{declared:?}");
    // Each renaming is reported, in the text and the answer.
    let renamed: Vec<(&str, &str)> = out
        .renamed
        .iter()
        .map(|r| (r.name.as_str(), r.identifier.as_str()))
        .collect();
    assert!(renamed.contains(&("a_b_c", "a_b_c_2")), "{renamed:?}");
    assert!(renamed.contains(&("torch", "torch_2")), "{renamed:?}");
    assert!(renamed.iter().any(|(n, id)| *n == long && id.len() == 32));
    assert!(
        out.text.contains(
            "! robocal: work object `torch` is declared as torch_2 (taken by tool `torch`)"
        ),
        "{}",
        out.text
    );
    // The module parses, and each tool is found under its identifier with
    // its own TCP.
    let module = format!(
        "MODULE T\r\n{}  PROC main()\r\n    MoveL [[100,0,0],[1,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]], v100, fine, a_b_c_2\\WObj:=torch_2;\r\n  ENDPROC\r\nENDMODULE\r\n",
        out.text
    );
    let p = parse(
        Language::Rapid,
        &[ProgramFile {
            name: "T.mod".into(),
            text: module,
        }],
    )
    .unwrap();
    let (FrameSpec::Inline(t), FrameSpec::Inline(w)) = (&p.sites[0].tool, &p.sites[0].work_object)
    else {
        panic!("{:?}", p.sites[0])
    };
    assert!((t.p.z - 0.2).abs() < 1e-9, "{t:?}");
    assert!((w.p.x - 1.0).abs() < 1e-9, "{w:?}");
}

#[test]
fn fanuc_writes_position_registers_only_when_given_them() {
    let cell = mixed_cell();
    let none = export_cell(Language::Fanuc, &cell, &model(), &ExportOptions::default()).unwrap();
    assert!(!none.text.contains("PR["), "{}", none.text);
    assert!(none.registers.is_empty());
    assert!(
        none.text
            .contains("! robocal: no position register written ;"),
        "{}",
        none.text
    );
    assert!(none
        .text
        .contains("! UTOOL[1] X 0.000000 Y 0.000000 Z 300.000000 ;"));
    let opts = ExportOptions {
        registers: Some("91..99".parse().unwrap()),
        ..Default::default()
    };
    let with = export_cell(Language::Fanuc, &cell, &model(), &opts).unwrap();
    assert!(
        with.text.contains("! robocal overwrites PR[91..94] ;"),
        "{}",
        with.text
    );
    for pr in 91..=94 {
        assert_eq!(
            count(&with.text, &format!("PR[{pr}]=LPOS")),
            1,
            "{}",
            with.text
        );
    }
    assert!(!with.text.contains("PR[95]"), "{}", with.text);
    // Tools, then work objects, each by number.
    assert!(with.text.contains("UTOOL[1]=PR[91] ;") && with.text.contains("UTOOL[2]=PR[92] ;"));
    assert!(with.text.contains("UFRAME[1]=PR[93] ;") && with.text.contains("UFRAME[2]=PR[94] ;"));
    let regs: Vec<(u32, &str)> = with
        .registers
        .iter()
        .map(|r| (r.register, r.name.as_str()))
        .collect();
    assert_eq!(
        regs,
        vec![(91, "torch"), (92, "gun"), (93, "table"), (94, "fixture")]
    );
    let short = ExportOptions {
        registers: Some("91..93".parse().unwrap()),
        ..Default::default()
    };
    let e = export_cell(Language::Fanuc, &cell, &model(), &short).unwrap_err();
    assert!(
        e.to_string().contains("needs 4 position registers") && e.to_string().contains("3 given"),
        "{e}"
    );
}

#[test]
fn names_in_comments_stay_on_their_line() {
    let cell = Cell {
        tools: vec![tool("gun;\r\nTOOL_DATA[3]={X 9}", Some(1), 100.0)],
        work_objects: vec![],
    };
    for language in [Language::Krl, Language::Fanuc, Language::UrScript] {
        let t = export_cell(language, &cell, &model(), &ExportOptions::default())
            .unwrap()
            .text;
        assert!(
            !t.lines().any(|l| l.starts_with("TOOL_DATA[3]")),
            "{language:?}: {t}"
        );
    }
}
