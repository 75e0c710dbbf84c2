//! The sections of the report page as maud templates (every interpolated
//! value is HTML-escaped by maud). Errors are position-error norms or signed
//! components `measured − predicted` in millimetres, in the registered robot
//! base frame of each pose's session.

use super::charts::{self, Point, Series};
use super::format::{key_label, method_label, num, opt, param};
use super::view::{Format, MethodView, ReportView, SetView};
use maud::{html, Markup};

/// The two pose sets: key and display name.
pub(super) const SETS: [(&str, &str); 2] = [
    ("identification", "Identification"),
    ("validation", "Validation"),
];
pub(super) const NOMINAL_COLOR: &str = "#d62728";
const PALETTE: [&str; 5] = ["#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf"];
const AXES: [&str; 3] = ["dx", "dy", "dz"];

/// A model whose errors the page shows: the nominal one or a method's.
pub(super) struct Model<'a> {
    pub key: &'a str,
    pub label: &'a str,
    pub color: &'a str,
    pub sets: &'a super::view::SetsView,
    pub method: Option<&'a MethodView>,
}

impl<'a> Model<'a> {
    pub(super) fn set(&self, set: &str) -> Option<&'a SetView> {
        match set {
            "identification" => self.sets.identification.as_ref(),
            _ => self.sets.validation.as_ref(),
        }
    }
}

/// Nominal first, then the methods in the thesis's order.
pub(super) fn models(r: &ReportView) -> Vec<Model<'_>> {
    let mut v = vec![Model {
        key: "nominal",
        label: "Nominal model",
        color: NOMINAL_COLOR,
        sets: &r.nominal,
        method: None,
    }];
    for (i, (k, m)) in r.ordered_methods().into_iter().enumerate() {
        v.push(Model {
            key: k,
            label: key_label(k),
            color: PALETTE[i % PALETTE.len()],
            sets: &m.sets,
            method: Some(m),
        });
    }
    v
}

pub(super) fn header(title: &str, r: &ReportView, models: &[Model]) -> Markup {
    let best = r.best();
    html! {
        header.top {
            p.kicker { "robocal · calibration report" }
            h1 { (title) }
            dl.meta {
                div { dt { "Robot" } dd { (if r.robot.is_empty() { "—" } else { &r.robot }) } }
                div { dt { "Identification poses" } dd { (r.identification_poses.map_or("—".into(), |n| n.to_string())) } }
                div { dt { "Validation poses" } dd { (r.validation_poses.map_or("—".into(), |n| n.to_string())) } }
                div { dt { "Methods" } dd {
                    @if models.len() <= 1 { "none" }
                    @for (i, m) in models.iter().skip(1).enumerate() { @if i > 0 { ", " } (m.label) }
                } }
                @if let Some(b) = best {
                    div { dt { "Best method" } dd { strong { (key_label(b)) } } }
                }
            }
            p.rule {
                "“Best” is the method with the smallest mean position error on the validation set "
                "(on the identification set when there is no validation set); the cards, tables and "
                "charts below use this one rule."
            }
            @match r.format() {
                Format::Current => {}
                Format::Older(v) => p.alert.warn {
                    "This report was written in format " (v) " (before per-pose error vectors, positions and "
                    "pose sources were stored): the per-axis and position sections are empty. Run the "
                    "calibration again to get them."
                }
                Format::Newer(v) => p.alert.warn {
                    "This report is in format " (v) ", newer than this robocal reads ("
                    (crate::calibrate::identify::REPORT_FORMAT_VERSION) "); the parts it understands are shown."
                }
            }
            (cards(r, models, best))
        }
    }
}

fn cards(r: &ReportView, models: &[Model], best: Option<&str>) -> Markup {
    let Some(b) = best.and_then(|b| models.iter().find(|m| m.key == b)) else {
        return html! {};
    };
    let _ = r;
    html! {
        div.cards {
            @for (set, name) in SETS {
                @let before = models[0].set(set).and_then(|s| s.mean_mm);
                @let after = b.set(set).and_then(|s| s.mean_mm);
                @if before.is_some() || after.is_some() {
                    div.card {
                        div.card-title { (name) " set · mean position error, nominal → " (b.label) }
                        div.card-value {
                            (opt(before, 4)) " mm " span.arrow { "→" } " "
                            span style={ "color:" (b.color) } { (opt(after, 4)) " mm" }
                        }
                    }
                }
            }
        }
    }
}

/// Warnings and failed methods, at the top of the page.
pub(super) fn alerts(r: &ReportView) -> Markup {
    let warned: Vec<(&str, &MethodView)> = r
        .ordered_methods()
        .into_iter()
        .filter(|(_, m)| !m.warnings.is_empty())
        .collect();
    if warned.is_empty() && r.failed.is_empty() {
        return html! {
            section #warnings { h2 { "Warnings" } p.ok { "No warnings: every method converged with plausible results." } }
        };
    }
    html! {
        section #warnings.alerts {
            h2 { "Warnings and failed methods" }
            @for f in &r.failed {
                p.alert.bad { strong { (method_label(f.method)) " failed: " } (f.reason) }
            }
            @for (k, m) in &warned {
                div.alert.warn {
                    strong { (key_label(k)) " — " (m.warnings.len()) " warning" @if m.warnings.len() > 1 { "s" } }
                    ul { @for w in &m.warnings { li { (w.message) } } }
                }
            }
        }
    }
}

/// Error statistics of every model on every set.
pub(super) fn statistics(models: &[Model], best: Option<&str>) -> Markup {
    html! {
        section #statistics {
            h2 { "Position errors" }
            table {
                thead { tr {
                    th { "Model" } th { "Set" } th.n { "n" } th.n { "mean" } th.n { "RMS" }
                    th.n { "std" } th.n { "95 %" } th.n { "max" }
                } }
                tbody {
                    @for m in models {
                        @for (set, name) in SETS {
                            @if let Some(s) = m.set(set) {
                                tr.best[best == Some(m.key)] {
                                    td { span.swatch style={ "background:" (m.color) } {} (m.label)
                                        @if best == Some(m.key) { " (best)" } }
                                    td { (name) }
                                    td.n { (s.n.map_or("—".into(), |n| n.to_string())) }
                                    @for v in [s.mean_mm, s.rms_mm, s.std_mm, s.p95_mm, s.max_mm] { td.n { (opt(v, 4)) } }
                                }
                            }
                        }
                    }
                }
            }
            p.note { "Millimetres; position-error norm per pose." }
            @if models.iter().any(|m| SETS.iter().any(|(set, _)| m.set(set).is_some_and(|s| s.orientation_n.is_some()))) {
                h2 #orientation { "Orientation errors" }
                table {
                    thead { tr {
                        th { "Model" } th { "Set" } th.n { "n" } th.n { "mean" } th.n { "RMS" }
                        th.n { "std" } th.n { "95 %" } th.n { "max" }
                    } }
                    tbody {
                        @for m in models { @for (set, name) in SETS {
                            @if let Some(s) = m.set(set).filter(|s| s.orientation_n.is_some()) {
                                tr.best[best == Some(m.key)] {
                                    td { span.swatch style={ "background:" (m.color) } {} (m.label) }
                                    td { (name) }
                                    td.n { (s.orientation_n.map_or("—".into(), |n| n.to_string())) }
                                    @for v in [s.orientation_mean_deg, s.orientation_rms_deg, s.orientation_std_deg, s.orientation_p95_deg, s.orientation_max_deg] { td.n { (opt(v, 4)) } }
                                }
                            }
                        } }
                    }
                }
                p.note { "Degrees; the angle of R_measured·R_predictedᵀ per pose that measured an orientation. "
                    "Compensators correct position only: their orientation is their base's." }
            }
        }
    }
}

/// Histograms of the error norms per set, every model overlaid (log bins).
pub(super) fn histograms(models: &[Model]) -> Markup {
    html! {
        section #histograms {
            h2 { "Error histograms before and after" }
            p.note { "Logarithmic error bins, so nominal errors (millimetres) and calibrated ones "
                "(hundredths) share one axis. Hover a bin for the counts." }
            (legend(models))
            div.grid2 {
                @for (set, name) in SETS {
                    @let series: Vec<Series> = models.iter().filter_map(|m| Some(Series {
                        name: m.label, color: m.color, values: m.set(set)?.finite() })).collect();
                    @if !series.is_empty() {
                        figure {
                            (charts::histogram(&series, true, 40, "position error [mm]"))
                            figcaption { (name) " set" }
                        }
                    }
                }
            }
        }
    }
}

pub(super) fn legend(models: &[Model]) -> Markup {
    html! {
        p.legend { @for m in models { span { span.swatch style={ "background:" (m.color) } {} (m.label) } } }
    }
}

/// Signed errors per axis: a table for every model and histograms of the best.
pub(super) fn per_axis(models: &[Model], best: Option<&str>) -> Markup {
    let stats = |v: &[f64]| {
        let n = v.len() as f64;
        let mean = v.iter().sum::<f64>() / n;
        let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0)).sqrt();
        let max = v.iter().map(|x| x.abs()).fold(0.0, f64::max);
        (mean, sd, max)
    };
    let shown: Vec<&Model> = models
        .iter()
        .filter(|m| m.key == "nominal" || Some(m.key) == best)
        .collect();
    html! {
        section #per-axis {
            h2 { "Errors per axis (dx, dy, dz)" }
            p.note { "Signed components of measured − predicted position, in the registered base frame [mm]. "
                "A mean far from zero is a bias the model does not explain." }
            table {
                thead { tr { th { "Model" } th { "Set" }
                    @for a in AXES { th.n { (a) " mean" } th.n { (a) " std" } th.n { "max |" (a) "|" } } } }
                tbody {
                    @for m in models { @for (set, name) in SETS {
                        @if let Some(s) = m.set(set).filter(|s| !s.errors_xyz_mm.is_empty()) {
                            tr { td { (m.label) } td { (name) }
                                @for k in 0..3 { @let (a, b, c) = stats(&s.axis(k));
                                    td.n { (num(a, 3)) } td.n { (num(b, 3)) } td.n { (num(c, 3)) } } }
                        }
                    } }
                }
            }
            @for (set, name) in SETS {
                @if shown.iter().any(|m| m.set(set).is_some_and(|s| !s.errors_xyz_mm.is_empty())) {
                    h3 { (name) " set" }
                    div.grid3 {
                        @for k in 0..3 {
                            @let series: Vec<Series> = shown.iter().filter_map(|m| Some(Series {
                                name: m.label, color: m.color, values: m.set(set)?.axis(k) })).collect();
                            figure { (charts::histogram(&series, false, 30, &format!("{} [mm]", AXES[k])))
                                figcaption { (AXES[k]) ", " (series.iter().map(|s| s.name).collect::<Vec<_>>().join(" and ")) } }
                        }
                    }
                }
            }
            @if models.iter().all(|m| SETS.iter().all(|(s, _)| m.set(s).is_none_or(|s| s.errors_xyz_mm.is_empty()))) {
                p.note { "This report holds no per-pose error vectors." }
            }
        }
    }
}

/// Pose positions seen from above (x–y) and from the side (x–z), coloured by
/// the error of the nominal model (before) and of the best method (after).
pub(super) fn positions(r: &ReportView, models: &[Model], best: Option<&str>) -> Markup {
    let shown: Vec<&Model> = models
        .iter()
        .filter(|m| m.key == "nominal" || Some(m.key) == best)
        .collect();
    let any_positions = shown.iter().any(|m| {
        SETS.iter()
            .any(|(s, _)| m.set(s).is_some_and(|s| !s.positions_mm.is_empty()))
    });
    html! {
        section #positions {
            h2 { "Error against position" }
            p.note { "Measured positions in the registered base frame [mm], equal scales; colour = error norm, "
                "saturating at the model's 95th percentile. Hover a point for its pose." }
            @for (set, name) in SETS {
                @for m in &shown {
                    @if let Some(s) = m.set(set).filter(|s| !s.positions_mm.is_empty()) {
                        @let vmax = s.p95_mm.filter(|v| *v > 0.0).unwrap_or(1.0);
                        h3 { (name) " set — " (m.label) }
                        (charts::colour_bar(vmax, "position error [mm]"))
                        div.grid2 {
                            figure { (charts::scatter(&points(r, set, s, 0, 1), vmax, "x [mm]", "y [mm]")) figcaption { "Top view (x–y)" } }
                            figure { (charts::scatter(&points(r, set, s, 0, 2), vmax, "x [mm]", "z [mm]")) figcaption { "Side view (x–z)" } }
                        }
                    }
                }
            }
            @if !any_positions { p.note { "This report holds no pose positions." } }
        }
    }
}

fn points(r: &ReportView, set: &str, s: &SetView, a: usize, b: usize) -> Vec<Point> {
    s.positions_mm
        .iter()
        .enumerate()
        .filter_map(|(i, p)| {
            let e = s
                .errors_mm
                .get(i)
                .copied()
                .flatten()
                .unwrap_or(f64::INFINITY);
            Some(Point {
                x: p[a]?,
                y: p[b]?,
                value: e,
                tip: format!("{}: {} mm", pose_name(r, set, i), num(e, 3)),
            })
        })
        .collect()
}

/// "set NAME row N (session S)" or "pose N" when the source is unknown.
pub(super) fn pose_name(r: &ReportView, set: &str, i: usize) -> String {
    match source(r, set, i) {
        Some(s) if s.session.is_empty() => format!("{} row {}", s.set, s.row),
        Some(s) => format!("{} row {} (session {})", s.set, s.row, s.session),
        None => format!("{set} pose {}", i + 1),
    }
}

pub(super) fn source<'a>(
    r: &'a ReportView,
    set: &str,
    i: usize,
) -> Option<&'a crate::calibrate::identify::PoseSource> {
    let p = r.pose_sources.as_ref()?;
    match set {
        "identification" => p.identification.get(i),
        _ => p.validation.get(i),
    }
}

/// Far-out threshold of Tukey's fences: Q3 + 3·IQR of the finite errors.
pub(super) fn outlier_limit(errors: &[f64]) -> Option<f64> {
    if errors.len() < 4 {
        return None;
    }
    let mut v = errors.to_vec();
    v.sort_by(f64::total_cmp);
    let q = |p: f64| {
        let x = p * (v.len() - 1) as f64;
        let (i, f) = (x.floor() as usize, x.fract());
        v[i] + (v[(i + 1).min(v.len() - 1)] - v[i]) * f
    };
    Some(q(0.75) + 3.0 * (q(0.75) - q(0.25)))
}

/// One row per pose of both sets; outliers of the best method flagged.
pub(super) fn pose_table(r: &ReportView, models: &[Model], best: Option<&str>) -> Markup {
    let best_model = models.iter().find(|m| Some(m.key) == best);
    let n_ident = models
        .iter()
        .filter_map(|m| m.set("identification"))
        .map(|s| s.errors_mm.len())
        .max()
        .unwrap_or(0);
    html! {
        section #poses {
            h2 { "Per-pose errors" }
            p.note {
                "Errors [mm] of every pose. “Outlier” marks a pose whose error with the best method ("
                (best.map(key_label).unwrap_or("—")) ") lies beyond Q3 + 3·IQR of its set (Tukey's far-out fence). "
                "Click a column heading to sort."
            }
            div.scroll {
                table.sortable #pose-table {
                    thead { tr {
                        th.n data-type="n" { "#" } th { "set" } th { "source" } th.n data-type="n" { "row" } th { "session" }
                        @for m in models { th.n data-type="n" { (m.label) } }
                        th { "flag" }
                    } }
                    tbody {
                        @for (set, name) in SETS {
                            @let n = models.iter().filter_map(|m| m.set(set)).map(|s| s.errors_mm.len()).max().unwrap_or(0);
                            @let limit = best_model.and_then(|b| b.set(set)).and_then(|s| outlier_limit(&s.finite()));
                            @for i in 0..n {
                                @let k = if set == "identification" { i + 1 } else { n_ident + i + 1 };
                                @let src = source(r, set, i);
                                @let e_best = best_model.and_then(|b| b.set(set)).and_then(|s| s.errors_mm.get(i).copied().flatten());
                                @let out = matches!((e_best, limit), (Some(e), Some(l)) if e > l);
                                tr.outlier[out] {
                                    td.n { (k) } td { (name) }
                                    td { (src.map_or("—", |s| s.set.as_str())) }
                                    td.n { (src.map_or(i + 1, |s| s.row)) }
                                    td { (src.map_or("—", |s| if s.session.is_empty() { "—" } else { s.session.as_str() })) }
                                    @for m in models {
                                        td.n { (opt(m.set(set).and_then(|s| s.errors_mm.get(i).copied().flatten()), 3)) }
                                    }
                                    td { @if out { "outlier" } }
                                }
                            }
                        }
                    }
                }
            }
        }
    }
}

/// Solver outcome per method and the TLBO convergence curve.
pub(super) fn solvers(models: &[Model]) -> Markup {
    html! {
        section #solvers {
            h2 { "Solvers" }
            table {
                thead { tr { th { "Method" } th { "converged" } th.n { "iterations" } th.n { "RMS before" } th.n { "RMS after" } th { "stop reason" } } }
                tbody {
                    @for m in models { @if let Some(s) = m.method.and_then(|x| x.solver.as_ref()) {
                        tr { td { (m.label) }
                            td { @if s.converged { span.ok { "yes" } } @else { span.bad { "no" } } }
                            td.n { (s.iterations) } td.n { (num(s.initial_rms_mm, 4)) } td.n { (num(s.final_rms_mm, 4)) }
                            td { (s.detail) } }
                    } }
                }
            }
            @for m in models { @if let Some(t) = m.method.and_then(|x| x.tlbo.as_ref()) {
                @let h: Vec<f64> = t.history.iter().map(|v| v.unwrap_or(f64::NAN)).collect();
                figure { (charts::line(&h, true, m.color, "generation", "best cost [mm²]"))
                    figcaption { (m.label) " convergence: best cost after each generation ("
                        (t.evaluations.map_or("—".into(), |e| e.to_string())) " evaluations)" } }
            } }
        }
    }
}

/// Identifiability summary, identified parameters and joint stiffness.
pub(super) fn parameters(r: &ReportView, models: &[Model]) -> Markup {
    let methods: Vec<&Model> = models.iter().filter(|m| m.method.is_some()).collect();
    html! {
        @if let Some(i) = &r.identifiability {
            section #identifiability {
                h2 { "Identifiability" }
                p { (i.kept.len()) " of " (i.candidates) " candidate parameters identified from " (i.poses)
                    " poses; condition number " (num(i.condition_number, 4)) ", O1 " (num(i.observability_o1, 4)) "." }
                @if !i.identifiable_by_orientation.is_empty() {
                    p { "Identified only thanks to the measured orientations (the positions alone would not): "
                        (i.identifiable_by_orientation.join(", ")) "." }
                }
                @if !i.unseen_tool_tip_terms.is_empty() {
                    p { "Not seen by position-only data: " (i.unseen_tool_tip_terms.join(", "))
                        ". A production tool's tip away from the measured point depends on them, so its error there is unknown; measure orientations (a 6-D probe) to identify them." }
                }
                @if !i.dropped.is_empty() {
                    table { thead { tr { th { "Not identified" } th { "why" } } }
                        tbody { @for d in &i.dropped { tr { td { (d.name) } td { (d.reason) } } } } }
                }
            }
        }
        section #parameters {
            h2 { "Identified parameters" }
            @for m in &methods { @let p = &m.method.map_or(&[][..], |x| &x.parameters[..]);
                @if !p.is_empty() {
                    h3 { (m.label) }
                    table.params { thead { tr { th { "parameter" } th { "unit" } th.n { "nominal" } th.n { "identified" } th.n { "σ" } } }
                        tbody { @for e in p.iter() { tr { td { (e.name) } td { (e.unit) }
                            td.n { (param(e.nominal, &e.unit)) } td.n { (param(e.value, &e.unit)) }
                            td.n { (e.std.map_or("—".into(), |s| param(s, &e.unit))) } } } } }
                }
            }
        }
        @if methods.iter().any(|m| m.method.is_some_and(|x| x.stiffness_nm_per_rad.iter().any(Option::is_some))) {
            section #stiffness {
                h2 { "Joint stiffness [N·m/rad]" }
                table { tbody { @for m in &methods { @if let Some(x) = m.method.filter(|x| x.stiffness_nm_per_rad.iter().any(Option::is_some)) {
                    tr { th { (m.label) } @for (j, k) in x.stiffness_nm_per_rad.iter().enumerate() {
                        td.n { "K" (j + 1) " = " (opt(*k, 4)) } } }
                } } } }
            }
        }
        @if !r.registration.is_empty() {
            section #registration {
                h2 { "Registration" }
                table { thead { tr { th { "session" } th.n { "RMS of the nominal model after registration [mm]" } } }
                    tbody { @for g in &r.registration { tr { td { (r.session_name(g.session)) } td.n { (opt(g.rms_mm, 4)) } } } } }
            }
        }
    }
}

/// `auto`'s decision in one line: tie or not, the deciding step, the
/// runner-up and the margin, the fallback to the better base and the
/// blocked-fold veto.
fn decision_line(d: &super::view::AutoDecisionView) -> String {
    let pct = d.tie_margin * 100.0;
    let mut s = match (&d.runner_up, d.tie) {
        (None, _) => "The only option.".to_string(),
        (Some(r), false) => format!(
            "No tie: the cross-validated mean is {:.4} mm below {}'s (more than {pct:.0} % apart).",
            d.mean_margin_mm,
            key_label(r)
        ),
        (Some(r), true) => format!(
            "Tie with {} on the cross-validated mean (within {pct:.0} %, {:+.4} mm), decided by {}, by {:.4} {}.",
            key_label(r),
            d.mean_margin_mm,
            d.step_label,
            d.margin,
            d.margin_unit
        ),
    };
    if let Some(f) = &d.fallback {
        s.push_str(&format!(
            " {} was set aside: it sits on {}, which {} beats outside the trained region ({:.4} against {:.4} mm, {}).",
            key_label(&f.instead_of),
            key_label(&f.weaker_base),
            key_label(&f.better_base),
            f.weaker_mm,
            f.better_mm,
            f.measured_by
        ));
    }
    for c in &d.blocked_checks {
        let edge = c.worst_edge.as_ref().map_or(String::new(), |e| {
            format!(
                "; at the worst of {} edges of the joints' drawn ranges, joint {} {} ({} poses), {:.4} / {:.4} mm against {:.4} / {:.4}",
                c.edges,
                e.joint,
                e.side,
                e.poses,
                e.option.mean_mm,
                e.option.max_mm,
                e.base.mean_mm,
                e.base.max_mm
            )
        });
        s.push_str(&format!(
            " Blocked-fold veto: {} on {} blocked regions ({} poses, each refitted without its region) {:.4} / {:.4} mm mean / max against {} alone {:.4} / {:.4}{edge}, {}.",
            key_label(&c.option),
            c.regions,
            c.poses,
            c.option_blocked.mean_mm,
            c.option_blocked.max_mm,
            key_label(&c.base),
            c.base_blocked.mean_mm,
            c.base_blocked.max_mm,
            c.verdict_label
        ));
    }
    s
}

/// The learned compensators: what each is, how it was trained, and its effect
/// on every set (base → compensated), with `auto`'s choice.
pub(super) fn compensators(models: &[Model]) -> Markup {
    let shown: Vec<(&Model, &MethodView)> = models
        .iter()
        .filter_map(|m| Some((m, m.method?)))
        .filter(|(_, v)| v.compensator.is_some() || v.auto.is_some())
        .collect();
    if shown.is_empty() {
        return html! {};
    }
    let gain = |b: Option<f64>, c: Option<f64>| match (b, c) {
        (Some(b), Some(c)) if b > 0.0 => format!("{:+.1} %", 100.0 * (c - b) / b),
        _ => "—".into(),
    };
    html! {
        section #compensators {
            h2 { "Compensators" }
            p.note { "Each compensator learns what its model-based base leaves: base → compensated, "
                "mean and max position error [mm]. Cross-validated figures are out-of-fold predictions "
                "on the training pool." }
            @for (m, v) in &shown {
                h3 { (m.label) }
                @if let Some(a) = &v.auto {
                    p { strong { "Chose " (key_label(&a.chosen)) ": " } (a.reason) }
                    @if let Some(d) = &a.decision {
                        p.note { (decision_line(d)) }
                    }
                }
                @if let Some(c) = &v.compensator {
                    p { (c.kind) " on " (c.inputs) ", " (c.units.map_or("—".into(), |u| u.to_string()))
                        " units, over " (key_label(&c.base)) "; trained by " (c.training.trainer)
                        " on " (c.training_poses.map_or("—".into(), |n| n.to_string())) " "
                        (c.trained_on) " poses, " (c.training.epochs.map_or("—".into(), |n| n.to_string()))
                        " epochs / iterations / generations; stopped: " (c.training.stop) }
                    @if let Some(n) = &c.orientation_note { p.note { (n) } }
                    @if let Some(o) = &c.orientation_part {
                        p.note { "Orientation part: " strong { (o.status) } " — " (o.reason) }
                    }
                    table {
                        thead { tr { th { "Set" } th.n { "base mean" } th.n { "mean" } th.n { "change" }
                            th.n { "base max" } th.n { "max" } th.n { "change" } } }
                        tbody {
                            @let rows = [
                                ("Cross-validated (training pool)", c.cross_validation.as_ref().map(|cv| (&cv.base, &cv.compensated))),
                            ];
                            @for (name, pair) in rows {
                                @if let Some((b, a)) = pair {
                                    tr { td { (name) }
                                        td.n { (opt(b.mean_mm, 4)) } td.n { (opt(a.mean_mm, 4)) } td.n { (gain(b.mean_mm, a.mean_mm)) }
                                        td.n { (opt(b.max_mm, 4)) } td.n { (opt(a.max_mm, 4)) } td.n { (gain(b.max_mm, a.max_mm)) } }
                                }
                            }
                            @for (name, b, a) in [
                                ("Identification", c.base_identification.as_ref(), v.sets.identification.as_ref()),
                                ("Training", c.base_training.as_ref(), v.training.as_ref()),
                                ("Validation", c.base_validation.as_ref(), v.sets.validation.as_ref()),
                            ] {
                                @if let (Some(b), Some(a)) = (b, a) {
                                    tr { td { (name) }
                                        td.n { (opt(b.mean_mm, 4)) } td.n { (opt(a.mean_mm, 4)) } td.n { (gain(b.mean_mm, a.mean_mm)) }
                                        td.n { (opt(b.max_mm, 4)) } td.n { (opt(a.max_mm, 4)) } td.n { (gain(b.max_mm, a.max_mm)) } }
                                }
                            }
                            @for (i, r) in c.cross_validation.iter().flat_map(|cv| cv.blocked.iter()).enumerate() {
                                tr { td { "Held-out region " (i + 1) " (" (r.poses.map_or("—".into(), |n| n.to_string())) " poses)" }
                                    td.n { (opt(r.base_mean_mm, 4)) } td.n { (opt(r.compensated_mean_mm, 4)) }
                                    td.n { (gain(r.base_mean_mm, r.compensated_mean_mm)) } td.n { "" } td.n { "" } td.n { "" } }
                            }
                        }
                    }
                    @if !c.trained_ranges_deg.is_empty() {
                        p.note { "Where it was trained: each joint's range (dark), the band over which its correction "
                            "fades to zero (light, " (opt(c.fade_deg, 1)) "°); beyond it the base alone applies and "
                            "solve flags the target." }
                        (crate::report::charts::ranges(&c.trained_ranges_deg, c.fade_deg.unwrap_or(0.0)))
                    }
                    @if let Some(u) = &c.uncertainty {
                        p { "Expected error per pose on the " (u.poses.map_or("—".into(), |n| n.to_string()))
                            " validation poses: mean " (opt(u.mean_expected_mm, 4)) " mm; the error exceeds it in "
                            (opt(u.above_expected.map(|x| x * 100.0), 1)) " % of the poses (Gaussian: 39.2 %) and "
                            "twice it in " (opt(u.above_twice_expected.map(|x| x * 100.0), 1)) " % (0.7 %); RMS error / RMS expected "
                            (opt(u.rms_ratio, 2)) "." }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The veto's line shows the worst edge beside the clusters, with the
    /// report's figures; a check without edges (an older report) shows none.
    #[test]
    fn the_veto_line_shows_the_worst_edge() {
        let d: super::super::view::AutoDecisionView = serde_json::from_value(serde_json::json!({
            "blocked_checks": [{
                "option": "skcm-maps", "base": "skcm", "verdict": "blocked_edge",
                "verdict_label": "vetoed at an edge", "regions": 4, "poses": 400,
                "option_blocked": {"mean_mm": 0.0924, "max_mm": 0.2677},
                "base_blocked": {"mean_mm": 0.1395, "max_mm": 0.4089},
                "edges": 12,
                "worst_edge": {"joint": 2, "side": "high", "poses": 93,
                    "option": {"mean_mm": 0.2293, "max_mm": 0.5371},
                    "base": {"mean_mm": 0.1279, "max_mm": 0.2814}}
            }, {
                "option": "km-maps", "base": "km", "verdict": "passed",
                "verdict_label": "within", "regions": 4, "poses": 400,
                "option_blocked": {"mean_mm": 0.1, "max_mm": 0.2},
                "base_blocked": {"mean_mm": 0.2, "max_mm": 0.3}
            }]
        }))
        .unwrap();
        let line = decision_line(&d);
        assert!(
            line.contains("0.1395 / 0.4089; at the worst of 12 edges of the joints' drawn ranges, joint 2 high (93 poses), 0.2293 / 0.5371 mm against 0.1279 / 0.2814, vetoed at an edge."),
            "{line}"
        );
        assert!(line.contains("0.2000 / 0.3000, within."), "{line}");
        assert_eq!(line.matches("worst of").count(), 1, "{line}");
    }
}
