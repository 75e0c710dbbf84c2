//! Fanuc `.ls`: 50 Cartesian positions in user frame 2 with tool 1, and a joint position.

use super::*;
use robocal_core::model::orientation::{rotation_to, OrientationConvention};
use robocal_core::program::{fanuc_config, fanuc_config_text, filter, TargetStatus};

fn program(f: &Fixture) -> Vec<ProgramFile> {
    let n = f.joints.len();
    let mut mn = String::from(
        "/PROG  SEAM\r\n/ATTR\r\nOWNER\t\t= MNEDITOR;\r\nCOMMENT\t\t= \"seam on the table\";\r\n\
         DEFAULT_GROUP\t= 1,*,*,*,*;\r\n/MN\r\n   1:  UFRAME_NUM=2 ;\r\n   2:  UTOOL_NUM=1 ;\r\n",
    );
    mn.push_str(&format!("   3:J P[{}] 100% FINE    ;\r\n", n + 1));
    let mut pos = String::from("/POS\r\n");
    for i in 0..n {
        let t = f.target(i);
        let (deg, c) = f.flag_input(i);
        let wpr = rotation_to(OrientationConvention::FanucWpr, &t.r);
        let kind = if i % 2 == 0 { "J" } else { "L" };
        let speed = if i % 2 == 0 { "100%" } else { "500mm/sec" };
        mn.push_str(&format!(
            "{:4}:{kind} P[{}] {speed} CNT50    ;\r\n",
            i + 4,
            i + 1
        ));
        if i % 5 == 0 {
            mn.push_str(&format!("{:4}:  DO[1]=ON ;\r\n", i + 4));
        }
        pos.push_str(&format!(
            "P[{}{}]{{\r\n   GP1:\r\n\tUF : 2, UT : 1,\t\tCONFIG : '{}',\r\n\
             \tX = {:9.3}  mm,\tY = {:9.3}  mm,\tZ = {:9.3}  mm,\r\n\
             \tW = {:9.3} deg,\tP = {:9.3} deg,\tR = {:9.3} deg\r\n}};\r\n",
            i + 1,
            if i % 7 == 0 { ":\"seam\"" } else { "" },
            fanuc_config_text(&fanuc_config(&deg, c)),
            t.p.x * 1e3,
            t.p.y * 1e3,
            t.p.z * 1e3,
            wpr[0],
            wpr[1],
            wpr[2]
        ));
    }
    pos.push_str(&format!(
        "P[{}:\"home\"]{{\r\n   GP1:\r\n\tUF : 0, UT : 1,\r\n\tJ1=     0.000 deg,\tJ2=    90.000 deg,\tJ3=   -20.000 deg,\r\n\
         \tJ4=     0.000 deg,\tJ5=    45.000 deg,\tJ6=     0.000 deg\r\n}};\r\n/END\r\n",
        n + 1
    ));
    vec![ProgramFile {
        name: "SEAM.LS".into(),
        text: mn + &pos,
    }]
}

#[test]
fn filtered_fanuc_brings_the_true_tcp_to_the_targets() {
    let f = fixture();
    let files = program(f);
    // The cell's torch carries the true load (the payload on the flange).
    let cell = f.cell_with_load();
    assert_filter_reaches_targets(f, Language::Fanuc, "Fanuc", &files, &cell);
}

#[test]
fn fanuc_without_targets_is_byte_identical_and_failures_are_marked() {
    let f = fixture();
    let joint_only = "/PROG  IO\n/MN\n   1:J P[1] 100% FINE    ;\n   2:  DO[1]=ON ;\n/POS\nP[1]{\n   GP1:\n\tUF : 0, UT : 1,\n\tJ1= 0.000 deg,\tJ2= 90.000 deg,\tJ3= -20.000 deg,\n\tJ4= 0.000 deg,\tJ5= 45.000 deg,\tJ6= 0.000 deg\n};\n/END\n";
    let file = ProgramFile {
        name: "IO.LS".into(),
        text: joint_only.into(),
    };
    let out = filter(
        Language::Fanuc,
        std::slice::from_ref(&file),
        &f.cell,
        &f.model,
        &settings(),
    )
    .unwrap();
    assert_eq!(out.files[0], file);
    let far = "/PROG  FAR\n/POS\nP[1:\"far\"]{\n   GP1:\n\tUF : 2, UT : 1,\t\tCONFIG : 'N U T, 0, 0, 0',\n\
               \tX = 9000.000 mm,\tY = 0.000 mm,\tZ = 0.000 mm,\n\tW = 0.000 deg,\tP = 0.000 deg,\tR = 0.000 deg\n};\n/END\n";
    let file = ProgramFile {
        name: "FAR.LS".into(),
        text: far.into(),
    };
    let out = filter(Language::Fanuc, &[file], &f.cell, &f.model, &settings()).unwrap();
    let t = &out.report.targets[0];
    assert_eq!((t.line, t.status), (3, TargetStatus::Failed));
    assert!(t.reason.as_ref().unwrap().contains("reach"));
    assert_eq!(
        out.files[0].text,
        far.replace("P[1:\"far\"]", "P[1:\"robocal: failed\"]")
    );
}
