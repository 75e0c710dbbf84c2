//! Joint programs: a list of joint targets (controller convention, degrees)
//! as a program that moves to each and waits there, in each language (e.g. a
//! measurement plan for the tracker). The parsers read them back
//! ([`super::Program::joints`]).

use super::{Language, ProgramFile};
use crate::measure::external::ExternalAxis;
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
            track: None,
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
    /// The track's value the robot stands at (a track plan's), if any.
    pub track: Option<TrackValue>,
}

/// A linear track's value at a joint target: its controller axis (`e1` is
/// KRL's `E1`, RAPID's `eax_a`, Fanuc's `E1` in `GP1`) and value [mm].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackValue {
    /// The track's axis.
    pub axis: ExternalAxis,
    /// Its value [mm].
    pub value_mm: f64,
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
                let mut axes: Vec<String> = t
                    .joints_deg
                    .iter()
                    .enumerate()
                    .map(|(k, v)| format!("A{} {v:.4}", k + 1))
                    .collect();
                if let Some(e) = t.track {
                    axes.push(format!("E{} {:.3}", e.axis.index() + 1, e.value_mm));
                }
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
                let mut eax = [
                    "9E+09".to_string(),
                    "9E+09".into(),
                    "9E+09".into(),
                    "9E+09".into(),
                    "9E+09".into(),
                    "9E+09".into(),
                ];
                if let Some(e) = t.track {
                    eax[e.axis.index()] = format!("{:.3}", e.value_mm);
                }
                let _ = write!(
                    s,
                    "    MoveAbsJ [[{}],[{}]], v100, fine, tool0; ! {}\r\n    WaitTime {wait_s};\r\n",
                    list(&t.joints_deg, &|v| format!("{v:.4}")),
                    eax.join(","),
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
            fanuc_stops(&mut s, targets.iter().map(|t| t.label.as_str()), wait_s);
            for (i, t) in targets.iter().enumerate() {
                let q = &t.joints_deg;
                let _ = write!(s, "P[{}]{{\r\n   GP1:\r\n\tUF : 0, UT : 0,\r\n", i + 1);
                let _ = write!(
                    s,
                    "\tJ1= {:.4} deg,\tJ2= {:.4} deg,\tJ3= {:.4} deg,\r\n\tJ4= {:.4} deg,\tJ5= {:.4} deg,\tJ6= {:.4} deg",
                    q[0], q[1], q[2], q[3], q[4], q[5]
                );
                if let Some(e) = t.track {
                    let _ = write!(s, ",\r\n\tE{}= {:.3} mm", e.axis.index() + 1, e.value_mm);
                }
                s.push_str("\r\n};\r\n");
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

/// A Fanuc `/MN` section's stops after its line 1, one per label: the
/// label as a remark, a joint move to `P[i]` and a wait of `wait_s`; then
/// `/POS`, whose positions the caller writes.
pub(super) fn fanuc_stops<'a>(s: &mut String, labels: impl Iterator<Item = &'a str>, wait_s: f64) {
    for (i, label) in labels.enumerate() {
        let _ = write!(
            s,
            "{:4}:  ! {label} ;\r\n{:4}:J P[{}] 20% FINE    ;\r\n{:4}:  WAIT {wait_s:.2}(sec) ;\r\n",
            3 * i + 2,
            3 * i + 3,
            i + 1,
            3 * i + 4
        );
    }
    s.push_str("/POS\r\n");
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

#[cfg(test)]
mod track_tests {
    use super::super::parse;
    use super::*;

    /// A track plan's joint programs carry the track's value with each
    /// pose and parse back to the same joints.
    #[test]
    fn track_values_ride_with_the_joints() {
        let targets: Vec<LabelledJoints> = [(0.0, 0.0), (-35.25, 1234.5678)]
            .iter()
            .map(|&(a1, e)| LabelledJoints {
                label: format!("at {e}"),
                joints_deg: [a1, 90.0, -20.0, 0.0, 45.0, 0.0],
                track: Some(TrackValue {
                    axis: ExternalAxis::E1,
                    value_mm: e,
                }),
            })
            .collect();
        for (language, written) in [
            (Language::Krl, "E1 1234.568}"),
            (Language::Rapid, "[1234.568,9E+09,9E+09,9E+09,9E+09,9E+09]]"),
            (Language::Fanuc, "E1= 1234.568 mm\r\n};"),
        ] {
            let files = labelled_joint_program(language, "plan", "head", &targets, 1.0);
            let text: String = files.iter().map(|f| f.text.as_str()).collect();
            assert!(text.contains(written), "{language:?}: {text}");
            let p = parse(language, &files).unwrap();
            let got: Vec<Vec<f64>> = p.joints.iter().map(|j| j.deg.clone()).collect();
            assert_eq!(got.len(), 2, "{language:?}");
            for (g, t) in got.iter().zip(&targets) {
                for (a, b) in g.iter().zip(&t.joints_deg) {
                    assert!((a - b).abs() < 1e-9, "{language:?}: {g:?}");
                }
            }
        }
    }
}
