//! The text of KUKA external kinematic systems (`kinematics.rs`): the lines
//! for `$machine.dat` (`$EX_KIN`, `$ETn_AX`, `$ERSYSROOT`, the frames
//! `$ETn_TA1KR`, `$ETn_TA2A1`, `$ETn_TA3A2`, `$ETn_TFLA3`) and `$config.dat`
//! (`MACHINE_DEF[2]`, a base kinematic system's root in the world), with
//! comments saying where each goes and what is not held. mm and degrees,
//! `R = Rz(A)·Ry(B)·Rx(C)`, CR LF line ends as the cell's data.

use super::frames::kuka_frame;
use super::kinematics::{KinematicKind, KukaKinematics};
use std::fmt::Write as _;

/// What system `k` is, for its header comment.
fn described(k: &KukaKinematics) -> String {
    let (n, a) = (k.system, k.system + 1);
    let world = if k.system == 1 {
        "the robot's base frame ($ROBROOT the null frame)"
    } else {
        "the cell frame, as for the track"
    };
    match k.kind {
        KinematicKind::Positioner => format!(
            "the calibrated positioner as external kinematic system ET{n} (E{n} the tilt, E{a} the rotate), its flange the face plate; the world is {world}"
        ),
        KinematicKind::Track => format!(
            "the calibrated track as external kinematic system ET{n} (E{n} the carriage), its flange the robot's base; the world is the cell frame"
        ),
        KinematicKind::Turntable => format!(
            "the calibrated turntable as external kinematic system ET{n} (E{n} its axis), its flange the face plate; the world is {world}"
        ),
    }
}

/// `$ETn_AX`'s aggregate and `$EX_KIN`'s identifier of system `k`.
fn axes_and_type(k: &KukaKinematics) -> (String, &'static str) {
    let (n, a) = (k.system, k.system + 1);
    match k.kind {
        KinematicKind::Positioner => (format!("{{TR_A1 #E{n},TR_A2 #E{a},TR_A3 #NONE}}"), "#EASYS"),
        KinematicKind::Track => (format!("{{TR_A1 #E{n},TR_A2 #NONE,TR_A3 #NONE}}"), "#ERSYS"),
        KinematicKind::Turntable => (format!("{{TR_A1 #E{n},TR_A2 #NONE,TR_A3 #NONE}}"), "#EASYS"),
    }
}

/// The lines of `systems` (ET1, then ET2 if any), as the controller's data.
pub fn kuka_text(systems: &[KukaKinematics]) -> String {
    let mut s = String::new();
    for k in systems {
        let _ = writeln!(s, "; {}", described(k));
    }
    let _ = writeln!(
        s,
        "; mm and degrees, R = Rz(A)*Ry(B)*Rx(C); each axis moves its frame about or along that frame's z"
    );
    let _ = writeln!(s, "; $machine.dat");
    let kinds: Vec<String> = (1..=6u8)
        .map(|n| {
            let kind = systems
                .iter()
                .find(|k| k.system == n)
                .map_or("#NONE", |k| axes_and_type(k).1);
            format!("ET{n} {kind}")
        })
        .collect();
    let _ = writeln!(s, "DECL EX_KIN $EX_KIN={{{}}}", kinds.join(","));
    for k in systems {
        let n = k.system;
        let _ = writeln!(s, "DECL ET_AX $ET{n}_AX={}", axes_and_type(k).0);
        if k.kind == KinematicKind::Track {
            let _ = writeln!(s, "FRAME $ERSYSROOT={}", kuka_frame(&k.root));
        }
        for (name, link) in ["TA1KR", "TA2A1", "TA3A2", "TFLA3"].iter().zip(&k.links) {
            let _ = writeln!(s, "FRAME $ET{n}_{name}={}", kuka_frame(link));
        }
    }
    for k in systems.iter().filter(|k| k.kind != KinematicKind::Track) {
        let name = match k.kind {
            KinematicKind::Turntable => "TURNTABLE",
            _ => "POSITIONER",
        };
        let _ = writeln!(
            s,
            "; $config.dat: the root in the world (MACHINE_DEF[1] is the robot)"
        );
        let _ = writeln!(
            s,
            "MACHINE_DEF[2]={{NAME[] \"{name}\",COOP_KRC_INDEX 1,PARENT[] \"WORLD\",ROOT {},MECH_TYPE #EASYS,GEOMETRY[] \" \"}}",
            kuka_frame(&k.root)
        );
    }
    for k in systems {
        not_held_lines(&mut s, k);
    }
    s.replace('\n', "\r\n")
}

/// The comment listing what system `k` does not hold.
fn not_held_lines(s: &mut String, k: &KukaKinematics) {
    if k.not_held.is_empty() {
        let _ = writeln!(
            s,
            "; every calibrated term of the {} is held",
            k.kind.name()
        );
        return;
    }
    let _ = writeln!(
        s,
        "; not held by the controller (the filter corrects it when given this chain as its controller {}):",
        k.kind.name()
    );
    for n in &k.not_held {
        let _ = writeln!(
            s,
            ";   {} {:.9}{}{}: {:.4} mm",
            n.term,
            n.value,
            if n.unit.is_empty() { "" } else { " " },
            n.unit,
            n.miss_mm
        );
    }
}

impl KukaKinematics {
    /// The lines of this one system for `$machine.dat` and `$config.dat`.
    pub fn text(&self) -> String {
        kuka_text(std::slice::from_ref(self))
    }
}
