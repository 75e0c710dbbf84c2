//! Fits judged before they are stored (issue 42): the rule against readings
//! simulated at and beyond the noise it states, readings that hold no fixed
//! point, a tracker fit far out, a tool whose orientation is known, work
//! objects whose points disagree.

use super::*;
use robocal_core::cell_fit::tcp::entry::{self, OrientationSource, Outcome, StoreRequest};
use robocal_core::cell_fit::tcp::judge::{self, Noise as Sources};
use robocal_core::cell_fit::tcp::{
    EntryField, JudgedFit, Reading, StoredEntry, ToolRequest, WoPoint,
};
use robocal_core::solve::cell::LoadDescription;

fn joint_rows(q: &[Vec<f64>]) -> Vec<Reading> {
    q.iter()
        .map(|q| Reading {
            joints_deg: Some(q.clone()),
            ..Reading::default()
        })
        .collect()
}

fn fixed_point_request(q: &[Vec<f64>]) -> ToolRequest {
    ToolRequest {
        method: TcpMethod::FixedPoint,
        rows: joint_rows(q),
        axis: None,
    }
}

/// Readings with the tip of `tool` at `point` ± `sigma_m` per axis.
fn noisy_fixed_point(tool: &Pose, n: usize, sigma_m: f64, seed: u64) -> Vec<Vec<f64>> {
    let model = calibrated_ur10();
    let point = Vector3::new(0.6, 0.2, 0.3);
    let mut noise = Noise::new(seed, sigma_m);
    tilted_orientations(n, 30.0)
        .into_iter()
        .map(|r| readings_for(&model, tool, &Pose::new(r, point + noise.vec())).unwrap())
        .collect()
}

/// The fit a verdict carries.
fn judged_tool(e: &tcp::FitError) -> &tcp::ToolFit {
    match e.fit.as_deref() {
        Some(JudgedFit::Tool(f)) => f,
        other => panic!("a tool fit, got {other:?}"),
    }
}

#[test]
fn the_rule_passes_readings_at_the_stated_noise_and_refuses_eight_times_it() {
    // σ per axis of a tip placed on a point on the calibrated robot: the
    // pointing and the robot's noise, √(0.25² + 0.15²) mm.
    let sigma_mm = (0.25f64.powi(2) + 0.15f64.powi(2)).sqrt();
    assert!((Sources::Pointing.sigma_mm() - sigma_mm).abs() < 1e-12);
    let model = calibrated_ur10();
    let tool = true_tool();
    for seed in 0..8 {
        let q = noisy_fixed_point(&tool, 8, sigma_mm * 1e-3, 100 + seed);
        let fit = tcp::fit_tool(&model, &fixed_point_request(&q))
            .unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        let limits = fit.limits.unwrap();
        assert!((limits.rms_mm - 3.0 * 3f64.sqrt() * sigma_mm).abs() < 1e-12);
        assert!(fit.rms_mm < limits.rms_mm, "seed {seed}: {}", fit.rms_mm);
        eprintln!(
            "seed {seed}: at σ rms {:.3} mm of ≤ {:.3} mm",
            fit.rms_mm, limits.rms_mm
        );
        let q = noisy_fixed_point(&tool, 8, 8.0 * sigma_mm * 1e-3, 200 + seed);
        let e = tcp::fit_tool(&model, &fixed_point_request(&q)).unwrap_err();
        assert!(
            matches!(
                e.reason,
                NotFittedReason::ResidualsTooLarge | NotFittedReason::ResidualOutlier
            ),
            "seed {seed}: {e}"
        );
        assert!(e.measured.unwrap() > e.needed.unwrap(), "{e:?}");
        eprintln!(
            "seed {seed}: at 8σ {} {:.3} mm of ≤ {:.3} mm",
            e.reason.as_str(),
            e.measured.unwrap(),
            e.needed.unwrap()
        );
    }
}

#[test]
fn eight_readings_without_a_fixed_point_are_not_fitted_and_not_stored() {
    let model = calibrated_ur10();
    let (q, _) = random_readings(8, 21);
    let e = tcp::fit_tool(&model, &fixed_point_request(&q)).unwrap_err();
    assert_eq!(e.reason, NotFittedReason::ResidualsTooLarge, "{e}");
    let fit = judged_tool(&e);
    // The figures: residuals per reading, their RMS against the bound.
    assert_eq!(fit.residual_mm.len(), 8);
    eprintln!(
        "8 readings without a fixed point: rms {:.1} mm (bound {:.3} mm), TCP {:.1} mm from the flange",
        fit.rms_mm,
        e.needed.unwrap(),
        fit.distance_mm
    );
    assert!(fit.rms_mm > 100.0, "rms {} mm", fit.rms_mm);
    assert_eq!(e.measured, Some(fit.rms_mm));
    let bound = 3.0 * 3f64.sqrt() * (0.25f64.powi(2) + 0.15f64.powi(2)).sqrt();
    assert!((e.needed.unwrap() - bound).abs() < 1e-12, "{e:?}");
    assert!(
        e.message.contains("do not hold the tip at one point"),
        "{e}"
    );
    assert!(fit.sigma_mm.iter().all(|s| *s > 1.0), "{:?}", fit.sigma_mm);
    // Nothing to store, unless forced: then stored with the verdict kept.
    let store = StoreRequest {
        store: true,
        rpy_deg: Some([0.0; 3]),
        ..StoreRequest::default()
    };
    assert!(matches!(
        entry::tool(Err(e.clone()), &store),
        Outcome::NotFitted(ref n) if n.reason == NotFittedReason::ResidualsTooLarge
    ));
    let forced = StoreRequest {
        force: true,
        ..store
    };
    let Outcome::Fitted(f) = entry::tool(Err(e), &forced) else {
        panic!("forced")
    };
    let a = f.answer();
    assert!(!a.fitted && a.forced);
    assert_eq!(
        a.overruled.unwrap().reason,
        NotFittedReason::ResidualsTooLarge
    );
    assert_eq!(f.entry.unwrap().xyz_mm, fit_xyz(&f.fit));
    // Readings that determine nothing cannot be forced.
    let e = tcp::fit_tool(&model, &fixed_point_request(&q[..3])).unwrap_err();
    assert!(matches!(
        entry::tool(Err(e), &forced),
        Outcome::NotFitted(_)
    ));
}

fn fit_xyz(f: &tcp::ToolFit) -> [f64; 3] {
    [f.tcp.p.x * 1e3, f.tcp.p.y * 1e3, f.tcp.p.z * 1e3]
}

/// Tracker rows: the flange at `q` carries the reflector at `tip` (flange
/// frame, m), measured in the tracker frame ± 0.01 mm.
fn tracker_rows(q: &[Vec<f64>], flanges: &[Pose], tip: &Vector3<f64>, seed: u64) -> Vec<Reading> {
    let model = calibrated_ur10();
    let mut noise = Noise::new(seed, 1e-5);
    q.iter()
        .zip(flanges)
        .map(|(q, f)| {
            let x = model
                .cell_from_base
                .transform_point(&f.transform_point(tip))
                + noise.vec();
            Reading {
                joints_deg: Some(q.clone()),
                xyz_mm: Some([x.x * 1e3, x.y * 1e3, x.z * 1e3]),
                ..Reading::default()
            }
        })
        .collect()
}

#[test]
fn a_tracker_point_fit_far_out_is_refused() {
    let model = calibrated_ur10();
    let (q, truth) = random_readings(8, 22);
    let req = |rows| ToolRequest {
        method: TcpMethod::TrackerPoint,
        rows,
        axis: None,
    };
    // A reflector that follows the flange 34 m out: the residuals are the
    // tracker's, the TCP is where no tool reaches.
    let far = Vector3::new(0.0, 0.0, 34.0);
    let e = tcp::fit_tool(&model, &req(tracker_rows(&q, &truth, &far, 23))).unwrap_err();
    assert_eq!(e.reason, NotFittedReason::TcpTooFar, "{e}");
    assert!((e.measured.unwrap() - 34_000.0).abs() < 0.1, "{e:?}");
    // The UR10's arm, joint 1 to the flange stretched out (its DH: a2, a3
    // with d4, d5, d6): 612 + √(572.3² + 163.941²) + 115.7 + 92.2 mm.
    let arm = 612.0 + 572.3f64.hypot(163.941) + 115.7 + 92.2;
    assert!((e.needed.unwrap() - arm).abs() < 1e-9, "{e:?}");
    assert!(judged_tool(&e).rms_mm < 0.05);
    // A reflector that stays in the room (every row one point): far off and
    // beyond the noise.
    let fixed: Vec<Reading> = q
        .iter()
        .map(|q| Reading {
            joints_deg: Some(q.clone()),
            xyz_mm: Some([2500.0, -800.0, 400.0]),
            ..Reading::default()
        })
        .collect();
    let e = tcp::fit_tool(&model, &req(fixed)).unwrap_err();
    assert_eq!(e.reason, NotFittedReason::ResidualsTooLarge, "{e}");
    // The true tool, measured the same way, is fitted and within its limits.
    let tool = true_tool();
    let ok = tcp::fit_tool(&model, &req(tracker_rows(&q, &truth, &tool.p, 24))).unwrap();
    assert!((ok.tcp.p - tool.p).norm() * 1e3 < 0.05);
    assert!(ok.rms_mm < ok.limits.unwrap().rms_mm);
    assert_eq!(ok.limits.unwrap().noise, Sources::Tracker);
}

#[test]
fn a_fixed_point_fit_keeps_the_known_orientation_of_the_tool() {
    let model = calibrated_ur10();
    let tool = true_tool(); // 30° about the flange's y
    let q = noisy_fixed_point(&tool, 6, 1e-5, 31);
    let fitted = tcp::fit_tool(&model, &fixed_point_request(&q));
    let fit = fitted.clone().unwrap();
    // The method fits the position only.
    assert_eq!(fit.rpy_deg, None);
    let load = LoadDescription {
        mass_kg: 4.0,
        com_mm: [0.0, 0.0, 120.0],
        frame: Default::default(),
        inertia_kgm2: None,
    };
    // As the user stated it: 1 mm off in each axis, the orientation right.
    let stated = StoredEntry {
        number: Some(3),
        frame: None,
        xyz_mm: [31.0, -19.0, 251.0],
        rpy_deg: [0.0, 30.0, 0.0],
        load: Some(load.clone()),
    };
    let req = StoreRequest {
        existing: Some(stated.clone()),
        store: true,
        ..StoreRequest::default()
    };
    let Outcome::Fitted(f) = entry::tool(fitted.clone(), &req) else {
        panic!("fitted")
    };
    let e = f.entry.clone().unwrap();
    assert_eq!(f.orientation, Some(OrientationSource::Kept));
    assert_eq!(e.rpy_deg, [0.0, 30.0, 0.0]);
    assert_eq!((e.number, e.load.as_ref()), (Some(3), Some(&load)));
    for (k, want) in [30.0, -20.0, 250.0].iter().enumerate() {
        assert!((e.xyz_mm[k] - want).abs() < 0.05, "{:?}", e.xyz_mm);
    }
    let r = f.replaced.as_ref().unwrap();
    assert_eq!(r.changed, vec![EntryField::Position]);
    assert!((r.moved_mm.unwrap() - 3f64.sqrt()).abs() < 0.05, "{r:?}");
    assert_eq!(r.turned_deg, Some(0.0));
    assert_eq!(r.old, stated);
    let text = r.describe();
    assert!(
        text.contains("orientation [deg]: [0.0000, 30.0000, 0.0000] → [0.0000, 30.0000, 0.0000] (turned 0.0000°, unchanged)"),
        "{text}"
    );
    // A new tool: its orientation is unknown, and it is not stored …
    let new = StoreRequest {
        store: true,
        ..StoreRequest::default()
    };
    let Outcome::NotFitted(e) = entry::tool(fitted.clone(), &new) else {
        panic!("not stored")
    };
    assert_eq!(e.reason, NotFittedReason::OrientationUnknown);
    assert!(!e.reason.forcible());
    assert!(e.message.contains("--rpy-deg"), "{e}");
    assert_eq!(judged_tool(&e).xyz_mm, fit.xyz_mm);
    // … unless given; a report that stores nothing says it is unknown.
    let given = StoreRequest {
        rpy_deg: Some([0.0, 30.0, 0.0]),
        ..new.clone()
    };
    let Outcome::Fitted(g) = entry::tool(fitted.clone(), &given) else {
        panic!("given")
    };
    assert_eq!(g.orientation, Some(OrientationSource::Given));
    assert_eq!(g.entry.unwrap().rpy_deg, [0.0, 30.0, 0.0]);
    let Outcome::Fitted(r) = entry::tool(fitted, &StoreRequest::default()) else {
        panic!("report")
    };
    assert_eq!(
        (r.orientation, r.entry),
        (Some(OrientationSource::Unknown), None)
    );
}

#[test]
fn an_axis_fit_gives_the_orientation_and_says_how_far_it_turned() {
    let model = calibrated_ur10();
    let tool = true_tool();
    let point = Vector3::new(0.6, 0.2, 0.3);
    let mark = Pose::new(tool.r, tool.p - tool.r * Vector3::new(0.0, 0.0, 0.15));
    let rows = |t: &Pose, seed| joint_rows(&fixed_point_readings(t, point, 6, 30.0, seed));
    let req = ToolRequest {
        method: TcpMethod::FixedPoint,
        rows: rows(&tool, 41),
        axis: Some(tcp::AxisRequest::Point(rows(&mark, 42))),
    };
    assert!(req.determines_orientation());
    let old = StoredEntry {
        number: None,
        frame: None,
        xyz_mm: [30.0, -20.0, 250.0],
        rpy_deg: [0.0, 0.0, 0.0],
        load: None,
    };
    let Outcome::Fitted(f) = entry::tool(
        tcp::fit_tool(&model, &req),
        &StoreRequest {
            existing: Some(old),
            store: true,
            ..StoreRequest::default()
        },
    ) else {
        panic!("fitted")
    };
    assert_eq!(f.orientation, Some(OrientationSource::Fitted));
    let r = f.replaced.unwrap();
    assert!(r.changed.contains(&EntryField::Orientation), "{r:?}");
    // The stored [0, 0, 0] was 30° off the true z.
    assert!((r.turned_deg.unwrap() - 30.0).abs() < 0.05, "{r:?}");
}

fn wo_rows(points: &[(WoPoint, Vector3<f64>)]) -> Vec<Reading> {
    let model = calibrated_ur10();
    points
        .iter()
        .map(|(p, x)| {
            let m = model.cell_from_base.transform_point(x) * 1e3;
            Reading {
                point: Some(*p),
                xyz_mm: Some([m.x, m.y, m.z]),
                ..Reading::default()
            }
        })
        .collect()
}

#[test]
fn a_work_object_whose_points_disagree_is_not_fitted() {
    let model = calibrated_ur10();
    let w = true_work_object();
    let [o, x, xy, plane] = wo_points(&w);
    let mut noise = Noise::new(51, 1e-5);
    let mut good: Vec<(WoPoint, Vector3<f64>)> = Vec::new();
    for (p, at) in [(WoPoint::Origin, o), (WoPoint::X, x), (WoPoint::Xy, xy)] {
        for _ in 0..3 {
            good.push((p, at + noise.vec()));
        }
    }
    good.push((WoPoint::Plane, plane + noise.vec()));
    let fit = tcp::fit_work_object(&model, &wo_rows(&good), None).unwrap();
    assert_eq!(fit.limits.unwrap().noise, Sources::TrackerOnly);
    // One origin reading 2 mm away from the others.
    let mut bad = good.clone();
    bad[1].1 += Vector3::new(0.002, 0.0, 0.0);
    let e = tcp::fit_work_object(&model, &wo_rows(&bad), None).unwrap_err();
    assert_eq!(e.reason, NotFittedReason::ResidualsTooLarge, "{e}");
    assert!(e.message.contains("`origin`"), "{e}");
    // RMS distance of three points from their mean, one 2 mm off the
    // others: √((4/3)² + 2·(2/3)²)/√3 = 2·√2/3 mm.
    assert!(
        (e.measured.unwrap() - 2.0 * 2f64.sqrt() / 3.0).abs() < 0.01,
        "{e:?}"
    );
    assert!((e.needed.unwrap() - 3.0 * 3f64.sqrt() * judge::TRACKER_SIGMA_MM).abs() < 1e-12);
    assert!(matches!(e.fit.as_deref(), Some(JudgedFit::WorkObject(_))));
    // A `plane` point 1 mm off the plane.
    let mut off = good.clone();
    off[9].1 += w.r * Vector3::new(0.0, 0.0, 0.001);
    let e = tcp::fit_work_object(&model, &wo_rows(&off), None).unwrap_err();
    assert_eq!(e.reason, NotFittedReason::OffPlane, "{e}");
    assert!((e.measured.unwrap() - 1.0).abs() < 0.01, "{e:?}");
    assert_eq!(e.row, Some(1));
    // Forced, it is stored with what it replaces, frame included.
    let old = StoredEntry {
        number: Some(2),
        frame: Some(robocal_core::solve::cell::WorkObjectFrame::Measurement),
        xyz_mm: [0.0; 3],
        rpy_deg: [0.0; 3],
        load: None,
    };
    let Outcome::Fitted(f) = entry::work_object(
        Err(e),
        &StoreRequest {
            existing: Some(old),
            store: true,
            force: true,
            ..StoreRequest::default()
        },
    ) else {
        panic!("forced")
    };
    let r = f.replaced.unwrap();
    assert_eq!(r.moved_mm, None);
    assert!(r.changed.contains(&EntryField::Frame));
    assert_eq!(f.entry.unwrap().number, Some(2));
}
