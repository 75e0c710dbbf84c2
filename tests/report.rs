//! The HTML calibration report: its sections, self-containment, escaping, the
//! format version, and a report of the real UR5 data (1000 + 20 poses).

use robocal::report::render_html;
use serde_json::{json, Value};
use std::sync::OnceLock;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// The demo report (thesis §7.4 simulation: YS100, KM, SKCM, SKCM-C), computed once.
fn demo() -> &'static Value {
    static REPORT: OnceLock<Value> = OnceLock::new();
    REPORT.get_or_init(|| {
        let study = robocal::sim::study::ys100_simulation(1, &|_| true).unwrap();
        serde_json::to_value(&study.report).unwrap()
    })
}

/// No reference to anything outside the page.
fn self_contained(html: &str) {
    assert!(html.starts_with("<!DOCTYPE html>"));
    let lower = html.to_lowercase();
    for bad in ["src=", "href=", "<link", "@import", "http://", "https://"] {
        assert!(!lower.contains(bad), "page contains `{bad}`");
    }
    // The only url() is the colour bar's in-page gradient.
    assert_eq!(
        lower.matches("url(").count(),
        lower.matches("url(#ramp)").count()
    );
    let body = &html[..html.find("<script>").unwrap_or(html.len())];
    assert!(!body.contains("NaN") && !body.contains(">inf"));
}

fn section<'a>(html: &'a str, id: &str) -> &'a str {
    let start = html
        .find(&format!(" id=\"{id}\""))
        .unwrap_or_else(|| panic!("section {id} missing"));
    let end = html[start..].find("</section>").unwrap() + start;
    &html[start..end]
}

#[test]
fn demo_report_has_every_section() {
    let r = demo();
    let html = render_html("YS100 — calibration 7", r);
    self_contained(&html);
    assert!(html.contains("<title>YS100 — calibration 7</title>"));
    // Histograms: one per set, every model a series.
    let h = section(&html, "histograms");
    assert_eq!(h.matches("<svg").count(), 2);
    let models = 1 + r["methods"].as_object().unwrap().len();
    assert_eq!(
        h.matches("<path").count(),
        2 * models,
        "nominal + methods per set"
    );
    // Per axis: three charts per set and a row per model and set.
    let a = section(&html, "per-axis");
    assert_eq!(a.matches("<svg").count(), 6);
    assert!(a.contains("dx mean") && a.contains("dz std"));
    // Positions: top and side view, before and after, per set; a tooltip on every pose.
    let n_id = r["identification_poses"].as_u64().unwrap() as usize;
    let n_va = r["validation_poses"].as_u64().unwrap() as usize;
    let p = section(&html, "positions");
    assert_eq!(p.matches("<circle").count(), 2 * 2 * (n_id + n_va));
    assert_eq!(p.matches("<circle").count(), p.matches("<title>").count());
    // Per-pose table: one row per pose, a column per model.
    let t = section(&html, "poses");
    assert_eq!(t.matches("<tr").count(), 1 + n_id + n_va);
    // The best method is the smallest validation mean, stated.
    let best = r["methods"]
        .as_object()
        .unwrap()
        .iter()
        .min_by(|a, b| {
            let m = |v: &Value| v["validation"]["mean_mm"].as_f64().unwrap();
            m(a.1).total_cmp(&m(b.1))
        })
        .unwrap()
        .0;
    let label = robocal::report::key_label(best);
    assert!(html.contains(&format!("<dd><strong>{label}</strong></dd>")));
    assert!(html.contains("smallest mean position error on the validation set"));
    // Every row of the statistics table matches the stored figure.
    let km = r["methods"]["km"]["validation"]["mean_mm"]
        .as_f64()
        .unwrap();
    assert!(section(&html, "statistics").contains(&robocal::report::format::num(km, 4)));
}

#[test]
fn user_text_is_escaped() {
    let mut r = demo().clone();
    r["robot"] = json!("<script>alert(1)</script>");
    r["failed"] = json!([{ "method": "skcm-payload", "reason": "<b>bold</b> & co" }]);
    let html = render_html("<b onclick=\"x()\">title</b>", &r);
    self_contained(&html);
    assert!(!html.contains("<script>alert"));
    assert!(html.contains("&lt;script&gt;alert(1)&lt;/script&gt;"));
    assert!(html.contains("<h1>&lt;b onclick=&quot;x()&quot;&gt;title&lt;/b&gt;</h1>"));
    assert!(section(&html, "warnings").contains("&lt;b&gt;bold&lt;/b&gt; &amp; co"));
}

#[test]
fn older_newer_and_unreadable_reports_say_so() {
    // Format 1: no version, no vectors or positions.
    let mut old = demo().clone();
    let o = old.as_object_mut().unwrap();
    o.remove("format_version");
    o.remove("pose_sources");
    let strip = |set: &mut Value| {
        if let Some(s) = set.as_object_mut() {
            s.remove("errors_xyz_mm");
            s.remove("positions_mm");
        }
    };
    for set in ["identification", "validation"] {
        strip(&mut old["nominal"][set]);
        for m in old["methods"].as_object_mut().unwrap().values_mut() {
            strip(&mut m[set]);
        }
    }
    let html = render_html("old", &old);
    assert!(html.contains("written in format 1"));
    let p = section(&html, "positions");
    assert!(p.contains("holds no pose positions"), "{p}");
    assert!(section(&html, "histograms").contains("<svg"));

    let mut newer = demo().clone();
    newer["format_version"] = json!(99);
    assert!(render_html("new", &newer).contains("in format 99, newer than this robocal reads"));

    let bad = render_html("bad", &json!({ "methods": 3 }));
    assert!(bad.contains("cannot be read"));
    let empty = render_html("", &json!({}));
    assert!(empty.contains("The report is empty"));
    assert!(empty.contains("<title>Calibration report</title>"));
}

/// The real UR5 data through `robocal calibrate --html`: 1000 grid poses for
/// identification, 20 random ones for validation.
#[test]
fn real_ur5_report_renders() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ur5.html");
    let data = format!("{ROOT}/data/ur5-wam-laser-tracker/UR5");
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_robocal"))
        .current_dir(ROOT)
        .args([
            "calibrate",
            "--model",
            "models/ur5.json",
            "--identify",
            &format!("{data}/3D_UR5_uncalibrated_grid_cleaned.csv"),
            "--validate",
            &format!("{data}/3D_UR5_uncalibrated_random_cleaned.csv"),
            "--method",
            "km,skcm",
            "--json",
            "--html",
        ])
        .arg(&out)
        .stdout(std::process::Stdio::null())
        .status()
        .unwrap();
    assert!(status.success());
    let html = std::fs::read_to_string(&out).unwrap();
    self_contained(&html);
    for id in ["warnings", "histograms", "per-axis", "positions", "poses"] {
        section(&html, id);
    }
    let t = section(&html, "poses");
    assert_eq!(t.matches("<tr").count(), 1 + 1000 + 20);
    // Pose sources: the upload's file and data row.
    assert!(t.contains("3D_UR5_uncalibrated_grid_cleaned.csv"));
    assert!(t.contains("<td class=\"n\">1000</td>"));
    let p = section(&html, "positions");
    assert_eq!(p.matches("<circle").count(), 2 * 2 * 1020);
    assert_eq!(p.matches("<circle").count(), p.matches("<title>").count());
}

/// A Gaussian-process compensator's report: the page draws each joint's
/// trained range (the report's own figures), lists the held-out regions of
/// the blocked cross-validation and the check of the expected errors.
#[test]
fn compensator_support_regions_and_expected_errors_are_shown() {
    use rand::SeedableRng;
    use robocal::calibrate::identify::{calibrate_with_training, CalibrationOptions, Method};
    use robocal::model::preset;
    use robocal::sim::random_configurations;
    use robocal::sim::unmodelled_truth;
    let nominal = preset("ys100").unwrap();
    let truth = unmodelled_truth(&nominal, true, 5);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let mut measure = |n: usize| {
        let qs = random_configurations(&nominal, n, &mut rng);
        let rows = truth
            .measure(&qs, Some(nominal.payload.mass), None, &mut rng)
            .unwrap();
        robocal::measure::to_measurements(&nominal, &rows, nominal.payload.mass)
    };
    let (ident, train, valid) = (measure(60), measure(150), measure(40));
    let opts = CalibrationOptions {
        methods: vec![Method::Km, Method::KmGp],
        ..Default::default()
    };
    let report =
        calibrate_with_training(&nominal, &ident, &train, &valid, &opts, &|_| true).unwrap();
    let c = report.methods[&Method::KmGp].compensator.as_ref().unwrap();
    assert_eq!(c.trained_ranges_deg.len(), 6);
    let u = c.uncertainty.as_ref().expect("a GP gives expected errors");
    assert_eq!(u.poses, 40);
    let blocked = &c.cross_validation.as_ref().unwrap().blocked;
    assert_eq!(blocked.len(), 4);
    let html = render_html("", &serde_json::to_value(&report).unwrap());
    self_contained(&html);
    let s = section(&html, "compensators");
    assert_eq!(s.matches("aria-label=\"Trained joint ranges\"").count(), 1);
    for (i, r) in c.trained_ranges_deg.iter().enumerate() {
        let title = format!("J{}: {:.1}° to {:.1}°", i + 1, r[0], r[1]);
        assert!(s.contains(&title), "{title}");
    }
    for i in 1..=4 {
        assert!(s.contains(&format!("Held-out region {i} (")), "region {i}");
    }
    assert!(s.contains("Expected error per pose on the 40 validation poses"));
}
