//! Programs that move external axes alone, the robot standing where it is
//! (e.g. a positioner's measurement plan: the tracker reads reflectors on
//! its face plate at each pair of values). Values in the controller's
//! units (degrees for a rotary axis, mm for a linear one), written as
//! constants:
//! - KRL: `PTP {E1 …, E2 …}`, an `E6AXIS` aggregate with the external
//!   axes' components alone, so the robot's axes keep their values;
//! - RAPID: `MoveExtJ` (mechanical units without a TCP) to a `jointtarget`
//!   whose robot axes are `9E+09` and external axes `eax_a` … by column,
//!   at `vrot10`;
//! - Fanuc: a program of motion group 2 alone (`DEFAULT_GROUP = *,1,*,*,*`),
//!   positions `GP2: J1 = …, J2 = …`, the axes in column order (the
//!   lowest column is `J1`);
//! - URScript has no external axes and is refused.

use super::export::fanuc_stops;
use super::{Language, ProgramFile};
use crate::measure::external::ExternalAxis;
use std::fmt::Write as _;

/// One stop of the external axes and the comment beside its motion.
#[derive(Debug, Clone, PartialEq)]
pub struct AxesStop {
    /// The motion's comment (e.g. `point 3`).
    pub label: String,
    /// The axes' values by column, in column order.
    pub values: Vec<(ExternalAxis, f64)>,
}

/// Why the program is not written.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AxesOnlyError {
    /// URScript has no external axes.
    #[error("URScript programs carry no external axes; write the plan's CSV or a KRL, RAPID or Fanuc program")]
    UrScript,
    /// A stop without values, or stops with different axes.
    #[error(
        "stop {0} moves other axes than the first stop does (every stop must give the same axes)"
    )]
    Axes(usize),
}

/// A program `name` headed by the comment `head`, moving the external axes
/// to each stop and waiting `wait_s` seconds there (module docs).
pub fn axes_only_program(
    language: Language,
    name: &str,
    head: &str,
    stops: &[AxesStop],
    wait_s: f64,
) -> Result<Vec<ProgramFile>, AxesOnlyError> {
    let axes: Vec<ExternalAxis> = stops
        .first()
        .map(|s| s.values.iter().map(|(a, _)| *a).collect())
        .unwrap_or_default();
    for (i, s) in stops.iter().enumerate() {
        let these: Vec<ExternalAxis> = s.values.iter().map(|(a, _)| *a).collect();
        if these.is_empty() || these != axes {
            return Err(AxesOnlyError::Axes(i + 1));
        }
    }
    let mut s = String::new();
    let file = |name: String, text: String| vec![ProgramFile { name, text }];
    match language {
        Language::UrScript => Err(AxesOnlyError::UrScript),
        Language::Krl => {
            let _ = write!(s, "&ACCESS RVP\r\nDEF {name}()\r\n; {head}\r\n");
            for t in stops {
                let list: Vec<String> = t
                    .values
                    .iter()
                    .map(|(a, v)| format!("E{} {v:.4}", a.index() + 1))
                    .collect();
                let _ = write!(
                    s,
                    "PTP {{{}}} ; {}\r\nWAIT SEC {wait_s}\r\n",
                    list.join(","),
                    t.label
                );
            }
            s.push_str("END\r\n");
            Ok(file(format!("{name}.src"), s))
        }
        Language::Rapid => {
            let _ = write!(s, "MODULE {name}\r\n  ! {head}\r\n  PROC main()\r\n");
            for t in stops {
                let mut eax: [String; 6] = std::array::from_fn(|_| "9E+09".to_string());
                for (a, v) in &t.values {
                    eax[a.index()] = format!("{v:.4}");
                }
                let _ = write!(
                    s,
                    "    MoveExtJ [[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09],[{}]], vrot10, fine; ! {}\r\n    WaitTime {wait_s};\r\n",
                    eax.join(","),
                    t.label
                );
            }
            s.push_str("  ENDPROC\r\nENDMODULE\r\n");
            Ok(file(format!("{name}.mod"), s))
        }
        Language::Fanuc => {
            let upper = name.to_ascii_uppercase();
            let _ = write!(
                s,
                "/PROG  {upper}\r\n/ATTR\r\nCOMMENT\t\t= \"robocal plan\";\r\nDEFAULT_GROUP\t= *,1,*,*,*;\r\n/MN\r\n   1:  ! {} stops of group 2 ;\r\n",
                stops.len()
            );
            fanuc_stops(&mut s, stops.iter().map(|t| t.label.as_str()), wait_s);
            for (i, t) in stops.iter().enumerate() {
                let joints: Vec<String> = t
                    .values
                    .iter()
                    .enumerate()
                    .map(|(k, (_, v))| format!("J{}= {v:.4} deg", k + 1))
                    .collect();
                let _ = write!(
                    s,
                    "P[{}]{{\r\n   GP2:\r\n\tUF : 0, UT : 0,\r\n\t{}\r\n}};\r\n",
                    i + 1,
                    joints.join(",\t")
                );
            }
            s.push_str("/END\r\n");
            Ok(file(format!("{upper}.LS"), s))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stops() -> Vec<AxesStop> {
        [(-90.0, 0.0), (15.5, -165.25)]
            .iter()
            .enumerate()
            .map(|(i, &(t, r))| AxesStop {
                label: format!("P{}", i + 1),
                values: vec![(ExternalAxis::E2, t), (ExternalAxis::E3, r)],
            })
            .collect()
    }

    fn text(language: Language) -> String {
        axes_only_program(language, "stn", "head", &stops(), 2.0)
            .unwrap()
            .iter()
            .map(|f| f.text.clone())
            .collect()
    }

    #[test]
    fn each_language_moves_the_axes_alone() {
        let krl = text(Language::Krl);
        assert!(
            krl.contains("PTP {E2 15.5000,E3 -165.2500} ; P2\r\nWAIT SEC 2\r\n"),
            "{krl}"
        );
        assert!(!krl.contains("A1"), "{krl}");
        let rapid = text(Language::Rapid);
        assert!(
            rapid.contains("    MoveExtJ [[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09],[9E+09,-90.0000,0.0000,9E+09,9E+09,9E+09]], vrot10, fine; ! P1\r\n    WaitTime 2;\r\n"),
            "{rapid}"
        );
        let fanuc = text(Language::Fanuc);
        assert!(fanuc.contains("DEFAULT_GROUP\t= *,1,*,*,*;"), "{fanuc}");
        assert!(
            fanuc.contains("P[2]{\r\n   GP2:\r\n\tUF : 0, UT : 0,\r\n\tJ1= 15.5000 deg,\tJ2= -165.2500 deg\r\n};"),
            "{fanuc}"
        );
        assert!(!fanuc.contains("GP1"), "{fanuc}");
    }

    #[test]
    fn urscript_and_uneven_stops_are_refused() {
        assert_eq!(
            axes_only_program(Language::UrScript, "s", "h", &stops(), 1.0),
            Err(AxesOnlyError::UrScript)
        );
        let mut uneven = stops();
        uneven[1].values.pop();
        assert_eq!(
            axes_only_program(Language::Krl, "s", "h", &uneven, 1.0),
            Err(AxesOnlyError::Axes(2))
        );
    }
}
