//! Joint programs: a list of joint targets (controller convention, degrees)
//! as a program that moves to each and waits there, in each language (e.g. a
//! measurement plan for the tracker). The parsers read them back
//! ([`super::Program::joints`]).

use super::{Language, ProgramFile};
use std::fmt::Write as _;

/// A program `name` moving to each of `joints_deg` (6 axes) and waiting
/// `wait_s` seconds, each motion commented `pose 1`, `pose 2`, ….
pub fn joint_program(
    language: Language,
    name: &str,
    joints_deg: &[[f64; 6]],
    wait_s: f64,
) -> Vec<ProgramFile> {
    let n = joints_deg.len();
    let head = format!("robocal measurement plan: {n} poses, a wait of {wait_s} s at each");
    let targets: Vec<LabelledJoints> = joints_deg
        .iter()
        .enumerate()
        .map(|(i, q)| LabelledJoints {
            label: format!("pose {}", i + 1),
            joints_deg: *q,
        })
        .collect();
    labelled_joint_program(language, name, &head, &targets, wait_s)
}

/// One joint target of a program and the comment beside its motion.
#[derive(Debug, Clone, PartialEq)]
pub struct LabelledJoints {
    /// The motion's comment (e.g. `P3 cycle 12`).
    pub label: String,
    /// Controller convention [deg].
    pub joints_deg: [f64; 6],
}

/// A program `name` headed by the comment `head`, moving to each target and
/// waiting `wait_s` seconds, each motion commented with its label.
pub fn labelled_joint_program(
    language: Language,
    name: &str,
    head: &str,
    targets: &[LabelledJoints],
    wait_s: f64,
) -> Vec<ProgramFile> {
    let n = targets.len();
    let list = |q: &[f64; 6], f: &dyn Fn(f64) -> String| q.map(f).join(", ");
    let mut s = String::new();
    match language {
        Language::Krl => {
            let _ = write!(s, "&ACCESS RVP\r\nDEF {name}()\r\n; {head}\r\n");
            for t in targets {
                let axes: Vec<String> = t
                    .joints_deg
                    .iter()
                    .enumerate()
                    .map(|(k, v)| format!("A{} {v:.4}", k + 1))
                    .collect();
                let _ = write!(
                    s,
                    "PTP {{{}}} ; {}\r\nWAIT SEC {wait_s}\r\n",
                    axes.join(","),
                    t.label
                );
            }
            s.push_str("END\r\n");
            vec![file(format!("{name}.src"), s)]
        }
        Language::Rapid => {
            let _ = write!(s, "MODULE {name}\r\n  ! {head}\r\n  PROC main()\r\n");
            for t in targets {
                let _ = write!(
                    s,
                    "    MoveAbsJ [[{}],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]], v100, fine, tool0; ! {}\r\n    WaitTime {wait_s};\r\n",
                    list(&t.joints_deg, &|v| format!("{v:.4}")),
                    t.label
                );
            }
            s.push_str("  ENDPROC\r\nENDMODULE\r\n");
            vec![file(format!("{name}.mod"), s)]
        }
        Language::Fanuc => {
            let upper = name.to_ascii_uppercase();
            let _ = write!(
                s,
                "/PROG  {upper}\r\n/ATTR\r\nCOMMENT\t\t= \"robocal plan\";\r\nDEFAULT_GROUP\t= 1,*,*,*,*;\r\n/MN\r\n   1:  ! {n} poses ;\r\n"
            );
            for (i, t) in targets.iter().enumerate() {
                let _ = write!(
                    s,
                    "{:4}:  ! {} ;\r\n{:4}:J P[{}] 20% FINE    ;\r\n{:4}:  WAIT {wait_s:.2}(sec) ;\r\n",
                    3 * i + 2,
                    t.label,
                    3 * i + 3,
                    i + 1,
                    3 * i + 4
                );
            }
            s.push_str("/POS\r\n");
            for (i, t) in targets.iter().enumerate() {
                let q = &t.joints_deg;
                let _ = write!(s, "P[{}]{{\r\n   GP1:\r\n\tUF : 0, UT : 0,\r\n", i + 1);
                let _ = write!(
                    s,
                    "\tJ1= {:.4} deg,\tJ2= {:.4} deg,\tJ3= {:.4} deg,\r\n\tJ4= {:.4} deg,\tJ5= {:.4} deg,\tJ6= {:.4} deg\r\n}};\r\n",
                    q[0], q[1], q[2], q[3], q[4], q[5]
                );
            }
            s.push_str("/END\r\n");
            vec![file(format!("{upper}.LS"), s)]
        }
        Language::UrScript => {
            let _ = write!(s, "def {name}():\n  # {head}\n");
            for t in targets {
                let _ = write!(
                    s,
                    "  movej([{}], a=0.5, v=0.3)  # {}\n  sleep({wait_s})\n",
                    list(&t.joints_deg, &|v| format!("{:.8}", v.to_radians())),
                    t.label
                );
            }
            let _ = write!(s, "end\n{name}()\n");
            vec![file(format!("{name}.script"), s)]
        }
    }
}

fn file(name: String, text: String) -> ProgramFile {
    ProgramFile { name, text }
}

#[cfg(test)]
mod tests {
    use super::super::parse;
    use super::*;

    #[test]
    fn joint_programs_parse_back_to_the_same_joints() {
        let joints = [
            [0.0, 90.0, -20.0, 0.0, 45.0, 0.0],
            [-35.25, 62.5, 10.125, 170.0, -88.5, -179.75],
            [120.0, 140.0, -100.0, -45.5, 30.0, 359.0],
        ];
        for language in [
            Language::Krl,
            Language::Rapid,
            Language::Fanuc,
            Language::UrScript,
        ] {
            let files = joint_program(language, "plan", &joints, 2.0);
            let p = parse(language, &files).unwrap();
            assert!(p.sites.is_empty(), "{language:?}");
            let got: Vec<&Vec<f64>> = p.joints.iter().map(|j| &j.deg).collect();
            assert_eq!(got.len(), joints.len(), "{language:?}");
            for (g, w) in got.iter().zip(&joints) {
                for (a, b) in g.iter().zip(w) {
                    assert!((a - b).abs() < 1e-5, "{language:?}: {g:?} vs {w:?}");
                }
            }
        }
    }
}
