//! The text report of `robocal calibrate`: accuracy, the comparison of
//! methods, orientation, compensators, identifiability, parameters.

use crate::calibrate::identify::{CalibrationReport, Method, SetErrors};
use crate::report::method_label;
use std::fmt::Write as _;

/// A parameter value in its display unit, one format per unit: lengths and
/// angles with 6 decimals (0.001 µm, 1e-6 deg), compliances in scientific
/// notation, masses with 3 decimals.
fn param_number(v: f64, unit: &str) -> String {
    match unit {
        "rad/(N·m)" => format!("{v:.4e}"),
        "kg" => format!("{v:.3}"),
        _ => format!("{v:.6}"),
    }
}

/// The text report: registration, accuracy table, comparison, orientation,
/// compensators, identifiability, parameters, stiffness, solvers, warnings.
pub fn render_report(r: &CalibrationReport) -> String {
    let mut s = String::new();
    write_header(&mut s, r);
    write_accuracy(&mut s, r);
    let _ = write!(s, "{}", render_comparison(r));
    let _ = write!(s, "{}", render_orientation(r));
    let _ = write!(s, "{}", render_compensators(r));
    write_identifiability(&mut s, r);
    write_parameters(&mut s, r);
    write_stiffness(&mut s, r);
    write_solvers(&mut s, r);
    write_problems(&mut s, r);
    s
}

/// The robot, its pose counts and each session's registration.
fn write_header(s: &mut String, r: &CalibrationReport) {
    let _ = writeln!(
        s,
        "robot {}: {} identification poses, {} validation poses",
        r.robot, r.identification_poses, r.validation_poses
    );
    for reg in &r.registration {
        let t = &reg.tracker_to_base;
        let _ = writeln!(
            s,
            "registration (session {}): tracker->base xyz [{:.3}, {:.3}, {:.3}] mm, rpy [{:.4}, {:.4}, {:.4}] deg, nominal RMS {:.3} mm",
            reg.session, t.xyz_mm[0], t.xyz_mm[1], t.xyz_mm[2], t.rpy_deg[0], t.rpy_deg[1], t.rpy_deg[2], reg.rms_mm
        );
    }
}

/// Absolute position accuracy on identification and validation, every model.
fn write_accuracy(s: &mut String, r: &CalibrationReport) {
    let _ = writeln!(s, "\nAbsolute position accuracy (mm)");
    let _ = writeln!(
        s,
        "{:<22} {:>8} {:>8} {:>8} {:>8} {:>8}   {:>8} {:>8} {:>8} {:>8} {:>8}",
        "", "id mean", "max", "std", "rms", "p95", "val mean", "max", "std", "rms", "p95"
    );
    let mut line =
        |label: &str, id: &crate::stats::ErrorStats, va: Option<&crate::stats::ErrorStats>| {
            let _ = write!(
                s,
                "{:<22} {:>8.4} {:>8.4} {:>8.4} {:>8.4} {:>8.4}",
                label, id.mean_mm, id.max_mm, id.std_mm, id.rms_mm, id.p95_mm
            );
            if let Some(v) = va {
                let _ = write!(
                    s,
                    "   {:>8.4} {:>8.4} {:>8.4} {:>8.4} {:>8.4}",
                    v.mean_mm, v.max_mm, v.std_mm, v.rms_mm, v.p95_mm
                );
            }
            let _ = writeln!(s);
        };
    line(
        "Nominal robot model",
        &r.nominal.identification.stats,
        r.nominal.validation.as_ref().map(|v| &v.stats),
    );
    for (name, m) in &r.methods {
        line(
            method_label(*name),
            &m.identification.stats,
            m.validation.as_ref().map(|v| &v.stats),
        );
    }
}

/// What the identifiability analysis kept, dropped and found correlated.
fn write_identifiability(s: &mut String, r: &CalibrationReport) {
    let id = &r.identifiability;
    let _ = writeln!(
        s,
        "\nIdentifiability: {} parameters kept of {} candidates (rank {}), condition number {:.2}, observability O1 {:.4}",
        id.kept.len(), id.candidates, id.rank, id.condition_number, id.observability_o1
    );
    for d in &id.dropped {
        if d.depends_on.is_empty() {
            let _ = writeln!(s, "  dropped {:<8} {}", d.name, d.reason);
        } else {
            let _ = writeln!(
                s,
                "  dropped {:<8} {} ({})",
                d.name,
                d.reason,
                d.depends_on.join(", ")
            );
        }
    }
    for p in &id.correlated_pairs {
        let _ = writeln!(s, "  correlated {} ~ {}: {:+.3}", p.a, p.b, p.correlation);
    }
    if !id.identifiable_by_orientation.is_empty() {
        let _ = writeln!(
            s,
            "  identified only thanks to the measured orientations: {}",
            id.identifiable_by_orientation.join(", ")
        );
    }
    if !id.unseen_tool_tip_terms.is_empty() {
        let _ = writeln!(
            s,
            "  not seen by position-only data (a production tool's tip depends on them; its error there is unknown): {}",
            id.unseen_tool_tip_terms.join(", ")
        );
    }
}

/// The identified parameters across methods, with their nominal values.
fn write_parameters(s: &mut String, r: &CalibrationReport) {
    let names: Vec<Method> = r.methods.keys().copied().collect();
    let _ = write!(
        s,
        "\nIdentified parameters (mm, deg, rad/(N·m))\n{:<10} {:>14}",
        "name", "nominal"
    );
    for n in &names {
        let _ = write!(s, " {:>14}", method_label(*n));
    }
    let _ = writeln!(s);
    let mut all: Vec<String> = Vec::new();
    for m in r.methods.values() {
        for p in &m.parameters {
            if !all.contains(&p.name) {
                all.push(p.name.clone());
            }
        }
    }
    for pname in &all {
        let nominal_v = r
            .methods
            .values()
            .flat_map(|m| &m.parameters)
            .find(|p| &p.name == pname)
            .map(|p| p.nominal)
            .unwrap_or(0.0);
        let unit = r
            .methods
            .values()
            .flat_map(|m| &m.parameters)
            .find(|p| &p.name == pname)
            .map(|p| p.unit.as_str())
            .unwrap_or("");
        let _ = write!(s, "{:<10} {:>14}", pname, param_number(nominal_v, unit));
        for n in &names {
            match r.methods[n].parameters.iter().find(|p| &p.name == pname) {
                Some(p) => {
                    let _ = write!(s, " {:>14}", param_number(p.value, unit));
                }
                None => {
                    let _ = write!(s, " {:>14}", "-");
                }
            }
        }
        let _ = writeln!(s);
    }
}

/// The joint stiffnesses of the methods that identified some.
fn write_stiffness(s: &mut String, r: &CalibrationReport) {
    let any_stiffness = r
        .methods
        .values()
        .any(|m| m.stiffness_nm_per_rad.iter().any(|k| k.is_some()));
    if any_stiffness {
        let _ = writeln!(s, "\nJoint stiffness (N·m/rad)");
    }
    for (n, m) in &r.methods {
        if m.stiffness_nm_per_rad.iter().any(|k| k.is_some()) {
            let ks: Vec<String> = m
                .stiffness_nm_per_rad
                .iter()
                .enumerate()
                .filter_map(|(k, v)| v.map(|v| format!("K{}={:.4e}", k + 1, v)))
                .collect();
            let _ = writeln!(s, "  {:<14} {}", method_label(*n), ks.join("  "));
        }
    }
}

/// How each method's solver ended.
fn write_solvers(s: &mut String, r: &CalibrationReport) {
    for (n, m) in &r.methods {
        let _ = writeln!(
            s,
            "solver {:<14} converged={} iterations={} reason={} ({})",
            method_label(*n),
            m.solver.converged,
            m.solver.iterations,
            m.solver.reason.code(),
            m.solver.detail
        );
    }
}

/// Every method's warnings, and the methods that failed.
fn write_problems(s: &mut String, r: &CalibrationReport) {
    if r.methods.values().any(|m| !m.warnings.is_empty()) {
        let _ = writeln!(s, "\nWarnings");
        for (n, m) in &r.methods {
            for w in &m.warnings {
                let _ = writeln!(s, "  {:<14} {}", method_label(*n), w.message);
            }
        }
    }
    if !r.failed.is_empty() {
        let _ = writeln!(s, "\nFailed methods (the others above are complete)");
        for f in &r.failed {
            let _ = writeln!(s, "  {:<14} {}", method_label(f.method), f.reason);
        }
    }
}

/// The seed-style comparison (rows = methods, columns = sets, mean / max in mm),
/// the compensator training pool between identification and validation.
pub fn render_comparison(r: &CalibrationReport) -> String {
    let mut s = String::new();
    let training = r.training_poses > 0;
    let validation = r.validation_poses > 0;
    let _ = write!(
        s,
        "\nComparison, mean / max (mm)\n{:<22} {:>19}",
        "", "identification (Q1)"
    );
    if training {
        let _ = write!(s, " {:>19}", "training (Q2)");
    }
    if validation {
        let _ = write!(s, " {:>19}", "validation (Q3)");
    }
    let _ = writeln!(s);
    let cell = |e: Option<&crate::stats::ErrorStats>| match e {
        Some(e) => format!("{:>9.4} / {:<7.4}", e.mean_mm, e.max_mm),
        None => format!("{:>19}", "-"),
    };
    let _ = write!(
        s,
        "{:<22} {}",
        "Nominal robot model",
        cell(Some(&r.nominal.identification.stats))
    );
    if training {
        let _ = write!(s, " {}", cell(None));
    }
    if validation {
        let _ = write!(
            s,
            " {}",
            cell(r.nominal.validation.as_ref().map(|v| &v.stats))
        );
    }
    let _ = writeln!(s);
    for (name, m) in &r.methods {
        let _ = write!(
            s,
            "{:<22} {}",
            method_label(*name),
            cell(Some(&m.identification.stats))
        );
        if training {
            let _ = write!(s, " {}", cell(m.training.as_ref().map(|v| &v.stats)));
        }
        if validation {
            let _ = write!(s, " {}", cell(m.validation.as_ref().map(|v| &v.stats)));
        }
        let _ = writeln!(s);
    }
    s
}

/// Orientation errors per set (mean / max in degrees), for every model, when
/// some set measured orientation; empty otherwise.
pub fn render_orientation(r: &CalibrationReport) -> String {
    let mut s = String::new();
    let nominal: [Option<&SetErrors>; 2] = [
        Some(&r.nominal.identification),
        r.nominal.validation.as_ref(),
    ];
    let any = nominal
        .into_iter()
        .chain(r.methods.values().flat_map(|m| {
            [
                Some(&m.identification),
                m.training.as_ref(),
                m.validation.as_ref(),
            ]
        }))
        .flatten()
        .any(|e| e.orientation.is_some());
    if !any {
        return s;
    }
    let training = r.training_poses > 0;
    let validation = r.validation_poses > 0;
    let _ = write!(
        s,
        "\nOrientation, mean / max (deg)\n{:<22} {:>19}",
        "", "identification (Q1)"
    );
    if training {
        let _ = write!(s, " {:>19}", "training (Q2)");
    }
    if validation {
        let _ = write!(s, " {:>19}", "validation (Q3)");
    }
    let _ = writeln!(s);
    let cell = |e: Option<&SetErrors>| match e.and_then(|e| e.orientation.as_ref()) {
        Some(o) => format!("{:>9.4} / {:<7.4}", o.mean_deg, o.max_deg),
        None => format!("{:>19}", "-"),
    };
    let _ = write!(
        s,
        "{:<22} {}",
        "Nominal robot model",
        cell(Some(&r.nominal.identification))
    );
    if training {
        let _ = write!(s, " {}", cell(None));
    }
    if validation {
        let _ = write!(s, " {}", cell(r.nominal.validation.as_ref()));
    }
    let _ = writeln!(s);
    for (name, m) in &r.methods {
        let _ = write!(
            s,
            "{:<22} {}",
            method_label(*name),
            cell(Some(&m.identification))
        );
        if training {
            let _ = write!(s, " {}", cell(m.training.as_ref()));
        }
        if validation {
            let _ = write!(s, " {}", cell(m.validation.as_ref()));
        }
        let _ = writeln!(s);
    }
    let _ = writeln!(
        s,
        "(compensators correct position only: their orientation is their base's)"
    );
    s
}

/// Each compensator: network, training, cross-validation and its effect on
/// every set; `auto`'s choice and why.
pub fn render_compensators(r: &CalibrationReport) -> String {
    let mut s = String::new();
    let with: Vec<_> = r
        .methods
        .iter()
        .filter(|(_, m)| m.compensator.is_some() || m.auto.is_some())
        .collect();
    if with.is_empty() {
        return s;
    }
    let _ = writeln!(s, "\nCompensators (mean / max in mm, base -> compensated)");
    let pair = |b: &crate::stats::ErrorStats, c: &crate::stats::ErrorStats| {
        format!(
            "{:.4} -> {:.4} / {:.4} -> {:.4}",
            b.mean_mm, c.mean_mm, b.max_mm, c.max_mm
        )
    };
    for (name, m) in with {
        if let Some(a) = &m.auto {
            let _ = writeln!(
                s,
                "  {:<14} chose {}: {}",
                method_label(*name),
                method_label(a.chosen),
                a.reason
            );
            let _ = writeln!(
                s,
                "  {:<14} decision: {}",
                "",
                a.decision.sentence(a.chosen)
            );
        }
        let Some(c) = &m.compensator else {
            continue;
        };
        let _ = writeln!(
            s,
            "  {:<14} {} on {}, {} units, over {}; trained by {} on {} {} poses: {} epochs / iterations / generations, {} loss evaluations, stopped: {}; training RMS {:.4} mm",
            method_label(*name),
            c.kind,
            c.inputs,
            c.units,
            method_label(c.base),
            c.training.trainer,
            c.training_poses,
            c.trained_on,
            c.training.epochs,
            c.training.evaluations,
            c.training.stop,
            c.training.rms_mm
        );
        if let Some(cv) = &c.cross_validation {
            let _ = writeln!(
                s,
                "  {:<14} cross-validated ({} folds on the {} poses): {}",
                "",
                cv.folds,
                c.trained_on,
                pair(&cv.base, &cv.compensated)
            );
        }
        let _ = writeln!(
            s,
            "  {:<14} identification: {}",
            "",
            pair(&c.base_identification, &m.identification.stats)
        );
        if let (Some(b), Some(t)) = (&c.base_training, &m.training) {
            let _ = writeln!(s, "  {:<14} training:       {}", "", pair(b, &t.stats));
        }
        if let (Some(b), Some(v)) = (&c.base_validation, &m.validation) {
            let _ = writeln!(s, "  {:<14} validation:     {}", "", pair(b, &v.stats));
        }
        let o = &c.orientation_part;
        let _ = writeln!(
            s,
            "  {:<14} orientation part: {} — {}",
            "",
            o.status.name(),
            o.reason
        );
    }
    s
}
